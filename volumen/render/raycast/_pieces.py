"""Compile-time specialization: tags for the mode, the shading model and the reconstruction, and pieces chosen by tag.

A kernel takes a *mode tag* and a *light tag*: empty NamedTuple instances
whose classes Numba sees as distinct types. A :func:`piece` is a generic
function whose implementation is picked by the class of its first argument
when the caller is compiled, so ``step(mode, ...)`` inside the marching loop
compiles to the composite step for a ``Composite()`` tag and to the projections'
step for a ``Projection()`` tag -- one skeleton, one specialised kernel per (mode, light),
each compiled on its first use (and cached: the tags' types pickle by class),
with no branch on the mode at run time (but among the three projections, which share one kernel:
``Settings.projection``, ``_project``).

The *reconstruction tag* (``Settings.recon``: :class:`Trilinear`, which also
covers nearest-voxel sampling by ``Settings.nearest``, or :class:`BSpline`) rides
in the frame's settings, whose type Numba keys the compiled code on: a B-spline
frame compiles kernels of its own on first use, and the trilinear ones are
unchanged by it (``_bspline``).

The *label tag* (``Settings.labels``: :class:`ScanOnly`, or :class:`WithLabels` exactly where a label map
classifies the samples, ``Settings.nlabels > 0``) rides there too, and in the light paths' medium
(``_medium.Medium.labels``). So the light paths of a frame without labels hold no call to the label
classification, not even one behind a branch: such a call in the shadow rays' loop never ran and still cost 2-7 %
of a scattering frame.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

from numba.core.errors import NumbaIRAssumptionWarning
from numba.extending import overload

from ...jit import inline_only, install_cuda
from ...jit._prefetch import register_cuda as register_prefetch

__all__ = ["piece", "for_cuda", "init", "step", "finish", "radius", "eager", "shade", "uses_normals", "MODE_TAGS",
           "LIGHT_TAGS",
           "Composite", "LabelledComposite", "Preintegrated", "Projection", "PROJECTIONS",
           "Isosurface", "Unlit", "Phong", "Headlight", "Shadowed", "Scatter", "Trilinear", "BSpline", "RECON_TAGS",
           "ScanOnly", "WithLabels", "label_tag", "labelled", "Sample", "RayEnd", "Pixel"]


class Sample(NamedTuple):
    """One sample the marching loop hands a mode's ``step``."""

    k: int       #: its index on the ray's sample grid
    t: float     #: its ray parameter (mm)
    v: float     #: its value (table units)
    have: bool   #: whether the sample before it (``k - 1``) was taken: a mode that reads it need not sample it again
    span: int    #: grid steps it stands for (more than 1 only where adaptive sampling merges steps, ``_march``)


class RayEnd(NamedTuple):
    """How the marching loop ended, handed to a mode's ``finish``."""

    taken: int   #: samples taken
    have: bool   #: whether the last sample of the grid before the exit was taken


class Pixel(NamedTuple):
    """Where a mode's ``finish`` writes: the outputs (``_frame.Outputs``) and the pixel's column and row."""

    out: object
    x: int
    y: int


class Composite(NamedTuple):
    """Emission-absorption compositing, post-classified."""


class LabelledComposite(NamedTuple):
    """Emission-absorption compositing, each sample classified through the label map (``_labelled``)."""


class Preintegrated(NamedTuple):
    """Emission-absorption compositing of pre-integrated segments."""


class Projection(NamedTuple):
    """Maximum, minimum or mean of the samples along the ray (``Settings.projection``: :data:`PROJECTIONS`): one kernel
    for the three, which differ by a branch on a value every ray of the frame shares, not by a compile of their
    own."""


class Isosurface(NamedTuple):
    """First threshold crossing seen from the eye's side."""


class Unlit(NamedTuple):
    """No lighting (emission-absorption only)."""


class Phong(NamedTuple):
    """Phong, every light fully visible (headlight and phong)."""


class Headlight(NamedTuple):
    """Phong with one light at the eye of a perspective camera: at every sample the light's direction is the
    view direction (no light vector to compute)."""


class Shadowed(NamedTuple):
    """Phong with each light weighted by its visibility (shadows; scattering on surfaces)."""


class Scatter(NamedTuple):
    """Single scattering in the medium (no normals)."""


class Trilinear(NamedTuple):
    """Trilinear reconstruction (nearest-voxel where ``Settings.nearest``); normals from the per-voxel codes."""


class BSpline(NamedTuple):
    """Tricubic B-spline reconstruction (the approximating cubic B-spline, ``_bspline``): values and gradients."""


class ScanOnly(NamedTuple):
    """The transfer function alone classifies the samples (no label map)."""


class WithLabels(NamedTuple):
    """The label-aware classification (``_labelled``) classifies the samples."""


def label_tag(nlab: int):
    """The label tag of a frame with ``nlab`` label-table rows (``Settings.nlabels``; 0: no label map)."""
    return WithLabels() if nlab > 0 else ScanOnly()


#: Scene.mode (and pre-integration, label-aware composite) -> mode tag class
MODE_TAGS = {"composite": Composite, "labelled": LabelledComposite, "preintegrated": Preintegrated, "mip": Projection,
             "minip": Projection, "average": Projection, "isosurface": Isosurface}
#: the projection modes, by ``Settings.projection`` (the :class:`Projection` tag's kernel)
PROJECTIONS = ("mip", "minip", "average")
#: lighting model name -> light tag class
LIGHT_TAGS = {"unlit": Unlit, "phong": Phong, "headlight": Headlight, "shadows": Shadowed, "scatter": Scatter}
#: Sampling.interpolation -> reconstruction tag class
RECON_TAGS = {"linear": Trilinear, "nearest": Trilinear, "bspline": BSpline}


# Numba's SSA pass, after inlining a piece whose implementation is inlined twice in one kernel, finds a
# variable of the inlined copy outside its scope and prints a "pedantic check" warning of a dozen lines
# per kernel on a user's first picture: numba/numba#9489 (open; Python 3.11). Harmless: the compiled
# kernels draw the pixels of their source run as Python (tests/render/test_cuda_sim.py). Only the pieces' own
# variables (``choose`` below) are silenced; goes when Numba fixes the scope of inlined variables.
warnings.filterwarnings("ignore", message=r"variable 'choose__locals__impl", category=NumbaIRAssumptionWarning)


#: every piece made, as ``(stub, choose)``: what :func:`for_cuda` registers with the CUDA target
_PIECES: list = []
#: numba-cuda's ``overload`` once :func:`for_cuda` ran (a piece made later registers itself)
_cuda: dict = {"overload": None}


def for_cuda() -> None:
    """Register every piece, and the prefetch hint, with numba-cuda's own overload registry (once; the CUDA
    kernels call it on import).

    numba-cuda (0.21 and later) types a kernel with its own typing context: an overload registered through
    ``numba.extending`` with ``inline="always"``, as :func:`piece` registers for the CPU, is inlined there with
    its arguments lost (``add(omitted, omitted)``: every kernel failed to compile; still so in 0.30.4, though
    NVIDIA/numba-cuda#624, the same fault for ``target="cuda"``, is closed). The same ``choose`` registered through
    ``numba.cuda.extending`` inlines as on the CPU.
    """
    if _cuda["overload"] is not None:
        return
    from numba.cuda.core.errors import NumbaIRAssumptionWarning as CudaIRWarning
    from numba.cuda.extending import overload as cuda_overload

    install_cuda()  # the inliner's patches (``_inlining``) in numba-cuda's own copy of the compiler

    # numba-cuda's own copy of numba/numba#9489's warning (silenced for the CPU above)
    warnings.filterwarnings("ignore", message=r"variable 'choose__locals__impl", category=CudaIRWarning)
    for stub, choose in _PIECES:
        cuda_overload(stub, inline="always")(choose)
    register_prefetch(cuda_overload)  # the march's prefetch hint (``volumen.jit.prefetch``): nothing on the GPU
    _cuda["overload"] = cuda_overload


def piece(name: str, params: str, doc: str = ""):
    """A generic function ``f(tag, <params>)`` calling the implementation registered for ``type(tag)``.

    ``params`` names the arguments after the tag (comma-separated: the arity is
    fixed, so Numba can inline the chosen implementation into its caller).
    ``@f.register(TagA, TagB)`` above an ``@njit`` function registers it for
    those tags; the implementation gets the arguments after the tag. Called
    from Python (``NUMBA_DISABLE_JIT=1``) it calls the same implementation.
    """
    impls: dict[type, object] = {}
    args = ", ".join(p.strip() for p in params.split(",") if p.strip())
    sep = ", " if args else ""
    ns: dict = {"impls": impls, "inline_only": inline_only}
    exec(f"def stub(tag{sep}{args}):\n    return impls[type(tag)]({args})\n"
         f"def choose(tag{sep}{args}):\n    fn = impls[tag.instance_class]\n"
         f"    def impl(tag{sep}{args}):\n        return fn({args})\n    return inline_only(impl)\n", ns)
    stub = ns["stub"]
    stub.__name__ = stub.__qualname__ = name
    stub.__doc__ = doc
    overload(stub, target="generic", inline="always")(ns["choose"])
    _PIECES.append((stub, ns["choose"]))
    if _cuda["overload"] is not None:
        _cuda["overload"](stub, inline="always")(ns["choose"])

    def register(*tags):
        def deco(fn):
            for t in tags:
                impls[t] = fn
            return fn

        return deco

    stub.register = register
    stub.impls = impls
    return stub


# the pieces of the marching skeleton (``_march``), implemented per mode tag in ``_composite``,
# ``_project`` and ``_iso``, and the lighting piece, implemented per light tag in ``_shade``
init = piece("init", "light, r, a, s", "-> (state, samples taken, done, previous sample usable)")
step = piece("step", "light, r, a, s, st, smp", "-> (state, extra samples taken, done); smp: the :class:`Sample`")
finish = piece("finish", "light, r, a, s, st, end, pix",
               "write the pixel; end: the :class:`RayEnd`, pix: the :class:`Pixel`")
radius = piece("radius", "a, s, st, o, bk, bj, bi", "-> blocks to jump (0: take the sample); o: the ray's octant")
eager = piece("eager", "", "-> True when one skippable block suffices to jump")
shade = piece("shade", "a, s, n, v, w", "-> (fr, fg, fb, sr, sg, sb) lighting factors of a sample")
uses_normals = piece("uses_normals", "", "-> whether shading reads the gradient")
labelled = piece("labelled", "", "-> whether the label map classifies the samples (per label tag: ``_medium``)")
