"""``phantom(name, ...)``: the registry of built-in phantoms.

Each phantom is a function ``builder(size=None, **params) -> Volume`` registered
under a name; ``phantom`` checks the name and the parameters, calls the builder
and records what was asked in ``meta["phantom"]`` so a volume says how to make
it again. Every phantom is deterministic: the same name and parameters give the
same bytes.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable

from ..core import Volume
from ..errors import UnknownChoiceError
from ._abdomen import abdomen
from ._airways import airways
from ._chest import arch
from ._head import head
from ._layered import layered_aorta
from ._mr import mr_head
from ._shapes import ellipsoid, slab, sphere
from ._tagged import tagged_colon
from ._terraces import terraces
from ._thorax import chest
from ._torso import torso
from ._vessel import stenosis_phantom
from ._washout import washout

__all__ = ["PHANTOMS", "phantom"]

_BUILDERS: dict[str, Callable[..., Volume]] = {
    "head": head,
    "mr_head": mr_head,
    "torso": torso,
    "abdomen": abdomen,
    "chest": chest,
    "sphere": sphere,
    "ellipsoid": ellipsoid,
    "slab": slab,
    "arch": arch,
    "airways": airways,
    "tagged_colon": tagged_colon,
    "washout": washout,
    "terraces": terraces,
    "stenosis": stenosis_phantom,
    "layered_aorta": layered_aorta,
}

PHANTOMS: tuple[str, ...] = tuple(_BUILDERS)


def phantom(name: str, size=None, **params) -> Volume:
    """A built-in phantom as a CT volume in Hounsfield units (int16, air -1000).

    Parameters
    ----------
    name : str
        One of :data:`PHANTOMS`:

        ``"head"``
            An upright head, face toward +y, vertex toward +z (default 128 voxels along z,
            1.875 mm isotropic, 240 mm). Params: ``noise`` (HU, default 10), ``seed``,
            ``blur`` (scanner point-spread sigma in voxels, default 0.5, built into every
            partial-volume edge; 0 leaves the bare partial-volume ramp, one voxel wide),
            ``grey_white`` (bool). A dense bead marks the patient's RIGHT (+x) at eye level.
        ``"mr_head"``
            The head as an MRI (uint16 scanner units, about 0-900, modality MR, Rician noise),
            with a few voxels far brighter than any tissue, as real MRIs have. Params: ``noise`` (default
            12), ``outliers`` (share of the head's voxels, default 0.0005; 0: none), ``gain`` (times the
            brightest tissue, default 4), ``seed``, ``dtype`` (``"uint16"``, or ``"float32"``: unrounded,
            unclipped). Not in HU: the one phantom that is not a CT.
        ``"torso"``
            The trunk with lungs and airway, spine, ribs, contrast-filled aorta and branches,
            and a colon with haustral folds and one polyp (default 160 voxels along z,
            2.5 mm isotropic, 360 x 260 x 400 mm). Params: ``noise``, ``seed``, ``blur``,
            ``fold_depth`` (fraction of the radius, <= 0.5), ``polyp_radius`` (mm).
        ``"abdomen"``, ``"chest"``
            Whole-region CTs built for speed measurements on scans like the ones people look at:
            soft tissue in most rays, organs with texture, gas in the bowel or lungs, bone, the table,
            partial-volume edges and correlated scanner noise (default (224, 202, 244) voxels, 1.64 mm,
            400 x 331 x 367 mm; abdomen: portal-venous phase from the lung bases to the iliac crests;
            chest: contrast in the vessels, shoulders to the upper abdomen). Params: ``noise`` (HU,
            default 12), ``seed``, ``blur`` (default 0.6).
        ``"sphere"``, ``"ellipsoid"``, ``"slab"``
            Analytic objects (default 64 voxels per axis at ``spacing`` 1 mm). Params:
            ``radius`` / ``semi_axes`` / ``thickness`` and ``axis`` (mm), ``center``
            (xyz mm), ``inside``, ``outside`` (HU), ``spacing`` (mm, scalar or (dz, dy, dx)),
            ``antialias`` (partial-volume blending; default sharp sampling at voxel centres).
        ``"terraces"``
            Whole-HU steps of ``step`` HU (default 100) around ``level`` (default 300) from a smooth
            random field (``sigma`` voxels, ``seed``): a fifth of the samples exactly at the level, the
            failure class of meshes of integer CT at an integer level (default 24 voxels per axis at
            ``spacing`` 1 mm).
        ``"stenosis"``
            A curved contrast-filled artery (radius 5 mm) with a 50 % stenosis and a fusiform aneurysm
            (18 mm across), contrast falling along it and layered across it, in soft tissue (default 176
            voxels along z, 1 mm isotropic). Params: ``noise``, ``seed``, ``blur``, ``layering`` (HU).
            ``meta["truth"]``: the ``vessel`` :class:`~volumen.data.Tube`, ``stenosis`` (%), ``max_diameter``.
        ``"layered_aorta"``
            A large contrast vessel (radius 13 mm) whose contrast is layered and mixed with a jet of
            unopacified blood (100-480 HU), correlated noise (``noise`` 30-60 HU, default 40), lung ``gap`` mm
            away, a bright neighbour touching it (default 100 voxels along z, 1.5 mm). Params: ``noise``,
            ``seed``, ``blur``, ``layering`` (HU), ``gap`` (mm). ``meta["truth"]["landmarks"]["starts"]``: 20 starts.
    size : int or (nz, ny, nx), optional
        Voxel count along the longest axis (isotropic voxels over the phantom's field of
        view), or the three counts (the spacing then follows per axis). For the analytic
        shapes an int means a cube of ``size`` voxels of ``spacing`` mm.
    **params
        The phantom's parameters listed above.

    Returns
    -------
    Volume
        Data ``[z, y, x]`` int16 HU (``mr_head``: uint16 scanner units); axis-aligned RAS affine (i -> +x Right, j -> +y
        Anterior, k -> +z Superior) with the volume centred near the world origin.
        ``meta["truth"]`` holds the ground truth (world RAS+ mm): for head and torso
        ``landmarks`` (name -> [x, y, z]) and :class:`~volumen.data.Tube` entries
        (``"nasal_airway"``; ``"colon"``, ``"aorta"``, ``"airway"``) plus ``"polyp"``
        for the torso; for the shapes the exact object. ``meta["phantom"]`` records
        ``name``, ``size`` and ``params``.

    Raises
    ------
    ValueError
        For an unknown name (the message lists :data:`PHANTOMS`) or a bad parameter value.
    TypeError
        For a parameter the phantom does not take (the message lists those it takes).
    """
    try:
        builder = _BUILDERS[name]
    except (KeyError, TypeError):
        raise UnknownChoiceError("phantom", name, PHANTOMS) from None
    accepted = [p for p in inspect.signature(builder).parameters if p != "size"]
    unknown = sorted(set(params) - set(accepted))
    if unknown:
        raise TypeError(f"phantom {name!r} takes no parameter {', '.join(unknown)}; it takes {', '.join(accepted)}")
    vol = builder(size, **params)
    vol.meta["phantom"] = {"name": name, "size": size, "params": dict(params)}
    return vol
