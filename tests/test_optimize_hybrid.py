"""The default optimizer ``hybrid``: Sobol' starts + L-BFGS-B finishes (spec 8.1; issue 13)."""

from __future__ import annotations

import numpy as np
import pytest

from ght_cad.core.errors import GHTError
from ght_cad.optimize import METHODS, differential_evolution, hybrid, minimize
from ght_cad.optimize.problems import (
    cone_strip_problem,
    default_dual_problem,
    default_interpolation_problem,
    default_strip_problem,
    wave_strip_problem,
)


def sphere(X):
    return np.sum(X**2, axis=1)


def rosenbrock(X):
    return np.sum(100.0 * (X[:, 1:] - X[:, :-1] ** 2) ** 2 + (1.0 - X[:, :-1]) ** 2, axis=1)


def box(d, b):
    return -b * np.ones(d), b * np.ones(d)


def test_default_method_is_hybrid():
    r = minimize(sphere, box(3, 2.0), seed=0)
    assert r.method == "hybrid" and r.fun < 1e-12
    assert "hybrid" in METHODS


@pytest.mark.parametrize("fun,dim,half,tol", [
    (sphere, 2, 5.12, 1e-12), (sphere, 6, 5.12, 1e-12),
    (lambda X: np.sum((X - 1.234) ** 2, axis=1), 5, 5.12, 1e-12),
    (rosenbrock, 2, 2.048, 1e-9), (rosenbrock, 5, 2.048, 1e-7),
])
def test_known_minima_with_finite_differences(fun, dim, half, tol):
    calls = []

    def f(X):
        calls.append(len(X))
        assert np.all(X >= -half) and np.all(X <= half)
        return fun(X)

    for seed in (0, 1):
        calls.clear()
        r = hybrid(f, box(dim, half), seed=seed)
        assert r.fun <= tol, (seed, r.fun)
        assert r.nfev == sum(calls) and r.njev == 0  # every finite-difference point is counted
        assert r.fun == float(fun(r.x[None])[0])


def test_exact_gradients_are_used_and_counted():
    p = default_dual_problem("En", check_surface=False)
    calls = {"vg": 0, "f": 0}
    orig_vg = p.value_and_grad

    class Counting:
        has_gradient = True
        names = p.names

        def __call__(self, X):
            calls["f"] += len(X)
            return p(X)

        def value_and_grad(self, X):
            calls["vg"] += len(X)
            return orig_vg(X)

    r = hybrid(Counting(), p.bounds, seed=0)
    assert r.njev == calls["vg"] > 0 and r.nfev == calls["f"] + calls["vg"]
    fd = hybrid(p, p.bounds, seed=0, jac="fd")
    assert fd.njev == 0 and fd.fun == pytest.approx(r.fun, rel=1e-9)
    # the history of gradient evaluations and the cost of a run
    assert r.history_njev is not None and r.history_njev[-1] == r.njev
    assert r.cost(2.0)[-1] == r.nfev + 2.0 * r.njev
    assert r.nfev_to_reach(r.fun, 2.0) <= r.nfev + 2.0 * r.njev


def test_user_jacobian():
    r = hybrid(sphere, box(4, 3.0), seed=0, jac=lambda X: 2 * X)
    assert r.fun < 1e-14 and r.njev > 0


@pytest.mark.parametrize("make,bound_params", [
    (default_interpolation_problem, {"mu": 1.0, "nu": -1.0, "gamma": -1.0}),
    (wave_strip_problem, {"a.mu": -1.0, "a.nu": 1.0, "a.gamma": -1.0, "b.nu": 1.0}),
    (cone_strip_problem, {"a.nu": -1.0, "a.gamma": -1.0, "b.nu": 1.0}),
])
@pytest.mark.slow
def test_optimum_on_the_box_boundary_is_reached_exactly(make, bound_params):
    p = make()
    de = differential_evolution(p, p.bounds, pop_size=30, max_iter=150, seed=0)
    for seed in range(3):
        for jac in (None, "fd"):
            r = hybrid(p, p.bounds, seed=seed, jac=jac)
            got = dict(zip(p.names, r.x))
            for k, v in bound_params.items():
                assert got[k] == v, (seed, jac, k, got[k])  # exactly on the bound
            assert r.fun <= de.fun * (1 + 1e-9)


def test_bounds_are_hard_for_a_general_box():
    lb, ub = np.array([0.1, -3.0, 2.0]), np.array([0.7, -1.3, 9.0])

    def f(X):
        assert np.all(X >= lb) and np.all(X <= ub)
        return np.sum((X - np.array([5.0, 0.0, 4.0])) ** 2, axis=1)  # optimum outside in x, y

    r = hybrid(f, (lb, ub), seed=3)
    assert r.x[0] == 0.7 and r.x[1] == -1.3 and r.x[2] == pytest.approx(4.0, abs=1e-7)


def test_reproducible_and_phases():
    p = default_strip_problem()
    a = hybrid(p, p.bounds, seed=4)
    b = hybrid(p, p.bounds, seed=np.random.default_rng(4))
    c = hybrid(p, p.bounds, seed=5)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.history, b.history) and a.nfev == b.nfev
    assert not np.array_equal(a.history, c.history)
    assert [name for name, _ in a.phases] == ["Sobol starts", "L-BFGS-B"]
    assert a.phases[1][1] == 1 and a.history_nfev[0] == 32
    assert np.all(np.diff(a.history) <= 0) and a.history[-1] == a.fun
    assert len(a.history) == len(a.history_nfev) == len(a.history_njev)
    assert a.fun < 2e-7 and a.x.shape == (6,)


@pytest.mark.parametrize("starts", ["pso", "igwo"])
def test_thesis_optimizer_as_global_phase(starts):
    p = default_dual_problem("CVEn", check_surface=False)
    r = hybrid(p, p.bounds, seed=0, starts=starts, pop_size=12, global_iter=5)
    per = 2 if starts == "igwo" else 1
    assert r.phases[0][0].startswith(starts.upper().replace("IGWO", "I-GWO"))
    assert r.phases[1][1] == 6  # initial population + 5 iterations recorded
    assert r.history_nfev[5] == 12 + 5 * per * 12
    ref = hybrid(p, p.bounds, seed=1)
    assert r.fun == pytest.approx(ref.fun, rel=1e-8)


def test_target_budget_callback_and_x0():
    p = default_strip_problem()
    r = hybrid(p, p.bounds, seed=0, target=1e-5)
    assert r.fun <= 1e-5 and "target" in r.message
    r = hybrid(p, p.bounds, seed=0, max_nfev=60)
    assert r.nfev <= 60 and "max_nfev" in r.message
    r = hybrid(p, p.bounds, seed=0, max_nfev=60, jac="fd")
    assert r.nfev <= 60 and "max_nfev" in r.message
    seen = []
    r = hybrid(p, p.bounds, seed=0, callback=lambda s: seen.append(s.nit) or s.nit >= 4)
    assert r.message == "stopped by callback" and seen == [0, 1, 2, 3, 4] and r.nit == 4
    r = hybrid(p, p.bounds, seed=0, max_iter=3)
    assert r.nit == 3 and "max_iter" in r.message
    x0 = p.x0
    r = hybrid(p, p.bounds, seed=0, x0=x0, pop_size=4, max_nfev=5)
    assert r.fun <= p.value(x0) and r.nfev == 5


def test_nan_for_some_points_counts_as_inf():
    f = lambda X: np.where(X[:, 0] > 0.5, np.nan, np.sum((X - 0.7) ** 2, axis=1))  # noqa: E731
    for jac in (None, "fd"):
        r = hybrid(f, box(2, 1.0), seed=0, jac=jac)
        assert np.isfinite(r.fun) and r.x[0] <= 0.5 and r.x[0] == pytest.approx(0.5, abs=1e-4)


@pytest.mark.parametrize("kw,needle", [
    (dict(max_iter=float("nan")), "max_iter=nan"),
    (dict(max_iter=float("inf")), "max_iter=inf"),
    (dict(max_nfev=float("inf")), "max_nfev=inf"),
    (dict(max_nfev=3), "max_nfev=3"),
    (dict(pop_size=2), "pop_size=2"),
    (dict(seed=1.5), "seed=1.5"),
    (dict(tol="x"), "tol='x'"),
    (dict(target=float("nan")), "target=nan"),
    (dict(starts="de"), "starts='de'"),
    (dict(local_starts=0), "local_starts=0"),
    (dict(jac="exact"), "jac='exact'"),
    (dict(jac=3), "jac=3"),
    (dict(x0=[3.0, 0.0]), "x0="),
])
def test_bad_options_are_named(kw, needle):
    with pytest.raises(GHTError, match=needle.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")):
        hybrid(sphere, box(2, 1.0), **kw)
    with pytest.raises(GHTError, match="method='lbfgs'"):
        minimize(sphere, box(2, 1.0), method="lbfgs")


def test_wrong_objective_output_is_named():
    with pytest.raises(GHTError, match="shape"):
        hybrid(lambda X: np.zeros((len(X), 2)), box(2, 1.0))
    with pytest.raises(GHTError, match="real numbers"):
        hybrid(lambda X: np.array(["a"] * len(X)), box(2, 1.0))

    class BadGrad:
        def __call__(self, X):
            return sphere(X)

        def value_and_grad(self, X):
            return sphere(X), np.zeros((len(X), 5))

    with pytest.raises(GHTError, match="gradient has shape"):
        hybrid(BadGrad(), box(2, 1.0))
