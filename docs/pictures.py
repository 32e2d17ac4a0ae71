"""The README's pictures, made from the README's own commands: ``make pictures`` runs ``python docs/pictures.py``.

Each picture in ``docs/`` is what ``volumen`` lines of the README write (:data:`PICTURES`: their outputs, by the
name the line gives), side by side at the first one's height: a PNG as it is, a video as some of its frames (at
times that are multiples of 1 / :data:`STEPS` of its length). The lines that write them (and those writing what they
read, such as a flight's JSON) run exactly as the README gives them, in its order, in a scratch folder, with
``../shared/data`` pointed at the shared data folder (``volumen.data.shared_data``). ``tests/test_readme.py``
runs every line of the README at a small size and compares each picture assembled from its outputs here with the
one in ``docs/`` scaled down to the same size.

Usage: ``python docs/pictures.py [NAME.png ...]`` (default: every picture).
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
#: the documents whose ``sh`` blocks hold the commands: the README and the benchmarks it links to
DOCUMENTS = ("README.md", "docs/benchmarks.md")
#: the arguments that name what a command writes
OUTPUT_FLAGS = ("-o", "--out", "--save-settings", "--save-path", "--screenshot")


#: a video's frames are picked at times that are multiples of 1 / STEPS of its length (0: the first, 1: the last)
STEPS = 12


@dataclass(frozen=True)
class Panel:
    """One part of a picture: the output a README line names (``out``), the file in it where that is a folder
    (``file``), and for a video the frames shown (``times``: fractions of its length, multiples of 1 / STEPS)."""

    out: str
    file: str = ""
    times: tuple[float, ...] = ()


#: docs/NAME -> its panels, left to right
PICTURES: dict[str, tuple[Panel, ...]] = {
    "head_montage.png": (Panel("head-slices/", "head_montage.png"),),
    "gallery.png": tuple(Panel("out", f"gallery/{stem}.png") for stem in (
        "torso_composite_bone_headlight", "torso_composite_ct-vessels_phong", "torso_minip",
        "head_composite_ct-skin-bone_phong", "head_iso300_headlight", "head_mip")),
    "app.png": (Panel("app.png"),),
    "web-page.png": (Panel("web-page.png"),),
    "web-vr.png": (Panel("web-vr.png"),),
    "aorta-flythrough.png": (Panel("iliac.mp4", times=(0, 1 / 2, 1)),),
    "aorta-cpr.png": (Panel("iliac-straight.png"), Panel("iliac-cpr.png")),
    "bronchoscopy.png": (Panel("bronchoscopy.mp4", times=(0, 1 / 3, 2 / 3, 1)),),
    # the last frame looks out past the colon's end, into the dark
    "tagged-colon.png": (Panel("tagged-colon.mp4", times=(0, 1 / 4, 1 / 2, 3 / 4)),),
    "aorta-cinematic.png": (Panel("aorta-cinematic.png"),),
    "labels-organs.png": (Panel("organs.png"),),
    "aorta-profile.png": (Panel("aorta-report/", "profile.png"),),
}


def readme_commands() -> list[str]:
    """The ``volumen`` lines of the ``sh`` blocks of :data:`DOCUMENTS`, continuation lines joined."""
    text = "".join((ROOT / doc).read_text(encoding="utf-8") for doc in DOCUMENTS)
    blocks = re.findall(r"```sh\n(.*?)```", text, flags=re.S)
    lines = "\n".join(blocks).replace("\\\n", " ").splitlines()
    return [ln.strip() for ln in lines if ln.strip().startswith("volumen ")]


def outputs(argv: list[str]) -> list[str]:
    """What the command ``argv`` (without ``volumen``) writes, as named on its line."""
    outs = [argv[i + 1] for i, t in enumerate(argv[:-1]) if t in OUTPUT_FLAGS]
    if argv[0] == "convert":
        outs.append(argv[2])
    return outs


def picture_lines(names=None) -> list[list[str]]:
    """The README's lines (as argv, in its order) that write the panels of ``names`` (default: every picture),
    and those that write what they read."""
    wanted = {p.out for name in (names or PICTURES) for p in PICTURES[name]}
    lines = [shlex.split(line, comments=True)[1:] for line in readme_commands()]
    chosen: list[int] = []
    for i in reversed(range(len(lines))):
        outs = set(outputs(lines[i]))
        if outs & wanted:
            chosen.append(i)
            wanted |= {a for a in lines[i][1:] if a not in outs}  # what it reads, if an earlier line writes it
    return [lines[i] for i in reversed(chosen)]


def frames(path: Path, times) -> list[np.ndarray]:
    """The frames of the video at ``path`` nearest the ``times`` (fractions of its length: 0 the first frame, 1
    the last)."""
    import imageio.v2 as iio

    with iio.get_reader(str(path)) as reader:
        every = [np.asarray(f)[..., :3] for f in reader]
    return [every[round(t * (len(every) - 1))] for t in times]


def panel_images(folder: Path, panel: Panel) -> list[np.ndarray]:
    from PIL import Image

    path = folder / panel.out / panel.file if panel.file else folder / panel.out
    if panel.times:
        return frames(path, panel.times)
    return [np.asarray(Image.open(path).convert("RGB"))]


def assemble(folder: Path, name: str) -> np.ndarray:
    """Picture ``name`` (RGB uint8) from the outputs in ``folder``: its panels side by side at the first one's
    height."""
    from PIL import Image

    images = [im for panel in PICTURES[name] for im in panel_images(folder, panel)]
    height = images[0].shape[0]
    scaled = [im if im.shape[0] == height else np.asarray(Image.fromarray(im).resize(
        (max(1, round(im.shape[1] * height / im.shape[0])), height), Image.Resampling.LANCZOS)) for im in images]
    return np.concatenate(scaled, axis=1)


def _shared(argv: list[str]) -> list[str]:
    if not any("../shared/data" in a for a in argv):
        return argv
    from volumen.data import shared_data

    shared = shared_data()
    if shared is None:
        raise SystemExit("the shared data folder ../shared/data is missing (VOLUMEN_SHARED_DATA)")
    return [a.replace("../shared/data", str(shared)) for a in argv]


def make(names=None, folder: Path | None = None) -> list[Path]:
    """Run the lines of :func:`picture_lines` in ``folder`` (a scratch folder by default) with this checkout's
    volumen and write each picture of ``names`` into docs/; returns their paths."""
    from PIL import Image

    names = list(names or PICTURES)
    folder = Path(folder or tempfile.mkdtemp(prefix="volumen-pictures-"))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    for argv in picture_lines(names):
        print("volumen " + shlex.join(argv), flush=True)
        subprocess.run([sys.executable, "-m", "volumen", *_shared(argv)], cwd=folder, env=env, check=True)
    written = []
    for name in names:
        Image.fromarray(assemble(folder, name)).save(ROOT / "docs" / name)
        written.append(ROOT / "docs" / name)
        print(f"wrote docs/{name}")
    return written


if __name__ == "__main__":
    make(sys.argv[1:] or None)
