"""The ray caster's cached kernels carry the stamp of every source they are compiled from, wherever Numba puts
them (``volumen.jit._stamp``)."""

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
