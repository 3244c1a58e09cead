"""The workbench's Developable loft feature tested inside Debian's FreeCAD (separate process).

``freecadcmd -t freecad.ght_workbench.tests.fc_loft``: the loft between the circles of two
sketches is the cone (rulings through the apex, area and flat pattern = closed form to 1e-9),
moving a rail's sketch recomputes it, save/reopen, the flat pattern of it, GHT curve rails with
fans and the Loft optimization, refusals naming the property. Here: the STEP file FreeCAD wrote
is read back with OCP 7.9: valid, one face, twist <= 0.01° from OCCT normals, area = closed form.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_developable_loft_inside_freecadcmd(tmp_path: Path) -> None:
    out = run_fc_unittest("freecad.ght_workbench.tests.fc_loft", tmp_path, min_tests=7, timeout=240)
    m = re.search(r"sketch cone: apex distance ([\deE.+-]+) \(MaxDeviation ([\deE.+-]+)\)", out)
    assert m and float(m.group(1)) <= 10 * float(m.group(2)), out[-3000:]
    fan = re.search(r"loft optimization: fan share ([\deE.+-]+) -> ([\deE.+-]+)", out)
    assert fan and float(fan.group(2)) <= float(fan.group(1)), out[-3000:]
    assert "moved rail: area" in out and "flat pattern: AreaFlat=" in out, out[-3000:]

    pytest.importorskip("OCP")
    from build123d import Face, Shape

    import ght_cad
    from ght_cad.cad.developable_faces import face_developability, shell_faces
    from ght_cad.cad.occ import is_valid, read_step

    shape = read_step(tmp_path / "loft.step")
    assert is_valid(shape)
    faces = shell_faces(shape)
    assert len(faces) == 1
    assert face_developability(Face(faces[0])).theta_max <= 0.01
    exact = float((tmp_path / "loft_area.txt").read_text())
    area = sum(p.area_3d for p in ght_cad.unroll(Shape.cast(shape)).panels)
    assert abs(area - exact) <= 1e-6 * exact, (area, exact)
