r"""Ruled surfaces and their developability degree (spec section 5).

A ruled surface is ``X(u, v) = a(u) + v (b(u) - a(u))``, u, v ∈ [0, 1], with directrix ``a`` and
ruling ``g = b - a``. It is developable iff ``det(a'(u), g(u), g'(u)) = 0`` for all u; then the
tangent plane is constant along each ruling and it unrolls with no stretch.

Every surface class of the package (enveloping, spine, geodesic, curve-pair strips) derives from
:class:`RuledSurface` and only implements :meth:`RuledSurface.a` and :meth:`RuledSurface.b` with
analytic derivatives; measures, sampling and conversion are shared.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..core._cache import readonly_cache
from ..core._validate import as_parameter_array
from ..core._vec import cross as _cross
from ..core._vec import dot as _dot
from ..core._vec import norm as _norm
from ..curves.curve import GHTCurve, gauss_legendre
from ..core.errors import DegenerateGeometryError, GHTError

__all__ = [
    "Developability",
    "RuledSurface",
    "CurvePairRuledSurface",
    "FunctionRuledSurface",
    "developability_from_jets",
    "regression_v",
]


@dataclass(frozen=True)
class Developability:
    r"""Developability degree of a ruled surface (spec section 5).

    Attributes:
        theta_max: max over u of ``θ(u) = angle(n_a, n_b)`` in degrees.
        theta_rms: ``sqrt(∫ θ(u)^2 du)`` in degrees.
        dd: degree of developability ``∫ cos θ(u) du`` (1 is exactly developable).
        R: smooth objective ``∫_0^1 (1 - n_a · n_b) du`` (Gauss–Legendre).
        residual_max: ``max |det(a', g, g')| / (|a'| |g| |g'|)`` (scale-free residual) over the parameters
            where both normals are defined (θ not NaN).
    """

    theta_max: float
    theta_rms: float
    dd: float
    R: float
    residual_max: float

    def as_dict(self) -> dict[str, float]:
        """The measures as a plain dict of floats (for JSON reports)."""
        return {k: float(getattr(self, k)) for k in ("theta_max", "theta_rms", "dd", "R", "residual_max")}

    def __str__(self) -> str:
        return (
            f"theta_max={self.theta_max:.3e} deg, theta_rms={self.theta_rms:.3e} deg, "
            f"DD={self.dd:.12f}, R={self.R:.3e}"
        )


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore"):
        return v / n


#: relative size of ``|a' × g|`` (against ``|a'| |g|``) below which the normal at that end of the
#: ruling is undefined (a singular point of the boundary curve, e.g. a' = 0 at an end)
SINGULAR_NORMAL_TOL = 1e-10


@readonly_cache(maxsize=8)
def _theta_parameters(nodes: int, samples: int) -> np.ndarray:
    """The developability's parameters: the ``nodes`` Gauss–Legendre nodes on [0, 1], then
    ``samples`` uniform ones (ends included); made once per pair (read-only)."""
    t, _ = gauss_legendre(nodes)
    return np.concatenate([t, np.linspace(0.0, 1.0, samples)])


def _theta(a1: np.ndarray, b1: np.ndarray, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(θ in degrees, n_a·n_b) with ``n_a = a'×g/|a'×g|`` and ``n_b = b'×g/|b'×g|``.

    Where the tangent of a boundary vanishes (``|a'| <= SINGULAR_NORMAL_TOL |g|``: an apex, a
    collapsed edge, a stationary end; what is left there is rounding noise of random direction),
    the normal at that end is the limit of the surface normal along the ruling: ``X_u × X_v =
    (a' + v g') × g → v (g' × g)``, so ``n_a = g'×g/|g'×g|`` and likewise ``n_b = -g'×g/|g'×g|``
    with ``g' = b' - a'``. Where a normal is still undefined (``|a'×g| <= SINGULAR_NORMAL_TOL
    |a'||g|``, both tangents vanish, or a zero ruling: ``|g| <= SINGULAR_NORMAL_TOL max(|a'|, |b'|)``,
    e.g. a pointed end whose end poles differ by rounding) θ and the dot product are NaN; callers
    ignore those parameters.
    """
    gl = _norm(g)
    a1l = _norm(a1)
    b1l = _norm(b1)
    tol_g = SINGULAR_NORMAL_TOL * gl
    a_sing = a1l <= tol_g
    b_sing = b1l <= tol_g
    ca = _cross(a1, g)
    cb = _cross(b1, g)
    if a_sing.any() or b_sing.any():  # the limit normal g' × g where a tangent vanishes
        g1 = b1 - a1
        g1l = _norm(g1)
        lim = _cross(g1, g)
        ca = np.where(a_sing[..., None], lim, ca)
        cb = np.where(b_sing[..., None], -lim, cb)
        a1l = np.where(a_sing, g1l, a1l)  # the tangent scale of each end's normal
        b1l = np.where(b_sing, g1l, b1l)
        g1_ok = g1l > tol_g  # the limit needs a turning ruling
        ok = ~((a_sing | b_sing) & ~g1_ok)
    else:
        ok = gl > 0
    la, lb = _norm(ca), _norm(cb)
    # a ruling shorter than SINGULAR_NORMAL_TOL of the boundary speeds is a point (a pointed end
    # read back from a B-spline face: 2e-13 on a 500 mm ruling, its direction rounding noise)
    ok &= (la > tol_g * a1l) & (lb > tol_g * b1l) & (gl > SINGULAR_NORMAL_TOL * np.maximum(a1l, b1l))
    with np.errstate(divide="ignore", invalid="ignore"):
        na = ca / la[..., None]
        nb = cb / lb[..., None]
        dot = np.minimum(np.maximum(_dot(na, nb), -1.0), 1.0)  # np.clip, without its overhead
        # atan2 of |na × nb| and na·nb is accurate near 0 where arccos is not
        cr = _norm(_cross(na, nb))
        th = np.degrees(np.arctan2(cr, dot))
    return np.where(ok, th, np.nan), np.where(ok, dot, np.nan)


def _residual(a1: np.ndarray, g: np.ndarray, g1: np.ndarray) -> np.ndarray:
    r"""``det(a', g, g') / (|a'| |g| |g'|)`` row-wise (0 where the scale vanishes)."""
    det = _dot(a1, _cross(g, g1))
    scale = _norm(a1) * _norm(g) * _norm(g1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(scale > 0, det / np.where(scale > 0, scale, 1.0), 0.0)


def regression_v(a1: np.ndarray, g: np.ndarray, g1: np.ndarray) -> np.ndarray:
    r"""Edge-of-regression parameter on the rulings of ``X = a + v g`` (spec 5.7):
    ``v* = -((a' × g)·(g' × g)) / |g' × g|²``, where ``X_u = a' + v g'`` is parallel to ``g``;
    ``inf`` where ``|g' × g|`` vanishes (cylinder-like: no singular point)."""
    c1 = np.cross(a1, g)
    c2 = np.cross(g1, g)
    den = np.sum(c2 * c2, axis=1)
    scale = np.sum(g * g, axis=1) * np.sum(g1 * g1, axis=1)
    ok = den > 1e-24 * np.maximum(scale, 1e-300)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(ok, -np.sum(c1 * c2, axis=1) / np.where(ok, den, 1.0), np.inf)


def developability_from_jets(
    a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray, weights: np.ndarray
) -> tuple[float, float, float, float]:
    """θ_rms, DD, R and θ_max from directrix values/derivatives at quadrature nodes."""
    th, dot = _theta(a1, b1, b0 - a0)
    return _integrals(th, dot, weights)


def _integrals(th: np.ndarray, dot: np.ndarray, weights: np.ndarray) -> tuple[float, float, float, float]:
    """``(θ_max, θ_rms, DD, R)`` from θ and ``n_a·n_b`` at quadrature nodes with ``weights``:
    ``θ_rms = sqrt(Σ w θ² / Σ w)``, ``DD = Σ w cos θ / Σ w``, ``R = Σ w (1 - n_a·n_b) / Σ w`` over the
    nodes where the normals are defined (NaN everywhere when they are nowhere)."""
    ok = np.isfinite(th)
    if not ok.all():
        if not ok.any():  # no normal anywhere (e.g. both edges collapsed to points): undefined, NaN
            return math.nan, math.nan, math.nan, math.nan
        weights, th, dot = weights[ok], th[ok], dot[ok]
    w = weights
    theta_rms = float(np.sqrt(np.sum(w * th**2) / np.sum(w)))
    dd = float(np.sum(w * np.cos(np.radians(th))) / np.sum(w))
    R = float(np.sum(w * (1.0 - dot)) / np.sum(w))
    return float(th.max()), theta_rms, dd, R


class RuledSurface(ABC):
    r"""Abstract ruled surface ``X(u, v) = a(u) + v (b(u) - a(u))`` on [0, 1]².

    Subclasses implement :meth:`a` and :meth:`b` (values and analytic derivatives, orders 0..2
    at least). ``v`` may leave [0, 1] to extend the rulings.
    """

    @abstractmethod
    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Directrix ``a^(r)(u)``, shape (len(u), 3)."""

    @abstractmethod
    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Second boundary ``b^(r)(u)``, shape (len(u), 3)."""

    # -- geometry ------------------------------------------------------------------------
    def ruling(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Ruling vector ``g^(r)(u) = b^(r)(u) - a^(r)(u)`` (not normalized)."""
        return self.b(u, derivative) - self.a(u, derivative)

    def edge_jets(self, u: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(a', g, g')`` at ``u``, each (n, 3), by :meth:`a` and :meth:`ruling` (whose override,
        e.g. a loft's cancellation-free ruling near a pointed end, is kept): what the development
        and the developability ask for, in one call (a face's adapter serves them from one kept
        surface jet)."""
        return self.a(u, 1), self.ruling(u), self.ruling(u, 1)

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        """Points ``X(u, v) = (1-v) a(u) + v b(u)``; u and v broadcast to a common 1-D shape."""
        uu, us = as_parameter_array(u, "u")
        vv, vs = as_parameter_array(v, "v")
        uu, vv = np.broadcast_arrays(uu, vv)
        A = self.a(uu)
        B = self.b(uu)
        out = A + vv[:, None] * (B - A)
        return out[0] if (us and vs) else out

    def grid(self, nu: int = 33, nv: int = 9) -> np.ndarray:
        """Points on a regular (nu, nv) grid, shape (nu, nv, 3)."""
        u = np.linspace(0.0, 1.0, nu)
        A = self.a(u)
        G = self.b(u) - A
        v = np.linspace(0.0, 1.0, nv)
        return A[:, None, :] + v[None, :, None] * G[:, None, :]

    def partials(self, u: Any, v: Any) -> tuple[np.ndarray, np.ndarray]:
        """``(X_u, X_v) = (a' + v g', g)``."""
        uu, _ = as_parameter_array(u, "u")
        vv, _ = as_parameter_array(v, "v")
        uu, vv = np.broadcast_arrays(uu, vv)
        a1 = self.a(uu, 1)
        g = self.ruling(uu)
        g1 = self.ruling(uu, 1)
        return a1 + vv[:, None] * g1, g

    def normal(self, u: Any, v: Any) -> np.ndarray:
        """Unit normal ``X_u × X_v / |X_u × X_v|``."""
        xu, xv = self.partials(u, v)
        return _unit(np.cross(xu, xv))

    def gaussian_curvature(self, u: Any, v: Any) -> np.ndarray:
        r"""Gaussian curvature of the ruled surface, ``K = -det(a', g, g')^2 / |X_u × g|^4``."""
        uu, _ = as_parameter_array(u, "u")
        vv, _ = as_parameter_array(v, "v")
        uu, vv = np.broadcast_arrays(uu, vv)
        a1 = self.a(uu, 1)
        g = self.ruling(uu)
        g1 = self.ruling(uu, 1)
        det = np.einsum("ij,ij->i", a1, np.cross(g, g1))
        w2 = np.sum(np.cross(a1 + vv[:, None] * g1, g) ** 2, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            return -(det**2) / w2**2

    def developability_residual(self, u: Any) -> np.ndarray:
        r"""Scale-free residual ``det(a', g, g') / (|a'| |g| |g'|)`` (0 on a developable).

        Its round-off is relative to the jets, not to ``|g'|``: ``g' = b' - a'`` is known only to
        ``eps (|a'| + |b'|)``, so on an exact developable ``|R| ≲ C eps (1 + (|a'| + |b'|) / |g'|)``
        (C = 58 the largest measured), large where the rulings hardly turn (``|g'| -> 0``).
        """
        uu, _ = as_parameter_array(u, "u")
        return _residual(self.a(uu, 1), self.ruling(uu), self.ruling(uu, 1))

    def theta(self, u: Any) -> np.ndarray:
        """Angle θ(u) in degrees between the normals at the two ends of the ruling at u."""
        uu, _ = as_parameter_array(u, "u")
        th, _ = _theta(self.a(uu, 1), self.b(uu, 1), self.ruling(uu))
        return th

    def developability(self, nodes: int = 64, samples: int = 257) -> Developability:
        r"""Developability degree (spec section 5).

        ``θ(u) = angle(n_a, n_b)``, ``n_a = a'×g/|a'×g|``, ``n_b = b'×g/|b'×g|``;
        ``θ_rms = sqrt(∫θ²)``, ``DD = ∫ cos θ``, ``R = ∫(1 - n_a·n_b)`` by ``nodes``-point
        Gauss–Legendre quadrature (>= 64); ``θ_max`` over the quadrature nodes and ``samples``
        uniform parameters (ends included).
        """
        if isinstance(nodes, bool) or not isinstance(nodes, (int, np.integer)) or nodes < 64:
            raise GHTError(
                f"nodes={nodes!r} is not allowed; the developability integrals use an integer >= 64 of "
                "Gauss–Legendre nodes"
            )
        t, w = gauss_legendre(nodes)
        uu = _theta_parameters(nodes, samples)
        # the quadrature nodes are the first entries of uu: one evaluation of a', b', g (a face's
        # boundary jets are kept per parameter array) and one of θ serve the integrals, θ_max and
        # the residual
        n = t.size
        a1, g, g1 = self.edge_jets(uu)
        b1 = self.b(uu, 1)
        th, dot = _theta(a1, b1, g)
        _, theta_rms, dd, R = _integrals(th[:n], dot[:n], w)
        fin = np.isfinite(th)
        if not fin.any():  # no ruling with a defined normal: nothing to measure (and no NaN to report)
            L = np.linalg.norm(g, axis=1)
            why = ("every sampled ruling has zero length (a zero-width surface)" if not (L > 0).any() else
                   "the surface normal is undefined at every sampled ruling (a' parallel to the ruling)")
            raise DegenerateGeometryError(f"developability is undefined: {why}; allowed: a surface of positive width")
        theta_max = float(np.fmax.reduce(th))  # undefined normals (NaN) skipped
        # the residual where the normals are defined (at a zero-length ruling it is noise / noise)
        res_all = np.abs(_residual(a1, g, g1))
        res = float(res_all[fin].max()) if fin.any() else float(res_all.max())
        return Developability(theta_max, theta_rms, dd, R, res)

    def ruling_lengths(self, u: Any) -> np.ndarray:
        """``|b(u) - a(u)|``."""
        return _norm(self.ruling(u))


class CurvePairRuledSurface(RuledSurface):
    """Ruled surface between two GHT curves paired by their common parameter.

    ``X(u, v) = (1-v) A(u) + v B(u)`` with ``A``, ``B`` 3-D :class:`GHTCurve` objects.
    Used for quasi-developable strips whose shape parameters are optimized (spec sections 5, 8).
    """

    def __init__(self, curve_a: GHTCurve, curve_b: GHTCurve) -> None:
        for name, c in (("curve_a", curve_a), ("curve_b", curve_b)):
            if not isinstance(c, GHTCurve):
                raise GHTError(f"{name} must be a GHTCurve, got {type(c).__name__}")
            if c.dim != 3:
                raise GHTError(f"{name} has dimension {c.dim}; a ruled surface needs 3-D curves")
        if (curve_a.shape_parameters == curve_b.shape_parameters and curve_a.seed.name == curve_b.seed.name
                and np.array_equal(curve_a.control_points, curve_b.control_points)):
            raise DegenerateGeometryError(
                "curve_a and curve_b are the same curve (equal control points and shape parameters): every ruling "
                "has zero length, the surface has zero width; allowed: two different curves")
        self.curve_a = curve_a
        self.curve_b = curve_b

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self.curve_a.derivative(u, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self.curve_b.derivative(u, derivative)


class FunctionRuledSurface(RuledSurface):
    """Ruled surface from two callables ``a(u, derivative)`` and ``b(u, derivative)``."""

    def __init__(self, a: Callable[[np.ndarray, int], np.ndarray], b: Callable[[np.ndarray, int], np.ndarray]) -> None:
        self._a = a
        self._b = b

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        return np.asarray(self._a(uu, derivative), dtype=float).reshape(uu.size, 3)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        return np.asarray(self._b(uu, derivative), dtype=float).reshape(uu.size, 3)
