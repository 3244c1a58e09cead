"""The GHT Plate feature in FreeCAD, and its STEP file read back with OCP.

* ``freecadcmd -t freecad.ght_workbench.tests.fc_plate`` (see that module): exact plates of a
  developable from planes, a loft with fans, a pointed loft (no end wall) and a spine developable; volumes vs the closed form;
  inside/outside faces; recompute, refusals, flat pattern of the plate, save/reopen, STEP;
* the hull plate's STEP file FreeCAD wrote is read here with OCP: one valid solid whose volume
  (``ght_cad.cad.occ.volume``, C0 faces split first) equals the closed form to 1e-8 relative and
  FreeCAD's ``Shape.Volume`` of it to 1e-9 by the default rule on the unsplit faces; the inside
  and outside faces are found geometrically 4 mm apart.
"""

from __future__ import annotations

import json

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_plate_inside_freecad_and_its_step_read_back(tmp_path) -> None:
    run_fc_unittest("freecad.ght_workbench.tests.fc_plate", tmp_path, 7, timeout=600)
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    from ght_cad.cad.occ import is_valid, read_step, volume
    from ght_cad.cad.sheet_solid import plate_faces

    d = json.loads((tmp_path / "fc_plate.json").read_text())
    shape = read_step(tmp_path / "fc_plate_loft.step")
    exp = TopExp_Explorer(shape, TopAbs_SOLID)
    solids = []
    while exp.More():
        solids.append(exp.Current())
        exp.Next()
    assert len(solids) == 1
    assert is_valid(shape)
    assert volume(shape) == pytest.approx(d["closed_form"], rel=1e-8)
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)  # the default rule, unsplit: what FreeCAD reports
    assert props.Mass() == pytest.approx(d["shape_volume"], rel=1e-9)
    found = plate_faces(shape)
    assert found is not None
    assert found.thickness == pytest.approx(d["T"], rel=1e-9)
