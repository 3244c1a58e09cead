r"""Placing the developed skin faces: rigid motions of the plane, the geometry of one face
(outward normal, curvature across the rulings, Gaussian curvature, orientation of its development),
edge chords, bend angles, and moving a face's panel. Moved from ``ght_cad/sheetmetal/blank.py`` (issue 27);
every name is importable from :mod:`ght_cad.sheetmetal.blank`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np


# -- rigid motions ---------------------------------------------------------------------------------
@dataclass
class _Motion:
    """``x -> Q (m x) + c``: ``m`` mirrors x (``diag(-1, 1)``) when ``mirror``."""

    Q: np.ndarray = field(default_factory=lambda: np.eye(2))
    c: np.ndarray = field(default_factory=lambda: np.zeros(2))
    mirror: bool = False

    def __call__(self, p: np.ndarray) -> np.ndarray:
        p = np.asarray(p, dtype=float)
        if self.mirror:
            p = p * np.array([-1.0, 1.0])
        return p @ self.Q.T + self.c


def _motion_onto(a0: np.ndarray, a1: np.ndarray, q0: np.ndarray, q1: np.ndarray, mirror: bool) -> _Motion:
    """The rigid motion (after the optional mirror) taking the segment q0 q1 onto a0 a1 (q0 -> a0,
    direction q1 - q0 -> a1 - a0)."""
    m = _Motion(mirror=mirror)
    q0m, q1m = m(q0), m(q1)
    da, dq = a1 - a0, q1m - q0m
    ang = math.atan2(da[1], da[0]) - math.atan2(dq[1], dq[0])
    c, s = math.cos(ang), math.sin(ang)
    m.Q = np.array([[c, -s], [s, c]])
    m.c = a0 - m.Q @ q0m
    return m


# -- geometry of one face ------------------------------------------------------------------------------
def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _outward(face: Any, u: float, v: float) -> tuple[np.ndarray, list[np.ndarray]]:
    """Outward unit normal ``o (S_u × S_v)/|.|`` and the jet ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` at (u, v)."""
    d = face.surface.d2(np.array([u]), np.array([v]))
    d = [x[0] for x in d]
    n = _unit(np.cross(d[1], d[2]))
    return (-n if face.reversed else n), d


def _curvature(face: Any, ruled: str, u: float, v: float) -> tuple[float, np.ndarray]:
    r"""Signed principal curvature across the rulings ``κ = (S_xx · n) / |w|²`` (``x`` the
    parameter across the rulings, ``w`` the part of ``S_x`` normal to the ruling; ``n`` outward)
    and the outward normal: ``κ > 0`` when the face bends towards its outward side."""
    n, d = _outward(face, u, v)
    sx, sxx, r = (d[1], d[3], d[2]) if ruled == "v" else (d[2], d[4], d[1])
    r = _unit(r)
    w = sx - (sx @ r) * r
    return float(sxx @ n) / float(w @ w), n


def _gaussian_curvature(face: Any) -> float:
    r"""Gaussian curvature ``K = (L N - M²) / (E G - F²)`` at the middle of the face's parameter box
    (first fundamental form ``E = S_u·S_u``, ``F = S_u·S_v``, ``G = S_v·S_v``; second ``L = S_uu·n``,
    ``M = S_uv·n``, ``N = S_vv·n``); 0 on a developable face."""
    u0, u1, v0, v1 = face.bounds
    n, d = _outward(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1))
    E, F, G = d[1] @ d[1], d[1] @ d[2], d[2] @ d[2]
    L, M, N = d[3] @ n, d[5] @ n, d[4] @ n
    return float((L * N - M * M) / (E * G - F * F))


def _edge_uv(face: Any, name: str) -> Any:
    for wire in face.wires:
        for e in wire:
            if e.name == name:
                return e
    return None


# -- the walk --------------------------------------------------------------------------------------
def _edge_chord(panel: Any, name: str) -> tuple[np.ndarray, np.ndarray] | None:
    for loop in panel.loops:
        for e in loop:
            if e.name == name:
                f = np.asarray(e.flat_fn(np.array([0.0, 1.0])), dtype=float) + panel.offset
                return f[0], f[1]
    return None


def _jacobian_sign(panel: Any, face: Any) -> float:
    """Sign of ``det dF/d(u, v)`` times the face orientation: +1 when the development keeps the
    outward normal's sense (x, y, +z)."""
    u0, u1, v0, v1 = face.bounds
    u, v = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
    hu, hv = 1e-4 * (u1 - u0), 1e-4 * (v1 - v0)
    p = panel.map(np.array([u - hu, u + hu, u, u]), np.array([v, v, v - hv, v + hv]))
    fu, fv = p[1] - p[0], p[3] - p[2]
    det = fu[0] * fv[1] - fu[1] * fv[0]
    o = -1.0 if face.reversed else 1.0  # (u, v) against the outward normal: reversed faces
    return math.copysign(1.0, det) * o


def _edge_key_order(key: str) -> tuple[int, str]:
    digits = "".join(ch for ch in key if ch.isdigit())
    return (int(digits) if digits else 0, key)


def _side(a0: np.ndarray, a1: np.ndarray, p: np.ndarray) -> float:
    d = a1 - a0
    w = p - a0
    return float(d[0] * w[1] - d[1] * w[0])


def _panel_point(panel: Any, m: _Motion) -> np.ndarray:
    """An interior point of a placed face: its outline's area centroid (vertex mean if outside)."""
    from ...pattern.flat_pattern import _centroid

    return m(_centroid(panel.loop_polylines()[0]))


def _line_distance(l0: np.ndarray, l1: np.ndarray) -> float:
    """Distance from the midpoint of segment ``l1`` to the line of ``l0``."""
    d = _unit(l0[1] - l0[0])
    w = 0.5 * (l1[0] + l1[1]) - l0[0]
    return abs(float(d[0] * w[1] - d[1] * w[0]))


def _bend_angle(fd: Any, bi: dict[str, Any], tang: Sequence[np.ndarray]) -> float:
    """Bend angle: a cylinder's ``|Δu|``; else the angle between the outward normals at the two
    tangent edges (up to π)."""
    u0, u1, v0, v1 = fd.bounds
    if bi["kind"] == "cylinder":
        return abs(u1 - u0)
    if bi["ruled"] == "v":
        pts = ((u0, 0.5 * (v0 + v1)), (u1, 0.5 * (v0 + v1)))
    else:
        pts = ((0.5 * (u0 + u1), v0), (0.5 * (u0 + u1), v1))
    n0, _ = _outward(fd, *pts[0])
    n1, _ = _outward(fd, *pts[1])
    if bi["kind"] == "cone":
        return abs(u1 - u0)  # the cone turns by Δu about its axis (the angle between the end rulings' planes)
    return math.acos(max(-1.0, min(1.0, float(n0 @ n1))))


def _apply_motion(panel: Any, m: _Motion) -> None:
    """Move a face's panel by ``m`` in place (outline functions, bend lines; texts dropped)."""
    off = panel.offset.copy()
    for loop in panel.loops:
        for e in loop:
            f = e.flat_fn
            e.flat_fn = (lambda t, f=f: m(np.asarray(f(t), dtype=float) + off))
            e.flat = m(e.flat + off)
            if e.dense_flat.size:
                e.dense_flat = m(e.dense_flat + off)
    if panel.bend_lines.size:
        bl = panel.bend_lines
        panel.bend_lines = np.stack([m(bl[:, 0]), m(bl[:, 1])], axis=1)
    texts = [(m(np.array([x, y]) + off), s, h) for x, y, s, h in panel.texts]
    panel.offset = np.zeros(2)
    panel.texts = [(float(p[0]), float(p[1]), s, h) for p, s, h in texts]
    panel.forming_texts, panel.marks = [], []
    panel.development = None
