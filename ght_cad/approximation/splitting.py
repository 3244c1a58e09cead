r"""Strip splitting: the strip-count estimate that picks the direction, the march of seams at a
deviation budget, the greedy split, and the seams' offsets that centre every strip's deviation
on the target. Moved from ``ght_cad/approximation.py`` (issue 27); every name is importable from
:mod:`ght_cad.approximation`.
"""

from __future__ import annotations

import numpy as np

from .frame import _Frame
from .seams import _ruling_deviation, _Seam, _strip_rulings


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
