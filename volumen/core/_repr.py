"""How the plain data shows itself in a notebook without drawing: the picture maker is handed in from above.

``Image``, ``Volume`` and ``Mesh`` answer IPython's ``_repr_png_`` / ``_repr_html_`` through
:func:`picture`, which calls the maker registered with :func:`set_picture_maker` (the root package
registers :mod:`volumen.notebook.pictures`, on the notebook floor, loaded the first time a picture is
asked for). With no maker, there is no picture (None: IPython shows the text ``repr``). So ``core``
imports no picture code and no module above it (docs/design.md section 1).
"""

from __future__ import annotations

from collections.abc import Callable

__all__ = ["picture", "set_picture_maker"]

_maker: dict[str, Callable] = {}


def set_picture_maker(make: Callable[[str, object], bytes | str]) -> None:
    """Register ``make(kind, obj)``; ``kind`` names the picture (``"image_png"``, ``"volume_png"``,
    ``"volume_html"``, ``"mesh_png"``)."""
    _maker["make"] = make


def picture(kind: str, obj):
    """The picture ``kind`` of ``obj`` from the registered maker, or None when none is registered."""
    make = _maker.get("make")
    return None if make is None else make(kind, obj)
