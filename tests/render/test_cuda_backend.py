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


def _ptx_key(*args: str, patches: bool) -> str:
    """What a PTX compile's outcome depends on: the contents of every source the CUDA kernels are built from
    (``volumen/render``, ``volumen/jit``, ``volumen/core``) and of the check script, the compiling packages'
    releases (Numba, numba-cuda, llvmlite, NVIDIA's libNVVM and NVRTC wheels), the arguments and the patches."""
    import hashlib
    from importlib import metadata

    import volumen

    h = hashlib.sha256(repr((args, patches, sys.version)).encode())
    package = Path(volumen.__file__).resolve().parent
    for f in sorted(p for d in ("render", "jit", "core") for p in (package / d).rglob("*.py")):
        h.update(f.relative_to(package).as_posix().encode() + hashlib.sha256(f.read_bytes()).digest())
    h.update((HERE / "cuda_ptx_check.py").read_bytes())
    for dist in sorted(metadata.distributions(), key=lambda d: d.metadata["Name"] or ""):
        name = (dist.metadata["Name"] or "").lower()
        if any(k in name for k in ("numba", "llvmlite", "nvidia", "cuda")):
            h.update(f"{name}=={dist.version}".encode())
    return h.hexdigest()[:24]


def _ptx_check(out: Path, *args: str, patches: bool = True) -> subprocess.CompletedProcess:
    """``cuda_ptx_check.py`` in a fresh process, writing the PTX into ``out``; without volumen's patches to Numba's
    compilers (``VOLUMEN_NUMBA_PATCHES=0``) where ``patches`` is false.

    A compile that succeeded is kept (its output and PTX files) in the kernel folder under :func:`_ptx_key`, as
    Numba keeps the CPU kernels: the same sources with the same compilers give the same PTX, so a later run of
    the same code reads them back instead of compiling for a minute; any changed source or release compiles."""
    import json
    import shutil

    from volumen.jit import kernel_folder

    kept = kernel_folder() / "ptx-checks" / _ptx_key(*args, patches=patches)
    if (kept / "result.json").is_file():
        shutil.copytree(kept, out)
        r = json.loads((kept / "result.json").read_text())
        return subprocess.CompletedProcess(r["args"], 0, r["stdout"] + "(kept from an earlier compile of the same "
                                           "sources)\n", r["stderr"])
    env = dict(os.environ)
    env.pop("NUMBA_ENABLE_CUDASIM", None)
    env["VOLUMEN_NUMBA_PATCHES"] = "1" if patches else "0"
    out.mkdir()
    r = subprocess.run([sys.executable, str(HERE / "cuda_ptx_check.py"), "--cc", "9.0", "--out", str(out), *args],
                       env=env, capture_output=True, text=True, timeout=900)
    if r.returncode == 0 and "PTX-SKIP" not in r.stdout:
        part = kept.with_name(f"{kept.name}.{os.getpid()}")
        shutil.copytree(out, part, dirs_exist_ok=True)
        (part / "result.json").write_text(json.dumps({"args": r.args, "stdout": r.stdout, "stderr": r.stderr}))
        try:
            part.rename(kept)  # whole or not at all
        except OSError:
            shutil.rmtree(part, ignore_errors=True)  # another process kept it first
    return r


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
