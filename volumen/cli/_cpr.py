"""``volumen cpr INPUT --path FLIGHT.json -o cpr.png``: a curved planar reformation along a flight's centerline.

The path is a flight written by ``volumen fly --save-path`` (its centerline), a
centerline JSON (:meth:`Centerline.to_json`) or a bare keyframe path (its
positions, densely sampled). ``--kind straightened`` (default) puts the
centerline on the picture's vertical mid-line with true lengths along it;
``stretched`` keeps the vessel's course along a fixed direction. The
cross-sections at ``--sections`` (arc lengths in mm; default four evenly
spread) are marked on the CPR and drawn beside it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ._common import WINDOW_HELP, _floats, add_load_options, count, load_from_args, parse_window

#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("out",)


def register(sub):
    p = sub.add_parser("cpr", help="curved planar reformation along a centerline (straightened or stretched) to PNG")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("--path", required=True, help="flight (volumen fly --save-path), centerline or keyframe JSON")
    p.add_argument("-o", "--out", required=True, help="output PNG")
    p.add_argument("--kind", choices=["straightened", "stretched"], default="straightened",
                   help="straightened (default): the centerline straight down the middle; stretched: along a fixed "
                        "direction, the vessel keeps its course")
    p.add_argument("--width", type=float, help="width across the path, mm (default: 8 times the path's median "
                   "lumen radius, the lumen a quarter of it; 40 along a keyframe path)")
    p.add_argument("--sections", help="arc lengths S1,S2,... (mm) of the cross-sections to mark and show "
                                      "(default: four evenly spread)")
    p.add_argument("--window", help=f"{WINDOW_HELP} (default: the darker of the lumen and the tissue round "
                   "it a quarter and the brighter three quarters up the ramp, a vascular window)")
    p.add_argument("--height", type=count, default=600, help="approximate picture height in pixels (default 600)")
    add_load_options(p)
    return p


def load_centerline(path):
    """The Centerline in a flight, centerline or keyframe-path JSON file; ValueError naming the file otherwise."""
    from volumen.endoscopy import Centerline, KeyframePath
    from volumen.endoscopy.path._centerline import resample_polyline

    try:
        d = json.loads(Path(path).read_text())
        if d.get("format") == "volumen-flight":
            if d.get("centerline") is None:
                raise ValueError("the flight holds no centerline")
            return Centerline.from_dict(d["centerline"])
        if "points" in d:
            return Centerline.from_dict(d)
        kp = KeyframePath.from_dict(d)
    except (OSError, json.JSONDecodeError, TypeError, KeyError, AttributeError, ValueError) as exc:
        raise ValueError(f"{path}: not a flight, centerline or keyframe path: {exc}") from None
    g = np.linspace(0.0, len(kp.keyframes) - 1, 50 * len(kp.keyframes))
    pts, arc = resample_polyline(np.array([kp.position_at(x) for x in g]), 1.0)
    return Centerline(pts, np.zeros(len(pts)), arc)


def run(args):
    from PIL import Image as PILImage

    from volumen.endoscopy import cpr_figure, cpr_width, curved_reformation

    out = Path(args.out)
    if out.suffix.lower() != ".png":
        raise ValueError(f"-o must end with .png, got {out.name!r}")
    cl = load_centerline(args.path)
    volume = load_from_args(args)
    window = parse_window(args.window, volume)
    marks = (_floats(args.sections, len(args.sections.split(",")), "--sections") if args.sections
             else list(np.linspace(0.0, cl.length, 6)[1:-1]))
    bad = [s for s in marks if not 0.0 <= s <= cl.length]
    if bad:
        raise ValueError(f"--sections {bad} mm lie outside the path (0..{cl.length:.1f} mm)")
    width = args.width or cpr_width(cl)
    cpr = curved_reformation(volume, cl, kind=args.kind, width=width)
    fig = cpr_figure(volume, cl, cpr, marks, window=window and window.range, section_width=width,
                     height=args.height)
    out.parent.mkdir(parents=True, exist_ok=True)
    PILImage.fromarray(fig).save(out)
    print(f"{out}: {fig.shape[1]}x{fig.shape[0]} px, a {args.kind} CPR of {cpr.values.shape[1]}x{cpr.values.shape[0]} "
          f"samples {cpr.pixel:.1f} mm apart along {cl.length:.1f} mm, {width:.1f} mm across; cross-sections at "
          f"{', '.join(f'{s:.1f}' for s in marks)} mm")
    return 0
