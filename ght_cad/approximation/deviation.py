r"""Deviation measurement of a built panel both ways (panel points projected onto the target,
target points onto the panel, Gauss–Newton). Moved from ``ght_cad/approximation.py``
(issue 27); every name is importable from :mod:`ght_cad.approximation`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..surfaces.ruled import RuledSurface
from .frame import _Frame
from .seams import _Seam


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
