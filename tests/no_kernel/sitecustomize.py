"""Put this folder first on PYTHONPATH to simulate a core-only environment (FreeCAD's Python):
importing any module named in ``GHT_BLOCK_MODULES`` (comma-separated top-level names; default
``OCP,build123d,cadquery``) raises ``ModuleNotFoundError`` as if it were not installed."""

from __future__ import annotations

import os
import sys

_BLOCKED = frozenset(filter(None, os.environ.get("GHT_BLOCK_MODULES", "OCP,build123d,cadquery").split(",")))


class _Blocker:
    """A meta-path finder that refuses the blocked top-level modules and their submodules."""

    @staticmethod
    def find_spec(name: str, path: object = None, target: object = None) -> None:
        if name.split(".")[0] in _BLOCKED:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None


sys.meta_path.insert(0, _Blocker())
