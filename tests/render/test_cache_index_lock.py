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


# An index written by older sources, naming a type those sources had and these do not (mip's mode tag ``Mip``
# became ``Projection``, and every drawing command failed with an internal error until the cache was deleted).

def _index_naming_a_gone_type(folder, stamp=("old stamp",)):
    """An index file of Numba's format whose signature names ``volumen.jit._savelock.Gone``, which no longer
    exists: written the way Numba writes it, with the type there, and the type then removed."""
    import pickle

    from numba.core import caching

    from volumen.jit import _savelock

    class Gone:
        pass

    Gone.__module__, Gone.__qualname__ = _savelock.__name__, "Gone"
    f = caching.IndexDataCacheFile(str(folder), "kernel-1.py311", ("stamp",))
    _savelock.Gone = Gone
    try:
        data = pickle.dumps((stamp, {((Gone,), "target"): "kernel-1.py311.1.nbc"}), protocol=-1)
    finally:
        del _savelock.Gone
    with open(f._index_path, "wb") as out:
        pickle.dump(f._version, out, protocol=-1)
        out.write(data)
    return f


def test_an_index_naming_a_gone_type_reads_as_stale(tmp_path):
    import pickle

    import pytest

    import volumen.jit  # noqa: F401 - installs the patches

    f = _index_naming_a_gone_type(tmp_path)
    with open(f._index_path, "rb") as raw:
        pickle.load(raw)
        with pytest.raises(AttributeError, match="Gone"):  # what Numba's own _load_index met
            pickle.loads(raw.read())
    assert f._load_index() == {}
    assert f.load(("any", "key")) is None
    f.save(("new", "key"), "machine code")  # written over the old index
    assert f._load_index() == {("new", "key"): "kernel-1.py311.1.nbc"}
    assert f.load(("new", "key")) == "machine code"


_KERNEL = '''
from numba import njit


@njit(cache=True)
def twice(x):
    return 2 * x
'''

_CALL = '''
import volumen.jit  # noqa: F401
import kernel_module
print(kernel_module.twice(21))
'''


def test_a_cached_kernel_over_an_index_of_older_sources_compiles_again(tmp_path):
    """End to end: a cached function whose index names a type gone since compiles and saves a readable index."""
    import os
    import subprocess
    import sys

    (tmp_path / "kernel_module.py").write_text(_KERNEL)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]))
    env.pop("NUMBA_CACHE_DIR", None)

    def call():
        out = subprocess.run([sys.executable, "-c", _CALL], cwd=tmp_path, env=env, capture_output=True, text=True,
                             timeout=120)
        assert out.returncode == 0, out.stderr[-2000:]
        return out.stdout.strip()

    assert call() == "42"  # compiled and cached
    cache = tmp_path / "__pycache__"
    (index,) = cache.glob("kernel_module.twice-*.nbi")
    old = _index_naming_a_gone_type(cache)
    os.replace(old._index_path, index)
    assert call() == "42"  # the old index read as stale: compiled again, not an AttributeError
    assert call() == "42"  # and the index it saved is read back
