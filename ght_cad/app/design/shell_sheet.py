r"""A ``[sheet]`` on several surfaces (``[[surfaces]]``): one shell, the material on one side of it.

Orientation rule. Every part of a surface is a ruled surface ``X(u, v) = a(u) + v g(u)`` with the
unit normal ``n = X_u × X_v / |X_u × X_v|`` (:func:`ght_cad.sheetmetal.sheet.ruling_normal`). That normal
orients the parameter square counter-clockwise, so it induces on the boundary ``a`` the direction
``+a'(u)`` and on ``b`` the direction ``-b'(u)``. Two surfaces sharing a rail (a boundary ``a`` or
``b`` of one lies on a boundary of the other: points within ``1e-6`` of the model size) are
oriented consistently when they induce **opposite** directions on the shared rail (as the two
faces of one sewn shell do). Breadth first over the surfaces in file order, the first surface of
each connected shell provisionally keeps its normal and every surface sharing a rail with an
oriented one gets ``±1`` so that the pair is consistent. Then each connected shell is turned
**outward**: when ``∫ (X - c)·N dA < 0`` (``N`` the shell's normal, ``c`` the shell's area
centroid), every orientation of that shell flips, so the shell's normal points to its convex
side (away from its centroid: outboard on a hull, out of a duct) whatever the order and
direction of every surface's rails. ``orientation`` (±1) is the sign of a surface's own normal
against the shell's. ``sheet.side`` is then measured on the shell's normal
``orientation · n`` (``"normal"``: the material on the outer, convex side); with
``side_reference = "surface"`` on each surface's own ``n``. A shell that cannot be oriented (a cycle of rails that contradict each other, e.g. three
surfaces on one rail) is refused with ``side_reference = "shell"``.

Joints. Along a shared rail point ``p`` the plates' outside edges are ``p + T_i m_i`` (``m_i`` the
unit direction the material of surface ``i`` goes, ``T_i`` its thickness); the report gives the
largest distance between the two outside edges, the fold angle between ``m_i`` and ``m_j``
(0: the plates continue each other) and whether the plates overlap (the material on the concave
side of the fold: the other surface turns towards it) or leave an open wedge (a gap: the material
on the convex side). Nothing is trimmed.

numpy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np

from ...core.errors import GHTError
from .build import BuiltSurface, sheet_parts, table_k_factor
from .schema import Design, DesignError, SheetSpec

#: points along each boundary tested against the other surfaces' boundaries
RAIL_SAMPLES = 129
#: a boundary point lies on another boundary within this fraction of the model size
RAIL_TOL = 1e-6


@dataclass
class SharedRail:
    """A rail shared by parts of two surfaces: boundary ``edge_i`` (``"a"``/``"b"``) of part
    ``part_i`` of surface ``i`` and ``edge_j`` of part ``part_j`` of surface ``j``, at the matched
    parameters ``u_i``/``u_j`` (same 3-D points ``points``) and the induced-direction vote
    (``> 0``: the given normals induce the same direction, i.e. they are inconsistent)."""

    i: int
    part_i: int
    edge_i: str
    j: int
    part_j: int
    edge_j: str
    u_i: np.ndarray
    u_j: np.ndarray
    points: np.ndarray
    vote: float


@dataclass
class SurfaceSheet:
    """The sheet of one surface: what the file asks and what it means on the surface's own normal."""

    name: str
    key: str
    requested: SheetSpec
    orientation: float
    sheet: SheetSpec  # side relative to the surface's own normal (what plate and unroll use)
    centre: list[float] = field(default_factory=list)
    normal: list[float] = field(default_factory=list)
    material: list[float] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        return {"surface": self.name, "thickness": self.sheet.thickness, "k_factor": self.sheet.k_factor,
                "side": self.requested.side, "side_reference": self.requested.side_reference,
                "orientation": int(self.orientation), "side_on_own_normal": self.sheet.side,
                "centre": self.centre, "normal_at_centre": self.normal, "material_direction": self.material,
                "material_goes": _direction_words(np.asarray(self.material)),
                **({"k_factor_ratio": self.sheet.k_factor_ratio} if self.sheet.k_factor_ratio is not None else {})}


def _direction_words(m: np.ndarray) -> str:
    """``"+x -y"``-style words for the largest components of a unit vector (|c| >= 0.3)."""
    words = [f"{'+' if c > 0 else '-'}{ax}" for ax, c in zip("xyz", m) if abs(c) >= 0.3]
    return " ".join(words) or "mixed"


def _edge(part: Any, which: str, u: np.ndarray, d: int = 0) -> np.ndarray:
    return np.asarray(part.a(u, d) if which == "a" else part.b(u, d), dtype=float)


def _induced(part: Any, which: str, u: np.ndarray) -> np.ndarray:
    """Direction the part's normal induces on its boundary: ``+a'`` on a, ``-b'`` on b."""
    t = _edge(part, which, u, 1)
    return t if which == "a" else -t


def _closest(part: Any, which: str, pts: np.ndarray, dense: int = 2049) -> tuple[np.ndarray, np.ndarray]:
    """Parameters of the points of boundary ``which`` closest to ``pts`` and the distances
    (nearest of ``dense`` samples, then Newton on ``(c(u) - p)·c'(u) = 0``, clamped to [0, 1])."""
    ud = np.linspace(0.0, 1.0, dense)
    cd = _edge(part, which, ud)
    d2 = ((pts[:, None, :] - cd[None, :, :]) ** 2).sum(axis=2)
    u = ud[np.argmin(d2, axis=1)]
    for _ in range(8):
        c, c1, c2 = _edge(part, which, u), _edge(part, which, u, 1), _edge(part, which, u, 2)
        r = c - pts
        f = np.einsum("ij,ij->i", r, c1)
        fp = np.einsum("ij,ij->i", c1, c1) + np.einsum("ij,ij->i", r, c2)
        step = np.where(np.abs(fp) > 1e-300, f / np.where(fp == 0, 1.0, fp), 0.0)
        u = np.clip(u - step, 0.0, 1.0)
    return u, np.linalg.norm(_edge(part, which, u) - pts, axis=1)


def model_size(builts: Sequence[BuiltSurface]) -> float:
    """Largest bounding-box extent of the surfaces' boundaries (sampled)."""
    u = np.linspace(0.0, 1.0, 65)
    pts = np.concatenate([_edge(p, w, u) for b in builts for p in sheet_parts(b.surface) for w in "ab"])
    return float(np.max(pts.max(axis=0) - pts.min(axis=0)))


def shared_rails(builts: Sequence[BuiltSurface], *, samples: int = RAIL_SAMPLES, rel_tol: float = RAIL_TOL) -> list[SharedRail]:
    """Every rail two surfaces share (module doc), with the induced-direction vote."""
    size = model_size(builts)
    tol = rel_tol * size
    u = np.linspace(0.0, 1.0, samples)
    rails: list[SharedRail] = []
    parts = [sheet_parts(b.surface) for b in builts]
    for i in range(len(builts)):
        for j in range(i + 1, len(builts)):
            for pi, P in enumerate(parts[i]):
                for ei in "ab":
                    pts = _edge(P, ei, u)
                    for pj, Q in enumerate(parts[j]):
                        for ej in "ab":
                            uj, dist = _closest(Q, ej, pts)
                            on = dist <= tol
                            if on.sum() < 3:
                                continue
                            ti, tj = _induced(P, ei, u[on]), _induced(Q, ej, uj[on])
                            ni, nj = np.linalg.norm(ti, axis=1), np.linalg.norm(tj, axis=1)
                            live = (ni > 1e-9 * size) & (nj > 1e-9 * size)  # not at an apex (a fan's point)
                            if live.sum() < 3:
                                continue
                            cos = np.einsum("ij,ij->i", ti[live], tj[live]) / (ni[live] * nj[live])
                            rails.append(SharedRail(i, pi, ei, j, pj, ej, u[on], uj[on], pts[on], float(np.mean(cos))))
    return rails


def shell_orientation(builts: Sequence[BuiltSurface], rails: Sequence[SharedRail]) -> tuple[list[float], list[str]]:
    """``orientation`` per surface (±1, module doc) and the contradictions found (empty: consistent)."""
    n = len(builts)
    sign: list[float | None] = [None] * n
    conflicts: list[str] = []
    names = [str(b.design.name) for b in builts]
    for start in range(n):
        if sign[start] is not None:
            continue
        sign[start] = 1.0
        queue = [start]
        while queue:
            k = queue.pop(0)
            for r in rails:
                if k not in (r.i, r.j) or abs(r.vote) < 0.5:
                    continue
                other = r.j if k == r.i else r.i
                want = -math.copysign(1.0, r.vote) * float(sign[k])  # opposite induced directions
                if sign[other] is None:
                    sign[other] = want
                    queue.append(other)
                elif sign[other] != want:
                    conflicts.append(f"{names[r.i]!r} and {names[r.j]!r} along their shared rail ({r.edge_i} of "
                                     f"{names[r.i]!r}, {r.edge_j} of {names[r.j]!r})")
    signs = [float(s) for s in sign]  # type: ignore[arg-type]
    # every connected shell is turned outward: its normal on its convex side (away from its centroid)
    comp = _components(n, rails)
    for members in comp:
        flux = _outward_flux(builts, members, signs)
        if flux < 0:
            for k in members:
                signs[k] = -signs[k]
    return signs, conflicts


def _components(n: int, rails: Sequence[SharedRail]) -> list[list[int]]:
    """The surfaces connected through shared rails, each list in file order."""
    parent = list(range(n))

    def root(k: int) -> int:
        while parent[k] != k:
            k = parent[k]
        return k

    for r in rails:
        if abs(r.vote) >= 0.5:
            parent[root(r.j)] = root(r.i)
    groups: dict[int, list[int]] = {}
    for k in range(n):
        groups.setdefault(root(k), []).append(k)
    return list(groups.values())


def _outward_flux(builts: Sequence[BuiltSurface], members: Sequence[int], signs: Sequence[float], samples: int = 129) -> float:
    r"""``∫ (X - c)·N dA`` over the surfaces ``members`` with the normals ``N = sign · n`` and ``c``
    their area centroid; > 0 when N points away from the centroid (the convex side). Along a
    ruling of a developable ``(X - c)·n = (a - c)·n`` and ``dA = |m| du dv`` with
    ``m = ((a' + b')/2) × g`` (trapezoid rule over ``samples`` rulings)."""
    u = np.linspace(0.0, 1.0, samples)
    rows = []
    for k in members:
        for part in sheet_parts(builts[k].surface):
            a, b = _edge(part, "a", u), _edge(part, "b", u)
            m = np.cross(0.5 * (_edge(part, "a", u, 1) + _edge(part, "b", u, 1)), b - a)
            w = np.linalg.norm(m, axis=1)
            nrm = signs[k] * m / np.where(w > 0, w, 1.0)[:, None]
            rows.append((a, 0.5 * (a + b), nrm, _trap(w, u), w))
    area = sum(r[3] for r in rows)
    c = sum(_trap(r[1] * r[4][:, None], u) for r in rows) / area
    return float(sum(_trap(np.einsum("ij,ij->i", r[0] - c, r[2]) * r[4], u) for r in rows))


def _trap(y: np.ndarray, x: np.ndarray) -> Any:
    """Trapezoid rule along axis 0 (numpy >= 1.24 and 2.x alike)."""
    dx = np.diff(x)
    return np.tensordot(dx, 0.5 * (y[1:] + y[:-1]), axes=(0, 0))


def _resolved(base: SheetSpec, over: dict[str, Any] | None) -> SheetSpec:
    return replace(base, **(over or {}))


def surface_sheets(design: Design, builts: Sequence[BuiltSurface]) -> tuple[list[SurfaceSheet], list[SharedRail]]:
    """The sheet of every surface of a ``[[surfaces]]`` design (module doc) and the shared rails.

    Raises:
        DesignError: ``side_reference = "shell"`` on a shell that cannot be oriented.
    """
    from ...sheetmetal.sheet import ruling_normal

    assert design.sheet is not None
    rails = shared_rails(builts)
    orient, conflicts = shell_orientation(builts, rails)
    if conflicts and design.sheet.side_reference == "shell":
        raise DesignError(f"{design.source}: key 'sheet.side_reference': the surfaces make no orientable shell (the "
                          f"rails contradict each other: {conflicts[0]}), so side='{design.sheet.side}' has no meaning on "
                          "it; allowed: side_reference = \"surface\" (each surface's own normal) with a side per surface "
                          "([surfaces.sheet] side)")
    out = []
    for b, spec, o in zip(builts, design.surfaces, orient):
        req = _resolved(design.sheet, spec.sheet)
        s = 1.0 if req.side == "normal" else -1.0
        if req.side_reference == "shell":
            s *= o
        eff = replace(req, side="normal" if s > 0 else "reverse", side_reference="surface")
        if "k_factor" in (spec.sheet or {}):  # the surface's own K wins over the design's table
            req, eff = replace(req, k_factor_table=None), replace(eff, k_factor_table=None)
        elif req.k_factor_table is not None:  # K by this surface's R/T, with its own thickness and side
            eff = table_k_factor(eff, b.surface)
            req = replace(req, k_factor=eff.k_factor, k_factor_ratio=eff.k_factor_ratio)
        parts = sheet_parts(b.surface)
        part = parts[len(parts) // 2]
        centre = np.asarray(part.evaluate(np.array([0.5]), np.array([0.5])), dtype=float).reshape(3)
        n = ruling_normal(part, np.array([0.5]), 0)[0][0]
        out.append(SurfaceSheet(str(spec.name), spec.key, req, o, eff, centre.tolist(), n.tolist(), (s * n).tolist()))
    return out, rails


def apply_sheets(builts: Sequence[BuiltSurface], sheets: Sequence[SurfaceSheet]) -> list[BuiltSurface]:
    """The built surfaces with each sub-design's ``sheet`` replaced by the surface's own sheet."""
    return [replace(b, design=replace(b.design, sheet=s.sheet), sheet_resolved=True) for b, s in zip(builts, sheets)]


def check_surface_sheets(design: Design, builts: Sequence[BuiltSurface]) -> list[float]:
    """:func:`ght_cad.app.design.check_sheet` on every surface (each with its own sheet); a refusal
    names the file, ``surfaces[i]`` and the surface.

    Returns:
        The smallest bending radius per surface.
    """
    from .build import check_sheet

    out = []
    for b, spec in zip(builts, design.surfaces):
        try:
            out.append(check_sheet(b.design, b.surface))
        except GHTError as exc:
            raise type(exc)(f"{design.source}: key '{spec.key}' (surface {spec.name!r}): {' '.join(str(exc).split())}") from None
    return out


def rail_joints(builts: Sequence[BuiltSurface], sheets: Sequence[SurfaceSheet], rails: Sequence[SharedRail]) -> list[dict[str, Any]]:
    r"""Per shared rail: how the two plates meet (module doc). For matched rail points ``p``:
    ``d = |T_i m_i - T_j m_j|`` (distance between the plates' outside edges), fold angle
    ``∠(m_i, m_j)``, and the kind: ``overlap`` where the other surface turns towards the material
    (``m_i · w_j > 0``, ``w_j`` the unit direction into surface ``j`` across the rail), ``gap``
    where it turns away, ``flush`` within 1e-9 (points on a zero-length ruling, a pointed end, have
    no direction across the rail and are left out of the kind)."""
    from ...sheetmetal.sheet import ruling_normal

    out = []
    for r in rails:
        rows = []
        for k, part_k, edge, u in ((r.i, r.part_i, r.edge_i, r.u_i), (r.j, r.part_j, r.edge_j, r.u_j)):
            part = sheet_parts(builts[k].surface)[part_k]
            sh = sheets[k].sheet
            n = ruling_normal(part, u, 0)[0]
            m = n * (1.0 if sh.side == "normal" else -1.0)
            t = _edge(part, edge, u, 1)
            g = np.asarray(part.ruling(u), dtype=float) * (1.0 if edge == "a" else -1.0)  # into the surface
            tl = np.linalg.norm(t, axis=1)
            th = t / np.where(tl > 0, tl, 1.0)[:, None]
            w = g - th * np.einsum("ij,ij->i", g, th)[:, None]
            wl = np.linalg.norm(w, axis=1)
            # a zero-length ruling (a pointed end, where the rails meet) has no direction across the
            # rail: NaN there, left out of the kind below (distance and fold angle need none)
            ok = wl > 1e-12 * max(float(wl.max(initial=0.0)), 1e-300)
            w = np.where(ok[:, None], w / np.where(ok, wl, 1.0)[:, None], np.nan)
            rows.append((m, w, sh.thickness))
        (mi, wi, Ti), (mj, wj, Tj) = rows
        d = np.linalg.norm(Ti * mi - Tj * mj, axis=1)
        fold = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", mi, mj), -1.0, 1.0)))
        turn = 0.5 * (np.einsum("ij,ij->i", mi, wj) + np.einsum("ij,ij->i", mj, wi))
        turn = turn[np.isfinite(turn)]
        kinds = np.where(turn > 1e-9, "overlap", np.where(turn < -1e-9, "gap", "flush"))
        uniq = sorted(set(kinds.tolist()))
        k = int(np.argmax(d))
        out.append({
            "surfaces": [sheets[r.i].name, sheets[r.j].name],
            "edges": [r.edge_i, r.edge_j],
            "points": int(len(d)),
            "length": float(np.sum(np.linalg.norm(np.diff(r.points, axis=0), axis=1))),
            "kind": uniq[0] if len(uniq) == 1 else "mixed (" + ", ".join(uniq) + ")",
            "outside_edge_distance_max": float(d[k]),
            "outside_edge_distance_min": float(np.min(d)),
            "at": r.points[k].tolist(),
            "fold_angle_deg_max": float(np.max(fold)),
            "fold_angle_deg_min": float(np.min(fold)),
            # the shell's normals (orientation x own normal) induce opposite directions on the rail
            "shell_consistent": bool(r.vote * sheets[r.i].orientation * sheets[r.j].orientation < 0),
        })
    return out
