"""Exact developable loft between two rails (spec section 5.7)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import ght_cad
from ght_cad import GHTCurve
from ght_cad.core.errors import DegenerateGeometryError, GHTError, NotDevelopableError
from ght_cad.developables.loft import (CallableRail, DevelopableLoft, as_rail, developable_loft, loft_function,
                                       plot_loft_sign)
from ght_cad.optimize.problems import LoftProblem
from ght_cad.surfaces.ruled import RuledSurface


# -- rails ----------------------------------------------------------------------------------
def cone_circle(k: float, z: float, th0: float, th1: float, c: float = 0.0, name: str = "circle") -> CallableRail:
    """Circle of the cone x² + y² = (k z)² (apex at the origin) at height z, angle th0 -> th1,
    re-parametrized by s -> (s + c s²) / (1 + c) (c > -1/2: regular; c = 0: uniform)."""
    r = k * z

    def ang(s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return th0 + (th1 - th0) * reparam(s, c), (th1 - th0) * (1 + 2 * c * s) / (1 + c)

    def pos(s: np.ndarray) -> np.ndarray:
        th, _ = ang(s)
        return np.column_stack([r * np.cos(th), r * np.sin(th), np.full_like(s, z)])

    def d1(s: np.ndarray) -> np.ndarray:
        th, w = ang(s)
        return np.column_stack([-r * np.sin(th) * w, r * np.cos(th) * w, 0 * s])

    return CallableRail(pos, d1, name=name)


def reparam(s: np.ndarray, c: float) -> np.ndarray:
    return (s + c * s * s) / (1 + c)


def ruling_apex_distance(loft: DevelopableLoft, apex: np.ndarray, n: int = 1001) -> float:
    """max over rulings of the distance from ``apex`` to the ruling line, relative to the size."""
    u = np.linspace(0.0, 1.0, n)
    A, B = loft.a(u), loft.b(u)
    d = (B - A) / np.linalg.norm(B - A, axis=1)[:, None]
    dist = np.linalg.norm(np.cross(apex - A, d), axis=1)
    size = float(np.linalg.norm(np.vstack([A, B]).max(axis=0) - np.vstack([A, B]).min(axis=0)))
    return float(dist.max() / size)


def annular_sector_area(k: float, z1: float, z2: float, angle: float) -> float:
    """Flat pattern of the frustum between heights z1 < z2 over ``angle`` of the circle: slant
    radii ρ = z sqrt(1 + k²), sector angle ``angle · k z2 / ρ2`` (spec section 6)."""
    rho1, rho2 = z1 * math.hypot(1, k), z2 * math.hypot(1, k)
    phi = angle * k * z2 / rho2
    return 0.5 * phi * (rho2**2 - rho1**2)


def covers_rails(loft: DevelopableLoft) -> None:
    """Segments are contiguous along the rails and cover t, s ∈ [0, 1] (s in rail b's direction)."""
    segs = loft.segments
    t_lo = min(min(sg.t_range) for sg in segs)
    t_hi = max(max(sg.t_range) for sg in segs)
    s_lo = min(min(sg.s_range) for sg in segs)
    s_hi = max(max(sg.s_range) for sg in segs)
    assert (t_lo, t_hi, s_lo, s_hi) == (0.0, 1.0, 0.0, 1.0)
    for left, right in zip(segs[:-1], segs[1:]):
        assert left.t_range[1] == pytest.approx(right.t_range[0], abs=1e-14)
        assert left.s_range[1] == pytest.approx(right.s_range[0], abs=1e-14)
        # the joint ruling is shared
        np.testing.assert_allclose(left.a(np.array([1.0])), right.a(np.array([0.0])), atol=1e-12 * loft.report.area**0.5)
        np.testing.assert_allclose(left.b(np.array([1.0])), right.b(np.array([0.0])), atol=1e-12 * loft.report.area**0.5)
    # the loft's ends are the rails' ends
    ra, rb = as_rail(loft.rail_a), as_rail(loft.rail_b)
    ends = np.array([0.0, 1.0])
    sb = ends[::-1] if loft.reversed_b else ends
    size = loft.report.area**0.5
    np.testing.assert_allclose(loft.a(ends), ra.evaluate(ends), atol=1e-12 * size)
    np.testing.assert_allclose(loft.b(ends), rb.evaluate(sb), atol=1e-12 * size)


CHINE = GHTCurve([[0, -700, 300], [1500, -1050, 200], [3000, -1150, 250], [4500, -950, 450]])
SHEER = GHTCurve([[0, -900, 1200], [1500, -1250, 1150], [3000, -1300, 1180], [4500, -1100, 1300]])


def hopper_rails(w: float = 1.0, R: float = 0.6, h: float = 1.2) -> tuple[GHTCurve, CallableRail]:
    """A round-to-square hopper quarter: a side of the square (a line) below a quarter of the circle."""
    th0, th1 = math.radians(225), math.radians(315)
    line = GHTCurve([(-w, -w, 0), (0, -w, 0), (w, -w, 0)])
    arc = CallableRail(
        lambda s: np.column_stack([R * np.cos(th0 + (th1 - th0) * s), R * np.sin(th0 + (th1 - th0) * s), np.full_like(s, h)]),
        lambda s: (th1 - th0) * np.column_stack([-R * np.sin(th0 + (th1 - th0) * s), R * np.cos(th0 + (th1 - th0) * s), 0 * s]),
        name="arc",
    )
    return line, arc


# -- known developables are reproduced --------------------------------------------------------
def test_cone_quarter_circles_ght_rails() -> None:
    """GHT quarter circles (γ = -1) of a cone: every ruling through the apex, area = annular sector."""
    k, z1, z2 = 0.8, 1.0, 2.2
    a = GHTCurve([(k * z1, 0, z1), (k * z1, k * z1, z1), (0, k * z1, z1)], gamma=-1)
    b = GHTCurve([(k * z2, 0, z2), (k * z2, k * z2, z2), (0, k * z2, z2)], gamma=-1)
    loft = developable_loft(a, b)
    assert [sg.kind for sg in loft.segments] == ["main"]
    assert ruling_apex_distance(loft, np.zeros(3)) <= 1e-9
    exact = annular_sector_area(k, z1, z2, math.pi / 2)
    pattern = ght_cad.unroll(loft)
    assert len(pattern.panels) == 1
    assert abs(pattern.area - exact) / exact <= 1e-9
    assert abs(loft.report.area - exact) / exact <= 1e-9
    assert loft.report.theta_max_deg <= 1e-8
    assert loft.report.fan_share == 0.0


@pytest.mark.parametrize("reverse_a, c", [(False, 1.5), (True, -0.4)])
def test_cone_reversed_and_reparametrized(reverse_a: bool, c: float) -> None:
    """One rail reversed, the other re-parametrized (s -> (s + c s²)/(1 + c)), arc of 218°: the cone is found (the
    antipodal branch, a double cone with its apex between the rails, is not taken)."""
    k, z1, z2, th0, th1 = 0.7, 1.0, 2.5, 0.2, 4.0
    a = cone_circle(k, z1, th1, th0) if reverse_a else cone_circle(k, z1, th0, th1)
    b = cone_circle(k, z2, th0, th1, c=c)
    loft = developable_loft(a, b)
    assert loft.reversed_b is reverse_a
    assert [sg.kind for sg in loft.segments] == ["main"]
    assert ruling_apex_distance(loft, np.zeros(3)) <= 1e-9
    exact = annular_sector_area(k, z1, z2, th1 - th0)
    assert abs(ght_cad.unroll(loft).area - exact) / exact <= 1e-9
    # σ pairs points of the same angle
    t = np.linspace(0.0, 1.0, 11)
    th_a = (th1 + (th0 - th1) * t) if reverse_a else th0 + (th1 - th0) * t
    th_b = th0 + (th1 - th0) * reparam(loft.sigma(t), c)
    np.testing.assert_allclose(th_b, th_a, atol=1e-10)


def test_oblique_cylinder() -> None:
    """Rails on an oblique circular cylinder (axis w tilted): rulings parallel to w (1e-9), the flat
    area R ∫ (h_b - h_a) dφ in closed form (1e-9)."""
    w = np.array([0.3, -0.2, 1.0])
    w /= np.linalg.norm(w)
    e1 = np.cross(w, [1.0, 0, 0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(w, e1)
    R, p0, p1 = 1.3, -0.4, 2.1

    def rail(h0: float, kc: float, ks: float) -> CallableRail:
        def pos(x: np.ndarray) -> np.ndarray:
            ph = p0 + (p1 - p0) * x
            h = h0 + kc * np.cos(ph) + ks * np.sin(ph)
            return R * (np.cos(ph)[:, None] * e1 + np.sin(ph)[:, None] * e2) + h[:, None] * w

        def d1(x: np.ndarray) -> np.ndarray:
            ph = p0 + (p1 - p0) * x
            dh = -kc * np.sin(ph) + ks * np.cos(ph)
            return (p1 - p0) * (R * (-np.sin(ph)[:, None] * e1 + np.cos(ph)[:, None] * e2) + dh[:, None] * w)

        return CallableRail(pos, d1)

    a = rail(0.0, 0.3, 0.1)
    b = rail(2.0, -0.2, 0.4)
    loft = developable_loft(a, b)
    u = np.linspace(0, 1, 1001)
    g = loft.ruling(u)
    assert np.max(np.linalg.norm(np.cross(g / np.linalg.norm(g, axis=1)[:, None], w), axis=1)) <= 1e-9
    exact = R * ((2.0 * (p1 - p0)) + (-0.2 - 0.3) * (math.sin(p1) - math.sin(p0)) - (0.4 - 0.1) * (math.cos(p1) - math.cos(p0)))
    assert abs(ght_cad.unroll(loft).area - exact) / exact <= 1e-9
    assert loft.report.regression_clearance == math.inf or loft.report.regression == []


# -- dory and hopper -------------------------------------------------------------------------
def test_dory_chine_sheer() -> None:
    """The dory's chine and sheer (examples/design_hull_plate.toml) admit an exact loft: θ ≤ 1e-8°,
    a small fan at each end with apex at the sheer's ends, rails covered, one flat panel."""
    loft = developable_loft(CHINE, SHEER)
    rep = loft.report
    assert [sg.kind for sg in loft.segments] == ["fan_b", "main", "fan_b"]
    np.testing.assert_allclose(loft.segments[0].apex, SHEER.evaluate(0.0), atol=1e-9)
    np.testing.assert_allclose(loft.segments[2].apex, SHEER.evaluate(1.0), atol=1e-9)
    assert rep.theta_max_deg <= 1e-8
    assert loft.developability().theta_max <= 1e-8
    assert rep.f_residual_max <= 1e-13
    assert 0.0 < rep.fan_share < 0.05
    assert rep.regression == [] and rep.degenerate_rulings == []
    covers_rails(loft)
    pattern = ght_cad.unroll(loft)
    assert len(pattern.panels) == 1
    assert pattern.errors["max"] <= 1e-9
    assert pattern.panels[0].bend_lines.shape[0] > 0
    # σ on the fans is the apex parameter; on the main part it solves F = 0 and increases
    assert loft.sigma(0.5 * loft.segments[0].t_range[1]) == 0.0
    assert loft.sigma(1.0) == 1.0
    t0, t1 = loft.segments[1].t_range
    t = np.linspace(t0, t1, 201)[1:-1]
    s = loft.sigma(t)
    assert np.all(np.diff(s) > 0)
    assert np.max(np.abs(loft_function(CHINE, SHEER, t, s))) <= 1e-13


def test_hopper_fans_where_expected() -> None:
    """Line under a quarter circle (round-to-square hopper): cone from each end of the line and the
    planar triangle to the arc's midpoint between them (the classical layout)."""
    line, arc = hopper_rails()
    loft = developable_loft(line, arc)
    assert [sg.kind for sg in loft.segments] == ["fan_a", "main", "fan_a"]
    assert loft.segments[0].s_range == pytest.approx((0.0, 0.5), abs=1e-12)
    np.testing.assert_allclose(loft.segments[0].apex, line.evaluate(0.0), atol=1e-12)
    np.testing.assert_allclose(loft.segments[2].apex, line.evaluate(1.0), atol=1e-12)
    # the main part is the planar triangle with apex at the arc's midpoint (0, -R, h)
    main = loft.segments[1]
    np.testing.assert_allclose(main.b(np.linspace(0, 1, 9)), np.tile([0.0, -0.6, 1.2], (9, 1)), atol=1e-12)
    assert loft.report.theta_max_deg <= 1e-8
    assert loft.report.regression == []
    covers_rails(loft)
    # the reversed pairing (fans folded over the triangle) was refused
    assert any("fold" in c.get("refused", "") for c in loft.report.candidates)
    pattern = ght_cad.unroll(loft)
    assert len(pattern.panels) == 1 and pattern.errors["max"] <= 1e-9
    # exact area: two cones over 45° arcs + triangle
    area = loft.report.area
    assert abs(pattern.area - area) / area <= 1e-9


# -- refusals and bad input ------------------------------------------------------------------
def test_skew_lines_refused() -> None:
    a = GHTCurve([(0, 0, 0), (0.5, 0, 0), (1, 0, 0)])
    b = GHTCurve([(0, 0, 1), (0, 0.5, 1), (0, 1, 1)])
    with pytest.raises(NotDevelopableError, match="no developable joins the rails") as exc:
        developable_loft(a, b)
    assert "plot_loft_sign" in str(exc.value)
    assert "no zero on the lower-left sides" in str(exc.value)


def test_refusal_writes_the_sign_plot(tmp_path) -> None:
    pytest.importorskip("matplotlib")
    from PIL import Image

    a = GHTCurve([(0, 0, 0), (0.5, 0, 0), (1, 0, 0)])
    b = GHTCurve([(0, 0, 1), (0, 0.5, 1), (0, 1, 1)])
    png = tmp_path / "why.png"
    with pytest.raises(NotDevelopableError, match="why.png shows the sign of F"):
        developable_loft(a, b, sign_png=png)
    assert Image.open(png).size == (800, 800)


@pytest.mark.slow
def test_bad_input() -> None:
    line, arc = hopper_rails()
    nan_rail = CallableRail(lambda t: np.column_stack([t, np.where(t > 0.5, np.nan, 0 * t), 0 * t]),
                            lambda t: np.column_stack([1 + 0 * t, 0 * t, 0 * t]))
    with pytest.raises(GHTError, match="rail_b position is not finite at t=0.50"):
        developable_loft(line, nan_rail)
    with pytest.raises(DegenerateGeometryError, match="coincide"):
        developable_loft(line, GHTCurve([(1, -1, 0), (0.2, -1, 0), (-1, -1, 0)]))
    point = CallableRail(lambda t: np.zeros((t.size, 3)), lambda t: np.zeros((t.size, 3)))
    with pytest.raises(DegenerateGeometryError, match="single point"):
        developable_loft(point, arc)
    with pytest.raises(GHTError, match="a rail is a 3-D GHTCurve"):
        developable_loft(line, [[0, 0, 0], [1, 1, 1]])
    with pytest.raises(GHTError, match="dimension 2"):
        developable_loft(line, GHTCurve([(0, 0), (1, 1), (2, 0)]))
    with pytest.raises(GHTError, match="orientation='sideways'"):
        developable_loft(line, arc, orientation="sideways")
    with pytest.raises(GHTError, match="max_step=0"):
        developable_loft(line, arc, max_step=0)
    with pytest.raises(GHTError, match="returned an array of shape"):
        developable_loft(line, CallableRail(lambda t: np.zeros(2), lambda t: np.zeros(2)))
    stationary = GHTCurve([(0, 0, 1), (0, 0, 1), (1, 0, 1)])  # zero tangent at t = 0
    with pytest.raises(DegenerateGeometryError, match="zero tangent"):
        developable_loft(line, stationary)
    flat = GHTCurve([(-1, -2, 0), (0, -2.5, 0), (1, -2, 0)])  # coplanar with the line
    with pytest.raises(DegenerateGeometryError, match="coplanar"):
        developable_loft(line, flat)


# -- data out --------------------------------------------------------------------------------
def test_segments_are_ruled_surfaces_with_bspline_data() -> None:
    loft = developable_loft(CHINE, SHEER)
    assert isinstance(loft, RuledSurface) and all(isinstance(sg, RuledSurface) for sg in loft.segments)
    size = float(np.linalg.norm(np.ptp(np.vstack([CHINE.evaluate(np.linspace(0, 1, 33)), SHEER.evaluate(np.linspace(0, 1, 33))]), axis=0)))
    data = loft.bspline_data()
    assert len(data) == 3
    for sg, d in zip(loft.segments, data):
        assert d.degree_v == 1 and list(d.knots_v) == [0.0, 0.0, 1.0, 1.0]
        assert d.max_deviation <= 1e-7 * size * 1.0001
        # end poles are the joint rulings exactly
        np.testing.assert_allclose(d.poles[0], np.vstack([sg.a(np.array([0.0])), sg.b(np.array([0.0]))]), atol=1e-9 * size)
        np.testing.assert_allclose(d.poles[-1], np.vstack([sg.a(np.array([1.0])), sg.b(np.array([1.0]))]), atol=1e-9 * size)
        assert d.info["theta_max_deg"] <= 1e-3
    plain = loft.to_dict()
    assert [s["kind"] for s in plain["segments"]] == ["fan_b", "main", "fan_b"]
    assert plain["report"]["fan_share"] == pytest.approx(loft.report.fan_share)
    import json

    json.dumps(plain)


def test_sign_plot(tmp_path) -> None:
    pytest.importorskip("matplotlib")
    from PIL import Image

    loft = developable_loft(CHINE, SHEER)
    out = plot_loft_sign(CHINE, SHEER, tmp_path / "sign.png", loft=loft, resolution=41)
    assert Image.open(out).size == (800, 800)


# -- objectives ------------------------------------------------------------------------------
def test_loft_problem_objectives() -> None:
    prob = LoftProblem(CHINE, SHEER, objective="fan_share", free=["a.mu", "b.nu"])
    X = np.array([[0.0, 0.0], [0.5, -0.5]])
    vals = prob(X)
    assert vals.shape == (2,)
    assert vals[0] == pytest.approx(developable_loft(CHINE, SHEER).report.fan_share, rel=1e-6)
    rep = prob.report(np.array([0.0, 0.0]))
    assert set(rep) == {"objective", "fan_share", "fairness", "regression"}
    assert rep["fairness"] > 0 and rep["regression"] == 0.0
    # skew-line rails are infeasible everywhere: +inf
    a = GHTCurve([(0, 0, 0), (0.5, 0, 0), (1, 0, 0)])
    b = GHTCurve([(0, 0, 1), (0, 0.5, 1), (0, 1, 1)])
    assert np.all(LoftProblem(a, b, objective={"fairness": 1.0})(np.zeros((2, 6))) == np.inf)
    with pytest.raises(GHTError, match="unknown"):
        LoftProblem(CHINE, SHEER, objective="beauty")


# -- property over a box of rail shapes ------------------------------------------------------
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    k=st.floats(0.3, 2.0),
    z1=st.floats(0.5, 2.0),
    dz=st.floats(0.3, 3.0),
    th0=st.floats(-3.0, 3.0),
    span=st.floats(0.3, 4.5),
    c=st.floats(-0.45, 2.0),
    rev=st.booleans(),
)
def test_cone_property(k: float, z1: float, dz: float, th0: float, span: float, c: float, rev: bool) -> None:
    """Over a box of cones, arcs and parametrizations: rulings through the apex (1e-9), flat area of
    the annular sector (1e-9), no fans."""
    z2 = z1 + dz
    a = cone_circle(k, z1, th0, th0 + span)
    b = cone_circle(k, z2, th0 + span, th0, c=c) if rev else cone_circle(k, z2, th0, th0 + span, c=c)
    loft = developable_loft(a, b)
    assert loft.reversed_b is rev
    assert [sg.kind for sg in loft.segments] == ["main"]
    assert ruling_apex_distance(loft, np.zeros(3), n=257) <= 1e-9
    exact = annular_sector_area(k, z1, z2, span)
    assert abs(loft.report.area - exact) / exact <= 1e-9


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(d=st.lists(st.floats(-150.0, 150.0), min_size=24, max_size=24))
def test_dory_box_exact_or_refused(d: list[float]) -> None:
    """Chine/sheer control points moved within ±150 mm: the loft is exact (θ ≤ 1e-8°, rails covered)
    or refused with NotDevelopableError — never an inexact surface."""
    D = np.asarray(d).reshape(2, 4, 3)
    a = GHTCurve(CHINE.control_points + D[0])
    b = GHTCurve(SHEER.control_points + D[1])
    try:
        loft = developable_loft(a, b)
    except NotDevelopableError as exc:
        assert "no developable joins the rails" in str(exc)
        return
    assert loft.report.theta_max_deg <= 1e-8
    covers_rails(loft)


def test_rails_meeting_at_the_bow() -> None:
    """Chine and sheer meeting at the stem (a zero ruling at t = s = 0, where F is singular): the
    branch leaves the meeting point along the zero direction of F's quadratic part, the zero
    ruling is reported, θ ≤ 1e-8° elsewhere, one flat panel with a pointed end."""
    bow = [0, -800, 900]
    chine = GHTCurve([bow, [1500, -1050, 200], [3000, -1150, 250], [4500, -950, 450]])
    sheer = GHTCurve([bow, [1500, -1250, 1150], [3000, -1300, 1180], [4500, -1100, 1300]])
    loft = developable_loft(chine, sheer)
    assert [sg.kind for sg in loft.segments] == ["main", "fan_b"]
    assert loft.report.degenerate_rulings[0] == {"t": 0.0, "s": 0.0, "kind": "zero length", "value": 0.0}
    assert loft.report.theta_max_deg <= 1e-8
    covers_rails(loft)
    # the derivatives at the meeting point are finite limits, so the B-spline export works
    for sg, data in zip(loft.segments, loft.bspline_data()):
        assert np.all(np.isfinite(sg.a(np.array([0.0, 1.0]), 2)))
        assert data.max_deviation <= 1e-7 * 4700
    pattern = ght_cad.unroll(loft)
    assert len(pattern.panels) == 1 and pattern.errors["max"] <= 1e-7


def test_to_face_shell() -> None:
    """``to_face()``: one valid shell of B-spline faces (fans and main part), area = loft area."""
    pytest.importorskip("build123d")
    from ght_cad.cad.occ import is_valid

    loft = developable_loft(CHINE, SHEER)
    shell = loft.to_face()
    assert is_valid(shell)
    assert len(shell.faces()) == 3
    assert abs(shell.area - loft.report.area) / loft.report.area <= 1e-6
    from ght_cad.cad.developable_faces import face_developability

    # θ from OCCT normals on every face, fans included (their apex edge is collapsed)
    assert max(face_developability(f).theta_max for f in shell.faces()) <= 1e-3


def test_round_to_oval_closed_rails() -> None:
    """Round-to-oval transition between a circle and an ellipse running the other way (closed
    rails in parallel planes): the rulings join points with parallel, equally directed tangents
    (1e-9), no fans, the loft closes (first ruling = last), one flat panel."""

    def ellipse(A: float, B: float, z: float, sense: float) -> CallableRail:
        def pos(s: np.ndarray) -> np.ndarray:
            th = sense * 2 * np.pi * s
            return np.column_stack([A * np.cos(th), B * np.sin(th), np.full_like(s, z)])

        def d1(s: np.ndarray) -> np.ndarray:
            th = sense * 2 * np.pi * s
            return sense * 2 * np.pi * np.column_stack([-A * np.sin(th), B * np.cos(th), 0 * s])

        return CallableRail(pos, d1)

    loft = developable_loft(ellipse(1.0, 1.0, 0.0, 1.0), ellipse(1.6, 0.8, 1.2, -1.0))
    assert loft.reversed_b and [sg.kind for sg in loft.segments] == ["main"]
    u = np.linspace(0.0, 1.0, 1001)
    A1, B1 = loft.a(u, 1), loft.b(u, 1)
    sine = np.linalg.norm(np.cross(A1, B1), axis=1) / (np.linalg.norm(A1, axis=1) * np.linalg.norm(B1, axis=1))
    assert sine.max() <= 1e-9 and np.all(np.einsum("ij,ij->i", A1, B1) > 0)
    np.testing.assert_allclose(loft.ruling(np.array([0.0])), loft.ruling(np.array([1.0])), atol=1e-12)
    assert loft.report.theta_max_deg <= 1e-8
    pattern = ght_cad.unroll(loft)
    assert len(pattern.panels) == 1 and pattern.errors["max"] <= 1e-9
