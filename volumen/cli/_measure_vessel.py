"""``volumen measure vessel INPUT --start X,Y,Z --end X,Y,Z [--lumen-mask FILE] -o REPORT/``: the numbers along a
vessel or an airway.

The lumen is grown from ``--start`` as ``volumen fly`` grows it (``--lumen``, ``--range``, ``--threshold``), or
read from ``--lumen-mask FILE [--label N|NAME]``; the centerline runs between the points (refused when it
detours through a leak). At each centerline point the section orthogonal to the path is measured
(:func:`volumen.analysis.profile`): area, equivalent, minimum and maximum diameters, the maximum inscribed
sphere radius; the branch points, the path's length and tortuosity, the stenosis and the maximum diameter.

Writes into the folder ``REPORT`` (made if missing): ``profile.csv`` (one row per section), ``report.json``
(the summary and the table) and ``profile.png`` (diameters and area against the distance along the path, the
stretched CPR above, the stenosis and the maximum marked), and prints the summary. A failure is one line on
stderr, exit status 1, and nothing is written.

:func:`register` adds the ``vessel`` action to the ``volumen measure`` group (``_measure.ACTIONS``).
"""

from __future__ import annotations

from pathlib import Path

from ._common import _floats, add_load_options, load_from_args, parse_point

__all__ = ["register", "run", "add_lumen_options", "print_summary", "flight_profile", "write_flight_report",
           "OUTPUTS"]

#: the arguments naming what the command writes (removed again when it fails: ``_contract.OutputFiles``)
OUTPUTS = ("out",)


def add_lumen_options(p) -> None:
    """The options that choose the lumen (as ``volumen fly``'s)."""
    from volumen.endoscopy import LUMEN_KINDS

    p.add_argument("--lumen", choices=LUMEN_KINDS, default="auto",
                   help="the lumen's polarity: air, contrast, or auto (from the data round --start)")
    p.add_argument("--range", dest="value_range", help="lumen values LO,HI in data units (default: estimated)")
    p.add_argument("--threshold", type=float, help="wall value in data units (default: estimated from the data)")
    p.add_argument("--lumen-mask", help="an existing segmentation as the lumen: a label file (NIfTI, NRRD, ...) or a "
                                        "folder of structure files")
    p.add_argument("--label", help="with --lumen-mask: label value N (a file) or structure NAME (a folder)")


def register(actions):
    """Add ``vessel`` to the ``volumen measure`` group's actions; returns its parser."""
    p = actions.add_parser("vessel", help="diameters, areas, stenosis and length along a vessel or airway",
                           description=__doc__.split("\n\n")[1])
    p.add_argument("input", help="volume file, DICOM folder, or phantom:NAME")
    p.add_argument("--start", required=True, help="path start X,Y,Z (world RAS mm), inside the lumen")
    p.add_argument("--end", required=True, help="path end X,Y,Z (world RAS mm), inside the same lumen")
    p.add_argument("-o", "--out", required=True, help="report folder: profile.csv, report.json, profile.png")
    add_lumen_options(p)
    add_load_options(p)
    return p


def check_out(out) -> Path:
    """The report folder, refused (before any work) when it names a file."""
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"-o must name a folder for the report, but {out.name!r} is a file")
    return out


def print_summary(profile, out: Path) -> None:
    """The summary in a few lines (mm to 0.1)."""
    st, mx = profile.stenosis, profile.maximum
    s = profile.sections
    print(f"path {profile.length:.1f} mm, tortuosity {profile.tortuosity:.2f}, {len(s.area)} sections, diameter "
          f"{s.diameter.min():.1f}..{s.diameter.max():.1f} mm, branch points {len(profile.branch_arcs)}")
    print(f"stenosis {st.percent:.0f} % at {st.arc:.1f} mm ({st.diameter:.1f} mm against {st.reference:.1f} mm)"
          f"{' FLAGGED' if st.flagged else ''}; maximum diameter {mx.diameter:.1f} mm at {mx.arc:.1f} mm"
          f"{' FLAGGED (aneurysm)' if mx.flagged else ''}")
    print(f"report: {out / 'profile.csv'}, {out / 'report.json'}, {out / 'profile.png'}")


def run(args):
    from volumen.analysis import profile, write_report
    from volumen.endoscopy import check_points_in_mask, load_lumen_mask
    from volumen.errors import require

    require("matplotlib", "the report's picture")
    out = check_out(args.out)
    if args.label and not args.lumen_mask:
        raise ValueError("--label needs --lumen-mask")
    start, end = parse_point(args.start), parse_point(args.end)
    rng = tuple(_floats(args.value_range, 2, "--range")) if args.value_range else None
    volume = load_from_args(args)
    mask = None
    if args.lumen_mask:
        mask = load_lumen_mask(args.lumen_mask, volume, args.label)
        check_points_in_mask(volume, mask, {"start": start, "end": end}, args.lumen_mask)
    prof = profile(volume, start, end, lumen=mask, kind=args.lumen, value_range=rng, threshold=args.threshold)
    write_report(prof, out, volume)
    print_summary(prof, out)
    return 0


def flight_profile(args, flight, volume):
    """``volumen fly --report``: the profile along the flight's centerline through its lumen (measured before any
    frame is drawn, so a failure writes nothing); None without ``--report``."""
    if not args.report:
        return None
    from volumen.analysis import measure
    from volumen.errors import require

    require("matplotlib", "the report's picture")
    check_out(args.report)
    if flight.centerline is None or flight.lumen is None:
        raise ValueError("--report needs the flight's centerline and lumen (--start/--end or --auto, or a flight "
                         "file saved with them)")
    return measure(volume, flight.lumen.mask, flight.centerline, refine=not args.lumen_mask)


def write_flight_report(args, profile, volume) -> None:
    """Write ``--report``'s folder (:func:`volumen.analysis.write_report`) and print its summary."""
    if profile is not None:
        from volumen.analysis import write_report

        write_report(profile, args.report, volume)
        print_summary(profile, Path(args.report))
