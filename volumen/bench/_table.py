"""Benchmark results as a printed table and a JSON file; the one place both formats are made."""

from __future__ import annotations

import json
import os
import platform
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["Table", "machine_info", "median_time", "resolve_device", "WARMUP_FRAMES"]

#: untimed frames before a ray-casting case is timed: the first compiles and fills the per-volume caches, the
#: second builds the cells of the transfer function (``render.raycast._cells``, built from the second frame
#: with the same visible entries), which a timed frame would otherwise pay for
WARMUP_FRAMES = 2


def machine_info() -> dict[str, Any]:
    """Facts that make a timing comparable: CPU count, Python, numpy and numba versions, threads."""
    import numpy

    info = {"python": platform.python_version(), "machine": platform.machine(), "cpus": os.cpu_count(),
            "numpy": numpy.__version__, "date": time.strftime("%Y-%m-%d %H:%M:%S")}
    try:
        import numba

        info["numba"] = numba.__version__
        info["numba_threads"] = numba.get_num_threads()
    except ImportError:  # pragma: no cover - numba is a dependency
        pass
    return info


def resolve_device(device: str) -> tuple[str, str]:
    """``(device, description)`` for a ray-casting benchmark: ``auto`` resolved; ``cuda`` checked at once, so a
    machine without a CUDA device fails before any volume is built (``CudaUnavailableError``, which says why)."""
    from volumen.render import resolve_device as resolve

    device = resolve(device, "raycast")
    if device == "cuda":
        from volumen.render.cuda import require_cuda

        return "cuda", f"CUDA {require_cuda()}"
    return device, device.upper()


def median_time(fn, repeat: int = 3, warmup: int = 1) -> float:
    """Median wall-clock seconds of ``fn()`` over ``repeat`` runs after ``warmup`` untimed runs."""
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    times.sort()
    return times[len(times) // 2]


class Table:
    """Rows of named values; prints as an aligned text table and saves as JSON.

    Parameters
    ----------
    title : str
    columns : sequence of (key, header, format) where format is a ``str.format`` spec such as ``".1f"``.
    """

    def __init__(self, title: str, columns: Sequence[tuple[str, str, str]]):
        self.title = title
        self.columns = list(columns)
        self.rows: list[dict[str, Any]] = []
        self.notes: list[str] = []

    def add(self, **row) -> dict[str, Any]:
        self.rows.append(row)
        return row

    def _cell(self, row, key, fmt) -> str:
        v = row.get(key)
        if v is None:
            return "-"
        if isinstance(v, float) and v != v:
            return "-"
        try:
            return format(v, fmt)
        except (TypeError, ValueError):
            return str(v)

    def render(self) -> str:
        """The table as markdown-compatible text (pipes), ready for a closing note."""
        heads = [h for _k, h, _f in self.columns]
        cells = [[self._cell(r, k, f) for k, _h, f in self.columns] for r in self.rows]
        widths = [max([len(h)] + [len(c[i]) for c in cells]) for i, h in enumerate(heads)]

        def line(vals):
            return "| " + " | ".join(v.rjust(w) for v, w in zip(vals, widths, strict=True)) + " |"

        out = [f"### {self.title}", "", line(heads), "|" + "|".join("-" * (w + 2) for w in widths) + "|"]
        out += [line(c) for c in cells]
        out += [""] + [f"- {n}" for n in self.notes]
        return "\n".join(out)

    def to_dict(self) -> dict[str, Any]:
        return {"title": self.title, "machine": machine_info(), "columns": [k for k, _h, _f in self.columns],
                "rows": self.rows, "notes": self.notes}

    def save(self, path: str | os.PathLike) -> Path:
        """Write the table as JSON (and the text beside it as ``.md``); returns the JSON path."""
        p = Path(path)
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(json.dumps(self.to_dict(), indent=2, default=float))
        p.with_suffix(".md").write_text(self.render() + "\n")
        return p
