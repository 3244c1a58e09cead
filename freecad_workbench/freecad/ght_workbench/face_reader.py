r"""FreeCAD faces as the core's face data (:class:`ght_cad.unrolling.face_unroll.FaceData`): the reader shared by
the Flat pattern feature (:mod:`.flat_pattern`) and the sheet-skin reader (:mod:`.sheet_skin`).

FreeCAD's ``face.Surface`` (B-spline and Bézier surfaces read into the core's :mod:`ght_cad.surfaces.nurbs`,
planes, cylinders and cones by the core's closed forms, others evaluated with ``value``/``getDN``),
every wire (``OuterWire`` first) in ``OrderedEdges`` order with its pcurve
``face.curveOnSurface(edge)``, the edges' 3-D curves and lengths (:func:`face_data`).

Moved from :mod:`.flat_pattern` (issue 27) so that :mod:`.sheet_skin` no longer imports the Flat
pattern feature, which uses :func:`.sheet_skin.sheet_skins` (the import cycle flat_pattern <->
sheet_skin). :mod:`.flat_pattern` imports every name back (``flat_pattern.face_data``,
``flat_pattern.FreeCADSurface`` ... still work).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

import FreeCAD as App
import Part

from ght_cad.core.errors import GHTError
from ght_cad.unrolling.face_unroll import (EdgeData, FaceData, SurfaceAdapter, analytic_jet, chain_loop, fd_derivative, jets_agree,
                                 surface_jet)
from ght_cad.surfaces.nurbs import NurbsCurve, NurbsSurface, expand_knots

__all__ = ["face_data", "FreeCADSurface", "read_surface", "read_curve"]

_KINDS = {
    "Plane": "plane",
    "Cylinder": "cylinder",
    "Cone": "cone",
    "SurfaceOfExtrusion": "extrusion",
    "BSplineSurface": "bspline",
    "BezierSurface": "bezier",
}


def _vec(v: Any, dim: int) -> tuple[float, ...]:
    """A FreeCAD ``Vector`` / ``Vector2d`` as a tuple of ``dim`` floats."""
    return (float(v.x), float(v.y)) if dim == 2 else (float(v.x), float(v.y), float(v.z))


def read_surface(s: Any) -> NurbsSurface | None:
    """The core evaluator (:class:`ght_cad.surfaces.nurbs.NurbsSurface`) of a ``Part.BSplineSurface`` or
    ``Part.BezierSurface``, read once: poles (``getPoles``, rows along u), weights (``getWeights``,
    only when ``isURational``/``isVRational``), flat knot vectors from ``getUKnots`` /
    ``getUMultiplicities`` (v likewise), degrees. None for other surfaces, periodic B-splines (left
    to FreeCAD's own evaluation) or data the core refuses."""
    name = type(s).__name__
    try:
        if name == "BSplineSurface":
            if s.isUPeriodic() or s.isVPeriodic():
                return None
            U = expand_knots(s.getUKnots(), s.getUMultiplicities())
            V = expand_knots(s.getVKnots(), s.getVMultiplicities())
        elif name == "BezierSurface":
            U = np.r_[np.zeros(s.UDegree + 1), np.ones(s.UDegree + 1)]
            V = np.r_[np.zeros(s.VDegree + 1), np.ones(s.VDegree + 1)]
        else:
            return None
        poles = np.array([[_vec(q, 3) for q in row] for row in s.getPoles()], dtype=float)
        weights = np.array(s.getWeights(), dtype=float) if (s.isURational() or s.isVRational()) else None
        return NurbsSurface.from_poles(U, V, int(s.UDegree), int(s.VDegree), poles, weights)
    except GHTError:
        return None


class _CurveEval:
    """Numpy evaluation of a FreeCAD curve read once: ``kind`` ("line", "circle", "bspline"),
    ``value(p)`` and the exact ``derivative(p)``, each (n, dim)."""

    def __init__(self, kind: str, value: Callable[[np.ndarray], np.ndarray], derivative: Callable[[np.ndarray], np.ndarray]) -> None:
        self.kind, self.value, self.derivative = kind, value, derivative


def read_curve(c: Any, dim: int, p0: float, p1: float) -> _CurveEval | None:
    r"""Numpy evaluation of a FreeCAD 2-D pcurve (``Geom2d``) or 3-D curve, checked against its own
    ``value`` at five parameters of ``[p0, p1]`` (1e-12 of the curve's size; None when it disagrees,
    then the caller evaluates point by point).

    Lines (``Line2d``/``Line``: ``P + p D`` from ``Location``/``Direction``; a ``Line2dSegment`` /
    ``LineSegment``: affine through its values at p0 and p1), circles and arcs (``O + R (cos p X +
    sin p Y)`` from ``Location``/``Center``, ``Radius``, ``XAxis``, ``YAxis``), B-splines and
    Béziers (:class:`ght_cad.surfaces.nurbs.NurbsCurve` from ``getPoles``, ``getWeights``,
    ``getKnots``/``getMultiplicities``, ``Degree``; a periodic B-spline, e.g. a drilled hole's
    pcurve, from a ``setNotPeriodic`` copy: the same curve on clamped knots, checked like the
    others), with exact first derivatives. Other kinds: None.
    """
    name = type(c).__name__.replace("2d", "")
    try:
        if name == "Line":
            P, D = np.array(_vec(c.Location, dim)), np.array(_vec(c.Direction, dim))
            out = _CurveEval("line", lambda p: P + p[:, None] * D, lambda p: np.broadcast_to(D, (p.size, dim)).copy())
        elif name == "LineSegment" and p1 != p0:
            A, B = np.array(_vec(c.value(p0), dim)), np.array(_vec(c.value(p1), dim))
            D = (B - A) / (p1 - p0)
            out = _CurveEval("line", lambda p: A + (p - p0)[:, None] * D, lambda p: np.broadcast_to(D, (p.size, dim)).copy())
        elif name in ("Circle", "ArcOfCircle"):
            O = np.array(_vec(c.Location if dim == 2 else c.Center, dim))
            X, Y, R = np.array(_vec(c.XAxis, dim)), np.array(_vec(c.YAxis, dim)), float(c.Radius)
            X, Y = X / np.linalg.norm(X), Y / np.linalg.norm(Y)
            out = _CurveEval("circle",
                             lambda p: O + R * (np.cos(p)[:, None] * X + np.sin(p)[:, None] * Y),
                             lambda p: R * (np.cos(p)[:, None] * Y - np.sin(p)[:, None] * X))
        elif name in ("BSplineCurve", "BezierCurve"):
            if name == "BSplineCurve":
                if c.isPeriodic():  # the same curve on clamped knots, same parameters (OCCT SetNotPeriodic)
                    c = c.copy()
                    c.setNotPeriodic()
                U = expand_knots(c.getKnots(), c.getMultiplicities())
            else:
                U = np.r_[np.zeros(c.Degree + 1), np.ones(c.Degree + 1)]
            poles = np.array([_vec(q, dim) for q in c.getPoles()], dtype=float)
            weights = np.array(c.getWeights(), dtype=float) if c.isRational() else None
            nc = NurbsCurve.from_poles(U, int(c.Degree), poles, weights)
            out = _CurveEval("bspline", nc.value, nc.derivative)
        else:
            return None
    except (GHTError, AttributeError):
        return None
    ps = np.linspace(p0, p1, 5)
    theirs = np.array([_vec(c.value(x), dim) for x in ps.tolist()], dtype=float)
    scale = max(1.0, float(np.abs(theirs).max()), float(getattr(c, "Radius", 0.0) or 0.0))
    if not float(np.abs(out.value(ps) - theirs).max()) <= 1e-12 * scale:
        return None
    return out


def _placement(s: Any, kind: str) -> tuple[np.ndarray, ...] | None:
    """``(O, X, Y, Z)`` of a FreeCAD plane, cylinder or cone: origin ``Position`` (plane) or
    ``Center``, axes the columns of its ``Rotation`` (None when FreeCAD does not give them)."""
    try:
        O = s.Position if kind == "plane" else s.Center
        rot = s.Rotation
        axes = [rot.multVec(App.Vector(*e)) for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1))]
    except Exception:  # pragma: no cover - a FreeCAD without these attributes: evaluate by FreeCAD
        return None
    return tuple(np.array([float(p.x), float(p.y), float(p.z)]) for p in [O, *axes])


class FreeCADSurface(SurfaceAdapter):
    """A FreeCAD ``face.Surface`` as :class:`ght_cad.unrolling.face_unroll.SurfaceAdapter`.

    ``kind`` from the surface's Python type, ``radius`` (``Radius``) and ``semi_angle``
    (``SemiAngle``) for cylinders and cones, ``ruled_hint`` for B-spline/Bézier surfaces of degree
    1 with 2 poles across. Non-periodic B-spline and Bézier surfaces are read once into the core's
    vectorized evaluator (:func:`read_surface`, :class:`ght_cad.surfaces.nurbs.NurbsSurface`) when it
    agrees with FreeCAD's ``value``/``getDN`` at four points to 1e-12 of the size (derivatives
    relative to their own size); planes, cylinders and cones are evaluated in numpy by OCCT's
    formulas (:func:`ght_cad.unrolling.face_unroll.analytic_jet`) from their placement (``Center`` or
    ``Position``, ``Rotation``), after the same agreement check. ``path`` says which evaluation is
    used: ``"nurbs"``, ``"analytic"`` or ``"freecad"`` (points by ``value(u, v)`` and partials by
    ``getDN(u, v, i, j)`` one by one; location included: ``face.Surface`` is already placed).
    ``fast=False`` forces the latter.
    """

    def __init__(self, face: "Part.Face", fast: bool = True) -> None:
        s = face.Surface
        self.s = s
        self.type_name = type(s).__name__
        self.kind = _KINDS.get(self.type_name, "other")
        self._nurbs: NurbsSurface | None = None
        self._ax: tuple[np.ndarray, ...] | None = None
        self.path = "freecad"
        if self.kind in ("cylinder", "cone"):
            self.radius = float(s.Radius)
        if self.kind == "cone":
            self.semi_angle = float(s.SemiAngle)
        if self.kind in ("bspline", "bezier"):
            if s.VDegree == 1 and s.NbVPoles == 2:
                self.ruled_hint = "v"
            elif s.UDegree == 1 and s.NbUPoles == 2:
                self.ruled_hint = "u"
            if self.ruled_hint is not None:  # equal weights across the rulings: affine along them
                w = np.asarray(s.getWeights(), dtype=float)
                self.affine_ruled = bool(np.all(w[:, 0] == w[:, 1]) if self.ruled_hint == "v" else np.all(w[0] == w[1]))
            if fast:
                nurbs = read_surface(s)
                if nurbs is not None and self._agrees(nurbs):
                    self._nurbs, self.path = nurbs, "nurbs"
        elif self.kind == "extrusion":
            self.affine_ruled = True  # C(u) + v D
        if fast and self.kind in ("plane", "cylinder", "cone"):
            ax = _placement(s, self.kind)
            if ax is not None and self._agrees_analytic(ax):
                self._ax, self.path = ax, "analytic"

    def _agrees_analytic(self, ax: tuple[np.ndarray, ...]) -> bool:
        """The closed form from ``ax`` matches FreeCAD's ``value`` and ``getDN`` (first and second
        partials) at four points to 1e-12 of their size (radius included in the size)."""
        uu = np.array([0.0, 1.3, 2.9, 5.1])
        vv = np.array([0.0, 0.7, -1.9, 3.4])
        ours = analytic_jet(self.kind, ax, self.radius, self.semi_angle, uu, vv, 2)
        theirs = [self._value_fc(uu, vv)] + self._dn(uu, vv, ((1, 0), (0, 1), (2, 0), (0, 2), (1, 1)))
        return jets_agree(ours, theirs, max(1.0, self.radius))

    def _agrees(self, nurbs: NurbsSurface) -> bool:
        """``nurbs`` matches FreeCAD's ``value`` and ``getDN`` (first partials) at four points of
        its knot box to 1e-12 of their size (as the OCP adapter's check)."""
        u0, u1, v0, v1 = nurbs.bounds
        uu = np.array([u0, 0.5 * (u0 + u1), 0.3 * u0 + 0.7 * u1, u1])
        vv = np.array([v0, 0.6 * v0 + 0.4 * v1, v1, 0.2 * v0 + 0.8 * v1])
        theirs = [self._value_fc(uu, vv)] + self._dn(uu, vv, ((1, 0), (0, 1)))
        return jets_agree(nurbs.eval(uu, vv, 1), theirs)

    def _value_fc(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        val = self.s.value
        out = [tuple(val(a, b)) for a, b in zip(np.ravel(u).tolist(), np.ravel(v).tolist())]
        return np.array(out, dtype=float).reshape(-1, 3)

    def _analytic(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        return analytic_jet(self.kind, self._ax, self.radius, self.semi_angle, u, v, order)  # type: ignore[arg-type]

    def value(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self._ax is not None:
            return self._analytic(u, v, 0)[0]
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, 0)[0]
        return self._value_fc(u, v)

    def _dn(self, u: np.ndarray, v: np.ndarray, orders: tuple) -> list[np.ndarray]:
        dn = self.s.getDN
        uu, vv = np.ravel(u).tolist(), np.ravel(v).tolist()
        return [np.array([tuple(dn(a, b, i, j)) for a, b in zip(uu, vv)], dtype=float).reshape(-1, 3) for i, j in orders]

    def d1(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        if self._ax is not None:
            return self._analytic(u, v, 1)[1:3]
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, 1)[1:3]
        return self._dn(u, v, ((1, 0), (0, 1)))

    def d2(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        if self._ax is not None:
            return self._analytic(u, v, 2)
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, 2)
        return [self.value(u, v)] + self._dn(u, v, ((1, 0), (0, 1), (2, 0), (0, 2), (1, 1)))

    def jet(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """``[S]``, ``[S, S_u, S_v]`` or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` (order 0, 1, 2) in one pass."""
        if self._ax is not None:
            return self._analytic(u, v, order)[: (1, 3, 6)[min(order, 2)]]
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, min(order, 2))
        return surface_jet(self, u, v, order, own=False)

    @property
    def fast_density_grid(self) -> bool:
        """:meth:`density_grid` works on the tensor grid (a B-spline read into the core), not point
        by point: the core's face area then puts whole pieces on grids."""
        return self._nurbs is not None and self._nurbs.patches is not None

    def density_grid(self, s: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``|S_u × S_v|`` at every (s_i, v_j), shape (len(s), len(v)) (a B-spline read into the core:
        each basis series evaluated once per s and once per v)."""
        s, v = np.asarray(s, dtype=float), np.asarray(v, dtype=float)
        if self._nurbs is not None:
            r = self._nurbs.density_grid(s, v)
            if r is not None:
                return r
        d = self.d1(np.repeat(s, v.size), np.tile(v, s.size))
        return np.linalg.norm(np.cross(d[0], d[1]), axis=1).reshape(s.size, v.size)

    def c0_breaks(self, direction: str) -> np.ndarray:
        return self._nurbs.c0_knots(direction) if self._nurbs is not None else np.zeros(0)

    def breaks(self, direction: str) -> np.ndarray:
        s = self.s
        if self.kind == "bspline":
            return np.asarray(s.getUKnots() if direction == "u" else s.getVKnots(), dtype=float)
        if self.kind == "extrusion" and direction == "u" and hasattr(s.BasisCurve, "getKnots"):
            return np.asarray(s.BasisCurve.getKnots(), dtype=float)
        if self.type_name == "SurfaceOfRevolution" and direction == "v" and hasattr(s.BasisCurve, "getKnots"):
            return np.asarray(s.BasisCurve.getKnots(), dtype=float)
        return np.zeros(0)

    def periods(self) -> tuple[float, float]:
        """(P_u, P_v), 0 for a non-periodic direction."""
        s = self.s
        return (float(s.UPeriod()) if s.isUPeriodic() else 0.0, float(s.VPeriod()) if s.isVPeriodic() else 0.0)


class _Edge:
    """One edge of a FreeCAD face: its pcurve ``face.curveOnSurface(edge)`` and 3-D curve, both as
    functions of t ∈ [0, 1] (``reverse``: from the last parameter to the first), ``shift`` added
    to (u, v) (a seam's other pcurve lies a period away).

    Lines, circles and B-splines/Béziers (pcurve and 3-D ``edge.Curve``) are
    evaluated in numpy (:func:`read_curve`) with exact pcurve derivatives; ``paths`` says which
    (``{"pcurve": "line" | "circle" | "bspline" | "freecad", "curve3d": ...}``). Other curves (and
    ``fast=False``): point by point, pcurve derivatives by finite differences between knots
    (:func:`ght_cad.unrolling.face_unroll.fd_derivative`: FreeCAD 0.20.2 has no pcurve derivative binding).
    """

    def __init__(self, face: "Part.Face", edge: "Part.Edge", surface: FreeCADSurface, fast: bool = True) -> None:
        cs = face.curveOnSurface(edge)
        if not cs:
            raise GHTError("an edge of the face has no curve on its surface (pcurve); cannot unroll it")
        self.c2, p0, p1 = cs[0], float(cs[1]), float(cs[2])
        self.p = (p0, p1)
        self.degenerated = bool(edge.Degenerated)
        self.edge, self.surface = edge, surface
        self.q = tuple(float(x) for x in edge.ParameterRange)
        self.reverse = edge.Orientation == "Reversed"
        self.shift = np.zeros(2)
        knots = np.asarray(self.c2.getKnots(), dtype=float) if hasattr(self.c2, "getKnots") else np.zeros(0)
        tb = (knots - p0) / (p1 - p0) if p1 != p0 else np.zeros(0)
        self._knots_t = np.sort(tb[(tb > 1e-12) & (tb < 1 - 1e-12)])
        self._f2 = read_curve(self.c2, 2, p0, p1) if fast else None
        self._f3: list[Any] = [] if fast and not self.degenerated else [None]  # read on first use
        self.paths = {"pcurve": self._f2.kind if self._f2 is not None else "freecad", "curve3d": "freecad"}

    def _par(self, t: np.ndarray, rng: tuple) -> np.ndarray:
        a, b = (rng[1], rng[0]) if self.reverse else rng
        return a + np.asarray(t, dtype=float) * (b - a)

    def ends(self) -> tuple[np.ndarray, np.ndarray]:
        u, v = self.uv(np.array([0.0, 1.0]))
        return np.array([u[0], v[0]]), np.array([u[1], v[1]])

    def uv(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = np.ravel(self._par(t, self.p))
        if self._f2 is not None:
            pts = self._f2.value(p)
        else:
            val = self.c2.value
            pts = np.array([(q.x, q.y) for q in (val(x) for x in p.tolist())], dtype=float).reshape(-1, 2)
        return pts[:, 0] + self.shift[0], pts[:, 1] + self.shift[1]

    def duv(self, t: np.ndarray) -> np.ndarray:
        if self._f2 is not None:
            a, b = (self.p[1], self.p[0]) if self.reverse else self.p
            return self._f2.derivative(np.ravel(self._par(t, self.p))) * (b - a)
        return fd_derivative(lambda x: np.stack(self.uv(x), axis=1), t, self.breaks())

    def breaks(self) -> np.ndarray:
        return np.sort(1.0 - self._knots_t) if self.reverse else self._knots_t

    def xyz(self, t: np.ndarray) -> np.ndarray:
        if self.degenerated:  # no 3-D curve (a cone apex): the surface point of the pcurve
            return self.surface.value(*self.uv(t))
        if not self._f3:
            f3 = read_curve(self.edge.Curve, 3, *self.q)
            if f3 is not None and not self._agrees_edge(f3):
                f3 = None
            self._f3.append(f3)
            self.paths["curve3d"] = f3.kind if f3 is not None else "freecad"
        q = np.ravel(self._par(t, self.q))
        if self._f3[0] is not None:
            return self._f3[0].value(q)
        at = self.edge.valueAt
        return np.array([tuple(at(x)) for x in q.tolist()], dtype=float).reshape(-1, 3)

    def _agrees_edge(self, f3: _CurveEval) -> bool:
        """The curve as read matches ``edge.valueAt`` (the edge's placement included) at three parameters."""
        qs = np.linspace(self.q[0], self.q[1], 3)
        theirs = np.array([tuple(self.edge.valueAt(x)) for x in qs.tolist()], dtype=float)
        return float(np.abs(f3.value(qs) - theirs).max()) <= 1e-12 * max(1.0, float(np.abs(theirs).max()))

    def length(self) -> float:
        if self.degenerated:
            return 0.0
        q0, q1 = self.q
        try:  # adaptive Gauss (GCPnts_AbscissaPoint) with a tight tolerance; edge.Length uses 1e-7
            return abs(float(self.edge.Curve.length(q0, q1, 1e-13)))
        except Exception:  # noqa: BLE001 - curves without a length() binding
            return float(self.edge.Length)


def face_data(face: "Part.Face", fast: bool = True, edge_name: Callable[[Any], str] | None = None) -> FaceData:
    """A FreeCAD face as :class:`ght_cad.unrolling.face_unroll.FaceData` (the adapter of this workbench).

    Wires: ``face.OuterWire`` first, then the other wires of ``face.Wires`` (holes), each in
    ``OrderedEdges`` order, edges named ``edge<k>`` in wire order or ``edge_name(edge)`` (a solid's
    edge key, :mod:`.sheet_skin`); every edge's pcurve is traversed in its orientation and, on periodic
    surfaces, shifted by whole periods so each loop is continuous in (u, v)
    (:func:`ght_cad.unrolling.face_unroll.chain_loop`) and lies in ``face.ParameterRange``.

    Raises:
        GHTError: an edge without a pcurve.
    """
    surf = FreeCADSurface(face, fast)
    u0, u1, v0, v1 = (float(x) for x in face.ParameterRange)
    periods = surf.periods()
    # matching tolerance per direction, relative to that direction's range: u of a cylinder is an
    # angle, v a length (one tolerance of 1e-6 of the larger range was 6 rad on a 6e6 mm cylinder)
    tol = 1e-6 * np.array([max(abs(u1 - u0), periods[0]) or 1.0, max(abs(v1 - v0), periods[1]) or 1.0])
    outer = face.OuterWire
    wires = [outer] + [w for w in face.Wires if not w.isSame(outer)]
    loops = []
    for w in wires:
        edges = [_Edge(face, e, surf, fast) for e in w.OrderedEdges]
        if not edges:
            continue
        for e, (rev, shift) in zip(edges, chain_loop([e.ends() for e in edges], periods, tol)):
            if rev:
                e.reverse = not e.reverse
            e.shift = np.asarray(shift, dtype=float)
        # the whole loop into the face's parameter range (periodic directions)
        pts = np.concatenate([np.stack(e.uv(np.linspace(0.0, 1.0, 5)), axis=1) for e in edges])
        for i, (lo, P) in enumerate(((u0, periods[0]), (v0, periods[1]))):
            if P > 0:
                k = np.floor((pts[:, i].min() - lo + tol[i]) / P)
                for e in edges:
                    e.shift[i] -= k * P
        loops.append(
            [EdgeData(uv=e.uv, duv=e.duv, xyz=e.xyz, length_3d=e.length(), breaks=e.breaks(),
                      name=f"edge{k}" if edge_name is None else edge_name(e.edge)) for k, e in enumerate(edges)]
        )
    return FaceData(surface=surf, bounds=(u0, u1, v0, v1), wires=loops, reversed=face.Orientation == "Reversed")
