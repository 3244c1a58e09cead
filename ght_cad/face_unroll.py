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

import functools
import math
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from .errors import DegenerateGeometryError, GHTError, NotDevelopableError
from ._vec import cross as _cross
from ._vec import norm as _norm
from ._vec import stack as _stack
from ._vec import unique_inverse
from .flat_pattern import BoundaryEdge, FlatPanel, FlatPattern, _point_in_polygon, _unit_samples, measure_panel
from .ruled import RuledSurface
from .ruled import _theta_parameters
from .unroll import (DEFAULT_TOL_DEG, RuledDevelopment, _check_developable, broadcast_uv, first_nodes, metric_angles,
                     metric_stencil)

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

Bounds = tuple[float, float, float, float]
#: surface kinds with a structural ruling direction "v" (their v-isolines are straight lines)
RULED_KINDS = ("plane", "cylinder", "cone", "extrusion")
#: surface kinds whose area density ``|S_u × S_v|`` does not depend on u (a plane: constant; a
#: cylinder or cone: u is the angle about the axis), so :func:`face_area` needs no inner integral
U_FREE_DENSITY_KINDS = ("plane", "cylinder", "cone")


class SurfaceAdapter:
    """The surface of a face as the core sees it (the adapter protocol; subclass and override).

    Attributes:
        kind: "plane", "cylinder", "cone", "extrusion", "bspline", "bezier" or "other".
        radius: cylinder radius / cone reference radius R (analytic kinds only).
        semi_angle: cone semi-angle α in radians (cone only).
        ruled_hint: "v" or "u" when the surface is structurally ruled in that direction (a B-spline
            or Bézier of degree 1 with 2 poles across), else None.
        affine_ruled: the surface is affine along its rulings, ``S(u, v) = S(u, v0) + (v - v0) /
            (v1 - v0) (S(u, v1) - S(u, v0))`` (rulings along v; u likewise): an extrusion, a
            degree-1 B-spline/Bézier with equal weights across. Then a point's ruling parameter is
            its own (v - v0) / (v1 - v0) and the map needs no projection onto the ruling.
        fast_density_grid: :meth:`density_grid` (when the adapter has one) costs far less a point
            on a tensor grid than the partials at scattered points (a B-spline read into the core):
            :func:`face_area` then integrates whole knot pieces on grids.
    """

    kind: str = "other"
    fast_density_grid: bool = False
    radius: float = 0.0
    semi_angle: float = 0.0
    ruled_hint: str | None = None
    affine_ruled: bool = False

    def value(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Points ``S(u, v)``, shape (n, 3)."""
        raise NotImplementedError

    def d1(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """``[S_u, S_v]`` at the points, each (n, 3)."""
        d = self.d2(u, v)
        return [d[1], d[2]]

    def d2(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """``[S, S_u, S_v, S_uu, S_vv, S_uv]`` at the points, each (n, 3)."""
        raise NotImplementedError

    def breaks(self, direction: str) -> np.ndarray:
        """Parameters in ``direction`` ("u" or "v") where the surface is not C∞ (B-spline knots);
        may include the ends; empty for analytic surfaces."""
        return np.zeros(0)

    def c0_breaks(self, direction: str) -> np.ndarray:
        """Parameters in ``direction`` where the surface is only C0 (B-spline knots of full
        multiplicity, e.g. a loft's joint rulings): the boundary measures are split there
        (:attr:`ght_cad.flat_pattern.BoundaryEdge.breaks`); empty when unknown."""
        return np.zeros(0)

    def jet(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """``[S]`` (order 0), ``[S, S_u, S_v]`` (1) or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` (2) at the
        points in one evaluation (override when that is cheaper than :meth:`value` + :meth:`d1`)."""
        return surface_jet(self, u, v, order, own=False)


def jets_agree(ours: Sequence[np.ndarray], theirs: Sequence[np.ndarray], floor: float = 1.0,
               rtol: float = 1e-12) -> bool:
    """A kernel's surface read into numpy checked against the kernel's own evaluation: every
    quantity ``k`` (point, partials) agrees to ``rtol`` of its own size,
    ``max |ours_k - theirs_k| <= rtol max(floor, max |theirs_k|)`` (NaN disagrees); all quantities
    equal-shaped, compared in one pass."""
    a, b = _stack(list(ours)), _stack(list(theirs))
    q = a.shape[0]
    err = np.abs(a - b).reshape(q, -1).max(axis=1)
    scale = np.maximum(np.abs(b).reshape(q, -1).max(axis=1), floor)
    return bool((err <= rtol * scale).all())


def analytic_jet(kind: str, frame: Sequence[np.ndarray], radius: float, semi_angle: float, u: Any, v: Any,
                 order: int) -> list[np.ndarray]:
    r"""``[S, S_u, S_v]`` (order <= 1) or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` of a plane, cylinder or
    cone from its placement ``frame = (O, X, Y, Z)`` (origin and orthonormal axes, as OCCT's
    ``gp_Ax3``), by OCCT's own parametrizations (``ElSLib``), shared by the CAD adapters:

    * plane ``S = O + u X + v Y``;
    * cylinder of radius R: ``S = O + R (cos u X + sin u Y) + v Z``;
    * cone of reference radius R and semi-angle α: ``S = O + (R + v sin α)(cos u X + sin u Y) + v cos α Z``.

    Raises:
        GHTError: another ``kind``.
    """
    O, X, Y, Z = frame
    u = np.asarray(u, dtype=float).reshape(-1, 1)
    v = np.asarray(v, dtype=float).reshape(-1, 1)
    if kind == "plane":
        zero = np.zeros((u.shape[0], 3))
        out = [O + u * X + v * Y, np.broadcast_to(X, zero.shape).copy(), np.broadcast_to(Y, zero.shape).copy()]
        return out + [zero, zero.copy(), zero.copy()] if order >= 2 else out
    if kind not in ("cylinder", "cone"):
        raise GHTError(f"kind={kind!r} has no closed-form evaluation; allowed 'plane', 'cylinder', 'cone'")
    c, s = np.cos(u), np.sin(u)
    radial = c * X + s * Y
    tangent = -s * X + c * Y
    if kind == "cylinder":
        R = radius
        out = [O + R * radial + v * Z, R * tangent, np.broadcast_to(Z, radial.shape).copy()]
        if order >= 2:
            out += [-R * radial, np.zeros_like(radial), np.zeros_like(radial)]
        return out
    sa, ca = math.sin(semi_angle), math.cos(semi_angle)
    r = radius + v * sa
    out = [O + r * radial + (v * ca) * Z, r * tangent, sa * radial + ca * Z]
    if order >= 2:
        out += [-r * radial, np.zeros_like(radial), sa * tangent]
    return out


def surface_jet(ev: Any, u: np.ndarray, v: np.ndarray, order: int, own: bool = True) -> list[np.ndarray]:
    """``ev.jet(u, v, order)`` when the adapter has one (``own``), else from ``value``/``d1``/``d2``
    (adapters that are not :class:`SurfaceAdapter` subclasses, e.g. a sheet's offset surface)."""
    if own and hasattr(ev, "jet"):
        return ev.jet(u, v, order)
    if order <= 0:
        return [ev.value(u, v)]
    if order == 1:
        return [ev.value(u, v), *ev.d1(u, v)]
    return ev.d2(u, v)


@dataclass
class EdgeData:
    """One boundary edge of a face in wire order, t ∈ [0, 1].

    Attributes:
        uv: t -> (u, v) arrays (the pcurve).
        duv: t -> (n, 2) derivatives ``(du/dt, dv/dt)``.
        xyz: t -> (n, 3) points of the edge's 3-D curve.
        length_3d: 3-D length (0 for a degenerate edge, e.g. a cone apex).
        breaks: interior t where the pcurve is not C∞ (its knots), sorted.
        name: edge name.
    """

    uv: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    duv: Callable[[np.ndarray], np.ndarray]
    xyz: Callable[[np.ndarray], np.ndarray]
    length_3d: float
    breaks: np.ndarray = field(default_factory=lambda: np.zeros(0))
    name: str = ""


@dataclass
class FaceData:
    """A face for :func:`unroll_face_data`: surface, parameter bounds (u0, u1, v0, v1), wires
    (outer first, then holes; each a list of :class:`EdgeData` in traversal order). A wrong
    outer wire is tolerated: :func:`unroll_face_data` puts the loop enclosing the largest (u, v)
    area first (:func:`outer_loop_index`)."""

    surface: SurfaceAdapter
    bounds: Bounds
    wires: list[list[EdgeData]]
    #: the face's orientation is reversed: its normal is ``-(S_u × S_v)`` (sheet side, ght_cad.sheet)
    reversed: bool = False


class FaceRuledSurface(RuledSurface):
    r"""The ruled surface of a face whose ``ruled``-isolines are straight lines.

    With ``ruled == "v"`` (rulings along v): ``a(t) = S(u0 + t Δu, v0)``, ``b(t) = S(u0 + t Δu, v1)``,
    ``a^(r)(t) = Δu^r ∂_u^r S``; with ``ruled == "u"`` the roles of u and v swap. ``breakpoints``
    are the surface's C∞-interval ends (B-spline knots) in t.

    Raises:
        GHTError: ``ruled`` is not "u" or "v".
    """

    def __init__(self, surface: SurfaceAdapter, ruled: str, bounds: Bounds) -> None:
        if ruled not in ("u", "v"):
            raise GHTError(f"ruled={ruled!r} is not allowed; use 'u' or 'v'")
        self.ev = surface
        self.ruled = ruled
        self.bounds = bounds
        u0, u1, v0, v1 = bounds
        if ruled == "v":
            self.t0, self.t1, self.s0, self.s1 = u0, u1, v0, v1
        else:
            self.t0, self.t1, self.s0, self.s1 = v0, v1, u0, u1
        ks = np.asarray(surface.breaks("u" if ruled == "v" else "v"), dtype=float)
        self.breakpoints = tuple(((ks - self.t0) / (self.t1 - self.t0)).tolist())
        self._jets: dict[bytes, tuple[int, list[np.ndarray]]] = {}

    def _jet(self, t: np.ndarray, order: int) -> list[np.ndarray]:
        """Jets of the surface at both boundaries ``(t, s0)`` and ``(t, s1)`` stacked (2n points), one
        surface evaluation per parameter array (kept for the last 16 arrays: the quadrature and the
        developability ask for a, a', b, b' at the same parameters; :meth:`prefetch` evaluates
        several arrays at once)."""
        key = t.tobytes()
        hit = self._jets.get(key)
        if hit is not None and hit[0] >= order:
            return hit[1]
        u, v = self._ends_uv(t)
        jet = surface_jet(self.ev, u, v, order)
        self._keep(key, order, jet)
        return jet

    def _ends_uv(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Face parameters of both boundaries at ``t``: ``uv(t, 0)`` then ``uv(t, 1)`` (2n points)."""
        ss = np.zeros(2 * t.size)
        ss[t.size:] = 1.0
        return self.uv(np.concatenate([t, t]), ss)

    def _keep(self, key: bytes, order: int, jet: list[np.ndarray]) -> None:
        """Remember the boundary jet of one parameter array (the last 16 arrays are kept)."""
        if key not in self._jets and len(self._jets) >= 16:
            self._jets.pop(next(iter(self._jets)))
        self._jets[key] = (order, jet)

    def prefetch(self, arrays: Sequence[np.ndarray], order: int,
                 extra: tuple[np.ndarray, np.ndarray] | None = None) -> list[np.ndarray] | None:
        """The boundary jets (:meth:`_jet`) of several parameter arrays in one surface evaluation,
        each kept as :meth:`_jet` keeps one (the per-evaluation overhead of a surface, ~25 µs for a
        B-spline, paid once: the developability's, the quadrature's first and the ruling ends'
        parameters are known before any of them is asked for); ``extra``: (u, v) points whose
        jet is evaluated in the same call and returned (the metric grid's partials).

        The points of each array are ``uv(t, 0)`` then ``uv(t, 1)``, the same numbers as
        :meth:`_jet` makes, so each array's jet is a contiguous slice of the result."""
        todo = []
        for t in arrays:
            t = _flat1(t)
            hit = self._jets.get(t.tobytes())
            if t.size and not (hit is not None and hit[0] >= order):
                todo.append(t)
        us, vs = [], []
        for t in todo:
            u, v = self._ends_uv(t)
            us.append(u)
            vs.append(v)
        if extra is not None:
            us.append(np.asarray(extra[0], dtype=float).ravel())
            vs.append(np.asarray(extra[1], dtype=float).ravel())
        if not us:
            return None
        jet = surface_jet(self.ev, np.concatenate(us), np.concatenate(vs), order)
        i = 0
        for t in todo:
            m = 2 * t.size
            self._keep(t.tobytes(), order, [d[i:i + m] for d in jet])
            i += m
        return [d[i:] for d in jet] if extra is not None else None

    def uv(self, t: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Face parameters of ruled parameters (t, s) ∈ [0, 1]²."""
        tp = self.t0 + t * (self.t1 - self.t0)
        sp = self.s0 + s * (self.s1 - self.s0)
        return (tp, sp) if self.ruled == "v" else (sp, tp)

    def ts(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Ruled parameters (t, s) of face parameters (u, v)."""
        tp, sp = (u, v) if self.ruled == "v" else (v, u)
        return (tp - self.t0) / (self.t1 - self.t0), (sp - self.s0) / (self.s1 - self.s0)

    def value_and_ends(self, t: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``S(u, v)`` at points on the rulings at ``t``, evaluated together with the ruling ends
        ``a(t)``, ``b(t)`` (kept for :meth:`a`, :meth:`b`) in one surface evaluation."""
        t = _flat1(t)
        key = t.tobytes()
        if key in self._jets:
            return self.ev.value(u, v)
        # the ends at the distinct t only (points along one ruling share them: a ruling edge's
        # samples, the metric stencil's v steps, the bend lines' two ends)
        tu, inv = unique_inverse(t)
        m = tu.size
        ue, ve = self.uv(np.concatenate([tu, tu]), np.concatenate([np.zeros(m), np.ones(m)]))
        n = np.size(u)
        p = self.ev.value(np.concatenate([np.asarray(u).ravel(), ue]), np.concatenate([np.asarray(v).ravel(), ve]))
        inv = inv.ravel()
        self._keep(key, 0, [np.concatenate([p[n:n + m][inv], p[n + m:][inv]])])
        return p[:n]

    def _edge(self, t: Any, s: float, derivative: int) -> np.ndarray:
        t = _flat1(t)
        if derivative > 2:
            raise GHTError(f"derivative={derivative} is not available for faces; allowed 0, 1, 2")
        d = self._jet(t, derivative)
        part = slice(0, t.size) if s == 0.0 else slice(t.size, 2 * t.size)
        if derivative == 0:
            return d[0][part].copy()
        k = (1 if self.ruled == "v" else 2) if derivative == 1 else (3 if self.ruled == "v" else 4)
        return d[k][part] * (self.t1 - self.t0) ** derivative

    def edge_jets(self, u: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(a', g, g')`` (:meth:`RuledSurface.edge_jets`) from one kept jet (:meth:`_jet`, order 1):
        the same numbers as :meth:`a` and :meth:`ruling` give."""
        t = _flat1(u)
        d = self._jet(t, 1)
        n = t.size
        k = 1 if self.ruled == "v" else 2
        s = self.t1 - self.t0
        a1, b1 = d[k][:n] * s, d[k][n:] * s
        return a1, d[0][n:] - d[0][:n], b1 - a1

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._edge(u, 0.0, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._edge(u, 1.0, derivative)


def _isoline_points(ev: SurfaceAdapter, bounds: Bounds, directions: Sequence[str]) -> dict[str, np.ndarray]:
    """Points of the nine isolines along each of ``directions`` (fixed other parameter at 0, 1/8,
    ..., 1 of its range, 33 points each): ``{direction: (9, 33, 3)}``, one surface evaluation."""
    u0, u1, v0, v1 = bounds
    run = np.linspace(0.0, 1.0, 33)
    us, vs = [], []
    for direction in directions:
        for f in np.linspace(0.0, 1.0, 9):
            if direction == "v":
                us.append(np.full_like(run, u0 + f * (u1 - u0)))
                vs.append(v0 + run * (v1 - v0))
            else:
                us.append(u0 + run * (u1 - u0))
                vs.append(np.full_like(run, v0 + f * (v1 - v0)))
    p = np.asarray(ev.value(np.concatenate(us), np.concatenate(vs)), dtype=float).reshape(len(directions), 9, 33, 3)
    return {d: p[k] for k, d in enumerate(directions)}


def isoline_stats(ev: SurfaceAdapter, bounds: Bounds, direction: str, points: np.ndarray | None = None) -> tuple[float, float]:
    r"""Straightness and openness of the isolines running along ``direction``.

    Nine isolines (fixed other parameter at 0, 1/8, ..., 1 of its range), each sampled at 33
    points ``p_0 .. p_32``, polyline length ``L = Σ |p_{k+1} - p_k|``, chord ``c = p_32 - p_0``.
    The line an isoline is compared with is its chord line when ``|c| > 1e-9 L``, else (a closed
    isoline) the best-fitting line (through the centroid along the principal axis of the points).
    The deviation of one isoline is ``max_k dist(p_k, line) / L`` (0 for a straight segment,
    ``1/π`` for a half circle, ``1/(2π)`` for a full circle); isolines with ``L = 0`` (a pole or
    an apex) are points and skipped.

    Args:
        ev: the surface.
        bounds: (u0, u1, v0, v1).
        direction: "u" (isolines along u) or "v".

        points: the isolines' points (:func:`_isoline_points`) when already evaluated.

    Returns:
        ``(deviation, openness)``: the largest deviation and the smallest ``|c| / L`` over the
        non-degenerate isolines (``openness`` 0 for closed isolines, 1 for straight ones);
        ``(0.0, 1.0)`` when every isoline is degenerate.
    """
    if points is None:
        points = _isoline_points(ev, bounds, (direction,))[direction]
    worst, openness = 0.0, 1.0
    lengths = np.linalg.norm(np.diff(points, axis=1), axis=2).sum(axis=1)
    with np.errstate(invalid="ignore", over="ignore"):
        scale = np.maximum(1.0, np.abs(points).max(axis=(1, 2)))
        good = np.isfinite(lengths) & ~(lengths <= 1e-14 * scale)  # else the isoline is a point (pole, apex)
    if not good.any():
        return worst, openness
    p, L = points[good], lengths[good]
    c = p[:, -1] - p[:, 0]
    chord = np.linalg.norm(c, axis=1)
    origin, axis = p[:, 0].copy(), c / np.where(chord > 0, chord, 1.0)[:, None]
    for k in np.nonzero(~(chord > 1e-9 * L))[0]:  # closed isoline: its best-fitting straight line
        origin[k] = p[k].mean(axis=0)
        axis[k] = np.linalg.svd(p[k] - origin[k], full_matrices=False)[2][0]
    dev = np.linalg.norm(np.cross(p - origin[:, None, :], axis[:, None, :]), axis=2).max(axis=1) / L
    return max(worst, float(dev.max())), min(openness, float((chord / L).min()))


def ruling_direction(surface: SurfaceAdapter, bounds: Bounds) -> tuple[str | None, dict[str, float]]:
    r"""Which parameter direction of the face has straight isolines (the rulings).

    Args:
        surface: the face's surface.
        bounds: its parameter bounds (u0, u1, v0, v1).

    Returns:
        ``("v", info)`` when the v-isolines are straight (deviation ``max dist(p, line) / L``
        < 1e-9, see :func:`isoline_stats`; a closed isoline deviates by ``1/(2π)``), ``"u"``
        likewise, ``None`` when neither. ``info`` holds ``deviation_u``, ``deviation_v``,
        ``openness_u``, ``openness_v`` and ``end_length_u``, ``end_length_v``
        (:func:`end_isoline_length`). Planes, cylinders, cones and extrusions return ``"v"``,
        a structurally ruled B-spline/Bézier its ``ruled_hint``, without measuring: their ``info``
        holds only the ruled direction's ``deviation`` (0) and ``openness`` (1) and
        ``ruled_by: "structure"``.
    """
    hint = "v" if surface.kind in RULED_KINDS else surface.ruled_hint
    if hint in ("u", "v"):
        # ruled by construction (an extrusion; a B-spline/Bézier of degree 1 with 2 poles across:
        # for fixed u, a rational-linear function of v is a straight segment), nothing to measure
        return hint, {f"deviation_{hint}": 0.0, f"openness_{hint}": 1.0, "ruled_by": "structure"}
    pts = _isoline_points(surface, bounds, ("v", "u"))
    dv, ov = isoline_stats(surface, bounds, "v", pts["v"])
    du, ou = isoline_stats(surface, bounds, "u", pts["u"])
    info = {"deviation_v": dv, "deviation_u": du, "openness_v": ov, "openness_u": ou}
    info.update({f"end_length_{d}": end_isoline_length(surface, bounds, d, pts[d]) for d in ("u", "v")})
    if dv <= 1e-9 and dv <= du:
        return "v", info
    if du <= 1e-9:
        return "u", info
    return None, info


def end_isoline_length(ev: SurfaceAdapter, bounds: Bounds, direction: str, points: np.ndarray | None = None) -> float:
    r"""How far the two end isolines along ``direction`` are from being points.

    For ``direction == "u"``: the u-isolines ``S(·, v0)`` and ``S(·, v1)`` (the boundary curves
    of rulings along v), each a 33-point polyline length, ``max(L(v0), L(v1)) / max_k L_k`` over
    the nine isolines of :func:`isoline_stats`: 0 when both end isolines are points (the poles
    of a full sphere), 1 when one of them is the longest.

    Args:
        ev: the surface.
        bounds: (u0, u1, v0, v1).
        direction: "u" or "v".
        points: the isolines' points (:func:`_isoline_points`) when already evaluated.

    Returns:
        The ratio in [0, 1] (1.0 when every isoline is a point).
    """
    if points is None:
        points = _isoline_points(ev, bounds, (direction,))[direction]
    lengths = [L if math.isfinite(L) else 0.0
               for L in np.linalg.norm(np.diff(points, axis=1), axis=2).sum(axis=1).tolist()]
    top = max(lengths)
    return max(lengths[0], lengths[-1]) / top if top > 0 else 1.0


def best_effort_direction(info: dict[str, float], label: str) -> str:
    """Ruling direction for flattening a non-ruled face: the boundary isolines ``S(·, v0)``,
    ``S(·, v1)`` (rulings along v) must be distinct curves, i.e. the v-isolines must be open, and
    must not both be points (``end_length_u`` > 1e-6, :func:`end_isoline_length`: rulings
    between the two poles of a full sphere span no area). Among directions whose isolines are
    clearly open (chord ≥ 1 % of the length), else merely open (chord > 1e-6 of the length), the
    straighter one is used.

    Raises:
        DegenerateGeometryError: no direction qualifies (a torus: isolines closed both ways; a
            full sphere: meridians open but both latitude ends are poles): there are no two
            distinct boundary curves to span rulings between.
    """
    other = {"u": "v", "v": "u"}
    spans = [d for d in ("v", "u") if info.get(f"end_length_{other[d]}", 1.0) > 1e-6]
    for lim in (1e-2, 1e-6):
        cands = [d for d in spans if info[f"openness_{d}"] >= lim]
        if cands:
            return min(cands, key=lambda d: info[f"deviation_{d}"])
    why = []
    if info["openness_u"] < 1e-6 and info["openness_v"] < 1e-6:
        why.append(
            f"its isolines are closed in both directions (chord/length {info['openness_u']:.3g} (u) and "
            f"{info['openness_v']:.3g} (v); allowed > 1e-6)"
        )
    for d in ("u", "v") if not why else ():
        if info[f"openness_{d}"] < 1e-6:
            why.append(f"its {d}-isolines are closed (chord/length {info[f'openness_{d}']:.3g}; allowed > 1e-6)")
        elif d not in spans:
            why.append(
                f"its {d}-isolines run between two points (both end {other[d]}-isolines are points: length "
                f"ratio {info[f'end_length_{other[d]}']:.3g}; allowed > 1e-6)"
            )
    raise DegenerateGeometryError(
        f"face {label!r} is not ruled (its isolines deviate from straight lines by "
        f"{info['deviation_u']:.3g} (u-isolines) and {info['deviation_v']:.3g} (v-isolines) relative to "
        "their lengths; allowed 1e-9) and cannot be flattened even with best_effort=True: "
        + " and ".join(why)
        + ", so it has no two distinct boundary curves to span rulings between; split the face (e.g. cut "
        "a torus or a sphere into sectors) first"
    )


@functools.lru_cache(maxsize=1)
def _gauss12() -> tuple[np.ndarray, np.ndarray]:
    """12-point Gauss–Legendre nodes and weights on [-1, 1] (computed once; read-only arrays)."""
    xg, wg = np.polynomial.legendre.leggauss(12)
    xg.flags.writeable = False
    wg.flags.writeable = False
    return xg, wg


def face_area(
    ev: SurfaceAdapter,
    edges_uv: list[list[tuple[Callable, Callable]]],
    u_lo: float,
    u_breaks: np.ndarray,
    u_span: float | None = None,
) -> float:
    r"""3-D area ``∬_Ω |S_u × S_v| du dv`` of a trimmed face by Green's theorem in (u, v).

    ``∬_Ω f du dv = ∮_{∂Ω} P dv`` with ``P(u, v) = ∫_{u_lo}^{u} f(s, v) ds``: the outer integral by
    16 × 12-point Gauss–Legendre panels along each pcurve (split at the pcurve's knots, the
    ``breaks`` attribute of ``duv``), the inner one by 12-point panels, at least 2 per interval
    between ``u_breaks`` (the surface's knots) and none wider than ``u_span / 8`` (an analytic
    but non-polynomial ``f``, e.g. an extruded ellipse over its whole period), i.e. exact up to
    the smoothness of ``f``. On a plane, cylinder or cone (``ev.kind``; u the angle about the axis)
    ``f`` does not depend on u and ``P(u, v) = (u - u_lo) f(u_lo, v)`` in closed form. Along an
    edge with constant u (an isoline of the parameter box) every node has the same inner nodes:
    the density is evaluated on that grid (``ev.density_grid(s, v)`` when the adapter has it).

    Args:
        ev: the surface (``d1``).
        edges_uv: per loop, per edge ``(t -> (u, v), t -> (u', v'))``.
        u_lo: lower limit of the inner integral (any u; the face's u0).
        u_breaks: the surface's u breaks.
        u_span: the face's u range ``u1 - u0`` (None: no width limit for the inner panels).

    Returns:
        ``|I_0| - Σ_{k≥1} |I_k|`` where ``I_k = ∮_{loop k} P dv`` (the first loop is the outer
        one, the others holes): independent of the loops' orientations.
    """
    xg, wg = _gauss12()
    u_breaks = np.asarray(u_breaks, dtype=float)
    # outer nodes of every edge of every loop; then one surface evaluation for all inner nodes
    parts = []  # (loop, outer weights dv * tw, u, v) per edge
    for k, loop in enumerate(edges_uv):
        for uvf, duv in loop:
            tn, tw = _edge_nodes(getattr(duv, "breaks", None))
            dv = duv(tn)[:, 1]
            if not dv.any():
                continue
            u, v = uvf(tn)
            parts.append((k, dv * tw, np.asarray(u, dtype=float), np.asarray(v, dtype=float)))
    totals = [0.0] * len(edges_uv)
    if not parts:
        return 0.0
    u = np.concatenate([p[2] for p in parts])
    v = np.concatenate([p[3] for p in parts])
    if getattr(ev, "kind", "other") in U_FREE_DENSITY_KINDS:
        # |S_u × S_v| does not depend on u: P(u, v) = (u - u_lo) f(u_lo, v) exactly
        d = ev.d1(np.full_like(v, u_lo), v)
        P = (u - u_lo) * np.linalg.norm(np.cross(d[0], d[1]), axis=1)
    else:
        P = np.zeros(u.size)
        general = np.ones(u.size, dtype=bool)
        grid = getattr(ev, "density_grid", None)
        i = 0
        for _, _, uu, vv in parts if grid is not None else ():
            m = uu.size
            if m and (uu == uu[0]).all():  # an edge along v (u constant): its inner nodes are shared
                # (none on u = u_lo, where P = 0)
                s_n, w_n = _inner_nodes_at(float(uu[0]), u_lo, u_breaks, u_span) if uu[0] != u_lo else (np.zeros(0),) * 2
                if s_n.size:
                    f = grid(s_n, vv)
                    P[i:i + m] = w_n @ f
                general[i:i + m] = False
            i += m
        if general.any():
            ug, vg = u[general], v[general]
            if grid is not None and getattr(ev, "fast_density_grid", False):
                P[general] = _inner_integrals_by_pieces(ev, ug, vg, u_lo, u_breaks, u_span)
            else:
                P[general] = _inner_integrals(ev, ug, vg, u_lo, u_breaks, u_span)
    i = 0
    for k, wdv, uu, _ in parts:
        totals[k] += float(np.sum(P[i:i + uu.size] * wdv))
        i += uu.size
    totals = [abs(t) for t in totals]
    return totals[0] - sum(totals[1:]) if totals else 0.0


@functools.lru_cache(maxsize=1)
def _edge_nodes_plain() -> tuple[np.ndarray, np.ndarray]:
    """:func:`_edge_nodes` without breaks (computed once; read-only arrays)."""
    out = _edge_nodes_at(np.linspace(0.0, 1.0, 17))
    for a in out:
        a.flags.writeable = False
    return out


def _edge_nodes_at(te: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    xg, wg = _gauss12()
    h = 0.5 * np.diff(te)
    return ((0.5 * (te[:-1] + te[1:])[:, None] + h[:, None] * xg[None, :]).ravel(), (h[:, None] * wg[None, :]).ravel())


def _edge_nodes(breaks: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights along an edge, t ∈ [0, 1]: 16 equal panels, also cut at
    the pcurve's ``breaks``, 12 points each."""
    if breaks is None or not len(breaks):
        return _edge_nodes_plain()
    return _edge_nodes_at(np.unique(np.concatenate([np.linspace(0.0, 1.0, 17), breaks])))


def _inner_nodes_at(u: float, u_lo: float, u_breaks: np.ndarray, u_span: float | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_inner_nodes` of one u (an edge with constant u): the nodes ``s`` and weights ``w``
    of ``∫_{u_lo}^{u} f(s, v) ds``, by the same panels and the same arithmetic, with the panel
    ends made in plain floats (one u: the array bookkeeping cost more than the nodes)."""
    xg, wg = _gauss12()
    lo, hi = min(u, u_lo), max(u, u_lo)
    sign = 1.0 if u >= u_lo else -1.0
    cuts = [lo, *sorted(b for b in np.asarray(u_breaks, dtype=float).tolist() if lo < b < hi), hi]
    a_s, b_s = [], []
    for a, b in zip(cuts[:-1], cuts[1:]):
        m = 0.5 * (a + b)
        for x0, x1 in ((a, m), (m, b)):
            if not x1 > x0:
                continue
            cnt = max(1, math.ceil((x1 - x0) * 8.0 / abs(u_span))) if u_span else 1
            step = (x1 - x0) / cnt
            a_s += [x0 + j * step for j in range(cnt)]
            b_s += [x0 + (j + 1) * step for j in range(cnt)] if u_span else [x1]
    A, B = np.array(a_s), np.array(b_s)
    h = 0.5 * (B - A)
    return ((A + h)[:, None] + h[:, None] * xg[None, :]).ravel(), (sign * h[:, None] * wg[None, :]).ravel()


def _inner_integrals(ev: SurfaceAdapter, u: np.ndarray, v: np.ndarray, u_lo: Any, u_breaks: np.ndarray,
                     u_span: float | None) -> np.ndarray:
    """``P(u_i, v_i) = ∫_{u_lo}^{u_i} |S_u × S_v|(s, v_i) ds`` point by point (:func:`_inner_nodes`,
    one evaluation of the partials at all nodes)."""
    xg, wg = _gauss12()
    s_all, v_all, w_all, own = _inner_nodes(u, v, u_lo, u_breaks, u_span, xg, wg)
    if not s_all.size:
        return np.zeros(u.size)
    d = ev.d1(s_all, v_all)
    f = _norm(_cross(d[0], d[1]))
    return np.bincount(own, weights=f * w_all, minlength=u.size)


def _inner_integrals_by_pieces(ev: SurfaceAdapter, u: np.ndarray, v: np.ndarray, u_lo: float,
                               u_breaks: np.ndarray, u_span: float | None) -> np.ndarray:
    r""":func:`_inner_integrals` with the same panels, the whole pieces on a grid.

    For ``u_i >= u_lo`` the interval ``[u_lo, u_i]`` cut at the breaks is ``[K_0, K_1], ...,
    [K_{m_i}, u_i]`` with ``K_0 = u_lo`` and ``K_1 < K_2 < ...`` the breaks: every piece but the
    last is the same for all points below which it lies, so its nodes ``s_j`` (the same halves and
    panels) serve all points on one tensor grid ``|S_u × S_v|(s_j, v_i)`` (``ev.density_grid``:
    each basis series once per s and once per v, about 10x cheaper a point than the partials at
    scattered points), ``P_i = Σ_{j < m_i} Σ w_j f(s_j, v_i) + ∫_{K_{m_i}}^{u_i}``, the last piece point
    by point. Points with ``u_i < u_lo`` go point by point. A trimmed B-spline loft face of 5
    spans: 112,000 scattered partials (48 ms an unroll) became a grid and 12 nodes a point."""
    out = np.empty(u.size)
    below = u < u_lo
    if below.any():
        out[below] = _inner_integrals(ev, u[below], v[below], u_lo, u_breaks, u_span)
    up = ~below
    if not up.any():
        return out
    uu, vv = u[up], v[up]
    br = np.unique(np.asarray(u_breaks, dtype=float))
    br = br[(br > u_lo) & (br < float(uu.max()))]
    K = np.concatenate([[float(u_lo)], br])
    m = np.searchsorted(br, uu, side="left")  # breaks strictly below u_i: the whole pieces
    total = np.zeros(uu.size)
    if br.size:
        nodes = [_inner_nodes_at(float(K[j + 1]), float(K[j]), np.zeros(0), u_span) for j in range(br.size)]
        s_all = np.concatenate([sn for sn, _ in nodes])
        w_all = np.concatenate([wn for _, wn in nodes])
        starts = np.cumsum([0] + [sn.size for sn, _ in nodes[:-1]])
        step = max(1, int(2_000_000 // max(s_all.size, 1)))  # grid memory: at most ~16 MB at once
        for a in range(0, uu.size, step):
            sl = slice(a, a + step)
            G = ev.density_grid(s_all, vv[sl])  # (nodes, points)
            S = np.add.reduceat(G * w_all[:, None], starts, axis=0)  # (pieces, points)
            C = np.concatenate([np.zeros((1, S.shape[1])), np.cumsum(S, axis=0)])
            total[sl] = C[m[sl], np.arange(S.shape[1])]
    last = _inner_integrals(ev, uu, vv, K[m], np.zeros(0), u_span)
    out[up] = total + last
    return out


def _inner_nodes(u: np.ndarray, v: np.ndarray, u_lo: Any, u_breaks: np.ndarray, u_span: float | None,
                 xg: np.ndarray, wg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    r"""Gauss–Legendre nodes of ``P(u_i, v_i) = ∫_{u_lo}^{u_i} f(s, v_i) ds`` for all i at once.

    Per i: the interval between ``u_lo`` and ``u_i`` cut at the ``u_breaks`` inside it, each piece
    halved, each half cut into ``max(1, ceil(8 L / |u_span|))`` equal panels (L its length; one
    panel without ``u_span``), ``len(xg)`` nodes per panel, weights signed by ``u_i >= u_lo``.

    Returns:
        (s, v, w, owner): node parameters, their v, weights, and the index i each belongs to.
    """
    n = u.size
    lo = np.minimum(u, u_lo)
    hi = np.maximum(u, u_lo)
    sign = np.where(u >= u_lo, 1.0, -1.0)
    br = np.broadcast_to(u_breaks, (n, u_breaks.size))
    inside = (br > lo[:, None]) & (br < hi[:, None])
    # every row: lo, the breaks inside (others pushed to hi, giving empty pieces), hi; sorted
    cuts = np.sort(np.concatenate([lo[:, None], np.where(inside, br, hi[:, None]), hi[:, None]], axis=1), axis=1)
    a, b = cuts[:, :-1], cuts[:, 1:]
    m = 0.5 * (a + b)
    a = _stack([a, m], axis=2).reshape(n, -1)  # halves [a, m], [m, b]
    b = _stack([m, b], axis=2).reshape(n, -1)
    owner = np.repeat(np.arange(n), a.shape[1])
    a, b = a.ravel(), b.ravel()
    keep = b > a
    a, b, owner = a[keep], b[keep], owner[keep]
    if u_span:
        cnt = np.maximum(1, np.ceil((b - a) * 8.0 / abs(u_span))).astype(int)
        rep = np.repeat(np.arange(a.size), cnt)
        j = np.arange(rep.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        step = (b - a)[rep] / cnt[rep]
        a, b, owner = a[rep] + j * step, a[rep] + (j + 1) * step, owner[rep]
    h = 0.5 * (b - a)
    s = ((a + h)[:, None] + h[:, None] * xg[None, :]).ravel()
    w = (sign[owner][:, None] * h[:, None] * wg[None, :]).ravel()
    own = np.repeat(owner, xg.size)
    return s, v[own], w, own


def loop_uv_area(loop: list[tuple[Callable, Callable]]) -> float:
    r"""Signed area a loop encloses in the parameter plane, ``∮ u dv`` (16 × 12-point
    Gauss–Legendre panels per edge, split at the pcurve's knots: exact for polynomial pieces).

    Args:
        loop: per edge ``(t -> (u, v), t -> (u', v'))`` in traversal order.

    Returns:
        The signed (u, v)-area (positive counter-clockwise).
    """
    total = 0.0
    for uvf, duv in loop:
        tn, tw = _edge_nodes(getattr(duv, "breaks", None))
        u, _ = uvf(tn)
        total += float(np.sum(np.asarray(u, dtype=float) * duv(tn)[:, 1] * tw))
    return total


def outer_loop_index(loops_uv: list[list[tuple[Callable, Callable]]]) -> int:
    """Index of the outer loop of a face: the one enclosing the largest (u, v)-area
    ``|∮ u dv|`` (:func:`loop_uv_area`; the outer boundary of a face's parameter domain encloses
    its holes). 0 when there are no loops.

    Args:
        loops_uv: per loop, per edge ``(t -> (u, v), t -> (u', v'))``.

    Returns:
        The index in ``loops_uv``.
    """
    if len(loops_uv) < 2:
        return 0
    return int(np.argmax([abs(loop_uv_area(lp)) for lp in loops_uv]))


def fd_derivative(fun: Callable[[np.ndarray], np.ndarray], t: np.ndarray, breaks: Sequence[float] = (), h: float = 1e-4) -> np.ndarray:
    r"""Derivative of a piecewise-smooth ``fun: t -> (n, k)`` on [0, 1] by 5-point differences.

    Central ``(-f(t+2h) + 8 f(t+h) - 8 f(t-h) + f(t-2h)) / 12h`` (O(h⁴)) with
    ``h = min(h, d/2.5)`` where ``d`` is the distance of t to the nearest break or end, so the
    stencil never straddles a knot; at a break or end (``d < 1e-9``) the one-sided 5-point formula
    ``(-25 f0 + 48 f1 - 36 f2 + 16 f3 - 3 f4) / 12h`` (O(h⁴)) pointing into [0, 1] is used.

    Args:
        fun: the function (vectorized over t).
        t: points in [0, 1].
        breaks: interior points where ``fun`` is not smooth.
        h: largest step.

    Returns:
        (n, k) derivatives.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    knots = np.unique(np.concatenate([[0.0, 1.0], np.asarray(breaks, dtype=float)]))
    dist = np.min(np.abs(t[:, None] - knots[None, :]), axis=1)
    step = np.minimum(h, dist / 2.5)
    out = np.empty((t.size, np.asarray(fun(t[:1])).shape[1]))
    central = dist >= 1e-9
    if central.any():
        tc, hc = t[central], step[central][:, None]
        f = [np.asarray(fun(tc + k * hc[:, 0])) for k in (-2, -1, 1, 2)]
        out[central] = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * hc)
    if (~central).any():
        tb = t[~central]
        sgn = np.where(tb < 0.5, 1.0, -1.0)
        hb = h * sgn
        f = [np.asarray(fun(tb + k * hb)) for k in range(5)]
        out[~central] = (-25 * f[0] + 48 * f[1] - 36 * f[2] + 16 * f[3] - 3 * f[4]) / (12 * hb[:, None])
    return out


def chain_loop(
    ends: list[tuple[np.ndarray, np.ndarray]], periods: tuple[float, float], tol: float | Sequence[float]
) -> list[tuple[bool, np.ndarray]]:
    r"""Make a wire's pcurves one continuous loop in (u, v).

    A seam edge of a periodic surface has two pcurves a period apart and a kernel may hand out the
    other one (or an edge in the other direction): walking the wire, each edge is kept or reversed
    and shifted by whole periods ``(k_u P_u, k_v P_v)`` so that it starts where the previous one
    ended (within ``tol``).

    Args:
        ends: per edge its (start, end) uv points in the given direction.
        periods: (P_u, P_v), 0 for a non-periodic direction.
        tol: matching tolerance in (u, v): one number, or ``(tol_u, tol_v)`` (u and v often have
            different units, e.g. an angle and a length: give each a tolerance relative to its
            own range).

    Returns:
        Per edge ``(reverse, shift)`` (an edge matching both ways, e.g. a closed isoline spanning a
        whole period, takes the smaller shift, then its given direction). Edges that cannot be
        matched are kept as given.
    """
    P = np.asarray(periods, dtype=float)

    def shift_to(p: np.ndarray, q: np.ndarray) -> np.ndarray | None:
        d = q - p
        k = np.where(P > 0, np.round(d / np.where(P > 0, P, 1.0)), 0.0)
        s = k * P
        return s if np.all(np.abs(d - s) <= np.asarray(tol, dtype=float)) else None

    out: list[tuple[bool, np.ndarray]] = [(False, np.zeros(2))]
    if not ends:
        return []
    a0, b0 = ends[0]
    if len(ends) > 1:  # the first edge given in the other direction: the second one starts at its start
        a1, b1 = ends[1]
        if shift_to(a1, b0) is None and shift_to(b1, b0) is None and (
            shift_to(a1, a0) is not None or shift_to(b1, a0) is not None
        ):
            out[0] = (True, np.zeros(2))
            a0, b0 = b0, a0
    cur = b0
    for a, b in ends[1:]:
        fwd, rev = shift_to(a, cur), shift_to(b, cur)
        # an edge spanning a whole period matches both ways: prefer the smaller shift, then forward
        if rev is not None and (fwd is None or np.abs(rev).sum() < np.abs(fwd).sum()):
            out.append((True, rev))
            cur = a + rev
        elif fwd is not None:
            out.append((False, fwd))
            cur = b + fwd
        else:
            out.append((False, np.zeros(2)))
            cur = b
    return out


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
        sheet: a :class:`ght_cad.sheet.Sheet` with ``T > 0``: the face's neutral offset
            ``S + σ K T n`` (n the face normal, orientation included) is unrolled instead
            (:class:`ght_cad.sheet.FaceSheet`: cylinders/cones keep their closed forms with the
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
    ev, bounds, kind = face.surface, face.bounds, face.surface.kind
    if not all(math.isfinite(b) and abs(b) < 1e50 for b in bounds) or bounds[0] >= bounds[1] or bounds[2] >= bounds[3]:
        raise DegenerateGeometryError(
            f"face {label!r} is unbounded or empty: parameter bounds (u0, u1, v0, v1) = "
            f"({', '.join(f'{b:.6g}' for b in bounds)}); allowed: a face trimmed by boundary wires, finite "
            "bounds with u0 < u1 and v0 < v1"
        )
    if not any(face.wires):
        raise DegenerateGeometryError(f"face {label!r} has no boundary wires; allowed: a face trimmed by boundary wires")
    info: dict[str, Any] = {"best_effort": bool(best_effort)}
    fsheet = None
    if sheet is not None and not sheet.is_zero:  # the neutral surface replaces the face's own
        from .sheet import FaceSheet

        fsheet = FaceSheet(face, sheet, label)
        ev = fsheet.neutral
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
    # boundary loops
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
    # rulings (bend lines and ruling-length check) over the UV box, clipped later to the outline
    u0, u1, v0, v1 = bounds
    bends = np.zeros((0, 2, 2))
    g3 = gf = np.zeros(0)
    if ruled_dir is not None:
        tt = _unit_samples(129)
        tb = np.arange(1, rulings + 1) / (rulings + 1)

        def ends(t: np.ndarray) -> tuple[np.ndarray, ...]:
            if ruled_dir == "v":
                uu = u0 + t * (u1 - u0)
                return uu, np.full(t.shape, float(v0)), uu, np.full(t.shape, float(v1))
            vv = v0 + t * (v1 - v0)
            return np.full(t.shape, float(u0)), vv, np.full(t.shape, float(u1)), vv

        # the ruling ends' 3-D lengths from the prefetched boundary jets; one evaluation of the map
        # for the ruling ends and the bend lines
        ua, va, ub, vb = ends(tt)
        n = tt.size
        if rs is not None:
            g3 = rs.ruling_lengths(tt)
        else:  # a cylinder or cone (closed form): one evaluation of the ruling ends
            p3 = ev.value(np.concatenate([ub, ua]), np.concatenate([vb, va]))
            g3 = _norm(p3[:n] - p3[n:])
    if mgrid is None:
        mgrid = _metric_grid(bounds)
    # the map's points in one call (it is pointwise; its per-call overhead dominated): the
    # edges' outline samples, the ruling ends and bend lines, the metric's stencil
    mU, mV, mhu, mhv = mgrid
    sampled, ts, edge_uv = _edge_sample_uv(loops, loops_uv, samples)
    clipped = None
    if ruled_dir is not None:
        # bend lines: rulings clipped to the loops in (u, v), where they are straight lines
        ca, cva, cb, cvb = ends(tb) if rulings else (np.zeros(0),) * 4
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
    area_3d = face_area(ev, loops_uv, u0, ev.breaks("u"), u1 - u0)
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


def clip_rulings_uv(polygons: Sequence[np.ndarray], c: np.ndarray, lo: float, hi: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    r"""Clip the rulings ``x = c_k``, ``y ∈ [lo, hi]`` of the parameter plane to a face's loops.

    A face's rulings are straight in its parameters (rulings along v: the lines u = c_k), so
    bend lines are clipped where they are exact: every loop edge ``A → B`` of the (u, v)
    polygons with ``(A_x <= c) != (B_x <= c)`` (half-open: a vertex on the line counts once)
    crosses at ``y = A_y + (c - A_x)(B_y - A_y) / (B_x - A_x)``; sorted along each ruling the
    crossings pair up into the inside intervals (even–odd over all loops: holes cut them), each
    clamped to [lo, hi].

    Args:
        polygons: the loops as closed (m, 2) polylines (x across the rulings, y along them).
        c: the rulings' positions, (k,).
        lo, hi: the rulings' extent along y.

    Returns:
        ``(ruling index, y0, y1)`` per inside interval, in ruling order then along y; None when
        some ruling crosses the loops an odd number of times (a polyline that is not closed).
    """
    A = np.concatenate(polygons)
    B = np.concatenate([np.concatenate([p[1:], p[:1]]) for p in polygons])
    # (A_x <= c) != (B_x <= c)  <=>  min(A_x, B_x) <= c < max(A_x, B_x): the crossing rulings of an
    # edge are a run of the sorted c, found by bisection (no rulings x edges table)
    by_c = np.argsort(c, kind="stable")
    cs = c[by_c]
    first = np.searchsorted(cs, np.minimum(A[:, 0], B[:, 0]), side="left")
    cnt = np.searchsorted(cs, np.maximum(A[:, 0], B[:, 0]), side="left") - first
    j = np.repeat(np.arange(A.shape[0]), cnt)
    k = by_c[np.repeat(first, cnt) + (np.arange(j.size) - np.repeat(np.cumsum(cnt) - cnt, cnt))]
    y = A[j, 1] + (c[k] - A[j, 0]) * (B[j, 1] - A[j, 1]) / (B[j, 0] - A[j, 0])
    order = np.lexsort((y, k))
    k, y = k[order], y[order]
    if np.any(np.bincount(k, minlength=c.size) % 2):
        return None
    k, y0, y1 = k[::2], np.maximum(y[::2], lo), np.minimum(y[1::2], hi)
    keep = y1 - y0 > 1e-12 * (hi - lo)
    return k[keep], y0[keep], y1[keep]


def _strided_memo(fun: Callable[[np.ndarray], np.ndarray]) -> Callable[[np.ndarray], np.ndarray]:
    """``fun`` (pointwise in t) remembering its last result: a parameter array equal to the last
    one or to every k-th entry of it (the outline's 257 samples after the length's 513) is
    answered by slicing (the same values, not recomputed). ``f.seed(t, r)`` stores ``r = fun(t)``
    computed elsewhere (all edges of a face in one map call, :func:`_seed_edge_samples`)."""
    last: list[Any] = [None, None]

    def f(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        t0, r0 = last
        if t0 is not None and t.ndim == 1 and t.size > 1 and t0.size >= t.size and (t0.size - 1) % (t.size - 1) == 0:
            k = (t0.size - 1) // (t.size - 1)
            if (t0[::k] == t).all():  # numpy.array_equal (same shapes here), without its overhead
                return r0[::k].copy()
        r = np.asarray(fun(t), dtype=float)
        last[0], last[1] = t.copy(), r
        return r.copy()

    def seed(t: np.ndarray, r: np.ndarray) -> None:
        last[0], last[1] = np.array(t, dtype=float), np.asarray(r, dtype=float)

    f.seed = seed  # type: ignore[attr-defined]
    return f


def _edge_sample_uv(loops: list[list[BoundaryEdge]], loops_uv: list[list[tuple[Callable, Callable]]],
                    samples: int) -> tuple[list[BoundaryEdge], np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """The edges with memos, their ``samples`` outline parameters ``t_i = i / (samples - 1)`` and
    all edges' (u, v) there, concatenated (edge by edge)."""
    edges = [(e, uvf) for loop, luv in zip(loops, loops_uv) for e, (uvf, _) in zip(loop, luv)
             if hasattr(e.flat_fn, "seed")]
    t = _unit_samples(samples)
    if not edges or samples < 2:
        return [], t, (np.zeros(0), np.zeros(0))
    uvs = [uvf(t) for _, uvf in edges]
    us = [_as_shape(u, t.shape) for u, _ in uvs]
    vs = [_as_shape(v, t.shape) for _, v in uvs]
    return [e for e, _ in edges], t, (np.concatenate(us), np.concatenate(vs))


def _c0_crossings(uvf: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], c0u: np.ndarray,
                  c0v: np.ndarray) -> tuple[float, ...]:
    """Edge parameters ``t`` in (0, 1) where a straight isoline edge (v constant and u affine in t,
    or the other way round: the rails and rulings of a B-spline face) crosses a knot line where the
    surface is only C0 (``c0u``/``c0v``, :meth:`SurfaceAdapter.c0_breaks`): ``t = (k - u(0)) /
    (u(1) - u(0))``. There the edge's parameter speed jumps (a loft's joint ruling), so its
    measures are split there (:attr:`ght_cad.flat_pattern.BoundaryEdge.breaks`). Other edges: ()."""
    u, v = (np.asarray(x, dtype=float) for x in uvf(np.array([0.0, 0.5, 1.0])))
    out: list[float] = []
    for along, fixed, ks in ((u, v, c0u), (v, u, c0v)):
        span = float(along[2] - along[0])
        if not ks.size or span == 0.0:
            continue
        tol = 1e-12 * abs(span)
        if float(np.ptp(fixed)) <= tol and abs(float(along[1]) - 0.5 * float(along[0] + along[2])) <= tol:
            t = (np.asarray(ks, dtype=float) - float(along[0])) / span
            out += [float(x) for x in t if 1e-9 < x < 1.0 - 1e-9]
    return tuple(sorted(out))


def _flat1(t: Any) -> np.ndarray:
    """``t`` as a 1-D float array (``np.atleast_1d(np.asarray(t, float)).ravel()``, the same
    array object when it is one already)."""
    t = np.asarray(t, dtype=float)
    return t if t.ndim == 1 else t.reshape(-1)


def _as_shape(x: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``np.broadcast_to(np.asarray(x, float), shape)``, the array itself when it has that shape."""
    x = np.asarray(x, dtype=float)
    return x if x.shape == shape else np.broadcast_to(x, shape)


def _seed_edge_samples(edges: list[BoundaryEdge], t: np.ndarray, flat: np.ndarray) -> None:
    """Seed the edges' memos with their outline samples' flat points ``flat`` (edge by edge, as
    from :func:`_edge_sample_uv`): the same pointwise values as one map call per edge, without
    the per-call overhead."""
    n = t.size
    for k, e in enumerate(edges):
        e.flat_fn.seed(t, flat[k * n:(k + 1) * n])  # type: ignore[attr-defined]


def _loop_points(loop: list[tuple[Callable, Callable]], n: int) -> np.ndarray:
    """(u, v) points of a loop, ``n`` per edge (end points excluded), shape (m, 2)."""
    t = (np.arange(n) + 0.5) / n
    return np.concatenate([_stack([np.asarray(x, dtype=float) for x in uvf(t)], axis=1) for uvf, _ in loop])


def _check_holes_inside(loops_uv: list[list[tuple[Callable, Callable]]], label: str) -> None:
    """Every hole loop must lie inside the outer loop in (u, v) (a face's holes do; a hole outside
    means inconsistent pcurves, e.g. one shifted by a period, and would be drawn outside the
    outline while the area stays right).

    Raises:
        DegenerateGeometryError: more than half of a hole's sample points lie outside the outer loop.
    """
    if len(loops_uv) < 2:
        return
    outer = _loop_points(loops_uv[0], 64)
    for k, loop in enumerate(loops_uv[1:], start=1):
        inside = _point_in_polygon(_loop_points(loop, 8), outer)
        if inside.mean() < 0.5:
            raise DegenerateGeometryError(
                f"face {label!r}: wire {k + 1} (a hole) lies outside the outer wire in the face's (u, v) "
                f"parameters ({inside.mean():.0%} of its points inside; allowed: holes inside the outer wire): "
                "the face's pcurves are inconsistent (one shifted by a period?); repair the face (e.g. "
                "Part > Check geometry, or re-import it) before unrolling"
            )


def _with_breaks(duv: Callable[[np.ndarray], np.ndarray], breaks: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    def f(t: np.ndarray) -> np.ndarray:
        return duv(t)

    f.breaks = np.asarray(breaks, dtype=float)  # type: ignore[attr-defined]
    return f
