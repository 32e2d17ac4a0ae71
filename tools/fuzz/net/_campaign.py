"""A seeded campaign over the network surfaces, counted per surface and mutation.

* **server**: :func:`run_requests` starts the viewer's server in a process of its own (:mod:`._target`), sends
  it mutated requests (:mod:`._mutate_http`) from a few threads, watches that it lives and its memory, and
  reads its log at the end for the token, the cookie's value, the patient's identity and tracebacks;
* **archive client**: :func:`run_replies` points ``volumen.pacs`` (what ``volumen pacs`` runs) at a hostile
  archive (:mod:`._archive`) answering mutated replies (:mod:`._mutate_replies`) and watches what it raises,
  what it would print and the memory.

Bad outcomes (:data:`BAD`): a 5xx, a hang, a crash, memory over the budget, a leak in the log, an escape in a
table. Mutant ``k`` of seed ``s`` is rebuilt from ``(s, k)`` alone.
"""

from __future__ import annotations

import hashlib
import hmac
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections import Counter, defaultdict
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from . import _mutate_dimse, _mutate_http, _mutate_replies
from ._archive import HostileArchive
from ._target import IDENTITY

__all__ = ["Report", "run_requests", "run_replies", "run_dimse_replies", "BAD", "SERVER_OUTCOMES",
           "CLIENT_OUTCOMES"]

SERVER_OUTCOMES = ("ok", "4xx", "closed", "5xx", "hang", "crash", "over-budget", "leak")
CLIENT_OUTCOMES = ("ok", "refused", "crash", "hang", "escape", "over-budget")
BAD = {"5xx", "hang", "crash", "over-budget", "leak", "escape"}


@dataclass
class Report:
    """Counts per mutation and outcome of one surface, the findings ``(index, mutation, outcome, detail)``, the
    peak memory (MiB) and its budget."""

    surface: str
    outcomes: tuple
    counts: dict = field(default_factory=lambda: defaultdict(Counter))
    findings: list = field(default_factory=list)
    peak_mib: float = 0.0
    budget_mib: float = 0.0
    seconds: float = 0.0

    def add(self, k: int, mutation: str, outcome: str, detail: str = "") -> None:
        self.counts[mutation.split("+")[0].split(" ")[0]][outcome] += 1
        if outcome in BAD:
            self.findings.append((k, mutation, outcome, detail))

    @property
    def total(self) -> Counter:
        out = Counter()
        for c in self.counts.values():
            out.update(c)
        return out

    def bad(self) -> int:
        return sum(n for o, n in self.total.items() if o in BAD)

    def table(self) -> str:
        """One row per mutation and a total row; a column per outcome."""
        width = max([len(m) for m in self.counts] + [5])
        head = f"{self.surface:<{width}}  " + "  ".join(f"{o:>11}" for o in self.outcomes)
        rows = [f"{m:<{width}}  " + "  ".join(f"{c[o]:>11}" for o in self.outcomes)
                for m, c in sorted(self.counts.items())]
        total = self.total
        rows.append(f"{'total':<{width}}  " + "  ".join(f"{total[o]:>11}" for o in self.outcomes))
        memory = f"peak memory {self.peak_mib:.0f} MiB (budget {self.budget_mib:.0f} MiB), {self.seconds:.0f} s"
        return "\n".join([head, *rows, memory])


def _rss(pid: int, key: str = "VmRSS") -> float:
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return 0.0
    m = re.search(rf"{key}:\s+(\d+)", text)
    return int(m.group(1)) / 1024 if m else 0.0


class _Target:
    """The server process under attack; restarted after a crash."""

    def __init__(self, folder: Path):
        self.token = os.urandom(16).hex()
        self.folder, self.logs, self.proc = folder, [], None
        self.start()

    def start(self) -> None:
        log = self.folder / f"server-{len(self.logs)}.log"
        self.logs.append(log)
        root = str(Path(__file__).resolve().parents[3])  # the repository: the target is tools.fuzz.net._target
        env = dict(os.environ, PYTHONPATH=root + os.pathsep + os.environ.get("PYTHONPATH", ""))
        self.proc = subprocess.Popen([sys.executable, "-m", "tools.fuzz.net._target", self.token],
                                     stdout=subprocess.PIPE, stderr=log.open("wb"), text=True, env=env)
        self.port = int(self.proc.stdout.readline())
        self.cookie_value = hmac.new(self.token.encode(), b"volumen serve cookie, port " + str(self.port).encode(),
                                     hashlib.sha256).hexdigest()
        info = urllib.request.urlopen(f"http://127.0.0.1:{self.port}/info.json?token={self.token}", timeout=120)
        self.bases = _mutate_http.seeds(self.token, f"volumen-token-{self.port}={self.cookie_value}",
                                        json.loads(info.read()))

    def alive(self) -> bool:
        return self.proc.poll() is None

    def stop(self) -> None:
        if self.alive():
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()

    def leaks(self) -> list[str]:
        """Log lines holding the token, a cookie's value, the patient's identity, or a traceback."""
        secrets = [self.token, self.cookie_value, *IDENTITY, "Traceback"]
        found = []
        for log in self.logs:
            for line in log.read_text(errors="replace").splitlines():
                if any(s.lower() in line.lower() for s in secrets):
                    found.append(line[:200])
        return found


def run_requests(n: int, *, seed: int = 1, threads: int = 8, timeout: float = 20.0, budget_mib: float = 1024.0
                 ) -> Report:
    """Send ``n`` mutated requests to a fresh viewer server; the report of the server surface."""
    report = Report("server", SERVER_OUTCOMES, budget_mib=budget_mib)
    folder = Path(tempfile.mkdtemp(prefix="volumen-netfuzz-"))
    t0 = time.perf_counter()
    target = _Target(folder)
    try:
        batch = threads * 16
        for start in range(0, n, batch):
            ks = range(start, min(n, start + batch))
            mutants = [_mutate_http.make_request(seed, k, target.bases) for k in ks]
            with ThreadPoolExecutor(threads) as pool:
                results = list(pool.map(lambda m: _mutate_http.send(target.port, m[1], timeout), mutants))
            crashed = not target.alive()
            rss = _rss(target.proc.pid, "VmHWM")
            report.peak_mib = max(report.peak_mib, rss)
            for k, (name, _), (outcome, status) in zip(ks, mutants, results, strict=True):
                if crashed and outcome in ("closed", "hang"):
                    outcome = "crash"
                report.add(k, name, "over-budget" if rss > budget_mib else outcome, str(status))
            if crashed:
                target.start()
    finally:
        target.stop()
        report.seconds = time.perf_counter() - t0
    for line in target.leaks():
        report.add(-1, "log", "leak", line)
    shutil.rmtree(folder, ignore_errors=True)
    return report


def _servers_toml(folder: Path, url: str, dimse_port: int = 0) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    dimse = (f'[servers.dimse]\nae_title = "FUZZ"\nhost = "127.0.0.1"\nport = {dimse_port}\ntimeout = 2\n'
             "deadline = 2\nmax_answer_mb = 4\n") if dimse_port else ""
    (folder / "servers.toml").write_text(f'[servers.fuzz]\nurl = "{url}"\ntimeout = 2\ndeadline = 2\n'
                                         "max_answer_mb = 8\nmax_instance_mb = 8\n" + dimse)


def run_replies(n: int, *, seed: int = 1, hang_s: float = 12.0, budget_mib: float = 256.0) -> Report:
    """Answer ``n`` runs of ``volumen pacs`` with mutated replies; the report of the archive client surface (its
    memory: this process's growth over the campaign)."""
    report = Report("archive client", CLIENT_OUTCOMES, budget_mib=budget_mib)
    folder = Path(tempfile.mkdtemp(prefix="volumen-netfuzz-"))
    saved = {k: os.environ.get(k) for k in ("VOLUMEN_CONFIG_DIR", "VOLUMEN_CACHE_DIR")}
    saved_as = resource.getrlimit(resource.RLIMIT_AS)
    t0 = time.perf_counter()
    try:
        with HostileArchive() as archive, HostileArchive() as other:
            _servers_toml(folder / "config", archive.url)
            os.environ["VOLUMEN_CONFIG_DIR"], os.environ["VOLUMEN_CACHE_DIR"] = str(folder / "config"), str(
                folder / "cache")
            elsewhere = other.url.replace("127.0.0.1", "localhost")
            for op, answers in _mutate_replies.OPERATIONS.items():   # unmutated, once: imports are not the memory
                _mutate_replies.run_reply(archive, "fuzz", op, [_mutate_replies.Reply(b(), headers=dict(h))
                                                                for b, h in answers])
            base = _rss(os.getpid())
            # a reply that makes the client allocate without end is a MemoryError (a crash here), not the OOM killer
            resource.setrlimit(resource.RLIMIT_AS, (int((_rss(os.getpid(), "VmSize") + 4 * budget_mib + 1024)
                                                        * 2 ** 20), saved_as[1]))
            for k in range(n):
                name, op, replies = _mutate_replies.make_reply(seed, k, elsewhere)
                shutil.rmtree(folder / "cache", ignore_errors=True)
                (outcome, detail), seconds = _mutate_replies.timed(_mutate_replies.run_reply, archive, "fuzz", op,
                                                                   replies)
                grown = _rss(os.getpid()) - base
                report.peak_mib = max(report.peak_mib, grown)
                if seconds > hang_s:
                    outcome, detail = "hang", f"{seconds:.1f} s"
                report.add(k, name, "over-budget" if grown > budget_mib else outcome, detail)
            if other.paths:
                report.add(-1, "redirect", "crash", f"the other host was asked {len(other.paths)} time(s)")
    finally:
        resource.setrlimit(resource.RLIMIT_AS, saved_as)
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
        report.seconds = time.perf_counter() - t0
        shutil.rmtree(folder, ignore_errors=True)
    return report


def run_dimse_replies(n: int, *, seed: int = 1, hang_s: float = 12.0) -> Report:
    """Answer ``n`` DIMSE searches (C-FIND) with mutated responses; the report of the DIMSE client surface."""
    report = Report("archive client (DIMSE)", CLIENT_OUTCOMES, budget_mib=256.0)
    folder = Path(tempfile.mkdtemp(prefix="volumen-netfuzz-"))
    saved = os.environ.get("VOLUMEN_CONFIG_DIR")
    t0 = time.perf_counter()
    scp = _mutate_dimse.HostileScp()
    try:
        _servers_toml(folder / "config", "http://127.0.0.1:9/dicom-web", scp.port)
        os.environ["VOLUMEN_CONFIG_DIR"] = str(folder / "config")
        base = _rss(os.getpid())
        for k in range(n):
            name, op, responses, pause = _mutate_dimse.make_dimse_reply(seed, k)
            (outcome, detail), seconds = _mutate_replies.timed(_mutate_dimse.run_dimse_reply, scp, "dimse", op,
                                                               responses, pause)
            grown = _rss(os.getpid()) - base
            report.peak_mib = max(report.peak_mib, grown)
            if seconds > hang_s:
                outcome, detail = "hang", f"{seconds:.1f} s"
            report.add(k, name, "over-budget" if grown > report.budget_mib else outcome, detail)
    finally:
        scp.close()
        if saved is None:
            os.environ.pop("VOLUMEN_CONFIG_DIR", None)
        else:
            os.environ["VOLUMEN_CONFIG_DIR"] = saved
        report.seconds = time.perf_counter() - t0
        shutil.rmtree(folder, ignore_errors=True)
    return report
