"""Two processes writing one Numba cache index at once keep every entry (``volumen.jit._savelock``)."""

from __future__ import annotations

import multiprocessing as mp

KEYS = 100  # without the lock, two such writers kept 228-329 of 400 entries at 200 keys each


def _writer(folder, who, start):
    from numba.core import caching

    import volumen.jit  # noqa: F401 - installs the lock

    f = caching.IndexDataCacheFile(folder, "kernel-1.py311", ("stamp",))
    start.wait()
    for i in range(KEYS):
        f.save((who, i), f"{who}:{i}")


def _run(folder):
    ctx = mp.get_context("spawn")
    start = ctx.Event()
    procs = [ctx.Process(target=_writer, args=(str(folder), w, start)) for w in ("a", "b")]
    for p in procs:
        p.start()
    start.set()
    for p in procs:
        p.join(60)
        assert p.exitcode == 0


def test_concurrent_saves_keep_every_entry(tmp_path):
    from numba.core import caching

    import volumen.jit
    from volumen.jit import _savelock

    assert volumen.jit and _savelock.installed()
    _run(tmp_path)
    f = caching.IndexDataCacheFile(str(tmp_path), "kernel-1.py311", ("stamp",))
    index = f._load_index()
    assert len(index) == 2 * KEYS  # every key of both writers
    assert len(set(index.values())) == 2 * KEYS  # each its own data file
    for w in ("a", "b"):
        for i in range(KEYS):
            assert f.load((w, i)) == f"{w}:{i}"  # and that file holds its own entry
