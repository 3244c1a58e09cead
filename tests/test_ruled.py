"""Developability degree of ruled surfaces (spec section 5): exact cases, invariance, singular ends."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from ght_cad import GHTCurve
from ght_cad.surfaces.ruled import CurvePairRuledSurface, FunctionRuledSurface


def _circle(r: float, z: float, cx: float = 0.0) -> GHTCurve:
    return GHTCurve([(cx + r, 0, z), (cx + r, r, z), (cx, r, z)], 0.0, 0.0, -1.0)


def test_cylinder_and_cone_are_exactly_developable() -> None:
    for surf in (CurvePairRuledSurface(_circle(2, 0), _circle(2, 3)), CurvePairRuledSurface(_circle(1, 0), _circle(3, 2))):
        d = surf.developability()
        assert d.theta_max <= 1e-12 and d.theta_rms <= 1e-12
        assert d.dd == pytest.approx(1.0, abs=1e-15) and abs(d.R) <= 1e-15
        assert d.residual_max <= 1e-13
        u = np.linspace(0, 1, 11)
        assert np.abs(surf.gaussian_curvature(u, 0.5)).max() <= 1e-14


def test_twisted_strip_is_measured_non_developable() -> None:
    a = GHTCurve([(0, 0, 0), (1, 0, 0), (2, 0, 0)])
    b = GHTCurve([(0, 1, 0), (1, 1, 0.5), (2, 0, 1)])
    s = CurvePairRuledSurface(a, b)
    d = s.developability()
    assert d.theta_max > 10.0 and d.dd < 0.999 and d.R > 1e-3
    assert (s.gaussian_curvature(np.linspace(0, 1, 9), 0.3) < -1e-3).all()


@given(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.integers(0, 2**31 - 1))
def test_measures_invariant_under_similarity(mu: float, nu: float, gamma: float, seed: int) -> None:
    rng = np.random.default_rng(seed)
    pa, pb = rng.normal(size=(4, 3)), rng.normal(size=(4, 3)) + [0, 0, 3]
    s = CurvePairRuledSurface(GHTCurve(pa, mu, nu, gamma), GHTCurve(pb, nu, mu, gamma))
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    k, off = 3.7, rng.normal(size=3)
    s2 = CurvePairRuledSurface(
        GHTCurve(pa, mu, nu, gamma).transformed(k * Q, off), GHTCurve(pb, nu, mu, gamma).transformed(k * Q, off)
    )
    d1, d2 = s.developability(), s2.developability()
    assert d2.R == pytest.approx(d1.R, rel=1e-8, abs=1e-14)
    assert d2.dd == pytest.approx(d1.dd, rel=1e-12)
    if np.isfinite(d1.theta_max):
        assert d2.theta_max == pytest.approx(d1.theta_max, rel=1e-7, abs=1e-9)


def test_singular_end_point_does_not_poison_theta() -> None:
    """Where a boundary tangent vanishes the normal is undefined: that sample is skipped, not NaN."""
    # a(u) with a'(1) = 0 (stationary end), b a straight translate: a cylinder over a cusp-free arc
    def a(u, r=0):
        u = np.asarray(u, float)
        x = [u - u**3 / 3, 1 - u**2, -2 * u][r] if r < 3 else -2 + 0 * u
        y = [np.zeros_like(u) + (1 - u) ** 3, -3 * (1 - u) ** 2, 6 * (1 - u)][r] if r < 3 else 0 * u - 6
        return np.column_stack([x, y, np.zeros_like(u)])

    def b(u, r=0):
        out = a(u, r)
        if r == 0:
            out[:, 2] += 1.0
        return out

    s = FunctionRuledSurface(a, b)
    assert np.isnan(s.theta([1.0])).all()
    d = s.developability()
    assert np.isfinite(d.theta_max) and d.theta_max <= 1e-10


def test_stationary_dual_curve_is_refused() -> None:
    """ν = γ = -1 makes U'(1) = 0: the end ruling is undefined and the input is refused."""
    from ght_cad import DegenerateGeometryError, developable_from_planes

    with pytest.raises(DegenerateGeometryError, match=r"at u=1 \(t=1\).*vanishes \(the dual curve is stationary.*nu = gamma = -1"):
        developable_from_planes([(-2, 1, 0, 0), (-2, 1, 1, 0), (-2, 0, 1, 0)], [(0, 0, 0, 1), (-5, 0, 0, 1)], 0.3, -1, -1)


def test_noise_tangent_at_a_singular_end_is_ignored() -> None:
    """a'(1) = 0 analytically but 1e-15 of rounding noise in a random direction: still skipped."""
    rng = np.random.default_rng(4)

    def a(u, r=0):
        u = np.asarray(u, float)
        base = np.column_stack([u - u**3 / 3, (1 - u) ** 3, np.zeros_like(u)]) if r == 0 else (
            np.column_stack([1 - u**2, -3 * (1 - u) ** 2, np.zeros_like(u)]))
        if r == 1:
            end = np.isclose(u, 1.0)
            base[end] = 1e-15 * rng.normal(size=(int(end.sum()), 3))
        return base

    def b(u, r=0):
        out = a(u, r).copy()
        if r == 0:
            out[:, 2] += 1.0
        else:
            out[np.isclose(np.asarray(u, float), 1.0)] = 1e-15 * rng.normal(size=(int(np.isclose(np.asarray(u, float), 1.0).sum()), 3))
        return out

    s = FunctionRuledSurface(a, b)
    assert np.isnan(s.theta([1.0])).all()
    assert s.developability().theta_max <= 1e-10


def test_cone_to_its_apex_has_defined_normals() -> None:
    """A strip whose a-edge collapses to the apex: n_a is the limit of the surface normal."""
    apex = GHTCurve([(0, 0, 2), (0, 0, 2), (0, 0, 2)])
    s = CurvePairRuledSurface(apex, _circle(1.5, 0.0))
    th = s.theta(np.linspace(0, 1, 33))
    assert np.isfinite(th).all() and th.max() <= 1e-12
    d = s.developability()
    assert d.theta_max <= 1e-12 and d.dd == pytest.approx(1.0, abs=1e-15)
    # every ruled surface through one point is a (general) cone, hence developable: a wavy base
    # curve is measured developable too
    wavy = CurvePairRuledSurface(apex, GHTCurve([(1, 0, 0), (1, 1, 1.5), (0, 1, 0)], gamma=-1))
    assert wavy.developability().theta_max <= 1e-12
