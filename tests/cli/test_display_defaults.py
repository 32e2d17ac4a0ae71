"""Every entry point opens an MRI with far-bright outliers the same way (``core.display_range``): the command
line with and without ``--preset mr-default``, the notebook, the app's model, a flythrough's ``--preset``; and
each starts its isosurface at ``core.default_iso`` (it started at 0: the background of an MRI)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from PIL import Image as PILImage

from volumen.cli import main
from volumen.core import default_iso, default_preset, fitted_preset
from volumen.data import phantom

REF = "phantom:mr_head?size=40"


@pytest.fixture(scope="module")
def mr():
    return phantom("mr_head", size=40)


def test_naming_mr_default_on_the_command_line_draws_the_picture_it_opens_with(tmp_path, capsys):
    """Bit for bit: ``--preset mr-default`` is the default fitted to the same display range."""
    shown = {}
    for name, extra in (("none", []), ("named", ["--preset", "mr-default"])):
        out = tmp_path / f"{name}.png"
        assert main(["render", REF, "-o", str(out), "--size", "48x48", *extra]) == 0
        shown[name] = np.asarray(PILImage.open(out))
    capsys.readouterr()
    assert np.array_equal(shown["none"], shown["named"]) and shown["none"].max() > 100


def test_the_notebook_and_a_flythrough_fit_a_named_preset_as_the_default(mr):
    from volumen.endoscopy import endoscopy_transfer
    from volumen.notebook._controls import preset_transfer

    class Scene:  # the notebook's helper reads the scene's volume only
        volume = mr

    assert preset_transfer(Scene, "mr-default") == default_preset(mr) == fitted_preset("mr-default", mr)
    assert endoscopy_transfer("mr-default", mr) == default_preset(mr)  # raised before: a data-relative preset
    assert endoscopy_transfer("mip-gray", mr) == default_preset(mr, "mip")


def test_the_app_model_and_the_notebook_start_the_isosurface_at_the_default_level(mr):
    """The app's model (no Qt) and ``volumen.show``: an MRI at the middle of its display range, a CT at bone; a
    session's look (a transfer function given) keeps its own level."""
    from volumen.app._state import AppState
    from volumen.core import TransferFunction

    st = AppState()
    st.set_volume(mr, REF)
    assert st.scene.isosurface.value == pytest.approx(default_iso(mr)) and 200 < default_iso(mr) < 400
    ct = phantom("head", size=24)
    st.set_volume(ct, "phantom:head?size=24")
    assert st.scene.isosurface.value == 300.0
    st.update_scene(isosurface=replace(st.scene.isosurface, value=123.0))
    st.set_volume(mr, REF, transfer=TransferFunction.preset("ct-bone"))
    assert st.scene.isosurface.value == 123.0

    import volumen

    pytest.importorskip("ipywidgets", reason="volumen.show needs ipywidgets (the notebook extra)")
    v = volumen.show(mr, size=(32, 32), slices=False)
    try:
        assert v.scene.isosurface.value == pytest.approx(default_iso(mr))
    finally:
        v.close()
