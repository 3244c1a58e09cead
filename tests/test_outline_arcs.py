"""Outline edges as lines and circular arcs (ght_cad.outline_arcs): exact lines/arcs recognized,
other curves within the chord tolerance (hypothesis), areas, refusals."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ght_cad.core.errors import GHTError
from ght_cad.pattern.outline_arcs import arc_chain, bulge_polygon_area


def arc_distance(q: np.ndarray, p0: np.ndarray, p1: np.ndarray, b: float) -> np.ndarray:
    """Exact distances of points q (m, 2) from the segment p0 -> p1 with bulge b (a straight
    segment for b = 0, else the circular arc of sweep 4 atan b): to the circle where q's angle
    lies within the arc's sweep, else to the nearer end point."""
    ends = np.minimum(np.linalg.norm(q - p0, axis=1), np.linalg.norm(q - p1, axis=1))
    c = p1 - p0
    L = float(np.hypot(*c))
    if L == 0.0:
        return ends
    if b == 0.0:
        s = np.clip((q - p0) @ c / (L * L), 0.0, 1.0)
        return np.linalg.norm(q - p0 - s[:, None] * c, axis=1)
    th = 4.0 * math.atan(b)
    kappa = 2.0 * math.sin(th / 2) / L
    n = np.array([-c[1], c[0]]) / L
    centre = 0.5 * (p0 + p1) + n * math.cos(th / 2) / kappa
    r = 1.0 / abs(kappa)
    a0 = math.atan2(*(p0 - centre)[::-1])
    a = np.arctan2(q[:, 1] - centre[1], q[:, 0] - centre[0])
    rel = np.mod((a - a0) if th > 0 else (a0 - a), 2 * math.pi)
    inside = rel <= abs(th)
    return np.where(inside, np.abs(np.linalg.norm(q - centre, axis=1) - r), ends)


def chain_distance(q: np.ndarray, points: np.ndarray, bulges: np.ndarray) -> np.ndarray:
    """Distances of q from an open chain (points (k + 1, 2), bulges (k,))."""
    return np.min([arc_distance(q, points[i], points[i + 1], float(b)) for i, b in enumerate(bulges)], axis=0)


def fourier_curve(coef: np.ndarray):
    """t -> Σ_k (a_k cos(kπt) + b_k sin(kπt)) for k = 1..K, both coordinates (coef (K, 4))."""
    K = coef.shape[0]
    k = np.arange(1, K + 1) * math.pi

    def f(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        C, S = np.cos(np.outer(t, k)), np.sin(np.outer(t, k))
        return np.stack([C @ coef[:, 0] + S @ coef[:, 1], C @ coef[:, 2] + S @ coef[:, 3]], axis=1)

    return f


@pytest.mark.slow
@given(st.lists(st.floats(-1.0, 1.0), min_size=16, max_size=16), st.floats(-6.0, -2.0), st.floats(-1.0, 3.0),
       st.floats(-math.pi, math.pi))
def test_curve_within_chord_tolerance(c: list[float], log_tol: float, log_scale: float, angle: float) -> None:
    """Over random regular curves (a chord of length 10^s turned by ``angle`` plus 4 Fourier modes
    per coordinate whose speed stays below 0.9 of the chord's, so the curve never stops or turns
    back along itself; s in -1 .. 3) and chord tolerances 1e-6 .. 1e-2 of the size: every point
    of the curve (4,001 parameters) lies within the tolerance of the arc chain (exact
    point-to-arc distance), and every point of the arcs (15 inside each) within the tolerance of the
    curve (a dense polyline, whose own sagitta is added; 12 arcs spread along the chain); the chain
    starts and ends at the curve's ends exactly."""
    scale = 10.0**log_scale
    coef = np.array(c).reshape(4, 4) / np.arange(1, 5)[:, None]
    speed = math.pi * float(np.sum(np.abs(coef) * np.arange(1, 5)[:, None]))  # bound of |perturbation'|
    coef *= 0.9 * scale / max(speed, 1e-300) if speed > 0.9 else scale
    wave = fourier_curve(coef)
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])

    def f(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        return (np.stack([scale * t, np.zeros_like(t)], axis=1) + wave(t)) @ rot.T

    t = np.linspace(0.0, 1.0, 4001)
    dense = f(t)
    size = float(np.max(np.ptp(dense, axis=0)))
    tol = 10.0**log_tol * size
    ch = arc_chain(f, tol, size)
    assert ch.kind in ("curve", "line", "arc", "arcs")
    np.testing.assert_array_equal(ch.points[[0, -1]], f(np.array([0.0, 1.0])))
    assert chain_distance(dense, ch.points, ch.bulges).max() <= tol * (1 + 1e-9) + 1e-12 * size
    # the arcs' own points against the curve's polyline (sagitta of a dense chord: h²κ/8 bounded by
    # the second differences' largest size)
    sag = float(np.max(np.linalg.norm(dense[2:] - 2 * dense[1:-1] + dense[:-2], axis=1)))
    for i in np.unique(np.linspace(0, ch.bulges.size - 1, 12).round().astype(int)):  # 12 arcs spread along
        b = float(ch.bulges[i])
        p0, p1 = ch.points[i], ch.points[i + 1]
        th = 4 * math.atan(b)
        s = np.linspace(0.0, 1.0, 17)[1:-1]
        if b == 0.0:
            q = p0 + s[:, None] * (p1 - p0)
        else:
            L = float(np.linalg.norm(p1 - p0))
            n = np.array([-(p1 - p0)[1], (p1 - p0)[0]]) / L
            kappa = 2 * math.sin(th / 2) / L
            centre = 0.5 * (p0 + p1) + n * math.cos(th / 2) / kappa
            a0 = math.atan2(*(p0 - centre)[::-1])
            ang = a0 + s * th
            q = centre + np.stack([np.cos(ang), np.sin(ang)], axis=1) / abs(kappa)
        seg = dense[1:] - dense[:-1]
        w = np.clip(np.einsum("mij,ij->mi", q[:, None, :] - dense[None, :-1], seg) / np.einsum("ij,ij->i", seg, seg), 0, 1)
        d = np.linalg.norm(q[:, None, :] - dense[None, :-1] - w[..., None] * seg[None], axis=2).min(axis=1)
        assert d.max() <= tol * (1 + 1e-9) + sag, (i, d.max(), tol)


@given(st.floats(0.01, 1000.0), st.floats(0.05, 1.9 * math.pi), st.floats(-math.pi, math.pi),
       st.sampled_from([1.0, -1.0]), st.floats(-100.0, 100.0))
def test_exact_arc_is_one_arc(r: float, sweep: float, start: float, sense: float, x0: float) -> None:
    """A circular arc (radius 0.01 .. 1000, sweep up to 342°) in a non-uniform parametrization is
    written as ONE arc (2 .. 4 above 180°) whose bulge is ``tan(sweep/4)`` (its sagitta to 1e-14
    of the coordinates) and whose area is the exact sector's to 1e-12 (or 1e-13 of |x0| r)."""
    def f(t: np.ndarray) -> np.ndarray:
        a = start + sense * sweep * (t + 0.2 * t * (1 - t))
        return np.stack([x0 + r * np.cos(a), r * np.sin(a)], axis=1)

    size = 2 * r
    ch = arc_chain(f, 1e-3, size)
    if sweep <= math.pi * (1 - 1e-9):
        assert ch.kind == "arc" and ch.bulges.size == 1
        # the arc's sagitta (L/2) b to round-off of the coordinates (~|x0| + r)
        L = float(np.linalg.norm(ch.points[1] - ch.points[0]))
        assert abs(ch.bulges[0] - sense * math.tan(sweep / 4)) * L / 2 <= 1e-14 * (abs(x0) + r)
    else:  # split where the merge's halving of the pieces falls: 2 .. 4 arcs, each at most 180°
        assert ch.kind == "arcs" and 2 <= ch.bulges.size <= 4 and np.all(np.abs(ch.bulges) <= 1 + 1e-12)
        assert 4 * np.sum(np.arctan(ch.bulges)) == pytest.approx(sense * sweep, rel=1e-12)
    area = bulge_polygon_area(np.concatenate([ch.points, [[x0, 0.0]]]), np.append(ch.bulges, [0.0, 0.0]))
    # the sector from the centre: (r²/2) sweep, signed by the sense
    assert area == pytest.approx(sense * 0.5 * r * r * sweep, rel=1e-12, abs=1e-13 * (abs(x0) + r) * r)


def test_line_full_circle_point_and_breaks() -> None:
    """A line in any parametrization: one straight segment; a closed circle: two half circles;
    a zero-length edge: no segment; a curve with a break: the break is a vertex."""
    line = arc_chain(lambda t: np.stack([3 * t**2, 2 - t**2], axis=1), 1e-3, 4.0)
    assert line.kind == "line" and line.bulges.tolist() == [0.0]
    circle = arc_chain(lambda t: np.stack([np.cos(2 * np.pi * t), np.sin(2 * np.pi * t)], axis=1), 1e-3, 2.0)
    assert circle.kind == "arcs" and circle.bulges.size == 2
    assert np.all(np.abs(circle.bulges - 1.0) <= 1e-12)  # two half circles, counter-clockwise
    assert bulge_polygon_area(circle.points[:-1], circle.bulges) == pytest.approx(math.pi, rel=1e-13)
    point = arc_chain(lambda t: np.zeros((t.size, 2)) + 5.0, 1e-3, 1.0)
    assert point.kind == "point" and point.bulges.size == 0
    # a polyline corner at t = 0.3 (a break): the vertex is kept, both sides straight
    kink = arc_chain(lambda t: np.stack([t, np.abs(t - 0.3)], axis=1), 1e-6, 1.0, breaks=(0.3,))
    assert kink.kind == "arcs" and kink.bulges.tolist() == [0.0, 0.0]
    np.testing.assert_allclose(kink.points[1], [0.3, 0.0], atol=1e-15)


def test_ellipse_area_converges_faster_than_the_tolerance() -> None:
    """A half ellipse (a = 300, b = 150; not a circle) within 1e-3: its area with the closing
    diameter is πab/2 to far better than tolerance × length (the three-point arcs' errors change
    sign along each piece): |ΔA| ≤ 1e-3 · tol · length, and the chain has few arcs."""
    a, b = 300.0, 150.0
    ch = arc_chain(lambda t: np.stack([a * np.cos(np.pi * t), b * np.sin(np.pi * t)], axis=1), 1e-3, 2 * a)
    assert ch.kind == "curve" and ch.deviation <= 1e-3
    area = bulge_polygon_area(ch.points, np.append(ch.bulges, 0.0))
    length = 1.2111 * 2 * a  # half the perimeter (Ramanujan: 1.2111 · 2a for b/a = 1/2)
    assert abs(area - math.pi * a * b / 2) <= 1e-3 * 1e-3 * length
    assert ch.bulges.size <= 64


def test_bad_chord_tolerance_is_refused() -> None:
    for bad in (0.0, -1e-3, math.inf, math.nan):
        with pytest.raises(GHTError, match="chord_tol"):
            arc_chain(lambda t: np.stack([t, t], axis=1), bad, 1.0)


def test_edge_standing_still_over_a_parameter_range() -> None:
    """An edge that stands still on part of its range (a loft's fan apex inside the edge of an
    approximation panel: the development's points there are rounding noise, ~1e-13): the still part
    becomes straight segments, the rest arcs, all within the chord tolerance (before: 131072
    pieces and a refusal, 'chord_tol cannot be met')."""
    rng = np.random.default_rng(3)

    def fn(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        s = np.clip((t - 0.3) / 0.7, 0.0, 1.0)
        p = np.stack([300.0 * np.sin(1.2 * s) + 40 * s * s, 300.0 * (1 - np.cos(1.2 * s))], 1)
        return p + 1e-13 * rng.standard_normal(p.shape)

    tol = 1e-3
    ch = arc_chain(fn, tol, 400.0, [0.3])
    assert ch.kind == "curve"
    q = fn(np.linspace(0, 1, 4001))
    assert chain_distance(q, ch.points, ch.bulges).max() <= tol
    assert np.allclose(ch.points[0], fn(np.array([0.0]))[0], atol=1e-9)
    assert np.allclose(ch.points[-1], fn(np.array([1.0]))[0], atol=1e-9)
