"""``volumen view [PATH]``: the desktop application; ``--screenshot`` saves the window and exits."""

from __future__ import annotations

from ._common import _floats

#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("screenshot",)


def register(sub):
    p = sub.add_parser("view", help="open the desktop application (slices, 3D view, endoscopy)")
    p.add_argument("path", nargs="?", help="volume file, DICOM folder, phantom:NAME or "
                   "dicomweb://SERVER/STUDY/SERIES (default: the head phantom)")
    p.add_argument("--screenshot", metavar="PNG",
                   help="wait for the final picture, save the whole window to PNG and exit")
    p.add_argument("--session", metavar="JSON", help="load a session saved by the application")
    p.add_argument("--size", metavar="WxH", help="window size in pixels, e.g. 1280x800")
    return p


def run(args):
    size = None
    if args.size:
        w, h = (int(v) for v in _floats(args.size, 2, "--size"))
        if w < 100 or h < 100:
            raise ValueError(f"--size must be at least 100x100, got {args.size}")
        size = (w, h)
    from volumen.errors import require

    require("PySide6", "the desktop application")
    from volumen.app import run as run_app
    return run_app(args.path, screenshot=args.screenshot, session=args.session, size=size)
