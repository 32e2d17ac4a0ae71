"""Fixtures of the raster tests: a headless OpenGL context (or a clean skip saying why), small volumes."""

from __future__ import annotations

import numpy as np
import pytest

from tests.render.raster.raster_helpers import blob_volume


@pytest.fixture(scope="session")
def gl():
    """The raster module's headless context, checked on a 16x16 target; skips with the reason when none."""
    from volumen.render.raster import RasterUnavailable, get_context, on_gl_thread
    from volumen.render.raster._context import Target

    def probe():  # OpenGL objects live on the library's one OpenGL thread
        ctx = get_context()
        with Target(ctx, (16, 16), [(4, "f4")]) as t:
            t.use()
            t.fbo.clear(0.25, 0.5, 0.75, 1.0)
            return ctx, t.read()

    try:
        ctx, px = on_gl_thread(probe)
    except RasterUnavailable as exc:
        print(f"raster tests skipped: {exc}")
        pytest.skip(f"no OpenGL context: {exc}")
    assert np.allclose(px, [0.25, 0.5, 0.75, 1.0]), "the 16x16 test target does not hold its clear colour"
    return ctx


@pytest.fixture(scope="session")
def raster_dir(output_dir):
    d = output_dir / "raster"
    d.mkdir(exist_ok=True)
    return d


@pytest.fixture(scope="session")
def blob():
    return blob_volume()
