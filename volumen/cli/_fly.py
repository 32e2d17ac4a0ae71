"""``volumen fly INPUT (--path P.json | --start X,Y,Z --end X,Y,Z | --auto) -o OUT.mp4``: a virtual endoscopy
flythrough.

The path comes from a keyframe file (``--path``, as written by ``--save-path``
or :meth:`volumen.endoscopy.KeyframePath.save`), or from the centerline of the
lumen between two points (``--start``/``--end``) or between its two ends
(``--auto``). The lumen is grown from a seed over a range of values (air by
default): ``--seed X,Y,Z``, else ``--start``; for a phantom without either, the
first centerline point of its colon ground truth (``meta["truth"]["colon"]``,
the rectum), or of its first tubular structure.

Writes the video (MP4 by default, GIF by suffix), and beside it
``OUT.timing.json`` with the per-frame render times, their mean and their
frame-time-weighted mean (``sum t^2 / sum t``), both also printed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._common import _floats, add_load_options, load_from_args, parse_point


def register(sub):
    p = sub.add_parser("fly", help="render a virtual endoscopy flythrough to MP4 or GIF")
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--path", help="keyframe path JSON file")
    src.add_argument("--start", help="centerline start X,Y,Z (world RAS mm; needs --end)")
    src.add_argument("--auto", action="store_true", help="centerline between the two ends of the lumen")
    p.add_argument("--end", help="centerline end X,Y,Z (world RAS mm)")
    p.add_argument("-o", "--out", required=True, help="output video (.mp4 or .gif)")
    p.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25)")
    p.add_argument("--speed", type=float, default=20.0, help="flight speed in mm/s along the path (default 20)")
    p.add_argument("--frames", type=int, help="number of frames (default: path duration x fps + 1)")
    p.add_argument("--size", default="256x256", help="frame size WxH in pixels (default 256x256)")
    p.add_argument("--fov", type=float, default=100.0, help="vertical field of view, 30..140 degrees (default 100)")
    from volumen.core import SHADINGS

    p.add_argument("--shading", choices=SHADINGS, default="phong",
                   help="every lit model (phong, the default; shadows, scattering, pathtrace) puts a flashlight on "
                        "the camera; headlight; none")
    p.add_argument("--mode", choices=["isosurface", "composite"],
                   help="wall as a surface at --threshold, or volume rendering with --preset "
                        "(default: composite when --preset is given, else isosurface)")
    p.add_argument("--preset", help="transfer function for composite mode (endo-air, endo-contrast, or a core preset)")
    p.add_argument("--threshold", type=float, default=-500.0, help="wall value in data units (default -500 HU)")
    p.add_argument("--seed", help="a point X,Y,Z inside the lumen (world RAS mm) to grow it from")
    p.add_argument("--range", dest="value_range", help="lumen values LO,HI in data units (default air: -1100,-500)")
    p.add_argument("--every", type=float, default=10.0, help="keyframe spacing along the centerline, mm (default 10)")
    p.add_argument("--both-directions", action="store_true",
                   help="fly to the end, then back to the start looking the other way")
    p.add_argument("--save-path", help="write the keyframe path used to this JSON file")
    p.add_argument("--unfold", help="also write the unfolded view of the wall along the centerline (PNG)")
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


def _centerline(args, volume):
    from volumen.endoscopy import AIR_RANGE, compute_centerline, lumen_mask

    start = parse_point(args.start)
    end = parse_point(args.end)
    if start is not None and end is None:
        raise ValueError("--start needs --end")
    seed = parse_point(args.seed) or start or default_seed(volume)
    if seed is None:
        raise ValueError("give --seed X,Y,Z inside the lumen (world RAS mm)")
    rng = tuple(_floats(args.value_range, 2, "--range")) if args.value_range else AIR_RANGE
    lumen = lumen_mask(volume, seed, rng)
    return compute_centerline(volume, lumen, start, end)


def run(args):
    from volumen.endoscopy import Endoscope, FrameLog, KeyframePath, VideoWriter, WallField, endoscopy_transfer, unfold

    out = Path(args.out)
    if out.suffix.lower() not in (".mp4", ".gif"):
        raise ValueError(f"-o must end with .mp4 or .gif, got {out.name!r}")
    size = _size(args.size)
    if args.unfold and args.path:  # before any rendering
        raise ValueError("--unfold needs a centerline (--auto or --start/--end), not --path")
    volume = load_from_args(args)
    cl = None
    if args.path:
        path = KeyframePath.load(args.path)
        path = KeyframePath(path.keyframes, speed=args.speed)
    else:
        if args.end and not args.start:
            raise ValueError("--end needs --start")
        cl = _centerline(args, volume)
        print(f"centerline: {cl.length:.1f} mm, {len(cl.points)} points, radius "
              f"{cl.radius.min():.1f}..{cl.radius.max():.1f} mm")
        path = KeyframePath.from_centerline(cl, every=args.every, speed=args.speed)
    if args.save_path:
        path.save(args.save_path)
    mode = args.mode or ("composite" if args.preset else "isosurface")
    transfer = endoscopy_transfer(args.preset or ("endo-contrast" if args.threshold > 0 else "endo-air"))
    endo = Endoscope(volume=volume, mode=mode, threshold=args.threshold, transfer=transfer, shading=args.shading,
                     fov=args.fov)
    poses = path.play(args.fps, args.frames)
    legs = [("out", poses)]
    if args.both_directions:
        back = (KeyframePath.from_centerline(cl.reversed(), every=args.every, speed=args.speed)
                if cl is not None else None)
        if back is None:  # a keyframe path: fly it backwards, turned round (looking where the camera goes)
            from volumen.endoscopy import Pose

            turned = [Pose(position=p.position, forward=tuple(-np.asarray(p.forward)), up=p.up) for p in poses[::-1]]
            legs.append(("back", turned))
        else:
            legs.append(("back", back.play(args.fps, args.frames)))
    log = FrameLog()
    out.parent.mkdir(parents=True, exist_ok=True)
    with VideoWriter(out, args.fps) as video:
        for name, leg in legs:
            for img in endo.frames(leg, size, log=log, progress=not args.no_progress, desc=name):
                video.append(img.to_uint8())
    timing = out.with_name(out.stem + ".timing.json")
    log.save(timing)
    print(f"{out}: {log.to_dict()['frames']} frames {size[0]}x{size[1]}; frame time mean {1e3 * log.mean:.1f} ms, "
          f"weighted mean (sum t^2 / sum t) {1e3 * log.weighted_mean:.1f} ms; timings in {timing}")
    if args.unfold:
        if cl is None:
            raise ValueError("--unfold needs a centerline (--auto or --start/--end), not --path")
        lumen_below = args.threshold <= 0
        wall = WallField.from_threshold(volume, args.threshold, "below" if lumen_below else "above")
        unfold(wall, cl, step=1.0).save(args.unfold)
        print(f"unfolded view: {args.unfold}")
    return 0
