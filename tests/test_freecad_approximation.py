"""The workbench's Developable approximation feature (issue 24) tested inside Debian's FreeCAD.

``freecadcmd -t freecad.ght_workbench.tests.fc_approximation`` (about 40 s idle: the cap is
approximated three times): a spherical cap (R 1000 mm, polar angle 0..40°; the core's tests take
the 0..60° cap) at Tolerance 1 mm in at most 14 panels, the deviation measured by FreeCAD's ``distToShape`` both ways within 1 mm
(+1 % for OCCT's extrema accuracy); its flat pattern; save/reopen and a new Tolerance changing
PanelCount; a cone face of a PartDesign Body in one panel; a B-spline dome (500 mm square)
imported from STEP within 1 mm; the Direction and Method properties (the core's choices) driving a small dome's panels
(Method loft, Direction u then v) with the progress indicator fed, the Report view clean;
refusals naming the property; a trimmed face (a hole, a curved outline) refused naming Untrimmed
and covered over its (u, v) box with it. Here: the printed figures, and
the flat pattern's DXF read back with ezdxf (one closed outline per panel).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from freecad_launch import run_fc_unittest

pytestmark = [pytest.mark.freecad, pytest.mark.slow]

_NUM = r"([\deE.+-]+)"


def test_developable_approximation_inside_freecadcmd(tmp_path: Path) -> None:
    out = run_fc_unittest("freecad.ght_workbench.tests.fc_approximation", tmp_path, min_tests=6, timeout=900)
    flat = out.replace("\t", "\n").replace("\r", "\n")
    cap = re.search(rf"cap tol 1: (\d+) panels, MaxDeviation {_NUM}, measured target->shell {_NUM} shell->target {_NUM}", flat)
    assert cap, out[-3000:]
    panels, measured = int(cap.group(1)), max(float(cap.group(3)), float(cap.group(4)))
    assert panels <= 14 and measured <= 1.01, cap.group(0)
    again = re.search(r"cap reopened, tol 4: (\d+) -> (\d+) panels", flat)
    assert again and int(again.group(2)) < int(again.group(1)) == panels, out[-3000:]
    cone = re.search(rf"cone: 1 panel, MaxDeviation {_NUM}, measured {_NUM} \(size {_NUM}\)", flat)
    assert cone and float(cone.group(2)) <= 1e-6 * float(cone.group(3)), out[-3000:]

    small = re.search(r"small dome tol 1: loft along u (\d+) panels; loft along v (\d+) panels", flat)
    assert small and int(small.group(1)) >= 1 and int(small.group(2)) >= 1, out[-3000:]
    dome = re.search(rf"dome tol 1: (\d+) panels, MaxDeviation {_NUM}, measured target->shell {_NUM} shell->target {_NUM}", flat)
    assert dome and max(float(dome.group(3)), float(dome.group(4))) <= 1.01, out[-3000:]

    # a trimmed face (a hole; a curved outline) refused naming Untrimmed; with it covered over its box
    trim = re.search(rf"trimmed dome: hole covers {_NUM} \(1 hole\), deck covers {_NUM}; refused; Untrimmed: (\d+) panels, "
                     rf"MaxDeviation {_NUM}", flat)
    assert trim and 0.9 < float(trim.group(1)) < 0.95 and 0.8 < float(trim.group(2)) < 0.9, out[-3000:]
    assert int(trim.group(3)) >= 1 and float(trim.group(4)) <= 1.0, trim.group(0)

    pytest.importorskip("ezdxf")
    from ezdxf import recover

    count, area = (tmp_path / "cap_panels.txt").read_text().split()
    assert int(count) == panels
    dxf, auditor = recover.readfile(str(tmp_path / "cap_flat.dxf"))
    assert not auditor.has_errors, [str(e) for e in auditor.errors]
    outlines = dxf.modelspace().query('POLYLINE[layer=="OUTLINE"]')
    assert len(outlines) == panels and all(o.is_closed for o in outlines), len(outlines)
