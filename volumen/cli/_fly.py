"""``volumen fly INPUT (--path P.json | --start X,Y,Z --end X,Y,Z | --auto) -o OUT.mp4``: a virtual endoscopy
flythrough.

The path comes from a flight file (``--path``, as written by ``--save-path``:
keyframes, endoscope settings and centerline; or a bare keyframe path), or from
the centerline of the lumen between two points (``--start``/``--end``) or
between its two ends (``--auto``).

The lumen is found from the start point alone (:func:`volumen.endoscopy.find_lumen`):
its polarity (``--lumen auto|air|contrast``), value range and wall threshold
come from the data around the point and are printed; it is grown with explosion
control, tagged fluid under a fluid level is joined to an air lumen, and thin
bridges to other structures are cut. ``--range`` and ``--threshold`` override the
estimate; ``--lumen-mask FILE [--label N|NAME]`` takes an existing segmentation
instead, whose boundary values give the polarity and the threshold. The wall
drawn is the data held to the lumen (:class:`volumen.endoscopy.LumenWall`), or the
mask's own smoothed boundary where the data does not separate lumen and wall.
A lumen that leaks and cannot be contained (the points join only through a narrow
opening, or the path between them detours through a widening) ends with one line
naming the leak and the flags to try, and nothing is written.
For a phantom without ``--seed`` or ``--start``, the seed is the first
centerline point of its colon ground truth (the rectum), or of its first tube.

``--report FOLDER`` also writes the profile along the centerline (``volumen measure vessel``'s report).

Writes the video (MP4 by default, GIF by suffix), and beside it
``OUT.timing.json`` with the per-frame render times, their mean and their
frame-time-weighted mean (``sum t^2 / sum t``), both also printed. Nothing is
written before the lumen, the centerline and every frame are made; the video
goes to a temporary name first.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from ._common import _floats, add_load_options, load_from_args, parse_point
from ._measure_vessel import flight_profile, write_flight_report

#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("out", "save_path", "unfold", "report")


def register(sub):
    p = sub.add_parser("fly", help="render a virtual endoscopy flythrough to MP4 or GIF")
    p.add_argument("input", help="volume file, DICOM folder, phantom:NAME, or dicomweb://SERVER/STUDY/SERIES")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--path", help="flight (or keyframe path) JSON file, as written by --save-path")
    src.add_argument("--start", help="centerline start X,Y,Z (world RAS mm; needs --end)")
    src.add_argument("--auto", action="store_true", help="centerline between the two ends of the lumen")
    p.add_argument("--end", help="centerline end X,Y,Z (world RAS mm)")
    p.add_argument("-o", "--out", required=True, help="output video (.mp4 or .gif)")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25)")
    p.add_argument("--speed", type=float, help="flight speed in mm/s along the path (default 20, or the saved one)")
    p.add_argument("--frames", type=int, help="number of frames (default: path duration x fps + 1)")
    p.add_argument("--size", default="256x256", help="frame size WxH in pixels (default 256x256)")
    p.add_argument("--fov", type=float, help="vertical field of view, 30..140 degrees (default 100, or the saved one)")
    from volumen.core import INTERPOLATIONS, SHADINGS
    from volumen.endoscopy import LUMEN_KINDS

    p.add_argument("--shading", choices=SHADINGS,
                   help="every lit model (phong, the default; shadows, scattering, pathtrace) puts a flashlight on "
                        "the camera; headlight; none (default phong, or the saved one)")
    p.add_argument("--mode", choices=["isosurface", "composite"],
                   help="wall as a surface at the wall threshold, or volume rendering with a transfer function made "
                        "from the lumen's values or --preset (default: composite when --preset is given, else "
                        "isosurface)")
    p.add_argument("--reconstruction", choices=INTERPOLATIONS,
                   help="between voxels: linear (trilinear, the default), nearest, or bspline (tricubic B-spline: "
                        "smooth walls on thick-slice scans, about 3x slower)")
    p.add_argument("--preset", help="transfer function for composite mode (endo-air, endo-contrast, or a core preset)")
    p.add_argument("--lumen", choices=LUMEN_KINDS, default="auto",
                   help="air lumen (darker than its wall: colon, airways), contrast lumen (brighter: vessels), or "
                        "auto: decided from the data around the start point (default)")
    p.add_argument("--threshold", type=float, help="wall value in data units (default: estimated from the data)")
    p.add_argument("--seed", help="a point X,Y,Z inside the lumen (world RAS mm) to grow it from (default --start)")
    p.add_argument("--range", dest="value_range", help="lumen values LO,HI in data units (default: estimated)")
    p.add_argument("--lumen-mask", help="an existing segmentation as the lumen: a label file (NIfTI, NRRD, ...) or a "
                                        "folder of per-structure masks (TotalSegmentator)")
    p.add_argument("--label", help="with --lumen-mask: label value N (a file) or structure NAME (a folder)")
    p.add_argument("--every", type=float, default=10.0, help="keyframe spacing along the centerline, mm (default 10)")
    p.add_argument("--both-directions", action="store_true",
                   help="fly to the end, then back to the start looking the other way")
    p.add_argument("--save-path", help="write the flight (keyframes, endoscope settings, centerline) to this JSON")
    p.add_argument("--unfold", help="also write the unfolded view of the wall along the centerline (PNG)")
    p.add_argument("--report", help="also write the profile along the centerline into this folder (profile.csv, "
                                    "report.json, profile.png: diameters, areas, stenosis, length)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    add_load_options(p)
    return p


def _size(text: str) -> tuple[int, int]:
    w, h = (int(v) for v in _floats(text, 2, "--size"))
    if w < 8 or h < 8:
        raise ValueError(f"--size must be at least 8x8 pixels, got {text!r}")
    return w, h


def default_seed(volume):
    """The lumen seed of a phantom: its colon's first centerline point (rectum), else its first tube's; else None."""
    truth = volume.meta.get("truth") or {}
    tubes = [truth["colon"]] if "colon" in truth else [t for t in truth.values() if hasattr(t, "centerline")]
    return tuple(float(v) for v in tubes[0].centerline[0]) if tubes else None


def _lumen(args, volume):
    """The :class:`LumenWall`: grown from the seed, or read from ``--lumen-mask`` (its boundary gives the
    estimate); ``--range`` and ``--threshold`` override the estimate."""
    from volumen.endoscopy import check_points_in_mask, load_lumen_mask, lumen_wall

    start, end = parse_point(args.start), parse_point(args.end)
    seed = parse_point(args.seed) or start or default_seed(volume)
    if seed is None:
        raise ValueError("give --seed X,Y,Z inside the lumen (world RAS mm)")
    rng = tuple(_floats(args.value_range, 2, "--range")) if args.value_range else None
    mask = None
    if args.lumen_mask:
        points = {"start": seed} if end is None else {"start": seed, "end": end}
        mask = load_lumen_mask(args.lumen_mask, volume, args.label)
        check_points_in_mask(volume, mask, points, args.lumen_mask)
    return lumen_wall(volume, seed, end, kind=args.lumen, value_range=rng, threshold=args.threshold, mask=mask)


def _centerline(args, volume):
    """``(centerline, wall)``: between --start and --end (refused when it detours through a leak), or between
    the lumen's two ends."""
    from volumen.core import values_of
    from volumen.endoscopy import checked_centerline, compute_centerline, smooth_wall

    start, end = parse_point(args.start), parse_point(args.end)
    if start is not None and end is None:
        raise ValueError("--start needs --end")
    wall = _lumen(args, volume)
    shape_only = " (the wall drawn is the lumen mask's own boundary: the data does not separate lumen and wall)"
    print(wall.estimate.describe(**values_of(volume)) + (shape_only if wall.shape_only else ""))
    if wall.note:
        print(wall.note, file=sys.stderr)
    if start is not None:
        cl = checked_centerline(volume, wall.mask, start, end)
    else:
        cl = compute_centerline(volume, wall.mask, start, end)
    if args.lumen_mask or args.threshold is not None:
        return cl, wall
    smooth = smooth_wall(volume, wall, cl)
    if smooth is not wall:
        print("wall: the grown lumen's smoothed boundary, redrawn at local half-way values (the values inside it "
              "vary more than the threshold allows)")
    return cl, smooth


def _overrides(args, volume) -> dict:
    """The endoscope settings given on the command line (they override a saved flight's)."""
    from volumen.endoscopy import endoscopy_transfer

    out = {k: getattr(args, k) for k in ("mode", "threshold", "shading", "fov") if getattr(args, k) is not None}
    if args.reconstruction is not None:
        out["interpolation"] = args.reconstruction
    if args.preset:
        out["transfer"] = endoscopy_transfer(args.preset, volume)
        out.setdefault("mode", "composite")
    return out


def _flight(args, volume):
    """The Flight to render: loaded from ``--path`` (flags given override its settings), or made from the
    centerline and the lumen's estimate."""
    from volumen.endoscopy import Flight, KeyframePath, make_flight

    if args.path:
        flight = Flight.load(args.path, volume)
        speed = args.speed or flight.path.speed
        path = KeyframePath(flight.path.keyframes, speed=speed)
        return Flight(path, flight.endoscope.with_(**_overrides(args, volume)), flight.centerline, flight.lumen), None
    if args.end and not args.start:
        raise ValueError("--end needs --start")
    cl, wall = _centerline(args, volume)
    est = wall.estimate
    print(f"centerline: {cl.length:.1f} mm, {len(cl.points)} points, radius "
          f"{cl.radius.min():.1f}..{cl.radius.max():.1f} mm")
    return make_flight(volume, wall, cl, every=args.every, speed=args.speed or 20.0, **_overrides(args, volume)), est


def _legs(args, flight, volume):
    """``[(name, poses)]``: out, and back when ``--both-directions`` (turned round: looking where it goes)."""
    from volumen.endoscopy import KeyframePath, Pose, aim_keyframes

    poses = flight.path.play(args.fps, args.frames)
    legs = [("out", poses)]
    if args.both_directions:
        if flight.centerline is not None:
            back = KeyframePath.from_centerline(flight.centerline.reversed(), every=args.every, speed=flight.path.speed)
            if flight.lumen is not None:
                back = aim_keyframes(back, flight.centerline.reversed(), volume, flight.lumen.mask)
            back = back.play(args.fps, args.frames)
        else:
            back = [Pose(position=p.position, forward=tuple(-np.asarray(p.forward)), up=p.up) for p in poses[::-1]]
        legs.append(("back", back))
    return legs


def _render_video(args, flight, volume, out: Path, size):
    """Every frame into ``OUT.part.SUFFIX``, renamed to ``out`` once complete; returns the FrameLog."""
    from volumen.endoscopy import FrameLog, VideoWriter

    log = FrameLog()
    out.parent.mkdir(parents=True, exist_ok=True)
    part = out.with_name(f"{out.stem}.part{out.suffix}")
    try:
        with VideoWriter(part, args.fps) as video:
            for name, leg in _legs(args, flight, volume):
                for img in flight.endoscope.frames(leg, size, log=log, progress=not args.no_progress, desc=name):
                    video.append(img.to_uint8())
        part.replace(out)
    finally:
        part.unlink(missing_ok=True)
    return log


def run(args):
    from volumen.endoscopy import WallField, unfold

    out = Path(args.out)
    if out.suffix.lower() not in (".mp4", ".gif"):
        raise ValueError(f"-o must end with .mp4 or .gif, got {out.name!r}")
    if out.suffix.lower() == ".mp4":
        from volumen.errors import require

        require("imageio_ffmpeg", "writing MP4")
    size = _size(args.size)
    if args.unfold and args.path:  # before any rendering
        raise ValueError("--unfold needs a centerline (--auto or --start/--end), not --path")
    if args.label and not args.lumen_mask:
        raise ValueError("--label needs --lumen-mask")
    volume = load_from_args(args)
    flight, est = _flight(args, volume)
    profile = flight_profile(args, flight, volume)
    unfolded = None
    if args.unfold:
        wall = WallField.from_threshold(flight.endoscope.volume, flight.endoscope.threshold, est.lumen_side)
        unfolded = unfold(wall, flight.centerline, step=1.0)
    log = _render_video(args, flight, volume, out, size)
    timing = out.with_name(out.stem + ".timing.json")
    log.save(timing)
    print(f"{out}: {log.to_dict()['frames']} frames {size[0]}x{size[1]}; frame time mean {1e3 * log.mean:.1f} ms, "
          f"weighted mean (sum t^2 / sum t) {1e3 * log.weighted_mean:.1f} ms; timings in {timing}")
    if args.save_path:
        flight.save(args.save_path)
    if unfolded is not None:
        unfolded.save(args.unfold)
        print(f"unfolded view: {args.unfold}")
    write_flight_report(args, profile, volume)
    return 0
