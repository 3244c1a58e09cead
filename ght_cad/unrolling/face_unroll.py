r"""Kernel-free unrolling of a CAD face (plane, cylinder, cone, extrusion, ruled B-spline, trimmed).

One implementation behind two thin adapters: :mod:`ght_cad.cad.unroll_faces` (OCP / build123d /
cadquery) and the FreeCAD workbench's ``flat_pattern`` (FreeCAD's ``Part`` API). An adapter
describes a face by a :class:`FaceData`: its surface (a :class:`SurfaceAdapter`: kind, radius /
semi-angle where analytic, value and partials at arrays of (u, v), parameter breaks), its
parameter bounds and its wires (outer first), each a list of :class:`EdgeData` in wire order
(t ∈ [0, 1] -> (u, v), (u', v'), xyz, and the 3-D length).

Development maps ``F(u, v)`` from the face's own parameters to the plane:

* plane: ``F(u, v) = (u, v)`` (the parameters of a plane are orthonormal coordinates);
* cylinder of radius R: ``F(u, v) = (R u, v)``;
* cone with reference radius R and semi-angle α, ``s = sin α``: the slant distance from the apex
  is ``ρ(v) = R/s + v`` and ``F(u, v) = ρ(v) (cos(s u), sin(s u))`` (annular sector of angle
  ``s Δu``: for a full cone ``2π r / ρ``);
* every other face whose isolines in one parameter direction are straight (surface of linear
  extrusion, B-spline/Bézier of degree 1 in one direction, ...): a :class:`FaceRuledSurface`
  ``a(t) = S(u(t), v0)``, ``b(t) = S(u(t), v1)`` developed by quadrature along the rulings
  (:class:`ght_cad.unroll.RuledDevelopment`); a point ``S(u, v)`` maps to ``A(t) + s |g| D(t)``
  where ``s`` is its projection onto the ruling.

Holes and trimmed boundaries are kept: every edge's pcurve ``(u(t), v(t))`` is mapped through
``F``; 3-D reference lengths come from the edges' own 3-D curves and the 3-D area by Green's
theorem in (u, v) with Gauss–Legendre quadrature (:func:`face_area`).

numpy/scipy only (runs inside FreeCAD's Python with numpy 1.24 / scipy 1.10).
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ..core.errors import DegenerateGeometryError, NotDevelopableError
from ..core._vec import norm as _norm
from ..core._vec import stack as _stack
from ..pattern.flat_pattern import BoundaryEdge, FlatPanel, FlatPattern, _unit_samples, measure_panel
from ..surfaces.ruled import _theta_parameters
from .ruled_development import (DEFAULT_TOL_DEG, RuledDevelopment, _check_developable, broadcast_uv, first_nodes,
                                metric_angles, metric_stencil)
# Moved to ght_cad.unrolling.faces (issue 27); every name stays importable from here.
from .faces.adapter import (analytic_jet, Bounds, EdgeData, FaceData, jets_agree, RULED_KINDS, surface_jet,
                            SurfaceAdapter, U_FREE_DENSITY_KINDS)  # noqa: F401
from .faces.area import (_edge_nodes, _edge_nodes_at, _edge_nodes_plain, _gauss12, _inner_integrals,
                         _inner_integrals_by_pieces, _inner_nodes, _inner_nodes_at, face_area)  # noqa: F401
from .faces.directions import (_isoline_points, best_effort_direction, end_isoline_length, isoline_stats,
                               ruling_direction)  # noqa: F401
from .faces.loops import (_as_shape, _c0_crossings, _check_holes_inside, _edge_sample_uv, _flat1, _loop_points,
                          _seed_edge_samples, _strided_memo, _with_breaks, chain_loop, clip_rulings_uv, fd_derivative,
                          loop_uv_area, outer_loop_index)  # noqa: F401
from .faces.ruled_face import FaceRuledSurface  # noqa: F401

__all__ = [
    "SurfaceAdapter",
    "EdgeData",
    "FaceData",
    "FaceRuledSurface",
    "ClosedFormMap",
    "isoline_stats",
    "ruling_direction",
    "best_effort_direction",
    "end_isoline_length",
    "face_area",
    "clip_rulings_uv",
    "fd_derivative",
    "chain_loop",
    "loop_uv_area",
    "outer_loop_index",
    "unroll_face_data",
]


#: the fractions of :func:`_metric_grid`'s 12 x 5 grid (u-major), made once
_METRIC_FU = np.repeat(np.linspace(0.05, 0.95, 12), 5)

_METRIC_FV = np.tile(np.linspace(0.05, 0.95, 5), 12)


def _metric_grid(bounds: Bounds) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The 12 x 5 grid ``(U, V)`` of :func:`_metric` (u at 0.05 .. 0.95 of its range, v likewise,
    u-major) and its difference steps ``hu, hv`` (1e-3 of the ranges)."""
    u0, u1, v0, v1 = bounds
    return u0 + (u1 - u0) * _METRIC_FU, v0 + (v1 - v0) * _METRIC_FV, 1e-3 * (u1 - u0), 1e-3 * (v1 - v0)


def _metric(ev: SurfaceAdapter, fmap: Callable, bounds: Bounds,
            grid: tuple[np.ndarray, np.ndarray, float, float] | None = None,
            d1: list[np.ndarray] | None = None) -> dict[str, np.ndarray]:
    """Angles between S_u, S_v and F_u, F_v on a 12 x 5 grid (:func:`ght_cad.unroll.metric_angles`;
    ``grid``: :func:`_metric_grid` of ``bounds`` when already made; ``d1``: ``[S_u, S_v]`` there
    when already evaluated)."""
    U, V, hu, hv = grid if grid is not None else _metric_grid(bounds)
    d = ev.d1(U, V) if d1 is None else d1
    return metric_angles(d[0], d[1], fmap, U, V, hu, hv)


class _MapBatch:
    """A pointwise map evaluated once on several requested point sets (one call, the per-call
    overhead paid once); a later call with exactly one of those sets is answered from the batch
    (the same values), any other call goes to the map."""

    def __init__(self, fmap: Callable[[np.ndarray, np.ndarray], np.ndarray],
                 requests: list[tuple[np.ndarray, np.ndarray]]) -> None:
        self.fmap = fmap
        reqs = [tuple(x.ravel() for x in broadcast_uv(u, v)) for u, v in requests]
        reqs = [r for r in reqs if r[0].size]
        self.done: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        if reqs:
            F = np.asarray(fmap(np.concatenate([r[0] for r in reqs]), np.concatenate([r[1] for r in reqs])), dtype=float)
            i = 0
            for u, v in reqs:
                self.done.append((u, v, F[i:i + u.size]))
                i += u.size

    def result(self, k: int) -> np.ndarray:
        """The k-th (non-empty) request's values."""
        return self.done[k][2].copy()

    def __call__(self, u: Any, v: Any) -> np.ndarray:
        uu, vv = broadcast_uv(u, v)
        if uu.ndim == 1:
            for bu, bv, F in self.done:
                if (bu is uu and bv is vv) or (bu.size == uu.size and (bu == uu).all() and (bv == vv).all()):
                    return F.copy()
        return self.fmap(uu, vv)


class ClosedFormMap:
    """Development map of a plane, cylinder or cone (closed form, see module doc)."""

    def __init__(self, kind: str, R: float = 0.0, s: float = 0.0) -> None:
        self.kind, self.R, self.s = kind, R, s

    def map(self, u: Any, v: Any) -> np.ndarray:
        """``F(u, v)``, shape (n, 2)."""
        u, v = broadcast_uv(u, v)
        if self.kind == "plane":
            return _stack([u, v], axis=1)
        if self.kind == "cylinder":
            return _stack([self.R * u, v], axis=1)
        rho = self.R / self.s + v
        ang = self.s * u
        return _stack([rho * np.cos(ang), rho * np.sin(ang)], axis=1)


class _RuledFaceMap:
    """Development map of a ruled face by quadrature along its rulings (see module doc)."""

    def __init__(self, rs: FaceRuledSurface, dev: RuledDevelopment, ev: SurfaceAdapter, project: bool) -> None:
        self.rs, self.dev, self.ev, self.project = rs, dev, ev, project

    def map(self, u: Any, v: Any) -> np.ndarray:
        u, v = broadcast_uv(u, v)
        t, s = self.rs.ts(u, v)
        if self.project:  # exact ruled face: project the true point onto its ruling
            return self.dev.map_points(t, self.rs.value_and_ends(t, u, v))
        return self.dev.map(t, s)


def unroll_face_data(
    face: FaceData,
    *,
    best_effort: bool = False,
    tol_deg: float = DEFAULT_TOL_DEG,
    rulings: int = 16,
    samples: int = 257,
    units: str = "mm",
    label: str = "P1",
    sheet: Any = None,
) -> FlatPattern:
    """Unroll one face given by an adapter (see module doc for the maps used).

    Steps: :func:`_check_face_extent`; :func:`_development_map` (closed form, or quadrature along
    the straight isolines after the developability check); :func:`_boundary_loops` (outer loop
    first); the rulings' ends and 3-D lengths (:func:`_ruling_ends`, :func:`_ruling_lengths_3d`)
    and the bend lines clipped in (u, v) (:func:`_bend_rulings_uv`); one batched evaluation of the
    map (:class:`_MapBatch`) for the outline samples, the rulings and the metric stencil; the
    panel measured (:func:`ght_cad.pattern.flat_pattern.measure_panel`) and placed at the origin.

    Args:
        face: the face's surface, bounds and wires.
        best_effort: flatten a face that is not ruled / not developable within ``tol_deg``; a
            non-ruled face is replaced by the ruled surface between its v0 and v1 (or u0, u1)
            boundary isolines (the straighter direction whose isolines are open;
            ``info["ruling_direction"]``), and the report measures the distortion against the
            true face.
        tol_deg: largest accepted ``θ_max`` in degrees (spec section 5).
        rulings: interior rulings drawn as bend lines (clipped to the trimmed outline).
        samples: points per boundary edge in the outline polylines.
        units: length unit of the model.
        label: panel label.
        sheet: a :class:`ght_cad.sheetmetal.sheet.Sheet` with ``T > 0``: the face's neutral offset
            ``S + σ K T n`` (n the face normal, orientation included) is unrolled instead
            (:class:`ght_cad.sheetmetal.sheet.FaceSheet`: cylinders/cones keep their closed forms with the
            offset radius); ``panel.info["sheet"]`` holds edge lengths and forming data.

    Returns:
        FlatPattern with one panel: all wires of the face mapped to the plane, the outer one
        (largest enclosed (u, v) area, :func:`outer_loop_index`) first, then the holes.

    Raises:
        NotDevelopableError: the face is not ruled (message gives the isolines' largest distance
            from a straight line relative to their length, :func:`isoline_stats`; a closed isoline
            gives about 0.159) or its θ_max exceeds ``tol_deg`` (message gives θ_max and DD), and
            best_effort is False.
        DegenerateGeometryError: best_effort on a non-ruled face whose isolines are closed in both
            directions (a full torus) or whose open isolines run between two points (a full
            sphere); an unbounded face (infinite bounds, OCCT's 2e100) or one without wires; a
            hole outside the outer wire in (u, v).
    """
    _check_face_extent(face, label)
    ev, bounds = face.surface, face.bounds
    info: dict[str, Any] = {"best_effort": bool(best_effort)}
    fsheet = None
    if sheet is not None and not sheet.is_zero:  # the neutral surface replaces the face's own
        from ..sheetmetal.sheet import FaceSheet

        fsheet = FaceSheet(face, sheet, label)
        ev = fsheet.neutral
    dmap, ruled_dir, rs, mgrid, metric_jet = _development_map(face, ev, best_effort, tol_deg, label, info)
    loops, loops_uv, k_out = _boundary_loops(face, dmap, fsheet, samples, label, info)
    # rulings (bend lines and ruling-length check) over the UV box, clipped later to the outline
    bends = np.zeros((0, 2, 2))
    g3 = gf = np.zeros(0)
    if ruled_dir is not None:
        tt = _unit_samples(129)
        # the ruling ends' 3-D lengths from the prefetched boundary jets; one evaluation of the map
        # for the ruling ends and the bend lines
        ua, va, ub, vb = _ruling_ends(bounds, ruled_dir, tt)
        n = tt.size
        g3 = _ruling_lengths_3d(ev, rs, tt, (ua, va, ub, vb))
    if mgrid is None:
        mgrid = _metric_grid(bounds)
    # the map's points in one call (it is pointwise; its per-call overhead dominated): the
    # edges' outline samples, the ruling ends and bend lines, the metric's stencil
    mU, mV, mhu, mhv = mgrid
    sampled, ts, edge_uv = _edge_sample_uv(loops, loops_uv, samples)
    clipped = None
    if ruled_dir is not None:
        ca, cva, cb, cvb, clipped = _bend_rulings_uv(bounds, ruled_dir, rulings, loops, sampled, ts, edge_uv)
        ruling_uv = (np.concatenate([ub, ua, ca, cb]), np.concatenate([vb, va, cva, cvb]))
    fmap = _MapBatch(dmap.map, [metric_stencil(mU, mV, mhu, mhv)] + ([ruling_uv] if ruled_dir is not None else [])
                     + [edge_uv])
    if sampled:
        _seed_edge_samples(sampled, ts, fmap(*edge_uv))
    if ruled_dir is not None:
        pf = fmap(*ruling_uv)
        gf = _norm(pf[:n] - pf[n:2 * n])
        if rulings:
            k = ca.size
            bends = _stack([pf[2 * n:2 * n + k], pf[2 * n + k:]], axis=1)
    area_3d = face_area(ev, loops_uv, bounds[0], ev.breaks("u"), bounds[1] - bounds[0])
    panel = FlatPanel(
        label=label,
        loops=loops,
        bend_lines=bends if clipped is None else np.zeros((0, 2, 2)),  # measure_panel clips in the plane
        ruling_lengths_3d=g3,
        ruling_lengths_flat=gf,
        area_3d=area_3d,
        metric=_metric(ev, fmap, bounds, mgrid, None if metric_jet is None else metric_jet[1:3]),
        info=info,
        development=dmap,
    )
    measure_panel(panel)
    if clipped is not None:
        panel.bend_lines = bends  # clipped in (u, v) already
    if fsheet is not None:
        wires = [w for w in face.wires if w]  # the loops' order: outer (k_out) first
        fsheet.finish(panel, dmap, rulings, [wires[k_out]] + wires[:k_out] + wires[k_out + 1:])
    # place: bounding box at the origin
    lo, _ = panel.bbox()
    panel.translate(-lo)
    return FlatPattern([panel], units=units)


# -- the steps of unroll_face_data ------------------------------------------------------------------

def _check_face_extent(face: FaceData, label: str) -> None:
    """Refuse an unbounded or empty face (infinite bounds, OCCT's 2e100, u0 >= u1 or v0 >= v1) and
    a face without boundary wires (:class:`DegenerateGeometryError` naming the face)."""
    bounds = face.bounds
    if not all(math.isfinite(b) and abs(b) < 1e50 for b in bounds) or bounds[0] >= bounds[1] or bounds[2] >= bounds[3]:
        raise DegenerateGeometryError(
            f"face {label!r} is unbounded or empty: parameter bounds (u0, u1, v0, v1) = "
            f"({', '.join(f'{b:.6g}' for b in bounds)}); allowed: a face trimmed by boundary wires, finite "
            "bounds with u0 < u1 and v0 < v1"
        )
    if not any(face.wires):
        raise DegenerateGeometryError(f"face {label!r} has no boundary wires; allowed: a face trimmed by boundary wires")


def _development_map(face: FaceData, ev: SurfaceAdapter, best_effort: bool, tol_deg: float, label: str,
                     info: dict[str, Any]) -> tuple[Any, str | None, FaceRuledSurface | None,
                                                    tuple[np.ndarray, np.ndarray, float, float] | None,
                                                    list[np.ndarray] | None]:
    r"""The development map ``F(u, v)`` of the face (module doc): a plane, cylinder or cone in closed
    form (:class:`ClosedFormMap`), any other face by quadrature along its straight isolines
    (:class:`_RuledFaceMap`) after :func:`ruling_direction` and the developability check
    (``θ_max <= tol_deg``, spec section 5); ``info`` gets the method, the direction and the checks.

    Returns:
        ``(map, ruling direction ("u", "v" or None for a plane), the ruled surface or None,
        the metric grid or None, the prefetched jets at the metric grid or None)``.

    Raises:
        NotDevelopableError, DegenerateGeometryError: as :func:`unroll_face_data`.
    """
    kind, bounds = face.surface.kind, face.bounds
    ruled_dir: str | None
    rs: FaceRuledSurface | None = None
    mgrid: tuple[np.ndarray, np.ndarray, float, float] | None = None
    metric_jet: list[np.ndarray] | None = None
    if kind == "plane":
        dmap: Any = ClosedFormMap("plane")
        ruled_dir = None
        info["method"] = "plane (identity in plane coordinates)"
    elif kind == "cylinder":
        dmap = ClosedFormMap("cylinder", R=ev.radius)
        ruled_dir = "v"
        info["method"] = "cylinder (closed form)"
    elif kind == "cone":
        dmap = ClosedFormMap("cone", R=ev.radius, s=math.sin(ev.semi_angle))
        ruled_dir = "v"
        info["method"] = "cone (closed form)"
    else:
        ruled_dir, straight = ruling_direction(face.surface, bounds)
        info.update(straight)
        if ruled_dir is None:
            if not best_effort:
                try:
                    best_effort_direction(straight, label)
                    hint = ("pass best_effort=True to flatten the ruled surface between its boundary "
                            "isolines with a distortion report")
                except DegenerateGeometryError as exc:  # say so instead of suggesting best_effort
                    hint = "best_effort=True cannot flatten it either" + str(exc).split("best_effort=True", 1)[1]
                raise NotDevelopableError(
                    f"face {label!r} is not ruled: its isolines deviate from straight lines by "
                    f"{straight['deviation_u']:.3g} (u-isolines) and {straight['deviation_v']:.3g} "
                    f"(v-isolines) relative to their lengths (allowed 1e-9; a closed isoline deviates "
                    f"0.159); {hint}"
                )
            ruled_dir = best_effort_direction(straight, label)
        info["ruling_direction"] = ruled_dir
        rs = FaceRuledSurface(ev, ruled_dir, bounds)
        # one surface evaluation for the boundary jets the developability, the quadrature's first
        # panels and the ruling ends ask for, and for the metric grid's partials
        mgrid = _metric_grid(bounds)
        metric_jet = rs.prefetch([_theta_parameters(64, 257), first_nodes(rs.breakpoints), _unit_samples(129)], 1,
                                 extra=mgrid[:2])
        dd = _check_developable(rs, tol_deg, best_effort, f"face {label!r}")
        info["developability"] = dd.as_dict()
        dev = RuledDevelopment(rs, breakpoints=rs.breakpoints, place=False)  # the panel is placed below
        info["method"] = "quadrature along rulings (adaptive Chebyshev panels)"
        info["panels"] = dev.panels
        info["quadrature_error_estimate"] = dev.quadrature_error_estimate
        # an exactly ruled face is mapped by projecting its true point onto the ruling, unless it
        # is affine along the rulings (then the ruling parameter is s itself)
        exact = min(info.get("deviation_u", math.inf), info.get("deviation_v", math.inf)) <= 1e-9
        dmap = _RuledFaceMap(rs, dev, ev, exact and not getattr(ev, "affine_ruled", False))
    return dmap, ruled_dir, rs, mgrid, metric_jet


def _boundary_loops(face: FaceData, dmap: Any, fsheet: Any, samples: int, label: str, info: dict[str, Any]
                    ) -> tuple[list[list[BoundaryEdge]], list[list[tuple[Callable, Callable]]], int]:
    """The face's wires as boundary loops: per edge a :class:`BoundaryEdge` whose flat image is
    ``F(u(t), v(t))`` (on a sheet: its 3-D image on the neutral surface), split at the surface's C0
    parameter lines, and the edge's pcurve ``(t -> (u, v), t -> (u', v'))``.

    The outer loop (the one enclosing the others in (u, v), :func:`outer_loop_index`) is put first
    (``info["outer_wire_reordered"]`` when the adapter's first wire was not it) and every hole is
    checked to lie inside it (:func:`_check_holes_inside`).

    Returns:
        ``(loops, loops_uv, k_out)``: k_out the index of the outer loop among the adapter's
        non-empty wires.
    """
    loops = []
    loops_uv = []
    c0 = getattr(face.surface, "c0_breaks", None)
    c0u, c0v = (c0("u"), c0("v")) if c0 is not None else (np.zeros(0), np.zeros(0))
    for wire in face.wires:
        loop = []
        loop_uv = []
        for k, e in enumerate(wire):
            duv = e.duv
            if not hasattr(duv, "breaks"):
                duv = _with_breaks(e.duv, e.breaks)
            loop_uv.append((e.uv, duv))

            flat_fn = _strided_memo(lambda t, uvf=e.uv: dmap.map(*uvf(t)))

            name = e.name or f"edge{k}"
            br = _c0_crossings(e.uv, c0u, c0v) if c0u.size or c0v.size else ()
            if fsheet is None:
                loop.append(BoundaryEdge(name=name, flat_fn=flat_fn, xyz_fn=e.xyz, length_3d=float(e.length_3d), samples=samples,
                                         breaks=br))
            else:  # the edge on the neutral surface, its length measured (Romberg)
                loop.append(BoundaryEdge(name=name, flat_fn=flat_fn, xyz_fn=fsheet.edge_xyz(e.uv),
                                         length_3d=0.0 if e.length_3d == 0 else None, samples=samples, breaks=br))
        if loop:
            loops.append(loop)
            loops_uv.append(loop_uv)
    # the outer loop first: an adapter's "outer wire" is not always right (FreeCAD 0.20's
    # Face.OuterWire hands out a hole of a drilled cylinder), the outer loop encloses the others
    k_out = outer_loop_index(loops_uv)
    if k_out:
        loops.insert(0, loops.pop(k_out))
        loops_uv.insert(0, loops_uv.pop(k_out))
        info["outer_wire_reordered"] = True
    _check_holes_inside(loops_uv, label)
    return loops, loops_uv, k_out


def _ruling_ends(bounds: Bounds, ruled_dir: str, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """``(u_a, v_a, u_b, v_b)``: the two ends of the rulings at ``t`` ∈ [0, 1] across the parameter
    box (rulings along v: ``u = u0 + t Δu`` from ``v0`` to ``v1``; along u the roles swap)."""
    u0, u1, v0, v1 = bounds
    if ruled_dir == "v":
        uu = u0 + t * (u1 - u0)
        return uu, np.full(t.shape, float(v0)), uu, np.full(t.shape, float(v1))
    vv = v0 + t * (v1 - v0)
    return np.full(t.shape, float(u0)), vv, np.full(t.shape, float(u1)), vv


def _ruling_lengths_3d(ev: SurfaceAdapter, rs: FaceRuledSurface | None, t: np.ndarray,
                       ends: tuple[np.ndarray, ...]) -> np.ndarray:
    """3-D lengths ``|S(u_b, v_b) - S(u_a, v_a)|`` of the rulings at ``t`` with ``ends`` (:func:`_ruling_ends`):
    from the ruled surface's prefetched boundary jets, or (a cylinder or cone in closed form) by one
    evaluation of the ruling ends."""
    ua, va, ub, vb = ends
    if rs is not None:
        return rs.ruling_lengths(t)
    n = ua.size
    p3 = ev.value(np.concatenate([ub, ua]), np.concatenate([vb, va]))
    return _norm(p3[:n] - p3[n:])


def _bend_rulings_uv(bounds: Bounds, ruled_dir: str, rulings: int, loops: list[list[BoundaryEdge]],
                     sampled: list[BoundaryEdge], ts: np.ndarray, edge_uv: tuple[np.ndarray, np.ndarray]
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, Any]:
    """The ends ``(u_a, v_a, u_b, v_b)`` of the ``rulings`` interior bend lines at
    ``t = k / (rulings + 1)``, clipped in (u, v) to the face's loops where they are straight
    (:func:`clip_rulings_uv`, when every edge was sampled here), and the clip's result (None: not
    clipped, :func:`measure_panel` clips the flat lines instead)."""
    u0, u1, v0, v1 = bounds
    tb = np.arange(1, rulings + 1) / (rulings + 1)
    clipped = None
    # bend lines: rulings clipped to the loops in (u, v), where they are straight lines
    ca, cva, cb, cvb = _ruling_ends(bounds, ruled_dir, tb) if rulings else (np.zeros(0),) * 4
    if rulings and len(sampled) == sum(len(lp) for lp in loops):
        m = ts.size
        pts = _stack(edge_uv, axis=1).reshape(len(sampled), m, 2)
        if ruled_dir == "u":
            pts = pts[..., ::-1]
        first = np.cumsum([0] + [len(lp) for lp in loops])
        polys = [pts[i:j, :-1].reshape(-1, 2) for i, j in zip(first[:-1], first[1:])]
        lo_, hi_ = (v0, v1) if ruled_dir == "v" else (u0, u1)
        clipped = clip_rulings_uv(polys, ca if ruled_dir == "v" else cva, lo_, hi_)
        if clipped is not None:
            kk, y0, y1 = clipped
            if ruled_dir == "v":
                ca, cva, cb, cvb = ca[kk], y0, cb[kk], y1
            else:
                ca, cva, cb, cvb = y0, cva[kk], y1, cvb[kk]
    return ca, cva, cb, cvb, clipped
