"""Tensor-product GHT-Bézier patches (spec 3.1): evaluation, boundaries, B-splines, joins."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

from ght_cad import basis
from ght_cad.core.errors import GHTError, ShapeParameterError, SingularJoinError
from ght_cad.surfaces.patch import GHTSurface, join_patches, measure_patch_continuity, patches_to_bspline

shape = st.floats(-1.0, 1.0, allow_nan=False)
params6 = st.tuples(shape, shape, shape, shape, shape, shape)


def _patch(m, n, params, seed, dim=3):
    rng = np.random.default_rng(seed)
    return GHTSurface(rng.normal(size=(m + 1, n + 1, dim)), *params)


@settings(max_examples=25)
@given(m=st.integers(2, 7), n=st.integers(2, 7), params=params6, seed=st.integers(0, 2**31 - 1))
def test_evaluate_is_the_double_sum_and_corners_interpolate(m, n, params, seed):
    s = _patch(m, n, params, seed)
    P = s.control_points
    rng = np.random.default_rng(seed)
    u, v = rng.uniform(0, 1, 50), rng.uniform(0, 1, 50)
    bu = basis(u, m, *params[:3])
    bv = basis(v, n, *params[3:])
    direct = np.array([sum(bu[k, i] * bv[k, j] * P[i, j] for i in range(m + 1) for j in range(n + 1)) for k in range(50)])
    assert np.abs(s.evaluate(u, v) - direct).max() <= 1e-12 * (1 + np.abs(P).max())
    for (a, b), q in {(0, 0): P[0, 0], (1, 0): P[-1, 0], (0, 1): P[0, -1], (1, 1): P[-1, -1]}.items():
        assert np.allclose(s.evaluate(a, b), q, atol=1e-13)
    grid = s.evaluate_grid(u[:5], v[:7])
    assert grid.shape == (5, 7, 3)
    assert np.allclose(grid[2, 3], s.evaluate(u[2], v[3]), atol=1e-13)


@settings(max_examples=20)
@given(m=st.integers(2, 6), n=st.integers(2, 6), params=params6, seed=st.integers(0, 2**31 - 1))
def test_boundaries_iso_curves_and_partials(m, n, params, seed):
    s = _patch(m, n, params, seed)
    t = np.linspace(0, 1, 33)
    z, o = np.zeros_like(t), np.ones_like(t)
    b = s.boundaries()
    assert np.allclose(b["u0"].evaluate(t), s.evaluate(z, t), atol=1e-12)
    assert np.allclose(b["u1"].evaluate(t), s.evaluate(o, t), atol=1e-12)
    assert np.allclose(b["v0"].evaluate(t), s.evaluate(t, z), atol=1e-12)
    assert np.allclose(b["v1"].evaluate(t), s.evaluate(t, o), atol=1e-12)
    # partial derivatives agree with the derivatives of the exact iso-curves (independent path)
    v0 = 0.37
    iso_u = s.iso_curve("u", v0)
    for r in range(4):
        assert np.allclose(s.derivative(t, v0, du=r), iso_u.derivative(t, r), rtol=1e-10, atol=1e-10)
    iso_v = s.iso_curve("v", 0.61)
    assert np.allclose(s.derivative(0.61, t, dv=2), iso_v.derivative(t, 2), rtol=1e-10, atol=1e-10)
    # unit normals orthogonal to both tangents
    nrm = s.normal(t, 1 - t)
    ok = np.isfinite(nrm).all(axis=1)
    assert np.allclose(np.linalg.norm(nrm[ok], axis=1), 1.0)
    assert np.abs(np.sum(nrm[ok] * s.derivative(t, 1 - t, du=1)[ok], axis=1)).max() <= 1e-9 * (1 + np.abs(s.control_points).max() * m)


def test_gamma_one_is_classical_bezier_patch():
    rng = np.random.default_rng(3)
    P = rng.normal(size=(4, 3, 3))
    s = GHTSurface(P, 0.5, -0.3, 1.0, -0.7, 0.2, 1.0)
    u, v = rng.uniform(0, 1, 30), rng.uniform(0, 1, 30)
    from math import comb

    Bu = np.array([[comb(3, i) * x**i * (1 - x) ** (3 - i) for i in range(4)] for x in u])
    Bv = np.array([[comb(2, j) * x**j * (1 - x) ** (2 - j) for j in range(3)] for x in v])
    assert np.allclose(s.evaluate(u, v), np.einsum("ki,kj,ijd->kd", Bu, Bv, P), atol=1e-13)


def test_exact_cylinder_patch():
    """γ = -1, μ = ν = 0 in u: the quarter-circle rows sweep an exact quarter cylinder."""
    ring = np.array([(1, 0), (1, 1), (0, 1)], float)
    P = np.zeros((3, 3, 3))
    for j, z in enumerate([0.0, 1.0, 2.0]):
        P[:, j, :2] = 2.0 * ring
        P[:, j, 2] = z
    s = GHTSurface(P, 0, 0, -1, 0, 0, 0.3)
    u, v = np.random.default_rng(0).uniform(0, 1, (2, 200))
    pts = s.evaluate(u, v)
    assert np.allclose(np.hypot(pts[:, 0], pts[:, 1]), 2.0, atol=1e-14)
    face_data = s.to_bspline()
    q = face_data.evaluate(u, v)
    assert np.abs(np.hypot(q[:, 0], q[:, 1]) - 2.0).max() <= face_data.info["tol"]


@pytest.mark.slow
@settings(max_examples=12)
@given(m=st.integers(2, 10), n=st.integers(2, 10), params=params6, seed=st.integers(0, 2**31 - 1))
def test_to_bspline_certified_deviation(m, n, params, seed):
    """Sampled deviation on fresh points <= bound <= tol (default tol = 1e-7 × box diagonal)."""
    s = _patch(m, n, params, seed)
    data = s.to_bspline()
    lo, hi = s.bounding_box()
    tol = 1e-7 * float(np.linalg.norm(hi - lo))
    assert data.info["tol"] == pytest.approx(tol)
    assert data.max_deviation <= tol
    rng = np.random.default_rng(seed + 1)
    u, v = rng.uniform(0, 1, (2, 5000))
    dev = np.linalg.norm(data.evaluate(u, v) - s.evaluate(u, v), axis=1).max()
    assert dev <= data.max_deviation
    # boundary rows of the net are interpolated: corners exact
    assert np.allclose(data.evaluate([0, 1, 0, 1], [0, 0, 1, 1]), s.evaluate([0, 1, 0, 1], [0, 0, 1, 1]), atol=1e-12 * (1 + np.abs(s.control_points).max()))


def _surface_u_derivative(data, u, v):
    """∂S~/∂u (u scalar, v array) of a BSplineSurfaceData."""
    K, L, d = data.poles.shape
    du = BSpline(data.knots_u, data.poles.reshape(K, L * d), data.degree_u).derivative()(u).reshape(L, d)
    return BSpline(data.knots_v, du, data.degree_v)(v)


@pytest.mark.parametrize("continuity, kw", [("C1", {}), ("G1", {"k": 1.7}), ("C2", {}), ("G2", {"k": 0.6, "beta2": 0.4})])
def test_join_patches_holds_on_surfaces_and_in_bsplines(continuity, kw):
    rng = np.random.default_rng(11)
    a = GHTSurface(rng.normal(size=(5, 4, 3)), 0.3, -0.2, 0.1, 0.5, 0.4, -0.6)
    b = GHTSurface(rng.normal(size=(4, 4, 3)) + [4, 0, 0], -0.5, 0.8, 0.0, 0.5, 0.4, -0.6)
    j = join_patches(a, continuity, b, **kw)
    order = int(continuity[1])
    c_ord, g_ord = measure_patch_continuity(a, j, tol=1e-9)
    assert (g_ord if continuity[0] == "G" else c_ord) >= order
    assert c_ord < 3 and g_ord < 3  # not more than asked (random free points)
    if continuity[0] == "G":
        assert c_ord < order
    # the exact surfaces: ∂u S_B(0, v) = k ∂u S_A(1, v)
    v = np.linspace(0, 1, 41)
    k = kw.get("k", 1.0)
    assert np.allclose(j.derivative(0.0, v, du=1), k * a.derivative(1.0, v, du=1), atol=1e-10)
    # and the B-spline faces converted together: same boundary, same cross derivative ratio
    da, db = patches_to_bspline([a, j])
    assert np.array_equal(da.knots_v, db.knots_v)
    scale = np.abs(a.derivative(1.0, v, du=1)).max()
    assert np.abs(db.evaluate(np.zeros_like(v), v) - da.evaluate(np.ones_like(v), v)).max() <= 1e-12 * 10
    assert np.abs(_surface_u_derivative(db, 0.0, v) - k * _surface_u_derivative(da, 1.0, v)).max() <= 1e-9 * scale


def test_join_patches_across_v():
    rng = np.random.default_rng(5)
    a = GHTSurface(rng.normal(size=(4, 5, 3)), 0.1, 0.2, 0.3, -0.4, 0.5, 0.6)
    b = GHTSurface(rng.normal(size=(4, 3, 3)), 0.1, 0.2, 0.3, 0.0, 0.0, 0.0)
    j = join_patches(a, "G1", b, direction="v", k=2.0)
    c_ord, g_ord = measure_patch_continuity(a, j, direction="v")
    assert g_ord >= 1 and c_ord == 0
    u = np.linspace(0, 1, 21)
    assert np.allclose(j.derivative(u, 0.0, dv=1), 2.0 * a.derivative(u, 1.0, dv=1), atol=1e-10)


def test_affine_invariance_and_round_trip():
    rng = np.random.default_rng(9)
    s = GHTSurface(rng.normal(size=(4, 5, 3)), 0.1, -0.2, 0.3, 0.4, -0.5, 0.6)
    A = rng.normal(size=(3, 3))
    b = rng.normal(size=3)
    u, v = rng.uniform(0, 1, (2, 100))
    assert np.allclose(s.transformed(A, b).evaluate(u, v), s.evaluate(u, v) @ A.T + b, atol=1e-12)
    assert np.allclose(s.translated(b).evaluate(u, v), s.evaluate(u, v) + b, atol=1e-13)
    back = GHTSurface.from_dict(s.to_dict())
    assert back.shape_parameters == s.shape_parameters
    assert np.array_equal(back.control_points, s.control_points)
    with pytest.raises(GHTError, match="matrix"):
        s.transformed(np.eye(2))


def test_patch_errors():
    with pytest.raises(GHTError, match="shape"):
        GHTSurface(np.zeros((2, 3, 3)))
    with pytest.raises(GHTError, match="NaN"):
        GHTSurface(np.full((3, 3, 3), np.nan))
    with pytest.raises(ValueError, match="mu"):
        GHTSurface(np.zeros((3, 3, 3)), mu_u=1.5)
    s = GHTSurface(np.random.default_rng(0).normal(size=(3, 3, 3)))
    with pytest.raises(GHTError, match="side"):
        s.boundary("w0")
    with pytest.raises(GHTError, match="tol"):
        s.to_bspline(tol=-1.0)
    with pytest.raises(GHTError, match="direction"):
        join_patches(s, "C1", s, direction="w")
    other = GHTSurface(np.random.default_rng(1).normal(size=(3, 4, 3)))
    with pytest.raises(GHTError, match="same basis"):
        join_patches(s, "C1", other)
    with pytest.raises(SingularJoinError):
        join_patches(s, "G1", s, k=-1.0)


@pytest.mark.parametrize("name, value", [("mu_u", 1.5), ("nu_u", -2.0), ("gamma_v", 1.5), ("mu_v", float("nan"))])
def test_patch_shape_parameter_errors_name_the_argument(name, value):
    # the message said "gamma=1.5" for gamma_v=1.5: which of the two directions was wrong was lost
    with pytest.raises(ShapeParameterError, match=rf"^{name}={value:g} "):
        GHTSurface(np.zeros((3, 3, 3)), **{name: value})
