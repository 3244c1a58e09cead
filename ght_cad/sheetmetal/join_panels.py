r"""One blank from several developed panels whose surfaces meet tangentially (issue 23).

Two developable pieces that share a boundary edge and meet there at G1 or smoother (one tangent
plane along the edge, the pieces on opposite sides of it) are one developable sheet: the
development of the union restricted to each piece is that piece's own development up to a rigid
motion of the plane (a rotation, possibly with a reflection: turning the sheet over). So each
piece is developed exactly as on its own and the next one is placed by the motion
``x ↦ M x + t`` that maps its flat image of the shared edge onto the previous piece's:

* ``M = R(α)`` or ``R(α) diag(1, -1)``, ``det M`` chosen so that the two interiors lie on
  opposite sides of the edge: with loop orientations ``s_i`` (the sign of the outer loop's
  area, after the motion already applied to piece i) and ``s_j``, and ``σ = ±1`` when the edges
  run the same / opposite way in 3-D, ``det M = -sgn(s_i s_j σ)``;
* ``α`` turns the flat chord of the child's edge onto the parent's, ``t`` maps the chords'
  midpoints onto each other (exact for any edge whose flat images are congruent: the geodesic
  curvature of a curve is that of its tangent planes, the same on both pieces at a G1 joint);
* the fit is checked on 17 interior points of the edge (3-D correspondence by nearest point).

The outer loops are merged into one loop (the parent's edges after the shared edge round to
before it, then the child's, traversed the way that keeps one orientation), the joint becomes a
bend line (a straight joint: a ruling) or a row of marks (a curved joint), and the joined panel
is measured again (:func:`ght_cad.pattern.flat_pattern.measure_panel`: its flat area is the sum of the
pieces' to rounding, the shared edges' contributions cancel). Pieces meeting at an angle (a sharp
chine, G0) are not joined: the angle between the inward conormal of one piece and the outward
conormal of the other, ``max_k ∠(m_i, -m_j)`` over the edge, must be at most ``tol_deg``. The
pieces form a graph (one node per panel, one link per tangent shared edge); a spanning tree
(breadth first from the first panel) is joined, links off the tree stay cut edges with matching
marks, as do chines. A joined outline that overlaps itself is not cut from one sheet: its pieces
are kept apart (``info["join"]`` says why).

This module is kernel-free (numpy only).
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from ..pattern.flat_pattern import (BoundaryEdge, FlatPanel, _polyline_param, _sagitta3, _shoelace, measure_panel,
                           shared_edge_pairs)
from ..unrolling.ruled_development import RULED_EDGE_UV

__all__ = ["join_panels", "ruled_conormals", "JoinedDevelopment", "rigid_motion_onto", "outline_self_overlap"]

#: interior edge parameters of the tangency and fit checks (ends left out: a fan's apex, a pointed end)
_CHECK_T = np.linspace(0.03, 0.97, 17)

Conormals = Callable[[str, np.ndarray], "np.ndarray | None"]


def ruled_conormals(surface: Any) -> Conormals:
    r"""Inward unit conormals along the four edges of a ruled panel (:data:`ght_cad.unroll.RULED_EDGE_UV`).

    At edge parameters ``t`` the edge point is ``X(u(t), v(t))``; the conormal is the surface's
    inward partial made orthogonal to the edge tangent: along ``a`` (``v = 0``) and ``b``
    (``v = 1``) ``±(X_v - (X_v·τ)τ)``, ``τ = X_u / |X_u|``; along the rulings ``u = 0``, ``u = 1``
    ``±(X_u - (X_u·d)d)``, ``d = X_v / |X_v|`` (sign: into the panel).

    Returns:
        ``f(edge_name, t) -> (n, 3)`` unit vectors, or None for an edge name it does not know.
    """
    inward = {"a": ("v", 1.0), "ruling u=1": ("u", -1.0), "b": ("v", -1.0), "ruling u=0": ("u", 1.0)}

    def conormal(name: str, t: np.ndarray) -> np.ndarray | None:
        if name not in inward:
            return None
        u, v = RULED_EDGE_UV[name](np.asarray(t, dtype=float))
        xu, xv = surface.partials(u, v)
        which, sign = inward[name]
        w, tan = (xv, xu) if which == "v" else (xu, xv)
        tan = tan / np.linalg.norm(tan, axis=1, keepdims=True)
        m = sign * (w - np.sum(w * tan, axis=1, keepdims=True) * tan)
        return m / np.linalg.norm(m, axis=1, keepdims=True)

    return conormal


def rigid_motion_onto(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray,
                      det: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    r"""The plane motion ``x ↦ M x + t`` taking the chord ``q0 q1`` onto ``p0 p1``.

    ``M = R(α) F``, ``F = diag(1, -1)`` when ``det < 0`` else the identity,
    ``α = arg(p1 - p0) - arg(F (q1 - q0))``, ``t = (p0 + p1)/2 - M (q0 + q1)/2`` (the chords'
    midpoints coincide; equal chord lengths are assumed, not enforced).

    Returns:
        ``(M, t)``: (2, 2) and (2,).
    """
    F = np.diag([1.0, -1.0]) if det < 0 else np.eye(2)
    dq = F @ (np.asarray(q1, float) - np.asarray(q0, float))
    dp = np.asarray(p1, float) - np.asarray(p0, float)
    a = math.atan2(dp[1], dp[0]) - math.atan2(dq[1], dq[0])
    ca, sa = math.cos(a), math.sin(a)
    M = np.array([[ca, -sa], [sa, ca]]) @ F
    t = 0.5 * (np.asarray(p0, float) + np.asarray(p1, float)) - M @ (0.5 * (np.asarray(q0, float) + np.asarray(q1, float)))
    return M, t


def _segments_cross(P: np.ndarray, Q: np.ndarray, A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(k, m) mask: segment k (P→Q) properly crosses segment m (A→B) (strict, both interiors)."""
    R, S = Q - P, B - A
    den = R[:, None, 0] * S[None, :, 1] - R[:, None, 1] * S[None, :, 0]
    d = A[None, :, :] - P[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (d[..., 0] * S[None, :, 1] - d[..., 1] * S[None, :, 0]) / den
        w = (d[..., 0] * R[:, None, 1] - d[..., 1] * R[:, None, 0]) / den
    eps = 1e-9
    return (np.abs(den) > 0) & (t > eps) & (t < 1 - eps) & (w > eps) & (w < 1 - eps)


def outline_self_overlap(loop: np.ndarray, chunk: int = 512) -> int:
    """Number of pairs of non-adjacent segments of a closed polyline that cross each other (0: a
    simple loop). O(n²) in blocks of ``chunk`` segments, with a bounding-box prefilter per block."""
    P = np.asarray(loop, dtype=float)
    Q = np.concatenate([P[1:], P[:1]])
    n = len(P)
    lo, hi = np.minimum(P, Q), np.maximum(P, Q)
    count = 0
    for s in range(0, n, chunk):
        e = min(s + chunk, n)
        blo, bhi = lo[s:e].min(axis=0), hi[s:e].max(axis=0)
        cand = np.nonzero(np.all(hi >= blo, axis=1) & np.all(lo <= bhi, axis=1))[0]
        cand = cand[cand >= s]  # each unordered pair once (j >= i below)
        if not cand.size:
            continue
        X = _segments_cross(P[s:e], Q[s:e], P[cand], Q[cand])
        i = np.arange(s, e)[:, None]
        j = cand[None, :]
        gap = np.abs(i - j)
        X &= (j > i) & (gap > 1) & (gap < n - 1)
        count += int(X.sum())
    return count


class JoinedDevelopment:
    """The development map of a joined blank: part ``k``'s map followed by its motion.

    ``map(u, v)`` takes ``u`` in ``[0, n]`` for ``n`` parts: part ``k = min(⌊u⌋, n - 1)`` at its own
    parameter ``u - k`` (a composite surface's strips in order); :meth:`part_map` maps one part.
    """

    def __init__(self, parts: Sequence[tuple[Any, np.ndarray, np.ndarray]]) -> None:
        self.parts = list(parts)  # (development, M, t)

    def part_map(self, k: int, u: Any, v: Any) -> np.ndarray:
        """Flat image of ``(u, v)`` of part ``k`` in the blank's coordinates."""
        dev, M, t = self.parts[k]
        return np.asarray(dev.map(u, v), dtype=float) @ M.T + t

    def map(self, u: Any, v: Any) -> np.ndarray:
        uu, vv = np.broadcast_arrays(np.atleast_1d(np.asarray(u, float)), np.atleast_1d(np.asarray(v, float)))
        uu, vv = uu.ravel(), vv.ravel()
        k = np.minimum(np.floor(uu).astype(int), len(self.parts) - 1)
        k = np.maximum(k, 0)
        out = np.empty((uu.size, 2))
        for kk in np.unique(k).tolist():
            sel = k == kk
            out[sel] = self.part_map(kk, uu[sel] - kk, vv[sel])
        return out


@dataclass
class _Placed:
    """One edge of a merged loop: the part's edge ``edge`` of panel ``panel``, run backwards if ``rev``."""

    edge: BoundaryEdge
    panel: int
    rev: bool


def _moved_edge(edge: BoundaryEdge, label: str, M: np.ndarray, t: np.ndarray, rev: bool) -> BoundaryEdge:
    """The edge under the motion ``x ↦ M x + t`` (run backwards when ``rev``), named ``label:name``."""
    f, g = edge.flat_fn, edge.xyz_fn
    if rev:
        def flat(s: np.ndarray) -> np.ndarray:
            return np.asarray(f(1.0 - np.asarray(s, float)), dtype=float) @ M.T + t

        def xyz(s: np.ndarray) -> np.ndarray:
            return g(1.0 - np.asarray(s, float))
        breaks = tuple(sorted(1.0 - b for b in edge.breaks))
    else:
        def flat(s: np.ndarray) -> np.ndarray:
            return np.asarray(f(s), dtype=float) @ M.T + t

        xyz, breaks = g, edge.breaks
    out = BoundaryEdge(name=f"{label}:{edge.name}", flat_fn=flat, xyz_fn=xyz, length_3d=edge.length_3d,
                       samples=edge.samples, breaks=breaks)
    out.xyz = edge.xyz[::-1].copy() if rev else edge.xyz.copy()  # the points the edges were matched on
    return out


def _orientation(panel: FlatPanel) -> float:
    """Sign of the outer loop's area in the panel's own coordinates (+1: counter-clockwise)."""
    pts = np.concatenate([e.flat[:-1] for e in panel.loops[0]], axis=0)
    return 1.0 if _shoelace(pts) >= 0 else -1.0


def _straight(xyz: np.ndarray, rel: float = 1e-9) -> bool:
    """The 3-D polyline is a straight segment (every point within ``rel`` of its length of the chord)."""
    c = xyz[-1] - xyz[0]
    L = float(np.linalg.norm(c))
    if L == 0:
        return False
    d = np.linalg.norm(np.cross(xyz - xyz[0], c / L), axis=1)
    return bool(d.max() <= rel * L)


def _closest_params(edge: BoundaryEdge, points: np.ndarray, steps: int = 4) -> np.ndarray:
    r"""Edge parameters of the points nearest to ``points`` (on the edge): the nearest point of its
    sample polyline, then Newton steps on ``(X(t) - p)·X'(t) = 0`` with
    ``t ← t - (X - p)·X' / |X'|²`` (``X'`` by a central difference, ``h = 1e-6``)."""
    _, s = _polyline_param(edge.xyz, points)
    t = np.clip(s / (len(edge.xyz) - 1), 0.0, 1.0)
    h = 1e-6
    for _ in range(steps):
        tc = np.clip(t, h, 1.0 - h)
        d = (np.asarray(edge.xyz_fn(tc + h), float) - np.asarray(edge.xyz_fn(tc - h), float)) / (2 * h)
        r = np.asarray(edge.xyz_fn(t), float) - points
        t = np.clip(t - np.sum(r * d, axis=1) / np.maximum(np.sum(d * d, axis=1), 1e-300), 0.0, 1.0)
    return t


def _tangency(e1: BoundaryEdge, c1: Conormals, e2: BoundaryEdge, c2: Conormals) -> tuple[float, np.ndarray, np.ndarray]:
    """``max ∠(m_1, -m_2)`` in degrees over :data:`_CHECK_T` of edge 1, with edge 2's parameters at
    the same 3-D points (nearest point on its samples); inf when a conormal is unknown."""
    p3 = np.asarray(e1.xyz_fn(_CHECK_T), dtype=float)
    t2 = _closest_params(e2, p3)
    m1, m2 = c1(e1.name, _CHECK_T), c2(e2.name, t2)
    if m1 is None or m2 is None:
        return math.inf, _CHECK_T, t2
    cosang = np.clip(-np.sum(m1 * m2, axis=1), -1.0, 1.0)
    sinang = np.linalg.norm(np.cross(m1, -m2), axis=1)
    return float(np.degrees(np.arctan2(sinang, cosang)).max()), _CHECK_T, t2


def join_panels(
    panels: Sequence[FlatPanel],
    conormals: Sequence[Conormals | None],
    *,
    tol_deg: float,
    rel_tol: float = 1e-5,
    label: str | None = None,
) -> list[FlatPanel]:
    r"""Join panels that meet tangentially along whole shared edges into blanks (module doc).

    Args:
        panels: measured panels (outline edges with 3-D points; the edges' ``xyz`` are what is
            matched, :func:`ght_cad.pattern.flat_pattern.shared_edge_pairs`).
        conormals: per panel, the inward conormals of its edges (:func:`ruled_conormals`) or None
            (the panel is never joined).
        tol_deg: largest angle between the pieces' tangent half-planes at a joint still joined.
        rel_tol: shared-edge matching tolerance (relative to the model size).
        label: the label of a blank made of all panels (default: the parts' labels joined by ``+``).

    Returns:
        The blanks and the panels left alone, in the order of their first panel. A blank's
        ``info`` holds ``parts`` (label, areas, motion), ``joints`` (the edges, the tangency angle,
        the fit residual, ``bend line`` or ``mark``) and, for pieces unrolled with a sheet, one
        ``sheet`` entry of all parts (edges renamed ``part:edge``, forming rows renumbered, positions
        and the roll chart continued along the blank).
    """
    n = len(panels)
    if n < 2:
        return list(panels)
    pairs = [(pi, e1, pj, e2) for pi, e1, pj, e2 in shared_edge_pairs(panels, rel_tol)
             if pi != pj and conormals[pi] is not None and conormals[pj] is not None
             and any(e1 is e for e in panels[pi].loops[0]) and any(e2 is e for e in panels[pj].loops[0])]
    links: dict[int, list[tuple[int, BoundaryEdge, int, BoundaryEdge, float]]] = {i: [] for i in range(n)}
    for pi, e1, pj, e2 in pairs:
        ang = _tangency(e1, conormals[pi], e2, conormals[pj])[0]  # type: ignore[arg-type]
        if ang <= tol_deg:
            links[pi].append((pi, e1, pj, e2, ang))
            links[pj].append((pj, e2, pi, e1, ang))
    allpts = np.concatenate([e.xyz for p in panels for e in p.loops[0]], axis=0)
    size = float(np.max(allpts.max(axis=0) - allpts.min(axis=0)))
    done = [False] * n
    out: list[FlatPanel] = []
    for root in range(n):
        if done[root]:
            continue
        done[root] = True
        if not links[root]:
            out.append(panels[root])
            continue
        group = _Group(panels, root)
        queue = deque([root])
        while queue:
            i = queue.popleft()
            for _, e1, j, e2, ang in links[i]:
                if done[j]:
                    continue
                if group.attach(i, e1, j, e2, ang, size, rel_tol):
                    done[j] = True
                    queue.append(j)
        if len(group.members) == 1:
            out.append(panels[root])
            continue
        blank = group.panel(label if len(group.members) == n else None)
        overlaps = outline_self_overlap(blank.loop_polylines()[0])
        if overlaps:
            note = (f"kept apart: joining {', '.join(panels[k].label for k in group.members)} gives an outline "
                    f"that overlaps itself ({overlaps} crossing segment pairs)")
            for k in group.members:
                panels[k].info["join"] = note
                out.append(panels[k])
            continue
        out.append(blank)
    return out


class _Group:
    """A blank under construction: its members' motions and the merged outer loop."""

    def __init__(self, panels: Sequence[FlatPanel], root: int) -> None:
        self.panels = panels
        self.members = [root]
        self.motion: dict[int, tuple[np.ndarray, np.ndarray]] = {root: (np.eye(2), np.zeros(2))}
        self.orient = {root: _orientation(panels[root])}
        self.loop = [_Placed(e, root, False) for e in panels[root].loops[0]]
        self.joints: list[dict[str, Any]] = []
        self.joint_lines: list[np.ndarray] = []  # flat points of each joint (blank coordinates)

    def _flat(self, k: int, e: BoundaryEdge, t: np.ndarray) -> np.ndarray:
        M, tv = self.motion[k]
        return np.asarray(e.flat_fn(t), dtype=float) @ M.T + tv

    def attach(self, i: int, e1: BoundaryEdge, j: int, e2: BoundaryEdge, ang: float, size: float, rel_tol: float) -> bool:
        """Place panel j across its edge e2 onto member i's edge e1 and merge its loop; False (and
        nothing changed) when the fit of the edges is off by more than the matching tolerance."""
        x1, x2 = e1.xyz, e2.xyz
        same = float(np.linalg.norm(x1[0] - x2[0]) + np.linalg.norm(x1[-1] - x2[-1])) <= \
            float(np.linalg.norm(x1[0] - x2[-1]) + np.linalg.norm(x1[-1] - x2[0]))
        sigma = 1.0 if same else -1.0
        oj = _orientation(self.panels[j])
        det = -math.copysign(1.0, self.orient[i] * oj * sigma)
        P = self._flat(i, e1, np.array([0.0, 1.0]))
        Q = np.asarray(e2.flat_fn(np.array([0.0, 1.0]) if same else np.array([1.0, 0.0])), dtype=float)
        M, tv = rigid_motion_onto(P[0], P[1], Q[0], Q[1], det)
        # the fit on interior points at the same 3-D places
        _, t1, t2 = _tangency(e1, lambda *_: None, e2, lambda *_: None)
        fit = float(np.max(np.linalg.norm(self._flat(i, e1, t1) - (np.asarray(e2.flat_fn(t2), float) @ M.T + tv), axis=1)))
        tol = rel_tol * size + 4.0 * max(_sagitta3(x1), _sagitta3(x2))
        if not fit <= tol:
            return False
        self.motion[j] = (M, tv)
        self.orient[j] = oj * det
        k = next(idx for idx, pl in enumerate(self.loop) if pl.edge is e1)
        own = [_Placed(e, j, False) for e in self.panels[j].loops[0]]
        if self.orient[j] != self.orient[self.members[0]]:
            own = [_Placed(pl.edge, j, True) for pl in reversed(own)]
        m = next(idx for idx, pl in enumerate(own) if pl.edge is e2)
        self.loop = self.loop[k + 1:] + self.loop[:k] + own[m + 1:] + own[:m]
        self.members.append(j)
        line = self._flat(i, e1, np.linspace(0.0, 1.0, 33))
        straight = _straight(np.asarray(e1.xyz_fn(np.linspace(0.0, 1.0, 33)), dtype=float))
        self.joint_lines.append(line[[0, -1]] if straight else line)
        self.joints.append({"parts": [self.panels[i].label, self.panels[j].label], "edges": [e1.name, e2.name],
                            "tangency_deg": ang, "fit": fit, "kind": "bend line" if straight else "mark"})
        return True

    def panel(self, label: str | None) -> FlatPanel:
        """The joined, measured blank."""
        order = sorted(self.members)
        ps = [self.panels[k] for k in order]
        lab = label or "+".join(p.label for p in ps)
        loop = [_moved_edge(pl.edge, self.panels[pl.panel].label, *self.motion[pl.panel], pl.rev) for pl in self.loop]
        holes = [[_moved_edge(e, self.panels[k].label, *self.motion[k], False) for e in lp]
                 for k in order for lp in self.panels[k].loops[1:]]
        bends = [p.bend_lines @ self.motion[k][0].T + self.motion[k][1] for k, p in zip(order, ps) if p.bend_lines.size]
        bends += [ln[None] for ln in self.joint_lines if len(ln) == 2]
        marks = [np.array([a, b]) for ln in self.joint_lines if len(ln) > 2 for a, b in zip(ln[:-1], ln[1:])]
        forming = []
        for k, p in zip(order, ps):
            M, tv = self.motion[k]
            for x, y, s, h, a in p.forming_texts:
                q = M @ np.array([x, y]) + tv
                d = M @ np.array([math.cos(math.radians(a)), math.sin(math.radians(a))])
                ang = math.degrees(math.atan2(d[1], d[0]))
                ang = ang - 180 if ang > 90 else ang + 180 if ang < -90 else ang
                forming.append((float(q[0]), float(q[1]), s, h, ang))
        metric = {key: np.concatenate([p.metric[key] for p in ps]) for key in ps[0].metric} if all(p.metric for p in ps) else {}
        info: dict[str, Any] = {
            "method": "joined developments (pieces placed across their tangent shared edges, ght_cad.join_panels)",
            "parts": [{"label": p.label, "area_flat": float(p.area_flat), "area_3d": float(p.area_3d),
                       "matrix": self.motion[k][0].tolist(), "translation": self.motion[k][1].tolist()}
                      for k, p in zip(order, ps)],
            "joints": self.joints,
        }
        sheet = _joined_sheet([(p.label, p.info.get("sheet")) for p in ps])
        if sheet is not None:
            info["sheet"] = sheet
        blank = FlatPanel(
            label=lab,
            loops=[loop] + holes,
            bend_lines=np.concatenate(bends, axis=0) if bends else np.zeros((0, 2, 2)),
            ruling_lengths_3d=np.concatenate([p.ruling_lengths_3d for p in ps]),
            ruling_lengths_flat=np.concatenate([p.ruling_lengths_flat for p in ps]),
            area_3d=float(sum(p.area_3d for p in ps)),
            metric=metric,
            info=info,
            development=JoinedDevelopment([(p.development, *self.motion[k]) for k, p in zip(order, ps)]),
            marks=marks,
            forming_texts=forming,
        )
        measure_panel(blank)
        return blank


def _joined_sheet(parts: Sequence[tuple[str, dict[str, Any] | None]]) -> dict[str, Any] | None:
    """One ``info["sheet"]`` of the parts' (None when no part has one): the first part's sheet
    values, every part's edges named ``part:edge``, forming rows numbered on along the blank and
    positions (rows and chart) continued from the previous part's end; the smallest bending radius."""
    have = [(lab, sh) for lab, sh in parts if sh]
    if not have:
        return None
    out = {k: v for k, v in have[0][1].items() if k not in ("edges", "forming", "chart", "min_bending_radius")}
    out["min_bending_radius"] = min(float(sh["min_bending_radius"]) for _, sh in have)
    out["edges"] = [{**e, "edge": f"{lab}:{e['edge']}"} for lab, sh in have for e in sh["edges"]]
    rows: list[dict[str, Any]] = []
    chart: dict[str, list[float]] = {"position": [], "radius_a": [], "radius_b": []}
    start = 0.0
    line = 0
    for _, sh in have:
        for r in sh["forming"]:
            if r["line"]:
                line += 1
            rows.append({**r, "line": line if r["line"] else 0, "position": r["position"] + start})
        ch = sh["chart"]
        chart["position"] += [x + start for x in ch["position"]]
        chart["radius_a"] += list(ch["radius_a"])
        chart["radius_b"] += list(ch["radius_b"])
        start += ch["position"][-1] if ch["position"] else 0.0
    out["forming"] = rows
    out["chart"] = chart
    return out
