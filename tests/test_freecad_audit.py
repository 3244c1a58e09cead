"""Bad property values in the workbench's features, run inside Debian's FreeCAD (separate process).

``freecadcmd -t freecad.ght_workbench.tests.fc_audit``: a negative/zero/NaN tolerance, coincident
control points, a missing source vertex, one Continuity/K value too few or too many, a non-GHT
segment, optimizer settings out of range: each puts the feature in FreeCAD's error state with exactly
the expected message naming the property and the allowed values (no silent replacement), printed
as one line without a Python traceback, and restoring the value recomputes the same geometry; a
feature in error survives save/reopen; a dependant is never built on a failed input; a bug (an
unexpected exception) keeps its traceback.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_bad_values_inside_freecadcmd(tmp_path: Path) -> None:
    out = run_fc_unittest("freecad.ght_workbench.tests.fc_audit", tmp_path, min_tests=20)
    for cls in ("CurveBadValuesTest", "CompositeBadValuesTest", "SurfaceBadValuesTest", "LinkedPlanesTest", "PlaneWeightsTest",
                "SpineBadValuesTest", "OptimizationBadValuesTest", "ReopenInErrorTest", "ErrorReportingTest"):
        assert cls in out, f"{cls} did not run:\n{out[-3000:]}"
