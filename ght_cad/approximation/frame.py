r"""The target in strip coordinates (:class:`_Frame`): ``x`` along the seams, ``y`` across (the
rulings' way); normals, projections and signed distances. Moved from ``ght_cad/approximation.py``
(issue 27); every name is importable from :mod:`ght_cad.approximation`.
"""

from __future__ import annotations

import numpy as np

from ..core._vec import cross as _cross
from .target import SurfaceTarget


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
