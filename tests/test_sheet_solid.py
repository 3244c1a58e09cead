"""The sheet as a solid plate (OCCT thickening) and plates read back from STEP (spec 6.1)."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("OCP")

from ght_cad.cad.occ import is_valid, read_step  # noqa: E402
from ght_cad.cad.sheet_solid import plate_faces, plate_solid, read_step_face_names, write_plate_step  # noqa: E402
from ght_cad.surfaces.ruled import CurvePairRuledSurface  # noqa: E402
from ght_cad.sheetmetal.sheet import Sheet, SheetError, ruling_normal  # noqa: E402
from ght_cad.unrolling.unroll import unroll  # noqa: E402
from tests.test_sheet import _surfaces, cylinder, quarter  # noqa: E402

VOLUME_RTOL = 1e-6


def test_quarter_cylinder_plate_volume_names_and_step(tmp_path) -> None:
    """V = (π/4)((r + T)² - r²) h; the STEP solid is valid, its faces named inside/outside/edge1..4,
    and the plate found in it has thickness T and unrolls to the design's neutral pattern."""
    r, h, T, K = 240.0, 100.0, 4.0, 0.42
    plate = plate_solid(cylinder(r, h), Sheet(T, K))
    assert is_valid(plate.solid)
    assert plate.volume == pytest.approx(0.25 * math.pi * ((r + T) ** 2 - r**2) * h, rel=VOLUME_RTOL)
    assert len(plate.edges) == 4
    path = write_plate_step(plate, tmp_path / "plate.step")
    shape, names = read_step_face_names(path)
    assert is_valid(shape)
    assert sorted(names.values()) == ["edge1", "edge2", "edge3", "edge4", "inside", "outside"]
    from ght_cad.cad.occ import volume

    assert volume(shape) == pytest.approx(plate.volume, rel=1e-9)
    for found in (plate_faces(shape, names), plate_faces(read_step(path))):
        assert found.thickness == pytest.approx(T, rel=1e-9)
        assert found.inside_index == [k for k, v in names.items() if v == "inside"][0]
        pat = unroll(found.inside, thickness=found.thickness, k_factor=K, side=found.side)
        arcs = sorted(e["flat"] for e in pat.sheet["edges"])[-2:]
        assert arcs == pytest.approx([0.5 * math.pi * (r + K * T)] * 2, rel=1e-7)
    assert plate_faces(read_step(path)).how == "geometry"
    assert plate_faces(shape, names).how == "names"


def test_cone_plate_volume() -> None:
    """Quarter cone frustum plate, material outward: Pappus V = (π/2) ℓ T ((r1 + r2)/2 + (T/2) cos α)."""
    r1, r2, H, T = 200.0, 400.0, 300.0, 4.0
    s = CurvePairRuledSurface(quarter(r1, 0.0), quarter(r2, H))
    n = ruling_normal(s, np.array([0.5]), 0)[0][0]
    side = "normal" if n[:2] @ s.evaluate(0.5, 0.5)[:2] > 0 else "reverse"
    plate = plate_solid(s, Sheet(T, 0.4, side))
    ell = math.hypot(r2 - r1, H)
    assert is_valid(plate.solid)
    assert plate.volume == pytest.approx(0.5 * math.pi * ell * T * ((r1 + r2) / 2 + T * H / ell / 2), rel=VOLUME_RTOL)


def test_demo_plate_thickened_and_unrolled_from_step(tmp_path) -> None:
    s = _surfaces()["planes"]
    sh = Sheet(8.0, 0.4)
    plate = plate_solid(s, sh)
    assert is_valid(plate.solid)
    path = write_plate_step(plate, tmp_path / "demo.step")
    found = plate_faces(*read_step_face_names(path))
    assert found.thickness == pytest.approx(8.0, rel=1e-9)
    pat = unroll(found.inside, thickness=found.thickness, k_factor=0.4, side=found.side)
    ref = unroll(s, sheet=sh)
    assert pat.area == pytest.approx(ref.area, rel=1e-6)
    assert sorted(e["flat"] for e in pat.sheet["edges"]) == pytest.approx(sorted(e["flat"] for e in ref.sheet["edges"]), rel=1e-6)


def test_bad_plates_are_refused(tmp_path) -> None:
    with pytest.raises(SheetError, match="thickness=0.0 is not allowed for a solid plate"):
        plate_solid(cylinder(10.0), Sheet(0.0))
    with pytest.raises(SheetError, match="bending radius 10"):
        plate_solid(cylinder(10.0), Sheet(10.5, 0.1, "reverse"))
    assert plate_faces(read_step(write_plate_step(plate_solid(cylinder(10.0), Sheet(1.0)), tmp_path / "x.step"))) is not None


def test_build123d_faces_and_solids() -> None:
    """The sheet options on a build123d face; the plate as a build123d solid (the cadquery
    half is the next test, which runs in the [cadquery] world: tests/test_install.py)."""
    pytest.importorskip("build123d")
    from build123d import Solid

    r, h, T, K = 30.0, 12.0, 1.5, 0.3
    b_face = next(f for f in Solid.make_cylinder(r, h, angle=90).faces() if f.geom_type.name == "CYLINDER")
    pat = unroll(b_face, thickness=T, k_factor=K)  # face normal away from the axis
    assert pat.area == pytest.approx(0.5 * math.pi * (r + K * T) * h, rel=1e-9)
    plate = plate_solid(b_face, Sheet(T, K))
    exact = 0.25 * math.pi * ((r + T) ** 2 - r**2) * h
    assert plate.to_build123d().volume == pytest.approx(exact, rel=1e-9)


def test_cadquery_faces_and_solids() -> None:
    """The same sheet options on a cadquery face; the plate as a cadquery solid."""
    cq = pytest.importorskip("cadquery")

    r, h, T, K = 30.0, 12.0, 1.5, 0.3
    c_face = next(f for f in cq.Workplane().cylinder(h, r, angle=90).faces().vals() if f.geomType() == "CYLINDER")
    pat = unroll(c_face, thickness=T, k_factor=K)  # face normal away from the axis
    assert pat.area == pytest.approx(0.5 * math.pi * (r + K * T) * h, rel=1e-9)
    plate = plate_solid(c_face, Sheet(T, K))
    exact = 0.25 * math.pi * ((r + T) ** 2 - r**2) * h
    assert plate.to_cadquery().Volume() == pytest.approx(exact, rel=1e-9)
    assert plate_solid(c_face, thickness=T, side="reverse").volume == pytest.approx(0.25 * math.pi * (r**2 - (r - T) ** 2) * h, rel=1e-9)