"""The ``cuda`` device where there is no GPU: a clear error, ``auto`` falls back to the CPU, the benchmarks
fail fast; and the CUDA kernels compile to PTX for an H100 where a CUDA compiler is installed."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.render import cuda_scenes
from volumen.render import render

HERE = Path(__file__).parent

try:
    from volumen.render.cuda import cuda_available

    HAVE_GPU = cuda_available()
except Exception:  # noqa: BLE001 - numba without CUDA support counts as no GPU
    HAVE_GPU = False

no_gpu = pytest.mark.skipif(HAVE_GPU, reason="a CUDA device is present: the no-device behaviour cannot be seen")


@no_gpu
def test_cuda_device_without_a_gpu_says_so():
    from volumen.render.cuda import CudaUnavailableError

    scene, cam, size = cuda_scenes.scenes()["composite-phong"]
    with pytest.raises(CudaUnavailableError, match="no CUDA device is available"):
        render(scene, cam, size, device="cuda")


@no_gpu
def test_auto_device_falls_back_to_the_cpu():
    from volumen.render import resolve_device

    scene, cam, size = cuda_scenes.scenes()["composite-phong"]
    assert resolve_device("auto") == "cpu"
    auto = render(scene, cam, size, device="auto")
    cpu = render(scene, cam, size, device="cpu")
    assert auto.stats["backend"] == "cpu" and auto.stats["renderer"] == {"device": "cpu", "technique": "raycast"}
    np.testing.assert_array_equal(auto.rgba, cpu.rgba)


@no_gpu
@pytest.mark.parametrize("what", ["render", "lighting"])
def test_bench_on_the_cuda_device_fails_fast(what, tmp_path):
    r = subprocess.run([sys.executable, "-m", "volumen", "bench", what, "--device", "cuda", "--quick",
                        "--out", str(tmp_path)], capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, (r.stdout, r.stderr)
    assert "no CUDA device is available" in r.stderr, r.stderr
    assert not list(tmp_path.iterdir())  # no table written


def _ptx_check(out: Path, *args: str, patches: bool = True) -> subprocess.CompletedProcess:
    """``cuda_ptx_check.py`` in a fresh process, writing the PTX into ``out``; without volumen's patches to Numba's
    compilers (``VOLUMEN_NUMBA_PATCHES=0``) where ``patches`` is false."""
    env = dict(os.environ)
    env.pop("NUMBA_ENABLE_CUDASIM", None)
    env["VOLUMEN_NUMBA_PATCHES"] = "1" if patches else "0"
    out.mkdir()
    return subprocess.run([sys.executable, str(HERE / "cuda_ptx_check.py"), "--cc", "9.0", "--out", str(out), *args],
                          env=env, capture_output=True, text=True, timeout=900)


def _same_code(path: Path) -> list[str]:
    """A PTX file's lines with what differs between two compiles of the same code taken out: the unique version
    numbers in the mangled names (``B5v1417B``), the unused environment globals, and the constant arrays' numbered
    names (each named by its contents instead; their declarations compared as a set)."""
    text = re.sub(r"B\d+v\d+B", "BvB", path.read_text())
    consts = dict(re.findall(r"^\.const .*? (_cudapy_cmem(?:\$\d+)?)\[\d+\] = (\{.*?\});", text, flags=re.M))
    order = sorted(set(consts.values()))
    named = {name: f"cmem{order.index(v)}" for name, v in consts.items()}
    text = re.sub(r"_cudapy_cmem(?:\$\d+)?", lambda m: named.get(m.group(0), m.group(0)), text)
    lines = [ln for ln in text.splitlines() if "NumbaEnv" not in ln]
    return [ln for ln in lines if not ln.startswith(".const")] + sorted(ln for ln in lines if ln.startswith(".const"))


def test_kernels_compile_to_ptx_for_h100(tmp_path):
    """Compiles the three kernels (and every shared function they call) for compute capability 9.0: the ray
    caster's for composite with shadows (trilinear) and for an unshaded MIP on the B-spline.

    Needs numba-cuda, libNVVM and NVRTC (the ``test`` extra installs them; no driver or GPU); skipped, saying why,
    without them. Before ``raycast.for_cuda``, numba-cuda 0.30 failed every kernel here (the pieces' inlined
    overloads lost their arguments), and so did the H100: the same kernels then drew the CPU's pixels bit for bit.

    They compile with volumen's inliner patches in numba-cuda's copy of the compiler (``_inlining.install_cuda``):
    the MIP kernel, compiled again without them, gives the same PTX up to the compiler's numbering of names.
    """
    r = _ptx_check(tmp_path / "patched")
    print(r.stdout)
    skip = [ln for ln in r.stdout.splitlines() if ln.startswith("PTX-SKIP")]
    if skip and os.environ.get("VOLUMEN_REQUIRE_PTX") == "1":  # make test: its install brings the compiler
        pytest.fail(f"the test extra installs numba-cuda with libNVVM, yet: {skip[0]}")
    if skip:
        pytest.skip(skip[0][len("PTX-SKIP "):])
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert sum(ln.startswith("PTX-OK") for ln in r.stdout.splitlines()) == 4, r.stdout
    assert "PATCHES on" in r.stdout.splitlines(), r.stdout
    plain = _ptx_check(tmp_path / "plain", "--only", "trace-mip-bspline", patches=False)
    print(plain.stdout)
    assert plain.returncode == 0 and "PATCHES off" in plain.stdout.splitlines(), plain.stdout + plain.stderr[-3000:]
    name = "trace-mip-bspline.ptx"
    assert _same_code(tmp_path / "patched" / name) == _same_code(tmp_path / "plain" / name)
