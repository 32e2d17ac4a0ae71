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

Each command must exit with 0 and write its outputs. Then each picture the README shows is made again from the
outputs of the lines that write it (``docs/pictures.py``, which ``make pictures`` runs at full size; those lines
run here small: :data:`PICTURE_SMALL`) and compared with the README's picture scaled down to its size:
:func:`picture_difference`, within :data:`PICTURE_MEAN_BAR` and :data:`PICTURE_P95_BAR` (a picture whose lines
skipped here is said not to be compared).
"""

from __future__ import annotations

import shlex
from pathlib import Path

import numpy as np
import pytest

from docs.pictures import PICTURES, STEPS, Panel, assemble, outputs, readme_commands

ROOT = Path(__file__).resolve().parents[1]

#: the README's own venv (``make readme-venv``: make demo's recipe); without it the commands run in this process
VENV_PYTHON = ROOT / ".venv-readme" / "bin" / "python"
SERIES = "1.2.840.99.1"
STUDY = "1.2.840.99"
SMALL = {"render": {"--size": "32x32", "--pt-samples": "2"}, "fly": {"--size": "24x24"},
         "serve": {"--size": "320x200"}}
#: the lines that write a README picture's panels (``docs/pictures.py``) run at their own aspect this many pixels
#: wide (render, fly) or square (demo), path tracing with PICTURE_SAMPLES samples; slices, cpr (its figure's layout
#: follows its height), the application's and the page's screenshots at the README's size
PICTURE_SMALL = {"render": 64, "fly": 48, "demo": 64}
PICTURE_SAMPLES = "4"
#: the picture assembled from those outputs against the README's scaled to its size: the mean over its pixels of
#: |RGB difference| / 255 (averaged over the channels), and its 95th percentile. Measured: 0.0000 (slices, cpr,
#: the screenshots: drawn at the README's size) to 0.0118 (the gallery, drawn 64 pixels square; its 95th percentile
#: 0.064, the others' 0.029 at most); a panel drawn with the defaults of before (the CPR's) differed by 0.24 and 0.81
PICTURE_MEAN_BAR, PICTURE_P95_BAR = 0.03, 0.15
EXTRA = {"fly": ["--frames", "3", "--no-progress"], "bench": ["--quick", "--no-vtk", "--repeat", "1"],
         "demo": ["--size", "24"], "batch": ["--workers", "1", "--no-progress"],
         "warm": ["--common", "--workers", "1"]}


def _panels(argv: list[str]) -> list[Panel]:
    """The panels of README pictures (``docs/pictures.py``) that the line ``argv`` writes."""
    outs = set(outputs(argv))
    return [p for panels in PICTURES.values() for p in panels if p.out in outs]


def _set(argv: list[str], flag: str, value: str) -> list[str]:
    if flag in argv:
        i = argv.index(flag)
        return argv[:i + 1] + [value] + argv[i + 2:]
    return [*argv, flag, value]


def _at_picture_size(argv: list[str]) -> list[str]:
    """A line that writes a README picture's panel, drawn small at its own aspect (:data:`PICTURE_SMALL`), a
    video with a frame at each time a picture may show (``STEPS + 1``)."""
    cmd, small = argv[0], PICTURE_SMALL.get(argv[0])
    if cmd in ("render", "fly"):
        default = "512x512" if cmd == "render" else "256x256"
        w, h = (int(v) for v in (argv[argv.index("--size") + 1] if "--size" in argv else default).split("x"))
        argv = _set(argv, "--size", f"{small}x{round(small * h / w)}")
    if cmd == "render" and "pathtrace" in argv:
        argv = _set(argv, "--pt-samples", PICTURE_SAMPLES)
    if cmd == "fly":
        argv = _set(argv, "--frames", str(STEPS + 1)) + ["--no-progress"]  # every time a picture may show
    if cmd == "demo":
        argv = _set(argv, "--size", str(small))
    return argv


def picture_difference(folder: Path, name: str) -> tuple[float, float]:
    """``(mean, 95th percentile)`` over the pixels of |RGB difference| / 255 (averaged over the channels) between
    picture ``name`` assembled from the outputs in ``folder`` and the README's, scaled down to its size."""
    from PIL import Image

    made = assemble(folder, name).astype(float)
    shown = Image.open(ROOT / "docs" / name).convert("RGB")
    shown = np.asarray(shown.resize((made.shape[1], made.shape[0]), Image.Resampling.BOX), float)
    diff = np.abs(made - shown).mean(axis=2) / 255
    return float(diff.mean()), float(np.percentile(diff, 95))


def _shrink(argv: list[str]) -> list[str]:
    if _panels(argv):
        return _at_picture_size(argv) + (["--port", "0"] if argv[0] == "serve" else [])
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
        out += [] if "--size" in out or "--screenshot" not in out else ["--size", "320x200"]
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
    for out in outputs(argv):
        p = workdir / out
        if not (p.exists() and (p.is_dir() or p.stat().st_size > 0)):
            return f"{line}: {out} not written"
    return None


def _compare_pictures(workdir: Path) -> list[str]:
    """Each README picture whose panels the lines wrote, compared with the one shown (:func:`picture_difference`);
    the problems found."""
    failures = []
    for name, panels in PICTURES.items():
        missing = [p.out for p in panels if not (workdir / p.out / p.file).exists()]
        if missing:
            print(f"docs/{name}: not compared, its lines were skipped ({', '.join(missing)} not written)")
            continue
        mean, p95 = picture_difference(workdir, name)
        print(f"docs/{name}: mean |RGB diff| {mean:.4f}, 95th percentile {p95:.4f}")
        if mean > PICTURE_MEAN_BAR or p95 > PICTURE_P95_BAR:
            failures.append(f"docs/{name} differs from what its lines write: mean {mean:.4f} (bar "
                            f"{PICTURE_MEAN_BAR}), 95th percentile {p95:.4f} (bar {PICTURE_P95_BAR})")
    return failures


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
    failures += _compare_pictures(workdir)
    assert not failures, "\n".join(failures)
