"""Bad property values in the workbench's features, run inside Debian's FreeCAD (separate process).

``freecadcmd -t freecad.ght_workbench.tests.fc_audit``: a negative/zero/NaN tolerance, coincident
control points, a missing source vertex, one Continuity/K value too few or too many, a non-GHT
segment, optimizer settings out of range: each puts the feature in error with a message naming the
property and the allowed values (no silent replacement), and restoring the value recomputes the
same geometry; a feature in error survives save/reopen.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from conftest import freecadcmd_or_skip
from freecad_launch import freecad_env, run_process, summary

pytestmark = pytest.mark.freecad


def test_bad_values_inside_freecadcmd(tmp_path: Path) -> None:
    exe = freecadcmd_or_skip()
    proc = run_process([exe, "-t", "freecad.ght_workbench.tests.fc_audit"], freecad_env(tmp_path), tmp_path, 120)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, summary(proc)
    ran = re.search(r"Ran (\d+) tests?", out)
    assert ran and int(ran.group(1)) >= 12, summary(proc)
    assert re.search(r"^OK\s*$", out, re.M) and not re.search(r"^FAILED \(", out, re.M), summary(proc)
    assert "skipped=" not in out, summary(proc)
    for cls in ("CurveBadValuesTest", "CompositeBadValuesTest", "SurfaceBadValuesTest", "OptimizationBadValuesTest", "ReopenInErrorTest"):
        assert cls in out, f"{cls} did not run:\n{summary(proc)}"
