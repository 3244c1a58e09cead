"""Problem 2: fairness (AL, En, CVEn; spec section 7) of dual curves, of 3-D GHT curves and of
interpolation curves, with the default dual and interpolation designs."""

from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from ...core._vec import cross as _cross
from ...core._quadrature import gauss_legendre
from ...curves.curve import GHTCurve
from ...core.errors import GHTError
from ...surfaces.ruled import RuledSurface
from .base import CurveParameterJets, FAIRNESS_MEASURES, PopulationBasis, Problem, SHAPE_NAMES, _split, population_basis


# --------------------------------------------------------------------------------------------
# problem 2: fairness (AL, En, CVEn)
# --------------------------------------------------------------------------------------------
def _weights(objective: Any) -> np.ndarray:
    """Weights (w_AL, w_En, w_CVEn) from a measure name or a mapping name -> weight."""
    if isinstance(objective, str):
        if objective not in FAIRNESS_MEASURES:
            raise GHTError(f"objective={objective!r} is unknown; use one of {FAIRNESS_MEASURES} or a dict of weights")
        return np.array([float(objective == m) for m in FAIRNESS_MEASURES])
    if isinstance(objective, Mapping):
        w = np.zeros(3)
        for k, v in objective.items():
            if k not in FAIRNESS_MEASURES:
                raise GHTError(f"objective weight key {k!r} is unknown; use {FAIRNESS_MEASURES}")
            v = float(v)
            if not (math.isfinite(v) and v >= 0):
                raise GHTError(f"objective weight {k}={v!r} is not allowed; weights must be finite and >= 0")
            w[FAIRNESS_MEASURES.index(k)] = v
        if not np.any(w > 0):
            raise GHTError(f"objective={dict(objective)!r} has no positive weight")
        return w
    raise GHTError(f"objective={objective!r} is not allowed; use 'AL', 'En', 'CVEn' or a dict of weights")


class FairnessProblem(Problem):
    r"""Shared fairness measures of one GHT curve ``X(t)`` (spec section 7).

    ``AL = ∫_0^1 |X'|``, ``En = ∫_0^1 |X''|²``, ``CVEn = ∫_0^1 |X'''|²`` (analytic derivatives,
    Gauss–Legendre); the objective is ``w1 AL + w2 En + w3 CVEn``. Parameters ``mu, nu, gamma``.
    """

    degree: int

    def _init_fairness(self, base: Sequence[float], objective: Any, free: Any, bounds: Any, nodes: int) -> None:
        if int(nodes) < 16:
            raise GHTError(f"nodes={nodes} is too few; use >= 16 Gauss–Legendre nodes")
        super().__init__(SHAPE_NAMES, base, free, bounds)
        self.weights = _weights(objective)
        self.objective = objective
        self.t, self.w = gauss_legendre(int(nodes))
        self._basis = PopulationBasis(self.t, self.degree)

    def control_points_for(self, F: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        """Control points per parameter row, (pop, m+1, dim) or (m+1, dim) if fixed."""
        raise NotImplementedError

    def measures(self, X: Any) -> np.ndarray:
        """``(AL, En, CVEn)`` for a population of free parameters, shape (pop, 3)."""
        return self.measures_full(self.full(X))

    def control_point_derivatives(self, F: np.ndarray, P: np.ndarray) -> np.ndarray | None:
        """``∂P/∂(μ, ν, γ)`` per row, shape (3, pop, m+1, dim); None for a fixed control polygon."""
        return None

    def measures_full(self, F: np.ndarray) -> np.ndarray:
        return self._measures(F, False)[0]

    def _measures(self, F: np.ndarray, grad: bool) -> tuple[np.ndarray, Any]:
        r"""``(AL, En, CVEn)`` (pop, 3) and, with ``grad``, their derivatives (pop, 3 params, 3 measures).

        ``∂AL = Σ_j w_j X^(1)·∂X^(1)/|X^(1)|``, ``∂En = 2 Σ_j w_j X^(2)·∂X^(2)``,
        ``∂CVEn = 2 Σ_j w_j X^(3)·∂X^(3)``, ``∂X^(r) = (∂b^(r)) P + b^(r) ∂P``.
        """
        mu, nu, ga = _split(F, 0)
        P = self.control_points_for(F)
        spec = "pnj,jd->pnd" if P.ndim == 2 else "pnj,pjd->pnd"
        out = np.empty((F.shape[0], 3))
        Bm = self._basis(mu, nu, ga, (1, 2, 3))
        dout = np.zeros((F.shape[0], 3, 3)) if grad else None
        if grad:
            dP = self.control_point_derivatives(F, P)
            if P.ndim == 2:  # fixed polygon: compact form, Bézier parts once per problem
                if getattr(self, "_pjets", None) is None:
                    self._pjets = CurveParameterJets(self.t, P, 3)
                dX = self._pjets(mu, nu, ga, (1, 2, 3))
            else:
                dBm = self._basis.parameter_derivatives(mu, nu, ga, (1, 2, 3))
        for r in (1, 2, 3):
            D = np.einsum(spec, Bm[r], P) if P.ndim == 3 else Bm[r] @ P
            sq = np.sum(D * D, axis=-1)
            out[:, r - 1] = (np.sqrt(sq) if r == 1 else sq) @ self.w
            if grad:
                dD = np.einsum("jpnk,pkd->jpnd", dBm[r], P) if P.ndim == 3 else dX[r]
                if dP is not None:
                    dD = dD + np.einsum("pnk,jpkd->jpnd", Bm[r], dP)
                dot = np.sum(D * dD, axis=-1)  # (3, pop, N)
                if r == 1:
                    with np.errstate(divide="ignore", invalid="ignore"):
                        dot = np.where(sq > 0, dot / np.sqrt(sq), 0.0)
                else:
                    dot = 2.0 * dot
                dout[:, :, r - 1] = (dot @ self.w).T
        out = np.where(np.isfinite(out), out, np.inf)
        if grad:
            dout[~np.all(np.isfinite(out), axis=1)] = 0.0
        return out, dout

    def evaluate_full(self, F: np.ndarray) -> np.ndarray:
        return self.measures_full(F) @ self.weights

    def value_and_grad_full(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``w·(AL, En, CVEn)`` and its exact gradient with respect to (mu, nu, gamma) (:meth:`_measures`)."""
        m, dm = self._measures(F, True)
        return m @ self.weights, dm @ self.weights

    def report(self, x: Any) -> dict[str, float]:
        """``AL``, ``En``, ``CVEn`` and the weighted objective at ``x``."""
        m = self.measures(np.asarray(x, dtype=float).reshape(1, -1))[0]
        return {"AL": float(m[0]), "En": float(m[1]), "CVEn": float(m[2]), "objective": float(m @ self.weights)}


class CurveFairnessProblem(FairnessProblem):
    """Fairness of a GHT curve with a fixed control polygon (any dimension).

    Args:
        curve: the :class:`GHTCurve` (its shape parameters are the base design).
        objective: ``"AL"``, ``"En"``, ``"CVEn"`` or weights ``{"AL": w1, "En": w2, "CVEn": w3}``.
        free: free names among ``mu, nu, gamma`` (default all).
        bounds: optional narrower bounds per name.
        nodes: Gauss–Legendre nodes.
    """

    label = "curve fairness"

    def __init__(self, curve: GHTCurve, objective: Any = "En", free: Sequence[str] | None = None,
                 bounds: Mapping[str, tuple[float, float]] | None = None, nodes: int = 64) -> None:
        if not isinstance(curve, GHTCurve) or curve.seed.name != "ght":
            raise GHTError(f"curve must be a GHTCurve with the 'ght' seed, got {curve!r}")
        self.curve = curve
        self.degree = curve.degree
        self._init_fairness(curve.shape_parameters, objective, free, bounds, nodes)

    def control_points_for(self, F: np.ndarray) -> np.ndarray:
        return self.curve.control_points

    def build(self, x: Any) -> GHTCurve:
        """The curve with shape parameters from ``x``."""
        p = self.parameters(x)
        return GHTCurve(self.curve.control_points, p["mu"], p["nu"], p["gamma"])


class InterpolationFairnessProblem(FairnessProblem):
    """Fairest GHT curve of degree ``k-1`` through ``k`` given points (any dimension).

    For each parameter set the control points solve ``Σ_i b_{i,m}(t_j) P_i = Q_j`` (k equations,
    k unknown points) at parameters ``t_j`` (default: chord length, ``t_0 = 0``, ``t_{k-1} = 1``).
    The curve passes through every point for all shape parameters; the shape parameters then
    choose the fairest interpolant (objective as in :class:`CurveFairnessProblem`).

    Raises:
        GHTError: fewer than 3 points, coincident consecutive points, parameters not strictly
            increasing from 0 to 1.
    """

    label = "interpolation fairness"

    def __init__(self, points: Any, parameters: Any = None, objective: Any = "En",
                 free: Sequence[str] | None = None, bounds: Mapping[str, tuple[float, float]] | None = None,
                 nodes: int = 64, mu: float = 0.0, nu: float = 0.0, gamma: float = 0.0) -> None:
        Q = np.asarray(points, dtype=float)
        if Q.ndim != 2 or Q.shape[0] < 3 or not np.all(np.isfinite(Q)):
            raise GHTError(f"points must be a finite (k, dim) array with k >= 3, got shape {Q.shape}")
        if parameters is None:
            d = np.linalg.norm(np.diff(Q, axis=0), axis=1)
            if np.any(d <= 0):
                raise GHTError(f"points {int(np.argmin(d))} and {int(np.argmin(d)) + 1} coincide; chord-length parameters need distinct neighbours")
            tj = np.concatenate([[0.0], np.cumsum(d)]) / np.sum(d)
        else:
            tj = np.asarray(parameters, dtype=float).reshape(-1)
            if tj.size != Q.shape[0] or tj[0] != 0.0 or tj[-1] != 1.0 or np.any(np.diff(tj) <= 0):
                raise GHTError(f"parameters={tj.tolist()} must increase strictly from 0 to 1, one per point")
        self.points, self.tj = Q, tj
        self.degree = Q.shape[0] - 1
        self._init_fairness((mu, nu, gamma), objective, free, bounds, nodes)

    def control_points_for(self, F: np.ndarray) -> np.ndarray:
        mu, nu, ga = _split(F, 0)
        M = population_basis(self.tj, self.degree, mu, nu, ga, 0)      # (pop, k, k)
        with np.errstate(all="ignore"):
            try:
                return np.linalg.solve(M, np.broadcast_to(self.points, (F.shape[0],) + self.points.shape))
            except np.linalg.LinAlgError:
                out = np.full((F.shape[0],) + self.points.shape, np.nan)
                for i in range(F.shape[0]):
                    try:
                        out[i] = np.linalg.solve(M[i], self.points)
                    except np.linalg.LinAlgError:
                        pass
                return out

    def control_point_derivatives(self, F: np.ndarray, P: np.ndarray) -> np.ndarray:
        r"""``∂P/∂θ = -M^{-1} (∂M/∂θ) P`` for ``M P = Q`` (``M_{ji} = b_{i,m}(t_j)``), shape (3, pop, k, dim)."""
        mu, nu, ga = _split(F, 0)
        dM = PopulationBasis(self.tj, self.degree).parameter_derivatives(mu, nu, ga, (0,))[0]  # (3, pop, k, k)
        M = population_basis(self.tj, self.degree, mu, nu, ga, 0)
        out = np.full((3,) + P.shape, np.nan)
        with np.errstate(all="ignore"):
            rhs = -(dM @ P)  # (3, pop, k, dim)
            try:
                return np.linalg.solve(M[None], rhs)
            except np.linalg.LinAlgError:  # some rows singular: those stay NaN
                for i in np.nonzero(np.all(np.isfinite(P), axis=(1, 2)))[0]:
                    try:
                        out[:, i] = np.linalg.solve(M[i][None], rhs[:, i])
                    except np.linalg.LinAlgError:
                        pass
        return out

    def build(self, x: Any) -> GHTCurve:
        """The interpolating curve for free parameters ``x``."""
        F = self.full(np.asarray(x, dtype=float).reshape(1, -1))
        p = self.parameters(x)
        return GHTCurve(self.control_points_for(F)[0], p["mu"], p["nu"], p["gamma"])


class EnvelopeStrip(RuledSurface):
    r"""Enveloping developable of a dual curve, cut by two boundary planes (spec section 5.2).

    ``a(t) = U ∩ U' ∩ E_a``, ``b(t) = U ∩ U' ∩ E_b`` as homogeneous meets ``X = meet(U, U', E)``;
    ``X' = meet(U, U'', E)`` (the term ``meet(U', U', E)`` vanishes), Cartesian derivative
    ``(X'_{1:3} X_0 - X_{1:3} X'_0) / X_0²``. A self-contained construction used to check that
    the optimized surfaces stay developable when :mod:`ght_cad.developables.envelope` is not available.
    """

    def __init__(self, dual: GHTCurve, boundary_planes: Any) -> None:
        E = np.asarray(boundary_planes, dtype=float)
        if E.shape != (2, 4) or not np.all(np.isfinite(E)):
            raise GHTError(f"boundary_planes must be two finite planes, shape (2, 4); got shape {E.shape}")
        self.dual, self.E = dual, E

    def _end(self, u: Any, derivative: int, E: np.ndarray) -> np.ndarray:
        from ...surfaces.planes import meet

        if derivative not in (0, 1):
            raise GHTError(f"derivative={derivative} is not available here; EnvelopeStrip gives orders 0 and 1")
        U, U1, U2 = (self.dual.derivative(u, r) for r in (0, 1, 2))
        X = meet(U, U1, E)
        if derivative == 0:
            return X[:, 1:] / X[:, :1]
        X1 = meet(U, U2, E)
        return (X1[:, 1:] * X[:, :1] - X[:, 1:] * X1[:, :1]) / X[:, :1] ** 2

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._end(u, derivative, self.E[0])

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._end(u, derivative, self.E[1])


class DualCurveFairnessProblem(FairnessProblem):
    r"""Problem 2: fairness of the dual curve of an enveloping developable (spec sections 5.2, 7).

    The control planes are normalized to unit normals (``U_i / |(u1, u2, u3)|``), the dual curve
    is ``U(t) = Σ b_{i,m}(t; μ,ν,γ) U_i`` (4-D), and ``AL``, ``En``, ``CVEn`` are measured on it.
    The envelope is developable for every parameter set; :meth:`build` returns the surface cut by
    ``boundary_planes`` (``ght_cad.developable_from_planes`` when available, else
    :class:`EnvelopeStrip`).

    Args:
        planes: control planes, shape (m+1, 4), m >= 2.
        boundary_planes: two planes ``E_a, E_b`` (needed only by :meth:`build`).
        objective: ``"AL"``, ``"En"``, ``"CVEn"`` or a dict of weights.
        free, bounds, nodes: as in :class:`CurveFairnessProblem`.
        mu, nu, gamma: base design.
        check_surface: with boundary planes, build (and so check) the surface of every candidate
            with a finite objective and give ``+inf`` to those that degenerate (stationary dual
            curve, e.g. ``mu = nu = gamma = -1`` with three planes, or nearly so: the tangent plane
            turning at an end slower than 1e-2 of its mean rate, see :meth:`_end_speeds_ok`; an edge
            of regression inside the strip; a boundary plane containing a ruling), so the optimum
            can always be built.
            Costs one surface construction per candidate (about 10 ms).
    """

    label = "dual-curve fairness"

    def __init__(self, planes: Any, boundary_planes: Any = None, objective: Any = "En",
                 free: Sequence[str] | None = None, bounds: Mapping[str, tuple[float, float]] | None = None,
                 nodes: int = 64, mu: float = 0.0, nu: float = 0.0, gamma: float = 0.0,
                 check_surface: bool = True) -> None:
        from ...surfaces.planes import check_control_planes, normalize_planes

        U = check_control_planes(planes)
        self.raw_planes = U
        self.planes = normalize_planes(U)
        self.boundary_planes = None if boundary_planes is None else np.asarray(boundary_planes, dtype=float)
        self.check_surface = bool(check_surface)
        self.degree = self.planes.shape[0] - 1
        self._init_fairness((mu, nu, gamma), objective, free, bounds, nodes)

    def evaluate_full(self, F: np.ndarray) -> np.ndarray:
        """Weighted fairness; ``+inf`` where the candidate's surface cannot be built (see
        ``check_surface``)."""
        val = super().evaluate_full(F)
        return np.where(self._admissible_full(F, np.isfinite(val)), val, np.inf)

    def value_and_grad_full(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Weighted fairness and its exact gradient; ``+inf`` (gradient 0) where the surface cannot be built."""
        val, G = super().value_and_grad_full(F)
        ok = self._admissible_full(F, np.isfinite(val))
        G[~ok] = 0.0
        return np.where(ok, val, np.inf), G

    def admissible(self, X: Any) -> np.ndarray:
        """Boolean mask over the rows of ``X`` (free parameters): True where the surface can be
        built (always True without boundary planes or with ``check_surface=False``)."""
        F = self.full(X)
        return self._admissible_full(F, np.ones(F.shape[0], dtype=bool))

    def _admissible_full(self, F: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Construction check of the rows selected by ``rows`` (others are returned False)."""
        ok = np.array(rows, dtype=bool)
        if self.boundary_planes is None or not self.check_surface:
            return ok
        ok &= self._end_speeds_ok(F)
        for i in np.nonzero(ok)[0]:
            try:
                with np.errstate(all="ignore"):
                    self._surface(*F[i, :3])
            except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
                ok[i] = False
        return ok

    #: An end where the tangent plane turns slower than this fraction of its mean turning rate
    #: counts as stationary (see :meth:`_end_speeds_ok`).
    END_SPEED_FRACTION = 1e-2

    def _end_speeds_ok(self, F: np.ndarray) -> np.ndarray:
        r"""``ω(0), ω(1) >= 1e-2 ∫_0^1 ω dt`` per row, with ``ω = |n × n'| / |n|²`` the turning rate
        of the unit normal of the plane ``U(t) = (u0, n)`` (``n = (u1, u2, u3)``).

        Not a rule of the spec: a guard for the CAD fit. At ``μ = γ = -1`` (``ν = γ = -1``) the end
        term ``f0'(0)`` (``f2'(1)``) vanishes; with three planes the dual curve is then stationary
        there (``U' = 0``, no ruling ``U ∩ U'``), and near that corner the rulings turn by O(1)
        within a tiny parameter step: the surface still builds but no B-rep fit reaches tolerance,
        so such candidates are refused like the stationary ones. A plane that moves without turning
        (``n' = 0``, ``U' ≠ 0``) has its ruling at infinity and is refused too. ``ω`` is invariant to
        rigid motions and scaling of the design and to the planes' scale (an earlier test on the
        4-vector speed ``|U'|``, which mixes the length ``u0`` with the unitless normal, moved its
        threshold by 2x between a design in m and the same design in mm or far from the origin);
        the fraction 1e-2 is empirical (it refuses ``μ = γ = -1 + ε`` for ``ε < 0.012`` on the
        three-plane test design).
        """
        mu, nu, ga = _split(F, 0)
        pb = getattr(self, "_end_basis", None)
        if pb is None:
            pb = self._end_basis = PopulationBasis(np.concatenate([[0.0, 1.0], self.t]), self.degree)
        b = pb(mu, nu, ga, (0, 1))
        n, n1 = b[0] @ self.planes[:, 1:], b[1] @ self.planes[:, 1:]  # (pop, 2 + N, 3)
        with np.errstate(divide="ignore", invalid="ignore"):
            om = np.linalg.norm(_cross(n, n1), axis=-1) / np.sum(n * n, axis=-1)
            return np.minimum(om[:, 0], om[:, 1]) >= self.END_SPEED_FRACTION * (om[:, 2:] @ self.w)

    def control_points_for(self, F: np.ndarray) -> np.ndarray:
        return self.planes

    def dual_curve(self, x: Any) -> GHTCurve:
        """The 4-D dual curve of the normalized planes for free parameters ``x``."""
        p = self.parameters(x)
        return GHTCurve(self.planes, p["mu"], p["nu"], p["gamma"])

    def build(self, x: Any) -> RuledSurface:
        """The enveloping developable between the boundary planes for free parameters ``x``.

        Raises:
            GHTError: no boundary planes were given.
        """
        if self.boundary_planes is None:
            raise GHTError("boundary_planes were not given; the surface needs two cutting planes E_a, E_b")
        p = self.parameters(x)
        return self._surface(p["mu"], p["nu"], p["gamma"])

    def _surface(self, mu: float, nu: float, gamma: float) -> RuledSurface:
        """The enveloping developable for one full parameter set (checked on construction)."""
        try:
            from ...developables.envelope import developable_from_planes  # written by another engineer
        except ImportError:
            return EnvelopeStrip(GHTCurve(self.planes, mu, nu, gamma), self.boundary_planes)
        return developable_from_planes(self.planes, self.boundary_planes, float(mu), float(nu), float(gamma))

    def report(self, x: Any) -> dict[str, float]:
        """AL, En, CVEn, the objective and, with boundary planes, ``θ_max`` and the residual."""
        out = super().report(x)
        if self.boundary_planes is not None:
            d = self.build(x).developability()
            out["theta_max"] = float(d.theta_max)
            out["residual_max"] = float(getattr(d, "residual_max", np.nan))
        return out

def default_dual_problem(objective: Any = "En", **kw: Any) -> DualCurveFairnessProblem:
    """Four control planes of a tilted, cylinder-like sheet, cut by ``z = 0`` and ``z = 1``.

    Plane i has normal ``(cos φ_i, sin φ_i, k_i)`` and passes through ``p_i``; its edge of
    regression stays far outside the strip for every parameter set in ``[-1, 1]^3``.
    """
    phi = np.radians([0.0, 35.0, 70.0, 100.0])
    normals = np.column_stack([np.cos(phi), np.sin(phi), [0.05, 0.12, 0.08, 0.1]])
    through = np.array([[1.0, 0.0, 0.0], [1.1, 0.5, 0.0], [0.4, 1.2, 0.0], [0.0, 1.3, 0.0]])
    planes = np.column_stack([-np.sum(normals * through, axis=1), normals])
    boundary = np.array([[0.0, 0.0, 0.0, 1.0], [-1.0, 0.0, 0.0, 1.0]])
    return DualCurveFairnessProblem(planes, boundary, objective=objective, **kw)


def default_interpolation_problem(objective: Any = "En", **kw: Any) -> InterpolationFairnessProblem:
    """Five points of a 3-D space curve (a helix-like arc)."""
    pts = [[0.0, 0.0, 0.0], [1.0, 0.8, 0.3], [2.0, 1.0, 0.9], [3.0, 0.4, 1.2], [3.6, -0.5, 1.0]]
    return InterpolationFairnessProblem(pts, objective=objective, **kw)

