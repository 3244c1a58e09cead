"""Bad property values in the workbench's features, run inside Debian's FreeCAD (separate process).

``freecadcmd -t freecad.ght_workbench.tests.fc_audit``: a negative/zero/NaN tolerance, coincident
control points, a missing source vertex, one Continuity/K value too few or too many, a non-GHT
segment, optimizer settings out of range: each puts the feature in error with a message naming the
property and the allowed values (no silent replacement), and restoring the value recomputes the
same geometry; a feature in error survives save/reopen.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_bad_values_inside_freecadcmd(tmp_path: Path) -> None:
    out = run_fc_unittest("freecad.ght_workbench.tests.fc_audit", tmp_path, min_tests=15)
    for cls in ("CurveBadValuesTest", "CompositeBadValuesTest", "SurfaceBadValuesTest", "LinkedPlanesTest", "PlaneWeightsTest",
                "SpineBadValuesTest", "OptimizationBadValuesTest", "ReopenInErrorTest"):
        assert cls in out, f"{cls} did not run:\n{out[-3000:]}"
