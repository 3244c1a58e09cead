"""Property tests of the GHT seeds and the degree-m basis (spec sections 1-3).

Tolerances: identities that hold exactly in real arithmetic are checked to 1e-13 (absolute, the
basis values are O(1)); derivatives against finite differences to a relative 1e-6 of the
derivative's scale (4th-order central stencil, h = 1e-3).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from ght_cad import GBTSeed, GHTCurve, GHTSeed, basis, bernstein
from ght_cad.curves.basis import bernstein_recursive_basis, seed_basis

params = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False)
degrees = st.integers(min_value=2, max_value=10)
T = np.linspace(0.0, 1.0, 101)


@given(degrees, params, params, params)
def test_partition_of_unity_and_nonnegativity(m: int, mu: float, nu: float, gamma: float) -> None:
    b = basis(T, m, mu, nu, gamma)
    assert b.shape == (T.size, m + 1)
    np.testing.assert_allclose(b.sum(axis=1), 1.0, rtol=0, atol=1e-13)
    assert b.min() >= -1e-14
    # derivatives of a partition of unity sum to zero
    for r in (1, 2, 3):
        d = basis(T, m, mu, nu, gamma, derivative=r)
        assert np.abs(d.sum(axis=1)).max() <= 1e-11 * max(1.0, np.abs(d).max())


@given(degrees, params, params, params)
def test_end_values(m: int, mu: float, nu: float, gamma: float) -> None:
    b = basis(np.array([0.0, 1.0]), m, mu, nu, gamma)
    expected = np.zeros((2, m + 1))
    expected[0, 0] = expected[1, m] = 1.0
    np.testing.assert_allclose(b, expected, atol=1e-15)


@given(degrees, params, params, params)
def test_symmetry(m: int, mu: float, nu: float, gamma: float) -> None:
    """b_{i,m}(t; μ,ν,γ) = b_{m-i,m}(1-t; ν,μ,γ)."""
    b = basis(T, m, mu, nu, gamma)
    br = basis(1.0 - T, m, nu, mu, gamma)[:, ::-1]
    np.testing.assert_allclose(b, br, atol=1e-14)


@given(degrees, params, params)
def test_gamma_one_is_bernstein(m: int, mu: float, nu: float) -> None:
    for r in range(4):
        np.testing.assert_allclose(basis(T, m, mu, nu, 1.0, derivative=r), bernstein(T, m, r), atol=1e-10 * 10**r)


@given(degrees, params, params)
def test_gamma_minus_one_is_gbt(m: int, mu: float, nu: float) -> None:
    gbt = GBTSeed(mu, nu)
    for r in range(4):
        np.testing.assert_allclose(
            basis(T, m, mu, nu, -1.0, derivative=r), seed_basis(T, m, gbt, r), atol=1e-13 * 10**r
        )
    # and the GBT seed is exactly the spec's formula
    s, c = np.sin(np.pi * T / 2), np.cos(np.pi * T / 2)
    np.testing.assert_allclose(gbt.jet(T)[:, 0], (1 - s) * (1 - mu * s), atol=1e-15)
    np.testing.assert_allclose(gbt.jet(T)[:, 2], (1 - c) * (1 - nu * c), atol=1e-15)


@given(degrees, params, params, params)
def test_closed_form_equals_recursion(m: int, mu: float, nu: float, gamma: float) -> None:
    seed = GHTSeed(mu, nu, gamma)
    np.testing.assert_allclose(basis(T, m, mu, nu, gamma), bernstein_recursive_basis(T, m, seed), atol=1e-14)


@given(degrees, params, params, params)
@example(2, -1.0, -1.0, -1.0)
@example(2, -1.0, -1.0, -0.9999999999999999)
@example(10, -1.0, -1.0, -1.0)
def test_linear_independence(m: int, mu: float, nu: float, gamma: float) -> None:
    """Linearly independent on the whole box for m >= 3; for m = 2 everywhere but one corner.

    At m = 2, mu = nu = gamma = -1 the seed is (c², 0, s²): f1 ≡ 0 and b_{1,2} vanishes, so the
    spec's independence claim fails exactly there (found by hypothesis with a random seed; the old
    bound 1e-8 also failed within ~1e-8 of that corner). Near it the conditioning degrades
    linearly in the distance d = 3 + mu + nu + gamma (measured: sigma_min/sigma_max >= 0.063 d).
    """
    tt = (np.arange(m + 1) + 0.5) / (m + 1)
    B = basis(tt, m, mu, nu, gamma)
    sv = np.linalg.svd(B, compute_uv=False)
    if m >= 3:
        assert sv.min() > 1e-5 * sv.max()  # measured >= 6.4e-5 (m = 10 at the corner)
    else:
        d = min(1.0, 3.0 + mu + nu + gamma)
        assert sv.min() > 0.03 * d * sv.max() - 1e-15
        if d == 0.0:
            t = np.linspace(0.0, 1.0, 101)
            assert np.abs(basis(t, 2, mu, nu, gamma)[:, 1]).max() < 1e-15  # f1 ≡ 0: P_1 has no influence


def _fd4(f, t: np.ndarray, h: float) -> np.ndarray:
    """4th-order central difference."""
    return (-f(t + 2 * h) + 8 * f(t + h) - 8 * f(t - h) + f(t - 2 * h)) / (12 * h)


@given(degrees, params, params, params)
def test_derivatives_match_finite_differences(m: int, mu: float, nu: float, gamma: float) -> None:
    tt = np.linspace(0.05, 0.95, 19)
    h = 1e-3
    for r in (1, 2, 3):
        analytic = basis(tt, m, mu, nu, gamma, derivative=r)
        fd = _fd4(lambda x: basis(x, m, mu, nu, gamma, derivative=r - 1), tt, h)
        scale = max(1.0, np.abs(analytic).max())
        assert np.abs(analytic - fd).max() <= 1e-6 * scale, (r, np.abs(analytic - fd).max(), scale)


@given(params, params, params)
def test_seed_jets_table(mu: float, nu: float, gamma: float) -> None:
    """The jets table of spec section 1 from the seed's analytic derivatives."""
    seed = GHTSeed(mu, nu, gamma)
    a, e = seed.end_jets()
    w = (1 + gamma) / 2
    pi = math.pi
    assert a[1, 0] == pytest.approx(-(1 - w) * (1 + mu) * pi / 2 - 2 * w, abs=1e-13)
    assert a[2, 0] == pytest.approx((1 - w) * mu * pi**2 / 2 + 2 * w, abs=1e-13)
    assert a[3, 0] == pytest.approx((1 - w) * (1 + mu) * pi**3 / 8, abs=1e-12)
    assert a[2, 2] == pytest.approx((1 - w) * (1 - nu) * pi**2 / 4 + 2 * w, abs=1e-13)
    assert a[1, 2] == pytest.approx(0.0, abs=1e-14)
    assert a[3, 2] == pytest.approx(0.0, abs=1e-12)
    for r in (1, 2, 3):
        assert a[r, 1] == pytest.approx(-(a[r, 0] + a[r, 2]), abs=1e-12)
    # at t = 1 by symmetry: e_r^2(μ,ν) = (-1)^r a_r^0(ν,μ), e_r^0(μ,ν) = (-1)^r a_r^2(ν,μ)
    a_sw, _ = GHTSeed(nu, mu, gamma).end_jets()
    for r in range(4):
        assert e[r, 2] == pytest.approx((-1) ** r * a_sw[r, 0], abs=1e-12)
        assert e[r, 0] == pytest.approx((-1) ** r * a_sw[r, 2], abs=1e-12)
    # seed admissibility: f2'(0) = f0'(1) = 0 and values at the ends
    np.testing.assert_allclose(a[0], [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(e[0], [0, 0, 1], atol=1e-15)
    assert abs(e[1, 0]) <= 1e-14


@given(degrees, params, params, params, st.integers(0, 2**31 - 1))
def test_end_derivative_formulas(m: int, mu: float, nu: float, gamma: float, seed: int) -> None:
    """P^(r)(0), P^(r)(1) by the spec's end-jet formula equal the analytic derivative."""
    pts = np.random.default_rng(seed).normal(size=(m + 1, 3))
    c = GHTCurve(pts, mu, nu, gamma)
    for r in range(4):
        for end in (0, 1):
            d = c.derivative(float(end), r)
            assert np.abs(c.end_derivative(end, r) - d).max() <= 1e-11 * max(1.0, np.abs(d).max())


@given(degrees, params, params, params)
def test_newest_point_coefficients(m: int, mu: float, nu: float, gamma: float) -> None:
    """c_1 = n + a_1^1, c_2 = n(n-1) + 2n a_1^1 + a_2^2, c_3 = n(n-1)(n-2) + 3n(n-1) a_1^1 + 3n a_2^2."""
    c = GHTCurve(np.zeros((m + 1, 2)) + np.arange(m + 1)[:, None], mu, nu, gamma)
    a, _ = c.seed.end_jets()
    n = m - 2
    c1 = n + a[1, 1]
    c2 = n * (n - 1) + 2 * n * a[1, 1] + a[2, 2]
    c3 = n * (n - 1) * (n - 2) + 3 * n * (n - 1) * a[1, 1] + 3 * n * a[2, 2]
    for r, cr in ((1, c1), (2, c2), (3, c3)):
        assert c.newest_point_coefficient(r) == pytest.approx(cr, abs=1e-11)
    # c_1 = n + (1-w)(1+mu) pi/2 + 2w >= 0, zero only for m = 2 at mu = gamma = -1 (stationary seed)
    c1 = c.newest_point_coefficient(1)
    assert c1 >= -1e-15
    if c1 <= 1e-12:
        assert m == 2 and mu == -1.0 and gamma == -1.0


def test_first_end_derivative_closed_form() -> None:
    """P'(0) = [n - a_1^0](P1 - P0), P'(1) = [n + e_1^2](P_m - P_{m-1})."""
    pts = np.array([[0, 0], [1, 2], [3, 3], [4, 1], [6, 0]], float)
    c = GHTCurve(pts, 0.4, -0.3, 0.2)
    a, e = c.seed.end_jets()
    n = c.degree - 2
    np.testing.assert_allclose(c.derivative(0.0), (n - a[1, 0]) * (pts[1] - pts[0]), atol=1e-13)
    np.testing.assert_allclose(c.derivative(1.0), (n + e[1, 2]) * (pts[-1] - pts[-2]), atol=1e-13)


def _cubic_seed_class(name: str) -> type:
    """A custom seed ``f0 = (1-t)^3, f2 = t^3`` (admissible: f2'(0) = f0'(1) = 0), orders 0..3 only."""
    from ght_cad import Seed

    class CubicSeed(Seed):
        def f0_f2(self, t, order=0):
            if order == 0:
                return (1 - t) ** 3, t**3
            if order == 1:
                return -3 * (1 - t) ** 2, 3 * t**2
            if order == 2:
                return 6 * (1 - t), 6 * t
            return np.full_like(t, -6.0), np.full_like(t, 6.0)

    CubicSeed.name = name
    return CubicSeed


def test_custom_seed_registration(monkeypatch: pytest.MonkeyPatch) -> None:
    """A user-registered seed plugs into the basis and curves."""
    import ght_cad.curves.seeds
    from ght_cad import Seed, make_seed, register_seed, seed_names

    # keep the global registry as it was after this test
    monkeypatch.setattr(ght_cad.curves.seeds, "_REGISTRY", dict(ght_cad.curves.seeds._REGISTRY))

    CubicSeed = _cubic_seed_class("cubic-test")
    assert issubclass(CubicSeed, Seed)
    register_seed("cubic-test", CubicSeed)
    assert "cubic-test" in seed_names()
    b = basis(T, 5, seed="cubic-test")
    np.testing.assert_allclose(b.sum(axis=1), 1.0, atol=1e-14)
    c = GHTCurve([[0, 0], [1, 1], [2, 0], [3, 1]], seed=make_seed("cubic-test"))
    np.testing.assert_allclose(c.evaluate(1.0), [3, 1], atol=1e-15)
    # its reversal goes through the generic ReversedSeed
    np.testing.assert_allclose(c.reversed().evaluate(T), c.evaluate(1 - T), atol=1e-14)


# -- one-pass jets and derivatives (seeds.ght_seed_jet / Seed.jets / basis.evaluate_derivatives) --
def _seeds(mu: float, nu: float, gamma: float) -> list:
    from ght_cad.curves.seeds import BernsteinSeed, ReversedSeed

    ght = GHTSeed(mu, nu, gamma)
    return [ght, GBTSeed(mu, nu), BernsteinSeed(), ReversedSeed(ght), _cubic_seed_class("cubic-jets-test")(), ReversedSeed(_cubic_seed_class("cubic-jets-test")())]


@given(params, params, params)
def test_seed_jets_equal_single_order_jets_exactly(mu: float, nu: float, gamma: float) -> None:
    """``Seed.jets(t, K)[r]`` is bit for bit ``Seed.jet(t, r)`` (same formula, shared sin/cos pass)."""
    for seed in _seeds(mu, nu, gamma):
        J = seed.jets(T, 3)
        assert len(J) == 4
        for r in range(4):
            np.testing.assert_array_equal(J[r], seed.jet(T, r))


@given(st.lists(st.tuples(params, params, params), min_size=1, max_size=6), st.integers(0, 6))
def test_ght_seed_jet_broadcasts_over_parameter_sets(P: list, r: int) -> None:
    """``ght_seed_jet`` on (P, 1) parameter columns gives, row by row, exactly ``GHTSeed.f0_f2``."""
    from ght_cad.curves.seeds import ght_seed_derivatives, ght_seed_jet

    arr = np.array(P)
    f0, f2 = ght_seed_jet(T, arr[:, :1], arr[:, 1:2], arr[:, 2:3], r)
    assert f0.shape == f2.shape == (len(P), T.size)
    for i, (mu, nu, gamma) in enumerate(P):
        g0, g2 = GHTSeed(mu, nu, gamma).f0_f2(T, r)
        np.testing.assert_array_equal(f0[i], g0)
        np.testing.assert_array_equal(f2[i], g2)
    # all orders at once: the same arrays
    for q, (a0, a2) in enumerate(ght_seed_derivatives(T, arr[:, :1], arr[:, 1:2], arr[:, 2:3], r)):
        b0, b2 = ght_seed_jet(T, arr[:, :1], arr[:, 1:2], arr[:, 2:3], q)
        np.testing.assert_array_equal(a0, b0)
        np.testing.assert_array_equal(a2, b2)


@given(params, params, params, st.integers(1, 6))
def test_ght_seed_high_orders_are_derivatives(mu: float, nu: float, gamma: float, r: int) -> None:
    """Order r of the GHT seed is the derivative of order r-1 (4th-order central differences, h=1e-3):
    relative 1e-6 of the order-r scale (which grows like (π)^r)."""
    from ght_cad.curves.seeds import ght_seed_jet

    t = np.linspace(0.05, 0.95, 37)
    h = 1e-3
    hi = np.array(ght_seed_jet(t, mu, nu, gamma, r))
    lo = [np.array(ght_seed_jet(t + k * h, mu, nu, gamma, r - 1)) for k in (-2, -1, 1, 2)]
    fd = (lo[0] - 8 * lo[1] + 8 * lo[2] - lo[3]) / (12 * h)
    assert np.abs(fd - hi).max() <= 1e-6 * max(1.0, math.pi**r)


def test_jets_reject_orders_a_seed_does_not_provide() -> None:
    from ght_cad.core.errors import GHTError

    cubic = _cubic_seed_class("cubic-jets-test")()
    with pytest.raises(GHTError, match="derivative order 4 .* provides orders 0..3"):
        cubic.jets(T, 4)
    with pytest.raises(GHTError, match="derivative order -1 .* provides orders 0, 1, 2"):
        GHTSeed().jets(T, -1)
    assert len(GHTSeed(0.2, 0.1, -0.4).jets(T, 6)) == 7  # the GHT family: every order


@given(st.integers(2, 9), params, params, params, st.integers(0, 5))
def test_evaluate_derivatives_equals_basis_matrix_products(m: int, mu: float, nu: float, gamma: float, which: int) -> None:
    """``evaluate_derivatives`` (compact form, one pass) = ``seed_basis(t, m, seed, r) @ P`` for r = 0..3,
    to 1e-13 relative to the size of the control points times (m+1) π^r (the scale of b^(r))."""
    from ght_cad.curves.basis import evaluate_derivatives, seed_basis_derivatives

    seed = _seeds(mu, nu, gamma)[which]
    P = np.random.default_rng(m).normal(size=(m + 1, 4))
    D = evaluate_derivatives(T, P, seed, 3)
    B = seed_basis_derivatives(T, m, seed, 3)
    for r in range(4):
        ref = seed_basis(T, m, seed, r)
        np.testing.assert_array_equal(B[r], ref)  # the same Leibniz combination
        scale = np.abs(P).max() * (m + 1) * math.pi**r * max(1, m) ** r
        np.testing.assert_allclose(D[r], ref @ P, rtol=0, atol=1e-13 * scale)


def test_evaluate_derivatives_chunks_long_inputs() -> None:
    """Parameters beyond one chunk (32768) give the same values as evaluating the pieces."""
    from ght_cad.curves.basis import evaluate_derivatives

    t = np.linspace(0.0, 1.0, 70001)
    P = np.random.default_rng(3).normal(size=(6, 3))
    seed = GHTSeed(0.3, -0.5, 0.2)
    whole = evaluate_derivatives(t, P, seed, 2)
    for lo, hi in ((0, 1000), (40000, 41000), (69000, 70001)):
        part = evaluate_derivatives(t[lo:hi], P, seed, 2)
        for r in range(3):
            np.testing.assert_array_equal(whole[r][lo:hi], part[r])


@given(params, params)
def test_second_derivative_cancels_exactly_at_the_ends(other: float, gamma: float) -> None:
    """f0''(1) = (1-w) π²/4 (1-μ) + 2w and f2''(0) = (1-w) π²/4 (1-ν) + 2w: at μ = 1 (ν = 1) the
    trigonometric part cancels to exactly 0 in floating point (cos(πt) is exactly -1 at t = 1), so
    degenerate ends are recognised (a boundary tangent that vanishes, not one of size 1e-15)."""
    w = 0.5 * (1.0 + gamma)
    f0, _ = GHTSeed(1.0, other, gamma).f0_f2(np.array([1.0]), 2)
    _, f2 = GHTSeed(other, 1.0, gamma).f0_f2(np.array([0.0]), 2)
    assert f0[0] == 2.0 * w and f2[0] == 2.0 * w
    assert GHTSeed(1.0, other, gamma).jets(np.array([1.0]), 3)[2][0, 0] == 2.0 * w
