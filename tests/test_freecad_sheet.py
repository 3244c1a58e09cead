"""Sheet thickness in FreeCAD's Flat pattern feature, and a FreeCAD-made plate solid unrolled by the core.

* ``freecadcmd -t freecad.ght_workbench.tests.fc_sheet`` (see that module): Thickness/KFactor/Side
  on a Part::Cylinder face, a ``makeThickness`` plate picked on either face, refusals, DXF layer
  FORMING, save/reopen;
* the plate FreeCAD exported to STEP is found here (inside/outside faces, thickness between them)
  and its neutral pattern equals the one of the design surface computed by the core (1e-6).
"""

from __future__ import annotations

import json
import math

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_sheet_inside_freecad_and_its_plate_unrolled_here(tmp_path) -> None:
    run_fc_unittest("freecad.ght_workbench.tests.fc_sheet", tmp_path, 5, timeout=300)
    from ght_cad.cad.occ import is_valid, read_step
    from ght_cad.cad.sheet_solid import plate_faces
    from ght_cad.unrolling.unroll import unroll
    from tests.test_sheet import cylinder

    d = json.loads((tmp_path / "fc_plate.json").read_text())
    shape = read_step(tmp_path / "fc_plate.step")
    assert is_valid(shape)
    found = plate_faces(shape)
    assert found is not None and found.how == "geometry"
    assert found.thickness == pytest.approx(d["T"], rel=1e-9)
    pat = unroll(found.inside, thickness=found.thickness, k_factor=d["K"], side=found.side)
    ref = unroll(cylinder(d["R"], d["H"]), thickness=d["T"], k_factor=d["K"])
    assert pat.area == pytest.approx(ref.area, rel=1e-6)
    assert pat.area == pytest.approx(d["area"], rel=1e-9)  # FreeCAD's own feature agrees
    assert pat.area == pytest.approx(0.5 * math.pi * (d["R"] + d["K"] * d["T"]) * d["H"], rel=1e-9)
    assert sorted(e["flat"] for e in pat.sheet["edges"]) == pytest.approx(sorted(e["flat"] for e in ref.sheet["edges"]), rel=1e-6)
