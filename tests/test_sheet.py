"""Sheet thickness, K-factor and the neutral surface (spec 6.1): closed forms, T = 0, refusals,
forming data and exports (core, no CAD kernel)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ght_cad import GHTCurve
from ght_cad.developables.envelope import RectifyingDevelopable, TangentDevelopable, developable_from_planes
from ght_cad.core.errors import GHTError
from ght_cad.surfaces.ruled import CurvePairRuledSurface
from ght_cad.sheetmetal.sheet import (
    OffsetRuledSurface,
    Sheet,
    SheetError,
    bending_radius,
    make_sheet,
    ruling_normal,
)
from ght_cad.unrolling.unroll import unroll, unroll_composite

CLOSED_FORM_RTOL = 1e-9


def cylinder(r: float, h: float = 100.0):
    """Exact quarter cylinder of radius r (planes (-r,1,0,0), (-r,1,1,0), (-r,0,1,0), γ = -1),
    z from 0 to h; its normal points away from the axis."""
    planes = np.array([[-r, 1, 0, 0], [-r, 1, 1, 0], [-r, 0, 1, 0]], float)
    return developable_from_planes(planes, np.array([[0, 0, 0, 1], [-h, 0, 0, 1]], float), gamma=-1)


def quarter(r: float, z: float) -> GHTCurve:
    return GHTCurve([(r, 0, z), (r, r, z), (0, r, z)], gamma=-1)


def edge(pattern, name: str) -> dict:
    return next(e for e in pattern.sheet["edges"] if e["edge"] == name)


@pytest.mark.slow
@settings(max_examples=20, deadline=None)
@given(r=st.floats(5.0, 500.0), t_rel=st.floats(0.001, 0.2), K=st.floats(0.0, 1.0), h=st.floats(1.0, 200.0))
def test_cylinder_flat_width_is_phi_r_plus_KT(r: float, t_rel: float, K: float, h: float) -> None:
    """Inside radius r, thickness T, K: flat width φ (r + K T), φ = π/2; outside φ (r + T); rulings h."""
    T = t_rel * r
    pat = unroll(cylinder(r, h), thickness=T, k_factor=K, rulings=3)
    phi = 0.5 * math.pi
    a = edge(pat, "a")
    assert a["flat"] == pytest.approx(phi * (r + K * T), rel=CLOSED_FORM_RTOL)
    assert a["neutral"] == pytest.approx(phi * (r + K * T), rel=CLOSED_FORM_RTOL)
    assert a["inside"] == pytest.approx(phi * r, rel=CLOSED_FORM_RTOL)
    assert a["outside"] == pytest.approx(phi * (r + T), rel=CLOSED_FORM_RTOL)
    assert edge(pat, "ruling u=0")["flat"] == pytest.approx(h, rel=CLOSED_FORM_RTOL)
    assert pat.area == pytest.approx(phi * (r + K * T) * h, rel=CLOSED_FORM_RTOL)
    assert pat.errors["max"] < 1e-12
    # forming: one line, radius r + K T, angle φ
    (row,) = pat.sheet["forming"]
    assert row["line"] == 0
    assert row["radius_a"] == pytest.approx(r + K * T, rel=CLOSED_FORM_RTOL)
    assert row["radius_b"] == pytest.approx(r + K * T, rel=CLOSED_FORM_RTOL)
    assert row["angle_deg"] == pytest.approx(90.0, rel=CLOSED_FORM_RTOL)


def test_reverse_side_and_din_k_factor() -> None:
    """Material against the normal (towards the axis): flat width φ (r - K T); DIN k = 2K is the same sheet."""
    r, T = 240.0, 4.0
    pat = unroll(cylinder(r), thickness=T, din_k_factor=0.84, side="reverse")
    assert pat.sheet["k_factor"] == pytest.approx(0.42, rel=1e-15)
    assert edge(pat, "a")["flat"] == pytest.approx(0.5 * math.pi * (r - 0.42 * T), rel=CLOSED_FORM_RTOL)
    assert edge(pat, "a")["outside"] == pytest.approx(0.5 * math.pi * (r - T), rel=CLOSED_FORM_RTOL)
    # the angle is negative: the reference face is the outside of this bend
    assert pat.sheet["forming"][0]["angle_deg"] == pytest.approx(-90.0, rel=CLOSED_FORM_RTOL)
    flipped = unroll(cylinder(r), sheet=Sheet(T, 0.42, "normal").flipped())
    np.testing.assert_array_equal(flipped.outline, pat.outline)


@settings(max_examples=15, deadline=None)
@given(r1=st.floats(0.5, 5.0), dr=st.floats(0.2, 5.0), H=st.floats(0.2, 5.0), t_rel=st.floats(0.001, 0.1), K=st.floats(0, 1))
def test_cone_frustum_plate_is_offset_annular_sector(r1: float, dr: float, H: float, t_rel: float, K: float) -> None:
    """Quarter cone frustum (radii r1 < r2, height H), material outward: the neutral surface is the
    cone of the same semi-angle α with slant radii ρ_i + δ cos α / sin α (ρ_i = slant · r_i / Δr),
    pattern an annular sector of angle (π/2) sin α: edge lengths and area to 1e-9."""
    r2 = r1 + dr
    T = t_rel * r1
    surf = CurvePairRuledSurface(quarter(r1, 0.0), quarter(r2, H))
    # the surface normal of this parametrization: check the side that puts the material outward
    n = ruling_normal(surf, np.array([0.5]), 0)[0][0]
    p = surf.evaluate(0.5, 0.5)
    side = "normal" if n[:2] @ p[:2] > 0 else "reverse"
    pat = unroll(surf, thickness=T, k_factor=K, side=side, rulings=2)
    slant = math.hypot(dr, H)
    sin_a, cos_a = dr / slant, H / slant
    rho1, rho2 = slant * r1 / dr + K * T * cos_a / sin_a, slant * r2 / dr + K * T * cos_a / sin_a
    ang = 0.5 * math.pi * sin_a
    assert edge(pat, "a")["flat"] == pytest.approx(ang * rho1, rel=CLOSED_FORM_RTOL)
    assert edge(pat, "b")["flat"] == pytest.approx(ang * rho2, rel=CLOSED_FORM_RTOL)
    assert edge(pat, "a")["outside"] == pytest.approx(0.5 * math.pi * (r1 + T * cos_a), rel=CLOSED_FORM_RTOL)
    assert pat.area == pytest.approx(0.5 * ang * (rho2**2 - rho1**2), rel=CLOSED_FORM_RTOL)
    (row,) = pat.sheet["forming"]  # a cone: constant radii along the plate, one line
    assert row["radius_a"] == pytest.approx(r1 / cos_a + K * T, rel=CLOSED_FORM_RTOL)
    assert row["radius_b"] == pytest.approx(r2 / cos_a + K * T, rel=CLOSED_FORM_RTOL)
    assert row["angle_deg"] == pytest.approx(90.0 * cos_a, rel=CLOSED_FORM_RTOL)


def _surfaces():
    c = GHTCurve([(0, 0, 0), (3, 0, 1), (5, 2, 0), (6, 5, 2)], gamma=0.3)
    planes = np.array([[-1389.189, -0.124, -0.9923, 0.0], [-1043.2074, -0.0293, -0.9235, -0.3825],
                       [-644.5781, 0.0517, -0.7062, -0.7062], [-269.167, 0.1054, -0.3806, -0.9187],
                       [0.0, 0.124, 0.0, -0.9923]])
    return {
        "planes": developable_from_planes(planes, np.array([[0, 1, 0, 0], [-6000, 1, 0, 0]], float), normalize=True),
        "spine": TangentDevelopable(c, 0.3, 1.5),
        "geodesic": RectifyingDevelopable(c, -0.4, 0.4),
    }


@pytest.mark.parametrize("kind", ["planes", "spine", "geodesic"])
def test_thickness_zero_is_bit_for_bit(kind: str) -> None:
    s = _surfaces()[kind]
    ref = unroll(s)
    for pat in (unroll(s, thickness=0.0, k_factor=0.3), unroll(s, sheet=Sheet(0.0, 1.0, "reverse"))):
        assert pat.sheet is None
        for lp, lq in zip(ref.outlines, pat.outlines):
            np.testing.assert_array_equal(lp, lq)
        np.testing.assert_array_equal(ref.bend_lines, pat.bend_lines)
        assert pat.errors == ref.errors


@pytest.mark.parametrize("kind", ["planes", "spine", "geodesic"])
def test_neutral_offset_of_general_developables(kind: str) -> None:
    """The neutral surface is at distance |δ| along n with the same rulings, developable; its pattern
    passes the length/area checks; the edge lengths are ordered inside/neutral/outside by the bend."""
    s = _surfaces()[kind]
    L = float(np.max(np.ptp(s.grid(9, 3).reshape(-1, 3), axis=0)))
    rmin = float(np.min(np.abs(bending_radius(s, np.linspace(0, 1, 257).repeat(2), np.tile([0.0, 1.0], 257)))))
    T = min(0.01 * L, 0.5 * rmin)
    sh = Sheet(T, 0.4)
    off = OffsetRuledSurface(s, sh.neutral_offset)
    u = np.linspace(0, 1, 33)
    for v in (0.0, 0.5, 1.0):
        d = off.evaluate(u, np.full_like(u, v)) - s.evaluate(u, np.full_like(u, v))
        np.testing.assert_allclose(np.linalg.norm(d, axis=1), abs(sh.neutral_offset), rtol=1e-12)
        np.testing.assert_allclose(np.einsum("ij,ij->i", d, s.ruling(u)), 0.0, atol=1e-9 * L * L)
    assert off.developability().theta_max < 1e-6
    pat = unroll(s, sheet=sh, rulings=6)
    assert pat.errors["max"] < 1e-9, pat.errors
    assert len(pat.sheet["forming"]) in (1, 6)
    for e in pat.sheet["edges"]:
        assert e["flat"] == pytest.approx(e["neutral"], rel=1e-9)


def test_forming_rows_of_a_varying_plate() -> None:
    """The bilge plate: one row per bend line, radii = |ρ_0 + δ| at the ruling ends, the angles add up
    to the total turning of the normal; labels on their own DXF layer."""
    s = _surfaces()["planes"]
    sh = Sheet(8.0, 0.45, "normal")
    pat = unroll(s, sheet=sh, rulings=8)
    rows = pat.sheet["forming"]
    assert [r["line"] for r in rows] == list(range(1, 9))
    for r in rows:
        rho_a = bending_radius(s, np.array([r["u"]]), np.array([0.0]))[0]
        assert r["radius_a"] == pytest.approx(abs(rho_a + sh.neutral_offset), rel=1e-12)
    n = ruling_normal(s, np.array([0.0, 1.0]), 0)[0]
    total = math.degrees(math.acos(float(np.clip(n[0] @ n[1], -1, 1))))
    # a plate turning about nearly one axis: the summed angle is the angle between its end normals
    assert abs(sum(r["angle_deg"] for r in rows)) == pytest.approx(total, rel=2e-3)
    assert len(pat.forming_labels) == 8
    assert "bend" in pat.forming_table()


def test_forming_layer_in_dxf_svg_and_chart(tmp_path) -> None:
    import ezdxf

    pat = unroll(cylinder(240.0), thickness=4.0, k_factor=0.42)
    doc = ezdxf.readfile(pat.export_dxf(tmp_path / "p.dxf"))
    texts = [t.dxf.text for t in doc.modelspace().query("TEXT") if t.dxf.layer == "FORMING"]
    assert texts == ["R241.7 A90.00deg"]
    r12 = pat.dxf_r12_text()
    assert "FORMING" in r12 and "R241.7 A90.00deg" in r12
    assert 'id="FORMING"' in pat.svg_text()
    png = pat.plot_roll_chart(tmp_path / "chart.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    plain = unroll(cylinder(240.0))
    with pytest.raises(GHTError, match="no sheet data"):
        plain.plot_roll_chart(tmp_path / "none.png")
    assert not (tmp_path / "none.png").exists()


def test_composite_plates() -> None:
    s = _surfaces()
    pat = unroll_composite([cylinder(50.0), s["spine"]], sheet=[Sheet(1.0, 0.5), None])
    assert pat.panels[0].info["sheet"]["thickness"] == 1.0
    assert "sheet" not in pat.panels[1].info
    assert pat.errors["max"] < 1e-9


@pytest.mark.parametrize(
    "kwargs, word",
    [
        ({"thickness": -1.0}, "thickness=-1.0"),
        ({"thickness": float("nan")}, "thickness=nan"),
        ({"thickness": float("inf")}, "thickness=inf"),
        ({"thickness": "2"}, "thickness='2'"),
        ({"thickness": 1.0, "k_factor": 1.2}, "k_factor=1.2"),
        ({"thickness": 1.0, "k_factor": -0.1}, "k_factor=-0.1"),
        ({"thickness": 1.0, "din_k_factor": 2.5}, "din_k_factor=2.5"),
        ({"thickness": 1.0, "k_factor": 0.3, "din_k_factor": 0.6}, "both given"),
        ({"thickness": 1.0, "side": "up"}, "side='up'"),
        ({"k_factor": 0.4}, "without a thickness"),
    ],
)
def test_bad_sheet_values_name_the_value(kwargs, word) -> None:
    with pytest.raises(SheetError, match=word.replace("(", r"\(")):
        unroll(cylinder(10.0), **kwargs)


def test_thickness_beyond_the_bending_radius_is_refused() -> None:
    """|K T| >= r (spec 6.1), and material through the centre of curvature, name the ruling and radius."""
    with pytest.raises(SheetError, match=r"thickness=12.0 .*K\*T\|=12 reaches the bending radius 10 of the ruling at u=[0-9.]+ \([ab] end\)"):
        unroll(cylinder(10.0), thickness=12.0, k_factor=1.0)
    with pytest.raises(SheetError, match=r"centre of curvature .* bending radius 10"):
        unroll(cylinder(10.0), thickness=10.5, k_factor=0.1, side="reverse")
    # below the radius it works on both sides
    assert unroll(cylinder(10.0), thickness=9.9, k_factor=0.1, side="reverse").errors["max"] < 1e-12


def test_make_sheet() -> None:
    assert make_sheet() is None
    sh = make_sheet(2.0, din_k_factor=1.0, side="reverse", flip=True)
    assert sh == Sheet(2.0, 0.5, "normal")
    assert sh.neutral_offset == 1.0 and sh.outside_offset == 2.0 and sh.din_k_factor == 1.0
    assert Sheet(2.0, 0.25, "reverse").neutral_offset == -0.5
    with pytest.raises(SheetError, match="not both"):
        unroll(cylinder(10.0), sheet=sh, thickness=1.0)


def test_rails_loft_plate_and_its_fan_apex() -> None:
    """A rails loft with fans (cones at the rail ends): material on the convex side of the fan apex
    is regular (the neutral surface turns the apex into an arc), on the concave side refused."""
    import ght_cad

    chine = GHTCurve([(0, -700, 300), (1500, -1050, 200), (3000, -1150, 250), (4500, -950, 450)])
    sheer = GHTCurve([(0, -900, 1200), (1500, -1250, 1150), (3000, -1300, 1180), (4500, -1100, 1300)])
    loft = ght_cad.developable_loft(chine, sheer)
    sides = {}
    for side in ("normal", "reverse"):
        try:
            sides[side] = unroll(loft, thickness=6.0, k_factor=0.4, side=side, rulings=4)
        except SheetError as exc:
            sides[side] = str(exc)
    ok = [p for p in sides.values() if not isinstance(p, str)]
    bad = [p for p in sides.values() if isinstance(p, str)]
    assert len(ok) == 1 and len(bad) == 1
    assert "ends in an apex" in bad[0] and "concave side" in bad[0]
    pat = ok[0]
    assert pat.errors["max"] < 1e-8
    for e in pat.sheet["edges"]:
        assert e["flat"] == pytest.approx(e["neutral"], rel=1e-8)
    assert len(pat.sheet["forming"]) == 4
