"""A bounded slice of the fuzz campaign (``make fuzz`` runs the long one).

300 mutants per family of formats (seed 7), each loaded in a worker process limited to
4 GiB of address space and 10 s: none may end untyped, hang, run out of memory, crash
the process or open a file outside the mutant's folder. About 2-4 s per family on two
cores; each family's table is printed (``pytest -s``) for the record.
"""

from __future__ import annotations

import pytest

from tools.fuzz.io import FAMILIES, run_campaign

PER_FAMILY = 300
SEED = 7


@pytest.mark.parametrize("family", FAMILIES)
def test_fuzz_slice_finds_nothing(family):
    report = run_campaign(PER_FAMILY, seed=SEED, families=(family,), workers=2, timeout=10.0, memory=4 << 30)
    print(f"\nfuzz slice {family}: {PER_FAMILY} mutants, seed {SEED}, {report.seconds:.0f} s\n{report.table()}")
    counts = report.counts[family]
    assert sum(counts.values()) == PER_FAMILY
    assert counts["typed"] > 0  # the mutants reach the readers' checks
    bad = [f"#{f.index} {f.outcome}: {f.detail} [{f.seed}; {f.what}]" for f in report.bad()]
    assert not bad, f"{len(bad)} mutants failed (rebuild with tools.fuzz.io.make_mutant):\n" + "\n".join(bad[:20])
