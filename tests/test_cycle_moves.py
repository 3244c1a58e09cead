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
    import ght_cad.app.batch as batch
    import ght_cad.app.design.step_input as step_input
    import ght_cad.core.workers as workers
    from ght_cad.app.batch import map_step_faces

    assert map_step_faces is step_input.map_step_faces is batch.map_step_faces
    assert "map_step_faces" in batch.__all__
    for name in ("_one_line", "_limit_threads", "_worker_threads", "_dask_client"):
        assert getattr(batch, name) is getattr(workers, name), name


def test_importing_batch_does_not_load_the_design_package() -> None:
    """``ght_cad.app.batch`` gives ``map_step_faces`` on first use only (the design package stays unloaded)."""
    code = (
        "import sys, json, ght_cad.app.batch as b\n"
        "before = 'ght_cad.app.design' in sys.modules\n"
        "f = b.map_step_faces\n"
        "print(json.dumps([before, 'ght_cad.app.design.step_input' in sys.modules, f.__module__]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert json.loads(out.stdout) == [False, True, "ght_cad.app.design.step_input"]


def test_sheet_forming_names_resolve_from_sheet() -> None:
    """Cycle flat_pattern -> sheet -> flat_pattern: the forming rows' presentation (row, table text,
    roll chart) moved to ``ght_cad.pattern.forming``; the sheet reads the pattern model and the face
    pieces (``ght_cad.pattern.model``, ``ght_cad.faces``) directly."""
    import ght_cad.pattern.forming as forming
    import ght_cad.sheetmetal.sheet as sheet
    from ght_cad.sheetmetal.sheet import FormingRow, forming_table_text, plot_roll_chart  # noqa: F401 - the old import works

    for name in ("FormingRow", "forming_table_text", "plot_roll_chart", "_fmt_r"):
        assert getattr(sheet, name) is getattr(forming, name), name
    assert {"FormingRow", "forming_table_text", "plot_roll_chart"} <= set(sheet.__all__)
    assert FormingRow.__module__ == "ght_cad.pattern.forming"


def test_ruled_development_names_resolve_from_unroll() -> None:
    """Cycles unroll <-> sheet and unroll <-> join_panels: the development of one ruled surface moved
    from ``ght_cad.unroll`` to ``ght_cad.ruled_development``; ``ght_cad.unroll`` gives every moved name."""
    import ght_cad.unrolling.ruled_development as rd
    import ght_cad.unrolling.unroll as un
    from ght_cad.unrolling.unroll import RuledDevelopment, _smooth_pieces, metric_angles, ruled_area  # noqa: F401 - old imports

    moved = ["DEFAULT_TOL_DEG", "RULED_EDGE_UV", "RuledDevelopment", "_PanelSeries", "_check_developable", "_chebint",
             "_clenshaw", "_coefficients", "_cheb_rows_of", "_fd5", "_frame", "_initial_edges", "_metric_samples",
             "_panel_nodes", "_ruled_edges", "_smooth_pieces", "broadcast_uv", "first_nodes", "metric_angles",
             "metric_stencil", "ruled_area", "_N", "_K", "_X", "_V", "_VI", "_INT", "_ONES", "_EDGES0"]
    for name in moved:
        assert getattr(un, name) is getattr(rd, name), name
    assert set(un.__all__) == {"unroll", "unroll_composite", "unroll_ruled", "ruled_area", "RuledDevelopment",
                               "DEFAULT_TOL_DEG"}
    assert callable(un) and un.unroll_ruled.__module__ == "ght_cad.unrolling.unroll"


def test_unroll_ruled_without_a_sheet_is_the_ruled_development() -> None:
    """``unroll_ruled`` without a sheet (or with a zero thickness) gives exactly ``unroll_ruled_surface``'s
    pattern: the same outline polylines, bit for bit, on a cone frustum."""
    import numpy as np

    from ght_cad import GHTCurve
    from ght_cad.unrolling.ruled_development import unroll_ruled_surface
    from ght_cad.sheetmetal.sheet import make_sheet
    from ght_cad.surfaces.ruled import CurvePairRuledSurface
    from ght_cad.unrolling.unroll import unroll_ruled

    surf = CurvePairRuledSurface(GHTCurve([(1, 0, 0), (1, 1, 0), (0, 1, 0)], gamma=-1),
                                 GHTCurve([(2, 0, 3), (2, 2, 3), (0, 2, 3)], gamma=-1))
    ref = unroll_ruled_surface(surf, rulings=4, samples=33).panels[0].loop_polylines()
    for sheet in (None, make_sheet(0.0)):
        got = unroll_ruled(surf, rulings=4, samples=33, sheet=sheet).panels[0].loop_polylines()
        assert len(got) == len(ref) and all(np.array_equal(g, r) for g, r in zip(got, ref))
