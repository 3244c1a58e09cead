"""Joins C0–C3 / G0–G3 and their independent measurement (spec section 4)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ght_cad import GHTCurve
from ght_cad.curves.continuity import Continuity, join, measure_continuity, reverse_g_parameters
from ght_cad.core.errors import GHTError, SingularJoinError

# Tolerances: measure_continuity's default relative tol (1e-9) is used throughout; a join is
# exact up to rounding, so residuals are ~1e-15, six orders below it.
TOL = 1e-9

param = st.floats(-1.0, 1.0, allow_nan=False)
shape3 = st.tuples(param, param, param)


def _coef(curve: GHTCurve, r: int, end: int = 0) -> float:
    return abs(curve.newest_point_coefficient(r, end=end))


@settings(max_examples=300)
@given(
    cont=st.sampled_from(list(Continuity)),
    ma=st.integers(2, 8),
    mb=st.integers(2, 8),
    dim=st.integers(2, 4),
    sa=shape3,
    sb=shape3,
    k=st.floats(0.25, 4.0),
    beta2=st.floats(-2.0, 2.0),
    beta3=st.floats(-2.0, 2.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_join_reaches_requested_order_and_no_higher(cont, ma, mb, dim, sa, sb, k, beta2, beta3, seed):
    r = cont.order
    mb = max(mb, r)
    rng = np.random.default_rng(seed)
    a = GHTCurve(rng.normal(size=(ma + 1, dim)), *sa)
    b_pts = rng.normal(size=(mb + 1, dim))
    b0 = GHTCurve(b_pts, *sb)
    # solvable: every newest-point coefficient of B up to r is away from 0; A's end tangent exists
    assume(all(_coef(b0, j) > 1e-3 for j in range(r + 1)))
    assume(_coef(a, 1, end=1) > 1e-2)
    if cont.geometric:
        assume(abs(k - 1.0) > 0.05)
        g = dict(k=k, beta2=beta2, beta3=beta3)
    else:
        g = {}
    b = join(a, cont, b0, **g)
    # remaining points are kept, the shape parameters too
    np.testing.assert_array_equal(b.control_points[r + 1 :], b_pts[r + 1 :])
    assert b.shape_parameters == b0.shape_parameters
    rep = measure_continuity(a, b)
    assert max(rep.c_residuals[: r + 1] if not cont.geometric else rep.g_residuals[: r + 1]) < 1e-12
    assert rep.satisfies(cont)
    if cont.geometric and r >= 1:
        assert rep.k == pytest.approx(k, rel=1e-9)
        if r >= 2:
            assert rep.beta2 == pytest.approx(beta2, rel=1e-7, abs=1e-7)
        if r >= 3:
            assert rep.beta3 == pytest.approx(beta3, rel=1e-7, abs=1e-7)
    # not higher by accident: B's point R_{r+1} is random and enters order r+1 with weight c_{r+1}
    if r < 3 and mb > r:
        assume(_coef(b0, r + 1) > 0.05)
        assert rep.g_order == r, (str(rep), rep.g_residuals)
        assert rep.c_order == (0 if cont.geometric else r), (str(rep), rep.c_residuals)
    elif r == 3 and cont.geometric:
        assert rep.c_order == 0  # k != 1: never C1
        assert rep.g_order == 3
    elif r == 3:
        assert rep.c_order == 3
    # else: B has no free point left (degree == r); higher orders may hold exactly, e.g. a
    # degree-2 curve always has R'''(0) parallel to R'(0), so C1 + degree 2 on both sides is G3.


def test_c1_point_matches_spec_closed_form():
    # R_1 = R_0 + P'(1)/c_1, P'(1) = [n_A + e_1^2](P_m - P_{m-1}), c_1 = n_B - a_1^0 (spec 3),
    # a_1^0 = f0'(0) = -(1-w)(1+mu)pi/2 - 2w, e_1^2(mu, nu) = -a_1^0(nu, mu).
    def a10(mu, w):
        return -(1 - w) * (1 + mu) * math.pi / 2 - 2 * w

    rng = np.random.default_rng(3)
    for ma, mb, (mua, nua, ga), (mub, nub, gb) in [
        (2, 5, (0.3, -0.7, -0.2), (-0.5, 0.9, 0.6)),
        (6, 3, (1.0, 1.0, -1.0), (-1.0, -1.0, 1.0)),
        (4, 4, (-0.2, 0.4, 0.9), (0.1, -0.3, -0.9)),
    ]:
        P = rng.normal(size=(ma + 1, 3))
        a = GHTCurve(P, mua, nua, ga)
        b = join(a, "C1", rng.normal(size=(mb + 1, 3)), mu=mub, nu=nub, gamma=gb)
        wa, wb = (1 + ga) / 2, (1 + gb) / 2
        dP = ((ma - 2) - a10(nua, wa)) * (P[-1] - P[-2])
        c1 = (mb - 2) - a10(mub, wb)
        np.testing.assert_allclose(b.control_points[0], P[-1], atol=1e-14)
        np.testing.assert_allclose(b.control_points[1], P[-1] + dP / c1, rtol=1e-12, atol=1e-12)


def test_measure_on_exact_circle_arcs():
    # gamma = -1, mu = nu = 0: (1,0),(1,1),(0,1) is exactly (cos(pi t/2), sin(pi t/2)).
    q1 = GHTCurve([(1, 0), (1, 1), (0, 1)], gamma=-1)
    q2 = GHTCurve([(0, 1), (-1, 1), (-1, 0)], gamma=-1)  # next quarter: same circle, same speed
    rep = measure_continuity(q1, q2)
    assert (rep.c_order, rep.g_order) == (3, 3)
    # radius-2 arc tangent at (0, 1): tangent ratio k = 2, curvature 1 vs 1/2: G1 only
    big = GHTCurve([(0, 1), (-2, 1), (-2, -1)], gamma=-1)
    rep = measure_continuity(q1, big)
    assert (rep.c_order, rep.g_order) == (0, 1)
    assert rep.k == pytest.approx(2.0, rel=1e-12)
    assert rep.g_residuals[2] > 0.01
    # cusp: tangent reversed, k = -1: G0 only
    back = GHTCurve([(0, 1), (1, 1), (1, 2)], gamma=-1)
    rep = measure_continuity(q1, back)
    assert (rep.c_order, rep.g_order) == (0, 0) and rep.k < 0
    # gap: not even C0
    gap = q2.translated((0.0, 1e-6))
    rep = measure_continuity(q1, gap)
    assert (rep.c_order, rep.g_order) == (-1, -1)


def test_tolerance_is_relative_and_respected():
    rng = np.random.default_rng(7)
    a = GHTCurve(rng.normal(size=(5, 2)), 0.2, -0.4, 0.1)
    b = join(a, "C2", rng.normal(size=(6, 2)), mu=-0.3, nu=0.5, gamma=-0.6)
    assert measure_continuity(a, b).c_order == 2
    # same joint scaled by 1e6 and moved far away: still C2 (relative tolerance)
    big_a = a.transformed(1e6 * np.eye(2), (3e6, -2e6))
    big_b = b.transformed(1e6 * np.eye(2), (3e6, -2e6))
    assert measure_continuity(big_a, big_b).c_order == 2
    # perturb R_2 by 1e-13 (relative): still C2 at tol 1e-9; by 1e-5: C1 only
    for delta, expected in [(1e-13, 2), (1e-5, 1)]:
        pts = np.array(b.control_points)
        pts[2] += delta * np.array([1.0, -1.0])
        rep = measure_continuity(a, b.with_control_points(pts))
        assert rep.c_order == expected, rep.c_residuals
    with pytest.raises(GHTError, match="tol"):
        measure_continuity(a, b, tol=0.0)


def test_reverse_g_parameters_solve_the_same_joint_backwards():
    rng = np.random.default_rng(11)
    k, b2, b3 = 1.7, -0.8, 0.6
    a = GHTCurve(rng.normal(size=(7, 3)), 0.4, -0.2, -0.5)
    b = join(a, "G3", rng.normal(size=(6, 3)), mu=0.6, nu=0.1, gamma=0.3, k=k, beta2=b2, beta3=b3)
    # rebuild A's last four points from B's start, joining the reversed curves
    kr, b2r, b3r = reverse_g_parameters(k, b2, b3)
    scrambled = a.with_control_points(np.vstack([a.control_points[:3], rng.normal(size=(4, 3))]))
    a2 = join(b.reversed(), "G3", scrambled.reversed(), k=kr, beta2=b2r, beta3=b3r).reversed()
    np.testing.assert_allclose(a2.control_points, a.control_points, rtol=1e-9, atol=1e-9)


def test_join_4d_plane_coordinates():
    # dual curves of developables: 4-D plane coordinates (spec 5.6)
    rng = np.random.default_rng(5)
    planes_a = rng.normal(size=(5, 4))
    a = GHTCurve(planes_a, -0.3, 0.8, -1.0)
    b = join(a, "G2", rng.normal(size=(6, 4)), mu=0.5, nu=-0.5, gamma=0.2, k=0.7, beta2=0.3)
    rep = measure_continuity(a, b)
    assert (rep.c_order, rep.g_order) == (0, 2)
    assert rep.k == pytest.approx(0.7, rel=1e-10)
    assert rep.beta2 == pytest.approx(0.3, rel=1e-8)
    np.testing.assert_allclose(b.evaluate(0.0), a.evaluate(1.0), atol=1e-14)
    c = join(a, "C3", rng.normal(size=(8, 4)), gamma=-1.0)
    for r in range(4):
        np.testing.assert_allclose(c.derivative(0.0, r), a.derivative(1.0, r), rtol=1e-11, atol=1e-11)
    assert measure_continuity(a, c).c_order == 3


def test_array_input_and_overrides():
    a = GHTCurve([(0, 0), (1, 1), (2, 0)], gamma=-1)
    b = join(a, "g1", [(9, 9), (9, 9), (3, -1), (4, 0)], k=2.0, mu=0.5)
    assert b.shape_parameters == (0.5, 0.0, 0.0)
    b2 = join(a, Continuity.C1, GHTCurve([(9, 9), (9, 9), (3, -1)], 0.1, 0.2, 0.3), gamma=-0.5)
    assert b2.shape_parameters == (0.1, 0.2, -0.5)
    assert measure_continuity(a, b2).c_order >= 1


def test_continuity_enum():
    assert Continuity.parse("g2") is Continuity.G2
    assert Continuity(" c3 ".strip()) is Continuity.C3
    assert Continuity.G3.order == 3 and Continuity.G3.geometric
    assert Continuity.C1.order == 1 and not Continuity.C1.geometric
    assert Continuity.G2 == "G2"
    with pytest.raises(GHTError, match=r"continuity='H2' is not allowed; use one of C0, C1"):
        Continuity.parse("H2")
    with pytest.raises(ValueError, match="not allowed"):
        Continuity("x")


def test_singular_cases_raise_clear_errors():
    a = GHTCurve([(0, 0), (1, 1), (2, 0), (3, 1)], 0.2, 0.3, 0.0)
    # degree 2, gamma = -1, mu = -1: c_1 = n - a_1^0 = 0
    with pytest.raises(SingularJoinError, match=r"C1.*c_1 .* is 0 \(zero\) for segment B of degree 2 with mu=-1, nu=0, gamma=-1"):
        join(a, "C1", [(0, 0), (1, 0), (2, 0)], mu=-1.0, gamma=-1.0)
    # degree 3, gamma = -1, nu = 1: c_3 = 3 n a_2^2 = 0 (a_2^2 = f2''(0) vanishes)
    with pytest.raises(SingularJoinError, match=r"G3.*c_3 .*degree 3 with mu=0, nu=1, gamma=-1"):
        join(a, "G3", [(0, 0), (1, 0), (2, 0), (3, 0)], nu=1.0, gamma=-1.0, k=1.5)
    # degree 3, gamma = -1, mu = -1, nu = 1: c_2 = 2 a_1^1 + a_2^2 = 0 (up to rounding 1e-16)
    with pytest.raises(SingularJoinError, match=r"c_2 .*degree 3 with mu=-1, nu=1, gamma=-1"):
        join(a, "C2", [(0, 0), (1, 0), (2, 0), (3, 0)], mu=-1.0, nu=1.0, gamma=-1.0)
    # B's degree too low to carry R_0..R_3
    with pytest.raises(SingularJoinError, match=r"G3.*segment B has degree 2 \(3 points\); G3 needs degree >= 3"):
        join(a, "G3", [(0, 0), (1, 0), (2, 0)])
    for bad_k in (0.0, -1.0):
        with pytest.raises(SingularJoinError, match=rf"k={bad_k:g} is not allowed: geometric continuity needs k > 0"):
            join(a, "G1", [(0, 0), (1, 0), (2, 0)], k=bad_k)
    with pytest.raises(GHTError, match="k=nan is not finite"):
        join(a, "G1", [(0, 0), (1, 0), (2, 0)], k=float("nan"))
    with pytest.raises(GHTError, match="segment_b has dimension 3 but segment_a has dimension 2"):
        join(a, "C1", [(0, 0, 0), (1, 0, 0), (2, 0, 0)])
    with pytest.raises(GHTError, match="apply to G1..G3 only"):
        join(a, "C2", [(0, 0), (1, 0), (2, 0)], k=2.0)
    with pytest.raises(GHTError, match="mu=2 is outside the allowed range"):
        join(a, "C1", [(0, 0), (1, 0), (2, 0)], mu=2.0)
    with pytest.raises(GHTError, match="measure_continuity needs two GHTCurve"):
        measure_continuity(a, [(0, 0), (1, 0), (2, 0)])


def test_join_end_rows_match_full_basis_evaluation():
    # join uses closed-form end rows from the seed's end jets; measure_continuity evaluates the
    # full basis. Both must agree (reversed seeds go through the uncached generic path).
    from ght_cad.curves.continuity import _end_rows, _end_rows_fast

    rng = np.random.default_rng(17)
    for m in range(2, 11):
        for curve in (
            GHTCurve(rng.normal(size=(m + 1, 2)), *rng.uniform(-1, 1, 3)),
            GHTCurve(rng.normal(size=(m + 1, 2)), *rng.uniform(-1, 1, 3)).reversed(),
            GHTCurve(rng.normal(size=(m + 1, 2)), 0.4, -0.6, seed="gbt"),
            GHTCurve(rng.normal(size=(m + 1, 2)), seed="bernstein"),
        ):
            for end in (0, 1):
                for x, y in zip(_end_rows(curve, end, 3), _end_rows_fast(curve, end, 3)):
                    np.testing.assert_allclose(y, x, rtol=1e-13, atol=1e-13 * max(1.0, np.abs(x).max()))


@pytest.mark.parametrize("cont", ["G1", "G2", "G3"])
def test_geometric_join_refuses_a_vanishing_end_tangent_of_segment_a(cont):
    # degree 2 with nu = -1, gamma = -1: P'(1) = (n + e_1^2)(P_2 - P_1) = 0 for any points (spec 1, 3),
    # so G1 (unit tangent continuity) is undefined; before the fix join returned B with R_1 = R_0
    # (a cusp) that measure_continuity then reported as G1 with k = 3.15 from rounding noise
    a = GHTCurve([(0, 0), (1, 1), (2, 0)], mu=0.3, nu=-1.0, gamma=-1.0)
    assert np.linalg.norm(a.derivative([1.0])[0]) < 1e-14
    with pytest.raises(SingularJoinError, match=rf"{cont}.*tangent P'\(1\) of segment A vanishes.*nu=-1, gamma=-1"):
        join(a, cont, [(0, 0), (0, 0), (3, 1), (4, 0)], k=2.0)
    # parametric C1 stays allowed (R'(0) = P'(1) = 0 holds exactly)
    b = join(a, "C1", [(0, 0), (0, 0), (3, 1), (4, 0)])
    rep = measure_continuity(a, b)
    assert rep.c_order >= 1
    # the G parameters are undefined there: NaN, as documented, not least-squares fits of noise
    assert math.isnan(rep.k) and math.isnan(rep.beta2) and math.isnan(rep.beta3)
    assert any("vanishes" in n for n in rep.notes)
