"""pydicom's whole test-data corpus: each file loads (agreeing with SimpleITK) or is refused with a typed error.

The corpus is the files installed with pydicom (nothing is downloaded); the counts are
printed (``pytest -s``) and quoted in README's Formats section. About 10 s on one core.
"""

import re

import pytest

from tests.io.dicom_corpus import DOCUMENTED_REFUSALS, corpus_files, examine, table
from volumen.errors import VolumeReadError

#: what a refusal may say: each reason tells the user what the file is or lacks
ACTIONABLE = re.compile(r"not a DICOM file|without pixel data|has no pixel data|holds no DICOM images|"
                        r"not a readable DICOM file|could not decode|is not a whole number|unreadable header|truncated")


@pytest.fixture(scope="module")
def outcomes():
    results = [examine(p) for p in corpus_files()]
    print("\n" + table(results))
    return results


def test_corpus_is_the_installed_pydicom_data(outcomes):
    assert len(outcomes) >= 150, "pydicom's installed test files are missing"


def test_no_untyped_errors(outcomes):
    bad = [(o.name, o.untyped) for o in outcomes if o.untyped]
    assert not bad


def test_loaded_files_agree_with_simpleitk(outcomes):
    """Shape, origin (RAS, 0.001 mm), spacing (1e-4 relative) and values (1e-4 of the range; lossy JPEG 1 grey
    level) where SimpleITK reads the file, through the documented conventions."""
    both = [o for o in outcomes if o.volume is not None and o.sitk is not None]
    assert len(both) >= 95
    assert not [(o.name, o.disagreements) for o in both if o.disagreements]


def test_refusals_are_typed_name_the_file_and_say_why(outcomes):
    for o in outcomes:
        if o.error is None:
            continue
        assert isinstance(o.error, VolumeReadError)
        assert o.name.split("/")[-1] in str(o.error), str(o.error)
        assert ACTIONABLE.search(o.error.problem), str(o.error)


def test_nothing_decodable_is_refused_except_the_documented_list(outcomes):
    refused = {o.name.split("/")[-1]: str(o.error) for o in outcomes
               if o.error is not None and (o.pydicom_decodes or o.sitk is not None)}
    assert set(refused) <= set(DOCUMENTED_REFUSALS), refused


def test_colour_and_monochrome1_are_kept_and_flagged(outcomes):
    loaded = {o.name.split("/")[-1]: o.volume for o in outcomes if o.volume is not None}
    assert sum(v.is_color for v in loaded.values()) >= 30
    assert loaded["examples_palette.dcm"].is_color and loaded["examples_palette.dcm"].dtype.name == "uint8"
    mono1 = [v for v in loaded.values() if v.meta.get("photometric") == "MONOCHROME1"]
    assert mono1 and all(v.meta["display_inverted"] for v in mono1)
