"""Turn (Scene, Camera, size) into the arrays and scalars the kernels read: one place for every backend.

:func:`pack_frame` validates the combination of settings, takes the
per-volume precomputations from the cache (``_cache``), builds the transfer
function tables, packs camera, geometry, lights and parameters, and builds
(or takes from the cache) the illumination volumes of the lights.
"""

from __future__ import annotations

import time

import numpy as np

from ._cache import prepare
from ._geometry import G_BOX, pack_camera, pack_geometry, pack_planes
from ._lightvol import light_volumes
from ._params import (
    I_BLOCK,
    I_BOUNCES,
    I_GRADOP,
    I_JITTER,
    I_MODE,
    I_MODEL,
    I_NEAREST,
    I_NLIGHTS,
    I_NPLANES,
    I_PREINT,
    I_SEED,
    I_SHADED,
    I_SKIP,
    MODEL_CODES,
    N_IPRM,
    N_PRM,
    P_ALBEDO,
    P_DS,
    P_DS0,
    P_ET,
    P_G,
    P_ISO,
    P_ISO_R,
    P_KA,
    P_KD,
    P_KEXT,
    P_KS,
    P_PRE_SCALE,
    P_SH_OFF,
    P_SH_STEP,
    P_SHINE,
    P_VMIN,
    P_VSCALE,
)
from ._precompute import NLUT
from ._scatter import medium
from ._shade import headlight, pack_lights
from ._tables import (
    NPRE,
    block_visibility,
    color_table,
    extinction_table,
    gradient_table,
    iso_extinction_table,
    iso_visibility,
    preintegrated_table,
    skip_distance,
)
from ._trace import MODE_CODES

__all__ = ["Frame", "pack_frame", "LIT_SHADINGS"]

#: shading modes that use the scene's lights and need the medium's light paths
LIT_SHADINGS = ("shadows", "scattering", "pathtrace")


class Frame:
    """The packed arrays of one frame (attributes named as the kernels' arguments) and timings."""

    def args(self) -> tuple:
        """The arguments of ``trace_pixel`` after the pixel coordinates, before the outputs."""
        return (self.cam, self.geo, self.planes, self.vol, self.nrm, self.lut, self.pre, self.glut, self.bflag,
                self.bmin, self.bmax, self.lights, self.lvm, self.lvd, self.sig, self.prm, self.iprm)


def _light_keys(scene, lights, geo, planes, kext):
    tf = scene.transfer.to_json() if scene.mode != "isosurface" else f"iso:{scene.isosurface.value!r}"
    clip = geo.tobytes() + planes.tobytes()
    scale = scene.shading.light_volume_scale
    return [(np.round(lights[i, :3], 9).tobytes(), tf, clip, scale, kext) for i in range(len(lights))]


def pack_frame(scene, camera, size: tuple[int, int], *, build_light_volumes=light_volumes) -> Frame:
    """Pack a frame; see ``volumen.render.render`` for the meaning of the settings.

    ``build_light_volumes`` has the signature of :func:`._lightvol.light_volumes` (the CUDA backend passes one
    that keeps the illumination volumes in device memory).
    """
    volume = scene.volume
    w, h = (int(s) for s in size)
    sh = scene.shading
    mode = scene.mode
    prep = prepare(volume)
    f = Frame()
    f.prep = prep
    timings = dict(prep.timings)
    smp = scene.sampling
    tf = scene.transfer
    ds0 = float(min(volume.spacing))
    ds = ds0 / smp.samples_per_voxel
    ratio = ds / ds0
    model = MODEL_CODES[sh.mode]
    medium_model = sh.mode in ("scattering", "pathtrace") and mode == "composite"
    if sh.mode in ("scattering", "pathtrace") and not medium_model:
        model = MODEL_CODES["shadows"]  # a surface has no medium: lit as with shadows
    kext, albedo = medium(sh) if medium_model else (1.0, 1.0)

    t = time.perf_counter()
    preint = smp.preintegrate and mode == "composite"
    lut = color_table(tf, prep.vmin, prep.vmax, ratio * kext if (mode == "composite" and not preint) else None)
    pre = preintegrated_table(tf, prep.vmin, prep.vmax, ratio * kext) if preint else np.zeros((1, 1, 4), np.float32)
    shaded = sh.mode != "none" and mode in ("composite", "isosurface")
    gradop = tf.gradient_opacity is not None and mode == "composite"
    if (shaded and not medium_model) or gradop:
        nrm, gmax = prep.normals(sh.gradient == "sobel")
    else:
        nrm, gmax = np.zeros((1, 1, 1, 4), np.int16), 0.0
    glut = gradient_table(tf, gmax) if gradop else np.ones(128, np.float32)
    u_iso = prep.to_u(scene.isosurface.value)
    skip = smp.skip_empty and mode != "average"
    if skip:
        bmin, bmax = prep.blocks(smp.block_size)
        if mode == "composite":
            bflag = skip_distance(block_visibility(lut[:, 3], bmin, bmax))
        elif mode == "isosurface":
            bflag = skip_distance(iso_visibility(u_iso, bmin, bmax))
        else:  # mip / minip decide per ray from bmin / bmax
            bflag = np.zeros(bmin.shape, np.uint8)
    else:
        bmin = bmax = np.zeros((1, 1, 1), np.float32)
        bflag = np.zeros((1, 1, 1), np.uint8)
    if sh.mode not in LIT_SHADINGS:
        sig = np.zeros(1, np.float32)
    elif mode == "isosurface":  # the drawn surface casts the shadows
        sig = iso_extinction_table(u_iso)
    else:
        sig = extinction_table(tf, prep.vmin, prep.vmax)
    timings["tables"] = time.perf_counter() - t

    if not shaded:
        lights, nlights = np.zeros((1, 11), np.float64), 0
    elif sh.mode == "headlight":
        lights, nlights = headlight(camera), 1
    else:
        lights, nlights = pack_lights(scene.lights, camera), len(scene.lights)
    geo = pack_geometry(volume, scene.clipping)
    planes = pack_planes(scene.clipping)
    nplanes = len(scene.clipping.planes)
    f.light_volumes_built = 0
    path_traced = sh.mode == "pathtrace" and mode == "composite"  # ratio tracking, no light volumes
    if shaded and model != MODEL_CODES["phong"] and not path_traced and nlights:
        inv = np.linalg.inv(np.asarray(volume.affine, float))
        pos_index = (np.c_[lights[:nlights, :3], np.ones(nlights)] @ inv.T)[:, :3]
        keys = _light_keys(scene, lights[:nlights], geo, planes, kext)
        method = "fast" if sh.mode == "pathtrace" else sh.shadow_method
        lvm, lvd, built = build_light_volumes(prep, keys, pos_index, geo[G_BOX:G_BOX + 3], geo[G_BOX + 3:G_BOX + 6], sig,
                                        geo, planes, nplanes, ds0, kext, sh.light_volume_scale, method)
        f.light_volumes_built = built
    else:
        from ._lightvol import NMETA

        lvm, lvd = np.zeros((1, NMETA)), np.ones(1, np.float32)
    timings.update(prep.timings)

    prm = np.zeros(N_PRM, np.float64)
    prm[P_DS], prm[P_ET] = ds, smp.early_termination
    prm[P_KA], prm[P_KD], prm[P_KS], prm[P_SHINE] = sh.ambient, sh.diffuse, sh.specular, sh.shininess
    prm[P_VMIN], prm[P_VSCALE] = prep.vmin, prep.scale
    prm[P_ISO] = u_iso
    prm[P_ISO_R:P_ISO_R + 3] = scene.isosurface.color
    prm[P_PRE_SCALE] = (NPRE - 1) / (NLUT - 1)
    prm[P_DS0], prm[P_SH_OFF], prm[P_SH_STEP] = ds0, sh.shadow_offset * ds0, sh.shadow_step * ds0
    prm[P_KEXT], prm[P_ALBEDO], prm[P_G] = kext, albedo, sh.phase_g
    iprm = np.zeros(N_IPRM, np.int64)
    iprm[I_MODE], iprm[I_NEAREST] = MODE_CODES[mode], int(smp.interpolation == "nearest")
    iprm[I_JITTER], iprm[I_SEED] = int(smp.jitter), smp.seed
    iprm[I_SKIP], iprm[I_BLOCK], iprm[I_PREINT] = int(skip), smp.block_size, int(preint)
    iprm[I_NLIGHTS], iprm[I_GRADOP] = nlights, int(gradop)
    iprm[I_NPLANES] = nplanes
    iprm[I_SHADED] = int(shaded)
    iprm[I_MODEL] = model
    iprm[I_BOUNCES] = sh.pt_bounces

    f.cam, f.geo, f.planes, f.vol, f.nrm = pack_camera(camera, (w, h)), geo, planes, prep.u, nrm
    f.lut, f.pre, f.glut, f.bflag, f.bmin, f.bmax = lut, pre, glut, bflag, bmin, bmax
    f.lights, f.lvm, f.lvd, f.sig, f.prm, f.iprm = lights, lvm, lvd, sig, prm, iprm
    f.timings, f.ds, f.ds0, f.size = timings, ds, ds0, (w, h)
    return f
