"""``python -m tools.fuzz.io [--mutants N] [--seed S]``: run a campaign and print its table.

Exit status 1 when any mutant ended untyped, hung, ran out of memory, crashed the
worker or opened a file outside its folder; each such finding is listed with the
mutant's index (``--keep DIR`` writes those mutants out to reproduce them).
"""

from __future__ import annotations

import argparse
import sys
from collections import Counter
from pathlib import Path

from ._campaign import run_campaign
from ._seeds import FAMILIES


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.fuzz.io", description=__doc__.splitlines()[0])
    ap.add_argument("--mutants", type=int, default=12000, help="number of mutants (default 12000)")
    ap.add_argument("--seed", type=int, default=1, help="campaign seed (default 1)")
    ap.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds before a mutant counts as a hang")
    ap.add_argument("--memory-gib", type=float, default=4.0, help="address-space limit per worker, GiB")
    ap.add_argument("--families", default=",".join(FAMILIES), help="comma-separated subset of " + ",".join(FAMILIES))
    ap.add_argument("--keep", type=Path, help="write the mutants of every finding into this folder")
    ap.add_argument("--show", type=int, default=60, help="findings listed (default 60; by cause)")
    args = ap.parse_args(argv)
    families = tuple(f for f in args.families.split(",") if f)
    unknown = set(families) - set(FAMILIES)
    if unknown:
        ap.error(f"unknown families {sorted(unknown)}; choose from {', '.join(FAMILIES)}")
    report = run_campaign(args.mutants, seed=args.seed, families=families, workers=args.workers,
                          timeout=args.timeout, memory=int(args.memory_gib * (1 << 30)), keep=args.keep)
    print(f"volumen fuzz: {args.mutants} mutants, seed {args.seed}, {args.workers} workers, "
          f"{report.seconds:.0f} s, limits {args.timeout:g} s and {args.memory_gib:g} GiB")
    print(report.table())
    bad = report.bad()
    causes = Counter((f.family, f.outcome, f.detail[:110]) for f in bad)
    if causes:
        print(f"\n{len(bad)} findings, {len(causes)} distinct (family, outcome, cause); first mutant of each:")
    first = {}
    for f in bad:
        first.setdefault((f.family, f.outcome, f.detail[:110]), f)
    for key, count in causes.most_common(args.show):
        f = first[key]
        print(f"  {count:5d}  #{f.index} {f.family} {f.outcome}: {f.detail[:110]}  [{f.seed}; {f.what[:80]}]")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
