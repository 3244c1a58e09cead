r"""Developable surfaces from GHT curves (spec section 5): planes (duality), spines, geodesics.

* :class:`EnvelopeDevelopable` (5.2): the envelope of the one-parameter family of planes
  ``U(t) = Σ b_{i,m}(t) U_i`` (the *dual curve*, a 4-D :class:`~ght_cad.curve.GHTCurve`).
  Ruling ``U ∩ U'``, edge of regression ``U ∩ U' ∩ U''``, boundary curves
  ``a(t) = U ∩ U' ∩ E_a`` and ``b(t) = U ∩ U' ∩ E_b`` (pairing kept), surface
  ``X(t, v) = (1-v) a(t) + v b(t)``. Derivatives of ``a, b`` are analytic: the meet
  (:func:`ght_cad.planes.meet`) is trilinear, so with ``X = meet(U, U', E)``
  ``X' = meet(U, U'', E)``, ``X'' = meet(U', U'', E) + meet(U, U''', E)`` and the Cartesian point
  ``x = (X1, X2, X3)/X0`` follows by the quotient rule.
* :class:`TangentDevelopable` (5.3): ``X(t, v) = C(t) + v T(t)``, trimmed to ``v ∈ [v0, v1]`` not
  containing 0 (C is the edge of regression).
* :class:`RectifyingDevelopable` (5.4): ``X(t, v) = C(t) + v D(t)``,
  ``D = (τT + κB)/sqrt(κ² + τ²)``; C is a geodesic of it.
* :class:`CanalSurface` (5.5): envelope of spheres ``(C(t), r(t))``; developable only as a cone or
  cylinder of revolution, otherwise only its (sampled Gaussian-curvature) report is given.
* Joins (5.6): :func:`join_developable` applies :func:`ght_cad.continuity.join` to the 4-D dual
  curves; :func:`measure_developable_joint` measures the achieved order independently (projective
  contact of the dual curves, i.e. common tangent plane, ruling, edge-of-regression point ...);
  :class:`CompositeDevelopable` chains segments that share their joint rulings.

All surfaces are parametrized on ``(u, v) ∈ [0, 1]²`` (``u`` is the surface parameter; with a
``t_range`` the dual-curve parameter is ``t = t0 + u (t1 - t0)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from math import comb
from typing import Any, Callable, Sequence

import numpy as np

from ._validate import as_parameter_array, check_finite_array, check_unit_interval
from .basis import _check_order, evaluate_derivatives
from .bspline import BSplineSurfaceData, fit_function
from .curve import GHTCurve
from .errors import ConversionError, DegenerateGeometryError, EdgeOfRegressionError, GHTError, SingularJoinError
from .planes import PARALLEL_TOL, as_plane, check_control_planes, meet, meet_matrix, normalize_planes, plucker
from .ruled import Developability, RuledSurface, regression_v

__all__ = [
    "EnvelopeDevelopable",
    "developable_from_planes",
    "TangentDevelopable",
    "RectifyingDevelopable",
    "CanalSurface",
    "CanalReport",
    "CompositeDevelopable",
    "DevelopableJointReport",
    "join_developable",
    "measure_developable_joint",
    "curve_derivatives",
    "developable_bspline",
    "RuledPiece",
    "ruled_pieces",
]

_Jet = list  # list of arrays: value and derivatives 0..K
_JET_CACHE_SIZE = 8  # dual-curve jets kept per EnvelopeDevelopable
_JET_CACHE_MAX = 4096  # largest parameter array whose jet is kept
_ZERO = np.array([0.0])
_ONE = np.array([1.0])


# ----------------------------------------------------------------------------------------------
# jets: values + derivatives propagated by Leibniz' rule
# ----------------------------------------------------------------------------------------------
def _jprod(f: Callable[[np.ndarray, np.ndarray], np.ndarray], A: _Jet, B: _Jet) -> _Jet:
    """``(f(A, B))^(r) = Σ_s C(r, s) f(A^(s), B^(r-s))`` for a bilinear ``f``."""
    K = min(len(A), len(B)) - 1
    return [sum(comb(r, s) * f(A[s], B[r - s]) for s in range(r + 1)) for r in range(K + 1)]


def _mul(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return x * y


def _dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.sum(x * y, axis=-1, keepdims=True)


def _cross(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.cross(x, y)


def _jpow(N: _Jet, p: float) -> _Jet:
    """Jet of ``N^p`` (Faà di Bruno up to order 3)."""
    n0 = N[0]
    out = [n0**p]
    if len(N) > 1:
        out.append(p * n0 ** (p - 1) * N[1])
    if len(N) > 2:
        out.append(p * (p - 1) * n0 ** (p - 2) * N[1] ** 2 + p * n0 ** (p - 1) * N[2])
    if len(N) > 3:
        out.append(
            p * (p - 1) * (p - 2) * n0 ** (p - 3) * N[1] ** 3
            + 3 * p * (p - 1) * n0 ** (p - 2) * N[1] * N[2]
            + p * n0 ** (p - 1) * N[3]
        )
    return out


def _junit(F: _Jet) -> _Jet:
    """Jet of ``F / |F|``."""
    return _jprod(_mul, F, _jpow(_jprod(_dot, F, F), -0.5))


def _jcartesian(X: _Jet) -> _Jet:
    """Jet of ``(X1, X2, X3) / X0`` from a homogeneous jet."""
    w = [x[:, :1] for x in X]
    Y = [x[:, 1:] for x in X]
    with np.errstate(divide="ignore", invalid="ignore"):
        return _jprod(_mul, Y, _jpow(w, -1.0))


def _check_derivative(derivative: Any, max_order: int = 2) -> int:
    """Derivative order in ``0..max_order`` (surfaces here give analytic orders 0..2)."""
    return _check_order(derivative, max_order)


def curve_derivatives(curve: GHTCurve, t: Any, max_order: int) -> list[np.ndarray]:
    r"""``[C(t), C'(t), ..., C^(max_order)(t)]`` analytically, also beyond order 3.

    ``C^(r) = Σ_i b^{(r)}_{i,m} P_i`` with ``b^{(r)}_{i,m} = Σ_s C(r,s) Σ_k B^{(r-s)}_{i-k,n} f_k^{(s)}``;
    seed derivatives of order > 3 come from the GHT seed formulas (sin/cos and polynomials), which
    hold for every order. All orders share one seed evaluation and one Bernstein matrix per order
    (:func:`ght_cad.basis.evaluate_derivatives`).

    Args:
        curve: a GHT curve (GHT/GBT/Bernstein seed, possibly reversed, for orders > 3).
        t: parameters in [0, 1].
        max_order: highest order (0..6).

    Raises:
        GHTError: a custom seed and ``max_order > 3``; t outside [0, 1].
    """
    tt, _ = as_parameter_array(t)
    check_unit_interval("t", tt, slack=1e-9)
    seed = curve.seed
    if max_order > seed.max_derivative:
        raise GHTError(
            f"derivative order {int(seed.max_derivative) + 1} of the seed {seed!r} is needed here but custom "
            f"seeds only guarantee orders 0..{int(seed.max_derivative)}; use the GHT/GBT/Bernstein seeds"
        )
    return evaluate_derivatives(tt, curve.control_points, seed, max_order)


def _fmt(v: Any) -> str:
    return np.array2string(np.asarray(v, dtype=float), precision=6, separator=", ")


def _check_range(t_range: Any) -> tuple[float, float]:
    try:
        t0, t1 = (float(x) for x in t_range)
    except (TypeError, ValueError):
        raise GHTError(f"t_range={t_range!r} must be a pair (t0, t1) with 0 <= t0 < t1 <= 1") from None
    if not (math.isfinite(t0) and math.isfinite(t1) and 0.0 <= t0 < t1 <= 1.0):
        raise GHTError(f"t_range=({t0:g}, {t1:g}) is not allowed; it must satisfy 0 <= t0 < t1 <= 1")
    return t0, t1


def _sign_change_roots(f: Callable[[np.ndarray], np.ndarray], u: np.ndarray, vals: np.ndarray) -> list[float]:
    """Parameters where the sampled scalar ``vals = f(u)`` changes sign, refined by bisection."""
    from scipy.optimize import brentq

    roots = []
    s = np.sign(vals)
    for i in np.nonzero(s[:-1] * s[1:] < 0)[0]:
        try:
            roots.append(float(brentq(lambda x: float(f(np.array([x]))[0]), u[i], u[i + 1], xtol=1e-14)))
        except ValueError:
            roots.append(float(0.5 * (u[i] + u[i + 1])))
    roots.extend(float(x) for x in u[vals == 0.0])
    return sorted(roots)


# ----------------------------------------------------------------------------------------------
# 5.2 enveloping developable
# ----------------------------------------------------------------------------------------------
class EnvelopeDevelopable(RuledSurface):
    r"""Envelope of the planes ``U(t) = Σ b_{i,m}(t; μ,ν,γ) U_i`` cut by two boundary planes.

    ``a(t) = U ∩ U' ∩ E_a``, ``b(t) = U ∩ U' ∩ E_b``, ``X(u, v) = (1-v) a + v b`` with
    ``t = t0 + u (t1 - t0)``. Derivatives of ``a``, ``b`` (orders 0..2) are analytic, by the
    product rule through the trilinear meet and the quotient rule for ``(X1, X2, X3)/X0``.

    Use :func:`developable_from_planes` to build one (it validates the input).

    Args:
        planes: (m+1, 4) control planes, or a 4-D :class:`GHTCurve` of planes (then mu, nu, gamma
            and normalize must be left at their defaults).
        boundary_planes: ``(E_a, E_b)``.
        mu, nu, gamma: shape parameters of the dual curve.
        t_range: kept dual-curve parameter range (trimming).
        normalize: rescale the control planes to unit normals first.
        check: run :meth:`check` (skip only for inputs known to be valid, e.g. inside optimizers).
        samples: parameters sampled by :meth:`check`.

    Raises:
        See :func:`developable_from_planes`.

    Attributes:
        dual_curve: the 4-D GHT curve of planes ``U(t)``.
        boundary_planes: ``(E_a, E_b)`` as a (2, 4) array.
        t_range: ``(t0, t1)``.
    """

    def __init__(
        self,
        planes: Any,
        boundary_planes: Any,
        mu: float = 0.0,
        nu: float = 0.0,
        gamma: float = 0.0,
        *,
        t_range: tuple[float, float] = (0.0, 1.0),
        normalize: bool = False,
        check: bool = True,
        samples: int = 513,
    ) -> None:
        if isinstance(planes, GHTCurve):
            if planes.dim != 4:
                raise GHTError(f"a dual curve of planes must be 4-D; got a curve of dimension {planes.dim}")
            if (mu, nu, gamma) != (0.0, 0.0, 0.0) or normalize:
                raise GHTError(
                    f"mu={mu!r}, nu={nu!r}, gamma={gamma!r}, normalize={normalize!r} were given with a "
                    "GHTCurve of planes; its shape parameters and plane scales are its own (pass an array "
                    "of planes to set them)"
                )
            check_control_planes(planes.control_points, "planes")
            curve = planes
        else:
            arr = check_control_planes(planes, "planes")
            if normalize:
                arr = normalize_planes(arr)
            curve = GHTCurve(arr, mu, nu, gamma)
        self.dual_curve: GHTCurve = curve
        try:
            bp = np.array(boundary_planes, dtype=float)
        except (TypeError, ValueError):
            raise GHTError("boundary_planes must be two plane 4-vectors (E_a, E_b)") from None
        if bp.shape != (2, 4):
            raise GHTError(f"boundary_planes must have shape (2, 4) (E_a, E_b); got shape {bp.shape}")
        self.boundary_planes = np.array([as_plane(bp[0], "E_a"), as_plane(bp[1], "E_b")])
        self.t_range = _check_range(t_range)
        if check:
            self.check(samples)

    # -- parameters -------------------------------------------------------------------------
    @property
    def planes(self) -> np.ndarray:
        """Control planes ``U_0..U_m`` (rows of the dual curve)."""
        return self.dual_curve.control_points

    def dual_parameter(self, u: Any) -> np.ndarray:
        """Dual-curve parameter ``t = t0 + u (t1 - t0)`` of surface parameter ``u``."""
        uu, _ = as_parameter_array(u, "u")
        # checked on u itself: for a trimmed surface an out-of-range u maps to a t inside [0, 1]
        # and would silently evaluate the envelope beyond the face
        check_unit_interval("u", uu, slack=1e-9)
        t0, t1 = self.t_range
        return t0 + uu * (t1 - t0)

    def _U(self, u: Any, K: int) -> _Jet:
        """``[d^r U(t(u)) / du^r for r = 0..K]`` (K <= 3), read-only arrays.

        ``d^r U / du^r = h^r U^(r)(t)``, ``h = t1 - t0``; all orders from one basis pass
        (:func:`ght_cad.basis.evaluate_derivatives`). The last few jets of up to
        ``_JET_CACHE_MAX`` parameters are kept: the checks and the B-spline fit ask for the same
        parameters several times (a, b, ruling, edge of regression).
        """
        t = self.dual_parameter(u)
        t0, t1 = self.t_range
        curve = self.dual_curve
        cache = self.__dict__.get("_jet_cache")
        if cache is None or cache[0] is not curve:
            cache = (curve, {})
            self._jet_cache = cache
        store = cache[1]
        key = (t.tobytes(), t0, t1) if t.size <= _JET_CACHE_MAX else None
        hit = store.get(key) if key is not None else None
        if hit is not None and len(hit) > K:
            return hit[: K + 1]
        check_unit_interval("t", t, slack=1e-9)
        h = t1 - t0
        out = evaluate_derivatives(t, curve.control_points, curve.seed, K)
        if h != 1.0:
            out = [d * h**r for r, d in enumerate(out)]
        if key is not None:
            for d in out:
                d.setflags(write=False)
            if len(store) >= _JET_CACHE_SIZE:
                store.pop(next(iter(store)))
            store[key] = out
        return out

    def _boundary_h(self, u: Any, K: int) -> _Jet:
        """Homogeneous jets of ``meet(U, U', E_a)`` and ``meet(U, U', E_b)`` side by side, (len(u), 8).

        ``meet(A, B, E) = plucker(A, B) @ M(E)`` (linear in E); the product rule gives
        ``X^(k) = Σ_s C(k,s) meet(U^(s), U^(k-s+1), E)``. Columns 0..3 belong to E_a, 4..7 to E_b;
        :meth:`a`, :meth:`b` and :meth:`boundary_jet` share this one computation.
        """
        U = self._U(u, K + 1)
        M = self._boundary_meet()
        return _jprod(lambda A, B: plucker(A, B) @ M, U[: K + 1], U[1 : K + 2])

    def _ab(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        """``(a(u), b(u))`` from one :meth:`_boundary_h` (the same values as :meth:`a`, :meth:`b`)."""
        H = self._boundary_h(u, 0)
        return tuple(_jcartesian([h[:, 4 * w : 4 * w + 4] for h in H])[0] for w in (0, 1))  # type: ignore[return-value]

    def _boundary_point_jet(self, u: Any, which: int, K: int) -> _Jet:
        """Cartesian jet ``[x, x', ..]`` of the boundary curve on ``E_a`` (which=0) or ``E_b`` (which=1)."""
        return _jcartesian([h[:, 4 * which : 4 * which + 4] for h in self._boundary_h(u, K)])

    # -- RuledSurface interface ---------------------------------------------------------------
    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        r"""``a^(r)(u)``, ``a = U ∩ U' ∩ E_a`` (analytic, r = 0..2)."""
        r = _check_derivative(derivative)
        return self._boundary_point_jet(u, 0, r)[r]

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        r"""``b^(r)(u)``, ``b = U ∩ U' ∩ E_b`` (analytic, r = 0..2)."""
        r = _check_derivative(derivative)
        return self._boundary_point_jet(u, 1, r)[r]

    def boundary_values(self, u: Any) -> np.ndarray:
        """``(a(u), b(u))`` side by side, shape (len(u), 6), sharing one evaluation of ``U, U'``."""
        U = self._U(u, 1)
        X = (plucker(U[0], U[1]) @ self._boundary_meet()).reshape(-1, 2, 4)
        with np.errstate(divide="ignore", invalid="ignore"):
            return (X[:, :, 1:] / X[:, :, :1]).reshape(-1, 6)

    def _boundary_meet(self) -> np.ndarray:
        """``[M(E_a) | M(E_b)]`` (6, 8): ``meet(U, V, E) = plucker(U, V) @ M(E)`` is linear in E, so
        one product cuts a line with both boundary planes. Kept while the boundary planes are unchanged."""
        E = self.boundary_planes
        key = E.tobytes()
        cached = self.__dict__.get("_meet_cache")
        if cached is None or cached[0] != key:
            cached = (key, np.hstack([meet_matrix(E[0]), meet_matrix(E[1])]))
            self._meet_cache = cached
        return cached[1]

    def boundary_jet(self, u: Any, order: int = 2) -> list[np.ndarray]:
        """``[(a, b), (a', b'), ...]`` up to ``order`` (<= 2), each (len(u), 6), from one ``U`` jet."""
        r = _check_derivative(order)
        H = self._boundary_h(u, r)
        sides = [_jcartesian([h[:, 4 * which : 4 * which + 4] for h in H]) for which in (0, 1)]
        return [np.hstack([sides[0][k], sides[1][k]]) for k in range(r + 1)]

    # -- geometry -------------------------------------------------------------------------------
    def ruling_direction(self, u: Any) -> np.ndarray:
        r"""Unit direction of the ruling ``U ∩ U'``: ``n(U) × n(U') / |..|`` (sign arbitrary)."""
        U = self._U(u, 1)
        d = np.cross(U[0][:, 1:], U[1][:, 1:])
        return d / np.linalg.norm(d, axis=1, keepdims=True)

    def edge_of_regression(self, u: Any, *, homogeneous: bool = False) -> np.ndarray:
        r"""Edge of regression ``U ∩ U' ∩ U''`` at surface parameter ``u``.

        Args:
            u: surface parameter(s).
            homogeneous: return the homogeneous 4-vectors (``X0 = 0`` at infinity, e.g. a cylinder).

        Returns:
            (len(u), 3) Cartesian points (``nan`` rows for points at infinity), or (len(u), 4).
        """
        U = self._U(u, 2)
        R = meet(U[0], U[1], U[2])
        if homogeneous:
            return R
        scale = np.linalg.norm(R, axis=1)
        at_inf = np.abs(R[:, 0]) <= 1e-13 * scale
        with np.errstate(divide="ignore", invalid="ignore"):
            out = R[:, 1:] / R[:, :1]
        out[at_inf] = np.nan
        return out

    def regression_parameter(self, u: Any) -> np.ndarray:
        r"""Position ``v_R`` of the edge of regression on the ruling, ``R = a + v_R (b - a)``.

        ``v_R = h / R0`` with ``h = (R_xyz - R0 a)·g / |g|²`` (``±inf`` for a point at infinity).
        The strip ``v ∈ [0, 1]`` is singular where ``0 <= v_R <= 1``.
        """
        h, R0 = self._regression_hr(u)
        with np.errstate(divide="ignore", invalid="ignore"):
            return h / R0

    def _regression_hr(
        self, u: Any, A: np.ndarray | None = None, g: np.ndarray | None = None, *, with_norm: bool = False
    ) -> Any:
        """``(h, R0)`` of :meth:`regression_parameter` for unit ``R``, and ``|R|`` if ``with_norm``;
        ``A = a(u)``, ``g = b(u) - a(u)`` may be passed when already known."""
        U = self._U(u, 2)
        R = meet(U[0], U[1], U[2])
        Rn = np.linalg.norm(R, axis=1, keepdims=True)
        R = R / np.maximum(Rn, 1e-300)
        if A is None or g is None:
            A, B = self._ab(u)
            g = B - A
        h = np.sum((R[:, 1:] - R[:, :1] * A) * g, axis=1) / np.sum(g * g, axis=1)
        return (h, R[:, 0], Rn[:, 0]) if with_norm else (h, R[:, 0])

    # -- validation -----------------------------------------------------------------------------
    def check(self, samples: int = 513) -> None:
        r"""Detect unusable input on ``samples`` parameters (refined where a sign changes).

        Raises:
            DegenerateGeometryError: ``U(t)`` and ``U'(t)`` with parallel normals (the ruling is at
                infinity or undefined); a boundary plane containing or parallel to a ruling (the
                boundary curve runs to infinity); ``E_a`` and ``E_b`` crossing on a ruling (zero
                strip width).
            EdgeOfRegressionError: the edge of regression ``U ∩ U' ∩ U''`` lies in the strip
                ``0 <= v <= 1`` (message gives u, t and v).
        """
        u = np.linspace(0.0, 1.0, int(samples))
        U = self._U(u, 2)
        n0, n1 = U[0][:, 1:], U[1][:, 1:]
        d = np.cross(n0, n1)
        dn = np.linalg.norm(d, axis=1)
        # turning rate |n × n'| compared with |n| max(|n'|, |n|): a vanishing U' (a cusp of the dual
        # curve, e.g. nu = gamma = -1 at t = 1) is degenerate too, not only parallel n and n'
        n0n = np.linalg.norm(n0, axis=1)
        ref = n0n * np.maximum(np.linalg.norm(n1, axis=1), n0n)
        bad = ~(dn > PARALLEL_TOL * ref)
        if bad.any():
            i = int(np.argmax(bad))
            t = float(self.dual_parameter(u[i])[0])
            stationary = np.linalg.norm(U[1][i]) <= PARALLEL_TOL * np.linalg.norm(U[0][i])
            what = (
                "vanishes (the dual curve is stationary there, e.g. "
                "nu = gamma = -1 gives U'(1) = 0 and mu = gamma = -1 gives U'(0) = 0), so the ruling "
                "U ∩ U' is undefined"
                if stationary
                else "have parallel normals, so the ruling U ∩ U' is at infinity"
            )
            raise DegenerateGeometryError(
                f"at u={u[i]:.6g} (t={t:.6g}) the dual curve's plane U={_fmt(U[0][i])} and its derivative "
                f"U'={_fmt(U[1][i])} {what}; "
                "the planes' normals must keep turning (no parallel neighbours, no turning back)" + self._orientation_hint()
            )
        dunit = d / dn[:, None]
        names = ("E_a", "E_b")
        for which in (0, 1):
            E = self.boundary_planes[which]
            nE = E[1:] / np.linalg.norm(E[1:])
            sin = dunit @ nE
            hits = [float(x) for x in u[np.abs(sin) <= PARALLEL_TOL]]
            # sampled values: _ruling_sin(self, u, nE) from the d, |d| above
            hits += _sign_change_roots(lambda x, nE=nE: _ruling_sin(self, x, nE), u, (d @ nE) / dn)
            if hits:
                x = hits[0]
                Ux = self._U(np.array([x]), 1)
                p = meet(Ux[0], Ux[1], np.concatenate([[0.0], np.cross(Ux[0][0, 1:], Ux[1][0, 1:])]))[0]
                p = p[1:] / p[0]
                dist = abs(E[0] + E[1:] @ p) / np.linalg.norm(E[1:])
                size = max(1.0, float(np.linalg.norm(p)))
                what = "contains" if dist <= 1e-9 * size else "is parallel to"
                t = float(self.dual_parameter(x)[0])
                raise DegenerateGeometryError(
                    f"boundary plane {names[which]}={_fmt(E)} {what} the ruling at u={x:.6g} (t={t:.6g}) "
                    f"(the line through {_fmt(p)} with direction {_fmt(self.ruling_direction(x)[0])}); "
                    "boundary planes must cut every ruling of the strip in one point" + self._orientation_hint()
                )
        # strip width: E_a and E_b must not cross on a ruling
        A, B = self._ab(u)
        G = B - A
        w = np.sum(G * dunit, axis=1)
        scale = np.maximum(np.linalg.norm(A, axis=1), 1.0)
        zero = np.abs(w) <= 1e-12 * scale
        roots = [float(x) for x in u[zero]] + _sign_change_roots(
            lambda x: np.sum((self.b(x) - self.a(x)) * self.ruling_direction(x), axis=1), u, w
        )
        if roots:
            x = roots[0]
            t = float(self.dual_parameter(x)[0])
            raise DegenerateGeometryError(
                f"boundary planes E_a={_fmt(self.boundary_planes[0])} and E_b={_fmt(self.boundary_planes[1])} "
                f"cut the ruling at u={x:.6g} (t={t:.6g}) in the same point {_fmt(self.a(x)[0])}; "
                "the strip has zero width there (the boundary planes must not cross inside the strip)"
                + self._orientation_hint()
            )
        # edge of regression inside the strip: phi = h (R0 - h) >= 0  <=>  0 <= v_R <= 1
        self._check_regression(u, A, G)

    def _check_regression(self, u: np.ndarray, A: np.ndarray | None = None, G: np.ndarray | None = None) -> None:
        from scipy.optimize import minimize_scalar

        h, R0, Rn = self._regression_hr(u, A, G, with_norm=True)
        phi = h * (R0 - h)
        # where U, U', U'' are dependent (an inflection of the dual curve) R vanishes and the edge
        # of regression is undefined at that single t: not a point of the strip
        U = self._U(u, 2)
        ref = np.prod([np.linalg.norm(x, axis=1) for x in U], axis=0)
        phi = np.where(Rn > 1e-12 * ref, phi, -np.inf)
        best_u, best_phi = float(u[int(np.argmax(phi))]), float(np.max(phi))
        # refine around local maxima that the neighbouring variation could lift above 0 (the edge
        # may enter the strip between two samples)
        interior = np.nonzero((phi[1:-1] >= phi[:-2]) & (phi[1:-1] >= phi[2:]))[0] + 1
        ends = [i for i in (0, phi.size - 1) if phi[i] >= phi[1 if i == 0 else -2]]
        cand = [int(i) for i in list(interior) + ends]
        with np.errstate(invalid="ignore"):
            jump = np.nan_to_num(np.abs(np.diff(phi)), nan=0.0, posinf=0.0)
        near = [i for i in cand if phi[i] + 2.0 * max(jump[max(i - 1, 0)], jump[min(i, jump.size - 1)]) >= 0.0]
        for i in sorted(near, key=lambda j: -phi[j])[:8]:
            lo, hi = u[max(i - 1, 0)], u[min(i + 1, u.size - 1)]

            def f(x: float) -> float:
                hh, rr = self._regression_hr(np.array([x]))
                return -float(hh[0] * (rr[0] - hh[0]))

            res = minimize_scalar(f, bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
            if -res.fun > best_phi:
                best_u, best_phi = float(res.x), float(-res.fun)
        if best_phi >= 0.0:
            vR = float(self.regression_parameter(np.array([best_u]))[0])
            t = float(self.dual_parameter(best_u)[0])
            R = self.edge_of_regression(np.array([best_u]))[0]
            inside = np.nonzero(phi >= 0.0)[0]
            if inside.size:
                t_lo, t_hi = (float(x) for x in self.dual_parameter(u[[inside[0], inside[-1]]]))
                where = f" (sampled: for t in [{t_lo:.4g}, {t_hi:.4g}])"
            else:
                where = ""
            raise EdgeOfRegressionError(
                f"the strip contains its edge of regression at u={best_u:.6g} (t={t:.6g}), v={vR:.6g} "
                f"(point {_fmt(R)}){where}; the surface is singular there. Move the boundary planes "
                f"E_a={_fmt(self.boundary_planes[0])}, E_b={_fmt(self.boundary_planes[1])} so that the "
                "edge of regression stays outside 0 <= v <= 1, or trim t_range" + self._orientation_hint()
            )

    def _orientation_hint(self) -> str:
        """A note when neighbouring control planes have opposite normal orientations."""
        P = self.planes
        n = P[:, 1:] / np.linalg.norm(P[:, 1:], axis=1, keepdims=True)
        dots = np.sum(n[:-1] * n[1:], axis=1)
        if np.all(dots >= 0.0):
            return ""
        i = int(np.argmin(dots))
        return (
            f". Note: control planes planes[{i}] and planes[{i + 1}] have opposite normal orientations "
            f"(n·n = {dots[i]:.3g}); U and -U are the same plane but blend differently: flip the sign of one"
        )

    # -- CAD ------------------------------------------------------------------------------------
    def to_face(self, tol: float | None = None, **kwargs: Any) -> Any:
        """One B-spline face (degree 1 across the rulings); see :func:`ght_cad.cad.developable_faces.developable_face`."""
        from .cad.developable_faces import developable_face

        return developable_face(self, tol=tol, **kwargs)

    def trimmed(self, t_range: tuple[float, float]) -> "EnvelopeDevelopable":
        """The same envelope restricted to the dual-curve parameters ``t_range``."""
        return EnvelopeDevelopable(self.dual_curve, self.boundary_planes, t_range=t_range)

    def to_dict(self) -> dict[str, Any]:
        """Plain data: ``{"planes", "boundary_planes", "mu", "nu", "gamma", "seed", "t_range"}``."""
        c = self.dual_curve
        return {
            "planes": c.control_points.tolist(),
            "boundary_planes": self.boundary_planes.tolist(),
            "mu": c.mu,
            "nu": c.nu,
            "gamma": c.gamma,
            "seed": c.seed.name,
            "t_range": list(self.t_range),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "EnvelopeDevelopable":
        """Inverse of :meth:`to_dict` (the input is validated again)."""
        curve = GHTCurve.from_dict(
            {
                "control_points": data["planes"],
                "mu": data.get("mu", 0.0),
                "nu": data.get("nu", 0.0),
                "gamma": data.get("gamma", 0.0),
                "seed": data.get("seed", "ght"),
            }
        )
        return cls(curve, data["boundary_planes"], t_range=tuple(data.get("t_range", (0.0, 1.0))))

    def __repr__(self) -> str:
        c = self.dual_curve
        return (
            f"EnvelopeDevelopable(degree={c.degree}, mu={c.mu:g}, nu={c.nu:g}, gamma={c.gamma:g}, "
            f"t_range={self.t_range})"
        )


def _ruling_sin(surf: EnvelopeDevelopable, u: np.ndarray, nE: np.ndarray) -> np.ndarray:
    """Sine of the angle between the ruling at u and a plane with unit normal nE (signed)."""
    U = surf._U(u, 1)
    d = np.cross(U[0][:, 1:], U[1][:, 1:])
    return (d @ nE) / np.linalg.norm(d, axis=1)


def developable_from_planes(
    planes: Any,
    boundary_planes: Any,
    mu: float = 0.0,
    nu: float = 0.0,
    gamma: float = 0.0,
    *,
    t_range: tuple[float, float] = (0.0, 1.0),
    normalize: bool = False,
) -> EnvelopeDevelopable:
    r"""Enveloping developable surface of control planes (spec sections 5.2, 9).

    Dual curve ``U(t) = Σ_{i=0..m} b_{i,m}(t; μ,ν,γ) U_i``; ruling ``U(t) ∩ U'(t)``; boundary
    curves ``a(t) = U ∩ U' ∩ E_a``, ``b(t) = U ∩ U' ∩ E_b``; surface
    ``X(t, v) = (1-v) a(t) + v b(t)`` with the pairing a(t)–b(t) kept. At t = 0 it touches ``U_0``
    along ``U_0 ∩ U_1``, at t = 1 ``U_m`` along ``U_{m-1} ∩ U_m``.

    The scale of each control plane acts like a rational weight: ``(-r, 1, 1, 0)`` as the middle
    plane (with γ = -1, μ = ν = 0) gives the exact circular cylinder, its unit-normal rescaling
    does not. Pass ``normalize=True`` to rescale every control plane to a unit normal first.

    Args:
        planes: (m+1, 4) control planes ``U_i = (u0, u1, u2, u3)``, m >= 2.
        boundary_planes: ``(E_a, E_b)``, two plane 4-vectors that cut every ruling.
        mu, nu, gamma: shape parameters in [-1, 1].
        t_range: dual-curve parameter range ``(t0, t1)`` kept (trimming), ``0 <= t0 < t1 <= 1``.
        normalize: rescale the control planes to unit normals before use.

    Returns:
        :class:`EnvelopeDevelopable` with ``.evaluate(u, v)``, ``.developability()``,
        ``.to_face()``, ``.edge_of_regression(u)``, ``.dual_curve``.

    Raises:
        DegenerateGeometryError: NaN/inf, zero normals, parallel or coincident neighbouring
            control planes, boundary planes containing or parallel to a ruling, crossing
            boundary planes.
        EdgeOfRegressionError: the strip contains its edge of regression.
        ShapeParameterError: μ, ν or γ outside [-1, 1].
        GHTError: wrong shapes, bad t_range.
    """
    return EnvelopeDevelopable(planes, boundary_planes, mu, nu, gamma, t_range=t_range, normalize=normalize)


# ----------------------------------------------------------------------------------------------
# B-spline data (compatible directrix poles)
# ----------------------------------------------------------------------------------------------
def _size(surface: RuledSurface) -> float:
    """Diagonal of the bounding box of the strip, from the boundary curves at 33 parameters (a
    ruling segment lies in the box of its end points)."""
    fast = getattr(surface, "boundary_values", None)
    u = np.linspace(0.0, 1.0, 33)
    g = fast(u).reshape(-1, 3) if fast is not None else np.vstack([surface.a(u), surface.b(u)])
    return float(np.linalg.norm(g.max(axis=0) - g.min(axis=0)))


def _bspline_theta(curve: Any, samples: int = 513) -> float:
    """θ_max (degrees) of the ruled B-spline ``(A(u), B(u))`` from its own derivatives."""
    from .ruled import _theta

    u = np.linspace(0.0, 1.0, samples)
    F = curve.evaluate(u)
    F1 = curve.evaluate(u, 1)
    th, _ = _theta(F1[:, :3], F1[:, 3:], F[:, 3:] - F[:, :3])
    return float(np.nanmax(th))


@dataclass(frozen=True)
class RuledPiece:
    r"""One smooth piece of a ruled surface between two of its ``breakpoints``.

    Attributes:
        lo, hi: the piece's parameter interval ``[λ_lo, λ_hi]`` on the whole surface.
        surface: the piece as a :class:`~ght_cad.ruled.RuledSurface` on ``x ∈ [0, 1]``,
            ``λ = λ_lo + x (λ_hi - λ_lo)`` (derivatives with respect to x).
        end_orders: the highest end derivative order of ``surface`` that is exact (one-sided) at
            ``x = 0`` and at ``x = 1`` (0..2).
    """

    lo: float
    hi: float
    surface: RuledSurface
    end_orders: tuple[int, int]


class _RuledInterval(RuledSurface):
    r"""``surface`` on ``[lo, hi]`` as a ruled surface on ``[0, 1]``:
    ``a_k^(r)(x) = (hi - lo)^r a^(r)(lo + x (hi - lo))`` (likewise b). At an interior breakpoint a
    surface evaluates one of its two sides only, so there only the value is a one-sided limit
    (``end_orders`` 0 at interior ends)."""

    def __init__(self, surface: RuledSurface, lo: float, hi: float) -> None:
        self._s = surface
        self._lo, self._w = float(lo), float(hi) - float(lo)

    def _lam(self, u: Any) -> np.ndarray:
        x = np.atleast_1d(np.asarray(u, dtype=float))
        return np.clip(self._lo + x * self._w, 0.0, 1.0)

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._s.a(self._lam(u), derivative) * self._w**derivative

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._s.b(self._lam(u), derivative) * self._w**derivative

    def __repr__(self) -> str:
        return f"{self._s!r}[{self._lo:.6g}, {self._lo + self._w:.6g}]"


def ruled_pieces(surface: RuledSurface) -> list[RuledPiece]:
    r"""The smooth pieces of a ruled surface between its ``breakpoints`` (where a, b are only C0 or
    C1 in u, e.g. the joint rulings of a :class:`~ght_cad.loft.DevelopableLoft`'s fans).

    The pieces are, in this order of preference: the surface's own ``segments`` when they match
    the breakpoints (a loft: each segment is exact with one-sided jets, ``end_orders`` =
    ``segment.end_order``); for an :class:`~ght_cad.sheet.OffsetRuledSurface` the offsets of its
    base's pieces (the same δ); otherwise the surface restricted to ``[λ_k, λ_{k+1}]``
    (``end_orders`` 2 at the surface's ends, 0 at interior breakpoints, where only the value is
    one-sided).

    Args:
        surface: any :class:`~ght_cad.ruled.RuledSurface` (``breakpoints`` optional).

    Returns:
        One :class:`RuledPiece` per interval; a single piece ``(0, 1, surface, (2, 2))`` without
        breakpoints in (0, 1).
    """
    bp = sorted(float(b) for b in getattr(surface, "breakpoints", ()) if 0.0 < float(b) < 1.0)
    if not bp:
        return [RuledPiece(0.0, 1.0, surface, (2, 2))]
    edges = [0.0] + bp + [1.0]
    segs = list(getattr(surface, "segments", None) or [])
    if len(segs) == len(edges) - 1 and all(isinstance(sg, RuledSurface) for sg in segs):
        ranges = [tuple(getattr(sg, "lam_range", (math.nan, math.nan))) for sg in segs]
        if all(abs(r[0] - lo) <= 1e-12 and abs(r[1] - hi) <= 1e-12 for r, lo, hi in zip(ranges, edges[:-1], edges[1:])):
            out = []
            for sg, lo, hi in zip(segs, edges[:-1], edges[1:]):
                k = int(getattr(sg, "end_order", 2))
                out.append(RuledPiece(lo, hi, sg, (k, k)))
            return out
    from .sheet import OffsetRuledSurface

    if isinstance(surface, OffsetRuledSurface):
        base = ruled_pieces(surface.base)
        if [(pc.lo, pc.hi) for pc in base] == list(zip(edges[:-1], edges[1:])):
            return [RuledPiece(pc.lo, pc.hi, OffsetRuledSurface(pc.surface, surface.delta), pc.end_orders) for pc in base]
    return [RuledPiece(lo, hi, _RuledInterval(surface, lo, hi), (2 if lo == 0.0 else 0, 2 if hi == 1.0 else 0))
            for lo, hi in zip(edges[:-1], edges[1:])]


def _check_fit_args(surface: Any, tol: Any, degree: Any, end_order: Any, theta_tol_deg: Any) -> tuple[float, int, float, float]:
    """Validated ``(tol, degree, theta_tol_deg, size)`` of :func:`developable_bspline`."""
    if not isinstance(surface, RuledSurface):
        raise GHTError(f"surface must be a RuledSurface, got {type(surface).__name__}")
    if end_order not in (0, 1, 2):
        raise GHTError(f"end_order={end_order!r} is not allowed; use 0, 1 or 2")
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer, float)) or int(degree) != degree \
            or not 1 <= int(degree) <= 25:
        raise GHTError(f"degree={degree!r} is not allowed; B-spline degrees are integers 1..25")
    degree = int(degree)
    size = _size(surface)
    if tol is None:
        tol = 1e-7 * max(size, 1e-300)
    try:
        tol = float(tol)
        theta_tol_deg = float(theta_tol_deg)
    except (TypeError, ValueError):
        bad = "tol" if not isinstance(tol, float) else "theta_tol_deg"
        raise GHTError(f"{bad}={(tol if bad == 'tol' else theta_tol_deg)!r} is not a number; it must be a positive float") from None
    if not (math.isfinite(tol) and tol > 0):
        raise GHTError(f"tol={tol!r} must be a positive finite number")
    if not theta_tol_deg > 0:
        raise GHTError(f"theta_tol_deg={theta_tol_deg!r} must be > 0 (use inf to skip the check)")
    return tol, degree, theta_tol_deg, size


def _strip_fit(surface: RuledSurface, tol: float, degree: int, end_orders: tuple[int, int],
               theta_tol_deg: float) -> tuple[Any, float, float]:
    """The certified 6-D fit of one smooth strip with its θ check: ``(curve, θ_max, tol used)``."""
    fast = getattr(surface, "boundary_values", None)

    def f(u: np.ndarray) -> np.ndarray:
        return fast(u) if fast is not None else np.hstack([surface.a(u), surface.b(u)])

    tops = tuple(min(k, degree - 1) for k in end_orders)
    jet = getattr(surface, "boundary_jet", None)
    if jet is not None:
        J = jet(np.array([0.0, 1.0]), max(tops))
        ends = tuple([J[r][e] for r in range(tops[e] + 1)] for e in (0, 1))
    else:
        ends = tuple(
            [np.concatenate([surface.a(np.array([e]), r)[0], surface.b(np.array([e]), r)[0]]) for r in range(tops[i] + 1)]
            for i, e in enumerate((0.0, 1.0))
        )
    exact_theta = None
    for attempt in range(4):
        try:
            curve = fit_function(f, tol=tol, degree=degree, end_derivatives=ends)
        except ConversionError as exc:
            raise ConversionError(f"could not fit the boundary curves of {surface!r} to tol={tol:g}: {exc}") from exc
        theta = _bspline_theta(curve) if math.isfinite(theta_tol_deg) else float("nan")
        if not theta > theta_tol_deg:
            break
        if exact_theta is None:
            exact_theta = float(np.nanmax(surface.theta(np.linspace(0.0, 1.0, 513))))
            if exact_theta > 0.5 * theta_tol_deg:
                break  # the surface itself is not developable to theta_tol_deg: keep the tol fit
        if attempt == 3:
            raise ConversionError(
                f"the B-spline fit of {surface!r} has θ_max={theta:.3g}° > theta_tol_deg={theta_tol_deg:g}° "
                f"even at tol={tol:g}; the exact surface has θ_max={exact_theta:.3g}°"
            )
        tol /= 10.0
    return curve, theta, tol


def developable_bspline(
    surface: RuledSurface,
    *,
    tol: float | None = None,
    degree: int = 5,
    end_order: int = 2,
    theta_tol_deg: float = 1e-3,
) -> BSplineSurfaceData:
    r"""B-spline surface data of a ruled strip from compatible directrix poles.

    ``f(u) = (a(u), b(u)) ∈ R^6`` is fitted by :func:`ght_cad.bspline.fit_function` with
    ``max_u |f(u) - F(u)| <= tol`` at matched parameters and exact end derivatives up to
    ``end_order``; poles ``F_i = (A_i, B_i)`` give the net ``P[i, 0] = A_i``, ``P[i, 1] = B_i`` with
    ``degree_v = 1``, ``knots_v = [0, 0, 1, 1]``, so ``S(u, v) = (1-v) A(u) + v B(u)``.

    A surface with ``breakpoints`` in (0, 1) (where f is only C0/C1, e.g. a loft's fans, whose apex
    stands still while the other rail moves) is fitted piece by piece (:func:`ruled_pieces`: each
    piece with its exact one-sided end jets, end order ``min(end_order, piece)``) and the pieces
    are joined with knots of multiplicity ``degree`` at the breakpoints
    (:func:`ght_cad.bspline.join_bsplines`): ``S`` is then each piece's fit exactly (C0 at the
    joint rulings, the joint ruling an exact pole pair), with the surface's own parameter u = λ.
    A surface without breakpoints takes the single fit as before (bit for bit).

    The fitted surface's own developability is then checked: ``θ(u)`` from the B-spline's
    derivatives (``n_A = A' × G``, ``n_B = B' × G``, ``G = B - A``) on 513 parameters (per piece);
    while ``θ_max > theta_tol_deg`` the fit is repeated with ``tol / 10`` (at most 3 times) — the
    face is then developable to ``theta_tol_deg`` by construction, not only close to a developable.

    Args:
        surface: any :class:`~ght_cad.ruled.RuledSurface`.
        tol: absolute deviation bound; default ``1e-7`` times the bounding-box diagonal.
        degree: B-spline degree in u (>= 3 recommended).
        end_order: highest end derivative reproduced exactly (0..2).
        theta_tol_deg: required θ_max of the B-spline surface (degrees); ``inf`` skips the check.

    Returns:
        :class:`~ght_cad.bspline.BSplineSurfaceData` with ``max_deviation`` and ``info``
        (``info["theta_max_deg"]``: θ_max of the B-spline surface, ``info["fit_tol"]``; with
        breakpoints also ``info["pieces"]``, ``info["breaks"]``, ``info["joint_gaps"]``).

    Raises:
        ConversionError: the fit could not reach ``tol``, or θ_max stays above
            ``theta_tol_deg`` (only for a surface that is not developable itself).
    """
    tol, degree, theta_tol_deg, size = _check_fit_args(surface, tol, degree, end_order, theta_tol_deg)
    pieces = ruled_pieces(surface)
    if len(pieces) == 1:
        curve, theta, tol = _strip_fit(surface, tol, degree, (end_order, end_order), theta_tol_deg)
    else:
        from .bspline import join_bsplines

        fits = [_strip_fit(pc.surface, tol, degree, tuple(min(end_order, k) for k in pc.end_orders), theta_tol_deg)
                for pc in pieces]
        curve = join_bsplines([c for c, _, _ in fits], [pieces[0].lo] + [pc.hi for pc in pieces])
        ths = [t for _, t, _ in fits if not math.isnan(t)]
        theta = max(ths) if ths else float("nan")
        tol = min(t for _, _, t in fits)
    poles = np.stack([curve.poles[:, :3], curve.poles[:, 3:]], axis=1)
    info = dict(curve.info)
    info["size"] = size
    info["theta_max_deg"] = theta
    info["fit_tol"] = tol
    return BSplineSurfaceData(poles, curve.knots, np.array([0.0, 0.0, 1.0, 1.0]), curve.degree, 1,
                              max_deviation=curve.max_deviation, info=info)


# ----------------------------------------------------------------------------------------------
# generic check of a ruled strip against its striction/regression points
# ----------------------------------------------------------------------------------------------
def _check_strip_regular(surf: RuledSurface, samples: int = 513, what: str = "strip") -> None:
    r"""Raise EdgeOfRegressionError when the singular point of a developable strip is inside it.

    On a developable the tangent plane is singular where ``X_u = a' + v g'`` is parallel to ``g``:
    ``v* = -((a' × g)·(g' × g)) / |g' × g|²``. Where ``|g' × g|`` vanishes (cylinder-like) there is
    no singular point.
    """
    u = np.linspace(0.0, 1.0, samples)
    a1 = surf.a(u, 1)
    g = surf.ruling(u)
    g1 = surf.ruling(u, 1)
    vs = regression_v(a1, g, g1)
    inside = np.isfinite(vs) & (vs >= 0.0) & (vs <= 1.0)
    if inside.any():
        i = int(np.argmax(inside))
        raise EdgeOfRegressionError(
            f"the {what} contains its edge of regression at u={u[i]:.6g}, v={vs[i]:.6g} "
            f"(point {_fmt(surf.evaluate(u[i], vs[i]))}); the surface is singular there"
        )


def _check_3d_curve(curve: Any, name: str) -> GHTCurve:
    if not isinstance(curve, GHTCurve):
        raise GHTError(f"{name} must be a GHTCurve, got {type(curve).__name__}")
    if curve.dim != 3:
        raise GHTError(f"{name} has dimension {curve.dim}; a space curve of dimension 3 is required")
    return curve


def _check_v_range(v0: Any, v1: Any) -> tuple[float, float]:
    try:
        a, b = float(v0), float(v1)
    except (TypeError, ValueError):
        raise GHTError(f"v0={v0!r}, v1={v1!r} must be real numbers") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise GHTError(f"v0={a}, v1={b} must be finite")
    if not a < b:
        raise GHTError(f"v0={a:g} must be smaller than v1={b:g}")
    return a, b


# ----------------------------------------------------------------------------------------------
# 5.3 spine-curve (tangent) developable
# ----------------------------------------------------------------------------------------------
class TangentDevelopable(RuledSurface):
    r"""Tangent developable of a GHT space curve, ``X(t, v) = C(t) + v T(t)``, ``v ∈ [v0, v1]``.

    ``a(t) = C + v0 T``, ``b(t) = C + v1 T`` (so the surface parameter ``v ∈ [0, 1]`` maps to
    ``v0 + v (v1 - v0)``; v0, v1 in length units since T is a unit vector). C is the edge of
    regression, so the range must not contain 0 (``v0 > 0`` or ``v1 < 0``).

    Raises:
        EdgeOfRegressionError: ``v0 <= 0 <= v1`` (the spine would lie in the face).
        DegenerateGeometryError: the spine has a vanishing tangent ``C'`` or curvature (an
            inflection: the tangent surface folds there).
        GHTError: not a 3-D GHT curve, bad v range.
    """

    def __init__(self, curve: GHTCurve, v0: float, v1: float, *, samples: int = 257) -> None:
        self.curve = _check_3d_curve(curve, "curve")
        self.v0, self.v1 = _check_v_range(v0, v1)
        if self.v0 <= 0.0 <= self.v1:
            raise EdgeOfRegressionError(
                f"v range [{self.v0:g}, {self.v1:g}] contains 0: the spine curve (edge of regression of "
                "the tangent developable) would lie inside the face; use v0 > 0 or v1 < 0"
            )
        u = np.linspace(0.0, 1.0, samples)
        d = curve_derivatives(self.curve, u, 2)
        sp = np.linalg.norm(d[1], axis=1)
        kap = np.linalg.norm(np.cross(d[1], d[2]), axis=1)
        L = max(float(np.ptp(self.curve.control_points, axis=0).max()), 1e-300)
        if not np.all(sp > 1e-12 * L):
            i = int(np.argmin(sp))
            raise DegenerateGeometryError(f"the spine curve has a vanishing tangent |C'|={sp[i]:.3g} at t={u[i]:.6g}")
        if not np.all(kap > 1e-12 * sp**2):
            i = int(np.argmin(kap / sp**2))
            raise DegenerateGeometryError(
                f"the spine curve has zero curvature at t={u[i]:.6g} (|C' x C''|={kap[i]:.3g}); "
                "its tangent developable folds along that ruling"
            )

    def _side(self, u: Any, v: float, r: int) -> np.ndarray:
        d = curve_derivatives(self.curve, u, r + 1)
        T = _junit(d[1 : r + 2])
        return d[r] + v * T[r]

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``a^(r) = C^(r) + v0 T^(r)`` (analytic, r = 0..2)."""
        return self._side(u, self.v0, _check_derivative(derivative))

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``b^(r) = C^(r) + v1 T^(r)`` (analytic, r = 0..2)."""
        return self._side(u, self.v1, _check_derivative(derivative))

    def edge_of_regression(self, u: Any) -> np.ndarray:
        """The spine ``C(t)``."""
        return self.curve.evaluate(as_parameter_array(u, "u")[0])

    def to_face(self, tol: float | None = None, **kwargs: Any) -> Any:
        """One B-spline face; see :func:`ght_cad.cad.developable_faces.developable_face`."""
        from .cad.developable_faces import developable_face

        return developable_face(self, tol=tol, **kwargs)


# ----------------------------------------------------------------------------------------------
# 5.4 rectifying (geodesic-interpolating) developable
# ----------------------------------------------------------------------------------------------
class RectifyingDevelopable(RuledSurface):
    r"""Rectifying developable ``X(t, v) = C(t) + v D(t)``, ``D = (τT + κB)/sqrt(κ² + τ²)``.

    C is a geodesic of the surface (normal ∥ N along C): the strip a flat sheet makes when laid
    along C. ``a = C + v0 D``, ``b = C + v1 D`` with ``v0 < v1`` in length units (0 inside keeps C on
    the face). ``D ∥ ω̃ = det(C', C'', C''') |C'|² C' + |C' × C''|² (C' × C'')`` (the Darboux vector
    up to a positive factor); derivatives (orders 0..2) use analytic curve derivatives up to 5.

    Raises:
        DegenerateGeometryError: vanishing tangent or curvature of C (D undefined).
        EdgeOfRegressionError: the strip ``[v0, v1]`` contains its edge of regression.
        GHTError: not a 3-D GHT curve, bad v range, a custom seed without derivatives of order 5.
    """

    def __init__(self, curve: GHTCurve, v0: float, v1: float, *, samples: int = 257, check: bool = True) -> None:
        self.curve = _check_3d_curve(curve, "curve")
        self.v0, self.v1 = _check_v_range(v0, v1)
        u = np.linspace(0.0, 1.0, samples)
        d = curve_derivatives(self.curve, u, 2)
        sp = np.linalg.norm(d[1], axis=1)
        kap = np.linalg.norm(np.cross(d[1], d[2]), axis=1)
        if not np.all(kap > 1e-12 * np.maximum(sp, 1e-300) ** 2):
            i = int(np.argmin(kap))
            raise DegenerateGeometryError(
                f"the curve has zero curvature or tangent at t={u[i]:.6g} (|C' x C''|={kap[i]:.3g}); "
                "the rectifying direction D = (τT + κB)/sqrt(κ² + τ²) is undefined there"
            )
        if check:
            _check_strip_regular(self, samples, "rectifying strip")

    def direction(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Unit rectifying direction ``D^(r)(t)`` (r = 0..2)."""
        r = _check_derivative(derivative)
        return self._D(u, r)[r]

    def _D(self, u: Any, r: int) -> _Jet:
        d = curve_derivatives(self.curve, u, r + 3)
        p, q, w = d[1 : r + 2], d[2 : r + 3], d[3 : r + 4]
        X = _jprod(_cross, p, q)
        delta = _jprod(_dot, p, _jprod(_cross, q, w))
        P2 = _jprod(_dot, p, p)
        X2 = _jprod(_dot, X, X)
        om = [x + y for x, y in zip(_jprod(_mul, _jprod(_mul, delta, P2), p), _jprod(_mul, X2, X))]
        return _junit(om)

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``a^(r) = C^(r) + v0 D^(r)``."""
        r = _check_derivative(derivative)
        return curve_derivatives(self.curve, u, r)[r] + self.v0 * self._D(u, r)[r]

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``b^(r) = C^(r) + v1 D^(r)``."""
        r = _check_derivative(derivative)
        return curve_derivatives(self.curve, u, r)[r] + self.v1 * self._D(u, r)[r]

    def to_face(self, tol: float | None = None, **kwargs: Any) -> Any:
        """One B-spline face; see :func:`ght_cad.cad.developable_faces.developable_face`."""
        from .cad.developable_faces import developable_face

        return developable_face(self, tol=tol, **kwargs)


# ----------------------------------------------------------------------------------------------
# 5.5 canal surfaces
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CanalReport:
    """Developability report of a canal surface (sampled Gaussian curvature).

    Attributes:
        k_max: ``max |K| ρ²`` over the samples (scale-free; ρ = mean sphere radius).
        k_rms: root mean square of ``K ρ²``.
        developable: True only for a cone or cylinder of revolution whose sampled ``|K| ρ²``
            stays below ``tol``.
        kind: ``"cylinder of revolution"``, ``"cone of revolution"`` or ``"not developable"``.
        tol: tolerance used on ``k_max``.
    """

    k_max: float
    k_rms: float
    developable: bool
    kind: str
    tol: float

    def __str__(self) -> str:
        return f"canal surface: {self.kind} (max |K| rho^2 = {self.k_max:.3e}, rms {self.k_rms:.3e})"


class CanalSurface:
    r"""Envelope of the spheres with centre ``C(t)`` and radius ``r(t)`` (spec 5.5).

    ``X(t, φ) = C - r ṙ/|C'|² C' + r sqrt(1 - ṙ²/|C'|²) (cos φ e1 + sin φ e2)`` where ``e1, e2``
    is an orthonormal frame normal to ``C'`` (``e1 = ref × T / |..|``, a fixed reference axis),
    ``φ = φ0 + v (φ1 - φ0)``. Not a ruled surface in general: it is developable only when it is a
    cone or a cylinder of revolution, which :meth:`developability` reports (it never calls another
    canal surface developable).

    Args:
        center: 3-D GHT curve ``C(t)``.
        radius: 1-D GHT curve ``r(t)`` (positive), or a positive number (pipe surface).
        phi_range: angle range in radians, default the full circle.

    Raises:
        DegenerateGeometryError: ``r <= 0``, ``|r'| >= |C'|`` (no real envelope), ``C' = 0``.
    """

    def __init__(self, center: GHTCurve, radius: Any, *, phi_range: tuple[float, float] = (0.0, 2 * math.pi), samples: int = 257) -> None:
        self.center = _check_3d_curve(center, "center")
        if isinstance(radius, GHTCurve):
            if radius.dim != 1:
                raise GHTError(f"radius must be a 1-D GHT curve; got dimension {radius.dim}")
            self.radius = radius
        else:
            try:
                r = float(radius)
            except (TypeError, ValueError):
                raise GHTError(f"radius={radius!r} must be a 1-D GHTCurve or a positive number") from None
            self.radius = GHTCurve([[r]] * 3)
        try:
            self.phi_range = (float(phi_range[0]), float(phi_range[1]))
        except (TypeError, ValueError, IndexError):
            raise GHTError(f"phi_range={phi_range!r} must be a pair of angles (phi0, phi1) in radians") from None
        if not (all(math.isfinite(x) for x in self.phi_range) and self.phi_range[0] != self.phi_range[1]):
            raise GHTError(
                f"phi_range={self.phi_range!r} is not allowed; it must be two finite, different angles (radians)"
            )
        u = np.linspace(0.0, 1.0, samples)
        rv = self.radius.evaluate(u)[:, 0]
        if not np.all(rv > 0):
            i = int(np.argmin(rv))
            raise DegenerateGeometryError(f"radius r(t)={rv[i]:.6g} at t={u[i]:.6g}; sphere radii must be > 0")
        c1 = self.center.derivative(u, 1)
        sp = np.linalg.norm(c1, axis=1)
        r1 = self.radius.derivative(u, 1)[:, 0]
        if not np.all(np.abs(r1) < sp):
            i = int(np.argmax(np.abs(r1) - sp))
            raise DegenerateGeometryError(
                f"at t={u[i]:.6g} |r'|={abs(r1[i]):.6g} >= |C'|={sp[i]:.6g}: the spheres are nested and "
                "have no real envelope; the radius must change slower than the centre moves"
            )
        T = c1 / sp[:, None]
        axes = np.eye(3)
        self._ref = axes[int(np.argmin(np.abs(T @ axes.T).max(axis=0)))]
        if not np.all(np.linalg.norm(np.cross(self._ref, T), axis=1) > 1e-6):
            raise DegenerateGeometryError("the centre curve turns through every coordinate axis; no fixed frame reference found")

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        """Points ``X(t, φ(v))``; u, v broadcast to a common 1-D shape."""
        uu, us = as_parameter_array(u, "u")
        vv, vs = as_parameter_array(v, "v")
        uu, vv = np.broadcast_arrays(uu, vv)
        out = self._point(uu, vv)
        return out[0] if (us and vs) else out

    def _point(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        C = self.center.evaluate(u)
        c1 = self.center.derivative(u, 1)
        r = self.radius.evaluate(u)[:, 0]
        r1 = self.radius.derivative(u, 1)[:, 0]
        s2 = np.sum(c1 * c1, axis=1)
        T = c1 / np.sqrt(s2)[:, None]
        e1 = np.cross(self._ref, T)
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
        e2 = np.cross(T, e1)
        phi = self.phi_range[0] + v * (self.phi_range[1] - self.phi_range[0])
        rho = r * np.sqrt(1.0 - r1**2 / s2)
        return C - (r * r1 / s2)[:, None] * c1 + rho[:, None] * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2)

    def gaussian_curvature(self, u: Any, v: Any, h: float = 1e-3) -> np.ndarray:
        r"""Gaussian curvature ``K = (LN - M²)/(EG - F²)`` from 4th-order central differences."""
        uu, _ = as_parameter_array(u, "u")
        vv, _ = as_parameter_array(v, "v")
        uu, vv = np.broadcast_arrays(uu, vv)
        # keep the stencil inside [0, 1] in u (v is periodic-safe: the formula extends smoothly)
        uc = np.clip(uu, 2 * h, 1 - 2 * h)

        def X(du: float, dv: float) -> np.ndarray:
            return self._point(uc + du * h, vv + dv * h)

        w = {-2: 1 / 12, -1: -2 / 3, 1: 2 / 3, 2: -1 / 12}
        w2 = {-2: -1 / 12, -1: 4 / 3, 0: -5 / 2, 1: 4 / 3, 2: -1 / 12}
        Xu = sum(c * X(k, 0) for k, c in w.items()) / h
        Xv = sum(c * X(0, k) for k, c in w.items()) / h
        Xuu = sum(c * X(k, 0) for k, c in w2.items()) / h**2
        Xvv = sum(c * X(0, k) for k, c in w2.items()) / h**2
        Xuv = sum(ci * cj * X(i, j) for i, ci in w.items() for j, cj in w.items()) / h**2
        n = np.cross(Xu, Xv)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        E, F, G = (np.sum(a * b, axis=1) for a, b in ((Xu, Xu), (Xu, Xv), (Xv, Xv)))
        L, M, N = (np.sum(a * n, axis=1) for a in (Xuu, Xuv, Xvv))
        return (L * N - M * M) / (E * G - F * F)

    def kind(self, tol: float = 1e-9, samples: int = 129) -> str:
        """``"cylinder of revolution"``, ``"cone of revolution"`` or ``"not developable"``.

        Geometric test on ``samples`` parameters: the centres ``C(t)`` lie on one line (distance
        ``<= tol L``, L the centre curve's extent) and the radius is an affine function of the
        position ``s = (C - C(0))·d`` along it, ``r = α + β s`` (residual ``<= tol max(L, r)``); then
        the spheres envelope a cone of revolution (``β ≠ 0``) or a cylinder (``β = 0``). Works for
        any parametrizations of the two curves.
        """
        t = np.linspace(0.0, 1.0, samples)
        C = self.center.evaluate(t)
        R = self.radius.evaluate(t)[:, 0]
        ext = C.max(axis=0) - C.min(axis=0)
        L = float(np.linalg.norm(ext))
        if L == 0.0:
            return "not developable"
        i = int(np.argmax(np.linalg.norm(C - C[0], axis=1)))
        d = (C[i] - C[0]) / np.linalg.norm(C[i] - C[0])
        off = C - C[0]
        sp = off @ d
        if np.max(np.linalg.norm(off - np.outer(sp, d), axis=1)) > tol * L:
            return "not developable"
        scale = max(L, float(np.abs(R).max()))
        A = np.column_stack([np.ones_like(sp), sp])
        coef, *_ = np.linalg.lstsq(A, R, rcond=None)
        if np.max(np.abs(A @ coef - R)) > tol * scale:
            return "not developable"
        return "cylinder of revolution" if abs(coef[1]) * L <= tol * scale else "cone of revolution"

    def developability(self, nu: int = 41, nv: int = 24, tol: float = 1e-6) -> CanalReport:
        """Sampled scale-free Gaussian curvature ``K ρ²`` and the structural kind (see :meth:`kind`)."""
        u = np.linspace(0.02, 0.98, nu)
        v = np.linspace(0.0, 1.0, nv, endpoint=False)
        U, V = (x.ravel() for x in np.meshgrid(u, v, indexing="ij"))
        K = self.gaussian_curvature(U, V)
        rho = float(np.mean(self.radius.evaluate(u)[:, 0]))
        Ks = K * rho**2
        kmax = float(np.max(np.abs(Ks)))
        krms = float(np.sqrt(np.mean(Ks**2)))
        kind = self.kind()
        dev = kind != "not developable" and kmax <= tol
        return CanalReport(kmax, krms, dev, kind if dev else "not developable", tol)


# ----------------------------------------------------------------------------------------------
# 5.6 joins and composites
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DevelopableJointReport:
    r"""Order achieved at the joint ``A(1) → B(0)`` of two enveloping developables.

    Attributes:
        order: projective contact order of the dual curves (-1..3): 0 common tangent plane,
            1 also common ruling, 2 second-order contact (implies a common edge-of-regression
            point and equal dual curvature), 3 third-order contact. Intrinsic: independent of
            plane scales and of the parametrization.
        residuals: relative residuals of the order-0..3 conditions.
        plane_angle: angle (degrees) between the end tangent planes.
        ruling_distance: largest distance of A's end ruling endpoints from B's start ruling,
            relative to the size of the ruling segment.
        dual: :class:`ght_cad.continuity.JointReport` of the 4-D dual curves (affine G/C order), or
            None if the continuity module is unavailable.
        tol: tolerance.
    """

    order: int
    residuals: tuple[float, ...]
    plane_angle: float
    ruling_distance: float
    dual: Any
    tol: float

    def satisfies(self, continuity: Any) -> bool:
        """True if the geometric order is at least that of ``"G1"``, ``"G2"``, ``"G3"``."""
        s = str(continuity).upper().strip()
        if len(s) != 2 or s[0] != "G" or s[1] not in "0123":
            raise GHTError(f"continuity={continuity!r} is not one of 'G0', 'G1', 'G2', 'G3'")
        return self.order >= int(s[1])

    def __str__(self) -> str:
        return (
            f"developable joint G{self.order} (plane angle {self.plane_angle:.3e} deg, ruling distance "
            f"{self.ruling_distance:.3e}, residuals {', '.join(f'{r:.2e}' for r in self.residuals)})"
        )


def _dual_end_derivs(surf: EnvelopeDevelopable, end: int) -> list[np.ndarray]:
    """``U^(r)`` at the surface end (u = end) with respect to u, r = 0..3."""
    return [x[0] for x in surf._U(np.array([float(end)]), 3)]


def measure_developable_joint(a: EnvelopeDevelopable, b: EnvelopeDevelopable, *, tol: float = 1e-9) -> DevelopableJointReport:
    r"""Measure the geometric order of the joint ``a(u=1) → b(u=0)`` from the two surfaces alone.

    Projective contact of the dual curves ``U`` (of a, at its end) and ``V`` (of b, at its start):
    order r holds when ``V(s) = λ(s) U(φ(s))`` to r-th order for some scale ``λ`` and
    reparametrization ``φ`` with ``φ' > 0``. Expanding,

    * r=0: ``V = λ0 U``;
    * r=1: ``V' = λ1 U + λ0 φ1 U'`` (common ruling ``U ∩ U'``);
    * r=2: ``V'' = λ2 U + (2λ1φ1 + λ0φ2) U' + λ0φ1² U''`` (implies a common edge-of-regression
      point ``U ∩ U' ∩ U''``);
    * r=3: ``V''' = λ3 U + (3λ2φ1 + 3λ1φ2 + λ0φ3) U' + (3λ1φ1² + 3λ0φ1φ2) U'' + λ0φ1³ U'''``.

    The unknowns are fitted order by order by least squares (new unknowns at order r: ``λ_r`` and
    ``φ_r``, the rest being known), and the condition holds when the relative residual
    ``|residual| / max(|V^(r)|, Σ|terms|) <= tol``. This is independent of how the joint was built.
    A 4-D affine G^r join (``λ ≡ 1``, :func:`ght_cad.continuity.join`) measures at least r.

    Args:
        a, b: enveloping developables (a's end meets b's start).
        tol: relative tolerance.

    Returns:
        :class:`DevelopableJointReport`.
    """
    if not isinstance(a, EnvelopeDevelopable) or not isinstance(b, EnvelopeDevelopable):
        raise GHTError(f"measure_developable_joint needs two EnvelopeDevelopable surfaces, got {type(a).__name__} and {type(b).__name__}")
    tol = float(tol)
    if not (math.isfinite(tol) and tol > 0):
        raise GHTError(f"tol={tol!r} must be a positive finite number")
    U = _dual_end_derivs(a, 1)
    V = _dual_end_derivs(b, 0)

    def fit(target: np.ndarray, known: list[np.ndarray]) -> tuple[np.ndarray, float]:
        """Solve ``target - Σ known = x0 U + x1 U'`` least squares; return x and relative residual."""
        rhs = target - sum(known) if known else target.copy()
        M = np.column_stack([U[0], U[1]])
        x, *_ = np.linalg.lstsq(M, rhs, rcond=None)
        res = float(np.linalg.norm(rhs - M @ x))
        scale = max(float(np.linalg.norm(target)), sum(float(np.linalg.norm(k)) for k in known),
                    float(np.linalg.norm(M @ x)), 1e-300)
        return x, res / scale

    res: list[float] = []
    # order 0: V = λ0 U
    lam0 = float(V[0] @ U[0]) / float(U[0] @ U[0])
    res.append(float(np.linalg.norm(V[0] - lam0 * U[0])) / max(float(np.linalg.norm(V[0])), 1e-300))
    # order 1: V' = λ1 U + (λ0 φ1) U'
    x, r1 = fit(V[1], [])
    lam1, phi1 = float(x[0]), float(x[1]) / lam0
    res.append(r1 if phi1 > 0 else math.inf)
    # order 2: V'' - λ0 φ1² U'' = λ2 U + (2λ1φ1 + λ0φ2) U'
    x, r2 = fit(V[2], [lam0 * phi1**2 * U[2]])
    lam2 = float(x[0])
    phi2 = (float(x[1]) - 2 * lam1 * phi1) / lam0
    res.append(r2)
    # order 3: V''' - (3λ1φ1² + 3λ0φ1φ2) U'' - λ0 φ1³ U''' = λ3 U + (...) U'
    _, r3 = fit(V[3], [(3 * lam1 * phi1**2 + 3 * lam0 * phi1 * phi2) * U[2], lam0 * phi1**3 * U[3]])
    res.append(r3)
    order = -1
    for r in range(4):
        if res[r] <= tol:
            order = r
        else:
            break
    nA = U[0][1:] / np.linalg.norm(U[0][1:])
    nB = V[0][1:] / np.linalg.norm(V[0][1:])
    angle = float(np.degrees(np.arctan2(np.linalg.norm(np.cross(nA, nB)), abs(float(nA @ nB)))))
    pa, pb = a.a(_ONE)[0], a.b(_ONE)[0]
    seg = max(float(np.linalg.norm(pb - pa)), 1e-300)
    dist = 0.0
    for p in (pa, pb):
        for P in (V[0], V[1]):
            dist = max(dist, abs(float(P[0] + P[1:] @ p)) / float(np.linalg.norm(P[1:])) / seg)
    dual = None
    try:
        from .continuity import measure_continuity

        dual = measure_continuity(a.dual_curve, b.dual_curve, tol=tol) if a.t_range == (0.0, 1.0) == b.t_range else None
    except ImportError:  # pragma: no cover - the continuity module ships with the package
        dual = None
    return DevelopableJointReport(order, tuple(res), angle, dist, dual, tol)


def join_developable(
    first: EnvelopeDevelopable,
    continuity: str,
    planes: Any,
    boundary_planes: Any = None,
    mu: float | None = None,
    nu: float | None = None,
    gamma: float | None = None,
    *,
    k: float = 1.0,
    beta2: float = 0.0,
    beta3: float = 0.0,
) -> EnvelopeDevelopable:
    r"""Second enveloping developable joined to ``first`` with G1, G2 or G3 through the dual curves.

    Spec 5.6: section 4 applied to the 4-D dual curves, ``V(0) = U(1)``, G1 ``V'(0) = k U'(1)``,
    G2 ``V''(0) = k² U''(1) + β2 U'(1)``, G3 ``V''' = k³ U''' + 3kβ2 U'' + β3 U'`` (all at the joint),
    solved for ``V_0..V_r`` by :func:`ght_cad.continuity.join`; the other control planes of
    ``planes`` are kept. G1 means a common tangent plane and a common ruling at the joint.

    Args:
        first: the first surface (untrimmed, t_range (0, 1)).
        continuity: ``"G1"``, ``"G2"`` or ``"G3"`` (``"C1".."C3"`` accepted too).
        planes: (n+1, 4) control planes of the second surface; rows 0..r are replaced.
        boundary_planes: ``(E_a, E_b)`` of the second surface; default: those of ``first``
            (then the two strips share their joint ruling segment, as a shell needs).
        mu, nu, gamma: shape parameters of the second surface (default: those of ``first``).
        k, beta2, beta3: G parameters (k > 0).

    Raises:
        SingularJoinError: G0 requested (the surfaces would not share a ruling), k <= 0, or an
            order that the second surface's degree / shape parameters cannot take.
        GHTError: a trimmed ``first``; plus every error of :func:`developable_from_planes`.
    """
    from .continuity import Continuity, join

    if not isinstance(first, EnvelopeDevelopable):
        raise GHTError(f"first must be an EnvelopeDevelopable, got {type(first).__name__}")
    if first.t_range != (0.0, 1.0):
        raise GHTError(f"first is trimmed to t_range={first.t_range}; join untrimmed surfaces (t_range (0, 1))")
    cont = Continuity.parse(continuity)
    if cont.order < 1:
        raise SingularJoinError(
            f"continuity={cont.value} joins only the tangent planes; the surfaces would not share a ruling. "
            "Developable joins need G1, G2 or G3"
        )
    arr = np.array(planes, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise GHTError(f"planes must have shape (count, 4); got shape {arr.shape}")
    check_finite_array("planes", arr)
    c = first.dual_curve
    mu = c.mu if mu is None else mu
    nu = c.nu if nu is None else nu
    gamma = c.gamma if gamma is None else gamma
    kw = {"k": k, "beta2": beta2, "beta3": beta3} if cont.geometric else {}
    joined = join(c, cont, arr, mu=mu, nu=nu, gamma=gamma, **kw)
    bp = first.boundary_planes if boundary_planes is None else boundary_planes
    return EnvelopeDevelopable(joined, bp)


class CompositeDevelopable:
    r"""A chain of developable strips whose consecutive joint rulings coincide.

    Args:
        segments: ruled surfaces (usually :class:`EnvelopeDevelopable`), segment i's end ruling
            ``a_i(1) b_i(1)`` equal to segment i+1's start ruling ``a_{i+1}(0) b_{i+1}(0)``.
        tol: relative tolerance on the joint ruling endpoints (relative to the ruling length).

    Raises:
        DegenerateGeometryError: a joint whose ruling segments differ (naming the joint and gap).
    """

    def __init__(self, segments: Sequence[RuledSurface], *, tol: float = 1e-9) -> None:
        segs = list(segments)
        if len(segs) < 1:
            raise GHTError("a composite developable needs at least one segment")
        for i, s in enumerate(segs):
            if not isinstance(s, RuledSurface):
                raise GHTError(f"segments[{i}] is a {type(s).__name__}, not a RuledSurface")
        for i in range(len(segs) - 1):
            A, B = segs[i], segs[i + 1]
            pa, pb = A.a(_ONE)[0], A.b(_ONE)[0]
            qa, qb = B.a(_ZERO)[0], B.b(_ZERO)[0]
            L = max(float(np.linalg.norm(pb - pa)), 1e-300)
            gap = max(float(np.linalg.norm(pa - qa)), float(np.linalg.norm(pb - qb))) / L
            if gap > tol:
                raise DegenerateGeometryError(
                    f"segments {i} and {i+1} do not share their joint ruling: end points {_fmt(pa)}-{_fmt(pb)} "
                    f"vs start points {_fmt(qa)}-{_fmt(qb)} (relative gap {gap:.3g} > tol={tol:g}); "
                    "join them with join_developable (G1 or higher, same boundary planes)"
                )
        self.segments = segs
        self.tol = tol

    def __len__(self) -> int:
        return len(self.segments)

    def developability(self) -> list[Developability]:
        """Developability degree of every segment."""
        return [s.developability() for s in self.segments]

    def joints(self, tol: float = 1e-9) -> list[DevelopableJointReport]:
        """:func:`measure_developable_joint` at every joint (enveloping segments only)."""
        return [measure_developable_joint(self.segments[i], self.segments[i + 1], tol=tol) for i in range(len(self.segments) - 1)]

    def to_shell(self, tol: float | None = None, **kwargs: Any) -> Any:
        """A shell of one B-spline face per segment with shared joint edges; see
        :func:`ght_cad.cad.developable_faces.composite_shell`."""
        from .cad.developable_faces import composite_shell

        return composite_shell(self, tol=tol, **kwargs)
