"""``volumen batch MANIFEST.csv --out results/``: render many studies on a Dask distributed cluster."""

from __future__ import annotations


def register(sub):
    p = sub.add_parser("batch", help="render every study of a manifest CSV on Dask (resumable; errors recorded)")
    p.add_argument("manifest", help="CSV with columns id, path, settings (JSON or a .json path), outputs "
                   "(png;slices;mesh;mp4)")
    p.add_argument("--out", required=True, help="results folder: one folder per study and results.csv")
    p.add_argument("--scheduler", help="address of a running Dask scheduler (default: a LocalCluster)")
    p.add_argument("--workers", type=int, default=2, help="LocalCluster worker processes (default 2)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    return p


def run(args):
    from volumen.scale import run_batch

    rows = run_batch(args.manifest, args.out, scheduler=args.scheduler, workers=args.workers,
                     progress=not args.no_progress)
    counts = {}
    for r in rows:
        counts[r["status"]] = counts.get(r["status"], 0) + 1
    print(f"{len(rows)} studies: " + ", ".join(f"{n} {s}" for s, n in sorted(counts.items()))
          + f"; table in {args.out}/results.csv")
    for r in rows:
        if r["status"] == "error":
            print(f"  {r['id']}: {r['error']}")
    warned = sum(1 for r in rows if r.get("warnings"))
    if warned:
        print(f"  studies drawn with warnings from their readers: {warned} (the warnings column)")
    return 1 if counts.get("error") else 0
