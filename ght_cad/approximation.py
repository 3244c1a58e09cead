r"""Developable panels for a surface that is not developable (issue 24).

A double-curved target ``S(u, v)`` (anything with positions and first/second derivatives) is
covered by strips bounded by target isolines (the *seams*); each strip is an exact developable:
the rails loft (spec 5.7) between its two seam curves, whose rulings run across the strip. The
rulings follow the conjugate direction of the seams; the parameter direction the rulings run along
is chosen as the one of least normal curvature (``direction="auto"``) from the strip-count estimate

    N_dir ≈ max_x ∫_0^1 sqrt(|κ_n(y)| / (16 tol)) |S_y| dy,

(the sagitta of a ruling of length w on a surface of normal curvature κ is ``κ w² / 8``; split
both ways it gives ``κ w² / 16``), where ``y`` is the parameter the rulings run along and ``x``
the other one. For a spherical cap given in longitude/latitude this gives conical bands between
latitude circles with rulings along the meridians.

Algorithm (all kernel-free, numpy/scipy):

1. **March**: from ``y = 0``, the next seam is the largest ``y1`` whose strip, with both seams on
   the target, deviates from it by a range ``max d - min d <= 2 tol f`` (``d`` the signed distance
   of the panel's points to the target along its normal; ``f = 0.9``, lowered when step 3 fails).
   The strip's rulings are found fast by Newton on ``F(t, s) = det(a'(t), b'(s), b(s) - a(t)) = 0``
   for every t (with fans ``a(0) -> b(s)``, ``a(t) -> b(0)`` ... where ``s(t)`` leaves [0, 1]),
   the same equation :func:`ght_cad.loft.developable_loft` traces.
2. **Split the deviation both ways**: every seam is moved off the target along its normal,
   ``r_j(t) = S(t, y_j) + δ_j n(t, y_j)``, by the fixed point
   ``δ_j ← δ_j - (m_{j-1} + m_j) / 2`` (``m_i = (max d + min d) / 2`` of strip i; one neighbour at
   the ends), so each panel's deviation range is centred on the target. Adjacent panels share
   the seam function ``r_j`` exactly (the same callable for both lofts): the seams are watertight up
   to the B-spline fit tolerance of the faces (1e-7 of the size).
3. **Build and measure**: each strip becomes an exact :func:`ght_cad.loft.developable_loft` between
   its rails (a seam that is one point, e.g. the pole of a sphere in longitude/latitude, gives a
   cone with its apex there) and its deviation is measured both ways (panel points projected onto
   the target and target points projected onto the panel, Gauss–Newton). If a panel exceeds
   ``tol``, the march is repeated with a smaller ``f``; a result needing more than ``max_panels``
   panels raises :class:`ght_cad.errors.GHTError` naming the best deviation reached.

4. **Loft or dual fit per strip** (``method="auto"``, spec 10.1): every strip also gets the dual
   fit of the target's tangent planes along its middle curve (:mod:`ght_cad.approximation_dual`:
   a GHT dual curve, spec 5.2, fitted by least squares, its μ, ν, γ optimized by
   :func:`ght_cad.optimize.minimize`), trimmed to the strip: its boundary on the seam rows is a
   seam ``S(x, y_j) + δ(x) n`` of the same family. Strips turn dual greedily where the dual seams
   give a smaller sampled deviation and the strip and its neighbours get closer; a seam next to a
   dual strip is that strip's trimmed boundary. Every panel is the loft between its two seams, so
   neighbours share the seam curve exactly whatever their methods; if the mix misses ``tol`` the
   all-loft set is built too and the better kept. A target closed along the seams (a full turn)
   keeps the lofts: one GHT dual curve cannot close.

Inputs that are developable already (a cone, a ght_cad loft) give one panel: the first march step
tries the whole box.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ._quadrature import leggauss
from .errors import GHTError
from .ruled import RuledSurface
from ._vec import cross as _cross

__all__ = [
    "SurfaceTarget",
    "as_target",
    "approximate",
    "ApproximationResult",
    "Panel",
    "ConeStrip",
]

_JET = Callable[[np.ndarray, np.ndarray, int], list]


# ----------------------------------------------------------------------------------------------
# targets
# ----------------------------------------------------------------------------------------------
class SurfaceTarget:
    r"""A target surface as the approximation sees it: ``jet(u, v, order)`` and its parameter box.

    ``jet(u, v, order)`` returns ``[S, S_u, S_v]`` (order 1) or ``[S, S_u, S_v, S_uu, S_vv, S_uv]``
    (order 2) at 1-D arrays of parameters, each (n, 3) — the :class:`ght_cad.face_unroll.SurfaceAdapter`
    convention.

    Args:
        jet: the evaluator.
        bounds: ``(u0, u1, v0, v1)``.
        name: label for messages and reports.
    """

    def __init__(self, jet: _JET, bounds: Sequence[float], name: str = "target") -> None:
        b = tuple(float(x) for x in bounds)
        if len(b) != 4 or not all(math.isfinite(x) for x in b) or not (b[1] > b[0] and b[3] > b[2]):
            raise GHTError(f"target bounds {bounds!r} are not allowed; give (u0, u1, v0, v1) with u1 > u0, v1 > v0")
        self._jet = jet
        self.bounds = b
        self.name = name

    def jet(self, u: np.ndarray, v: np.ndarray, order: int = 2) -> list[np.ndarray]:
        """``[S, S_u, S_v(, S_uu, S_vv, S_uv)]`` at the points, each (n, 3)."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        out = self._jet(u, v, order)
        return [np.asarray(x, dtype=float).reshape(-1, 3) for x in out[: 3 if order <= 1 else 6]]

    def __repr__(self) -> str:
        return f"SurfaceTarget({self.name!r}, bounds={self.bounds})"


def _ght_jet(surf: Any) -> _JET:
    def jet(u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        d = [(0, 0), (1, 0), (0, 1)] + ([(2, 0), (0, 2), (1, 1)] if order >= 2 else [])
        return [np.asarray(surf.derivative(u, v, du, dv), dtype=float)[:, :3] for du, dv in d]
    return jet


def _ruled_jet(surf: RuledSurface) -> _JET:
    r"""``S(u, v) = a(u) + v (b(u) - a(u))``: ``S_u = a' + v g'``, ``S_v = g``, ``S_uu = a'' + v g''``,
    ``S_vv = 0``, ``S_uv = g'``."""
    def jet(u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        vv = v[:, None]
        a = [np.asarray(surf.a(u, k), dtype=float).reshape(-1, 3) for k in range(3 if order >= 2 else 2)]
        b = [np.asarray(surf.b(u, k), dtype=float).reshape(-1, 3) for k in range(3 if order >= 2 else 2)]
        g = [bk - ak for ak, bk in zip(a, b)]
        out = [a[0] + vv * g[0], a[1] + vv * g[1], g[0]]
        if order >= 2:
            out += [a[2] + vv * g[2], np.zeros_like(g[0]), g[1]]
        return out
    return jet


def as_target(target: Any) -> SurfaceTarget:
    """A :class:`SurfaceTarget` from a GHTSurface, a NurbsSurface, a RuledSurface (e.g. a
    :class:`ght_cad.loft.DevelopableLoft`), an object with ``jet(u, v, order)`` and ``bounds``, or a
    build123d/cadquery/OCP face (through :func:`ght_cad.cad.approximate.face_target`).

    Raises:
        GHTError: anything else.
    """
    from .nurbs import NurbsSurface
    from .patch import GHTSurface

    if isinstance(target, SurfaceTarget):
        return target
    if isinstance(target, NurbsSurface):
        return SurfaceTarget(lambda u, v, k: target.eval(u, v, min(k, 2)), target.bounds, "NurbsSurface")
    if isinstance(target, GHTSurface):
        if target.dim < 3:
            raise GHTError(f"the GHTSurface target has dimension {target.dim}; a 3-D surface is needed")
        return SurfaceTarget(_ght_jet(target), (0.0, 1.0, 0.0, 1.0), "GHTSurface")
    if isinstance(target, RuledSurface):
        return SurfaceTarget(_ruled_jet(target), (0.0, 1.0, 0.0, 1.0), type(target).__name__)
    if hasattr(target, "jet") and hasattr(target, "bounds"):
        b = target.bounds() if callable(target.bounds) else target.bounds
        return SurfaceTarget(lambda u, v, k: target.jet(u, v, k), b, type(target).__name__)
    if hasattr(target, "wrapped") or type(target).__module__.startswith("OCP"):
        from ._kernel import adapter  # the kernel adapter, through the core's dispatch

        return adapter("face_target")(target)
    raise GHTError(
        f"target of type {type(target).__name__} is not allowed; give a GHTSurface, NurbsSurface, RuledSurface, "
        "a SurfaceTarget (jet + bounds) or a build123d/cadquery/OCP face"
    )


# ----------------------------------------------------------------------------------------------
# the target in strip coordinates: x along the seams (rail parameter), y across (rulings' way)
# ----------------------------------------------------------------------------------------------
def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


class _Frame:
    """The target on the unit square ``(x, y)``; ``direction`` names the parameter the rulings
    run along (``"v"``: x = u, y = v; ``"u"``: x = v, y = u)."""

    def __init__(self, target: SurfaceTarget, direction: str) -> None:
        self.t = target
        self.direction = direction
        u0, u1, v0, v1 = target.bounds
        self.swap = direction == "u"
        self.o = np.array([u0, v0])
        self.d = np.array([u1 - u0, v1 - v0])
        g = self.grid_points(17, 17)
        self.size = float(np.linalg.norm(g.max(axis=0) - g.min(axis=0))) or 1.0
        # closed along x (e.g. a full turn of longitude): both x-ends are the same curve
        xs = np.linspace(0, 1, 9)
        e0 = self.jet(np.zeros(9), xs, 0)[0]
        e1 = self.jet(np.ones(9), xs, 0)[0]
        self.closed_x = bool(np.max(np.linalg.norm(e0 - e1, axis=1)) <= 1e-9 * self.size)

    def uv(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Target parameters of (x, y)."""
        if self.swap:
            x, y = y, x
        return self.o[0] + self.d[0] * x, self.o[1] + self.d[1] * y

    def jet(self, x: np.ndarray, y: np.ndarray, order: int = 1) -> list[np.ndarray]:
        """``[S, S_x, S_y(, S_xx, S_yy, S_xy)]`` in the unit-square coordinates."""
        x = np.asarray(x, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        u, v = self.uv(x, y)
        j = self.t.jet(u, v, max(order, 1) if order else 0)
        du, dv = self.d
        if order == 0:
            return j[:1]
        out = [j[0], j[1] * du, j[2] * dv]
        if order >= 2:
            out += [j[3] * du * du, j[4] * dv * dv, j[5] * du * dv]
        if self.swap:
            out[1], out[2] = out[2], out[1]
            if order >= 2:
                out[3], out[4] = out[4], out[3]
        return out

    def grid_points(self, nx: int, ny: int) -> np.ndarray:
        X, Y = np.meshgrid(np.linspace(0, 1, nx), np.linspace(0, 1, ny), indexing="ij")
        return self.jet(X.ravel(), Y.ravel(), 0)[0]

    def normal(self, x: np.ndarray, y: np.ndarray, jet: list[np.ndarray] | None = None) -> np.ndarray:
        """Unit normal ``S_x × S_y / |..|``; where ``|S_x × S_y| <= 1e-8 size²`` (a collapsed row:
        the pole of a sphere, where the cross product is rounding noise) the normal 1e-6 inward in
        both coordinates."""
        x = np.asarray(x, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        j = jet if jet is not None else self.jet(x, y, 1)
        N = _cross(j[1], j[2])
        nn = np.linalg.norm(N, axis=1)
        bad = nn <= 1e-8 * self.size * self.size
        if np.any(bad):
            xb = x[bad] + 1e-6 * np.sign(0.5 - x[bad])
            yb = y[bad] + 1e-6 * np.sign(0.5 - y[bad])
            jb = self.jet(xb, yb, 1)
            N[bad] = _cross(jb[1], jb[2])
        return _unit(N)

    def normal_dx(self, x: np.ndarray, y: np.ndarray, j: list[np.ndarray]) -> np.ndarray:
        r"""``∂n/∂x = (N_x - (N_x·n) n) / |N|``, ``N = S_x × S_y``, ``N_x = S_xx × S_y + S_x × S_xy``."""
        N = _cross(j[1], j[2])
        nn = np.linalg.norm(N, axis=1, keepdims=True)
        Nx = _cross(j[3], j[2]) + _cross(j[1], j[5])
        n = N / np.where(nn > 0, nn, 1.0)
        out = (Nx - np.sum(Nx * n, axis=1, keepdims=True) * n) / np.where(nn > 0, nn, np.inf)
        return out

    def project(self, X: np.ndarray, x: np.ndarray, y: np.ndarray, iters: int = 10) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest target points of ``X`` by damped Gauss–Newton from ``(x, y)``, clamped to the
        square. Returns (x, y, signed distance ``(X - S)·n``)."""
        x = np.clip(np.asarray(x, dtype=float).copy(), 0, 1)
        y = np.clip(np.asarray(y, dtype=float).copy(), 0, 1)
        for _ in range(iters):
            S, Sx, Sy = self.jet(x, y, 1)
            r = X - S
            a = np.sum(Sx * Sx, 1)
            b = np.sum(Sx * Sy, 1)
            c = np.sum(Sy * Sy, 1)
            mu = 1e-10 * (a + c) + 1e-300
            a, c = a + mu, c + mu
            gx = np.sum(Sx * r, 1)
            gy = np.sum(Sy * r, 1)
            det = a * c - b * b
            dx = (c * gx - b * gy) / det
            dy = (a * gy - b * gx) / det
            x = np.clip(x + np.clip(dx, -0.25, 0.25), 0, 1)
            y = np.clip(y + np.clip(dy, -0.25, 0.25), 0, 1)
        S = self.jet(x, y, 0)[0]
        d = np.sum((X - S) * self.normal(x, y), 1)
        return x, y, d


# ----------------------------------------------------------------------------------------------
# seams
# ----------------------------------------------------------------------------------------------
class _Seam:
    r"""A seam curve ``r(t) = S(t, y) + δ(t) n(t, y)``, t ∈ [0, 1]; δ a Chebyshev series in
    ``2t - 1`` (a constant on a target closed along x, so the seam stays closed)."""

    def __init__(self, frame: _Frame, y: float, coef: Sequence[float] = (0.0,)) -> None:
        self.f = frame
        self.y = float(y)
        self.coef = np.asarray(coef, dtype=float)
        t = np.linspace(0, 1, 33)
        P = frame.jet(t, np.full(33, self.y), 0)[0]
        self.length = float(np.sum(np.linalg.norm(np.diff(P, axis=0), axis=1)))
        self.point = self.length <= 1e-9 * frame.size

    def delta(self, t: np.ndarray, k: int = 0) -> np.ndarray:
        c = self.coef
        for _ in range(k):
            c = np.polynomial.chebyshev.chebder(c) * 2.0
        return np.polynomial.chebyshev.chebval(2 * t - 1, c) if c.size else np.zeros_like(t)

    def eval(self, t: np.ndarray, order: int = 1) -> list[np.ndarray]:
        """``[r, r']`` (order 1) or ``[r]`` (0) at the parameters."""
        t = np.asarray(t, dtype=float).ravel()
        y = np.full(t.size, self.y)
        if not np.any(self.coef):
            j = self.f.jet(t, y, 1)
            if not order:
                return [j[0]]
            return [j[0], np.zeros_like(j[0]) if self.point else j[1]]
        j = self.f.jet(t, y, 2 if order else 1)
        n = self.f.normal(t, y, j[:3])
        d = self.delta(t)[:, None]
        r = j[0] + d * n
        if not order:
            return [r]
        if self.point:
            return [r, np.zeros_like(r)]
        r1 = j[1] + d * self.f.normal_dx(t, y, j) + self.delta(t, 1)[:, None] * n
        return [r, r1]

    def rail(self, by_arc_length: bool = True) -> "SeamCurve":
        """The seam as a B-spline curve fitted to ``1e-9`` of the target size (ends interpolated):
        both panels of the seam are lofted from this one curve."""
        key = "_rail" if by_arc_length else "_rail_x"
        if getattr(self, key, None) is None:
            from scipy.interpolate import PchipInterpolator

            from .bspline import fit_function

            # by normalized arc length (chords of 4096 pieces): a target whose speed jumps at its
            # knots (a rational sphere's G1 joints) still gives a smooth rail
            x = np.linspace(0.0, 1.0, 4097)
            P = self.eval(x, 0)[0]
            cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(P, axis=0), axis=1))])
            if by_arc_length and cum[-1] > 0 and np.all(np.diff(cum) > 0):
                xs = PchipInterpolator(cum / cum[-1], x)  # monotone, local: no ringing at a kink

                def func(t: np.ndarray) -> np.ndarray:
                    return self.eval(np.clip(xs(t), 0.0, 1.0), 0)[0]
            else:
                def func(t: np.ndarray) -> np.ndarray:
                    return self.eval(t, 0)[0]
            ends = self.eval(np.array([0.0, 1.0]), 0)[0]
            data = fit_function(func, tol=1e-9 * self.f.size, degree=7, end_derivatives=([ends[0]], [ends[1]]))
            setattr(self, key, SeamCurve(data.knots, data.poles, data.degree))
        return getattr(self, key)


class SeamCurve:
    """A seam curve on [0, 1] as a (non-rational) B-spline with exact derivatives (rail protocol:
    ``evaluate(t)``, ``derivative(t, order)``)."""

    def __init__(self, knots: np.ndarray, poles: np.ndarray, degree: int) -> None:
        from scipy.interpolate import BSpline

        self.knots = np.asarray(knots, dtype=float)
        self.poles = np.asarray(poles, dtype=float)
        self.degree = int(degree)
        self._sp = BSpline(self.knots, self.poles, self.degree, extrapolate=True)

    def evaluate(self, t: Any) -> np.ndarray:
        """Points, (n, 3)."""
        return self.derivative(t, 0)

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        """``r^(order)(t)``, (n, 3), order 0..3."""
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=float)).ravel(), 0.0, 1.0)
        return self._sp(tt, order)

    def __call__(self, t: np.ndarray, k: int = 0) -> np.ndarray:
        return self.derivative(t, k)


class BSplineRuled(RuledSurface):
    r"""The ruled surface of :class:`~ght_cad.bspline.BSplineSurfaceData` of degree 1 across:
    ``X(u, w) = (1 - w) A(u) + w B(u)`` (the face written to STEP); ``breakpoints`` at its knots of
    multiplicity >= degree (a loft's fan joints)."""

    def __init__(self, data: Any) -> None:
        self.data = data
        self._a = SeamCurve(data.knots_u, data.poles[:, 0, :], data.degree_u)
        self._b = SeamCurve(data.knots_u, data.poles[:, 1, :], data.degree_u)
        k, m = np.unique(np.asarray(data.knots_u), return_counts=True)
        self.breakpoints = [float(x) for x, c in zip(k, m) if c >= data.degree_u and 0.0 < x < 1.0]

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._a.derivative(u, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._b.derivative(u, derivative)

    def area(self) -> float:
        r"""3-D area ``∫∫ |(A' + w G') × G| dw du`` (``G = B - A``): Gauss–Legendre, 12 nodes per
        knot span in u and 8 in w (the integrand is smooth inside a span)."""
        k = np.unique(np.asarray(self.data.knots_u, dtype=float))
        xu, wu = leggauss(12)
        xw, ww = leggauss(8)
        lo, hi = k[:-1], k[1:]
        u = (0.5 * (hi - lo)[:, None] * (xu[None, :] + 1) + lo[:, None]).ravel()
        wt = (0.5 * (hi - lo)[:, None] * wu[None, :]).ravel()
        a1, g = self.a(u, 1), self.b(u) - self.a(u)
        g1 = self.b(u, 1) - a1
        w = 0.5 * (xw + 1)
        Xu = a1[:, None, :] + w[None, :, None] * g1[:, None, :]
        dens = np.linalg.norm(_cross(Xu, np.broadcast_to(g[:, None, :], Xu.shape)), axis=2)
        return float(wt @ (dens @ (0.5 * ww)))


def _det(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", _cross(x, y), z)


def _match(A: _Seam, B: _Seam, t: np.ndarray, iters: int = 14) -> np.ndarray:
    r"""``s(t)`` with ``det(a'(t), b'(s), b(s) - a(t)) = 0`` by Newton from ``s = t`` (dF/ds by a
    central difference), clipped to [0, 1] (a clipped value: a fan at the rail end)."""
    a, a1 = A.eval(t)
    s = t.copy()
    h = 1e-6
    for _ in range(iters):
        sp = np.clip(s + h, 0, 1)
        sm = np.clip(s - h, 0, 1)
        bp, b1p = B.eval(sp)
        bm, b1m = B.eval(sm)
        b, b1 = B.eval(s)
        F = _det(a1, b1, b - a)
        dF = (_det(a1, b1p, bp - a) - _det(a1, b1m, bm - a)) / np.maximum(sp - sm, 1e-300)
        step = -F / np.where(np.abs(dF) > 0, dF, np.inf)
        s = np.clip(s + np.clip(step, -0.2, 0.2), 0, 1)
        if np.max(np.abs(step)) < 1e-12:
            break
    return s


@dataclass
class _Rulings:
    """Sampled rulings of a strip: end points in 3-D and their (x, y) on the target."""
    P: np.ndarray
    Q: np.ndarray
    xy_p: np.ndarray
    xy_q: np.ndarray
    t: np.ndarray  # the A-seam parameter of each ruling


def _strip_rulings(A: _Seam, B: _Seam, n: int = 65) -> _Rulings:
    t = np.linspace(0, 1, n)
    if A.point or B.point:
        s = t.copy()
    else:
        s = _match(A, B, t)
    ta, sb = [t], [s]
    # fans at the ends of rail a: a(0) -> b(s), s in [0, s(0)]; a(1) -> b(s), s in [s(1), 1]
    m = 9
    if s[0] > 1e-9:
        ta.append(np.zeros(m))
        sb.append(np.linspace(0, s[0], m))
    if s[-1] < 1 - 1e-9:
        ta.append(np.ones(m))
        sb.append(np.linspace(s[-1], 1, m))
    tt = np.concatenate(ta)
    ss = np.concatenate(sb)
    return _Rulings(A.eval(tt, 0)[0], B.eval(ss, 0)[0], np.stack([tt, np.full(tt.size, A.y)], 1),
                    np.stack([ss, np.full(ss.size, B.y)], 1), tt)


_W = np.linspace(0.0, 1.0, 9)


def _ruling_deviation(frame: _Frame, R: _Rulings, w: np.ndarray = _W) -> tuple[np.ndarray, np.ndarray]:
    """Signed deviation of the panel points ``P + w (Q - P)`` from the target, (n_rulings, len(w)),
    and the points."""
    X = R.P[:, None, :] + w[None, :, None] * (R.Q - R.P)[:, None, :]
    G = R.xy_p[:, None, :] + w[None, :, None] * (R.xy_q - R.xy_p)[:, None, :]
    _, _, d = frame.project(X.reshape(-1, 3), G[..., 0].ravel(), G[..., 1].ravel())
    return d.reshape(X.shape[:2]), X


# ----------------------------------------------------------------------------------------------
# panels
# ----------------------------------------------------------------------------------------------
class ConeStrip(RuledSurface):
    r"""The cone between a curve ``a(u)`` and an apex ``b(u) = P`` (a strip with a one-point seam):
    developable (every ruling passes through P)."""

    def __init__(self, curve: Callable[[np.ndarray, int], np.ndarray], apex: np.ndarray) -> None:
        self._c = curve
        self._p = np.asarray(apex, dtype=float).reshape(3)

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
        return self._c(uu, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
        return np.tile(self._p, (uu.size, 1)) if derivative == 0 else np.zeros((uu.size, 3))

    def area(self) -> float:
        """3-D area (:func:`ght_cad.unroll.ruled_area`)."""
        from .unroll import ruled_area

        return float(ruled_area(self, rtol=1e-13))

    def parameters(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        uu = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
        return uu, uu


@dataclass
class Panel:
    """One developable panel of an approximation.

    Attributes:
        surface: the panel as exported: :class:`BSplineRuled` (B-spline face data of degree 1 across,
            fitted to 1e-7 of the size to ``exact``).
        y0, y1: the seams' positions across the strips (0..1 over the target's parameter range).
        max_out, max_in: largest deviation of the panel outside / inside the target (along the
            target's normal, both ways: panel -> target and target -> panel), lengths >= 0.
        max_deviation: ``max(max_out, max_in)``.
        theta_max_deg: the developability measure θ_max of the panel (degrees).
        area: 3-D area.
        exact: the exact developable (a :class:`ght_cad.loft.DevelopableLoft` or :class:`ConeStrip`).
        method: ``"loft"`` (seams centred by the offsets of step 2) or ``"dual"`` (seams = the
            trimmed boundary of the strip's dual fit, :mod:`ght_cad.approximation_dual`).
        choice: how the method was chosen: the sampled deviations of both candidates
            (``deviation_loft``, ``deviation_dual``), the dual fit's μ, ν, γ and its deviation at
            ``μ = ν = γ = 0`` and after optimization (``dual_start``, ``dual_optimized``).
    """

    surface: Any
    y0: float
    y1: float
    max_out: float = math.nan
    max_in: float = math.nan
    max_deviation: float = math.nan
    theta_max_deg: float = math.nan
    area: float = math.nan
    exact: Any = None
    method: str = "loft"
    choice: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {k: float(getattr(self, k)) for k in ("y0", "y1", "max_out", "max_in", "max_deviation", "theta_max_deg", "area")}
        d["method"] = self.method
        d.update(self.choice)
        return d


@dataclass
class ApproximationResult:
    """What :func:`approximate` returns.

    Attributes:
        panels: the panels in seam order.
        tol: the tolerance asked for.
        direction: the parameter the rulings run along ("u" or "v").
        size: bounding-box diagonal of the target.
        max_deviation: largest panel deviation (both ways).
        deviation_map: ``{"xyz": (n, 3), "uv": (n, 2), "d": (n,)}`` target samples with the signed
            distance of the panels from them (panel minus target along the target normal).
        seams: the seams' positions across (0..1) and offsets (``delta`` Chebyshev coefficients).
        info: estimates, march history, time.
    """

    panels: list[Panel]
    tol: float
    direction: str
    size: float
    max_deviation: float
    deviation_map: dict[str, np.ndarray]
    seams: list[dict[str, Any]]
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def surfaces(self) -> list[Any]:
        """The panels' developable surfaces."""
        return [p.surface for p in self.panels]

    def as_dict(self) -> dict[str, Any]:
        """Plain JSON-able report."""
        return {
            "panels": len(self.panels),
            "tol": self.tol,
            "direction": self.direction,
            "size": self.size,
            "max_deviation": self.max_deviation,
            "total_area": float(sum(p.area for p in self.panels)),
            "panel_report": [dict(p.as_dict(), index=i + 1) for i, p in enumerate(self.panels)],
            "seams": self.seams,
            "info": self.info,
        }

    def flat_pattern(self, **kwargs: Any) -> Any:
        """All panels unrolled on one sheet with seam marks (:func:`ght_cad.unroll.unroll_composite`
        of the exact developables, whose fans and apexes it handles; labels P1..PN in seam order)."""
        from .unroll import unroll_composite

        return unroll_composite([p.exact if p.exact is not None else p.surface for p in self.panels], **kwargs)


# ----------------------------------------------------------------------------------------------
# direction estimate
# ----------------------------------------------------------------------------------------------
def _estimate(frame: _Frame, tol: float, n: int = 33) -> float:
    r"""``max_x ∫ sqrt(|κ_n(S_y)| / (16 tol)) |S_y| dy`` on an n × n grid (trapezoid rule)."""
    x = np.linspace(0, 1, n)
    X, Y = np.meshgrid(x, x, indexing="ij")
    j = frame.jet(X.ravel(), Y.ravel(), 2)
    nrm = frame.normal(X.ravel(), Y.ravel(), j[:3])
    Syy = j[4]
    L = np.linalg.norm(j[2], axis=1)
    kappa = np.abs(np.sum(Syy * nrm, 1)) / np.maximum(L * L, 1e-300)
    f = (np.sqrt(kappa / (16 * tol)) * L).reshape(n, n)
    integral = 0.5 * np.sum((f[:, 1:] + f[:, :-1]) * np.diff(x), axis=1)
    return float(np.max(integral))


# ----------------------------------------------------------------------------------------------
# the approximation
# ----------------------------------------------------------------------------------------------
def _strip_range(frame: _Frame, A: _Seam, B: _Seam, n: int = 49) -> tuple[float, float]:
    d, _ = _ruling_deviation(frame, _strip_rulings(A, B, n))
    return float(d.min()), float(d.max())


def _march(frame: _Frame, tol: float, f: float, max_panels: int, min_width: float) -> list[float]:
    """Seam positions 0 = y_0 < ... < y_N = 1 by the greedy march (module doc, step 1), balanced:
    the smallest range limit that still gives N strips (bisection, 6 steps), so the last strip is
    not a narrow remainder."""
    limit = 2 * tol * f
    ys = _greedy(frame, limit, max_panels, min_width)
    n = len(ys) - 1
    if n <= 1 or n > max_panels:
        return ys
    lo, hi = limit * ((n - 1) / n) ** 2 * 0.9, limit
    for _ in range(6):
        mid = 0.5 * (lo + hi)
        cand = _greedy(frame, mid, n, min_width)
        if len(cand) - 1 <= n:
            hi, ys = mid, cand
        else:
            lo = mid
    return ys


def _greedy(frame: _Frame, limit: float, max_panels: int, min_width: float) -> list[float]:
    """The greedy march with the deviation range ``limit`` (stops after ``max_panels + 1`` strips)."""
    ys = [0.0]
    while ys[-1] < 1.0:
        y0 = ys[-1]
        A = _Seam(frame, y0)

        def ok(y1: float) -> bool:
            lo, hi = _strip_range(frame, A, _Seam(frame, y1))
            return hi - lo <= limit

        if ok(1.0):
            ys.append(1.0)
            break
        lo_y, hi_y = y0, 1.0
        while hi_y - lo_y > max(1e-3 * (1.0 - y0), 1e-9):
            mid = 0.5 * (lo_y + hi_y)
            if ok(mid):
                lo_y = mid
            else:
                hi_y = mid
        nxt = max(lo_y, y0 + min_width)
        ys.append(min(nxt, 1.0))
        if len(ys) - 1 > max_panels:
            break
    return ys


def _offsets(frame: _Frame, ys: list[float], degree: int, iters: int) -> list[_Seam]:
    """Seams moved off the target so each strip's deviation is split both ways (module doc, step 2)."""
    seams = [_Seam(frame, y) for y in ys]
    nt = 49
    tg = np.linspace(0, 1, nt)
    deg = 0 if frame.closed_x else degree
    for _ in range(iters):
        mids = []  # per strip: (values at seam A params, values at seam B params)
        for A, B in zip(seams[:-1], seams[1:]):
            R = _strip_rulings(A, B, nt)
            d, _ = _ruling_deviation(frame, R)
            m = 0.5 * (d.max(axis=1) + d.min(axis=1))
            main = slice(0, nt)
            mids.append((R.t[main], R.xy_q[main, 0], m[main]))
        new = []
        for j, sm in enumerate(seams):
            ts, vals = [], []
            for i in (j - 1, j):
                if 0 <= i < len(mids):
                    ta, sb, m = mids[i]
                    ts.append(sb if i == j - 1 else ta)
                    vals.append(m)
            t_all = np.concatenate(ts)
            v_all = np.concatenate(vals)
            if sm.point or deg == 0:
                corr = np.array([np.mean(v_all)])
            else:
                corr = np.polynomial.chebyshev.chebfit(2 * t_all - 1, v_all, deg)
            c = np.zeros(max(sm.coef.size, corr.size))
            c[: sm.coef.size] += sm.coef
            c[: corr.size] -= corr
            new.append(_Seam(frame, sm.y, c))
        seams = new
    return seams


def _strip_dev(frame: _Frame, A: _Seam, B: _Seam) -> float:
    """Sampled one-way deviation ``max |d|`` of the loft between two seams (the march's ruling
    samples); ``inf`` where the rulings cannot be found."""
    try:
        lo, hi = _strip_range(frame, A, B)
    except (GHTError, FloatingPointError, ValueError):
        return math.inf
    v = max(-lo, hi)
    return v if math.isfinite(v) else math.inf


def _dual_seams(frame: _Frame, loft: list[_Seam], duals: list[Any], chosen: list[bool]) -> list[_Seam]:
    r"""Seams of a method mix: seam j is the trimmed boundary ``δ_j = h(x, y_j)`` of the dual fit of
    the chosen neighbouring strip (the mean of the two Chebyshev series when both neighbours are
    dual), else the loft seam of step 2. Every panel is then the loft between its two seams, so
    neighbours share the seam curve exactly whatever their methods."""
    out = []
    for j, sm in enumerate(loft):
        props = []
        if j - 1 >= 0 and chosen[j - 1]:
            props.append(duals[j - 1].delta_hi)
        if j < len(chosen) and chosen[j]:
            props.append(duals[j].delta_lo)
        if not props or sm.point:
            out.append(sm)
            continue
        c = np.zeros(max(p.size for p in props))
        for p in props:
            c[: p.size] += p / len(props)
        out.append(_Seam(frame, sm.y, c))
    return out


def _choose_methods(frame: _Frame, loft: list[_Seam], duals: list[Any], method: str) -> tuple[list[bool], list[dict[str, float]]]:
    r"""Per strip: loft or dual (module doc, step 4). ``method="dual"``: every strip whose dual fit
    is usable. ``"auto"``: greedy by gain ``e_loft - e_dual`` (sampled deviations of the loft
    between the loft seams and between the dual fit's own trimmed seams); a strip turns dual only if
    the largest deviation of it and its two neighbours (whose shared seams change) goes down, a seam
    between two dual strips being the mean of their trimmed boundaries."""
    n = len(duals)
    e_loft = [_strip_dev(frame, A, B) for A, B in zip(loft[:-1], loft[1:])]
    e_dual = []
    for i, d in enumerate(duals):
        if d is None or not d.ok:
            e_dual.append(math.inf)
            continue
        A = loft[i] if loft[i].point else _Seam(frame, loft[i].y, d.delta_lo)
        B = loft[i + 1] if loft[i + 1].point else _Seam(frame, loft[i + 1].y, d.delta_hi)
        e_dual.append(_strip_dev(frame, A, B))
    info = [{"deviation_loft": e_loft[i], "deviation_dual": e_dual[i]} for i in range(n)]
    if method == "dual":
        return [bool(d is not None and d.ok and math.isfinite(e_dual[i])) for i, d in enumerate(duals)], info
    chosen = [False] * n
    cur = list(e_loft)
    for i in sorted(range(n), key=lambda k: e_dual[k] - e_loft[k]):
        if not e_dual[i] < e_loft[i]:
            break
        trial = chosen.copy()
        trial[i] = True
        seams = _dual_seams(frame, loft, duals, trial)
        near = [k for k in (i - 1, i, i + 1) if 0 <= k < n]
        alone = not any(0 <= k < n and chosen[k] for k in (i - 1, i + 1))
        new = {k: (e_dual[i] if k == i and alone else _strip_dev(frame, seams[k], seams[k + 1])) for k in near}
        if max(new.values()) < max(cur[k] for k in near):
            chosen = trial
            for k, v in new.items():
                cur[k] = v
    return chosen, info


def _build_panel(frame: _Frame, A: _Seam, B: _Seam) -> Any:
    if B.point:
        return ConeStrip(A.rail(), B.eval(np.array([0.5]), 0)[0][0])
    if A.point:
        return ConeStrip(B.rail(), A.eval(np.array([0.5]), 0)[0][0])
    from .errors import NotDevelopableError
    from .loft import developable_loft

    try:
        return developable_loft(A.rail(), B.rail(), orientation="same", samples=65)
    except NotDevelopableError:  # the arc-length rails failed: the target's own parameters
        return developable_loft(A.rail(False), B.rail(False), orientation="same", samples=65)


def _project_panel(panel: Any, X: np.ndarray, iters: int = 8) -> np.ndarray:
    """Closest points of ``X`` on the ruled panel ``a(λ) + w (b(λ) - a(λ))`` (start: nearest of a
    257 × 17 grid; then Gauss–Newton in (λ, w), clamped to [0, 1]², a step kept only where it
    brings the point closer, else halved; the closest point met is returned)."""
    from scipy.spatial import cKDTree

    lg = np.linspace(0, 1, 257)
    wg = np.linspace(0, 1, 17)
    a = panel.a(lg)
    b = panel.b(lg)
    G = a[:, None, :] + wg[None, :, None] * (b - a)[:, None, :]
    _, idx = cKDTree(G.reshape(-1, 3)).query(X)
    lam = lg[idx // wg.size]
    w = wg[idx % wg.size]
    best = np.full(X.shape[0], np.inf)
    best_p = np.zeros_like(X)
    scale = np.ones(X.shape[0])
    prev = (lam, w)
    for it in range(iters + 1):
        a, a1 = panel.a(lam), panel.a(lam, 1)
        b, b1 = panel.b(lam), panel.b(lam, 1)
        P = a + w[:, None] * (b - a)
        r = X - P
        dist = np.linalg.norm(r, axis=1)
        better = dist < best
        best = np.where(better, dist, best)
        best_p[better] = P[better]
        # a step that did not reduce the distance (near a fan's apex, where a' = 0) is halved
        scale = np.where(better, np.minimum(1.0, 2 * scale), 0.5 * scale)
        lam = np.where(better, lam, prev[0])
        w = np.where(better, w, prev[1])
        if it == iters:
            break
        if not np.all(better):
            a, a1 = panel.a(lam), panel.a(lam, 1)
            b, b1 = panel.b(lam), panel.b(lam, 1)
            r = X - (a + w[:, None] * (b - a))
        Pl = a1 + w[:, None] * (b1 - a1)
        Pw = b - a
        prev = (lam, w)
        aa = np.sum(Pl * Pl, 1) + 1e-300
        bb = np.sum(Pl * Pw, 1)
        cc = np.sum(Pw * Pw, 1) + 1e-300
        g1 = np.sum(Pl * r, 1)
        g2 = np.sum(Pw * r, 1)
        det = aa * cc - bb * bb
        det = np.where(np.abs(det) > 1e-300, det, 1e-300)
        lam = np.clip(lam + scale * np.clip((cc * g1 - bb * g2) / det, -0.05, 0.05), 0, 1)
        w = np.clip(w + scale * np.clip((aa * g2 - bb * g1) / det, -0.5, 0.5), 0, 1)
    return best_p


def _strip_grid(frame: _Frame, A: _Seam, B: _Seam, nx: int, ny: int) -> tuple[np.ndarray, np.ndarray]:
    x = np.linspace(0, 1, nx)
    y = np.linspace(A.y, B.y, ny)
    X, Y = np.meshgrid(x, y, indexing="ij")
    return X.ravel(), Y.ravel()


def _measure_panel(frame: _Frame, panel: RuledSurface, A: _Seam, B: _Seam, nl: int = 129, ny: int = 9) -> tuple[float, float, dict[str, np.ndarray]]:
    r"""Two-way deviation of a panel: (max_out, max_in, map samples of target -> panel).

    Panel -> target: the points ``a(λ) + w (b(λ) - a(λ))`` (129 × 9) projected onto the target
    (start: the nearest of a 257 × 17 target grid of the strip); target -> panel: a 129 × 9 grid of
    the strip projected onto the panel. Deviations are signed along the target's normal (panel
    outside the target > 0)."""
    from scipy.spatial import cKDTree

    lam = np.linspace(0, 1, nl)
    a, b = panel.a(lam), panel.b(lam)
    w = np.linspace(0, 1, ny)
    P = (a[:, None, :] + w[None, :, None] * (b - a)[:, None, :]).reshape(-1, 3)
    gx, gy = _strip_grid(frame, A, B, 257, 17)
    G = frame.jet(gx, gy, 0)[0]
    _, idx = cKDTree(G).query(P)
    _, _, d1 = frame.project(P, gx[idx], gy[idx])
    x, y = _strip_grid(frame, A, B, nl, ny)
    S = frame.jet(x, y, 0)[0]
    n = frame.normal(x, y)
    Q = _project_panel(panel, S)
    d2 = np.sum((Q - S) * n, 1)
    u, v = frame.uv(x, y)
    out = max(float(d1.max()), float(d2.max()), 0.0)
    inn = max(float(-d1.min()), float(-d2.min()), 0.0)
    return out, inn, {"xyz": S, "uv": np.stack([u, v], 1), "d": d2}


def _check_number(name: str, v: Any, lo: float, integer: bool = False) -> None:
    ok = isinstance(v, (int, np.integer)) if integer else isinstance(v, (int, float, np.floating, np.integer))
    if isinstance(v, bool) or not ok or not math.isfinite(float(v)) or v < lo:
        kind = "an integer" if integer else "a finite number"
        raise GHTError(f"{name}={v!r} is not allowed; it must be {kind} >= {lo:g}")


def approximate(
    target: Any,
    tol: float,
    *,
    direction: str = "auto",
    max_panels: int = 64,
    offset_degree: int = 4,
    offset_iterations: int = 2,
    safety: float = 0.9,
    method: str = "auto",
    optimizer: str | None = "igwo",
    optimizer_budget: int = 60,
    dual_degree: int = 10,
    progress: Callable[[str], None] | None = None,
) -> ApproximationResult:
    r"""Cover ``target`` with exactly developable panels within ``tol`` (module doc).

    Strips between target isolines (seams); each strip is the developable loft between its seam
    curves ``r_j(t) = S(t, y_j) + δ_j(t) n(t, y_j)`` (spec 5.7: rulings where
    ``det(a', b', b - a) = 0``), a cone where a seam is one point. Seams are placed by a greedy
    march on the on-target deviation range (``max d - min d <= 2 tol f``) and then moved off the
    target along its normal so the deviation is split both ways; neighbouring panels share the
    seam curve ``r_j`` exactly.

    Args:
        target: GHTSurface, NurbsSurface, RuledSurface, :class:`SurfaceTarget` or a CAD face.
        tol: largest allowed deviation (both ways, model units).
        direction: ``"auto"``, ``"u"`` or ``"v"``: the parameter the rulings run along (the seams
            are isolines of the other one).
        max_panels: largest panel count accepted.
        offset_degree: Chebyshev degree of the seam offsets δ_j(t) (0: constant).
        offset_iterations: fixed-point iterations of the offsets.
        safety: the march's share ``f`` of the deviation budget (lowered by 7 % per retry).
        method: ``"auto"`` (spec 10.1: per strip the closer of the loft and the dual fit of the tangent
            planes, step 4), ``"loft"`` or ``"dual"`` (the dual fit wherever it is usable, the loft
            only where it is not; no all-loft fallback: a finer march instead).
        optimizer: :func:`ght_cad.optimize.minimize` method for each dual fit's μ, ν, γ
            (``"igwo"``, ``"pso"``, ``"hybrid"``, ...), or None to keep ``μ = ν = γ = 0``.
        optimizer_budget: objective evaluations per strip for that optimizer.
        dual_degree: degree m of the fitted dual curves.
        progress: called with a line of text per step (e.g. ``print``).

    Returns:
        :class:`ApproximationResult`.

    Raises:
        GHTError: bad arguments, or no approximation within ``tol`` with at most ``max_panels``
            panels (the message names the best deviation reached and its panel count).
    """
    _check_number("tol", tol, 0.0)
    if not tol > 0:
        raise GHTError(f"tol={tol!r} is not allowed; it must be > 0")
    _check_number("max_panels", max_panels, 1, integer=True)
    _check_number("offset_degree", offset_degree, 0, integer=True)
    _check_number("offset_iterations", offset_iterations, 0, integer=True)
    _check_number("safety", safety, 0.05)
    if direction not in ("auto", "u", "v"):
        raise GHTError(f"direction={direction!r} is not allowed; use 'auto', 'u' or 'v'")
    if method not in ("auto", "loft", "dual"):
        raise GHTError(f"method={method!r} is not allowed; use 'auto', 'loft' or 'dual'")
    _check_number("optimizer_budget", optimizer_budget, 1, integer=True)
    _check_number("dual_degree", dual_degree, 3, integer=True)
    if optimizer is not None:
        from .approximation_dual import check_optimizer

        check_optimizer(optimizer)
    from .developable import developable_bspline

    say = progress or (lambda s: None)
    t0 = time.perf_counter()
    tgt = as_target(target)
    info: dict[str, Any] = {"target": tgt.name, "bounds": list(tgt.bounds)}
    if direction == "auto":
        est = {d: _estimate(_Frame(tgt, d), tol) for d in ("u", "v")}
        direction = min(est, key=lambda d: est[d])
        info["estimate"] = est
        say(f"direction: rulings along {direction} (estimated strips {est})")
    frame = _Frame(tgt, direction)
    tol = float(tol)
    best: tuple[float, int] | None = None
    f = float(safety)
    history = []
    panels: list[Panel] = []
    for attempt in range(8):
        ys = _march(frame, tol, f, max_panels, min_width=1e-6)
        n = len(ys) - 1
        say(f"march f={f:.3f}: {n} strips")
        if n > max_panels:
            history.append({"f": f, "panels": n, "max_deviation": None})
            break
        loft_seams = _offsets(frame, ys, offset_degree, offset_iterations)
        chosen = [False] * n
        duals: list[Any] = []
        choice = [{} for _ in range(n)]
        if method != "loft" and frame.closed_x:
            # a full turn of tangent planes: one GHT dual curve cannot close, and closed seams keep
            # constant offsets; measured on the cap, the dual seams were 2.3x farther (0.48 vs 0.21)
            choice = [{"dual_ok": False, "dual_reason": "closed strip (a GHT dual curve does not close)"} for _ in range(n)]
        elif method != "loft":
            from .approximation_dual import fit_strip

            for A, B in zip(loft_seams[:-1], loft_seams[1:]):
                try:
                    duals.append(fit_strip(frame, A.y, B.y, degree=dual_degree, optimizer=optimizer,
                                           max_nfev=optimizer_budget, closed=frame.closed_x))
                except (GHTError, FloatingPointError, ValueError, np.linalg.LinAlgError):
                    duals.append(None)
            chosen, choice = _choose_methods(frame, loft_seams, duals, method)
            for c, d in zip(choice, duals):
                if d is not None:
                    c.update({"dual_ok": d.ok, "dual_reason": d.reason, "mu": d.params[0], "nu": d.params[1],
                              "gamma": d.params[2], "dual_start": d.half_range_start, "dual_optimized": d.half_range})
            say(f"  dual fits usable: {sum(1 for d in duals if d is not None and d.ok)}/{n}; chosen: {sum(chosen)}")
        mixes = [(_dual_seams(frame, loft_seams, duals, chosen), chosen)] if any(chosen) else []
        if method != "dual" or not mixes:  # "dual": no all-loft fallback (a finer march instead)
            mixes.append((loft_seams, [False] * n))
        best_mix = None
        for seams, ch in mixes:
            panels, maps = [], []
            try:
                for i, (A, B) in enumerate(zip(seams[:-1], seams[1:])):
                    exact = _build_panel(frame, A, B)
                    if ch[i] and getattr(getattr(exact, "report", None), "regression", None):
                        raise GHTError(f"the dual panel {i + 1} contains its edge of regression")
                    data = developable_bspline(exact, tol=1e-7 * frame.size, degree=5)
                    surf = BSplineRuled(data)
                    out, inn, mp = _measure_panel(frame, surf, A, B)
                    th = data.info.get("theta_max_deg", math.nan)
                    panels.append(Panel(surf, A.y, B.y, out, inn, max(out, inn), float(th) if math.isfinite(th) else 0.0,
                                        exact=exact, method="dual" if ch[i] else "loft", choice=dict(choice[i])))
                    maps.append(mp)
            except GHTError as exc:
                say(f"  mix refused: {exc}")
                continue
            w = max(p.max_deviation for p in panels)
            if best_mix is None or w < best_mix[0]:
                best_mix = (w, panels, maps, seams)
            if w <= tol:
                break
        if best_mix is None:  # no developable between some seams: a finer march
            history.append({"f": f, "panels": n, "max_deviation": None, "error": "no developable between the seams"})
            panels = []
            f *= 0.93
            continue
        _, panels, maps, seams = best_mix
        worst = max(p.max_deviation for p in panels)
        history.append({"f": f, "panels": n, "max_deviation": worst})
        say(f"  {n} panels, max deviation {worst:.4g} (tol {tol:.4g})")
        if best is None or worst < best[0]:
            best = (worst, n)
        if worst <= tol:
            break
        f *= 0.93
    else:
        panels = []
    info["history"] = history
    if not panels or max(p.max_deviation for p in panels) > tol or len(panels) > max_panels:
        if best is None:
            raise GHTError(
                f"no approximation of the target within tol={tol:g} with at most max_panels={max_panels} panels: "
                f"the march needed more than {max_panels} strips; raise max_panels or tol"
            )
        raise GHTError(
            f"no approximation of the target within tol={tol:g} with at most max_panels={max_panels} panels; "
            f"best deviation reached {best[0]:.6g} with {best[1]} panels"
        )
    for p in panels:
        p.area = p.surface.area()
    dmap = {k: np.concatenate([m[k] for m in maps]) for k in maps[0]}
    info["methods"] = [p.method for p in panels]
    info["seconds"] = time.perf_counter() - t0
    seam_info = [{"y": s.y, "delta": [float(c) for c in s.coef], "point": s.point} for s in seams]
    return ApproximationResult(panels, tol, direction, frame.size, max(p.max_deviation for p in panels), dmap, seam_info, info)
