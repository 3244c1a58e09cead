"""Problems over shape parameters (spec sections 5, 7): vectorized objectives and their optima."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from ght_cad import GHTCurve, basis
from ght_cad.curves.curve import integrate
from ght_cad.core.errors import GHTError
from ght_cad.optimize import igwo, pso
from ght_cad.optimize.problems import (
    CurveFairnessProblem,
    EnvelopeStrip,
    StripProblem,
    default_dual_problem,
    default_interpolation_problem,
    default_strip_problem,
    ght_seed_jets,
    population_basis,
)

box = st.floats(-1.0, 1.0)


@settings(max_examples=40)
@given(mu=box, nu=box, gamma=box, degree=st.integers(2, 8), r=st.integers(0, 3))
def test_population_basis_equals_core_basis(mu, nu, gamma, degree, r):
    t = np.linspace(0.0, 1.0, 11)
    P = np.array([[mu, nu, gamma], [0.0, 0.0, 0.0]])
    B = population_basis(t, degree, P[:, 0], P[:, 1], P[:, 2], r)
    for k in range(2):
        ref = basis(t, degree, *P[k], derivative=r)
        assert np.max(np.abs(B[k] - ref)) <= 1e-12 * max(1.0, np.max(np.abs(ref)))


@settings(max_examples=30)
@given(st.lists(st.tuples(box, box, box), min_size=1, max_size=5), st.integers(0, 3))
def test_population_seed_jets_are_the_core_seed_formula(P, r):
    """One GHT seed formula: the population jets equal ``GHTSeed.f0_f2`` row by row, bit for bit,
    and the population basis equals the core ``seed_basis`` row by row, bit for bit."""
    from ght_cad.curves.basis import seed_basis
    from ght_cad.curves.seeds import GHTSeed

    t = np.linspace(0.0, 1.0, 17)
    arr = np.array(P)
    f0, f2 = ght_seed_jets(t, arr[:, 0], arr[:, 1], arr[:, 2], r)
    B = population_basis(t, 5, arr[:, 0], arr[:, 1], arr[:, 2], r)
    for k, (mu, nu, gamma) in enumerate(P):
        seed = GHTSeed(mu, nu, gamma)
        g0, g2 = seed.f0_f2(t, r)
        np.testing.assert_array_equal(f0[k], g0)
        np.testing.assert_array_equal(f2[k], g2)
        np.testing.assert_array_equal(B[k], seed_basis(t, 5, seed, r))


@settings(max_examples=20)
@given(st.lists(box, min_size=6, max_size=6))
def test_strip_R_matches_ruled_surface(params):
    p = default_strip_problem()
    x = np.array(params)
    d = p.build(x).developability()
    assert p.value(x) == pytest.approx(d.R, rel=1e-12, abs=1e-16)


def test_strip_optimization_lowers_theta_max():
    p = default_strip_problem()
    before = p.report(p.x0)
    r = igwo(p, p.bounds, pop_size=20, max_iter=60, seed=0, x0=p.x0)
    after = p.report(r.x)
    # measured: theta_max 11.27 deg -> 0.22 deg, R 6.3e-3 -> 1.2e-6
    assert before["theta_max"] > 10.0
    assert after["theta_max"] < 0.05 * before["theta_max"]
    assert after["R"] < 1e-3 * before["R"] and after["DD"] > before["DD"]
    assert after["R"] == pytest.approx(r.fun, rel=1e-12)


@pytest.fixture(scope="module")
def strip_grid():
    """The two-parameter strip problem over (a.mu, b.nu) and its values on a 161 x 161 grid
    (evaluated once for both optimizers)."""
    p = default_strip_problem(free=("a.mu", "b.nu"))
    g = np.linspace(-1.0, 1.0, 161)
    G = np.array(np.meshgrid(g, g, indexing="ij")).reshape(2, -1).T
    v = np.concatenate([p(G[i : i + 4000]) for i in range(0, len(G), 4000)])
    return p, g, G, v


@pytest.mark.slow
@pytest.mark.parametrize("opt", [igwo, pso])
def test_strip_two_parameters_agree_with_dense_grid(opt, strip_grid):
    """Over (a.mu, b.nu) a 161 x 161 grid cannot beat the optimizer by more than 1e-6 relative."""
    p, g, G, v = strip_grid
    i = int(np.argmin(v))
    r = opt(p, p.bounds, pop_size=15, max_iter=40, seed=0)
    assert r.fun <= v[i] * (1.0 + 1e-6)
    assert np.all(np.abs(r.x - G[i]) <= 2 * (g[1] - g[0]))
    assert p.report(r.x)["theta_max"] < 0.5 * p.report(p.x0)["theta_max"]


def _fairness_reference(curve: GHTCurve) -> np.ndarray:
    """AL, En, CVEn by adaptive quadrature on the core curve's own derivatives."""
    return np.array([
        integrate(lambda t: np.linalg.norm(curve.derivative(t, 1), axis=1)),
        integrate(lambda t: np.sum(curve.derivative(t, 2) ** 2, axis=1)),
        integrate(lambda t: np.sum(curve.derivative(t, 3) ** 2, axis=1)),
    ])


@settings(max_examples=10)
@given(mu=box, nu=box, gamma=box)
def test_dual_measures_match_core_curve(mu, nu, gamma):
    p = default_dual_problem()
    x = np.array([mu, nu, gamma])
    m = p.measures(x[None])[0]
    U = p.dual_curve(x)
    assert np.allclose(np.linalg.norm(U.control_points[:, 1:], axis=1), 1.0)   # normalized planes
    assert np.allclose(m, _fairness_reference(U), rtol=1e-10)


@pytest.mark.slow
@pytest.mark.parametrize("objective", ["AL", "En", "CVEn"])
def test_dual_fairness_lowered_and_developable(objective):
    p = default_dual_problem(objective)
    f0 = p.value(np.zeros(3))
    r = igwo(p, p.bounds, pop_size=15, max_iter=40, seed=1)
    assert r.fun < f0 * (1.0 - 1e-3), (r.fun, f0)        # measured: -2.7 % (AL), -2.1 % (En), -69 % (CVEn)
    rep = p.report(r.x)
    assert rep[objective] == pytest.approx(r.fun, rel=1e-12)
    surf = p.build(r.x)
    d = surf.developability()
    assert d.theta_max < 1e-9 and d.residual_max < 1e-9          # round-off: measured ~1e-14 deg
    # an independent construction (meets of U, U', E) agrees with the developable module's surface
    own = EnvelopeStrip(p.dual_curve(r.x), p.boundary_planes)
    u = np.linspace(0.0, 1.0, 33)
    assert np.allclose(own.a(u), surf.a(u), atol=1e-9) and np.allclose(own.b(u), surf.b(u), atol=1e-9)
    assert own.developability().theta_max < 1e-9


def test_weighted_sum_is_the_weighted_measures():
    w = {"AL": 1.0, "En": 0.1, "CVEn": 0.01}
    p = default_dual_problem(w)
    X = np.random.default_rng(0).uniform(-1, 1, (5, 3))
    assert np.allclose(p(X), p.measures(X) @ np.array([1.0, 0.1, 0.01]), rtol=1e-14)


@pytest.mark.parametrize("objective", ["AL", "En", "CVEn"])
def test_interpolation_fairness(objective):
    p = default_interpolation_problem(objective)
    X = np.random.default_rng(2).uniform(-1, 1, (4, 3))
    for x in X:                                    # every parameter set interpolates the points
        c = p.build(x)
        assert np.allclose(c.evaluate(p.tj), p.points, atol=1e-10)
        assert np.allclose(p.measures(x[None])[0], _fairness_reference(c), rtol=1e-9)
    r = pso(p, p.bounds, pop_size=15, max_iter=40, seed=0)
    assert r.fun < p.value(np.zeros(3)) * (1.0 - 1e-3)


def test_curve_fairness_problem_3d():
    c = GHTCurve([[0, 0, 0], [1, 2, 0], [3, 2, 1], [4, 0, 1]])
    p = CurveFairnessProblem(c, "CVEn", free=("mu", "nu"), bounds={"mu": (-0.5, 0.5)})
    assert p.names == ("mu", "nu") and p.lb[0] == -0.5 and p.ub[0] == 0.5
    r = igwo(p, p.bounds, pop_size=10, max_iter=30, seed=0)
    assert r.fun < p.value(p.x0) and -0.5 <= r.x[0] <= 0.5
    assert np.allclose(p.measures(r.x[None])[0], _fairness_reference(p.build(r.x)), rtol=1e-10)


def test_problem_errors():
    with pytest.raises(GHTError, match="'a.xi' is unknown"):
        default_strip_problem(free=("a.xi",))
    with pytest.raises(GHTError, match=r"bounds for 'a.mu' = \(-2, 0\)"):
        default_strip_problem(free=("a.mu",), bounds={"a.mu": (-2.0, 0.0)})
    with pytest.raises(GHTError, match="nodes=32"):
        default_strip_problem(nodes=32)
    with pytest.raises(GHTError, match="objective='Energy'"):
        default_dual_problem("Energy")
    with pytest.raises(GHTError, match="no positive weight"):
        default_dual_problem({"AL": 0.0})
    with pytest.raises(GHTError, match="3-D GHTCurve"):
        StripProblem(GHTCurve([[0, 0], [1, 1], [2, 0]]), GHTCurve([[0, 1], [1, 2], [2, 1]]))
    with pytest.raises(GHTError, match="5 columns"):
        default_strip_problem()(np.zeros((2, 5)))
    with pytest.raises(GHTError, match="boundary_planes"):
        default_dual_problem().__class__(default_dual_problem().planes).build(np.zeros(3))


_QUINTIC = GHTCurve([[0.0, 0.1, 1.0], [0.8, 0.9, 1.3], [1.6, -0.2, 0.8], [2.2, 0.6, 1.4], [3.1, 0.1, 1.1], [3.9, 0.5, 1.2]])


@pytest.mark.parametrize("make", [
    default_strip_problem,
    lambda: StripProblem(default_strip_problem().curve_a, _QUINTIC),  # degrees 3 and 5: curves evaluated apart
], ids=["same degree", "mixed degrees"])
@settings(max_examples=15, deadline=None)
@given(data=st.data())
def test_strip_kernel_is_the_reference_evaluation(make, data):
    """The fast strip kernel (stacked seed jets, padded Bernstein products, four cross products for
    the whole gradient) gives the values of the direct basis-matrix route bit for bit (the thesis'
    optimizers see the same objective) and the same gradient to 1e-12 of its size."""
    p = _STRIPS.setdefault(id(make), make())
    pop = data.draw(st.integers(1, 6))
    X = np.array([[data.draw(box) for _ in range(6)] for _ in range(pop)])
    F = p.full(X)
    val, G = p._r_and_grad(F, True)
    ref, Gref = p._r_and_grad_reference(F, True)
    assert np.array_equal(val, ref)
    assert np.array_equal(p._r_and_grad(F, False)[0], ref)
    A, A1, B, B1 = p.jets(F)
    assert np.array_equal(A, population_basis(p.t, p.curve_a.degree, *F[:, :3].T, 0) @ p.curve_a.control_points)
    assert np.array_equal(B1, population_basis(p.t, p.curve_b.degree, *F[:, 3:].T, 1) @ p.curve_b.control_points)
    scale = np.abs(Gref).max(axis=1, keepdims=True)
    assert np.all(np.abs(G - Gref) <= 1e-12 * scale)


_STRIPS: dict = {}


def _moved_dual(p, T=np.zeros(3), L=1.0):
    """The same design after x -> L x + T: plane u0 + n·x = 0 becomes (L u0 - n·T) + n·x = 0."""
    U, E = p.raw_planes.copy(), p.boundary_planes.copy()
    U[:, 0] = L * U[:, 0] - U[:, 1:] @ T
    E[:, 0] = L * E[:, 0] - E[:, 1:] @ T
    return type(p)(U, E, objective="AL")


def test_stationary_end_test_is_scale_free_and_refuses_the_corner():
    """The nearly-stationary-end guard of the dual problem (turning rate of the unit normal at the
    ends against its mean) gives the same verdicts for the design in other units or far from the
    origin, and refuses the three-plane corner mu = gamma = -1 and its neighbourhood."""
    base = default_dual_problem("AL")
    three = type(base)(base.raw_planes[[0, 1, 3]], base.boundary_planes, objective="AL")
    eps = np.logspace(-5, 0, 200)
    X = np.column_stack([-1 + eps, np.zeros_like(eps), -1 + eps])
    X = np.concatenate([X, np.random.default_rng(1).uniform(-1, 1, (200, 3))])
    ok = three._end_speeds_ok(three.full(X))
    assert not ok[0] and not three._end_speeds_ok(three.full([[-1.0, 0.3, -1.0]]))[0]
    assert ok[np.argmax(eps > 0.1)]
    for T, L in ((np.array([50.0, -30.0, 0.0]), 1.0), (np.zeros(3), 1000.0), (np.array([5.0, 3.0, 7.0]), 0.01)):
        assert np.array_equal(_moved_dual(three, T, L)._end_speeds_ok(three.full(X)), ok)
