"""The FreeCAD adapter reads B-spline surfaces and curves into the core NURBS evaluator
(``freecadcmd -t freecad.ght_workbench.tests.fc_nurbs``: paths taken, jet/density_grid vs
FreeCAD's getDN to 1e-12, the old point-by-point path, periodic and disagreeing surfaces fall back
to FreeCAD; planes, cylinders and cones by the core's closed forms), and its flat outlines equal the OCP adapter's on the same faces (BREP files the
FreeCAD run wrote) to 1e-12 of the pattern's size."""

from __future__ import annotations

import json

import numpy as np
import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad

CASES = ("rational_cylinder", "drilled_rational_cylinder", "tangent_dev_bspline", "bezier_quarter_cylinder")


@pytest.fixture(scope="module")
def fc_out(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("fc_nurbs")
    text = run_fc_unittest("freecad.ght_workbench.tests.fc_nurbs", out, 9, timeout=300)
    for name in ("test_rational_bspline_cylinder_reads_into_core", "test_periodic_bspline_surface_stays_on_freecad",
                 "test_plane_cylinder_cone_evaluated_in_numpy",
                 "test_disagreeing_reading_falls_back_to_freecad", "test_flat_pattern_feature_uses_the_core_evaluator",
                 "test_face_reader_names_resolve_from_flat_pattern"):
        assert name in text, f"{name} did not run"
    return out


def _read_brep(path):
    from OCP.BRep import BRep_Builder
    from OCP.BRepTools import BRepTools
    from OCP.TopoDS import TopoDS_Shape

    shape = TopoDS_Shape()
    assert BRepTools.Read_s(shape, str(path), BRep_Builder()), path
    return shape


@pytest.mark.parametrize("case", CASES)
def test_freecad_outlines_equal_ocp_outlines(fc_out, case: str) -> None:
    from ght_cad.cad.unroll_faces import shape_faces, unroll_face

    fc = json.loads((fc_out / "nurbs.json").read_text())[case]
    pat = unroll_face(shape_faces(_read_brep(fc_out / f"{case}.brep"))[0], rulings=8, samples=65)
    ocp = [np.asarray(e.flat) + p.offset for p in pat.panels for loop in p.loops for e in loop]
    theirs = [np.asarray(e) for loop in fc["outline"] for e in loop]
    assert len(theirs) == len(ocp)
    size = fc["size"]
    for e in theirs:  # each FreeCAD edge against the closest OCP edge, either direction
        d = min(min(float(np.abs(e - f).max()), float(np.abs(e - f[::-1]).max())) for f in ocp if f.shape == e.shape)
        assert d <= 1e-12 * size, f"{case}: outline distance {d / size:.2e} of the size"
    assert pat.area == pytest.approx(fc["area"], rel=1e-12)
