"""The core NURBS evaluator (:mod:`ght_cad.surfaces.nurbs`) against an independent reference.

Reference: scipy's ``BSpline`` (its own de Boor evaluation) gives every basis function and its
derivatives (``BSpline(U, I, p)(x, nu=k)``); the homogeneous surface / curve and its partials are
contracted with the poles and the rational quotient rule applied. Values, first and second
derivatives must agree to 1e-12 relative (to the largest reference value of each quantity), for
random clamped knot vectors (repeated interior knots included), degrees 1..5, rational weights;
also the grid area density and the Chebyshev-patch path (orders 0, 1) vs the difference-net path
(order 2).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import BSpline

from ght_cad.core.errors import GHTError
from ght_cad.surfaces.nurbs import NurbsCurve, NurbsSurface, expand_knots

RTOL = 1e-12


def _knots(rng: np.random.Generator, p: int, spans: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distinct knots (spacing >= 0.05 of the range), multiplicities (ends p+1, interior 1..p) and
    the flat vector."""
    gaps = rng.uniform(0.05, 1.0, spans)
    k = np.r_[0.0, np.cumsum(gaps)] * rng.uniform(0.5, 20.0) + rng.uniform(-5, 5)
    m = np.r_[p + 1, rng.integers(1, p + 1, spans - 1), p + 1]
    return k, m, expand_knots(k, m)


def _basis_ref(U: np.ndarray, p: int, x: np.ndarray, k: int) -> np.ndarray:
    """All basis functions' k-th derivatives at x by scipy, (len(x), n)."""
    n = U.size - p - 1
    return BSpline(U, np.eye(n), p, extrapolate=False)(x, nu=k) if k <= p else np.zeros((x.size, n))


def _params(U: np.ndarray, p: int, rng: np.random.Generator, n: int) -> np.ndarray:
    """Interior samples, both ends and the distinct interior knots of the knot range."""
    a, b = U[p], U[-p - 1]
    inner = np.unique(U[(U > a) & (U < b)])
    return np.r_[a, b, inner, rng.uniform(a, b, n)]


def _random_surface(rng: np.random.Generator, pu: int, pv: int, su: int, sv: int, rational: bool
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None, NurbsSurface]:
    """Random knots (su, sv spans), poles in [-50, 50]^3 and weights in [0.5, 2] (rational):
    ``(U, V, P, w, surface)``."""
    _, _, U = _knots(rng, pu, su)
    _, _, V = _knots(rng, pv, sv)
    nu, nv = U.size - pu - 1, V.size - pv - 1
    P = rng.uniform(-50, 50, (nu, nv, 3))
    w = rng.uniform(0.5, 2.0, (nu, nv)) if rational else None
    return U, V, P, w, NurbsSurface.from_poles(U, V, pu, pv, P, w)


def _check(ours: np.ndarray, ref: np.ndarray, what: str) -> None:
    scale = max(1.0, float(np.abs(ref).max()))
    err = float(np.abs(ours - ref).max())
    assert err <= RTOL * scale, f"{what}: {err:.3e} vs scale {scale:.3e}"


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), p=st.integers(1, 5), spans=st.integers(1, 5), dim=st.sampled_from([2, 3]),
       rational=st.booleans())
def test_curve_matches_scipy(seed: int, p: int, spans: int, dim: int, rational: bool) -> None:
    rng = np.random.default_rng(seed)
    _, _, U = _knots(rng, p, spans)
    n = U.size - p - 1
    P = rng.uniform(-50, 50, (n, dim))
    w = rng.uniform(0.5, 2.0, n) if rational else None
    c = NurbsCurve.from_poles(U, p, P, w)
    x = _params(U, p, rng, 40)
    ww = np.ones(n) if w is None else w
    H = [_basis_ref(U, p, x, k) @ np.c_[P * ww[:, None], ww] for k in range(3)]
    W = H[0][:, -1:]
    S = H[0][:, :-1] / W
    S1 = (H[1][:, :-1] - H[1][:, -1:] * S) / W
    S2 = (H[2][:, :-1] - 2 * H[1][:, -1:] * S1 - H[2][:, -1:] * S) / W
    _check(c.value(x), S, "value")
    _check(c.derivative(x), S1, "first derivative")
    got = c.derivatives(x, 2)
    for a, b, what in zip(got, (S, S1, S2), ("P", "P'", "P''")):
        _check(a, b, what)
    assert c.bounds == (U[p], U[-p - 1])


def _surface_ref(U, V, pu, pv, P, w, u, v):
    """[S, S_u, S_v, S_uu, S_vv, S_uv] by scipy basis functions and the quotient rule."""
    C = np.concatenate([P * w[..., None], w[..., None]], axis=2)  # (nu, nv, 4)
    Nu = [_basis_ref(U, pu, u, k) for k in range(3)]
    Nv = [_basis_ref(V, pv, v, k) for k in range(3)]
    H = {(a, b): np.einsum("ni,nj,ijk->nk", Nu[a], Nv[b], C) for a in range(3) for b in range(3 - a)}
    W = H[(0, 0)][:, 3:]
    S = H[(0, 0)][:, :3] / W
    Su = (H[(1, 0)][:, :3] - H[(1, 0)][:, 3:] * S) / W
    Sv = (H[(0, 1)][:, :3] - H[(0, 1)][:, 3:] * S) / W
    Suu = (H[(2, 0)][:, :3] - 2 * H[(1, 0)][:, 3:] * Su - H[(2, 0)][:, 3:] * S) / W
    Svv = (H[(0, 2)][:, :3] - 2 * H[(0, 1)][:, 3:] * Sv - H[(0, 2)][:, 3:] * S) / W
    Suv = (H[(1, 1)][:, :3] - H[(1, 0)][:, 3:] * Sv - H[(0, 1)][:, 3:] * Su - H[(1, 1)][:, 3:] * S) / W
    return [S, Su, Sv, Suu, Svv, Suv]


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pu=st.integers(1, 5), pv=st.integers(1, 4), su=st.integers(1, 4),
       sv=st.integers(1, 3), rational=st.booleans())
def test_surface_matches_scipy(seed: int, pu: int, pv: int, su: int, sv: int, rational: bool) -> None:
    rng = np.random.default_rng(seed)
    U, V, P, w, s = _random_surface(rng, pu, pv, su, sv, rational)
    nu, nv = P.shape[:2]
    u, v = _params(U, pu, rng, 30), _params(V, pv, rng, 30)
    m = min(u.size, v.size)
    u, v = u[:m], v[:m]
    ref = _surface_ref(U, V, pu, pv, P, np.ones((nu, nv)) if w is None else w, u, v)
    names = ("S", "S_u", "S_v", "S_uu", "S_vv", "S_uv")
    for order in (0, 1, 2):  # orders 0, 1: Chebyshev patches; 2: difference nets
        got = s.eval(u, v, order)
        assert len(got) == (1, 3, 6)[order]
        for a, b, what in zip(got, ref, names):
            _check(a, b, f"order {order} {what}")
    # the area density on a grid against |S_u x S_v| of the reference
    gu, gv = np.sort(u[:9]), np.sort(v[:7])
    G = _surface_ref(U, V, pu, pv, P, np.ones((nu, nv)) if w is None else w, np.repeat(gu, gv.size), np.tile(gv, gu.size))
    dens = np.linalg.norm(np.cross(G[1], G[2]), axis=1).reshape(gu.size, gv.size)
    _check(s.density_grid(gu, gv), dens, "density_grid")
    np.testing.assert_array_equal(s.poles(), P if w is None else (P * w[..., None]) / w[..., None])
    assert s.bounds == (U[pu], U[-pu - 1], V[pv], V[-pv - 1])


def test_bezier_patch_is_one_polynomial_patch() -> None:
    """A polynomial Bézier patch (one span each way, equal weights) takes the single-patch product
    path and still matches the reference, values and first partials."""
    rng = np.random.default_rng(3)
    U, V = np.r_[np.zeros(4), np.ones(4)], np.r_[np.zeros(2), np.ones(2)]
    P = rng.uniform(-1, 1, (4, 2, 3))
    s = NurbsSurface.from_poles(U, V, 3, 1, P)
    assert s.poly_patch is not None
    u, v = rng.uniform(0, 1, 50), rng.uniform(0, 1, 50)
    ref = _surface_ref(U, V, 3, 1, P, np.ones((4, 2)), u, v)
    for a, b in zip(s.eval(u, v, 1), ref):
        _check(a, b, "bezier")


def test_expand_knots() -> None:
    np.testing.assert_array_equal(expand_knots([0.0, 0.5, 1.0], [3, 1, 3]), [0, 0, 0, 0.5, 1, 1, 1])


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: expand_knots([0.0, 1.0], [2]), "multiplicities"),
        (lambda: expand_knots([1.0, 0.0], [2, 2]), "strictly increasing"),
        (lambda: NurbsCurve.from_poles([0, 0, 1, 1], 1, np.zeros((3, 2))), "knot vector"),
        (lambda: NurbsCurve.from_poles([0, 0, 1, 1], 1, np.zeros((2, 2)), [1.0, 0.0]), "weights"),
        (lambda: NurbsSurface.from_poles([0, 0, 1, 1], [0, 0, 1, 1], 1, 1, np.zeros((2, 2))), "poles of shape"),
        (lambda: NurbsSurface.from_poles([0, 0, 0, 0], [0, 0, 1, 1], 1, 1, np.zeros((2, 2, 3))), "knot vector"),
        (lambda: NurbsSurface.from_poles([0, 0, 1, 1], [0, 0, 1, 1], 1, 1, np.zeros((2, 2, 3)), -np.ones((2, 2))), "weights"),
    ],
)
def test_bad_data_is_refused(call, match: str) -> None:
    with pytest.raises(GHTError, match=match):
        call()


class _NurbsAdapter:
    """A bare :class:`NurbsSurface` as a face surface (``d1``, ``density_grid``, fast grid)."""

    fast_density_grid = True

    def __init__(self, s: NurbsSurface) -> None:
        self.s = s

    def d1(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        return self.s.eval(u, v, 1)[1:3]

    def density_grid(self, s: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.s.density_grid(s, v)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), pu=st.integers(1, 5), pv=st.integers(1, 3), su=st.integers(1, 6),
       sv=st.integers(1, 3), rational=st.booleans(), cap=st.booleans())
def test_face_area_inner_integrals_by_pieces(seed: int, pu: int, pv: int, su: int, sv: int, rational: bool,
                                              cap: bool) -> None:
    """The face area's inner integrals ``P(u_i, v_i) = ∫_{u_lo}^{u_i} |S_u × S_v| ds`` with the whole
    knot pieces on one tensor grid (ght_cad.face_unroll._inner_integrals_by_pieces, the path of
    B-spline faces) equal the point-by-point quadrature on the same panels to 1e-13 of the
    largest |P| (rounding: the same nodes, summed in another order), for points above and below
    u_lo, on knots and between them, with and without the u_span/8 panel cap."""
    from ght_cad.unrolling.face_unroll import _inner_integrals, _inner_integrals_by_pieces

    rng = np.random.default_rng(seed)
    U, V, _, _, surface = _random_surface(rng, pu, pv, su, sv, rational)
    ad = _NurbsAdapter(surface)
    a, b = U[pu], U[-pu - 1]
    breaks = np.unique(U[(U > a) & (U < b)])
    u_lo = a if rng.random() < 0.7 else float(rng.uniform(a, b))  # the face's u0, or inside (points below it)
    uu = np.r_[_params(U, pu, rng, 40), u_lo]
    vv = rng.uniform(V[pv], V[-pv - 1], uu.size)
    span = (b - a) if cap else None
    ref = _inner_integrals(ad, uu, vv, u_lo, breaks, span)
    got = _inner_integrals_by_pieces(ad, uu, vv, u_lo, breaks, span)
    scale = max(1e-300, float(np.abs(ref).max()))
    assert float(np.abs(got - ref).max()) <= 1e-13 * scale
    assert np.all(np.sign(got[np.abs(ref) > 1e-12 * scale]) == np.sign(ref[np.abs(ref) > 1e-12 * scale]))
