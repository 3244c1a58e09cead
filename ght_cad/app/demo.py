"""``ght-cad demo``: the whole pipeline on the embedded default design.

The default design (``ght_cad/data/default_design.toml``) is run through
:func:`ght_cad.app.design.run_design`; see that function for the list of outputs.
"""

from __future__ import annotations

import os
from typing import Any

__all__ = ["run_demo", "default_design_text", "DEFAULT_DESIGN"]

DEFAULT_DESIGN = "default_design.toml"


def default_design_text() -> str:
    """The embedded default design file (TOML text)."""
    from importlib import resources

    return resources.files("ght_cad").joinpath("data", DEFAULT_DESIGN).read_text(encoding="utf-8")


def run_demo(out_dir: str | os.PathLike, *, progress: bool = True, quick: bool = False, wait: bool = False,
             timeout: float | None = None, chord_tol: float | None = None) -> dict[str, Any]:
    """Run the embedded default design into ``out_dir`` and return the report dictionary.

    Args:
        out_dir: output folder (created if missing; files in it are replaced atomically).
        progress: draw progress on stderr when it is a terminal.
        quick: fewer optimizer iterations (smoke tests).
        wait, timeout: wait (at most ``timeout`` s) while another process writes ``out_dir``
            instead of refusing (see :func:`ght_cad.app.design.run_design`).
        chord_tol: DXF/SVG outline chord tolerance in mm (None: 1e-3 mm).

    Returns:
        The report (also written as ``report.json`` and ``report.md``).

    Raises:
        GHTError: the embedded design is invalid (a bug), its geometry degenerates, or ``chord_tol``
            is not > 0.
    """
    from .design import parse_design_text, run_design

    design = parse_design_text(default_design_text(), source=f"<embedded {DEFAULT_DESIGN}>")
    if quick and design.optimize is not None:
        design.optimize.iterations = min(design.optimize.iterations, 10)
    return run_design(design, out_dir, progress=progress, wait=wait, timeout=timeout, chord_tol=chord_tol)
