"""Recently opened files, kept in a small JSON file (plain Python, no Qt).

The list lives in ``recent.json`` of volumen's configuration folder (``$VOLUMEN_CONFIG_DIR``, else
``$XDG_CONFIG_HOME/volumen``, else ``~/.config/volumen``; ``servers.toml`` sits beside it), newest first,
at most :data:`MAX_RECENT` entries,
written atomically.
"""

from __future__ import annotations

import json
from pathlib import Path

__all__ = ["RecentFiles", "MAX_RECENT", "config_dir"]

MAX_RECENT = 10


def config_dir() -> Path:
    """Where the application keeps its settings (``volumen.pacs.config_dir``: one definition)."""
    from ..pacs import config_dir as _config_dir

    return _config_dir()


class RecentFiles:
    """The list of recent paths; a missing or unreadable file is an empty list, never an error."""

    def __init__(self, path: Path | None = None):
        self.path = Path(path) if path is not None else config_dir() / "recent.json"
        try:
            items = json.loads(self.path.read_text(encoding="utf-8"))
            self.items = [str(p) for p in items if isinstance(p, str)][:MAX_RECENT]
        except (OSError, ValueError):
            self.items = []

    def add(self, path: str) -> None:
        """Put ``path`` first and save (failures to save are ignored: the list is a convenience)."""
        from ._session import write_atomic

        path = str(path)
        self.items = [path] + [p for p in self.items if p != path]
        self.items = self.items[:MAX_RECENT]
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(self.path, json.dumps(self.items, indent=1))
        except OSError:
            pass
