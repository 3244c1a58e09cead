"""GHT workbench for FreeCAD: parametric GHT-Bézier curves, developables and flat patterns.

Importing this package (FreeCAD does it at start-up for every ``freecad.<name>`` namespace
package in a ``Mod`` folder) only makes the ``ght_cad`` core importable: if it is not installed in
FreeCAD's Python, the repository checkout this addon lives in (``<repo>/freecad_workbench``) is put
on ``sys.path``. The core needs numpy and scipy only; build123d/OCP are never imported here.
"""

from __future__ import annotations

import os
import sys

__version__ = "0.1.0"

WB_DIR = os.path.dirname(os.path.realpath(__file__))
ICON_DIR = os.path.join(WB_DIR, "icons")


def icon(name: str) -> str:
    """Absolute path of the SVG icon ``name`` (without extension)."""
    return os.path.join(ICON_DIR, name + ".svg")


def _ensure_core() -> None:
    """Make ``import ght_cad`` work: installed package first, else the enclosing repository."""
    try:
        import ght_cad  # noqa: F401

        return
    except ImportError:
        pass
    repo = os.path.realpath(os.path.join(WB_DIR, "..", "..", ".."))
    if os.path.isfile(os.path.join(repo, "ght_cad", "__init__.py")) and repo not in sys.path:
        sys.path.insert(0, repo)


_ensure_core()
