"""docs/notebook.ipynb runs from top to bottom without errors and its outputs hold the pictures."""

from __future__ import annotations

import base64
import io
from pathlib import Path

import numpy as np
import pytest

NOTEBOOK = Path(__file__).resolve().parents[2] / "docs" / "notebook.ipynb"


def test_the_docs_notebook_executes_and_shows_pictures(output_dir):
    nbformat = pytest.importorskip("nbformat", reason="nbformat is not installed (the 'test' extra has it)")
    nbclient = pytest.importorskip("nbclient", reason="nbclient is not installed (the 'test' extra has it)")
    pytest.importorskip("ipykernel", reason="ipykernel is not installed (the 'test' extra has it)")
    from PIL import Image as PILImage

    nb = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                     resources={"metadata": {"path": str(NOTEBOOK.parent)}})
    client.execute()  # raises CellExecutionError on any error
    nbformat.write(nb, output_dir / "notebook_executed.ipynb")
    pictures = []
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            assert out.get("output_type") != "error", out
            png = out.get("data", {}).get("image/png")
            if png:
                pictures.append(np.asarray(PILImage.open(io.BytesIO(base64.b64decode(png))).convert("RGB")))
            elif "data:image/png;base64," in out.get("data", {}).get("text/html", ""):
                pictures.append(None)  # the Volume's table with its montage
    # volume montage (html), render, lighting, endoscopy, mesh, viewer (widget + png), mip, command line
    assert len(pictures) >= 8, len(pictures)
    for pic in pictures:
        if pic is not None:
            assert pic.size and (pic.max(axis=2) > 10).mean() > 0.02  # each picture shows something
