"""``ght-cad export``.

Moved from :mod:`ght_cad.app.cli` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .common import _chord_tol, _emit, EXIT_OK, UsageError
from .design import _load


_EXPORT_SUFFIXES = (".step", ".stp", ".dxf", ".svg", ".json", ".png")


def cmd_export(args: argparse.Namespace) -> int:
    """``ght-cad export``: write the design's result to files chosen by suffix."""
    from ..design import export_files

    for f in args.files:
        if Path(f).suffix.lower() not in _EXPORT_SUFFIXES:
            raise UsageError(
                f"cannot export to {f!r}: unknown suffix {Path(f).suffix!r}; allowed: {', '.join(_EXPORT_SUFFIXES)}"
            )
    design = _load(args)
    written = export_files(design, args.files, chord_tol=_chord_tol(args))
    result = {"command": "export", "name": design.name, "outputs": written}
    _emit(args, result, lambda r: "\n".join(f"wrote {v}" for v in r["outputs"].values()))
    return EXIT_OK
