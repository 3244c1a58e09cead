"""Exact derivatives with respect to the shape parameters (spec section 8.1; issue 13).

The seed is affine in μ, in ν and in γ separately (f0 bilinear in (μ, w), f2 in (ν, w)), so a
central difference in one parameter is exact up to rounding whatever its step: the seed and basis
derivatives are checked that way to 1e-12. The objectives are not affine; their gradients are
checked against a 4th-order central difference (step 1e-3: truncation ~1e-12) to 1e-8 relative to
the gradient's size, over the whole box with hypothesis.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from ght_cad.curves.basis import basis, basis_parameter_derivatives
from ght_cad.optimize.problems import (
    CurveFairnessProblem,
    PopulationBasis,
    cone_strip_problem,
    default_dual_problem,
    default_interpolation_problem,
    default_strip_problem,
    wave_strip_problem,
)
from ght_cad.curves.curve import GHTCurve
from ght_cad.curves.seeds import ght_seed_jet, ght_seed_parameter_derivatives

param = st.floats(-1.0, 1.0, allow_nan=False)
T = np.linspace(0.0, 1.0, 11)


@settings(max_examples=40, deadline=None)
@given(mu=param, nu=param, gamma=param)
def test_seed_parameter_derivatives_are_exact(mu, nu, gamma):
    h = 0.25  # any step: f0, f2 are affine in each parameter
    for r, (d0mu, d0ga, d2nu, d2ga) in enumerate(ght_seed_parameter_derivatives(T, mu, nu, gamma, 5)):
        f = lambda m, n, g: ght_seed_jet(T, m, n, g, r)  # noqa: E731
        scale = max(1.0, (np.pi / 2) ** r * 4)
        for got, (plus, minus), k in (
            (d0mu, (f(mu + h, nu, gamma), f(mu - h, nu, gamma)), 0),
            (d2nu, (f(mu, nu + h, gamma), f(mu, nu - h, gamma)), 1),
            (d0ga, (f(mu, nu, gamma + h), f(mu, nu, gamma - h)), 0),
            (d2ga, (f(mu, nu, gamma + h), f(mu, nu, gamma - h)), 1),
        ):
            assert np.allclose(got, (plus[k] - minus[k]) / (2 * h), rtol=0, atol=1e-12 * scale)
        # f0 does not depend on nu, f2 not on mu
        assert np.array_equal(f(mu, nu, gamma)[0], f(mu, -nu, gamma)[0])
        assert np.array_equal(f(mu, nu, gamma)[1], f(-mu, nu, gamma)[1])


@settings(max_examples=30, deadline=None)
@given(mu=param, nu=param, gamma=param, degree=st.integers(2, 7), r=st.integers(0, 3))
def test_basis_parameter_derivatives_are_exact(mu, nu, gamma, degree, r):
    D = basis_parameter_derivatives(T, degree, mu, nu, gamma, r)
    assert D.shape == (3, T.size, degree + 1)
    h = 0.25
    for j, name in enumerate(("mu", "nu", "gamma")):
        kp = dict(mu=mu, nu=nu, gamma=gamma)
        km = dict(kp)
        kp[name] += h
        km[name] -= h
        # outside [-1, 1] basis() refuses the parameters: evaluate through the seed-level formula
        fd = (_basis_any(T, degree, **kp, r=r) - _basis_any(T, degree, **km, r=r)) / (2 * h)
        assert np.allclose(D[j], fd, rtol=0, atol=1e-11 * 10**r), name
    # partition of unity: the derivatives of sum_i b_i = 1 vanish
    assert np.allclose(D.sum(axis=-1), 0.0, atol=1e-11 * 10**r)


def _basis_any(t, degree, mu, nu, gamma, r):
    return PopulationBasis(t, degree)(np.array([mu]), np.array([nu]), np.array([gamma]), (r,))[r][0]


def test_basis_parameter_derivatives_match_population_basis_and_validate():
    pb = PopulationBasis(T, 5)
    got = pb.parameter_derivatives(np.array([0.3, -0.7]), np.array([0.1, 0.9]), np.array([-0.2, 0.5]), (0, 2))
    for i, (m, n, g) in enumerate([(0.3, 0.1, -0.2), (-0.7, 0.9, 0.5)]):
        for r in (0, 2):
            assert np.allclose(got[r][:, i], basis_parameter_derivatives(T, 5, m, n, g, r), atol=1e-14)
    assert basis_parameter_derivatives(0.5, 3, 0.2, 0.1, 0.0).shape == (3, 4)
    from ght_cad.core.errors import GHTError

    with pytest.raises(GHTError, match="mu"):
        basis_parameter_derivatives(T, 3, 1.5, 0.0, 0.0)
    # values of the basis itself are untouched
    assert np.array_equal(basis(T, 4, 0.2, 0.3, 0.4), basis(T, 4, 0.2, 0.3, 0.4))


def _fd4(p, X, h=1e-3):
    G = np.zeros_like(X)
    for j in range(X.shape[1]):
        E = np.zeros_like(X)
        E[:, j] = h
        G[:, j] = (-p(X + 2 * E) + 8 * p(X + E) - 8 * p(X - E) + p(X - 2 * E)) / (12 * h)
    return G


_SPIRAL = GHTCurve([[0, 0, 0], [1, 0.5, 0.2], [1.5, 1.5, 0.4], [0.5, 2.2, 0.9], [-0.5, 1.8, 1.2]])
PROBLEMS = {
    "strip R": lambda: default_strip_problem(),
    "wave strip R": lambda: wave_strip_problem(),
    "cone strip R": lambda: cone_strip_problem(),
    "strip R, 3 free": lambda: default_strip_problem(free=("a.nu", "b.mu", "b.gamma")),
    "dual AL": lambda: default_dual_problem("AL", check_surface=False),
    "dual En": lambda: default_dual_problem("En", check_surface=False),
    "dual CVEn": lambda: default_dual_problem("CVEn", check_surface=False),
    "dual weighted": lambda: default_dual_problem({"AL": 1.0, "En": 0.1, "CVEn": 0.01}, check_surface=False),
    "interpolation AL": lambda: default_interpolation_problem("AL"),
    "interpolation En": lambda: default_interpolation_problem("En"),
    "interpolation CVEn": lambda: default_interpolation_problem("CVEn"),
    "interpolation weighted": lambda: default_interpolation_problem({"AL": 2.0, "En": 0.5, "CVEn": 0.05}),
    "curve weighted": lambda: CurveFairnessProblem(_SPIRAL, {"AL": 1.0, "En": 0.3, "CVEn": 0.02}),
}
_BUILT = {}


@pytest.mark.parametrize("name", sorted(PROBLEMS))
@settings(max_examples=12, deadline=None)
@given(data=st.data())
def test_objective_gradients_match_high_order_differences(name, data):
    p = _BUILT.setdefault(name, PROBLEMS[name]())
    X = np.array([[data.draw(st.floats(-0.995, 0.995)) for _ in range(p.dim)] for _ in range(3)])
    f, G = p.value_and_grad(X)
    assert np.array_equal(f, p(X))  # the values are the objective's, bit for bit
    assert G.shape == X.shape
    Gfd = _fd4(p, X)
    scale = np.maximum(np.abs(Gfd).max(axis=1), 1e-3 * np.abs(f))[:, None]
    assert np.all(np.abs(G - Gfd) <= 1e-8 * scale), (X, G, Gfd)


def test_gradient_on_the_box_boundary_and_at_an_admissibility_failure():
    p = default_strip_problem()
    X = np.array([[1.0, -1.0, 1.0, -1.0, 1.0, -1.0], [-1.0] * 6])
    G = p.gradient(X)
    h = 1e-6  # one-sided into the box is not needed: the formulas extend beyond [-1, 1]
    Gfd = np.stack([(p(X + h * e) - p(X - h * e)) / (2 * h) for e in np.eye(6)], axis=1)
    assert np.allclose(G, Gfd, rtol=1e-6, atol=1e-10)
    # the dual problem with its surface check: +inf rows get gradient 0
    d = default_dual_problem("En")
    f, G = d.value_and_grad(np.array([[0.2, 0.1, 0.3]]))
    assert np.isfinite(f[0]) and np.all(np.isfinite(G))
