"""Every ``volumen ...`` command of the README's shell examples runs, against the phantoms and
the shared data, so an example can never go stale.

The commands run one after the other in one folder (a later one may read what an earlier one wrote), through
``volumen.cli.main``, with their sizes made small so the whole README runs in about a minute: phantoms at a
coarse grid (not for ``fly``, whose lumens need the full one), pictures and videos a few pixels and frames,
the benchmark ``--quick``, the warm-up its common kernels in one child. Placeholders the README uses for the
reader's own data are made here:

* ``scan/``: a DICOM series (pydicom) of the torso phantom, series UID ``1.2.840.99.1`` (for ``1.2.840...``);
* ``head.nii.gz``: the head phantom as NIfTI (nibabel);
* ``segmentations/``: a TotalSegmentator-style folder, ``aorta.nii.gz`` = the torso phantom's aorta;
* ``manifest.csv``: a batch of one study (``head.nii.gz``), one
  small picture each, drawn on one worker;
* ``../shared/data/``: the shared data folder (those commands skip, saying so, where it is missing);
* ``archive``: the test Orthanc (``tests/pacs``) holding ``scan/`` as study ``1.2.840.99``, named in a
  ``servers.toml`` under a temporary ``XDG_CONFIG_HOME`` with an empty cache (the ``pacs`` and
  ``dicomweb://`` commands skip, saying so, where Orthanc is not installed).
* ``cert.pem`` / ``key.pem``: a self-signed certificate made with ``openssl`` (the https line skips without it).
* ``session.json``: a session of ``scan/`` with a ruler and an ellipse on it (``volumen.measure``).

The commands run with the README's own venv where ``make readme-venv`` (``make test`` does) made it with make demo's
recipe: every user extra and none of the test tools, as a new user has them; else in this process, saying so.
``volumen serve`` answers one request for ``info.json`` with its token (over https where it serves https) and
stops instead of serving until Ctrl-C, and opens no browser; its ``--screenshot`` lines run headless Chromium
in a small window (they skip, saying so, without Chromium, or without the iwer emulator for ``--vr``).

Each command must exit with 0 and write its outputs.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
#: the README's own venv (``make readme-venv``: make demo's recipe); without it the commands run in this process
VENV_PYTHON = ROOT / ".venv-readme" / "bin" / "python"
SERIES = "1.2.840.99.1"
STUDY = "1.2.840.99"
SMALL = {"render": {"--size": "32x32", "--pt-samples": "2"}, "fly": {"--size": "24x24"},
         "serve": {"--window": "320x200"}}
#: README pictures that an example draws: its output -> (the picture in docs/, the rows of that picture showing it, the
#: rows of the output they show as fractions of its height); the example is drawn PICTURE_WIDTH pixels wide at its
#: own aspect and compared with the picture scaled to the same size
PICTURES = {"aorta-cinematic.png": ("docs/aorta-cinematic.png", (124, 244), (110 / 360, 230 / 360))}
PICTURE_WIDTH, PICTURE_SAMPLES = 64, "4"
#: mean |RGB difference| / 255 allowed between an example's output and its picture (the aorta: 0.006 measured;
#: 0.25 without the --shift its scanner units need)
PICTURE_BAR = 0.02
EXTRA = {"fly": ["--frames", "3", "--no-progress"], "bench": ["--quick", "--no-vtk", "--repeat", "1"],
         "demo": ["--size", "24"], "batch": ["--workers", "1", "--no-progress"],
         "warm": ["--common", "--workers", "1"]}


#: the documents whose ``sh`` blocks are run: the README and the benchmarks it links to
DOCUMENTS = ("README.md", "docs/benchmarks.md")


def readme_commands() -> list[str]:
    """The ``volumen`` lines of the ``sh`` blocks of :data:`DOCUMENTS`, continuation lines joined."""
    text = "".join((ROOT / doc).read_text(encoding="utf-8") for doc in DOCUMENTS)
    blocks = re.findall(r"```sh\n(.*?)```", text, flags=re.S)
    lines = "\n".join(blocks).replace("\\\n", " ").splitlines()
    return [ln.strip() for ln in lines if ln.strip().startswith("volumen ")]


def _pictured(argv: list[str]) -> str | None:
    """The output name of a README line that draws one of :data:`PICTURES`, else None."""
    outs = [Path(o).name for o in _outputs(argv)]
    return next((o for o in outs if o in PICTURES), None)


def _at_picture_size(argv: list[str]) -> list[str]:
    """A pictured line drawn :data:`PICTURE_WIDTH` pixels wide at its own aspect, with few samples."""
    i = argv.index("--size")
    w, h = (int(v) for v in argv[i + 1].split("x"))
    argv = argv[:i + 1] + [f"{PICTURE_WIDTH}x{round(PICTURE_WIDTH * h / w)}"] + argv[i + 2:]
    return argv + (["--pt-samples", PICTURE_SAMPLES] if "pathtrace" in argv and "--pt-samples" not in argv else [])


def _picture_difference(out: Path, name: str) -> float:
    """Mean |RGB difference| / 255 between the output ``out`` and its README picture, at the output's size."""
    from PIL import Image

    ref, (r0, r1), (f0, f1) = PICTURES[name]
    pic = np.asarray(Image.open(out).convert("RGB"), float)
    rows = slice(round(f0 * pic.shape[0]), round(f0 * pic.shape[0]) + round((f1 - f0) * pic.shape[0]))
    pic = pic[rows]
    shown = Image.open(ROOT / ref).convert("RGB").crop((0, r0, Image.open(ROOT / ref).width, r1))
    shown = np.asarray(shown.resize((pic.shape[1], pic.shape[0]), Image.Resampling.BOX), float)
    return float(np.abs(pic - shown).mean() / 255)


def _shrink(argv: list[str]) -> list[str]:
    if _pictured(argv):
        return _at_picture_size(argv)
    cmd = argv[0]
    out = []
    it = iter(argv)
    for tok in it:
        if tok in SMALL.get(cmd, {}):
            out += [tok, SMALL[cmd][tok]]
            next(it)
        elif tok.startswith("phantom:") and cmd != "fly":
            out.append(f"{tok}?size=48")
        else:
            out.append(tok)
    if cmd == "render" and "--size" not in out:
        out += ["--size", "32x32"]
    if cmd == "fly" and "--size" not in out:
        out += ["--size", "24x24"]
    if cmd == "serve":
        out += [] if "--window" in out or "--screenshot" not in out else ["--window", "320x200"]
        out += ["--port", "0"]
    return out + EXTRA.get(cmd, [])


def _scan(folder: Path) -> None:
    from tests.io.dicom_factory import stack_positions, write_series
    from volumen.data import phantom

    vol = phantom("torso", size=48)
    raw = np.clip(np.asarray(vol.data), -1024, 3000).astype(np.int16)
    dz, dy, dx = vol.spacing
    write_series(folder, raw, row_dir=(1, 0, 0), col_dir=(0, 1, 0), pixel_spacing=(dy, dx), series_uid=SERIES,
                 positions=stack_positions((0.0, 0.0, 0.0), (1, 0, 0), (0, 1, 0), np.arange(len(raw)) * dz),
                 slice_thickness=dz, patient={"PatientName": "Doe^Jane", "PatientID": "README-1",
                                              "StudyInstanceUID": STUDY, "StudyDate": "20240315"})


def _nifti(path: Path, data, affine) -> None:
    import nibabel as nib

    nib.save(nib.Nifti1Image(np.ascontiguousarray(np.asarray(data).transpose(2, 1, 0)), affine), str(path))


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    from volumen.data import phantom

    d = tmp_path_factory.mktemp("readme")
    _scan(d / "scan")
    head = phantom("head", size=48)
    _nifti(d / "head.nii.gz", head.data, head.affine)
    torso = phantom("torso")
    (d / "segmentations").mkdir()
    _nifti(d / "segmentations" / "aorta.nii.gz", torso.meta["truth"]["aorta"].mask.astype(np.uint8), torso.affine)
    _manifest(d / "manifest.csv")
    _certificate(d)
    _session(d)
    return d


def _session(folder: Path) -> None:
    """``session.json``: ``scan/`` (as a relative path, as the commands run in ``folder``) with a ruler and a region."""
    import json

    import volumen
    from volumen import measure

    scan = volumen.load(folder / "scan")
    c = scan.center
    items = measure.Measurements([measure.distance(c - 10, c + 10, volume=scan),
                                  measure.roi_stats(scan, measure.slice_plane(scan, "axial", scan.shape[0] // 2),
                                                    measure.Ellipse((80.0, 60.0), (30.0, 20.0)))])
    d = {"version": 1, "scene": {"volume": "scan"}, measure.SESSION_KEY: items.to_dicts()}
    (folder / "session.json").write_text(json.dumps(d))


def _certificate(folder: Path) -> None:
    """A self-signed certificate for 127.0.0.1 (``cert.pem``, ``key.pem``), where ``openssl`` is installed."""
    import shutil
    import subprocess

    if shutil.which("openssl"):
        subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj",
                        "/CN=volumen", "-addext", "subjectAltName=IP:127.0.0.1", "-keyout", str(folder / "key.pem"),
                        "-out", str(folder / "cert.pem")], check=True, capture_output=True)


def _info_answered(scheme: str, port: int, token: str) -> bool:
    """Whether the viewer server on ``port`` answers a request for info.json with ``token`` with the volume."""
    import json
    import ssl
    import urllib.request

    ctx = ssl._create_unverified_context() if scheme == "https" else None  # the test's self-signed certificate
    req = urllib.request.Request(f"{scheme}://127.0.0.1:{port}/info.json", headers={"X-Volumen-Token": token})
    with urllib.request.urlopen(req, timeout=120, context=ctx) as r:
        return r.status == 200 and "volume" in json.loads(r.read())


def _serve_once(server) -> None:
    """Instead of serving until Ctrl-C: start, answer one request for info.json with the token, stop."""
    server.start()
    try:
        assert _info_answered("https" if server.ssl_context else "http", server.port, server.token)
    finally:
        server.stop()


def _skip_reason(argv: list[str], workdir: Path) -> str | None:
    """Why a ``volumen serve`` line cannot run here (no certificate, Chromium or iwer), or None."""
    if argv[0] != "serve":
        return None
    if "--certfile" in argv and not (workdir / "cert.pem").exists():
        return "openssl is not installed: no certificate for the https example"
    if "--screenshot" in argv:
        from volumen.web import BrowserUnavailable, find_chromium
        from volumen.web._bench import iwer_script

        try:
            find_chromium()
        except BrowserUnavailable as exc:
            return str(exc)
        if "--vr" in argv and iwer_script() is None:
            return "the WebXR emulator iwer is not installed (`make web-deps`)"
    return None


def _manifest(path: Path) -> None:
    import csv

    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "path", "settings", "outputs"])
        w.writerow(["head", "head.nii.gz", '{"size": [24, 24]}', "png"])


def _outputs(argv: list[str]) -> list[str]:
    outs = [argv[i + 1] for i, t in enumerate(argv[:-1]) if t in ("-o", "--out", "--save-settings", "--save-path")]
    if argv[0] == "convert":
        outs.append(argv[2])
    return outs


@pytest.fixture(scope="module")
def readme_archive(request, workdir, tmp_path_factory):
    """(config home, archive) with ``scan/`` uploaded, or the reason Orthanc cannot run here."""
    from tests.pacs.orthanc_server import missing_reason

    reason = missing_reason()
    if reason:
        return reason
    from tests.pacs.archive_data import write_servers_toml

    archive = request.getfixturevalue("archive")
    files = sorted((workdir / "scan").iterdir())
    assert archive.server.upload(files) == len(files)
    home = tmp_path_factory.mktemp("readme-config")
    write_servers_toml(home, archive.server)
    return home, archive


def _uses_archive(argv: list[str]) -> bool:
    return argv[0] == "pacs" or any(a.startswith(("dicomweb://", "dimse://")) for a in argv)


def _serve_in(argv: list[str], workdir: Path, env: dict) -> tuple[int, str]:
    """``volumen serve`` in the README's venv: started, asked for info.json with the token from the address it
    prints, stopped."""
    import subprocess
    import urllib.parse

    argv = argv if "--no-browser" in argv else [*argv, "--no-browser"]
    proc = subprocess.Popen([str(VENV_PYTHON), "-m", "volumen", *argv], cwd=workdir, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    ok, why = False, "no answer"
    try:
        url = urllib.parse.urlsplit(proc.stdout.readline().strip())
        ok = _info_answered(url.scheme, url.port, urllib.parse.parse_qs(url.query).get("token", [""])[0])
    except (OSError, ValueError) as exc:
        ok, why = False, f"{type(exc).__name__}: {exc}"
    finally:
        proc.terminate()
        err = proc.communicate(timeout=60)[1]
    return (0, err) if ok else (1, f"{why}; {err}")


def _run_in_readme_venv(argv: list[str], workdir: Path) -> tuple[int, str]:
    """``(exit code, stderr)`` of ``volumen ARGV`` run by the README's venv (``make readme-venv``: make demo's
    recipe), the kernels from the suite's kernel folder."""
    import os
    import subprocess

    from volumen.jit import kernel_folder

    env = dict(os.environ, VOLUMEN_KERNEL_DIR=str(kernel_folder()))
    env.pop("PYTHONPATH", None)
    if argv[0] == "serve" and "--screenshot" not in argv:
        return _serve_in(argv, workdir, env)
    done = subprocess.run([str(VENV_PYTHON), "-m", "volumen", *argv], cwd=workdir, env=env, capture_output=True,
                          text=True, timeout=1200)
    return done.returncode, done.stderr


def _run(line: str, workdir: Path, capsys, archive=None) -> str | None:
    """Run one README line; None when it worked, else what went wrong."""
    from volumen.cli import main
    from volumen.data import shared_data

    argv = shlex.split(line, comments=True)[1:]
    if _uses_archive(argv) and isinstance(archive, str):
        print(f"skipped ({archive}): {line}")
        return None
    argv = [a.replace("1.2.840...", SERIES) for a in argv]
    if any("../shared/data" in a for a in argv):
        shared = shared_data()
        if shared is None:
            print(f"skipped (the shared data folder ../shared/data is missing): {line}")
            return None
        argv = [a.replace("../shared/data", str(shared)) for a in argv]
    argv = _shrink(argv)
    reason = _skip_reason(argv, workdir)
    if reason:
        print(f"skipped ({reason}): {line}")
        return None
    if VENV_PYTHON.exists():
        code, err = _run_in_readme_venv(argv, workdir)
    else:
        code, err = main(argv), capsys.readouterr().err
    if code != 0:
        return f"{line}\n -> exit {code}: {err}"
    for out in _outputs(argv):
        p = workdir / out
        if not (p.exists() and (p.is_dir() or p.stat().st_size > 0)):
            return f"{line}: {out} not written"
    name = _pictured(argv)
    if name:
        diff = _picture_difference(workdir / _outputs(argv)[0], name)
        print(f"{name}: mean |RGB diff| {diff:.4f} from {PICTURES[name][0]}")
        if diff > PICTURE_BAR:
            return f"{line}: differs from {PICTURES[name][0]} by {diff:.4f} (bar {PICTURE_BAR})"
    return None


def test_readme_commands_run_in_order(workdir, readme_archive, monkeypatch, capsys):
    """All of them in one test, in the README's order, in one folder: a later command reads what an earlier
    one wrote (settings, saved flights), so they cannot be spread over test workers."""
    import webbrowser

    from volumen.web import ViewerServer

    monkeypatch.chdir(workdir)
    monkeypatch.setattr(ViewerServer, "run", _serve_once)
    monkeypatch.setattr(webbrowser, "open", lambda url: True)
    if not isinstance(readme_archive, str):
        from tests.pacs.archive_data import PASSWORD_ENV
        from tests.pacs.orthanc_server import PASSWORD

        monkeypatch.delenv("VOLUMEN_CONFIG_DIR", raising=False)
        monkeypatch.setenv("XDG_CONFIG_HOME", str(readme_archive[0]))
        monkeypatch.setenv("VOLUMEN_CACHE_DIR", str(workdir / "cache"))
        monkeypatch.setenv(PASSWORD_ENV, PASSWORD)
    lines = readme_commands()
    assert len(lines) >= 15
    print(f"the README's commands run with {VENV_PYTHON} (make demo's extras)" if VENV_PYTHON.exists() else
          f"{VENV_PYTHON} is missing (`make readme-venv` makes it): the README's commands run in the test venv")
    failures = [f for f in (_run(line, workdir, capsys, readme_archive) for line in lines) if f]
    assert not failures, "\n".join(failures)
