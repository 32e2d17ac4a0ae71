"""``python -m tools.fuzz.net [--requests N] [--replies N] [--dimse N] [--seed S]``: a network fuzz campaign.

Prints a table per surface (the viewer's server, the archive client) and exits 1 when any request or reply
ended badly (a 5xx, a hang, a crash, memory over the budget, the token or the patient in a log, a control
character in a table), listing the first findings with their index (``make_request`` / ``make_reply`` of the
seed and the index rebuild each).
"""

from __future__ import annotations

import argparse
import sys

from ._campaign import run_dimse_replies, run_replies, run_requests


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tools.fuzz.net", description=__doc__.splitlines()[0])
    ap.add_argument("--requests", type=int, default=20000, help="mutated requests to the server (default 20000)")
    ap.add_argument("--replies", type=int, default=5000, help="mutated DICOMweb answers (default 5000)")
    ap.add_argument("--dimse", type=int, default=500, help="mutated C-FIND responses (default 500)")
    ap.add_argument("--seed", type=int, default=1, help="campaign seed (default 1)")
    ap.add_argument("--threads", type=int, default=8, help="connections at a time to the server (default 8)")
    ap.add_argument("--show", type=int, default=30, help="findings listed (default 30)")
    args = ap.parse_args(argv)
    reports = []
    if args.requests:
        reports.append(run_requests(args.requests, seed=args.seed, threads=args.threads))
    if args.replies:
        reports.append(run_replies(args.replies, seed=args.seed))
    if args.dimse:
        reports.append(run_dimse_replies(args.dimse, seed=args.seed))
    bad = 0
    for report in reports:
        print(report.table(), end="\n\n")
        for k, mutation, outcome, detail in report.findings[:args.show]:
            print(f"  {report.surface} #{k} {mutation}: {outcome} {detail}")
        bad += report.bad()
    print(f"volumen net fuzz: seed {args.seed}, {args.requests} requests, {args.replies} DICOMweb and {args.dimse} "
          f"DIMSE replies: {bad} bad outcome(s)")
    return 1 if bad else 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
