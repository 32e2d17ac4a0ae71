"""Built-in data: generated phantoms (deterministic, in Hounsfield units) and installed sample volumes.

``phantom(name, size=None, **params)`` builds one of ``PHANTOMS``; ground truth for
tests lives in ``volume.meta["truth"]`` (landmarks, :class:`Tube` entries for tubular
structures, the exact analytic shapes). ``sample(name)`` loads real data found on the
machine (``samples()`` lists it); ``shared_data(*parts)`` finds the shared data folder
(``VOLUMEN_SHARED_DATA``, else ``shared/data`` beside the repository or beside its folder).
``fill_outside_field(volume, fill)`` turns a phantom into a resampler's output: floats, the voxels outside the
field of view one fill value far below the rest.
"""

from ._fill import fill_outside_field
from ._organs import ORGANS, organ_phantom
from ._phantom import PHANTOMS, phantom
from ._samples import sample, samples
from ._shared_data import shared_data, shared_data_candidates
from ._tubes import Tube

__all__ = ["PHANTOMS", "phantom", "organ_phantom", "ORGANS", "sample", "samples", "Tube", "shared_data",
           "shared_data_candidates", "fill_outside_field"]
