"""Names moved to break the import cycles (issue 27) still resolve from their old modules.

Each cycle was broken by moving the piece both sides used into a module below both; the old module
imports it back (or gives it on first use), so every ``from old.module import name`` of before
still works and gives the same object as the new home.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_batch_step_names_resolve_from_batch() -> None:
    """Cycle batch -> design -> design.step_input -> batch: the parallel STEP unroll moved into
    ``ght_cad.design.step_input``, the worker helpers into ``ght_cad.core.workers``."""
    import ght_cad.batch as batch
    import ght_cad.design.step_input as step_input
    import ght_cad.core.workers as workers
    from ght_cad.batch import map_step_faces

    assert map_step_faces is step_input.map_step_faces is batch.map_step_faces
    assert "map_step_faces" in batch.__all__
    for name in ("_one_line", "_limit_threads", "_worker_threads", "_dask_client"):
        assert getattr(batch, name) is getattr(workers, name), name


def test_importing_batch_does_not_load_the_design_package() -> None:
    """``ght_cad.batch`` gives ``map_step_faces`` on first use only (the design package stays unloaded)."""
    code = (
        "import sys, json, ght_cad.batch as b\n"
        "before = 'ght_cad.design' in sys.modules\n"
        "f = b.map_step_faces\n"
        "print(json.dumps([before, 'ght_cad.design.step_input' in sys.modules, f.__module__]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert json.loads(out.stdout) == [False, True, "ght_cad.design.step_input"]


def test_sheet_forming_names_resolve_from_sheet() -> None:
    """Cycle flat_pattern -> sheet -> flat_pattern: the forming rows' presentation (row, table text,
    roll chart) moved to ``ght_cad.pattern.forming``; the sheet reads the pattern model and the face
    pieces (``ght_cad.pattern.model``, ``ght_cad.faces``) directly."""
    import ght_cad.pattern.forming as forming
    import ght_cad.sheet as sheet
    from ght_cad.sheet import FormingRow, forming_table_text, plot_roll_chart  # noqa: F401 - the old import works

    for name in ("FormingRow", "forming_table_text", "plot_roll_chart", "_fmt_r"):
        assert getattr(sheet, name) is getattr(forming, name), name
    assert {"FormingRow", "forming_table_text", "plot_roll_chart"} <= set(sheet.__all__)
    assert FormingRow.__module__ == "ght_cad.pattern.forming"
