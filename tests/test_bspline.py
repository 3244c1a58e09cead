"""Certified B-spline conversion (ght_cad.surfaces.bspline.fit_function / curve_to_bspline)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ght_cad import GHTCurve
from ght_cad.surfaces.bspline import BSplineCurveData, _banded_least_squares, _nonzero_basis, clamped_knots, curve_to_bspline, fit_function
from ght_cad.core.errors import ConversionError, GHTError

shape = st.floats(-1.0, 1.0, allow_nan=False)


def _independent_deviation(curve: GHTCurve, bs: BSplineCurveData, seed: int = 7) -> float:
    """Deviation at matched parameters on points the fitter never saw (random + uniform)."""
    rng = np.random.default_rng(seed)
    t = np.concatenate([rng.uniform(0.0, 1.0, 20000), np.linspace(0.0, 1.0, 4001)])
    return float(np.linalg.norm(curve.evaluate(t) - bs.evaluate(t), axis=1).max())


@settings(max_examples=30)
@given(
    degree=st.integers(2, 10),
    mu=shape,
    nu=shape,
    gamma=shape,
    dim=st.sampled_from([2, 3]),
    seed=st.integers(0, 2**31 - 1),
)
def test_curve_deviation_below_default_tolerance(degree, mu, nu, gamma, dim, seed):
    rng = np.random.default_rng(seed)
    curve = GHTCurve(rng.normal(size=(degree + 1, dim)) * 10.0, mu, nu, gamma)
    bs = curve_to_bspline(curve)
    lo, hi = curve.bounding_box()
    tol = 1e-7 * float(np.linalg.norm(hi - lo))
    assert bs.info["tol"] == pytest.approx(tol)
    assert bs.max_deviation <= tol
    # independent check on 24001 fresh parameters: the reported figure is the true maximum
    dev = _independent_deviation(curve, bs)
    assert dev <= tol * (1 + 1e-6)
    # plus rounding: evaluating points of size |P| costs a few ulps of |P|
    assert dev <= bs.max_deviation * (1 + 1e-3) + 8 * np.finfo(float).eps * float(np.abs(curve.control_points).max())


@settings(max_examples=20)
@given(degree=st.integers(2, 10), mu=shape, nu=shape, gamma=shape, seed=st.integers(0, 2**31 - 1),
       p=st.integers(4, 8))
def test_end_derivatives_are_exact(degree, mu, nu, gamma, seed, p):
    """C^(r)(0) = P^(r)(0), C^(r)(1) = P^(r)(1), r = 0..3, to 1e-9 relative to |P^(r)|."""
    rng = np.random.default_rng(seed)
    curve = GHTCurve(rng.normal(size=(degree + 1, 3)), mu, nu, gamma)
    bs = curve_to_bspline(curve, degree=p)
    ends = np.array([0.0, 1.0])
    for r in range(4):
        exact = curve.derivative(ends, r)
        got = bs.evaluate(ends, r)
        scale = max(1.0, float(np.abs(exact).max()))
        assert np.abs(got - exact).max() <= 1e-9 * scale, r


def test_explicit_tolerance_and_pole_count():
    curve = GHTCurve([(0, 0), (1, 2), (3, 3), (4, 0), (6, 1)], 0.3, -0.5, 0.2)
    coarse = curve_to_bspline(curve, tol=1e-4)
    fine = curve_to_bspline(curve, tol=1e-10)
    assert coarse.max_deviation <= 1e-4 and fine.max_deviation <= 1e-10
    assert coarse.poles.shape[0] < fine.poles.shape[0] < 200
    assert _independent_deviation(curve, fine) <= 1e-10


def test_stacked_function_shares_knots_and_pairs_poles():
    """Two boundary curves stacked into d = 6 get one knot vector; each half is within tol."""
    a = GHTCurve([(0, 0, 0), (1, 0.5, 0), (2, 0, 0.3), (3, 1, 0)], 0.2, 0.4, -0.3)
    b = GHTCurve([(0, 0, 1), (1, 0.2, 1.2), (2.5, 0, 1), (3, 0.5, 1)], -0.6, 0.1, 0.5)
    bs = fit_function(lambda t: np.hstack([a.evaluate(t), b.evaluate(t)]), tol=1e-8)
    assert bs.dim == 6
    t = np.linspace(0, 1, 5001)
    vals = bs.evaluate(t)
    assert np.linalg.norm(vals[:, :3] - a.evaluate(t), axis=1).max() <= 1e-8
    assert np.linalg.norm(vals[:, 3:] - b.evaluate(t), axis=1).max() <= 1e-8


def test_scalar_function_and_polynomial_exactness():
    # a quintic is reproduced to round-off by one degree-5 span
    f = lambda t: 1 + t - 3 * t**2 + t**5  # noqa: E731
    bs = fit_function(f, tol=1e-12, degree=5)
    assert bs.info["spans"] == 1 and bs.poles.shape == (6, 1)
    assert bs.max_deviation <= 1e-12


def test_fixed_end_derivatives_for_a_function():
    f = lambda t: np.column_stack([np.cos(3 * t), np.sin(3 * t)])  # noqa: E731
    ends = ([[1, 0], [0, 3], [-9, 0]], [[np.cos(3), np.sin(3)], [-3 * np.sin(3), 3 * np.cos(3)], [-9 * np.cos(3), -9 * np.sin(3)]])
    bs = fit_function(f, tol=1e-9, degree=5, end_derivatives=ends)
    for r in range(3):
        assert np.allclose(bs.evaluate([0.0], r)[0], ends[0][r], atol=1e-9)
        assert np.allclose(bs.evaluate([1.0], r)[0], ends[1][r], atol=1e-9)


def test_unreachable_tolerance_raises_conversion_error():
    f = lambda t: np.abs(t - 1 / 3) ** 0.5  # noqa: E731  (not smooth: needs endless refinement)
    with pytest.raises(ConversionError, match="max_spans"):
        fit_function(f, tol=1e-12, max_spans=64)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"tol": 0.0}, "tol"),
        ({"tol": float("nan")}, "tol"),
        ({"tol": 1e-6, "degree": 0}, "degree"),
        ({"tol": 1e-6, "degree": 2.5}, "degree"),
        ({"tol": 1e-6, "degree": 2, "end_derivatives": ([0, 1, 2], [])}, "orders"),
        ({"tol": 1e-6, "max_spans": 0}, "max_spans"),
    ],
)
def test_bad_arguments(kwargs, match):
    with pytest.raises(GHTError, match=match):
        fit_function(lambda t: t, **kwargs)


def test_bad_function_output():
    with pytest.raises(GHTError, match="shape"):
        fit_function(lambda t: np.ones((3, 3, 3)), tol=1e-6)
    with pytest.raises(GHTError, match="NaN"):
        fit_function(lambda t: np.full(t.shape, np.nan), tol=1e-6)


@pytest.mark.parametrize(
    "points",
    [
        [(1.0, 1.0, 1.0)] * 4,  # a point: default tol falls back to the rounding floor
        [(0, 0), (0, 0), (0, 0), (3, -1), (4, 0)],  # vanishing end derivatives
        np.array([(0, 0, 0), (1, 2, 0), (3, 1, 1)]) + 1e6,  # far from the origin
        np.array([(0, 0, 0), (1, 2, 0), (3, 1, 1)]) * 1e-9,  # tiny
    ],
)
def test_degenerate_and_badly_scaled_curves_convert(points):
    curve = GHTCurve(points, 0.2, 0.1, -0.5)
    bs = curve_to_bspline(curve)
    assert bs.max_deviation <= bs.info["tol"]
    assert _independent_deviation(curve, bs) <= bs.info["tol"]
    scale = float(np.abs(curve.control_points).max())
    assert bs.info["tol"] >= 64 * np.finfo(float).eps * scale


def test_many_spans_use_the_banded_solver_and_stay_certified():
    """> 400 poles (banded normal equations): still within tol, end jets still exact."""
    f = lambda t: np.column_stack([np.sin(40 * t), np.cos(40 * t)])  # noqa: E731
    bs = fit_function(f, tol=1e-8, degree=3, end_derivatives=([[0, 1], [40, 0]], []))
    assert bs.poles.shape[0] > 400
    assert bs.max_deviation <= 1e-8
    t = np.random.default_rng(0).uniform(0, 1, 50000)
    assert np.abs(bs.evaluate(t) - f(t)).max() <= 1e-8
    assert np.allclose(bs.evaluate([0.0], 1)[0], [40, 0], atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(p=st.integers(1, 8), spans=st.integers(1, 60), r0=st.integers(0, 3), r1=st.integers(0, 3),
       seed=st.integers(0, 2**31 - 1))
def test_banded_least_squares_matches_dense_lstsq(p, spans, r0, r1, seed):
    """The banded normal-equation solve (with end poles fixed) equals a dense QR/SVD least-squares
    solve to 1e-9 relative to the largest pole, on random breakpoints and data."""
    from scipy.interpolate import BSpline

    rng = np.random.default_rng(seed)
    r0, r1 = min(r0, p), min(r1, p)
    breaks = np.concatenate([[0.0], np.sort(rng.uniform(0.05, 0.95, spans - 1)), [1.0]])
    if np.any(np.diff(breaks) < 1e-3):
        breaks = np.linspace(0.0, 1.0, spans + 1)
    knots = clamped_knots(breaks, p)
    n = knots.size - p - 1
    if r0 + r1 >= n:
        return
    xg = 0.5 * (np.polynomial.legendre.leggauss(p + 2)[0] + 1.0)
    t = (breaks[:-1, None] + np.diff(breaks)[:, None] * xg[None, :]).ravel()
    F = rng.normal(size=(t.size, 3))
    fixed = np.zeros((n, 3))
    fixed[:r0] = rng.normal(size=(r0, 3))
    fixed[n - r1 :] = rng.normal(size=(r1, 3))
    A = BSpline(knots, np.eye(n), p)(t)
    free = np.zeros(n, dtype=bool)
    free[r0 : n - r1] = True
    expected = fixed.copy()
    expected[free] = np.linalg.lstsq(A[:, free], F - A[:, ~free] @ fixed[~free], rcond=None)[0]
    vals, first = _nonzero_basis(t, knots, p)
    assert np.allclose(vals, A[np.arange(t.size)[:, None], first[:, None] + np.arange(p + 1)], atol=1e-14)
    got = _banded_least_squares(vals, first, F, fixed, r0, n - r1)
    assert np.abs(got - expected).max() <= 1e-9 * max(1.0, float(np.abs(expected).max()))
    assert np.array_equal(got[~free], fixed[~free])


@pytest.mark.parametrize("p", [5, 8])
def test_steep_function_certified_with_few_poles(p):
    """A tanh front and a narrow Gaussian (error far from uniform): deviation <= tol on 200 001
    fresh parameters, reported maximum within 1e-6 of the true one, and at most 150 poles
    (the refine-then-reduce fitter before the equidistributing one needed 136 and 182)."""
    f = lambda t: np.column_stack([np.tanh(30 * (t - 0.3)), np.exp(-50 * (t - 0.7) ** 2), t])  # noqa: E731
    bs = fit_function(f, tol=1e-9, degree=p)
    t = np.concatenate([np.random.default_rng(p).uniform(0.0, 1.0, 200001), np.linspace(0.0, 1.0, 4001)])
    dev = float(np.linalg.norm(f(t) - bs.evaluate(t), axis=1).max())
    assert bs.max_deviation <= 1e-9 and dev <= 1e-9
    assert dev <= bs.max_deviation * (1 + 1e-6)
    assert bs.poles.shape[0] <= 150


def test_each_round_calls_func_once_and_never_repeats_a_span():
    """One call per fit round (the first also takes the 257 uniform check points, kept for all
    rounds), on the nodes of spans not seen before, then 3 calls per certification (zoom)."""
    calls: list[np.ndarray] = []

    def f(t: np.ndarray) -> np.ndarray:
        calls.append(np.array(t))
        return np.column_stack([np.sin(4 * t), np.exp(t)])

    bs = fit_function(f, tol=1e-9, degree=5)
    fits = bs.info["fits"]
    zooms, rest = divmod(len(calls) - fits, 3)
    assert rest == 0 and zooms >= 1
    nodes = 7 + 24  # per span for p = 5: 7 Gauss nodes + 24 check points
    assert np.array_equal(calls[0][:257], np.linspace(0.0, 1.0, 257))
    assert calls[0].size == 257 + 7 * nodes  # the 7 first spans
    rounds = [calls[0][257:]] + calls[1:fits]
    assert all(c.size % nodes == 0 for c in rounds)
    # no parameter evaluated twice in the fit rounds but the breakpoints (Lobatto ends shared by
    # neighbouring spans, 0 and 1): a call on s new spans repeats at most s + 1 values
    flat = np.concatenate(rounds)
    assert flat.size - np.unique(flat).size <= sum(c.size // nodes + 1 for c in rounds)
    assert bs.info["samples_checked"] == sum(c.size for c in calls)


@given(st.integers(2, 12), shape, shape, shape, st.integers(0, 2**32 - 1), st.sampled_from([2, 3, 5, 8]))
@settings(max_examples=40)
def test_end_poles_are_the_end_control_points_exactly(degree, mu, nu, gamma, seed, p):
    # C(0) = P_0 and C(1) = P_m bit for bit (b_{i,m}(0) = δ_i0): edges of a wire then meet in the
    # user's exact points. The end poles were solved by LU with pivoting and came out as
    # (-4.0e-16, -6.0e-16, 0) for P_0 = (0, 0, 0) (GHTCurve [(0,0,0),(5,5,0),(10,0,0)], p = 5).
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=(degree + 1, 3)) * rng.choice([1e-3, 1.0, 1e3])
    pts[0] = 0.0
    c = GHTCurve(pts, mu, nu, gamma)
    b = curve_to_bspline(c, degree=p)
    assert np.array_equal(b.poles[0], c.control_points[0])
    assert np.array_equal(b.poles[-1], c.control_points[-1])


def test_end_poles_exact_for_the_reported_case():
    b = curve_to_bspline(GHTCurve([(0, 0, 0), (5, 5, 0), (10, 0, 0)]))
    assert np.array_equal(b.poles[0], [0.0, 0.0, 0.0]) and np.array_equal(b.poles[-1], [10.0, 0.0, 0.0])
