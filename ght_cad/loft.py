r"""Exact developable loft between two rails (spec section 5.7).

For rails ``a(t)``, ``b(s)``, t, s ∈ [0, 1], the segment ``a(t)–b(s)`` is a ruling of a
developable through both rails iff the tangent plane is the same at its two ends:

    F(t, s) = det(a'(t), b'(s), b(s) - a(t)) = 0.

The loft is one branch of the zero set of F in the unit square, an increasing curve ``s = σ(t)``
(rulings must not cross). It is traced by predictor–corrector continuation in the path parameter
``λ = (t + s) / 2``: on the branch ``t + s = 2λ`` and ``F = 0`` give

    dt/dλ = 2 F_s / (F_s - F_t),   ds/dλ = -2 F_t / (F_s - F_t),

(both >= 0 on an increasing branch; ``F_t = det(a'', b', g)``, ``F_s = det(a', b'', g)``,
``g = b - a``) and every point is corrected by Newton's method on ``G(t) = F(t, 2λ - t)`` to
round-off, so θ of spec section 5 is round-off on every ruling. Where the branch meets a side of
the square the loft is completed by fans, cones with apex at a rail end: the branch starting on
``s = 0`` at ``t0 > 0`` adds the fan with apex ``b(0)`` over ``a([0, t0])``, starting on ``t = 0``
at ``s0 > 0`` the fan with apex ``a(0)`` over ``b([0, s0])``, and likewise at the upper-right
sides with apex ``a(1)`` or ``b(1)``. The whole loft is then the path from the corner (0, 0) to
(1, 1) in the (t, s) square, parametrized by ``λ ∈ [0, 1]``: fans run along the sides, the main
part along the branch. So both rails are covered over their whole length, the fans share the
tangent plane of the main part along the common ruling (G1), and the loft is one ruled surface
``X(λ, v) = (1-v) a(t(λ)) + v b(s(λ))`` that unrolls as one panel.

Rails running opposite ways (the developable pairs a(t) with a decreasing s) are handled by
tracing with rail b reversed (``orientation="auto"`` tries both).

This module imports numpy and scipy only; matplotlib is imported inside :func:`plot_loft_sign`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Mapping, Protocol, Sequence, runtime_checkable

import numpy as np

from ._validate import as_parameter_array, is_real
from ._vec import cross as _cross3
from .curve import GHTCurve, gauss_legendre
from .errors import DegenerateGeometryError, GHTError, NotDevelopableError
from .optimize.problems import Problem
from .ruled import Developability, RuledSurface, regression_v

__all__ = [
    "Rail",
    "CallableRail",
    "as_rail",
    "developable_loft",
    "DevelopableLoft",
    "LoftSegment",
    "LoftReport",
    "loft_function",
    "plot_loft_sign",
    "LoftProblem",
    "LOFT_OBJECTIVES",
    "LoftGradientFallback",
    "loft_measures_and_gradients",
]

_EPS = np.finfo(float).eps
#: rails whose ends are closer than this (relative to the size) meet there: a pointed loft end
CORNER_TOL = 1e-12
#: parameter distance from a meeting corner within which ``g = b - a`` is integrated (no cancellation)
CORNER_RADIUS = 1.0 / 32
_CORNER_GL = np.polynomial.legendre.leggauss(16)
#: relative size of a fan (in the rail parameter) below which the branch is taken to start or end
#: at the corner (no fan)
MIN_FAN = 1e-12


# ----------------------------------------------------------------------------------------------
# rails
# ----------------------------------------------------------------------------------------------
@runtime_checkable
class Rail(Protocol):
    """What a rail must provide: positions and derivatives on t ∈ [0, 1], each (n, 3).

    GHTCurve objects qualify; CAD edges are wrapped in :class:`CallableRail` by the adapters.
    """

    def evaluate(self, t: Any) -> np.ndarray:  # pragma: no cover - protocol
        """Points ``r(t)``, shape (n, 3)."""

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:  # pragma: no cover - protocol
        """Derivative ``r^(order)(t)``, shape (n, 3)."""


def _fd(fun: Callable[[np.ndarray], np.ndarray], t: np.ndarray, h: float = 1e-3) -> np.ndarray:
    r"""Derivative of ``fun`` by 4th-order differences inside [0, 1].

    Central ``(-f(t+2h) + 8f(t+h) - 8f(t-h) + f(t-2h)) / 12h`` where the stencil fits in [0, 1],
    else the one-sided ``±(-25 f(t) + 48 f(t±h) - 36 f(t±2h) + 16 f(t±3h) - 3 f(t±4h)) / 12h``.
    """
    out = np.empty((t.size, 3))
    lo = t < 2 * h
    hi = (t > 1 - 2 * h) & ~lo
    mid = ~(lo | hi)
    if mid.any():
        x = t[mid]
        out[mid] = (-fun(x + 2 * h) + 8 * fun(x + h) - 8 * fun(x - h) + fun(x - 2 * h)) / (12 * h)
    for mask, sgn in ((lo, 1.0), (hi, -1.0)):
        if mask.any():
            x = t[mask]
            hh = sgn * h
            out[mask] = (-25 * fun(x) + 48 * fun(x + hh) - 36 * fun(x + 2 * hh) + 16 * fun(x + 3 * hh)
                         - 3 * fun(x + 4 * hh)) / (12 * hh)
    return out


def _as_points(value: Any, n: int, what: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.size != 3 * n:
        raise GHTError(f"{what} returned an array of shape {arr.shape}; expected ({n}, 3)")
    return arr.reshape(n, 3)


class CallableRail:
    r"""A rail from plain callables ``position(t)``, ``first(t)`` (and optionally ``second(t)``).

    Each callable takes a 1-D array of parameters in [0, 1] and returns an (n, 3) array. Higher
    derivatives that are not given are computed by 4th-order finite differences of the highest
    given one (step 1e-3 in t, error about 1e-12 of the curve size for a smooth edge), which is
    what the CAD adapters use for edges whose kernel gives only two derivatives.

    Args:
        position: ``t -> r(t)``.
        first: ``t -> r'(t)``.
        second: ``t -> r''(t)`` or None.
        name: label used in error messages.
    """

    def __init__(
        self,
        position: Callable[[np.ndarray], Any],
        first: Callable[[np.ndarray], Any],
        second: Callable[[np.ndarray], Any] | None = None,
        *,
        name: str = "rail",
    ) -> None:
        for nm, f in (("position", position), ("first", first), ("second", second)):
            if f is not None and not callable(f):
                raise GHTError(f"CallableRail {nm} must be callable, got {type(f).__name__}")
        self._f = [position, first, second]
        self.name = name

    def _call(self, r: int, t: np.ndarray) -> np.ndarray:
        return _as_points(self._f[r](t), t.size, f"{self.name} derivative {r}")

    def _deriv(self, t: np.ndarray, r: int) -> np.ndarray:
        if r < len(self._f) and self._f[r] is not None:
            return self._call(r, t)
        return _fd(lambda x: self._deriv(x, r - 1), t)

    def evaluate(self, t: Any) -> np.ndarray:
        """Points ``r(t)``, shape (n, 3)."""
        return self.derivative(t, 0)

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        """``r^(order)(t)`` for order 0..3 (given callables or finite differences of them)."""
        if order not in (0, 1, 2, 3):
            raise GHTError(f"order={order!r} is not allowed; rails give derivatives of order 0..3")
        tt, _ = as_parameter_array(t, "t")
        return self._deriv(tt, order)

    def __repr__(self) -> str:
        return f"CallableRail(name={self.name!r})"


class _ObjectRail:
    """Adapter for any object with ``evaluate(t)`` and ``derivative(t, order)`` (GHTCurve too).

    Orders the object refuses are computed by finite differences of the highest it gives.
    """

    def __init__(self, obj: Any, name: str) -> None:
        self.obj = obj
        self.name = name
        self._max_order = 3

    def _call(self, t: np.ndarray, r: int) -> np.ndarray:
        if r == 0:
            return _as_points(self.obj.evaluate(t), t.size, f"{self.name}.evaluate")
        return _as_points(self.obj.derivative(t, r), t.size, f"{self.name}.derivative(order={r})")

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        tt, _ = as_parameter_array(t, "t")
        if order <= self._max_order:
            try:
                return self._call(tt, order)
            except (NotImplementedError, TypeError, ValueError) as exc:
                if order <= 1 or isinstance(exc, GHTError) and "order" not in str(exc):
                    raise
                self._max_order = order - 1
        return _fd(lambda x: self.derivative(x, order - 1), tt)

    def evaluate(self, t: Any) -> np.ndarray:
        return self.derivative(t, 0)

    def jet(self, t: np.ndarray, k: int) -> list[np.ndarray]:
        """``[r, r', ..., r^(k)]`` at t; one pass for a GHTCurve (:meth:`GHTCurve.derivatives`)."""
        if isinstance(self.obj, GHTCurve) and k <= 3:
            return self.obj.derivatives(t, k)
        return [self.derivative(t, r) for r in range(k + 1)]

    def __repr__(self) -> str:
        return f"{self.name}={self.obj!r}"


def as_rail(obj: Any, name: str = "rail") -> Any:
    """A rail object (``evaluate`` and ``derivative(t, order)`` of orders 0..3) for ``obj``.

    Args:
        obj: a 3-D :class:`~ght_cad.curve.GHTCurve`, a :class:`CallableRail`, or any object with
            ``evaluate(t) -> (n, 3)`` and ``derivative(t, order=1) -> (n, 3)`` on [0, 1]. CAD
            edges (build123d/OCP, FreeCAD ``Part.Edge``) are wrapped by the adapters
            (``ght_cad.cad``, ``freecad_workbench``) into a :class:`CallableRail`.
        name: label used in error messages ("rail_a", "rail_b").

    Raises:
        GHTError: an object without those methods, or a GHTCurve that is not 3-D.
    """
    if isinstance(obj, (CallableRail, _ObjectRail)):
        return obj
    if isinstance(obj, GHTCurve):
        if obj.dim != 3:
            raise GHTError(f"{name} is a GHTCurve of dimension {obj.dim}; a rail must be a 3-D curve")
        return _ObjectRail(obj, name)
    if callable(getattr(obj, "evaluate", None)) and callable(getattr(obj, "derivative", None)):
        return _ObjectRail(obj, name)
    raise GHTError(
        f"{name} is a {type(obj).__name__}; a rail is a 3-D GHTCurve, a CallableRail(position, first, "
        "second=None) or an object with evaluate(t) and derivative(t, order) on [0, 1] (CAD edges: use "
        "the build123d/FreeCAD loft adapters, which wrap them)"
    )


class _Reversed:
    """``r~(s) = r(1 - s)``: derivatives of order k get the sign ``(-1)^k``."""

    def __init__(self, rail: Any) -> None:
        self.rail = rail
        self.name = getattr(rail, "name", "rail") + " (reversed)"

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        tt, _ = as_parameter_array(t, "t")
        return (-1.0) ** order * self.rail.derivative(1.0 - tt, order)

    def evaluate(self, t: Any) -> np.ndarray:
        return self.derivative(t, 0)

    def jet(self, t: np.ndarray, k: int) -> list[np.ndarray]:
        return [(-1.0) ** r * x for r, x in enumerate(_jet(self.rail, 1.0 - np.asarray(t, float), k))]


def _jet(rail: Any, t: np.ndarray, k: int) -> list[np.ndarray]:
    """``[r, r', ..., r^(k)]`` at t (the rail's one-pass ``jet`` where it has one)."""
    fast = getattr(rail, "jet", None)
    if fast is not None:
        return fast(t, k)
    return [rail.derivative(t, r) for r in range(k + 1)]


def _det(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Row-wise ``det(x, y, z) = x · (y × z)`` of (n, 3) arrays (explicit: np.cross is slow on small arrays)."""
    return (x[:, 0] * (y[:, 1] * z[:, 2] - y[:, 2] * z[:, 1])
            + x[:, 1] * (y[:, 2] * z[:, 0] - y[:, 0] * z[:, 2])
            + x[:, 2] * (y[:, 0] * z[:, 1] - y[:, 1] * z[:, 0]))


# ----------------------------------------------------------------------------------------------
# the tangent-plane function F and its continuation
# ----------------------------------------------------------------------------------------------
class _Pair:
    """Rails a, b (b possibly reversed) with F and its partial derivatives."""

    def __init__(self, ra: Any, rb: Any, size: float) -> None:
        self.ra, self.rb, self.size = ra, rb, size
        # corners (0, 0), (1, 1) where the rails meet (a pointed end of the loft: a zero ruling);
        # near them g = b - a is computed without cancellation (:meth:`_near_corner_gap`)
        self.corners: list[tuple[float, float, np.ndarray]] = []
        for c in (0.0, 1.0):
            e = np.array([c])
            gap = np.asarray(rb.derivative(e, 0), dtype=float)[0] - np.asarray(ra.derivative(e, 0), dtype=float)[0]
            if float(np.linalg.norm(gap)) <= CORNER_TOL * max(float(size), 1e-300):
                self.corners.append((c, c, gap))

    def _near_corner_gap(self, t: np.ndarray, s: np.ndarray, g: np.ndarray,
                         offsets: tuple[np.ndarray, np.ndarray, int] | None = None) -> tuple[np.ndarray, np.ndarray]:
        r"""``g = b(s) - a(t)`` near a corner where the rails meet, without cancellation, and a mask
        of the points where it was so computed.

        ``g = (b(s0) - a(t0)) + y ∫_0^1 b'(s0 + τ y) dτ - x ∫_0^1 a'(t0 + τ x) dτ`` (``x = t - t0``,
        ``y = s - s0``, 16-point Gauss–Legendre: round-off relative to ``|g|``, where the plain
        difference of two points near the meeting point carries ``eps |a|``).
        """
        near = np.zeros(t.shape, dtype=bool)
        if not self.corners:
            return g, near
        g = g.copy()
        for c, (t0, s0, gap) in enumerate(self.corners):
            if offsets is not None and offsets[2] == c:
                # exact offsets from the corner (t - t0 rounded near 1 would carry eps absolute)
                x, y = offsets[0], offsets[1]
            else:
                x, y = t - t0, s - s0
            m = (np.abs(x) <= CORNER_RADIUS) & (np.abs(y) <= CORNER_RADIUS)
            if not m.any():
                continue
            xs, ys = x[m], y[m]
            nodes, weights = _CORNER_GL
            tau = 0.5 * (nodes + 1.0)
            w = 0.5 * weights
            da = np.asarray(self.ra.derivative((t0 + xs[:, None] * tau[None, :]).ravel(), 1), dtype=float)
            db = np.asarray(self.rb.derivative((s0 + ys[:, None] * tau[None, :]).ravel(), 1), dtype=float)
            ia = np.einsum("j,ijk->ik", w, da.reshape(xs.size, tau.size, 3))
            ib = np.einsum("j,ijk->ik", w, db.reshape(ys.size, tau.size, 3))
            g[m] = gap + ys[:, None] * ib - xs[:, None] * ia
            near |= m
        return g, near

    def parts(self, t: np.ndarray, s: np.ndarray, k: int = 1,
              offsets: tuple[np.ndarray, np.ndarray, int] | None = None) -> dict[str, Any]:
        """F, F_t, F_s (and with k = 2 the second partials) at (t, s); scale = |a'||b'||g|.
        ``offsets``: exact ``(t - t0, s - s0, corner index)`` near a meeting corner."""
        A = _jet(self.ra, t, k + 1)
        B = _jet(self.rb, s, k + 1)
        g = B[0] - A[0]
        g, near = self._near_corner_gap(np.asarray(t, float), np.asarray(s, float), g, offsets)
        out: dict[str, Any] = {"A": A, "B": B, "g": g}
        out["F"] = _det(A[1], B[1], g)
        out["Ft"] = _det(A[2], B[1], g)
        out["Fs"] = _det(A[1], B[2], g)
        ab = np.linalg.norm(A[1], axis=1) * np.linalg.norm(B[1], axis=1)
        out["scale"] = ab * np.linalg.norm(g, axis=1)
        # rounding error of F: g = b - a carries eps (|a| + |b|), the product eps |a'||b'||g|
        out["noise"] = _EPS * ab * (np.linalg.norm(g, axis=1) + np.linalg.norm(A[0], axis=1) + np.linalg.norm(B[0], axis=1))
        if near.any():  # near a meeting corner g is good to eps |g| (the jets to eps)
            out["noise"] = np.where(near, 4.0 * _EPS * ab * np.linalg.norm(g, axis=1), out["noise"])
        if k >= 2:
            out["Ftt"] = _det(A[3], B[1], g) - _det(A[2], B[1], A[1])
            out["Fts"] = _det(A[2], B[2], g)
            out["Fss"] = _det(A[1], B[3], g) + _det(A[1], B[2], B[1])
        return out

    def F(self, t: np.ndarray, s: np.ndarray) -> np.ndarray:
        A0, A1 = _jet(self.ra, t, 1)
        B0, B1 = _jet(self.rb, s, 1)
        g, _ = self._near_corner_gap(np.asarray(t, float), np.asarray(s, float), B0 - A0)
        return _det(A1, B1, g)

    def _corner_H(self, c: int, x: np.ndarray, w: np.ndarray) -> np.ndarray:
        r"""``H = F / x²`` at ``(t0 + x, s0 + w x)`` near the meeting corner ``c``, free of cancellation:

            H = det(A2, b', G) + w det(a1, B2, G) + det(a1, b1, w² B̃2 - Ã2),

        ``a1 = a'(t0)``, ``b1 = b'(s0)``, ``b' = b'(s0 + y)``, ``G = g/x = w B1(y) - A1(x)`` and the
        divided differences ``A1 = ∫ a'(t0 + τx) dτ``, ``A2 = ∫ a''(t0 + τx) dτ``,
        ``Ã2 = ∫ (1-τ) a''(t0 + τx) dτ`` (likewise B with y = w x; τ ∈ [0, 1], 16-point
        Gauss–Legendre); the first-order terms of F cancel identically, ``H(0, w) = ½ (D_a - w² D_b)``.
        """
        t0, s0, _ = self.corners[c]
        y = w * x
        nodes, weights = _CORNER_GL
        tau = 0.5 * (nodes + 1.0)
        wt = 0.5 * weights
        n = x.size

        def dd(rail: Any, z0: float, z: np.ndarray) -> tuple[np.ndarray, ...]:
            pts = (z0 + z[:, None] * tau[None, :]).ravel()
            d1 = np.asarray(rail.derivative(pts, 1), dtype=float).reshape(n, tau.size, 3)
            d2 = np.asarray(rail.derivative(pts, 2), dtype=float).reshape(n, tau.size, 3)
            return (np.einsum("j,ijk->ik", wt, d1), np.einsum("j,ijk->ik", wt, d2),
                    np.einsum("j,ijk->ik", wt * (1.0 - tau), d2))

        A1, A2, A2t = dd(self.ra, t0, x)
        B1, B2, B2t = dd(self.rb, s0, y)
        e = np.array([t0]), np.array([s0])
        a1 = np.broadcast_to(np.asarray(self.ra.derivative(e[0], 1), dtype=float), (n, 3))
        b1 = np.broadcast_to(np.asarray(self.rb.derivative(e[1], 1), dtype=float), (n, 3))
        bp = b1 + y[:, None] * B2
        G = w[:, None] * B1 - A1
        return _det(A2, bp, G) + w * _det(a1, B2, G) + _det(a1, b1, (w * w)[:, None] * B2t - A2t)

    def corner_branch(self, c: int, dlam: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r"""Offsets ``(x, y) = (t - t0, s - s0)`` of the branch point at ``λ = λ_c + dlam`` near the
        meeting corner ``c`` (``x + y = 2 dlam``): ``y = w x`` with ``H(x, w) = 0``
        (:meth:`_corner_H`, secant iteration in w from the corner slope), so the point is on the
        branch to round-off relative to its distance from the corner (a Newton on F in absolute t
        resolves ``t - t0`` only to ``eps``, and the ruling direction to ``eps/|t - t0|``).
        """
        t0, s0, _ = self.corners[c]
        dlam = np.asarray(dlam, dtype=float)
        r = self.corner_slope(t0, s0)
        w0 = np.full(dlam.shape, r)
        x_of = lambda w: 2.0 * dlam / (1.0 + w)  # noqa: E731
        h0 = self._corner_H(c, x_of(w0), w0)
        w1 = w0 * (1.0 + 1e-6)
        h1 = self._corner_H(c, x_of(w1), w1)
        for _ in range(30):
            den = h1 - h0
            with np.errstate(divide="ignore", invalid="ignore"):
                step = np.where(den != 0, h1 * (w1 - w0) / den, 0.0)
            w0, h0 = w1, h1
            w1 = w1 - step
            if np.all(np.abs(step) <= 4 * _EPS * np.abs(w1)):
                break
            h1 = self._corner_H(c, x_of(w1), w1)
        x = x_of(w1)
        return x, w1 * x

    def corner_slope(self, t0: float, s0: float) -> float:
        r"""``ds/dt`` of the branch at a corner where the rails meet: with ``x = t - t0``,
        ``y = s - s0``, ``F = ½ (D_a x² - D_b y²) + O(3)``, ``D_a = det(a', b', a'')``,
        ``D_b = det(a', b', b'')`` (the first-order terms cancel), so ``y/x → r = sqrt(D_a/D_b)``.

        Raises:
            NotDevelopableError: ``D_a/D_b <= 0`` (no increasing branch enters the corner).
        """
        A = _jet(self.ra, np.array([t0]), 2)
        B = _jet(self.rb, np.array([s0]), 2)
        Da = float(_det(A[1], B[1], A[2])[0])
        Db = float(_det(A[1], B[1], B[2])[0])
        if not (Db != 0 and Da / Db > 0):
            raise NotDevelopableError(
                f"the rails meet at the corner t={t0:g}, s={s0:g} but no increasing branch of F = 0 enters it "
                f"(det(a', b', a'')={Da:.6g}, det(a', b', b'')={Db:.6g} must have the same sign)"
            )
        return math.sqrt(Da / Db)

    def f(self, t: np.ndarray, s: np.ndarray) -> np.ndarray:
        """Scale-free ``F / (|a'| |b'| |g|)`` (the sine of the angle between the two end planes,
        up to the sines of the ruling angles); 0 where a scale factor vanishes."""
        A0, A1 = _jet(self.ra, t, 1)
        B0, B1 = _jet(self.rb, s, 1)
        g = B0 - A0
        sc = np.linalg.norm(A1, axis=1) * np.linalg.norm(B1, axis=1) * np.linalg.norm(g, axis=1)
        F = _det(A1, B1, g)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(sc > 0, F / np.where(sc > 0, sc, 1.0), 0.0)

    # -- Newton on the branch at fixed λ --------------------------------------------------
    def correct(self, lam: np.ndarray, t: np.ndarray, iters: int = 12) -> tuple[np.ndarray, np.ndarray, bool]:
        """Solve ``G(t) = F(t, 2λ - t) = 0`` by Newton from ``t`` (vectorized); (t, s, converged)."""
        lam = np.asarray(lam, float)
        lo = np.maximum(0.0, 2 * lam - 1.0)
        hi = np.minimum(1.0, 2 * lam)
        t = np.clip(np.asarray(t, float).copy(), lo, hi)
        self.last = None
        for it in range(iters):
            s = 2 * lam - t
            p = self.parts(t, s, 1)
            dG = p["Ft"] - p["Fs"]
            with np.errstate(divide="ignore", invalid="ignore"):
                dt = np.where(dG != 0, p["F"] / dG, 0.0)
            if not np.all(np.isfinite(dt)):
                return t, 2 * lam - t, False
            resid = np.abs(p["F"]) <= 4 * p["noise"]
            if np.all(resid | (np.abs(dt) <= 2 * _EPS * np.maximum(1.0, np.abs(t)))):
                # converged at this t (F at round-off): keep t and its partials
                self.last = p
                return t, s, True
            t = np.clip(t - dt, lo, hi)
        s = 2 * lam - t
        p = self.parts(t, s, 1)
        self.last = p
        ok = bool(np.all(np.abs(p["F"]) <= 1e-12 * p["scale"] + 64 * p["noise"]))
        return t, s, ok

    def tangent(self, t: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(dt/dλ, ds/dλ) = (2 F_s, -2 F_t) / (F_s - F_t)`` on the branch."""
        p = self.parts(t, s, 1)
        den = p["Fs"] - p["Ft"]
        with np.errstate(divide="ignore", invalid="ignore"):
            return 2 * p["Fs"] / den, -2 * p["Ft"] / den

    def side_root(self, side: str, guess: float, iters: int = 30) -> float | None:
        """Newton/bisection root of F on a side ('t=1' solves F(1, s) = 0 for s, 's=1' F(t, 1) = 0)."""
        from scipy.optimize import brentq

        def fun(x: float) -> float:
            if side == "t=1":
                return float(self.F(np.array([1.0]), np.array([x]))[0])
            return float(self.F(np.array([x]), np.array([1.0]))[0])

        x = min(max(guess, 0.0), 1.0)
        # the branch may end at a corner, where F is round-off but need not change sign
        for c in (0.0, 1.0):
            if abs(x - c) <= 1e-2:
                tt, ss = (np.array([1.0]), np.array([c])) if side == "t=1" else (np.array([c]), np.array([1.0]))
                if abs(float(self.f(tt, ss)[0])) <= 1e-12:
                    return c
        h = 1e-6
        for lo_, hi_ in ((x - h, x + h), (x - 1e-3, x + 1e-3), (x - 0.05, x + 0.05), (0.0, 1.0)):
            lo_, hi_ = max(lo_, 0.0), min(hi_, 1.0)
            flo, fhi = fun(lo_), fun(hi_)
            if flo == 0.0:
                return lo_
            if fhi == 0.0:
                return hi_
            if flo * fhi < 0:
                r = brentq(fun, lo_, hi_, xtol=1e-16, rtol=4 * _EPS, maxiter=200)
                return self._polish_side(side, r)
        return None

    def _polish_side(self, side: str, x: float) -> float:
        for _ in range(3):
            if side == "t=1":
                p = self.parts(np.array([1.0]), np.array([x]), 1)
                d = p["Fs"][0]
            else:
                p = self.parts(np.array([x]), np.array([1.0]), 1)
                d = p["Ft"][0]
            if d == 0:
                break
            xn = min(max(x - p["F"][0] / d, 0.0), 1.0)
            if abs(xn - x) > 1e-9:
                break
            x = xn
        return x


@dataclass(eq=False)
class _Branch:
    """A traced branch: nodes (λ, t, s, dt/dλ, ds/dλ), from a lower-left to an upper-right side."""

    lam: np.ndarray
    t: np.ndarray
    s: np.ndarray
    tp: np.ndarray
    sp: np.ndarray
    reversed_b: bool

    @property
    def start(self) -> tuple[float, float]:
        return float(self.t[0]), float(self.s[0])

    @property
    def end(self) -> tuple[float, float]:
        return float(self.t[-1]), float(self.s[-1])


def _boundary_roots(pair: _Pair, samples: int) -> list[tuple[float, float]]:
    """Zeros of F on the lower-left sides s = 0 (t ∈ [0, 1]) and t = 0 (s ∈ [0, 1]), corner first."""
    from scipy.optimize import brentq

    x = np.linspace(0.0, 1.0, samples)
    z = np.zeros_like(x)
    out: list[tuple[float, float]] = []
    f00 = float(pair.f(np.array([0.0]), np.array([0.0]))[0])
    if abs(f00) <= 1e-12:
        out.append((0.0, 0.0))
    for side in ("s=0", "t=0"):
        vals = pair.f(x, z) if side == "s=0" else pair.f(z, x)

        def fun(y: float, side: str = side) -> float:
            yy = np.array([y])
            zz = np.array([0.0])
            return float((pair.F(yy, zz) if side == "s=0" else pair.F(zz, yy))[0])

        for i in range(samples - 1):
            if vals[i] == 0.0 and i > 0:
                r = x[i]
            elif vals[i] * vals[i + 1] < 0:
                fa, fb = fun(x[i]), fun(x[i + 1])
                if fa * fb < 0:
                    r = brentq(fun, x[i], x[i + 1], xtol=1e-16, rtol=4 * _EPS, maxiter=200)
                else:  # the sampled sign change is rounding at an end (e.g. a rail to a straight rail:
                    # the scale-free f and the corner-integrated F differ there): the root is that end
                    r = x[i] if abs(fa) <= abs(fb) else x[i + 1]
            else:
                continue
            if r <= MIN_FAN:
                if not out or out[0] != (0.0, 0.0):
                    out.insert(0, (0.0, 0.0))
                continue
            pt = (r, 0.0) if side == "s=0" else (0.0, r)
            if all(abs(pt[0] - q[0]) + abs(pt[1] - q[1]) > 1e-10 for q in out):
                out.append(pt)
        if vals[-1] == 0.0:
            pt = (1.0, 0.0) if side == "s=0" else (0.0, 1.0)
            if pt not in out:
                out.append(pt)
    return out


class _TraceFailure(Exception):
    pass


def _meeting_tangent(pair: _Pair, t: float, s: float) -> tuple[float, float]:
    r"""Branch direction where the rails meet (``a(t) = b(s)``, a zero ruling: F is singular there).

    With ``A1, A2 = a'(t), a''(t)`` and ``B1, B2 = b'(s), b''(s)``, expanding ``g`` to second order
    gives ``F(t + x, s + y) ≈ (x² D_a - y² D_b) / 2``, ``D_a = det(A1, B1, A2)``,
    ``D_b = det(A1, B1, B2)``: the zero set leaves the meeting point along ``y / x = ±sqrt(D_a / D_b)``;
    the increasing branch has ``(dt/dλ, ds/dλ) = (2, 2m) / (1 + m)``, ``m = sqrt(D_a / D_b)``.

    Raises:
        _TraceFailure: ``D_a / D_b <= 0`` (no increasing branch leaves the meeting point) or the
            rails do not meet there (a singular point of F with a nonzero ruling).
    """
    p = pair.parts(np.array([t]), np.array([s]), 1)
    if float(np.linalg.norm(p["g"][0])) > 1e-9 * pair.size:
        raise _TraceFailure(f"F is singular (grad F = 0) at t={t:.6g}, s={s:.6g}")
    try:
        m = pair.corner_slope(t, s)  # ds/dt = sqrt(D_a / D_b) there
    except NotDevelopableError as exc:
        raise _TraceFailure(str(exc)) from None
    return 2.0 / (1.0 + m), 2.0 * m / (1.0 + m)


def _at_corner(pair: _Pair, t: float, s: float) -> bool:
    """(t, s) is a corner where the rails meet (``_Pair.corners``: a pointed end of the loft)."""
    return any(abs(t - t0) <= 1e-12 and abs(s - s0) <= 1e-12 for t0, s0, _ in pair.corners)


def _trace(pair: _Pair, start: tuple[float, float], reversed_b: bool, max_step: float, tol: float) -> _Branch:
    """Predictor–corrector continuation in λ = (t + s) / 2 from ``start`` to an upper-right side.

    Predictor: Hermite extrapolation ``t + h t'`` (Euler) from the last node; corrector: Newton on
    ``F(t, 2λ - t) = 0`` to round-off. Step control: the corrector displacement must stay below
    ``tol`` (halve the step, or grow it by sqrt(tol / displacement) up to ``max_step``).

    Raises:
        _TraceFailure: the branch turns back (dt/dλ or ds/dλ < 0: crossing rulings), meets a
            singular point of F, or leaves the square through a lower-left side.
    """
    t, s = start
    lam = 0.5 * (t + s)
    tp, sp = (float(v[0]) for v in pair.tangent(np.array([t]), np.array([s])))
    if not (np.isfinite(tp) and np.isfinite(sp)) or _at_corner(pair, t, s):
        # where the rails meet both partials of F vanish: (F_s, -F_t) is round-off (0/0, or a
        # finite direction of noise when the meeting point carries a gap of a few eps)
        tp, sp = _meeting_tangent(pair, t, s)
    mono = -1e-9

    def check(tp: float, sp: float, t: float, s: float) -> None:
        if not (np.isfinite(tp) and np.isfinite(sp)):
            raise _TraceFailure(f"F is singular (grad F = 0 along the branch direction) at t={t:.6g}, s={s:.6g}")
        if tp < mono or sp < mono:
            raise _TraceFailure(
                f"the branch turns back at t={t:.6g}, s={s:.6g} (dt/dλ={tp:.3g}, ds/dλ={sp:.3g}): "
                "its rulings would cross"
            )

    check(tp, sp, t, s)
    L, T, S, TP, SP = [lam], [t], [s], [tp], [sp]
    h = min(max_step, 1e-2)
    hmin = 1e-13
    steps = 0
    while True:
        steps += 1
        if steps > 200000:
            raise _TraceFailure(f"tracing did not finish (step too small near t={t:.6g}, s={s:.6g})")
        t_pred, s_pred = t + h * tp, s + h * sp
        if t_pred >= 1.0 or s_pred >= 1.0:
            # the branch leaves through an upper-right side: find where exactly
            ht = (1.0 - t) / tp if tp > 0 else np.inf
            hs = (1.0 - s) / sp if sp > 0 else np.inf
            if ht <= hs:
                sr = pair.side_root("t=1", s + ht * sp)
                end = None if sr is None else (1.0, sr)
            else:
                tr = pair.side_root("s=1", t + hs * tp)
                end = None if tr is None else (tr, 1.0)
            if end is not None and end[0] >= t - 1e-12 and end[1] >= s - 1e-12:
                te, se = end
                lam_e = 0.5 * (te + se)
                # the end must be reached by a short monotone step (else keep stepping)
                if lam_e - lam <= 1.5 * h or h <= 1e-9:
                    tpe, spe = (float(v[0]) for v in pair.tangent(np.array([te]), np.array([se])))
                    if _at_corner(pair, te, se):
                        tpe, spe = _meeting_tangent(pair, te, se)
                    elif not (np.isfinite(tpe) and np.isfinite(spe)):
                        tpe, spe = tp, sp
                    if lam_e - lam > 1e-14:
                        L.append(lam_e), T.append(te), S.append(se), TP.append(tpe), SP.append(spe)
                    else:
                        T[-1], S[-1] = te, se
                    break
            h *= 0.5
            if h < hmin:
                raise _TraceFailure(f"the branch cannot be followed to a side near t={t:.6g}, s={s:.6g}")
            continue
        lam_n = lam + h
        tn, sn, ok = pair.correct(np.array([lam_n]), np.array([t_pred]))
        tn, sn = float(tn[0]), float(sn[0])
        disp = abs(tn - t_pred) + abs(sn - s_pred)
        if not ok or disp > tol or tn < t - 1e-12 or sn < s - 1e-12:
            h *= 0.5
            if h < hmin:
                raise _TraceFailure(
                    f"Newton on F = 0 does not converge near t={t:.6g}, s={s:.6g}: the branch turns back, "
                    "branches cross or F vanishes on a region there"
                )
            continue
        q = pair.last
        den = float(q["Fs"][0] - q["Ft"][0])
        tpn, spn = (2 * float(q["Fs"][0]) / den, -2 * float(q["Ft"][0]) / den) if den != 0 else (math.nan, math.nan)
        check(tpn, spn, tn, sn)
        lam, t, s, tp, sp = lam_n, tn, sn, tpn, spn
        L.append(lam), T.append(t), S.append(s), TP.append(tp), SP.append(sp)
        h = min(max_step, h * min(2.0, math.sqrt(tol / max(disp, 1e-3 * tol))))
    return _Branch(np.array(L), np.array(T), np.array(S), np.array(TP), np.array(SP), reversed_b)


# ----------------------------------------------------------------------------------------------
# segments: fans and the main part as ruled surfaces
# ----------------------------------------------------------------------------------------------
_KINDS = ("fan_a", "fan_b", "main")


class _Path:
    """The path (t(λ), s(λ)) from (0, 0) to (1, 1) through fans and the branch, with derivatives."""

    def __init__(self, pair: _Pair, branch: _Branch) -> None:
        self.pair = pair
        self.branch = branch
        from scipy.interpolate import CubicHermiteSpline

        lam, t = branch.lam, branch.t
        if lam.size >= 2:
            self._guess = CubicHermiteSpline(lam, t, branch.tp, extrapolate=True)
        else:
            self._guess = None
        self.lam0, self.lam1 = float(lam[0]), float(lam[-1])
        self._cache: dict[bytes, Any] = {}
        # branch ends at a corner where the rails meet (a pointed loft end): (corner index, λ there)
        self.corner_ends: list[tuple[int, float]] = []
        for c, (t0, s0, _) in enumerate(pair.corners):
            for (tb, sb), lb in ((branch.start, self.lam0), (branch.end, self.lam1)):
                if abs(tb - t0) <= MIN_FAN and abs(sb - s0) <= MIN_FAN:
                    self.corner_ends.append((c, float(t0)))

    def near_corner(self, lam: np.ndarray) -> np.ndarray | None:
        """Mask of the λ within ``CORNER_RADIUS / 2`` of a meeting corner (None: the branch has none)."""
        if not self.corner_ends:
            return None
        m = np.zeros(lam.shape, dtype=bool)
        for _, lc in self.corner_ends:
            m |= np.abs(lam - lc) <= 0.5 * CORNER_RADIUS
        return m

    def _corner_main(self, lam: np.ndarray, k: int) -> tuple[list[np.ndarray], list[np.ndarray], dict[str, Any], np.ndarray] | None:
        r"""The branch within ``CORNER_RADIUS / 2`` (in λ) of a meeting corner (:meth:`_Pair.corner_branch`):
        ``t, s`` and their λ-derivatives ``t' = 2 F_s / (F_s - F_t)``, ``t''`` from the partials at
        the exact offsets (F_t, F_s are O(|g|), computed without cancellation); at the corner
        itself ``t' = 2 / (1 + r)``, ``r = sqrt(D_a / D_b)`` (:meth:`_Pair.corner_slope`) and
        ``t''`` extrapolated (cubic, from λ offsets 1e-4 .. 4e-4). None when no point is near one.
        """
        if not self.corner_ends:
            return None
        hit = None
        for c, lc in self.corner_ends:
            m = np.abs(lam - lc) <= 0.5 * CORNER_RADIUS
            if m.all():
                hit = (c, lc)
                break
        if hit is None:
            return None
        c, lc = hit
        t0, s0, _ = self.pair.corners[c]
        dlam = lam - lc
        at = dlam == 0.0
        dl = np.where(at, np.where(lc > 0.5, -1e-4, 1e-4), dlam)
        x, y = self.pair.corner_branch(c, dl)
        x, y = np.where(at, 0.0, x), np.where(at, 0.0, y)
        t, s = t0 + x, s0 + y
        p = self.pair.parts(t, s, max(k, 1), offsets=(x, y, c))
        Ft, Fs = p["Ft"], p["Fs"]
        den = Fs - Ft
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = 2 * Fs / den
            out_t, out_s = [t, tp], [s, 2.0 - tp]
            if k >= 2:
                dFt = p["Ftt"] * tp + p["Fts"] * (2.0 - tp)
                dFs = p["Fts"] * tp + p["Fss"] * (2.0 - tp)
                tpp = 2 * (Fs * dFt - Ft * dFs) / den**2
                out_t.append(tpp)
                out_s.append(-tpp)
        if at.any():
            r = self.pair.corner_slope(t0, s0)
            out_t[1][at], out_s[1][at] = 2.0 / (1.0 + r), 2.0 * r / (1.0 + r)
            if k >= 2:
                sgn = -1.0 if lc > 0.5 else 1.0
                hs = sgn * 1e-4 * np.arange(1.0, 5.0)
                sub = self._corner_main(lc + hs, 2)
                assert sub is not None
                q = sub[0][2]
                out_t[2][at] = 4 * q[0] - 6 * q[1] + 4 * q[2] - q[3]
                out_s[2][at] = -out_t[2][at]
        return out_t[: k + 1], out_s[: k + 1], p, np.stack([x, y], axis=1)

    def main(self, lam: np.ndarray, k: int) -> list[np.ndarray]:
        """[t, t', t''], [s, s', s''] on the branch at ``lam`` (derivatives w.r.t. λ, up to k)."""
        key = lam.tobytes()
        hit = self._cache.get(key)
        if hit is not None and len(hit[0]) >= k + 1:
            return hit
        near = self.near_corner(lam)
        if near is not None and near.any() and not near.all():  # split: near a meeting corner / elsewhere
            r1, r2 = self.main(lam[near], k), self.main(lam[~near], k)
            # k + 1 of each: either part may come from the cache with more derivatives than asked
            tt = [np.empty(lam.shape) for _ in range(k + 1)]
            ss = [np.empty(lam.shape) for _ in range(k + 1)]
            for r in range(k + 1):
                tt[r][near], tt[r][~near] = r1[0][r], r2[0][r]
                ss[r][near], ss[r][~near] = r1[1][r], r2[1][r]
            g = np.empty((lam.size, 3))
            g[near], g[~near] = r1[2]["g"], r2[2]["g"]
            return tt, ss, {"g": g}
        cm = self._corner_main(lam, k) if near is not None and near.size and near.all() else None
        if cm is not None:
            res = (cm[0], cm[1], cm[2])
            if len(self._cache) > 8:
                self._cache.clear()
            self._cache[key] = res
            return res
        g = np.clip(self._guess(lam), 0.0, 1.0) if self._guess is not None else np.full(lam.shape, self.branch.t[0])
        t, s, ok = self.pair.correct(lam, g)
        p = self.pair.last
        if not ok:
            bad = int(np.argmax(np.abs(self.pair.f(t, s))))
            raise NotDevelopableError(
                f"Newton on F(t, s) = 0 failed at λ={lam[bad]:.9g} (t={t[bad]:.9g}, s={s[bad]:.9g}) of the traced branch"
            )
        if k >= 2:
            p = self.pair.parts(t, s, 2)
        Ft, Fs = p["Ft"], p["Fs"]
        den = Fs - Ft
        with np.errstate(divide="ignore", invalid="ignore"):
            tp = 2 * Fs / den
            sp = 2.0 - tp
            out_t, out_s = [t, tp], [s, sp]
            if k >= 2:
                dFt = p["Ftt"] * tp + p["Fts"] * sp
                dFs = p["Fts"] * tp + p["Fss"] * sp
                tpp = 2 * (Fs * dFt - Ft * dFs) / den**2
                out_t.append(tpp)
                out_s.append(-tpp)
        bad = ~np.all(np.isfinite(np.vstack(out_t[1:])), axis=0)
        if bad.any():
            # where the rails meet (a zero ruling at a branch end, F singular): the derivatives'
            # limits, taken inside the branch: t' at 1e-8 of the branch (F's partials are O(|g|)
            # there, t' good to ~1e-8); t'' (a quotient of O(|g|²) differences) at 1e-3
            span = self.lam1 - self.lam0
            for r in range(1, len(out_t)):
                d = 1e-8 if r == 1 else 1e-3
                nudged = np.clip(lam[bad], self.lam0 + d * span, self.lam1 - d * span)
                if np.any(nudged == lam[bad]):
                    raise NotDevelopableError(f"F is singular on the traced branch at λ={lam[bad][0]:.9g}")
                sub_t, sub_s, _ = self.main(nudged, r)
                out_t[r][bad] = sub_t[r]
                out_s[r][bad] = sub_s[r]
        res = (out_t, out_s, p)
        if len(self._cache) > 8:
            self._cache.clear()
        self._cache[key] = res
        return res


class LoftSegment(RuledSurface):
    r"""One piece of a developable loft: a fan (cone with apex at a rail end) or the main part.

    ``X(u, v) = (1-v) a(t(λ)) + v b(s(λ))``, ``λ = λ0 + u (λ1 - λ0)``, u ∈ [0, 1], with the path
    of the loft in the (t, s) square (module doc). ``kind`` is ``"fan_a"`` (apex on rail a: t
    constant), ``"fan_b"`` (apex on rail b: s constant) or ``"main"`` (the traced branch
    ``F(t, σ(t)) = 0``). ``a``, ``b`` are rail a and rail b in their given orientation.

    Attributes:
        kind, lam_range, t_range, s_range (parameters on the given rails), apex (3-D point or None).
    """

    def __init__(self, loft: "DevelopableLoft", kind: str, lam0: float, lam1: float, side: str | None = None) -> None:
        self._loft = loft
        self.kind = kind
        self.side = side  # for fans: "s=0", "t=0", "t=1", "s=1"
        self.lam_range = (float(lam0), float(lam1))

    # path parameters (internal orientation: rail b possibly reversed)
    def _ts(self, u: np.ndarray, k: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
        lam0, lam1 = self.lam_range
        dl = lam1 - lam0
        lam = lam0 + u * dl
        if self.kind == "main":
            tt, ss, _ = self._loft._path.main(lam, k)
        else:
            z = np.zeros_like(lam)
            one = np.ones_like(lam)
            if self.side == "s=0":
                tt, ss = [2 * lam, 2 * one], [z, z]
            elif self.side == "t=0":
                tt, ss = [z, z], [2 * lam, 2 * one]
            elif self.side == "t=1":
                tt, ss = [one, z], [2 * lam - 1.0, 2 * one]
            else:  # s=1
                tt, ss = [2 * lam - 1.0, 2 * one], [one, z]
            tt = tt + [z] * k
            ss = ss + [z] * k
        tt = [np.clip(tt[0], 0.0, 1.0)] + [tt[r] * dl**r for r in range(1, k + 1)]
        ss = [np.clip(ss[0], 0.0, 1.0)] + [ss[r] * dl**r for r in range(1, k + 1)]
        return tt, ss

    @staticmethod
    def _compose(rail: Any, x: list[np.ndarray], r: int) -> np.ndarray:
        """``d^r/du^r rail(x(u))`` for r = 0, 1, 2 (Faà di Bruno)."""
        if r == 0:
            return rail.derivative(x[0], 0)
        if r == 1:
            return rail.derivative(x[0], 1) * x[1][:, None]
        if r == 2:
            J = _jet(rail, x[0], 2)
            return J[2] * (x[1] ** 2)[:, None] + J[1] * x[2][:, None]
        raise GHTError(f"derivative={r!r} is not allowed; loft segments give derivatives of order 0..2")

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        tt, _ = self._ts(uu, derivative)
        return self._compose(self._loft._pair.ra, tt, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        _, ss = self._ts(uu, derivative)
        return self._compose(self._loft._pair.rb, ss, derivative)

    def ruling(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``g = b - a``; near a corner where the rails meet (a pointed end) the ruling is the
        branch's own, integrated from the corner without cancellation (:meth:`_Pair.corner_branch`):
        the plain difference carries ``eps |a|``, i.e. the direction ``eps |a| / |g|``."""
        g = self.b(u, derivative) - self.a(u, derivative)
        path = self._loft._path
        if derivative or self.kind != "main" or not path.corner_ends:
            return g
        uu, _ = as_parameter_array(u, "u")
        lam0, lam1 = self.lam_range
        lam = lam0 + uu * (lam1 - lam0)
        near = path.near_corner(lam)
        if near is not None and near.any():
            g[near] = path.main(lam[near], 0)[2]["g"]
        return g

    def parameters(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        """Rail parameters ``(t, s)`` of the rulings at ``u`` (s on rail b as given)."""
        uu, _ = as_parameter_array(u, "u")
        tt, ss = self._ts(uu, 0)
        return tt[0], self._loft._given_s(ss[0])

    @property
    def t_range(self) -> tuple[float, float]:
        t, _ = self.parameters(np.array([0.0, 1.0]))
        return float(t[0]), float(t[1])

    @property
    def s_range(self) -> tuple[float, float]:
        _, s = self.parameters(np.array([0.0, 1.0]))
        return float(s[0]), float(s[1])

    @property
    def end_order(self) -> int:
        """Highest end derivative order that is exact at both ends: 2, or 1 where the rails meet
        at an end of the segment (a zero ruling: the second derivative there is a limit known to
        about 1e-3 only)."""
        g = self.ruling_lengths(np.array([0.0, 1.0]))
        return 1 if float(g.min()) <= 1e-9 * self._loft._pair.size else 2

    @property
    def apex(self) -> np.ndarray | None:
        """The cone apex (a rail end) of a fan; None for the main part."""
        if self.kind == "fan_a":
            return self.a(np.array([0.5]))[0]
        if self.kind == "fan_b":
            return self.b(np.array([0.5]))[0]
        return None

    def __repr__(self) -> str:
        t0, t1 = self.t_range
        s0, s1 = self.s_range
        return f"LoftSegment({self.kind}, t=[{t0:.6g}, {t1:.6g}], s=[{s0:.6g}, {s1:.6g}])"


# ----------------------------------------------------------------------------------------------
# report
# ----------------------------------------------------------------------------------------------
@dataclass
class LoftReport:
    r"""What the loft construction found (spec section 5.7).

    Attributes:
        reversed_b: rail b was traced reversed (the rails run opposite ways).
        branch_start, branch_end: (t, s) where the branch meets the lower-left / upper-right sides
            (s on rail b as given).
        nodes: number of traced branch nodes (predictor–corrector steps + 1).
        segments: per segment: kind, t and s ranges, apex, area.
        area: 3-D area of the loft; fan_area, fan_share = fan_area / area.
        theta_max_deg: max θ over ``samples`` rulings per segment (round-off expected).
        f_residual_max: max ``|F| / (|a'||b'||b - a|)`` at those rulings.
        theta: (λ, t, s, θ in degrees) of the sampled rulings.
        degenerate_rulings: rulings with ``|b - a|`` below 1e-9 of the size, or a rail tangent
            parallel to the ruling (sine below 1e-9): dicts with t, s, kind, value.
        regression: sampled rulings with the edge of regression between the rails,
            ``v* = -((a' × g)·(g' × g)) / |g' × g|²`` in [0, 1]: dicts with t, s, v, point.
        regression_clearance: min over the sampled rulings of the distance of ``v*`` from [0, 1]
            (0 when the edge of regression meets the loft; inf for a cylinder-like loft).
        candidates: every branch tried: start, end, orientation, fan_share or why it was refused.
    """

    reversed_b: bool
    branch_start: tuple[float, float]
    branch_end: tuple[float, float]
    nodes: int
    segments: list[dict[str, Any]]
    area: float
    fan_area: float
    fan_share: float
    theta_max_deg: float
    f_residual_max: float
    theta: np.ndarray = field(repr=False)
    degenerate_rulings: list[dict[str, Any]] = field(default_factory=list)
    regression: list[dict[str, Any]] = field(default_factory=list)
    regression_clearance: float = math.inf
    candidates: list[dict[str, Any]] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        """Plain data (floats, lists, dicts) for JSON reports."""
        d = asdict(self)
        d["theta"] = np.asarray(self.theta).tolist()
        return _plain(d)

    def __str__(self) -> str:
        kinds = ", ".join(f"{s['kind']} t=[{s['t'][0]:.4g},{s['t'][1]:.4g}] s=[{s['s'][0]:.4g},{s['s'][1]:.4g}]"
                          for s in self.segments)
        return (
            f"developable loft: {len(self.segments)} segment(s) ({kinds}); fan share {self.fan_share:.4g}; "
            f"θ_max={self.theta_max_deg:.3g}°; |F| residual {self.f_residual_max:.2g}; "
            f"{len(self.degenerate_rulings)} degenerate ruling(s); edge of regression "
            + ("between the rails" if self.regression else f"clear (margin {self.regression_clearance:.3g})")
        )


def _plain(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    return x


# ----------------------------------------------------------------------------------------------
# the loft
# ----------------------------------------------------------------------------------------------
class DevelopableLoft(RuledSurface):
    r"""The exact developable loft between two rails (spec section 5.7), fans included.

    As a whole it is one ruled surface ``X(λ, v) = (1-v) a(t(λ)) + v b(s(λ))``, λ ∈ [0, 1]
    (``λ = (t + s)/2`` along the path from corner (0, 0) to (1, 1) of the (t, s) square, module
    doc), smooth inside each segment and G1 across the joint rulings (listed in
    ``breakpoints``), so :func:`ght_cad.unroll` gives one panel with bend lines along the
    rulings. ``segments`` are the fans and the main part in order along the rails.

    Do not construct directly: use :func:`developable_loft`.

    Attributes:
        rail_a, rail_b: the rails as given.
        segments: :class:`LoftSegment` list (RuledSurface instances).
        report: :class:`LoftReport`.
        breakpoints: λ of the joint rulings (inside (0, 1)).
    """

    def __init__(self, rail_a: Any, rail_b: Any, pair: _Pair, branch: _Branch, *, samples: int = 257,
                 candidates: Sequence[dict[str, Any]] = (), area_rtol: float = 1e-13) -> None:
        self.rail_a = rail_a
        self.rail_b = rail_b
        self._pair = pair
        self._branch = branch
        self.reversed_b = branch.reversed_b
        self._path = _Path(pair, branch)
        (t0, s0), (t1, s1) = branch.start, branch.end
        segs: list[LoftSegment] = []
        lam0, lam1 = self._path.lam0, self._path.lam1
        if t0 > MIN_FAN:
            segs.append(LoftSegment(self, "fan_b", 0.0, lam0, "s=0"))
        elif s0 > MIN_FAN:
            segs.append(LoftSegment(self, "fan_a", 0.0, lam0, "t=0"))
        if lam1 - lam0 > MIN_FAN:
            segs.append(LoftSegment(self, "main", lam0, lam1))
        if t1 < 1.0 - MIN_FAN:
            segs.append(LoftSegment(self, "fan_b", lam1, 1.0, "s=1"))
        elif s1 < 1.0 - MIN_FAN:
            segs.append(LoftSegment(self, "fan_a", lam1, 1.0, "t=1"))
        self.segments: list[LoftSegment] = segs
        self._edges = np.array([segs[0].lam_range[0]] + [sg.lam_range[1] for sg in segs])
        self._edges[0], self._edges[-1] = 0.0, 1.0
        self.breakpoints = tuple(float(x) for x in self._edges[1:-1])
        self.report = self._make_report(samples, list(candidates), area_rtol)

    # -- parametrization -----------------------------------------------------------------
    def _given_s(self, s: np.ndarray) -> np.ndarray:
        return 1.0 - s if self.reversed_b else s

    def _dispatch(self, u: Any, fn: Callable[[LoftSegment, np.ndarray], np.ndarray]) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        idx = np.clip(np.searchsorted(self._edges, uu, side="right") - 1, 0, len(self.segments) - 1)
        out = np.empty((uu.size, 3))
        for i, sg in enumerate(self.segments):
            m = idx == i
            if m.any():
                lo, hi = self._edges[i], self._edges[i + 1]
                out[m] = fn(sg, (uu[m] - lo) / (hi - lo), hi - lo)
        return out

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Rail a along the loft: ``a(t(λ))`` and its λ-derivatives."""
        return self._dispatch(u, lambda sg, x, w: sg.a(x, derivative) / w**derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Rail b along the loft: ``b(s(λ))`` and its λ-derivatives."""
        return self._dispatch(u, lambda sg, x, w: sg.b(x, derivative) / w**derivative)

    def ruling(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``g = b - a`` (near a pointed end the segment's cancellation-free ruling, :meth:`LoftSegment.ruling`)."""
        if not self._path.corner_ends:
            return super().ruling(u, derivative)
        return self._dispatch(u, lambda sg, x, w: sg.ruling(x, derivative) / w**derivative)

    def parameters(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        """Rail parameters ``(t, s)`` of the rulings at loft parameters ``u`` (= λ)."""
        uu, _ = as_parameter_array(u, "u")
        ts = self._dispatch(uu, lambda sg, x, w: np.column_stack([*sg.parameters(x), np.zeros(x.size)]))
        return ts[:, 0], ts[:, 1]

    def sigma(self, t: Any) -> np.ndarray:
        r"""``s = σ(t)``: the parameter on rail b (as given) of the ruling from ``a(t)``.

        On the main part ``F(t, σ(t)) = 0`` solved by Newton in s to round-off; where a(t) is
        covered by a fan with apex on rail b it is that apex's parameter (0 or 1); at an end of
        rail a that is a fan apex itself, the end of the branch.
        """
        tt, scalar = as_parameter_array(t, "t")
        if np.any((tt < 0) | (tt > 1)) or not np.all(np.isfinite(tt)):
            raise GHTError("t must be finite and in [0, 1]")
        br = self._branch
        (t0, s0), (t1, s1) = br.start, br.end
        s = np.interp(tt, br.t, br.s)
        s = np.where(tt <= t0, s0 if t0 <= MIN_FAN else 0.0, s)
        s = np.where(tt >= t1, s1 if t1 >= 1 - MIN_FAN else 1.0, s)
        inner = (tt > t0) & (tt < t1)
        if inner.any():
            ti, si = tt[inner], s[inner]
            for _ in range(8):
                p = self._pair.parts(ti, si, 1)
                with np.errstate(divide="ignore", invalid="ignore"):
                    ds = np.where(p["Fs"] != 0, p["F"] / p["Fs"], 0.0)
                si = np.clip(si - ds, 0.0, 1.0)
                if np.all(np.abs(ds) <= 4 * _EPS):
                    break
            s[inner] = si
        out = self._given_s(s)
        return out[0] if scalar else out

    # -- measures ------------------------------------------------------------------------
    def developability(self, nodes: int = 64, samples: int = 257) -> Developability:
        """Developability degree of the whole loft, per segment combined (θ_max over all rulings;
        integrals weighted by the segments' λ-lengths)."""
        parts = [sg.developability(nodes, samples) for sg in self.segments]
        w = np.diff(self._edges)
        w = w / w.sum()
        th = [p.theta_max for p in parts if math.isfinite(p.theta_max)]
        return Developability(
            theta_max=max(th) if th else math.nan,
            theta_rms=float(math.sqrt(sum(wi * p.theta_rms**2 for wi, p in zip(w, parts) if math.isfinite(p.theta_rms)))),
            dd=float(sum(wi * p.dd for wi, p in zip(w, parts) if math.isfinite(p.dd))),
            R=float(sum(wi * p.R for wi, p in zip(w, parts) if math.isfinite(p.R))),
            residual_max=max(p.residual_max for p in parts),
        )

    def area(self) -> float:
        """3-D area, sum over the segments of ``∫∫ |(a' + v g') × g| dv du``."""
        from .unroll import ruled_area

        return float(sum(ruled_area(sg, rtol=1e-13) for sg in self.segments))

    def ruling_field(self, u: Any) -> dict[str, np.ndarray]:
        """Unit ruling direction ``d = g/|g|`` and its λ-derivative ``d' = (g' - d (d·g'))/|g|``."""
        uu, _ = as_parameter_array(u, "u")
        g = self.ruling(uu)
        g1 = self.ruling(uu, 1)
        L = np.linalg.norm(g, axis=1)
        d = g / L[:, None]
        d1 = (g1 - d * np.einsum("ij,ij->i", d, g1)[:, None]) / L[:, None]
        return {"d": d, "d1": d1, "length": L}

    def fairness(self, nodes: int = 32) -> float:
        r"""Fairness of the ruling field ``∫_0^1 |d'(λ)|² dλ`` (Gauss–Legendre per segment)."""
        x, w = gauss_legendre(nodes)
        tot = 0.0
        for i in range(len(self.segments)):
            lo, hi = self._edges[i], self._edges[i + 1]
            uu = lo + (hi - lo) * x
            d1 = self.ruling_field(uu)["d1"]
            tot += float(np.sum(w * (hi - lo) * np.sum(d1 * d1, axis=1)))
        return tot

    def regression_parameter(self, u: Any) -> np.ndarray:
        r"""``v* = -((a' × g)·(g' × g)) / |g' × g|²``: where on the ruling ``X = a + v g`` the
        surface is singular (the edge of regression); ±inf where ``g' × g = 0`` (cylinder-like)."""
        uu, _ = as_parameter_array(u, "u")
        return regression_v(self.a(uu, 1), self.ruling(uu), self.ruling(uu, 1))

    def bspline_data(self, tol: float | None = None, degree: int = 5, theta_tol_deg: float = 1e-3) -> list[Any]:
        r"""Plain-data B-spline surfaces, one per segment (poles, knots, degrees; degree 1 across
        the rulings), from :func:`ght_cad.developable.developable_bspline`: the boundary curves are
        fitted together (compatible poles) with ``max_u |f(u) - F(u)| <= max_deviation <= tol``,
        so the faces' edges lie on the rails within ``max_deviation`` (the certified tolerance) and
        joint rulings are exact end poles."""
        from .developable import developable_bspline

        return [developable_bspline(sg, tol=tol, degree=degree, theta_tol_deg=theta_tol_deg, end_order=sg.end_order)
                for sg in self.segments]

    def to_dict(self, tol: float | None = None, degree: int = 5) -> dict[str, Any]:
        """Plain data: the report and per segment the B-spline data (poles, knots, degrees)."""
        segs = []
        for sg, data in zip(self.segments, self.bspline_data(tol=tol, degree=degree)):
            segs.append({
                "kind": sg.kind,
                "t_range": list(sg.t_range),
                "s_range": list(sg.s_range),
                "poles": np.asarray(data.poles).tolist(),
                "knots_u": np.asarray(data.knots_u).tolist(),
                "knots_v": np.asarray(data.knots_v).tolist(),
                "degree_u": int(data.degree_u),
                "degree_v": int(data.degree_v),
                "max_deviation": float(data.max_deviation),
            })
        return {"report": self.report.as_dict(), "segments": segs}

    def to_face(self, tol: float | None = None, **kwargs: Any) -> Any:
        """A build123d ``Shell`` of one B-spline face per segment sewn along the joint rulings
        (:func:`ght_cad.cad.developable_faces.composite_shell`; needs build123d)."""
        from .cad.developable_faces import composite_shell

        return composite_shell(self.segments, tol=tol, **kwargs)

    def joint_folds(self) -> list[dict[str, float]]:
        r"""Joint rulings where the surface folds back (a fan lying over the main part).

        At a joint ruling the segments share the tangent plane; the loft continues across it iff
        the normals ``N = X_λ × g`` at mid-ruling (``X_λ = a' + g'/2``) on both sides point the same
        way, ``N_left · N_right > 0``. Returns the folded joints (λ, t, s of the joint).
        """
        out = []
        one, zero = np.array([1.0]), np.array([0.0])
        for i in range(len(self.segments) - 1):
            L, R = self.segments[i], self.segments[i + 1]
            nl = np.cross(0.5 * (L.a(one, 1) + L.b(one, 1)), L.ruling(one))[0]
            nr = np.cross(0.5 * (R.a(zero, 1) + R.b(zero, 1)), R.ruling(zero))[0]
            if float(np.dot(nl, nr)) < 0:
                t, s = L.parameters(one)
                out.append({"lam": L.lam_range[1], "t": float(t[0]), "s": float(s[0])})
        return out

    def __repr__(self) -> str:
        return f"DevelopableLoft({', '.join(sg.kind for sg in self.segments)}; fan share {self.report.fan_share:.3g})"

    # -- report --------------------------------------------------------------------------
    def _make_report(self, samples: int, candidates: list[dict[str, Any]], area_rtol: float) -> LoftReport:
        from .unroll import ruled_area
        from .ruled import _theta

        size = self._pair.size
        seg_info = []
        area = fan_area = 0.0
        rows = []
        degenerate: list[dict[str, Any]] = []
        regression: list[dict[str, Any]] = []
        clearance = math.inf
        fres = 0.0
        for i, sg in enumerate(self.segments):
            ar = ruled_area(sg, rtol=area_rtol)
            area += ar
            if sg.kind != "main":
                fan_area += ar
            apex = sg.apex
            seg_info.append({
                "kind": sg.kind,
                "t": list(sg.t_range),
                "s": list(sg.s_range),
                "lam": list(sg.lam_range),
                "apex": None if apex is None else apex.tolist(),
                "area": ar,
            })
            u = np.linspace(0.0, 1.0, samples)
            a0, a1 = sg.a(u), sg.a(u, 1)
            b0, b1 = sg.b(u), sg.b(u, 1)
            g = b0 - a0
            th, _ = _theta(a1, b1, g)
            lam = sg.lam_range[0] + u * (sg.lam_range[1] - sg.lam_range[0])
            t, s = sg.parameters(u)
            rows.append(np.column_stack([lam, t, s, th]))
            if sg.kind == "main":
                tt, ss, _ = self._path.main(lam, 0)
                fres = max(fres, float(np.max(np.abs(self._pair.f(tt[0], ss[0])))))
            L = np.linalg.norm(g, axis=1)
            # degenerate rulings: zero length or a rail tangent along the ruling
            sin_a = _sine(self._pair.ra.derivative(np.clip(t, 0, 1), 1), g)
            sin_b = _sine(self._pair.rb.derivative(np.clip(self._given_s(s), 0, 1), 1), g)
            for j in range(u.size):
                if L[j] <= 1e-9 * size:
                    degenerate.append({"t": float(t[j]), "s": float(s[j]), "kind": "zero length", "value": float(L[j])})
                elif sin_a[j] <= 1e-9 or sin_b[j] <= 1e-9:
                    which = "rail_a" if sin_a[j] <= sin_b[j] else "rail_b"
                    degenerate.append({"t": float(t[j]), "s": float(s[j]), "kind": f"{which} tangent along the ruling",
                                       "value": float(min(sin_a[j], sin_b[j]))})
            vs = regression_v(a1, g, b1 - a1)
            # a cone's apex on a rail (a stationary side: v* = 0 with a' = 0, v* = 1 with b' = 0) is
            # the edge of regression of a fan (or of a planar triangle), not a defect between the rails
            g1n = np.linalg.norm(b1 - a1, axis=1)
            apex = ((np.linalg.norm(a1, axis=1) <= 1e-9 * g1n) & (np.abs(vs) <= 1e-6)) | (
                (np.linalg.norm(b1, axis=1) <= 1e-9 * g1n) & (np.abs(vs - 1) <= 1e-6))
            vs = np.where(apex, np.inf, vs)
            fin = np.isfinite(vs)
            if fin.any():
                dist = np.where(vs < 0, -vs, np.where(vs > 1, vs - 1, 0.0))[fin]
                clearance = min(clearance, float(dist.min()))
                inside = np.flatnonzero(fin & (vs >= 0) & (vs <= 1))
                for j in inside:
                    regression.append({"t": float(t[j]), "s": float(s[j]), "v": float(vs[j]),
                                       "point": (a0[j] + vs[j] * g[j]).tolist()})
        theta = np.vstack(rows)
        fin = np.isfinite(theta[:, 3])
        theta_max = float(np.max(theta[fin, 3])) if fin.any() else math.nan
        start = (float(self._branch.t[0]), float(self._given_s(np.array([self._branch.s[0]]))[0]))
        end = (float(self._branch.t[-1]), float(self._given_s(np.array([self._branch.s[-1]]))[0]))
        return LoftReport(
            reversed_b=bool(self.reversed_b),
            branch_start=start,
            branch_end=end,
            nodes=int(self._branch.lam.size),
            segments=seg_info,
            area=area,
            fan_area=fan_area,
            fan_share=fan_area / area if area > 0 else math.nan,
            theta_max_deg=theta_max,
            f_residual_max=fres,
            theta=theta,
            degenerate_rulings=degenerate,
            regression=regression,
            regression_clearance=clearance,
            candidates=candidates,
        )


def _sine(x: np.ndarray, g: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        den = np.linalg.norm(x, axis=1) * np.linalg.norm(g, axis=1)
        return np.where(den > 0, np.linalg.norm(np.cross(x, g), axis=1) / np.where(den > 0, den, 1.0), 1.0)


# ----------------------------------------------------------------------------------------------
# entry point
# ----------------------------------------------------------------------------------------------
_ORIENTATIONS = ("auto", "same", "reversed")


def _max_distance(P: np.ndarray, rail: Any, t: np.ndarray, Q: np.ndarray) -> float:
    """max over the points P of their distance to the curve ``rail`` (samples Q at t): nearest
    sample, then Newton on ``(r(s) - p) · r'(s) = 0``."""
    s = t[np.argmin(np.linalg.norm(P[:, None, :] - Q[None, :, :], axis=2), axis=1)]
    for _ in range(4):
        r0, r1, r2 = rail.derivative(s, 0), rail.derivative(s, 1), rail.derivative(s, 2)
        e = r0 - P
        den = np.einsum("ij,ij->i", r1, r1) + np.einsum("ij,ij->i", e, r2)
        with np.errstate(divide="ignore", invalid="ignore"):
            ds = np.where(den > 0, np.einsum("ij,ij->i", e, r1) / np.where(den > 0, den, 1.0), 0.0)
        s = np.clip(s - ds, 0.0, 1.0)
    return float(np.max(np.linalg.norm(rail.derivative(s, 0) - P, axis=1)))


def _check_rails(ra: Any, rb: Any, samples: int = 129) -> float:
    """Sample both rails: finite values, regular tangents, not coincident; returns the size."""
    t = np.linspace(0.0, 1.0, samples)
    pts = {}
    for name, r in (("rail_a", ra), ("rail_b", rb)):
        try:
            P = r.derivative(t, 0)
            D = r.derivative(t, 1)
        except GHTError:
            raise
        except Exception as exc:  # a user callable failing: say which rail
            raise GHTError(f"{name} could not be evaluated on t ∈ [0, 1]: {type(exc).__name__}: {exc}") from exc
        for what, arr in (("position", P), ("derivative", D)):
            bad = ~np.all(np.isfinite(arr), axis=1)
            if bad.any():
                i = int(np.argmax(bad))
                raise GHTError(f"{name} {what} is not finite at t={t[i]:.6g}: {arr[i].tolist()}; rails must be finite")
        ext = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
        speed = np.linalg.norm(D, axis=1)
        if ext <= 0 or not np.any(speed > 0):
            raise DegenerateGeometryError(f"{name} is a single point {P[0].tolist()}; a rail must be a curve of positive length")
        pts[name] = (P, speed, ext)
    Pa, sa, ea = pts["rail_a"]
    Pb, sb, eb = pts["rail_b"]
    allp = np.vstack([Pa, Pb])
    size = float(np.linalg.norm(allp.max(axis=0) - allp.min(axis=0)))
    for name, sp in (("rail_a", sa), ("rail_b", sb)):
        low = sp <= 1e-9 * size
        if low.any():
            i = int(np.argmax(low))
            raise DegenerateGeometryError(
                f"{name} has a zero tangent (|r'| = {sp[i]:.3g}) at t={t[i]:.6g}; a loft needs regular rails "
                "(split the rail there or re-parametrize it)"
            )
    if _max_distance(Pa, rb, t, Pb) <= 1e-9 * size and _max_distance(Pb, ra, t, Pa) <= 1e-9 * size:
        raise DegenerateGeometryError("rail_a and rail_b coincide (every point of one lies on the other); give two distinct rails")
    return size


def developable_loft(
    rail_a: Any,
    rail_b: Any,
    *,
    orientation: str = "auto",
    branch: str | int = "auto",
    max_step: float = 1.0 / 16,
    step_tol: float = 2e-3,
    samples: int = 257,
    boundary_samples: int = 513,
    sign_png: Any = None,
) -> DevelopableLoft:
    r"""The exact developable loft between two rails (spec section 5.7).

    Traces the branch of ``F(t, s) = det(a'(t), b'(s), b(s) - a(t)) = 0`` from a zero of F on a
    lower-left side of the (t, s) square (s = 0 or t = 0) as an increasing ``s = σ(t)`` by
    predictor–corrector continuation in ``λ = (t + s)/2`` with Newton correction to round-off, to
    an upper-right side, and adds fans (cones with apex at a rail end) along the sides so both
    rails are covered over [0, 1] (module doc).

    Args:
        rail_a, rail_b: GHTCurve objects, :class:`CallableRail` or objects with ``evaluate(t)``
            and ``derivative(t, order)`` on [0, 1] (see :func:`as_rail`).
        orientation: ``"same"`` (s increases with t), ``"reversed"`` (rail b is traced from its
            end: s decreases with t) or ``"auto"``: both, keep the better branch.
        branch: ``"auto"`` keeps, among the branches that join the lower-left to the upper-right
            sides, the one without an edge of regression between the rails and with the smallest
            fan share; an integer picks ``report.candidates[i]`` (in the order they were found).
        max_step: largest continuation step in λ.
        step_tol: largest corrector displacement (in t + s) of an accepted step.
        samples: rulings per segment sampled for the report (θ, degenerate rulings, regression).
        boundary_samples: samples per side when looking for the zeros of F on the lower-left sides.
        sign_png: a path; when no loft exists, :func:`plot_loft_sign` writes the sign of F there
            before the error is raised (the message names the file).

    Returns:
        :class:`DevelopableLoft` with ``segments``, ``report``, ``sigma``, ``developability``.

    Raises:
        NotDevelopableError: no branch of F = 0 joins the rails over their whole length (the
            message says where the branches go; :func:`plot_loft_sign` draws the sign of F).
        DegenerateGeometryError: coincident rails, a rail that is a point or has a zero tangent,
            coplanar rails (F ≡ 0).
        GHTError: bad options or rails that cannot be evaluated.
    """
    if orientation not in _ORIENTATIONS:
        raise GHTError(f"orientation={orientation!r} is not allowed; use one of {_ORIENTATIONS}")
    if not (branch == "auto" or (isinstance(branch, (int, np.integer)) and not isinstance(branch, bool) and branch >= 0)):
        raise GHTError(f"branch={branch!r} is not allowed; use 'auto' or a candidate index >= 0")
    for nm, v, lo, hi in (("max_step", max_step, 1e-6, 0.5), ("step_tol", step_tol, 1e-8, 0.1)):
        if not (is_real(v) and math.isfinite(v) and lo <= v <= hi):
            raise GHTError(f"{nm}={v!r} is not allowed; it must be a number in [{lo:g}, {hi:g}]")
    for nm, v, lo in (("samples", samples, 9), ("boundary_samples", boundary_samples, 17)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise GHTError(f"{nm}={v!r} is not allowed; it must be an integer >= {lo}")
    ra = as_rail(rail_a, "rail_a")
    rb = as_rail(rail_b, "rail_b")
    size = _check_rails(ra, rb)
    orients = {"auto": (False, True), "same": (False,), "reversed": (True,)}[orientation]
    found: list[tuple[_Pair, _Branch]] = []
    cands: list[dict[str, Any]] = []
    zero_everywhere = True
    for rev in orients:
        pair = _Pair(ra, _Reversed(rb) if rev else rb, size)
        grid = np.linspace(0.0, 1.0, 33)
        T, S = np.meshgrid(grid, grid, indexing="ij")
        fv = pair.f(T.ravel(), S.ravel())
        if np.max(np.abs(fv)) > 1e-10:
            zero_everywhere = False
        for start in _boundary_roots(pair, boundary_samples):
            given = (start[0], 1.0 - start[1] if rev else start[1])
            entry: dict[str, Any] = {"orientation": "reversed" if rev else "same", "start": list(given)}
            try:
                br = _trace(pair, start, rev, max_step, step_tol)
            except _TraceFailure as exc:
                entry["refused"] = str(exc) if not rev else str(exc) + " (rail_b reversed: s there is 1 - s on rail_b)"
                cands.append(entry)
                continue
            entry["end"] = [br.end[0], 1.0 - br.end[1] if rev else br.end[1]]
            entry["index"] = len(found)
            found.append((pair, br))
            cands.append(entry)
    if zero_everywhere:
        raise DegenerateGeometryError(
            "F(t, s) = det(a', b', b - a) vanishes on the whole square: the rails are coplanar (every ruled "
            "surface between them is planar); use a planar face instead of a loft"
        )
    def refuse() -> NotDevelopableError:
        msg = _no_branch_message(ra, rb, size, cands, orients)
        if sign_png is not None:
            path = plot_loft_sign(ra, rb, sign_png)
            msg = msg.replace("ght_cad.loft.plot_loft_sign(rail_a, rail_b, 'sign.png') draws", f"{path} shows")
        return NotDevelopableError(msg)

    if not found:
        raise refuse()
    lofts = []
    # with several candidates, rank them on a coarse report (65 rulings, areas to 1e-9) and build
    # the full report for the chosen one only
    coarse = branch == "auto" and len(found) > 1
    for i, (pair, br) in enumerate(found):
        if branch != "auto" and i != branch:
            continue
        try:
            lf = DevelopableLoft(rail_a, rail_b, pair, br, samples=min(samples, 65) if coarse else samples,
                                 candidates=cands, area_rtol=1e-9 if coarse else 1e-13)
            lf._index = i
            folds = lf.joint_folds()
            if folds:
                raise NotDevelopableError(
                    "the fans fold back over the main part at the joint ruling(s) "
                    + ", ".join(f"t={f['t']:.6g}, s={f['s']:.6g}" for f in folds)
                )
            lofts.append(lf)
        except NotDevelopableError as exc:
            for c in cands:
                if c.get("index") == i:
                    c["refused"] = str(exc)
    if branch != "auto" and not lofts:
        raise GHTError(f"branch={branch} is not a usable candidate; candidates: {cands}")
    if not lofts:
        raise refuse()
    for lf in lofts:
        for c in cands:
            if c.get("index") == lf._index:
                c["fan_share"] = lf.report.fan_share
                c["regression_inside"] = bool(lf.report.regression)
    best = min(lofts, key=lambda lf: (bool(lf.report.regression), round(lf.report.fan_share, 9),
                                      len(lf.segments)))
    if coarse:
        index = best._index
        best = DevelopableLoft(rail_a, rail_b, best._pair, best._branch, samples=samples, candidates=cands)
        best._index = index
        for c in cands:
            if c.get("index") == index:
                c["fan_share"] = best.report.fan_share
    best.report.candidates = cands
    return best


def _no_branch_message(ra: Any, rb: Any, size: float, cands: list[dict[str, Any]], orients: tuple[bool, ...]) -> str:
    what = "in either orientation of rail_b" if len(orients) == 2 else ("with rail_b reversed" if orients[0] else "with rail_b as given")
    head = (
        "no developable joins the rails over their whole length: no branch of F(t, s) = det(a'(t), b'(s), "
        f"b(s) - a(t)) = 0 runs from a lower-left side (t = 0 or s = 0) to an upper-right side (t = 1 or s = 1) "
        f"of the parameter square as an increasing curve, {what}"
    )
    if not cands:
        pair = _Pair(ra, rb, size)
        g = np.linspace(0.0, 1.0, 65)
        T, S = np.meshgrid(g, g, indexing="ij")
        f = pair.f(T.ravel(), S.ravel())
        pos = float(np.mean(f > 0))
        tail = (f"; F has no zero on the lower-left sides (F/(|a'||b'||b-a|) ranges over [{f.min():.3g}, {f.max():.3g}] "
                f"on the square, positive on {100 * pos:.0f}% of it)")
    else:
        tail = "; branches found: " + "; ".join(
            f"from (t, s) = ({c['start'][0]:.6g}, {c['start'][1]:.6g}) [{c['orientation']}]: {c.get('refused', 'refused')}"
            for c in cands
        )
    return head + tail + ". ght_cad.loft.plot_loft_sign(rail_a, rail_b, 'sign.png') draws the sign of F over the square."


def loft_function(rail_a: Any, rail_b: Any, t: Any, s: Any, *, normalized: bool = True) -> np.ndarray:
    r"""``F(t, s) = det(a'(t), b'(s), b(s) - a(t))`` (or ``F / (|a'||b'||b - a|)`` when normalized)
    at broadcast parameter arrays."""
    ra = as_rail(rail_a, "rail_a")
    rb = as_rail(rail_b, "rail_b")
    tt, ss = np.broadcast_arrays(np.asarray(t, float), np.asarray(s, float))
    pair = _Pair(ra, rb, 1.0)
    fn = pair.f if normalized else pair.F
    return fn(tt.ravel(), ss.ravel()).reshape(tt.shape)


def plot_loft_sign(rail_a: Any, rail_b: Any, path: Any, *, loft: DevelopableLoft | None = None, resolution: int = 241) -> Any:
    r"""PNG of the sign of ``F(t, s) = det(a'(t), b'(s), b(s) - a(t))`` over the (t, s) square.

    Blue where F < 0, red where F > 0: the zero set (the boundary between the colours) holds the
    possible rulings; a developable loft over the whole rails is an increasing branch from the
    lower-left to the upper-right sides. With ``loft`` its path (fans along the sides, the traced
    branch) is drawn in black. 800 x 800 pixels, written atomically (:mod:`ght_cad.plotting`
    conventions: Agg canvas, no pyplot).

    Returns:
        The written path.
    """
    from .plotting import DPI, _save
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or resolution < 9:
        raise GHTError(f"resolution={resolution!r} is not allowed; it must be an integer >= 9")
    ra = as_rail(rail_a, "rail_a")
    rb = as_rail(rail_b, "rail_b")
    g = np.linspace(0.0, 1.0, resolution)
    T, S = np.meshgrid(g, g, indexing="ij")
    f = _Pair(ra, rb, 1.0).f(T.ravel(), S.ravel()).reshape(T.shape)
    fig = Figure(figsize=(800 / DPI, 800 / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.pcolormesh(g, g, np.sign(f).T, cmap=ListedColormap(["#4a7bd0", "#f0f0f0", "#d05a4a"]), vmin=-1, vmax=1, shading="nearest")
    ax.contour(g, g, f.T, levels=[0.0], colors="#303030", linewidths=0.6)
    if loft is not None:
        lam = np.linspace(0.0, 1.0, 801)
        t, s = loft.parameters(lam)
        ax.plot(t, s, color="black", lw=2.2, label="loft path (fans on the sides)")
        ax.legend(loc="upper left")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.set_aspect("equal")
    ax.set_xlabel("t (rail_a)")
    ax.set_ylabel("s (rail_b)")
    ax.set_title("sign of F(t, s) = det(a', b', b - a): red > 0, blue < 0")
    return _save(fig, path)


# ----------------------------------------------------------------------------------------------
# objectives for optimizing GHT rails' shape parameters
# ----------------------------------------------------------------------------------------------
LOFT_OBJECTIVES = ("fan_share", "fairness", "regression")


def _regression_penalty(loft: DevelopableLoft, margin: float, nodes: int = 32) -> float:
    r"""``∫_0^1 max(0, 1 - c(λ)/margin)² dλ`` with ``c`` the distance of ``v*(λ)`` from [0, 1]
    (fans' apexes excluded: a cone's apex on its rail is not an edge of regression between the
    rails)."""
    x, w = gauss_legendre(nodes)
    tot = 0.0
    for i, sg in enumerate(loft.segments):
        lo, hi = loft._edges[i], loft._edges[i + 1]
        if sg.kind != "main":
            continue
        vs = regression_v(sg.a(x, 1), sg.ruling(x), sg.ruling(x, 1))
        c = np.where(vs < 0, -vs, np.where(vs > 1, vs - 1, 0.0))
        c = np.where(np.isfinite(vs), c, np.inf)
        tot += float(np.sum(w * (hi - lo) * np.maximum(0.0, 1.0 - c / margin) ** 2))
    return tot


class LoftProblem(Problem):
    r"""Objectives of the developable loft over the shape parameters of two GHT rails.

    Parameters ``a.mu, a.nu, a.gamma, b.mu, b.nu, b.gamma``; for each candidate the loft is built
    (:func:`developable_loft`) and the objective is the weighted sum of

    * ``fan_share``: fan area / loft area (0 = rulings end to end),
    * ``fairness``: ``∫_0^1 |d'(λ)|² dλ``, d the unit ruling direction,
    * ``regression``: ``∫ max(0, 1 - c/margin)² dλ``, c the distance of the edge of regression
      parameter ``v*`` from [0, 1] on the main part (0 when it stays ``margin`` away),

    ``+inf`` where no loft exists (infeasible candidate). Usable with
    :func:`ght_cad.optimize.minimize` (``problem(X) -> (pop,)``); it has the attributes of
    :class:`ght_cad.optimize.problems.Problem` (names, lb, ub, x0, build, report).

    Gradients (:meth:`value_and_grad`, used by ``method="hybrid"``, spec 8.1): exact where the
    loft's structure is locally fixed (same chosen branch and orientation, same fans):
    :func:`loft_measures_and_gradients`. Where it is not, the objective itself is not
    differentiable and the gradient is as follows:

    * a branch end within ``MIN_FAN`` of a corner of the (t, s) square where F does not vanish (a
      fan appears or vanishes; for GHT rails the end tangents are ``∝ P_1 - P_0``, so F at a corner
      vanishes for all shape parameters or for none and this is a coincidence of measure zero) and
      a non-finite derivative (a zero ruling where the rails meet: ``|d'|²`` is a limit there;
      ``F_s = F_t`` on the branch): forward finite differences, reason in :attr:`fallbacks`,
      evaluations in :attr:`fallback_nfev`;
    * a switch of the chosen branch or orientation between candidates (:func:`developable_loft`
      ranks them), or the regression penalty where ``v*`` touches [0, 1] (a kink): not detected;
      the gradient is that of the loft built at the point (one-sided).
    

    Args:
        rail_a, rail_b: 3-D GHTCurve objects with the 'ght' seed.
        objective: a name of :data:`LOFT_OBJECTIVES` or a mapping name -> weight.
        free, bounds: as in :class:`ght_cad.optimize.problems.Problem`.
        margin: regression margin (fraction of the ruling length).
        loft_options: passed to :func:`developable_loft`.
    """

    label = "loft"

    def __init__(
        self,
        rail_a: GHTCurve,
        rail_b: GHTCurve,
        objective: str | Mapping[str, float] = "fan_share",
        free: Sequence[str] | None = None,
        bounds: Mapping[str, tuple[float, float]] | None = None,
        *,
        margin: float = 0.25,
        loft_options: Mapping[str, Any] | None = None,
    ) -> None:
        for nm, c in (("rail_a", rail_a), ("rail_b", rail_b)):
            if not isinstance(c, GHTCurve) or c.dim != 3:
                raise GHTError(f"{nm} must be a 3-D GHTCurve to optimize its shape parameters, got {c!r}")
            if c.seed.name != "ght":
                raise GHTError(f"{nm} uses seed {c.seed.name!r}; shape-parameter problems need the 'ght' seed")
        if isinstance(objective, str):
            objective = {objective: 1.0}
        weights = dict(objective)
        for k, v in weights.items():
            if k not in LOFT_OBJECTIVES:
                raise GHTError(f"loft objective {k!r} is unknown; allowed: {', '.join(LOFT_OBJECTIVES)}")
            if not (is_real(v) and math.isfinite(v) and v >= 0):
                raise GHTError(f"weight {k}={v!r} is not allowed; weights are finite numbers >= 0")
        if not any(v > 0 for v in weights.values()):
            raise GHTError(f"objective={objective!r} has no positive weight")
        if not (is_real(margin) and math.isfinite(margin) and margin > 0):
            raise GHTError(f"margin={margin!r} is not allowed; it must be a finite number > 0")
        names = [f"{r}.{p}" for r in ("a", "b") for p in ("mu", "nu", "gamma")]
        super().__init__(names, list(rail_a.shape_parameters) + list(rail_b.shape_parameters), free, bounds)
        self.rail_a, self.rail_b = rail_a, rail_b
        self.weights = weights
        self.margin = float(margin)
        self.loft_options = dict(loft_options or {"samples": 33})
        self.label = "loft " + "+".join(weights)

    def rails(self, x: Any) -> tuple[GHTCurve, GHTCurve]:
        """The two rails for free parameters ``x``."""
        p = self.parameters(x)
        a = GHTCurve(self.rail_a.control_points, p["a.mu"], p["a.nu"], p["a.gamma"])
        b = GHTCurve(self.rail_b.control_points, p["b.mu"], p["b.nu"], p["b.gamma"])
        return a, b

    def _rails_full(self, row: np.ndarray) -> tuple[GHTCurve, GHTCurve]:
        return (GHTCurve(self.rail_a.control_points, *row[:3]), GHTCurve(self.rail_b.control_points, *row[3:]))

    def measures_of(self, loft: DevelopableLoft) -> dict[str, float]:
        """fan_share, fairness and regression of one loft."""
        return {
            "fan_share": float(loft.report.fan_share),
            "fairness": loft.fairness(),
            "regression": _regression_penalty(loft, self.margin),
        }

    def evaluate_full(self, F: np.ndarray) -> np.ndarray:
        out = np.empty(F.shape[0])
        for i, row in enumerate(F):
            try:
                if not np.all(np.abs(row) <= 1.0):
                    raise GHTError("outside the box")
                lf = developable_loft(*self._rails_full(row), **self.loft_options)
                m = self.measures_of(lf)
                out[i] = sum(w * m[k] for k, w in self.weights.items())
            except GHTError:
                out[i] = math.inf
        return np.where(np.isfinite(out), out, np.inf)

    #: exact gradients where the loft's structure is locally fixed, finite differences elsewhere
    has_gradient = True
    #: finite-difference step (box units) of the fallback
    fd_step = 1e-7

    def gradient_of(self, loft: DevelopableLoft, rail_a: GHTCurve, rail_b: GHTCurve) -> np.ndarray:
        r"""Exact gradient (6,) of the weighted objective of ``loft`` built from ``rail_a``, ``rail_b``
        with respect to ``(a.μ, a.ν, a.γ, b.μ, b.ν, b.γ)`` (:func:`loft_measures_and_gradients`).

        Raises:
            LoftGradientFallback: the loft's structure is not locally fixed (see there).
        """
        _, g = loft_measures_and_gradients(loft, rail_a, rail_b, self.margin)
        return sum(w * g[k] for k, w in self.weights.items())

    def value_and_grad_full(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r"""Values (pop,) (those of :meth:`evaluate_full`) and gradients (pop, 6).

        Exact (:meth:`gradient_of`: implicit-function derivative of the traced branch plus the
        moving-breakpoint terms) where the loft's structure is locally fixed; for a candidate where
        it is not (:class:`LoftGradientFallback`: a branch end at a box corner where F does not
        vanish, a zero ruling, F_s = F_t) forward differences of step :attr:`fd_step` inwards
        (6 more lofts; counted in :attr:`fallback_nfev`, the reason in :attr:`fallbacks`). ``0`` where
        the value is ``+inf``.
        """
        F = np.atleast_2d(np.asarray(F, dtype=float))
        out = np.empty(F.shape[0])
        G = np.zeros(F.shape)
        for i, row in enumerate(F):
            try:
                if not np.all(np.abs(row) <= 1.0):
                    raise GHTError("outside the box")
                ca, cb = self._rails_full(row)
                lf = developable_loft(ca, cb, **self.loft_options)
                m = self.measures_of(lf)
                out[i] = sum(w * m[k] for k, w in self.weights.items())
            except GHTError:
                out[i] = math.inf
                continue
            if not math.isfinite(out[i]):
                out[i] = math.inf
                continue
            try:
                with np.errstate(all="ignore"):
                    G[i] = self.gradient_of(lf, ca, cb)
            except LoftGradientFallback as exc:
                self.fallbacks.append(str(exc))
                steps = np.where(row + self.fd_step <= 1.0, self.fd_step, -self.fd_step)
                Xs = np.repeat(row[None, :], 6, axis=0) + np.diag(steps)
                fs = self.evaluate_full(Xs)
                self.fallback_nfev += 6
                with np.errstate(invalid="ignore"):
                    G[i] = np.where(np.isfinite(fs), (fs - out[i]) / steps, 0.0)
        return out, G

    @property
    def fallbacks(self) -> list[str]:
        """Why :meth:`value_and_grad_full` used finite differences, per fallback candidate."""
        if not hasattr(self, "_fallbacks"):
            self._fallbacks: list[str] = []
        return self._fallbacks

    @property
    def fallback_nfev(self) -> int:
        """Loft evaluations spent on finite-difference fallbacks (not counted by the optimizer)."""
        return int(getattr(self, "_fallback_nfev", 0))

    @fallback_nfev.setter
    def fallback_nfev(self, v: int) -> None:
        self._fallback_nfev = int(v)

    def build(self, x: Any) -> DevelopableLoft:
        """The loft for free parameters ``x``."""
        return developable_loft(*self.rails(x), **self.loft_options)

    def report(self, x: Any) -> dict[str, float]:
        """The objective and all three measures at ``x`` (inf where no loft exists)."""
        try:
            lf = self.build(x)
        except GHTError:
            return {"objective": math.inf, **{k: math.inf for k in LOFT_OBJECTIVES}}
        m = self.measures_of(lf)
        return {"objective": sum(w * m[k] for k, w in self.weights.items()), **m}


# ----------------------------------------------------------------------------------------------
# exact shape-parameter gradients of the loft objectives (spec 8.1)
# ----------------------------------------------------------------------------------------------
class LoftGradientFallback(GHTError):
    """The loft's structure is not locally fixed at this candidate (no exact gradient): the reason."""


def _rail_parameter_jets(curve: GHTCurve, t: np.ndarray, k: int, reverse: bool) -> list[np.ndarray]:
    r"""``∂r^(q)/∂(μ, ν, γ)`` at ``t`` for q = 0..k, each (3, N, 3) (closed form,
    :class:`ght_cad.optimize.problems.CurveParameterJets`); for the reversed rail ``r~(s) = r(1-s)``,
    ``∂r~^(q)(s) = (-1)^q ∂r^(q)(1-s)``."""
    from .optimize.problems import CurveParameterJets

    x = 1.0 - t if reverse else t
    J = CurveParameterJets(x, curve.control_points, k)(np.array([curve.mu]), np.array([curve.nu]),
                                                       np.array([curve.gamma]), tuple(range(k + 1)))
    return [((-1.0) ** q if reverse else 1.0) * J[q][:, 0] for q in range(k + 1)]


def _det6(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """:func:`_det` broadcast over a leading parameter axis: (..., N, 3) -> (..., N)."""
    return np.einsum("...i,...i->...", x, _cross3(y, z))


class _LoftJets:
    r"""Along the loft at path parameters ``lam`` of one segment: the rails' jets, the path
    ``t, s, t_λ, s_λ`` and their total derivatives with respect to the six shape parameters
    ``p = (a.μ, a.ν, a.γ, b.μ, b.ν, b.γ)`` at fixed λ.

    On the main part the path solves ``F(t, s; p) = 0``, ``t + s = 2λ``; at fixed λ
    ``∂t/∂p = -F_p / (F_t - F_s)``, ``∂s/∂p = -∂t/∂p`` (implicit function theorem), and from
    ``t_λ = 2 F_s / (F_s - F_t)``: ``∂t_λ/∂p = 2 (F_s δF_t - F_t δF_s) / (F_s - F_t)²`` with
    ``δF_t = F_tp + (F_tt - F_ts) ∂t/∂p``, ``δF_s = F_sp + (F_ts - F_ss) ∂t/∂p``, ``s_λ = 2 - t_λ``;
    ``F_p = det(a'_p, b', g) + det(a', b'_p, g) + det(a', b', b_p - a_p)``,
    ``F_tp = det(a''_p, b', g) + det(a'', b'_p, g) + det(a'', b', b_p - a_p)``,
    ``F_sp = det(a'_p, b'', g) + det(a', b''_p, g) + det(a', b'', b_p - a_p)``. On a fan (t or s
    fixed at a side, the other linear in λ) the path does not move with p.

    Attributes (each (6, N, 3) or (N, 3)): ``al`` = a_λ, ``g`` = b - a, ``gl`` = g_λ and their
    derivatives ``dal``, ``dg``, ``dgl``.
    """

    def __init__(self, lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, sg: LoftSegment, lam: np.ndarray) -> None:
        pair = lf._pair
        n = lam.size
        z, one = np.zeros(n), np.ones(n)
        tll = sll = z
        if sg.kind == "main":
            (t, tl, tll), (s, sl, sll), _ = lf._path.main(lam, 2)
        elif sg.side == "s=0":
            t, tl, s, sl = 2 * lam, 2 * one, z, z
        elif sg.side == "t=0":
            t, tl, s, sl = z, z, 2 * lam, 2 * one
        elif sg.side == "t=1":
            t, tl, s, sl = one, z, 2 * lam - 1.0, 2 * one
        else:
            t, tl, s, sl = 2 * lam - 1.0, 2 * one, one, z
        t, s = np.clip(t, 0.0, 1.0), np.clip(s, 0.0, 1.0)
        A = _jet(pair.ra, t, 2)
        B = _jet(pair.rb, s, 2)
        dA = [np.concatenate([x, np.zeros_like(x)]) for x in _rail_parameter_jets(ca, t, 2, False)]
        dB = [np.concatenate([np.zeros_like(x), x]) for x in _rail_parameter_jets(cb, s, 2, lf.reversed_b)]
        g = B[0] - A[0]
        Tp = np.zeros((6, n))
        dTl = np.zeros((6, n))
        if sg.kind == "main":
            p = pair.parts(t, s, 2)
            dg0 = dB[0] - dA[0]
            Fp = _det6(dA[1], B[1], g) + _det6(A[1], dB[1], g) + _det6(A[1], B[1], dg0)
            Ftp = _det6(dA[2], B[1], g) + _det6(A[2], dB[1], g) + _det6(A[2], B[1], dg0)
            Fsp = _det6(dA[1], B[2], g) + _det6(A[1], dB[2], g) + _det6(A[1], B[2], dg0)
            Ft, Fs = p["Ft"], p["Fs"]
            den = Fs - Ft
            Tp = Fp / den
            dFt = Ftp + (p["Ftt"] - p["Fts"]) * Tp
            dFs = Fsp + (p["Fts"] - p["Fss"]) * Tp
            dTl = 2.0 * (Fs * dFt - Ft * dFs) / den**2
        Sp, dSl = -Tp, -dTl
        dA0 = dA[0] + A[1] * Tp[..., None]
        dA1 = dA[1] + A[2] * Tp[..., None]
        dB0 = dB[0] + B[1] * Sp[..., None]
        dB1 = dB[1] + B[2] * Sp[..., None]
        self.al = A[1] * tl[:, None]
        bl = B[1] * sl[:, None]
        self.g = g
        self.gl = bl - self.al
        self.dal = dA1 * tl[:, None] + A[1] * dTl[..., None]
        dbl = dB1 * sl[:, None] + B[1] * dSl[..., None]
        self.dg = dB0 - dA0
        self.dgl = dbl - self.dal
        # second λ-derivatives (for the moving quadrature nodes of the regression penalty)
        self.all = A[2] * (tl**2)[:, None] + A[1] * tll[:, None]
        self.gll = B[2] * (sl**2)[:, None] + B[1] * sll[:, None] - self.all

    def part(self, sl: slice) -> "_LoftJets":
        """The same quantities at a subset of the nodes."""
        out = object.__new__(_LoftJets)
        for k in ("al", "g", "gl", "all", "gll"):
            setattr(out, k, getattr(self, k)[sl])
        for k in ("dal", "dg", "dgl"):
            setattr(out, k, getattr(self, k)[:, sl])
        return out

    # integrands q(λ) and their derivatives at fixed λ
    def area(self) -> tuple[np.ndarray, np.ndarray]:
        r"""``ρ = Σ_v w_v |(a_λ + v g_λ) × g|`` (16-node Gauss–Legendre in v, as :func:`ght_cad.unroll.ruled_area`)
        and ``∂ρ = Σ_v w_v c_v·∂c_v / |c_v|``."""
        tv, wv = gauss_legendre(16)
        ca_, cg_ = _cross3(self.al, self.g), _cross3(self.gl, self.g)  # c_v = ca + v cg
        dca = _cross3(self.dal, self.g) + _cross3(self.al, self.dg)
        dcg = _cross3(self.dgl, self.g) + _cross3(self.gl, self.dg)
        rho = np.zeros(self.g.shape[0])
        drho = np.zeros((6, self.g.shape[0]))
        for v, w in zip(tv, wv):
            c = ca_ + v * cg_
            nc = np.sqrt(np.sum(c * c, axis=-1))
            rho += w * nc
            drho += (w / nc) * (np.einsum("nd,pnd->pn", c, dca) + v * np.einsum("nd,pnd->pn", c, dcg))
        return rho, drho

    def fairness(self) -> tuple[np.ndarray, np.ndarray]:
        r"""``h = |d_λ|² = |g_λ|²/|g|² - (g·g_λ)²/|g|⁴`` (d = g/|g|) and its derivative."""
        A_ = np.sum(self.gl * self.gl, axis=-1)
        B_ = np.sum(self.g * self.gl, axis=-1)
        C_ = np.sum(self.g * self.g, axis=-1)
        dA_ = 2.0 * np.einsum("nd,pnd->pn", self.gl, self.dgl)
        dB_ = np.einsum("pnd,nd->pn", self.dg, self.gl) + np.einsum("nd,pnd->pn", self.g, self.dgl)
        dC_ = 2.0 * np.einsum("nd,pnd->pn", self.g, self.dg)
        h = A_ / C_ - B_**2 / C_**2
        dh = dA_ / C_ - A_ * dC_ / C_**2 - 2.0 * B_ * dB_ / C_**2 + 2.0 * B_**2 * dC_ / C_**3
        return h, dh

    def regression(self, margin: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""``q = max(0, 1 - c/margin)²``, ``c = dist(v*, [0, 1])``, ``v* = -(c1·c2)/|c2|²``,
        ``c1 = a_λ × g``, ``c2 = g_λ × g`` (:func:`ght_cad.ruled.regression_v`), its derivative at
        fixed λ (``dc/dv* = -1`` below 0, ``+1`` above 1) and ``q_λ`` (``c1_λ = a_λλ × g + a_λ × g_λ``,
        ``c2_λ = g_λλ × g``): q is only C¹ in λ, so the penalty's quadrature is differentiated
        node by node (moving nodes) rather than as the exact integral."""
        c1 = _cross3(self.al, self.g)
        c2 = _cross3(self.gl, self.g)
        dc1 = _cross3(self.dal, self.g) + _cross3(self.al, self.dg)
        dc2 = _cross3(self.dgl, self.g) + _cross3(self.gl, self.dg)
        num = np.sum(c1 * c2, axis=-1)
        den = np.sum(c2 * c2, axis=-1)
        vs = regression_v(self.al, self.g, self.gl)
        fin = np.isfinite(vs)
        with np.errstate(divide="ignore", invalid="ignore"):
            dvs = -(np.einsum("pnd,nd->pn", dc1, c2) + np.einsum("nd,pnd->pn", c1, dc2)) / den \
                + num * 2.0 * np.einsum("nd,pnd->pn", c2, dc2) / den**2
        c = np.where(vs < 0, -vs, np.where(vs > 1, vs - 1, 0.0))
        sgn = np.where(vs < 0, -1.0, np.where(vs > 1, 1.0, 0.0))
        c = np.where(fin, c, np.inf)
        m = np.maximum(0.0, 1.0 - c / margin)
        q = m**2
        slope = np.where(fin & (m > 0), -2.0 * m / margin * sgn, 0.0)
        dq = slope * np.where(fin, dvs, 0.0)
        c1l = _cross3(self.all, self.g) + _cross3(self.al, self.gl)
        c2l = _cross3(self.gll, self.g)
        with np.errstate(divide="ignore", invalid="ignore"):
            vl = -(np.sum(c1l * c2, axis=-1) + np.sum(c1 * c2l, axis=-1)) / den \
                + num * 2.0 * np.sum(c2 * c2l, axis=-1) / den**2
        ql = slope * np.where(fin, vl, 0.0)
        return q, dq, ql


def _side_shift(lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, t: float, s: float, end: str) -> np.ndarray:
    r"""``∂λ/∂p`` of a branch end (6,): on ``s = 0`` or ``s = 1`` ``F(t, s; p) = 0`` gives
    ``∂t/∂p = -F_p/F_t``, on ``t = 0`` or ``t = 1`` ``∂s/∂p = -F_p/F_s`` (``λ = (t + s)/2``); a branch
    end at a corner where ``F`` vanishes to round-off, or where the rails meet (a pointed end:
    they meet there for every shape parameter), stays there (``0``).

    Raises:
        LoftGradientFallback: an end at (within MIN_FAN of) a corner where F does not vanish (a fan
            appears or vanishes there: the objective is not differentiable).
    """
    pair = lf._pair
    tt, ss = np.array([t]), np.array([s])
    if end == "start":
        at_t, at_s = t <= MIN_FAN, s <= MIN_FAN  # on the side t = 0 / s = 0
    else:
        at_t, at_s = t >= 1.0 - MIN_FAN, s >= 1.0 - MIN_FAN  # on the side t = 1 / s = 1
    if at_t and at_s:
        if _at_corner(pair, t, s):  # the rails meet there for every shape parameter (a GHT curve
            return np.zeros(6)      # interpolates its end points): the end stays at the corner
        p = pair.parts(tt, ss, 1)
        if abs(float(p["F"][0])) <= 64 * float(p["noise"][0]) + 1e-13 * float(p["scale"][0]):
            return np.zeros(6)
        raise LoftGradientFallback(f"the branch {end}s at the corner (t, s) = ({t:.3g}, {s:.3g}) where F does not vanish "
                                   "identically: a fan appears or vanishes there")
    A = _jet(pair.ra, tt, 2)
    B = _jet(pair.rb, ss, 2)
    dA = [np.concatenate([x, np.zeros_like(x)]) for x in _rail_parameter_jets(ca, tt, 1, False)]
    dB = [np.concatenate([np.zeros_like(x), x]) for x in _rail_parameter_jets(cb, ss, 1, lf.reversed_b)]
    g = B[0] - A[0]
    Fp = (_det6(dA[1], B[1], g) + _det6(A[1], dB[1], g) + _det6(A[1], B[1], dB[0] - dA[0]))[:, 0]
    if at_s:  # s fixed on the side: t moves
        Ft = float(_det(A[2], B[1], g)[0])
        return -Fp / Ft / 2.0
    Fs = float(_det(A[1], B[2], g)[0])
    return -Fp / Fs / 2.0


def loft_measures_and_gradients(lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, margin: float = 0.25,
                                nodes: int = 32, area_nodes: int = 64) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    r"""The loft objectives of :class:`LoftProblem` and their exact gradients with respect to
    ``(a.μ, a.ν, a.γ, b.μ, b.ν, b.γ)`` where the loft's structure is locally fixed.

    Each measure is a sum over segments of ``I = ∫_{λ_lo}^{λ_hi} q(λ; p) dλ`` (area density
    ``ρ``, ruling fairness ``|d_λ|²``, regression penalty on the main part), so
    ``∂I/∂p = ∫ ∂q/∂p|_λ dλ + q(λ_hi) ∂λ_hi/∂p - q(λ_lo) ∂λ_lo/∂p``: the integrand's derivative at
    fixed λ (:class:`_LoftJets`: implicit-function derivative of the path on the main part) plus the
    boundary terms of the moving breakpoints (:func:`_side_shift`). ``fan_share = A_fan / A`` gives
    ``(∂A_fan A - A_fan ∂A) / A²``. Integrals by Gauss–Legendre: ``nodes`` per segment (as the
    measures themselves), ``area_nodes`` for the area derivative (the area is adaptive to 1e-13).

    Returns:
        ``(measures, gradients)``: ``{"fan_share", "fairness", "regression"}`` (measures as
        :meth:`LoftProblem.measures_of`) and the (6,) gradient of each.

    Raises:
        LoftGradientFallback: the structure changes at this candidate (a branch end at a corner
            where F does not vanish) or a quantity is singular (zero ruling, F_s = F_t on the
            branch, a non-finite derivative); the caller falls back to finite differences.
    """
    with np.errstate(all="ignore"):
        return _loft_measures_and_gradients(lf, ca, cb, margin, nodes, area_nodes)


def _loft_measures_and_gradients(lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, margin: float, nodes: int,
                                 area_nodes: int) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    x, w = gauss_legendre(nodes)
    xa, wa = gauss_legendre(area_nodes)
    (t0, s0), (t1, s1) = lf._branch.start, lf._branch.end
    shift = {"start": _side_shift(lf, ca, cb, t0, s0, "start"), "end": _side_shift(lf, ca, cb, t1, s1, "end")}
    zero = np.zeros(6)
    grads = {k: np.zeros(6) for k in ("fan_area", "area", "fairness", "regression")}
    for i, sg in enumerate(lf.segments):
        lo, hi = lf._edges[i], lf._edges[i + 1]
        # the outer edges are λ = 0, 1; an inner edge is the branch start λ0 or its end λ1
        dlo = zero if i == 0 else (shift["start"] if sg.kind == "main" else shift["end"])
        dhi = zero if i == len(lf.segments) - 1 else (shift["end"] if sg.kind == "main" else shift["start"])
        L = hi - lo
        nq, na = x.size, xa.size
        jall = _LoftJets(lf, ca, cb, sg, np.concatenate([[lo, hi], lo + L * x, lo + L * xa]))
        je, jq, ja = jall.part(slice(0, 2)), jall.part(slice(2, 2 + nq)), jall.part(slice(2 + nq, 2 + nq + na))
        rho, drho = ja.area()
        rho_e, _ = je.area()
        dA = L * (drho @ wa) + rho_e[1] * dhi - rho_e[0] * dlo
        grads["area"] += dA
        if sg.kind != "main":
            grads["fan_area"] += dA
        h, dh = jq.fairness()
        h_e, _ = je.fairness()
        grads["fairness"] += L * (dh @ w) + h_e[1] * dhi - h_e[0] * dlo
        if sg.kind == "main":
            # the penalty's own quadrature differentiated with its nodes λ_j = lo + x_j L moving
            q, dq, ql = jq.regression(margin)
            dnode = dlo[:, None] + x[None, :] * (dhi - dlo)[:, None]
            grads["regression"] += (dhi - dlo) * (q @ w) + L * ((dq + ql[None, :] * dnode) @ w)
    area, fan = lf.report.area, lf.report.fan_area
    out = {
        "fan_share": (grads["fan_area"] * area - fan * grads["area"]) / area**2,
        "fairness": grads["fairness"],
        "regression": grads["regression"],
    }
    for k, v in out.items():
        if not np.all(np.isfinite(v)):
            raise LoftGradientFallback(f"the derivative of {k} is not finite here (zero ruling or F_s = F_t on the branch)")
    measures = {"fan_share": float(lf.report.fan_share), "fairness": lf.fairness(),
                "regression": _regression_penalty(lf, margin)}
    return measures, out
