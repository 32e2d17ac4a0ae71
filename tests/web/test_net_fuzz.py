"""A bounded slice of the network fuzz campaign (``make fuzz-net`` runs the long one): 2,000 mutated requests
to a viewer server in a process of its own, 120 mutated DICOMweb answers and 8 mutated C-FIND responses to
``volumen pacs`` (seed 7). None may
end in a 5xx, a hang, a crash, memory over the budget, the token or the patient in the server's log, or a control
character in a table. About 45 s on two cores; each surface's table is printed (``pytest -s``)."""

from __future__ import annotations

from tools.fuzz.net._campaign import run_dimse_replies, run_replies, run_requests

SEED = 7


def _problems(report, n: int, answered: str) -> list[str]:
    """What is wrong with a campaign's ``report`` of ``n`` mutants: a count that does not add up, too few mutants
    reaching the checks (``answered``: the outcome of a refused mutant) or none passing them, and every bad
    outcome (empty: all is well); its table is printed."""
    print(f"\n{report.table()}")
    total = report.total
    problems = [f"bad outcome #{k} {m}: {o} {d} (rebuild with make_request / make_reply, seed {SEED})"
                for k, m, o, d in report.findings][:20]
    if sum(c for o, c in total.items() if o != "leak") != n:
        problems.append(f"the outcomes add up to {sum(total.values())}, not {n}")
    if total[answered] < n // 4 or total["ok"] == 0:
        problems.append(f"{total[answered]} {answered} and {total['ok']} ok of {n}: the mutants miss the checks")
    return problems


def test_mutated_requests_to_the_server():
    problems = _problems(run_requests(2000, seed=SEED, threads=8, timeout=20.0), 2000, "4xx")
    assert not problems, "\n".join(problems)


def test_mutated_replies_to_the_archive_client():
    problems = _problems(run_replies(120, seed=SEED), 120, "refused")
    assert not problems, "\n".join(problems)


def test_mutated_c_find_responses_to_the_archive_client():
    problems = _problems(run_dimse_replies(8, seed=SEED), 8, "refused")
    assert not problems, "\n".join(problems)
