"""Sheet thickness on CAD faces (ght_cad.face_unroll through the OCP adapter): cylinders and cones
keep their closed forms with the offset radius, ruled B-spline faces are offset; T = 0 bit for bit."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("build123d")

from build123d import Solid  # noqa: E402

from ght_cad.sheetmetal.sheet import Sheet, SheetError  # noqa: E402
from ght_cad.unrolling.unroll import unroll  # noqa: E402

RTOL = 1e-9


def _face(solid, kind: str):
    return next(f for f in solid.faces() if f.geom_type.name == kind)


def _edge_rows(pattern):
    return sorted(pattern.sheet["edges"], key=lambda e: e["inside"])


@pytest.mark.parametrize("side, sign", [("normal", 1.0), ("reverse", -1.0)])
def test_cylinder_face_offset_radius(side: str, sign: float) -> None:
    """Quarter cylinder r = 240, h = 100 (face normal away from the axis): flat width φ (r ± K T)."""
    r, h, T, K = 240.0, 100.0, 4.0, 0.42
    f = _face(Solid.make_cylinder(r, h, angle=90), "CYLINDER")
    pat = unroll(f, thickness=T, k_factor=K, side=side)
    arcs = [e for e in pat.sheet["edges"] if abs(e["inside"] - h) > 1e-6]
    assert len(arcs) == 2
    for e in arcs:
        assert e["inside"] == pytest.approx(0.5 * math.pi * r, rel=RTOL)
        assert e["flat"] == pytest.approx(0.5 * math.pi * (r + sign * K * T), rel=RTOL)
        assert e["outside"] == pytest.approx(0.5 * math.pi * (r + sign * T), rel=RTOL)
    assert pat.area == pytest.approx(0.5 * math.pi * (r + sign * K * T) * h, rel=RTOL)
    (row,) = pat.sheet["forming"]
    assert row["radius_a"] == pytest.approx(r + sign * K * T, rel=RTOL)
    # positive: the design face is the inside of the bend (material on the convex side)
    assert row["angle_deg"] == pytest.approx(sign * 90.0, rel=RTOL)
    assert pat.errors["max"] < 1e-12


def test_cone_face_offset_sector() -> None:
    """Quarter cone frustum radii 400 / 200 over 300: annular sector of radii ρ_i + K T cos α / sin α."""
    R1, R2, H, T, K = 400.0, 200.0, 300.0, 4.0, 0.42
    f = _face(Solid.make_cone(R1, R2, H, angle=90), "CONE")
    pat = unroll(f, thickness=T, k_factor=K)
    slant = math.hypot(R1 - R2, H)
    sin_a, cos_a = (R1 - R2) / slant, H / slant
    shift = K * T * cos_a / sin_a
    rho = sorted([slant * R / (R1 - R2) + shift for R in (R1, R2)])
    ang = 0.5 * math.pi * sin_a
    arcs = sorted(e["flat"] for e in pat.sheet["edges"] if abs(e["inside"] - slant) > 1e-6)
    assert arcs == pytest.approx([ang * rho[0], ang * rho[1]], rel=RTOL)
    assert pat.area == pytest.approx(0.5 * ang * (rho[1] ** 2 - rho[0] ** 2), rel=RTOL)
    (row,) = pat.sheet["forming"]
    assert sorted([row["radius_a"], row["radius_b"]]) == pytest.approx([R2 / cos_a + K * T, R1 / cos_a + K * T], rel=RTOL)
    assert row["angle_deg"] == pytest.approx(90.0 * cos_a, rel=RTOL)


def test_faces_thickness_zero_bit_for_bit() -> None:
    for solid, kind in ((Solid.make_cylinder(50, 20, angle=120), "CYLINDER"), (Solid.make_cone(30, 10, 25, angle=200), "CONE")):
        f = _face(solid, kind)
        ref, pat = unroll(f), unroll(f, thickness=0.0)
        assert pat.sheet is None
        for a, b in zip(ref.outlines, pat.outlines):
            np.testing.assert_array_equal(a, b)
        assert ref.errors == pat.errors


def test_bspline_face_matches_ruled_surface() -> None:
    """The B-spline face of a developable: its neutral pattern equals the ruled surface's (fit 1e-7)."""
    from ght_cad.cad.developable_faces import developable_face
    from tests.test_sheet import _surfaces

    s = _surfaces()["planes"]
    face = developable_face(s)
    sh = Sheet(8.0, 0.45)
    ref = unroll(s, sheet=sh)
    pat = unroll(face, sheet=sh)
    assert pat.errors["max"] < 1e-8
    assert pat.area == pytest.approx(ref.area, rel=1e-6)
    lens = sorted(e["flat"] for e in pat.sheet["edges"])
    assert lens == pytest.approx(sorted(e["flat"] for e in ref.sheet["edges"]), rel=1e-6)


def test_face_thickness_beyond_radius_is_refused() -> None:
    f = _face(Solid.make_cylinder(5, 20, angle=90), "CYLINDER")
    with pytest.raises(SheetError, match=r"thickness=6.0 .*bending radius 5 "):
        unroll(f, thickness=6.0, k_factor=1.0)


def test_forming_label_avoids_a_hole() -> None:
    """A drilled cylinder plate: the one forming label sits on the plate, not in the hole at its centre."""
    from build123d import Plane

    from ght_cad.pattern.flat_pattern import _inside

    cyl = Solid.make_cylinder(50, 40, angle=120)
    c, s = math.cos(math.radians(60)), math.sin(math.radians(60))
    drill = Solid.make_cylinder(6, 200, Plane(origin=(0, 0, 20), z_dir=(c, s, 0)))
    face = _face(cyl - drill, "CYLINDER")
    pat = unroll(face, thickness=1.0, k_factor=0.5)
    assert len(pat.panels[0].loops) == 2  # outline and hole
    (label,) = pat.forming_labels
    loops = pat.panels[0].loop_polylines()
    assert _inside(np.array([label[:2]]), loops)[0]
    # the plate centre (where the label would go) is in the hole
    lo, hi = pat.panels[0].bbox()
    assert not _inside(np.array([0.5 * (lo + hi)]), loops)[0]
    # neutral sector minus the developed drill hole (about a disc of radius 6: loose, 2e-3)
    assert pat.area == pytest.approx((2 * math.pi / 3) * 50.5 * 40 - math.pi * 6**2, rel=2e-3)
