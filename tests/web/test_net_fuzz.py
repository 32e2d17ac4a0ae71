"""A bounded slice of the network fuzz campaign (``make fuzz-net`` runs the long one): 2,000 mutated requests
to a viewer server in a process of its own, 120 mutated DICOMweb answers and 8 mutated C-FIND responses to
``volumen pacs`` (seed 7). None may
end in a 5xx, a hang, a crash, memory over the budget, the token or the patient in the server's log, or a control
character in a table. About 45 s on two cores; each surface's table is printed (``pytest -s``)."""

from __future__ import annotations

from volumen.web.fuzz._campaign import run_dimse_replies, run_replies, run_requests

SEED = 7


def _check(report, n: int, answered: str) -> None:
    print(f"\n{report.table()}")
    total = report.total
    assert sum(n for o, n in total.items() if o != "leak") == n
    assert total[answered] >= n // 4 and total["ok"] > 0   # the mutants reach the checks and some pass them
    bad = [f"#{k} {m}: {o} {d}" for k, m, o, d in report.findings]
    assert not bad, f"{len(bad)} bad outcome(s) (rebuild with make_request / make_reply, seed {SEED}):\n" + "\n".join(
        bad[:20])


def test_mutated_requests_to_the_server():
    _check(run_requests(2000, seed=SEED, threads=8, timeout=20.0), 2000, "4xx")


def test_mutated_replies_to_the_archive_client():
    _check(run_replies(120, seed=SEED), 120, "refused")


def test_mutated_c_find_responses_to_the_archive_client():
    _check(run_dimse_replies(8, seed=SEED), 8, "refused")
