r"""Developable surfaces from GHT curves (spec section 5): planes (duality), spines, geodesics.

* :class:`EnvelopeDevelopable` (5.2): the envelope of the one-parameter family of planes
  ``U(t) = Σ b_{i,m}(t) U_i`` (the *dual curve*, a 4-D :class:`~ght_cad.curves.curve.GHTCurve`).
  Ruling ``U ∩ U'``, edge of regression ``U ∩ U' ∩ U''``, boundary curves
  ``a(t) = U ∩ U' ∩ E_a`` and ``b(t) = U ∩ U' ∩ E_b`` (pairing kept), surface
  ``X(t, v) = (1-v) a(t) + v b(t)``. Derivatives of ``a, b`` are analytic: the meet
  (:func:`ght_cad.surfaces.planes.meet`) is trilinear, so with ``X = meet(U, U', E)``
  ``X' = meet(U, U'', E)``, ``X'' = meet(U', U'', E) + meet(U, U''', E)`` and the Cartesian point
  ``x = (X1, X2, X3)/X0`` follows by the quotient rule.
* :class:`TangentDevelopable` (5.3): ``X(t, v) = C(t) + v T(t)``, trimmed to ``v ∈ [v0, v1]`` not
  containing 0 (C is the edge of regression).
* :class:`RectifyingDevelopable` (5.4): ``X(t, v) = C(t) + v D(t)``,
  ``D = (τT + κB)/sqrt(κ² + τ²)``; C is a geodesic of it.
* :class:`CanalSurface` (5.5): envelope of spheres ``(C(t), r(t))``; developable only as a cone or
  cylinder of revolution, otherwise only its (sampled Gaussian-curvature) report is given.
* Joins (5.6): :func:`join_developable` applies :func:`ght_cad.curves.continuity.join` to the 4-D dual
  curves; :func:`measure_developable_joint` measures the achieved order independently (projective
  contact of the dual curves, i.e. common tangent plane, ruling, edge-of-regression point ...);
  :class:`CompositeDevelopable` chains segments that share their joint rulings.

All surfaces are parametrized on ``(u, v) ∈ [0, 1]²`` (``u`` is the surface parameter; with a
``t_range`` the dual-curve parameter is ``t = t0 + u (t1 - t0)``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..core._validate import as_parameter_array, check_finite_array, check_unit_interval
from ..curves.basis import evaluate_derivatives
from ..curves.curve import GHTCurve
from ..core.errors import DegenerateGeometryError, EdgeOfRegressionError, GHTError, SingularJoinError
from ..surfaces.planes import PARALLEL_TOL, as_plane, check_control_planes, meet, meet_matrix, normalize_planes, plucker
from ..surfaces.ruled import Developability, RuledSurface
# Moved to ght_cad.developables (issue 27); every name stays importable from here.
from .canal import (CanalReport, CanalSurface)  # noqa: F401
from .checks import (_check_3d_curve, _check_strip_regular, _check_v_range)  # noqa: F401
from .fit import (_bspline_theta, _check_fit_args, _RuledInterval, _size, _strip_fit, developable_bspline,
                               ruled_pieces, RuledPiece)  # noqa: F401
from .jets import (_check_derivative, _check_range, _cross, _dot, _fmt, _jcartesian, _Jet, _JET_CACHE_MAX,
                                _JET_CACHE_SIZE, _jpow, _jprod, _junit, _mul, _ONE, _sign_change_roots, _ZERO,
                                curve_derivatives)  # noqa: F401

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
        (:func:`ght_cad.curves.basis.evaluate_derivatives`). The last few jets of up to
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
        from ..core._kernel import adapter

        return adapter("developable_face")(self, tol=tol, **kwargs)

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
        from ..core._kernel import adapter

        return adapter("developable_face")(self, tol=tol, **kwargs)


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
        from ..core._kernel import adapter

        return adapter("developable_face")(self, tol=tol, **kwargs)


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
        dual: :class:`ght_cad.curves.continuity.JointReport` of the 4-D dual curves (affine G/C order), or
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
    A 4-D affine G^r join (``λ ≡ 1``, :func:`ght_cad.curves.continuity.join`) measures at least r.

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
        from ..curves.continuity import measure_continuity

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
    solved for ``V_0..V_r`` by :func:`ght_cad.curves.continuity.join`; the other control planes of
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
    from ..curves.continuity import Continuity, join

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
        from ..core._kernel import adapter

        return adapter("composite_shell")(self, tol=tol, **kwargs)
