"""A seeded fuzz campaign: make mutants, load each in a worker process, count outcomes per family.

Mutant ``k`` of a campaign with seed ``s`` is fully decided by ``(s, k)``: its family is
``FAMILIES[k % len(families)]`` and a ``random.Random(f"{s}:{k}")`` picks the seed file,
the file to edit and the mutation, so :func:`make_mutant` rebuilds any finding.

Workers (:mod:`._worker`) are persistent processes, restarted after a crash or a hang;
each mutant is written to its worker's own folder, next to nothing else, and a canary
file lies outside every such folder for the header edits to point at.
"""

from __future__ import annotations

import json
import os
import random
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from . import _fields, _mutate
from ._seeds import FAMILIES, Seed, build_seeds

__all__ = ["OUTCOMES", "Mutant", "Finding", "Report", "make_mutant", "run_campaign"]

OUTCOMES = ("ok", "typed", "untyped", "hang", "out-of-memory", "crash", "outside-path")
_TEXT_KIND = {"nrrd": "nrrd", "nhdr": "nrrd", "mha": "metaimage", "mhd": "metaimage", "vtk": "vtk"}


@dataclass
class Mutant:
    index: int
    family: str
    seed: str
    files: dict[str, bytes]
    main: str
    options: dict
    what: str


@dataclass
class Finding:
    index: int
    family: str
    seed: str
    what: str
    outcome: str
    detail: str


@dataclass
class Report:
    counts: dict[str, Counter] = field(default_factory=dict)
    findings: list[Finding] = field(default_factory=list)
    seconds: float = 0.0

    def bad(self) -> list[Finding]:
        return [f for f in self.findings if f.outcome not in ("ok", "typed")]

    def table(self) -> str:
        head = f"{'family':8s}" + "".join(f"{o:>14s}" for o in OUTCOMES) + f"{'total':>8s}"
        rows = [head]
        total = Counter()
        for fam, c in self.counts.items():
            total.update(c)
            rows.append(f"{fam:8s}" + "".join(f"{c[o]:14d}" for o in OUTCOMES) + f"{sum(c.values()):8d}")
        rows.append(f"{'all':8s}" + "".join(f"{total[o]:14d}" for o in OUTCOMES) + f"{sum(total.values()):8d}")
        return "\n".join(rows)


def _mutations(family: str):
    ops = list(_mutate.GENERIC)
    if family in _TEXT_KIND:
        ops += [_mutate.text_edit(_TEXT_KIND[family])] * 4
    special = {"nifti": _fields.nifti_field, "npy": _fields.npy_field, "npz": _fields.npz_member,
               "dicom": _fields.dicom_field}.get(family)
    if special is not None:
        ops += [special] * 4
    return ops


def make_mutant(seeds: dict[str, list[Seed]], campaign_seed: int, k: int, ctx: _mutate.Context) -> Mutant:
    families = [f for f in FAMILIES if seeds.get(f)]
    family = families[k % len(families)]
    rng = random.Random(f"{campaign_seed}:{k}")
    seed = rng.choice(seeds[family])
    files, options = dict(seed.files), dict(seed.options)
    if family == "raw" and rng.random() < 0.3:
        options, what = _fields.raw_options(rng, options)
    else:
        # the main file most of the time; a data file of a detached header sometimes
        name = seed.main if rng.random() < 0.8 or len(files) == 1 else rng.choice(sorted(files))
        op = rng.choice(_mutations(family) if name == seed.main else _mutate.GENERIC)
        if op is _fields.dicom_field:
            others = tuple(s.files[s.main] for s in seeds[family] if s is not seed)
            files[name], what = op(rng, files[name], ctx, others=others)
        else:
            files[name], what = op(rng, files[name], ctx)
        what = f"{name}: {what}"
    return Mutant(k, family, seed.name, files, seed.main, options, what)


class _Worker:
    def __init__(self, folder: Path, memory: int):
        self.folder, self.memory = folder, memory
        self.proc: subprocess.Popen | None = None
        self.mutant: Mutant | None = None
        self.deadline = 0.0

    def start(self) -> None:
        env = dict(os.environ, VOLUMEN_FUZZ_MEMORY=str(self.memory), PYTHONFAULTHANDLER="")
        root = str(Path(__file__).resolve().parents[3])
        env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
        self.proc = subprocess.Popen([sys.executable, "-m", "tools.fuzz.io._worker"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env, cwd=self.folder.parent,
                                     text=True, bufsize=1)

    def send(self, mutant: Mutant, timeout: float) -> None:
        if self.proc is None or self.proc.poll() is not None:
            self.start()
        shutil.rmtree(self.folder, ignore_errors=True)
        self.folder.mkdir(parents=True)
        for name, data in mutant.files.items():
            (self.folder / name).write_bytes(data)
        task = {"path": mutant.main, "folder": str(self.folder), "options": mutant.options}
        self.mutant, self.deadline = mutant, time.monotonic() + timeout
        self.proc.stdin.write(json.dumps(task) + "\n")
        self.proc.stdin.flush()

    def receive(self) -> tuple[str, str]:
        line = self.proc.stdout.readline()
        if line:
            result = json.loads(line)
            return result["outcome"], result["detail"]
        code = self.proc.wait()
        self.proc = None
        name = signal.Signals(-code).name if code < 0 and -code in signal.Signals._value2member_map_ else str(code)
        return "crash", f"worker died ({name})"

    def kill(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None

    def stop(self) -> None:
        if self.proc is not None:
            self.proc.stdin.close()
            try:
                self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.kill()
            self.proc = None


def run_campaign(n: int, *, seed: int = 0, families=FAMILIES, workers: int = 2, timeout: float = 10.0,
                 memory: int = 4 << 30, keep: Path | None = None, progress=None) -> Report:
    """Load ``n`` mutants (spread evenly over ``families``) and count their outcomes.

    ``keep``: a folder where every mutant whose outcome is not ok/typed is written
    (``<index>-<outcome>/``) to be reproduced by hand.
    """
    seeds = build_seeds(families)
    report = Report(counts={f: Counter() for f in FAMILIES if seeds.get(f)})
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="volumen-fuzz-") as tmp:
        root = Path(tmp)
        (root / "outside").mkdir()
        (root / "outside" / "canary.raw").write_bytes(bytes(4096))
        ctx = _mutate.Context("../outside/canary.raw", str(root / "outside" / "canary.raw"))
        pool = [_Worker(root / f"w{i}", memory) for i in range(workers)]
        todo = iter(range(n))
        busy: dict[int, _Worker] = {}
        try:
            for w in pool:
                _next(w, todo, seeds, seed, ctx, timeout, busy)
            while busy:
                _collect(busy, todo, seeds, seed, ctx, timeout, report, keep, progress)
        finally:
            for w in pool:
                w.stop()
    report.seconds = time.monotonic() - start
    return report


def _next(w: _Worker, todo, seeds, seed, ctx, timeout, busy) -> None:
    k = next(todo, None)
    if k is None:
        return
    w.send(make_mutant(seeds, seed, k, ctx), timeout)
    busy[w.proc.stdout.fileno()] = w


def _collect(busy, todo, seeds, seed, ctx, timeout, report: Report, keep, progress) -> None:
    now = time.monotonic()
    wait = max(0.0, min(w.deadline for w in busy.values()) - now)
    ready, _, _ = select.select(list(busy), [], [], wait)
    done = []
    for fd in ready:
        w = busy[fd]
        done.append((w, *w.receive()))
    for fd, w in list(busy.items()):
        if fd not in ready and time.monotonic() > w.deadline:
            w.kill()
            done.append((w, "hang", f"no answer in {timeout:g} s"))
    for w, outcome, detail in done:
        busy.pop(next(fd for fd, x in busy.items() if x is w))
        m = w.mutant
        report.counts[m.family][outcome] += 1
        if outcome not in ("ok", "typed"):
            report.findings.append(Finding(m.index, m.family, m.seed, m.what, outcome, detail))
            if keep is not None:
                _keep(Path(keep) / f"{m.index}-{outcome}", m)
        if progress is not None:
            progress(m, outcome, detail)
        _next(w, todo, seeds, seed, ctx, timeout, busy)


def _keep(folder: Path, m: Mutant) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    for name, data in m.files.items():
        (folder / name).write_bytes(data)
    (folder / "mutant.json").write_text(json.dumps({"index": m.index, "family": m.family, "seed": m.seed,
                                                    "main": m.main, "options": m.options, "what": m.what}))
