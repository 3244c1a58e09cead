r"""The target in strip coordinates (:class:`_Frame`): ``x`` along the seams, ``y`` across (the
rulings' way); normals, projections and signed distances. Moved from ``ght_cad/approximation.py``
(issue 27); every name is importable from :mod:`ght_cad.approximation`.

Strip directions (:func:`strip_uv`, maths 10.2), with the normalized parameters
``u_n = (u - u0) / (u1 - u0)``, ``v_n = (v - v0) / (v1 - v0)`` in [0, 1]:

* ``"v"``: rulings along v, seams the isolines of v: ``(u_n, v_n) = (x, y)``; ``"u"``: ``(y, x)``.
* ``"diagonal"`` (:class:`_DiagonalFrame`): seams the isolines ``u_n + v_n = s`` clipped to the box,
  ``s = 2 y``; the seam at ``s`` runs from ``(s, 0)`` to ``(0, s)`` for ``s <= 1``
  (``u_n = s (1 - x)``, ``v_n = s x``) and from ``(1, s - 1)`` to ``(s - 1, 1)`` for ``s > 1``
  (``u_n = 1 - (2 - s) x``, ``v_n = s - 1 + (2 - s) x``). Bilinear in ``(x, s)`` on each half:
  ``∂²u_n/∂x² = ∂²u_n/∂y² = 0``, ``∂²u_n/∂x∂y = ∓2``; the first derivative in y jumps at
  ``s = 1`` (y = 1/2, where the seam is the whole diagonal through the corners (1, 0) and
  (0, 1)), and the jet there is the one-sided one of the lower half. The seams at y = 0 and
  y = 1 are the corners (0, 0) and (1, 1): single points.
* ``"antidiagonal"``: the same with ``v_n -> 1 - v_n`` (seams the isolines of ``u_n - v_n``; the
  point seams are the corners (0, 1) and (1, 0)).
"""

from __future__ import annotations

import numpy as np

from ..core._vec import cross as _cross
from .target import SurfaceTarget

#: the strip directions: the parameter the rulings run along (``"u"``, ``"v"``) or the family of
#: seams (``"diagonal"``: isolines of u_n + v_n, ``"antidiagonal"``: of u_n - v_n)
STRIP_DIRECTIONS = ("u", "v", "diagonal", "antidiagonal")


def _diagonal_map(x: np.ndarray, y: np.ndarray, anti: bool) -> tuple[np.ndarray, ...]:
    r"""Normalized parameters of the diagonal frame and their derivatives (module doc):
    ``(u_n, v_n, u_x, v_x, u_y, v_y, u_xy, v_xy)`` (``u_xx = u_yy = 0`` on each half; at
    ``y = 1/2`` the lower half's one-sided values)."""
    x = np.asarray(x, dtype=float)
    s = 2.0 * np.asarray(y, dtype=float)
    lo = s <= 1.0
    one = np.ones_like(x)
    un = np.where(lo, s * (1 - x), 1 - (2 - s) * x)
    vn = np.where(lo, s * x, s - 1 + (2 - s) * x)
    ux = np.where(lo, -s, -(2 - s))
    vx = -ux
    uy = np.where(lo, 2 * (1 - x), 2 * x)
    vy = np.where(lo, 2 * x, 2 * (1 - x))
    uxy = np.where(lo, -2.0, 2.0) * one
    vxy = -uxy
    if anti:
        vn, vx, vy, vxy = 1 - vn, -vx, -vy, -vxy
    return un, vn, ux, vx, uy, vy, uxy, vxy


def strip_uv(direction: str, bounds: tuple[float, float, float, float], x: np.ndarray,
             y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Target parameters ``(u, v)`` of the strip coordinates ``(x, y)`` (x along the seams, y across)
    for a strip ``direction`` of :data:`STRIP_DIRECTIONS` on the parameter box ``bounds`` =
    ``(u0, u1, v0, v1)`` (module doc)."""
    u0, u1, v0, v1 = (float(b) for b in bounds)
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    if direction in ("diagonal", "antidiagonal"):
        un, vn = _diagonal_map(x, y, direction == "antidiagonal")[:2]
    elif direction == "u":
        un, vn = y, x
    elif direction == "v":
        un, vn = x, y
    else:
        raise ValueError(f"direction={direction!r} is not allowed; use one of {STRIP_DIRECTIONS}")
    return u0 + (u1 - u0) * un, v0 + (v1 - v0) * vn


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
        if direction not in ("u", "v") and not isinstance(self, _DiagonalFrame):
            raise ValueError(f"_Frame(direction={direction!r}) is not allowed; use 'u' or 'v', or make_frame() "
                             f"for any of {STRIP_DIRECTIONS}")
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

    def breaks(self) -> tuple[float, ...]:
        """Positions across (0 < y < 1) where a seam must lie (none here)."""
        return ()

    def project(self, X: np.ndarray, x: np.ndarray, y: np.ndarray, iters: int = 10) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closest target points of ``X`` by damped Gauss–Newton from ``(x, y)``, clamped to the
        square: at most ``iters`` steps, fewer once no parameter moved by more than ``1e-12`` (the
        convergence is linear with the ratio distance × curvature, 1e-3 on the panels: the next
        steps would move by rounding noise). Returns (x, y, signed distance ``(X - S)·n``)."""
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
            x1 = np.clip(x + np.clip(dx, -0.25, 0.25), 0, 1)
            y1 = np.clip(y + np.clip(dy, -0.25, 0.25), 0, 1)
            moved = max(float(np.max(np.abs(x1 - x), initial=0.0)), float(np.max(np.abs(y1 - y), initial=0.0)))
            x, y = x1, y1
            if moved <= 1e-12:
                break
        j = self.jet(x, y, 1)
        d = np.sum((X - j[0]) * self.normal(x, y, j), 1)
        return x, y, d


class _DiagonalFrame(_Frame):
    r"""The target on the unit square with seams along the isolines of ``u_n + v_n``
    (``"diagonal"``) or ``u_n - v_n`` (``"antidiagonal"``) of the normalized parameter box (module
    doc): rulings run across them. The jet by the chain rule of the piecewise bilinear map
    ``(x, y) -> (u_n, v_n)`` (:func:`_diagonal_map`):

        S_x = S_u u_x + S_v v_x,   S_y = S_u u_y + S_v v_y,
        S_xx = S_uu u_x² + 2 S_uv u_x v_x + S_vv v_x²,   S_yy likewise with y,
        S_xy = S_uu u_x u_y + S_uv (u_x v_y + u_y v_x) + S_vv v_x v_y + S_u u_xy + S_v v_xy

    (u, v the target's parameters: ``u_x = (u1 - u0) ∂u_n/∂x`` ...). A seam must lie at y = 1/2
    (:meth:`breaks`): there the seam runs through two corners of the box, and a strip across it
    would cut those corners off."""

    def __init__(self, target: SurfaceTarget, direction: str) -> None:
        if direction not in ("diagonal", "antidiagonal"):
            raise ValueError(f"direction={direction!r} is not allowed; use 'diagonal' or 'antidiagonal'")
        self.anti = direction == "antidiagonal"
        super().__init__(target, direction)
        self.swap = False

    def breaks(self) -> tuple[float, ...]:
        return (0.5,)

    def uv(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return strip_uv(self.direction, self.t.bounds, x, y)

    def jet(self, x: np.ndarray, y: np.ndarray, order: int = 1) -> list[np.ndarray]:
        x = np.asarray(x, dtype=float).ravel()
        y = np.asarray(y, dtype=float).ravel()
        un, vn, ux, vx, uy, vy, uxy, vxy = _diagonal_map(x, y, self.anti)
        du, dv = self.d
        u, v = self.o[0] + du * un, self.o[1] + dv * vn
        j = self.t.jet(u, v, min(order, 2) if order else 0)
        if order == 0:
            return j[:1]
        ux, uy, uxy = (du * a[:, None] for a in (ux, uy, uxy))
        vx, vy, vxy = (dv * a[:, None] for a in (vx, vy, vxy))
        S, Su, Sv = j[:3]
        out = [S, Su * ux + Sv * vx, Su * uy + Sv * vy]
        if order >= 2:
            Suu, Svv, Suv = j[3:6]
            out += [Suu * ux * ux + 2 * Suv * ux * vx + Svv * vx * vx,
                    Suu * uy * uy + 2 * Suv * uy * vy + Svv * vy * vy,
                    Suu * ux * uy + Suv * (ux * vy + uy * vx) + Svv * vx * vy + Su * uxy + Sv * vxy]
        return out


def make_frame(target: SurfaceTarget, direction: str) -> _Frame:
    """The frame of a strip ``direction`` (:data:`STRIP_DIRECTIONS`)."""
    if direction in ("diagonal", "antidiagonal"):
        return _DiagonalFrame(target, direction)
    if direction not in ("u", "v"):
        raise ValueError(f"direction={direction!r} is not allowed; use one of {STRIP_DIRECTIONS}")
    return _Frame(target, direction)
