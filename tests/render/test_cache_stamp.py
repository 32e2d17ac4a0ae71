"""The ray caster's cached kernels carry the stamp of every source they are compiled from, wherever Numba puts
them (``volumen.jit._stamp``), and the markers that say a kernel is cached sit beside them (``render._ready``)."""

from __future__ import annotations


def test_an_install_the_user_cannot_write_to_caches_stamped_kernels_in_the_user_folder(monkeypatch, tmp_path):
    """Where ``__pycache__`` beside the sources is not writable and ``NUMBA_CACHE_DIR`` is not set, Numba caches in
    the user's cache folder: the kernel there is keyed on its whole group of sources too, not on its own file."""
    import numba
    from numba.core import caching

    from volumen.jit import source_stamp, stamped_with
    from volumen.render.raycast import _march

    monkeypatch.setattr(numba.config, "CACHE_DIR", "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    monkeypatch.setattr(caching.InTreeCacheLocator, "from_function", classmethod(lambda cls, f, p: None))
    impl = caching.CompileResultCacheImpl(_march._trace_tiles.py_func)
    locator = impl.locator
    assert type(locator).__module__ == "volumen.jit._stamp"
    assert isinstance(locator, caching.UserWideCacheLocator)
    assert locator.get_cache_path().startswith(str(tmp_path))
    group = stamped_with(_march.__file__)
    assert len(group) > 10 and locator.get_source_stamp() == source_stamp(group)


def test_kernel_markers_go_to_the_user_folder_when_the_tree_is_not_writable(monkeypatch, tmp_path):
    """The stand-ins' markers (``render._ready``: this kernel is in Numba's cache) sit beside Numba's cache: with
    ``__pycache__`` not writable, in the user's cache folder, where a later session finds them."""
    from pathlib import Path

    import numba
    from numba.core import caching

    from volumen.render import _ready
    from volumen.render.raycast import _march

    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(numba.config, "CACHE_DIR", "")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert _ready.marker_dir().parent.name == "__pycache__"  # a writable tree: beside the sources
    monkeypatch.setattr(_ready, "_writable", lambda folder: False)
    monkeypatch.setattr(caching.InTreeCacheLocator, "from_function", classmethod(lambda cls, f, p: None))
    where = _ready.marker_dir()
    numba_root = Path(caching.CompileResultCacheImpl(_march._trace_tiles.py_func).locator.get_cache_path())
    assert where.parent == tmp_path / "numba" and numba_root.is_relative_to(where.parent)
    monkeypatch.setattr(_ready, "_READY", set())
    _ready.note_ready(("a kernel key of this test",))
    monkeypatch.setattr(_ready, "_READY", set())  # a later session: only the marker is left
    assert _ready.is_ready(("a kernel key of this test",)) and len(list(where.glob("*"))) == 1
