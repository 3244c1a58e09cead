"""Tracing the loft's branch of ``F = 0`` (spec section 5.7): boundary roots, predictor–corrector
continuation in ``λ = (t + s) / 2`` with Newton correction, and the corner-to-corner path of fans
and main part (:class:`_Path`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...core.errors import NotDevelopableError
from .equation import CORNER_RADIUS, MIN_FAN, _EPS, _Pair


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

