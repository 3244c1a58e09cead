r"""Strip splitting: the strip-count estimate that picks the direction, the march of seams at a
deviation budget, the greedy split, and the seams' offsets that centre every strip's deviation
on the target. Moved from ``ght_cad/approximation.py`` (issue 27); every name is importable from
:mod:`ght_cad.approximation`.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .frame import _Frame, make_frame
from .target import SurfaceTarget
from .seams import _ruling_deviation, _Seam, _strip_rulings


# ----------------------------------------------------------------------------------------------
# direction estimate
# ----------------------------------------------------------------------------------------------
def _estimate(frame: _Frame, tol: float, n: int = 33) -> float:
    r"""Strips needed across the frame (maths 10.2): ``max_x ∫_0^1 f(x, y) dy`` with

        f = sqrt(|det II| / (16 tol |L_xx|)),   det II = L_xx L_yy - L_xy²,

    ``L_xx = S_xx·n``, ``L_xy = S_xy·n``, ``L_yy = S_yy·n`` the second fundamental form in the
    frame's (x, y). The rulings of a strip between seams along x follow the conjugate direction
    ``r = L_xy S_x - L_xx S_y`` (``II(S_x, r) = 0``): across a strip of width dy a ruling has length
    ``|r| dy / |L_xx|`` and normal curvature ``κ_r = L_xx det II / |r|²``, so its sagitta split both
    ways is ``κ_r ℓ² / 16 = det II dy² / (16 L_xx)``; ``<= tol`` gives f strips per unit y. With
    ``L_xy = 0`` it is ``sqrt(|L_yy| / (16 tol))``, the normal curvature along the rulings; on a
    developable (``det II = 0``) it is 0; seams along asymptotic lines (``L_xx = 0``) would need
    rulings along the seams: ``|L_xx|`` is floored at ``1e-3 (|L_xx| + 2 |L_xy| + |L_yy|)`` so f
    stays finite there but large (about 16 times the diagonal value on the saddle ``z = x y / L``
    in its own parameters). Below that floor f² is at least ``|L_yy| / (16 tol)``: seams along the
    rulings of a developable (``L_xx = L_xy = 0``, every direction conjugate) bound planar strips
    whose sagitta is ``L_yy dy² / 8`` (a cylinder cut along its axis). Midpoint rule in y on
    ``n - 1`` rows (no row on a point seam), n columns in x."""
    x = np.linspace(0, 1, n)
    y = (np.arange(n - 1) + 0.5) / (n - 1)
    X, Y = np.meshgrid(x, y, indexing="ij")
    j = frame.jet(X.ravel(), Y.ravel(), 2)
    nrm = frame.normal(X.ravel(), Y.ravel(), j[:3])
    lxx, lyy, lxy = (np.sum(j[k] * nrm, 1) for k in (3, 4, 5))
    det = np.abs(lxx * lyy - lxy * lxy)
    floor = 1e-3 * (np.abs(lxx) + 2 * np.abs(lxy) + np.abs(lyy))
    f2 = det / np.maximum(np.maximum(np.abs(lxx), floor), 1e-300)
    # seams along a ruling of a developable (L_xx = L_xy = 0): every direction is conjugate, the
    # strip between two such seams is planar and deviates by L_yy dy² / 8
    f2 = np.where(np.abs(lxx) < floor, np.maximum(f2, np.abs(lyy)), f2)
    f = np.sqrt(f2 / (16 * tol)).reshape(n, n - 1)
    return float(np.max(np.sum(f, axis=1) / (n - 1)))


def _estimate_curvature(frame: _Frame, tol: float, n: int = 33) -> float:
    r"""The estimate before the conjugate one (kept for comparison in reports and tests):
    ``max_x ∫ sqrt(|κ_n(S_y)| / (16 tol)) |S_y| dy`` on an n × n grid (trapezoid rule): the normal
    curvature along the parameter the rulings run along."""
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


#: the diagonal strips are chosen only when their estimate is this many times below the better of u
#: and v (the u/v strips follow the target's own isolines: exact end seams, no corner cones)
DIAGONAL_GAIN = 2.0
#: ... and only when u/v need more than this many strips by the estimate
DIAGONAL_MIN_STRIPS = 1.0


def _choose_direction(target: SurfaceTarget, tol: float) -> tuple[str, dict[str, float]]:
    r"""``direction="auto"``: the strip direction of least :func:`_estimate` among ``"u"`` and ``"v"``;
    ``"diagonal"``/``"antidiagonal"`` instead only where the better of them needs fewer strips by the
    factor :data:`DIAGONAL_GAIN` (and u/v more than :data:`DIAGONAL_MIN_STRIPS`), never on a target
    closed along a parameter (a full turn: the diagonal seams would cross its seam line). Returns
    the direction and the estimates computed."""
    frames = {d: make_frame(target, d) for d in ("u", "v")}
    est = {d: _estimate(f, tol) for d, f in frames.items()}
    est = {d: (e if np.isfinite(e) else np.inf) for d, e in est.items()}
    best = min(est, key=lambda d: est[d])
    if any(f.closed_x for f in frames.values()) or not est[best] > DIAGONAL_MIN_STRIPS:
        return best, est
    for d in ("diagonal", "antidiagonal"):
        e = _estimate(make_frame(target, d), tol)
        est[d] = e if np.isfinite(e) else np.inf
    # "diagonal" unless "antidiagonal" is clearly better (a symmetric target ties up to rounding)
    diag = "antidiagonal" if est["antidiagonal"] < est["diagonal"] * (1 - 1e-6) else "diagonal"
    if est[diag] * DIAGONAL_GAIN < est[best]:
        best = diag
    return best, est


# ----------------------------------------------------------------------------------------------
# the approximation
# ----------------------------------------------------------------------------------------------
def _strip_range(frame: _Frame, A: _Seam, B: _Seam, n: int = 49) -> tuple[float, float]:
    d, _ = _ruling_deviation(frame, _strip_rulings(A, B, n))
    return float(d.min()), float(d.max())


def _march_caches(frame: _Frame) -> tuple[dict, dict]:
    """Per frame (kept on the frame, as the per-object caches of the other modules): the seams on
    the target (``_Seam(frame, y)``) and the strip ranges between two of them that the march has
    built, by ``y`` and ``(y0, y1)``: the greedy runs of :func:`_march_piece` repeat the same first
    trials (a pure function of the frame and the positions)."""
    c = frame.__dict__.get("_march_caches")
    if c is None:
        c = frame._march_caches = ({}, {})  # type: ignore[attr-defined]
    return c


def _seam_on(frame: _Frame, y: float) -> _Seam:
    """``_Seam(frame, y)``, remembered per frame."""
    seams = _march_caches(frame)[0]
    y = float(y)
    sm = seams.get(y)
    if sm is None:
        sm = seams[y] = _Seam(frame, y)
    return sm


def _range_between(frame: _Frame, y0: float, y1: float) -> tuple[float, float]:
    """:func:`_strip_range` of the strip between the seams on the target at ``y0`` and ``y1``,
    remembered per frame."""
    ranges = _march_caches(frame)[1]
    key = (float(y0), float(y1))
    r = ranges.get(key)
    if r is None:
        r = ranges[key] = _strip_range(frame, _seam_on(frame, y0), _seam_on(frame, y1))
    return r


def _march(frame: _Frame, tol: float, f: float, max_panels: int, min_width: float,
           balance: bool = True) -> list[float]:
    """Seam positions 0 = y_0 < ... < y_N = 1 by the greedy march (module doc, step 1) with the
    range limit ``2 tol f``, balanced: the smallest range limit that still gives N strips
    (bisection, 6 steps), so the last strip is not a narrow remainder (``balance=False``: the plain
    greedy march, for counting). The frame's :meth:`~_Frame.breaks` (the diagonal frame's
    y = 1/2) are seams: each piece between them is marched on its own. More than ``max_panels``
    strips: the march stops after ``max_panels + 1``."""
    cuts = [0.0, *frame.breaks(), 1.0]
    ys = [0.0]
    for a, b in zip(cuts[:-1], cuts[1:]):
        left = max_panels - (len(ys) - 1)
        if left < 1:
            return ys + [b]
        ys += _march_piece(frame, tol, f, left, min_width, a, b, balance)[1:]
    return ys


def _march_within(frame: _Frame, tol: float, f: float, max_panels: int, min_width: float,
                  doublings: int = 40, bisections: int = 6) -> list[float] | None:
    r"""The seams of the finest march with at most ``max_panels`` strips, for a march at
    ``f`` that needs more: the smallest share ``g`` (range limit ``2 tol g``) whose greedy march
    gives at most ``max_panels`` strips, found by doubling ``g = 2^k f`` until it fits and then
    ``bisections`` steps on ``log g`` (``g = sqrt(g_lo g_hi)``; stopped early at exactly
    ``max_panels`` strips), then :func:`_march` balanced at that ``g``. Marches only (no panel is
    built): the caller builds and measures the result once. None when no march fits (fewer
    ``max_panels`` than the frame's pieces between :meth:`~_Frame.breaks`, or a strip range that
    is not finite)."""
    if max_panels < len(frame.breaks()) + 1:
        return None
    lo, hi = f, None
    for _ in range(doublings):
        g = 2.0 * lo
        if len(_march(frame, tol, g, max_panels, min_width, balance=False)) - 1 <= max_panels:
            hi = g
            break
        lo = g
    if hi is None:
        return None
    for _ in range(bisections):
        mid = math.sqrt(lo * hi)
        n = len(_march(frame, tol, mid, max_panels, min_width, balance=False)) - 1
        if n <= max_panels:
            hi = mid
            if n == max_panels:
                break
        else:
            lo = mid
    return _march(frame, tol, hi, max_panels, min_width)


def _march_piece(frame: _Frame, tol: float, f: float, max_panels: int, min_width: float, y_start: float,
                 y_end: float, balance: bool = True) -> list[float]:
    """:func:`_march` from ``y_start`` to ``y_end``."""
    limit = 2 * tol * f
    ys = _greedy(frame, limit, max_panels, min_width, y_start, y_end)
    n = len(ys) - 1
    if n <= 1 or n > max_panels or not balance:
        return ys
    lo, hi = limit * ((n - 1) / n) ** 2 * 0.9, limit
    for _ in range(6):
        mid = 0.5 * (lo + hi)
        cand = _greedy(frame, mid, n, min_width, y_start, y_end)
        if len(cand) - 1 <= n:
            hi, ys = mid, cand
        else:
            lo = mid
    return ys


def _width(frame: _Frame, y0: float, y1: float) -> float:
    lo, hi = _range_between(frame, y0, y1)
    return hi - lo


def _bisection_point(y0: float, y_end: float, eps: float, j: int) -> float:
    """The float the bisection of ``[y0, y_end]`` to width ``eps`` (``mid = (lo + hi) / 2``) reaches
    as its lower end when grid point ``j`` (of ``y0 + j (y_end - y0) / 2^K``) passes and ``j + 1``
    fails: the same arithmetic, bit for bit."""
    lo, hi = y0, y_end
    a, b = 0, _levels(y0, y_end, eps)
    while hi - lo > eps and b - a > 1:
        mid = 0.5 * (lo + hi)
        m = (a + b) // 2
        if j >= m:
            lo, a = mid, m
        else:
            hi, b = mid, m
    return lo


def _levels(y0: float, y_end: float, eps: float) -> int:
    """``2^K``, K the halvings of ``y_end - y0`` down to ``eps``."""
    w, n = y_end - y0, 1
    while w > eps:
        w *= 0.5
        n *= 2
    return n


def _next_seam(width: Callable[[float], float], limit: float, y0: float, y_end: float, r_end: float) -> float:
    r"""The greedy step: the seam after ``y0``, the point of bisection of ``(y0, y_end]`` for the
    strip range ``width(y1) <= limit`` to ``eps = max(1e-3 (y_end - y0), 1e-9)``
    (``r_end = width(y_end) > limit``), found on the same grid ``y0 + j (y_end - y0) / 2^K`` with
    the same floats, so with a range that grows with y1 the same answer: the largest grid point
    that passes, the next one failing.

    The range grows about as a power of the strip width (measured on the hull: nearly linearly,
    not with its square): the power law ``r = c j^p`` through the last two trials (``p = 2`` from
    the end alone, ``0.25 <= p <= 8`` else bisection) estimates the index of ``r = limit``; the
    trial is the grid point below the estimate after a failing trial and the one above after a
    passing one (two trials then close the bracket). Safeguard: after two model steps in a row
    that do not halve the bracket, a bisection step. Measured on the hull march: 3-4 trials a seam
    instead of 10-11, the same seams."""
    eps = max(1e-3 * (y_end - y0), 1e-9)
    n = _levels(y0, y_end, eps)
    jl, jh = 0, n
    best = y0
    pts = [(float(n), r_end)]  # (index, range) of the trials, the end first
    passed = False
    slow = 0  # model steps in a row that did not halve the bracket
    while jh - jl > 1:
        before = jh - jl
        est = None
        if slow < 2 and limit > 0:
            # power law r = c j^p through the last two trials with r > 0 (p = 2 from one)
            (j1, r1), (j2, r2) = (pts[-2], pts[-1]) if len(pts) >= 2 else ((0.0, 0.0), pts[-1])
            if r2 > 0 and j2 > 0:
                p = 2.0
                if r1 > 0 and j1 > 0 and j1 != j2 and r1 != r2:
                    p = np.log(r2 / r1) / np.log(j2 / j1)
                if np.isfinite(p) and 0.25 <= p <= 8.0:
                    est = j2 * (limit / r2) ** (1.0 / p)
        if est is not None and np.isfinite(est):
            m = int(np.floor(est)) + (1 if passed else 0)
            m = min(max(m, jl + 1), jh - 1)
        else:
            m = (jl + jh) // 2
        y = _bisection_point(y0, y_end, eps, m)
        r = width(y)
        pts.append((float(m), r))
        passed = r <= limit
        if passed:
            jl, best = m, y
        else:
            jh = m
        slow = slow + 1 if est is not None and jh - jl > before // 2 else 0
    return best


def _greedy(frame: _Frame, limit: float, max_panels: int, min_width: float, y_start: float = 0.0,
            y_end: float = 1.0) -> list[float]:
    """The greedy march with the deviation range ``limit`` from ``y_start`` to ``y_end`` (stops
    after ``max_panels + 1`` strips)."""
    ys = [y_start]
    while ys[-1] < y_end:
        y0 = ys[-1]
        r_end = _width(frame, y0, y_end)
        if r_end <= limit:
            ys.append(y_end)
            break
        lo_y = _next_seam(lambda y1: _width(frame, y0, y1), limit, y0, y_end, r_end)
        nxt = max(lo_y, y0 + min_width)
        ys.append(min(nxt, y_end))
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
