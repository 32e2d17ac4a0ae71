"""Turn (Scene, Camera, size) into the arrays and scalars the kernels read: one place for every backend.

:func:`pack_frame` validates the combination of settings, takes the
per-volume precomputations from the cache (``_cache``), builds the transfer
function tables, packs camera, geometry, lights and parameters, and builds
(or takes from the cache) the illumination volumes of the lights.
"""

from __future__ import annotations

import time

import numpy as np

from ...core import Environment, adaptive_on, studio_lights
from ._cache import prepare, shared_table
from ._cells import NO_CELLS, cell_bits
from ._environment import pack_environment
from ._frame import Arrays, Frame, Settings
from ._geometry import G_BOX, pack_camera, pack_geometry, pack_planes
from ._labelled import label_blocks, label_table, packed_labels, solid_rows
from ._lightvol import NMETA, light_volumes
from ._medium import Medium, label_scale
from ._normals import BRICK, DIRS, NO_CODES, NO_SLOTS
from ._octants import octant_sides
from ._pieces import LIGHT_TAGS, MODE_TAGS, PROJECTIONS, RECON_TAGS, label_tag
from ._precompute import NLUT
from ._scatter import medium
from ._shade import L_POS, headlight, pack_lights
from ._tables import (
    ADAPTIVE_ALPHA,
    ADAPTIVE_STRIDE,
    NPRE,
    block_visibility,
    coarse_blocks,
    color_table,
    extinction_table,
    gradient_table,
    iso_extinction_table,
    iso_visibility,
    preintegrated_table,
)

__all__ = ["pack_frame", "scene_lights", "LIT_SHADINGS", "MODELS"]

#: shading modes that use the scene's lights and need the medium's light paths
LIT_SHADINGS = ("shadows", "scattering", "pathtrace")
#: shading modes lit by the scene's lights (or the studio rig's) and the environment
LIGHTED = ("phong", *LIT_SHADINGS)
#: Shading.mode -> lighting model (``_pieces.LIGHT_TAGS``); path tracing reads the scattering medium
MODELS = {"none": "unlit", "headlight": "phong", "phong": "phong", "shadows": "shadows", "scattering": "scatter",
          "pathtrace": "scatter"}


class _Same:
    """A key part equal only for the same object (a label map: cached, never changed in place); it holds the
    object, so its id is not reused while the key lives."""

    __slots__ = ("obj",)

    def __init__(self, obj):
        self.obj = obj

    def __eq__(self, other):
        return isinstance(other, _Same) and other.obj is self.obj

    def __hash__(self):
        return id(self.obj)


def _light_keys(scene, lights, geo, planes, kext, med):
    tf = scene.transfer.to_json() if scene.mode != "isosurface" else f"iso:{scene.isosurface.value!r}"
    clip = geo.tobytes() + planes.tobytes()
    scale = scene.shading.shadows.light_volume_scale
    labels = (_Same(med.label_map), med.label_lut.tobytes(), med.lscale) if med.nlabels > 0 else None
    recon = type(med.recon).__name__
    return [(np.round(lights[i, L_POS:L_POS + 3], 9).tobytes(), tf, clip, scale, kext, labels, recon)
            for i in range(len(lights))]


def _model(scene) -> tuple[str, bool]:
    """``(lighting model, lit as a medium)`` of the scene's shading and mode."""
    sh, mode = scene.shading, scene.mode
    if sh.mode == "none" or mode not in ("composite", "isosurface"):
        return "unlit", False
    medium_model = sh.mode in ("scattering", "pathtrace") and mode == "composite"
    if sh.mode in ("scattering", "pathtrace") and not medium_model:
        return "shadows", False  # a surface has no medium: lit as with shadows
    return MODELS[sh.mode], medium_model


def _skip_tables(scene, prep, lut, u_iso, lab):
    """``(skip, bflag, bmin, bmax)``: empty-space skipping and its block grids."""
    smp, mode = scene.sampling, scene.mode
    if not (smp.skip_empty and mode != "average"):
        return False, _NO_FLAGS, _NO_BLOCKS, _NO_BLOCKS
    bmin, bmax = prep.blocks(smp.block_size)
    seen = (lut[:, 3] > 0).tobytes()  # which table entries are visible: the flags' key
    if mode == "composite" and lab is not None:  # the scan's visible blocks and the solid structures'
        solid = label_blocks(lab[0], lab[1], smp.block_size)  # one object per (label map, table, block); the
        # memo holds it, so its id names it while the entry lives
        bflag = prep.memo(("skip-labels", smp.block_size, seen, id(solid)),
                          lambda: (solid, octant_sides(block_visibility(lut[:, 3], bmin, bmax) | solid)))[1]
    elif mode == "composite":  # depends only on which table entries are visible: kept while the camera moves
        bflag = prep.memo(("skip", smp.block_size, seen),
                          lambda: octant_sides(block_visibility(lut[:, 3], bmin, bmax)))
    elif mode == "isosurface":
        bflag = prep.memo(("skip-iso", smp.block_size, u_iso),
                          lambda: octant_sides(iso_visibility(u_iso, bmin, bmax)))
    else:  # mip / minip decide per ray from bmin / bmax
        bflag = _NO_FLAGS
    return True, bflag, bmin, bmax


def _shown(scene, prep, lut, preint):
    """The bricks whose normal codes a frame reads (``_normals``): those a post-classified composite picture without
    labels can show, kept while the visible table entries are the same; None (every brick) where
    what is shown is not known from the table alone (isosurfaces, labels, pre-integration)."""
    if scene.mode != "composite" or preint or scene.labels is not None:
        return None
    seen = (lut[:, 3] > 0).tobytes()
    return prep.memo(("shown", seen), lambda: block_visibility(lut[:, 3], *prep.blocks(BRICK)) > 0)


def _coarse_table(scene, prep, lut, lab):
    """``Arrays.coarse_flags``: the blocks adaptive sampling takes longer steps in (post-classified composite without
    labels, with skipping), else a (1, 1, 1, 1) zero placeholder."""
    smp = scene.sampling
    if not (adaptive_on(scene) and smp.skip_empty and scene.mode == "composite" and lab is None
            and not smp.preintegrate):
        return _NO_COARSE
    bmin, bmax = prep.blocks(smp.block_size)
    alpha = lut[:, 3]
    return prep.memo(("coarse", smp.block_size, (alpha >= ADAPTIVE_ALPHA).tobytes(), (alpha > 0).tobytes()),
                     lambda: coarse_blocks(alpha, bmin, bmax))


#: the placeholder of a frame without adaptive sampling
_NO_COARSE = np.zeros((1, 1, 1, 1), np.uint8)


def _cell_table(scene, prep, lut, lab, skip):
    """``Arrays.cells``: which cells can hold a visible sample (post-classified composite without labels, with
    skipping, not the B-spline, not path traced), else :data:`NO_CELLS`. Built from the second frame that asks
    with the same visible table entries on, and kept while the camera moves: the pass over the volume (50 ms
    for 11 M int16 voxels, 165 ms for 37 M, on 2 cores) costs more than one frame saves, and while a transfer
    function is dragged every frame has new entries."""
    smp = scene.sampling
    if not (skip and scene.mode == "composite" and lab is None and not smp.preintegrate
            and smp.interpolation != "bspline" and scene.shading.mode != "pathtrace"):
        return NO_CELLS
    alpha = lut[:, 3]
    return prep.memo_repeated(("cells", (alpha > 0).tobytes()),
                              lambda: cell_bits(prep.u, prep.u0, prep.ufac, alpha), NO_CELLS, "cells")


def _range_table(build, prep, tf, ratio):
    """``build(tf, vmin, vmax, ratio)`` over the volume's range (:func:`color_table`,
    :func:`preintegrated_table`), kept while only the camera moves: the frames, and the volumes with the same
    range, share it (nothing writes into it; the pre-integrated table took 11 ms of every frame to rebuild)."""
    return shared_table((build.__name__, tf, prep.vmin, prep.vmax, ratio),
                        lambda: build(tf, prep.vmin, prep.vmax, ratio))


def _tables(scene, prep, ratio, kext, model, medium_model, u_iso) -> dict:
    """The transfer-function tables, normals and skipping grids of the frame (fields of :class:`Arrays`)."""
    tf, mode, sh = scene.transfer, scene.mode, scene.shading
    preint = scene.sampling.preintegrate and mode == "composite"
    lut = _range_table(color_table, prep, tf, ratio * kext if (mode == "composite" and not preint) else None)
    pre = _range_table(preintegrated_table, prep, tf, ratio * kext) if preint else _NO_PRE
    gradop = tf.gradient_opacity is not None and mode == "composite"
    shaded = model != "unlit" and not medium_model
    ncode, nslot, gcode = NO_CODES, NO_SLOTS, _NO_MAGS
    if shaded or gradop:
        sobel = sh.phong.gradient == "sobel"
        nrm, gmax = prep.normals(sobel, magnitude=gradop)
        if scene.sampling.interpolation != "bspline":  # the B-spline's gradients are its own (``_bspline.normal``)
            keep = _shown(scene, prep, lut, preint) if shaded else None
            ncode, nslot, gcode = prep.codes(sobel, shaded, gradop, keep)
    else:
        nrm, gmax = np.zeros((4, 3), np.float64), 0.0
    glut = gradient_table(tf, gmax) if gradop else np.ones(128, np.float32)
    lab = _labels(scene, ratio * kext)
    skip, bflag, bmin, bmax = _skip_tables(scene, prep, lut, u_iso, lab)
    bcoarse = _coarse_table(scene, prep, lut, lab)
    cells = _cell_table(scene, prep, lut, lab, skip)
    if sh.mode not in LIT_SHADINGS or model == "unlit":
        sig = np.zeros(1, np.float32)
    elif mode == "isosurface":  # the drawn surface casts the shadows
        sig = iso_extinction_table(u_iso)
    else:
        sig = extinction_table(tf, prep.vmin, prep.vmax)
    lab, llut = lab if lab is not None else (_NO_LAB, _NO_LLUT)
    return dict(lut=lut, pre=pre, nrm=nrm, ncode=ncode, nslot=nslot, gcode=gcode, glut=glut, bflag=bflag, bmin=bmin,
                bmax=bmax, bcoarse=bcoarse, cells=cells, sig=sig, skip=skip, gradop=gradop, preint=preint, lab=lab,
                llut=llut)


#: the label arrays of a scene without labels: one object, so a device keeps it between frames (PER_VOLUME)
_NO_LAB = np.zeros((1, 1, 1), np.uint8)
_NO_LLUT = np.zeros((1, 5), np.float32)
_NO_MAGS = np.zeros((1, 1, 1), np.uint8)
#: no pre-integrated table (post-classification)
_NO_PRE = np.zeros((1, 1, 4), np.float32)
#: no skip flags / block grids (no empty-space skipping, or a projection's rays, which read bmin / bmax only)
_NO_FLAGS = np.zeros((1, 1, 1, 1), np.uint8)
_NO_BLOCKS = np.zeros((1, 1, 1), np.float32)
#: no majorant grid (the path tracer adds its own: ``_progressive``)
NO_MAJ = np.zeros((1, 1, 1), np.float32)
#: the environment of the unlit models
_UNIFORM = Environment(kind="uniform")
#: no opacity carried in (a whole frame, not a part of one: ``_ray``)
NO_CARRY = np.zeros((1, 1), np.float32)


def _labels(scene, ratio):
    """``(label map, label table)`` of a scene with a label layer drawn in composite mode, else None."""
    layer = scene.labels
    if layer is None or scene.mode != "composite":
        return None
    if layer.labels.shape != scene.volume.shape:
        raise ValueError(f"the labels' grid {layer.labels.shape} differs from the volume's {scene.volume.shape}: "
                         "put them on it first (volumen.io.labels_on_grid)")
    return packed_labels(layer.labels.data), label_table(layer, ratio)


def _lights(scene, camera, model, env):
    """``(packed lights, count)``: the scene's, or the studio rig's when it has none and the environment is the
    studio (:func:`~volumen.core.studio_lights`)."""
    if model == "unlit":
        return np.zeros((1, 11), np.float64), 0
    if scene.shading.mode == "headlight":
        return headlight(camera), 1
    lights = scene_lights(scene, camera, env)
    return pack_lights(lights, camera), len(lights)


def scene_lights(scene, camera, env: Environment | None = None) -> tuple:
    """The lights that light ``scene``: its own, or where it has none and its environment (``env``; default the
    scene's, resolved) is the studio, the studio rig placed about its volume (:func:`~volumen.core.studio_lights`)."""
    env = scene.environment.resolved(bool(scene.lights)) if env is None else env
    if scene.lights or env.kind != "studio":
        return tuple(scene.lights)
    vol = scene.volume
    return studio_lights(camera, vol.center, vol.diagonal, env.intensity)


def _env_power(lights, nlights, env) -> float:
    """Weight of the environment in the path tracer's choice of a light to sample (the lights': intensity x
    luminance of their colour): twice its mean luminance (the irradiance it gives a surface over pi, from both
    sides of a medium sample), 0 for a uniform environment (its light is found by paths that leave)."""
    img = env[0]
    if img.shape[:2] == (2, 2) and not img.any():
        return 0.0
    lum = img[..., 0] * 0.2126 + img[..., 1] * 0.7152 + img[..., 2] * 0.0722
    wt = np.sin((np.arange(img.shape[0]) + 0.5) * np.pi / img.shape[0])[:, None]
    return float(2.0 * (lum * wt).sum() / (wt.sum() * img.shape[1]))


def _light_volumes(scene, prep, t, st, lights, model, build):
    """``(lvm, lvd, built)``: the illumination volumes of the lit models that read them."""
    sh = scene.shading
    path_traced = sh.mode == "pathtrace" and scene.mode == "composite"  # ratio tracking, no light volumes
    nlights, kext = st.nlights, st.extinction_scale
    if model in ("unlit", "phong") or path_traced or not nlights:
        prep.light_set = None  # nothing reads the volume's light volumes now: they go (built again when asked for)
        return np.zeros((1, NMETA)), np.ones(1, np.float32), 0
    geo, planes = t["geo"], t["planes"]
    inv = np.linalg.inv(np.asarray(scene.volume.affine, float))
    pos_index = (np.c_[lights[:nlights, L_POS:L_POS + 3], np.ones(nlights)] @ inv.T)[:, :3]
    med = Medium(prep.u, t["sig"], prep.u0, prep.ufac, t["lab"], t["llut"], t["lut"],
                 label_scale(st.ds, st.ds0, kext), st.nlabels, st.recon, st.labels)
    keys = _light_keys(scene, lights[:nlights], geo, planes, kext, med)
    method = "fast" if sh.mode == "pathtrace" else sh.shadows.method
    return build(prep, keys, pos_index, geo[G_BOX:G_BOX + 3], geo[G_BOX + 3:G_BOX + 6], med, geo, planes,
                 len(scene.clipping.planes), st.ds0, kext,
                 sh.shadows.light_volume_scale, method)


def _settings(scene, prep, t, ds0, kext, albedo, u_iso, nlights, envmode, env_power) -> Settings:
    sh, smp = scene.shading, scene.sampling
    ph, shw = sh.phong, sh.shadows
    c = scene.isosurface.color
    nlab = len(t["llut"]) if scene.labels is not None and t["lab"].size > 1 else 0
    return Settings(
        ds=ds0 / smp.samples_per_voxel, ds0=ds0, early_termination=smp.early_termination, ambient=ph.ambient,
        diffuse=ph.diffuse, specular=ph.specular, shininess=ph.shininess, sample_offset=prep.u0,
        sample_scale=prep.ufac, value_min=prep.vmin, value_scale=prep.scale, iso_value=u_iso, iso_red=c[0],
        iso_green=c[1], iso_blue=c[2], pre_scale=(NPRE - 1) / (NLUT - 1), shadow_offset=shw.offset * ds0,
        shadow_step=shw.step * ds0, extinction_scale=kext, albedo=albedo, phase_g=sh.scattering.phase_g,
        nearest=smp.interpolation == "nearest", recon=RECON_TAGS[smp.interpolation](), jitter=bool(smp.jitter),
        lattice=smp.lattice, seed=int(smp.seed),
        skip=t["skip"], stride=ADAPTIVE_STRIDE if t["bcoarse"] is not _NO_COARSE else 1, cells=t["cells"].size > 1,
        block=int(smp.block_size), gradient_opacity=t["gradop"], sobel=sh.phong.gradient == "sobel",
        nlights=nlights, nplanes=len(scene.clipping.planes),
        bounces=sh.pathtrace.bounces, nlabels=nlab, labels=label_tag(nlab),
        solid_labels=bool(solid_rows(t["llut"]).any()),
        color=prep.is_color, env_mode=envmode, env_power=env_power,
        projection=PROJECTIONS.index(scene.mode) if scene.mode in PROJECTIONS else 0,
        hdr=scene.display.resolved(scene.shading.mode, scene.mode).tonemap != "linear")


def pack_frame(scene, camera, size: tuple[int, int], *, build_light_volumes=light_volumes) -> Frame:
    """Pack a frame; see ``volumen.render.render`` for the meaning of the settings.

    ``build_light_volumes`` has the signature of :func:`._lightvol.light_volumes` (the CUDA backend passes one
    that keeps the illumination volumes in device memory).
    """
    volume = scene.volume
    w, h = (int(s) for s in size)
    prep = prepare(volume)
    timings = dict(prep.timings)
    ds0 = float(min(volume.spacing))
    model, medium_model = _model(scene)
    kext, albedo = medium(scene.shading) if medium_model else (1.0, 1.0)
    u_iso = prep.to_u(scene.isosurface.value)
    t0 = time.perf_counter()
    t = _tables(scene, prep, (ds0 / scene.sampling.samples_per_voxel) / ds0, kext, model, medium_model, u_iso)
    t["geo"], t["planes"] = pack_geometry(volume, scene.clipping), pack_planes(scene.clipping)
    timings["tables"] = time.perf_counter() - t0
    lit = model != "unlit" and scene.shading.mode in LIGHTED  # the headlight keeps its own ambient term
    environment = scene.environment.resolved(bool(scene.lights)) if lit else _UNIFORM
    envmode, env = pack_environment(environment, camera)
    lights, nlights = _lights(scene, camera, model, environment)
    st = _settings(scene, prep, t, ds0, kext, albedo, u_iso, nlights, envmode, _env_power(lights, nlights, env))
    lvm, lvd, built = _light_volumes(scene, prep, t, st, lights, model, build_light_volumes)
    timings.update(prep.timings)
    arrays = Arrays(cam=pack_camera(camera, (w, h)), geo=t["geo"], planes=t["planes"], vol=prep.u,
                    gradient_matrix=t["nrm"], normal_codes=t["ncode"], normal_slots=t["nslot"],
                    gradient_codes=t["gcode"], normal_dirs=DIRS,
                    lut=t["lut"], preintegrated=t["pre"], gradient_lut=t["glut"], skip_flags=t["bflag"],
                    bmin=t["bmin"], bmax=t["bmax"], coarse_flags=t["bcoarse"], cells=t["cells"], lights=lights,
                    light_meta=lvm, light_data=lvd, extinction=t["sig"], label_map=t["lab"], label_lut=t["llut"],
                    rgb=prep.rgb, whole=t["geo"], carry=NO_CARRY, env=env[0], env_basis=env[1], env_cdf=env[2],
                    env_sh=env[3], majorant=NO_MAJ)
    mode = "preintegrated" if t["preint"] else "labelled" if st.nlabels > 0 else scene.mode
    at_eye = model == "phong" and scene.shading.mode == "headlight" and camera.projection == "perspective"
    return Frame(arrays, st, MODE_TAGS[mode](),
                 LIGHT_TAGS["headlight" if at_eye else model](), (w, h), prep, built, timings)
