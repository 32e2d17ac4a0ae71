"""Compile the CUDA kernels of ``volumen.render.cuda`` to PTX without a GPU (run as a script by test_cuda_ptx).

Prints ``PTX-OK <kernel> <bytes> <seconds>`` per kernel (``--only``: those named), or ``PTX-SKIP <reason>`` when
no CUDA compiler (numba-cuda with libNVVM) is available, and ``PATCHES on`` / ``off``: whether volumen's
inliner patches (``jit._inlining.install_cuda``) were in numba-cuda's compiler. Numba asks the
current device for its compute capability when it compiles a device
function; with no device, that question is answered with ``--cc`` here.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import time
import types as pytypes

import numpy as np


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cc", default="9.0", help="compute capability to compile for (H100: 9.0)")
    ap.add_argument("--out", help="folder to write <kernel>.ptx into")
    ap.add_argument("--only", nargs="*", help="compile only these kernels")
    opts = ap.parse_args()
    cc = tuple(int(x) for x in opts.cc.split("."))
    if importlib.util.find_spec("numba_cuda") is None:
        print("PTX-SKIP numba-cuda is not installed (pip install numba-cuda: the CUDA target these kernels need)")
        return 0
    import numba
    from numba import cuda

    try:
        from numba.cuda.cudadrv import nvvm

        nvvm.NVVM()
    except Exception as exc:  # noqa: BLE001 - no libNVVM: nothing to compile with
        print(f"PTX-SKIP libNVVM not found ({type(exc).__name__}: {str(exc).splitlines()[0][:200]})")
        return 0
    import numba.cuda.dispatcher as disp

    disp.get_current_device = lambda: pytypes.SimpleNamespace(compute_capability=cc)

    from volumen.core import Camera, Light, Sampling, Scene, Shading, TransferFunction
    from volumen.data import phantom
    from volumen.render.cuda import _kernels
    from volumen.render.raycast import LV_AXA, LV_AXB, LV_AXC, Medium, Outputs, PathTracer, Sweep, pack_frame

    vol = phantom("head", size=16)
    cam = Camera.orbit(vol)
    scene = Scene(volume=vol, transfer=TransferFunction.preset("ct-bone"), lights=(Light(position=(0, 300, 200)),),
                  shading=Shading(mode="shadows"))
    f = pack_frame(scene, cam, (8, 8))
    ty = numba.typeof
    sig = (ty(f.arrays), ty(f.settings), ty(Outputs.empty(8, 8)), ty(f.mode), ty(f.light))
    # and the other branches of the pieces: a projection (MIP) unshaded, on the B-spline reconstruction
    g2 = pack_frame(scene.with_(mode="mip", shading=Shading(mode="none"),
                                sampling=Sampling(interpolation="bspline")), cam, (8, 8))
    sig_mip = (ty(g2.arrays), ty(g2.settings), ty(Outputs.empty(8, 8)), ty(g2.mode), ty(g2.light))
    pt = PathTracer(scene, cam, (8, 8))
    g = pt.frame
    sig_paths = (numba.int64, numba.int64, ty(g.arrays), ty(g.settings), ty(pt.acc), ty(pt.coverage), ty(pt.features))
    a = f.arrays
    m = a.light_meta[0]
    axes = tuple(int(m[j]) for j in (LV_AXA, LV_AXB, LV_AXC))
    med = Medium(a.vol, a.extinction, 0.0, 1.0, a.label_map, a.label_lut, a.lut, 1.0, 0)
    sw = Sweep.of(med, lambda x: np.transpose(x, axes), np.zeros((3, 4)), a.geo, a.planes, m, 1, 1.0, 1.0)
    sig_sweep = (ty(sw), ty(np.zeros((2, 2, 2), np.float32)))
    from volumen.jit import _inlining

    print("PATCHES", "on" if _inlining._state["cuda"] else "off")
    failed = 0
    for name, kern, s in (("trace", _kernels.trace, sig), ("trace-mip-bspline", _kernels.trace, sig_mip),
                          ("paths", _kernels.paths, sig_paths),
                          ("sweep", _kernels.sweep, sig_sweep)):
        if opts.only and name not in opts.only:
            continue
        try:
            t0 = time.perf_counter()
            ptx, _ = cuda.compile_ptx(kern.py_func, s, cc=cc, fastmath=True)
            print(f"PTX-OK {name} {len(ptx)} {time.perf_counter() - t0:.1f}", flush=True)
            if opts.out:
                with open(f"{opts.out}/{name}.ptx", "w") as fh:
                    fh.write(ptx)
        except Exception as exc:  # noqa: BLE001 - report every kernel
            failed += 1
            print(f"PTX-FAIL {name} {type(exc).__name__}: {exc}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
