"""``volumen bench WHAT``: print a benchmark table and write it as JSON (never run as tests)."""

from __future__ import annotations

from pathlib import Path

BENCHES = ("render", "techniques", "lighting", "mesh", "scale", "labels", "compile", "pathtrace", "web", "memory")


def register(sub):
    p = sub.add_parser("bench", help="benchmarks: print a table and write it as JSON")
    p.add_argument("what", choices=BENCHES, help="render: ray casting vs VTK's fixed-point CPU mapper "
                   "(--device gl: the OpenGL ray caster vs VTK's GPU mapper); "
                   "techniques: meshes, ray casting and texture slicing along a camera path; "
                   "lighting: shadows and scattering in the seeds' experiment; "
                   "mesh: marching cubes on real scans vs VTK's flying edges and scikit-image; "
                   "scale: out-of-core vs in-memory ray casting (OME-Zarr) and batch throughput on Dask; "
                   "labels: label-aware composite against plain composite; "
                   "compile: the first picture of each ray-casting mode in a fresh process (cold Numba cache); "
                   "pathtrace: error of 16 denoised / 256 raw samples against 4096, equal-time, bias, samples/s; "
                   "web: frames per second of the browser viewer in headless Chromium (desktop and both eyes of "
                   "an emulated headset) beside the gl device; "
                   "memory: peak memory of one picture of a 700x512x512 int16 CT per shading model")
    p.add_argument("--out", default="out/bench", help="folder for the JSON (and .md) results (default out/bench)")
    p.add_argument("--quick", action="store_true", help="tiny sizes, to check the benchmark itself runs")
    p.add_argument("--huge", action="store_true", help="scale: instead, a 2048x2048x1024 int16 volume (8 GiB, "
                   "written to a temporary folder and deleted) drawn out of core with a 1 GiB cache; peak RSS "
                   "against its bound (takes minutes, 8 GiB of disk)")
    p.add_argument("--no-vtk", action="store_true", help="skip the VTK peer even when installed")
    p.add_argument("--repeat", type=int, default=3, help="timed frames per case (median reported)")
    p.add_argument("--spv", type=float, default=1.0, help="samples per voxel")
    p.add_argument("--data", default=None, help="render: only the data sets whose names contain one of these "
                   "comma-separated words (e.g. abdomen,366)")
    p.add_argument("--scan", action="append", default=[], metavar="FILE",
                   help="render, lighting, mesh: a scan of your own (any file or DICOM folder volumen opens; "
                   "repeat for more), benched instead of the built-in data sets (render: besides those --data "
                   "names), turned to RAS+ axis order and resampled to the benchmark's sizes; named scan1, "
                   "scan2, ... in the table, never by its file name")
    from volumen.render import TECHNIQUES

    devices = (*TECHNIQUES["raycast"].devices, "auto")
    p.add_argument("--device", "--backend", dest="device", choices=devices, default=devices[0],
                   help=f"render and lighting: where the ray caster runs, one of {', '.join(devices)} (default "
                   f"{devices[0]}; cuda fails at once where there is none; auto: cuda when a device is usable); "
                   "--backend is its old name")
    return p


#: the benchmarks that take ``--scan``
SCANNED = ("render", "lighting", "mesh")


def _scans(args) -> list:
    """The ``--scan`` files, read (``bench._datasets.read_scan``) before any benchmark starts: a file that is
    missing or does not read stops the run at once, in one line that names it by its number, not its path."""
    if args.scan and args.what not in SCANNED:
        raise ValueError(f"--scan is for bench {', '.join(SCANNED)}, not {args.what}")
    from volumen.bench._datasets import read_scan

    for n, f in enumerate(args.scan, 1):
        if not Path(f).exists():
            raise ValueError(f"--scan {n} (scan{n}): no such file or folder")
    return [read_scan(f, n) for n, f in enumerate(args.scan, 1)]


def _choose_data(args, scans, kw: dict, default: dict) -> None:
    """``bench render``'s data sets into ``kw["datasets"]``: those of the known ones (``kw``'s, else ``default``)
    that ``--data`` names (none where only ``--scan`` is given), and the scans at the benchmark's sizes (a small
    one with ``--quick``); ``kw`` unchanged where neither is given."""
    from volumen.bench._datasets import SCAN_QUICK_SIZE, SCAN_SIZES, scan_datasets

    if not (args.data or scans):
        return
    known, chosen = kw.get("datasets", default), {}
    if args.data:
        words = [w for w in args.data.split(",") if w]
        chosen = {n: d for n, d in known.items() if any(w in n for w in words)}
        if not chosen:
            raise ValueError(f"--data {args.data!r} names no data set of {', '.join(known)}")
    chosen.update(scan_datasets(scans, (SCAN_QUICK_SIZE,) if args.quick else SCAN_SIZES))
    kw["datasets"] = chosen


def run(args):
    scans = _scans(args)
    if args.what == "techniques":
        from volumen.bench._techniques import main

        return main(args)
    if args.what == "mesh":
        from volumen.bench._mesh import bench_mesh

        table = bench_mesh(quick=args.quick, with_vtk=not args.no_vtk, scans=scans)
    elif args.what == "scale":
        from volumen.bench._scale import bench_scale, bench_scale_huge

        table = bench_scale_huge() if args.huge else bench_scale(quick=args.quick, repeat=args.repeat)
    elif args.what == "lighting":
        from volumen.bench._lighting import bench_lighting

        table = bench_lighting(quick=args.quick, repeat=args.repeat, device=args.device, scans=scans)
    elif args.what == "compile":
        from volumen.bench._compile import bench_compile

        table = bench_compile(quick=args.quick)
    elif args.what == "pathtrace":
        from volumen.bench._pathtrace import bench_pathtrace

        table = bench_pathtrace(quick=args.quick)
    elif args.what == "web":
        from volumen.web._bench import WEB_QUICK, bench_web

        table = bench_web(**(WEB_QUICK if args.quick else {"frames": max(args.repeat, 3)}))
    elif args.what == "memory":
        from volumen.bench._memory import bench_memory

        table = bench_memory(quick=args.quick)
    elif args.what == "labels":
        from volumen.bench._labels import bench_labels

        table = bench_labels(quick=args.quick, repeat=args.repeat, device=args.device)
    elif args.device == "gl":  # the OpenGL ray caster against VTK's GPU mapper on the same OpenGL
        from volumen.bench._render_gl import GL_DATASETS, GL_QUICK, bench_render_gl

        kw = dict(GL_QUICK) if args.quick else {}
        _choose_data(args, scans, kw, GL_DATASETS)
        table = bench_render_gl(spv=args.spv, rounds=args.repeat, with_vtk=not args.no_vtk, **kw)
    else:
        from volumen.bench._render import DATASETS, QUICK, bench_render

        kw = dict(QUICK) if args.quick else {}
        _choose_data(args, scans, kw, DATASETS)
        if scans and not args.data:  # the peak memory of the large aorta belongs to the whole benchmark
            kw["memory_datasets"] = {}
        table = bench_render(spv=args.spv, repeat=args.repeat, with_vtk=not args.no_vtk, backend=args.device, **kw)
    print()
    print(table.render())
    huge = "-huge" if args.what == "scale" and args.huge else ""
    path = table.save(Path(args.out) / f"{args.what}{huge}{'-quick' if args.quick else ''}.json")
    print(f"\nwrote {path} and {path.with_suffix('.md')}")
    return 0
