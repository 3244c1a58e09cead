"""The loft equation (spec section 5.7): the tangent-plane function
``F(t, s) = det(a'(t), b'(s), b(s) - a(t))``, its derivatives and its continuation near meeting
rail ends (:class:`_Pair`), and :func:`loft_function`."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...core._quadrature import leggauss
from ...core.errors import NotDevelopableError
from .rails import _det, _jet, as_rail


_EPS = np.finfo(float).eps
#: rails whose ends are closer than this (relative to the size) meet there: a pointed loft end
CORNER_TOL = 1e-12
#: parameter distance from a meeting corner within which ``g = b - a`` is integrated (no cancellation)
CORNER_RADIUS = 1.0 / 32
_CORNER_GL = leggauss(16)
#: relative size of a fan (in the rail parameter) below which the branch is taken to start or end
#: at the corner (no fan)
MIN_FAN = 1e-12

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

def loft_function(rail_a: Any, rail_b: Any, t: Any, s: Any, *, normalized: bool = True) -> np.ndarray:
    r"""``F(t, s) = det(a'(t), b'(s), b(s) - a(t))`` (or ``F / (|a'||b'||b - a|)`` when normalized)
    at broadcast parameter arrays."""
    ra = as_rail(rail_a, "rail_a")
    rb = as_rail(rail_b, "rail_b")
    tt, ss = np.broadcast_arrays(np.asarray(t, float), np.asarray(s, float))
    pair = _Pair(ra, rb, 1.0)
    fn = pair.f if normalized else pair.F
    return fn(tt.ravel(), ss.ravel()).reshape(tt.shape)

