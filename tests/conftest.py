"""Shared fixtures: tests generate their own data; outputs go to test-output/."""

from __future__ import annotations

import os
import time
from pathlib import Path

import pytest

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

ROOT = Path(__file__).resolve().parents[1]


def pytest_configure(config):
    """The kernel cache folder is fixed before any test moves ``VOLUMEN_CACHE_DIR`` to a temporary archive cache
    (``volumen.jit.kernel_folder``: read once per process), and workers compile each cached Numba kernel once
    between them (tests/compile_lock.py)."""
    from volumen.jit import kernel_folder

    kernel_folder()
    if os.environ.get("VOLUMEN_COMPILE_LOCK", "1") != "0":
        from tests.compile_lock import install

        install()


@pytest.fixture(autouse=True)
def no_stand_in(monkeypatch):
    """Viewers draw their first picture on the CPU here (``volumen.render._standin``;
    ``tests/render/raster/test_standin.py`` turns the stand-in on): it starts a child process per kernel not yet
    drawn in a process, seconds each across the suite, and would make OpenGL draw the first frame of every viewer
    under test."""
    monkeypatch.setenv("VOLUMEN_STANDIN", "0")


#: the longest single tests, collected late by name, go first, so one worker runs them while the other starts on the
#: rest and neither waits for them at the end: the README's commands in order (about 2 minutes warm) and the CUDA
#: kernels compiled to PTX (about 1 minute where their sources changed since the last run)
FIRST = ("tests/test_readme.py::", "tests/render/test_cuda_backend.py::test_kernels_compile_to_ptx")


def pytest_collection_modifyitems(session, config, items):
    """:data:`FIRST` first, every other test in its collected order."""
    items.sort(key=lambda item: not item.nodeid.startswith(FIRST))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """With ``VOLUMEN_TEST_TIMELINE=FILE``: one line per test, ``worker start end nodeid`` (epoch seconds), to
    see where a run's time goes (idle workers at the end, long tests, compiles)."""
    path = os.environ.get("VOLUMEN_TEST_TIMELINE")
    t0 = time.time()
    yield
    if path:
        with open(path, "a", encoding="utf-8") as f:
            f.write(f"{os.environ.get('PYTEST_XDIST_WORKER', 'main')}\t{t0:.2f}\t{time.time():.2f}\t{item.nodeid}\n")


@pytest.fixture(scope="session")
def output_dir() -> Path:
    """A folder kept after the run (test-output/) for pictures worth looking at."""
    d = ROOT / "test-output"
    d.mkdir(exist_ok=True)
    return d


@pytest.fixture(scope="session")
def archive(tmp_path_factory):
    """A running Orthanc (Debian's package, free local ports, temporary storage) holding the test studies and
    pydicom's files (tests/pacs/archive_data.py); stopped at the end. Skips, saying why, without Orthanc."""
    from tests.pacs.archive_data import running_archive

    yield from running_archive(tmp_path_factory)


@pytest.fixture
def archive_config(archive, tmp_path, monkeypatch):
    """``archive`` named ``archive`` in a servers.toml under a temporary XDG_CONFIG_HOME (the password in an
    environment variable) and an empty temporary cache; returns the servers.toml path."""
    from tests.pacs.archive_data import PASSWORD_ENV, write_servers_toml
    from tests.pacs.orthanc_server import PASSWORD

    monkeypatch.delenv("VOLUMEN_CONFIG_DIR", raising=False)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    monkeypatch.setenv("VOLUMEN_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setenv(PASSWORD_ENV, PASSWORD)
    return write_servers_toml(tmp_path / "config", archive.server)
