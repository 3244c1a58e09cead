r"""Flat pattern (development) of a developable feature or of any developable face, with bend lines (spec 6).

The source is a developable feature of this workbench (its exact core ruled surface is unrolled
by :func:`ght_cad.unroll`, quadrature along the rulings) or any face of any FreeCAD object whose
surface is developable: the lateral face of a ``Part::Cylinder`` / ``Part::Cone`` (closed-form
maps), a plane, a surface of extrusion, a ruled B-spline or Bézier face (``Part::RuledSurface``,
re-imported STEP), trimmed or with holes. Faces go through the kernel-free
:func:`ght_cad.face_unroll.unroll_face_data` (the same code that unrolls build123d/OCP faces)
via the small adapter below (:func:`face_data`): FreeCAD's ``face.Surface`` (B-spline and
Bézier surfaces read into the core's :mod:`ght_cad.surfaces.nurbs`, others evaluated with
``value``/``getDN``), every wire (``OuterWire`` first) in ``OrderedEdges`` order with its pcurve
``face.curveOnSurface(edge)``, the edges' 3-D curves and lengths. The face's real outline and
holes are kept. Non-developable faces (sphere, torus, twisted loft) are refused with the
isolines' deviation or θ_max / DD unless ``BestEffort``.

Sheet metal (spec 6.1): with ``Thickness`` T > 0, ``KFactor`` K and ``Side`` (material along the
face/surface normal or against it) the pattern is the development of the neutral surface
``S ± K T n`` (:mod:`ght_cad.sheet`); with Thickness 0 and a face of a solid plate (a SheetMetal
base bend, ``Part::Thickness``, ``makeThickness``, a GHT Plate) the thickness, inside face and side
are read from the solid (:func:`plate_partner`; a GHT Plate, :mod:`.plate`, gives its inside face,
exact thickness and K-factor; as Source without a face it stands for its inside face). ``FormingTable`` lists each bend line's neutral bending
radius and angle; the DXF export carries them on layer FORMING.

Every boundary edge of the pattern is fitted as a planar B-spline edge (straight ones become
line segments) and the interior rulings become bend-line edges. The shape is a compound of the
planar face and the bend lines in the XY plane (move it with ``Placement``).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

import FreeCAD as App
import Part

from ght_cad.core.errors import GHTError
from ght_cad.face_unroll import (EdgeData, FaceData, SurfaceAdapter, analytic_jet, chain_loop, fd_derivative, jets_agree,
                                 surface_jet, unroll_face_data)
from ght_cad.surfaces.nurbs import NurbsCurve, NurbsSurface, expand_knots

from ._base import BaseCommand, FeatureProxy, ViewProviderBase, info_panel, new_feature, register_command, set_read_only
from .convert import edge_from_data

__all__ = [
    "FlatPatternFeature",
    "make_flat_pattern",
    "surface_of_source",
    "face_of_source",
    "face_data",
    "FreeCADSurface",
    "plate_partner",
]

#: the Side property's values (ght_cad.sheet.SIDES): material along / against the face normal
SIDES = ["normal", "reverse"]

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
    """A FreeCAD ``face.Surface`` as :class:`ght_cad.face_unroll.SurfaceAdapter`.

    ``kind`` from the surface's Python type, ``radius`` (``Radius``) and ``semi_angle``
    (``SemiAngle``) for cylinders and cones, ``ruled_hint`` for B-spline/Bézier surfaces of degree
    1 with 2 poles across. Non-periodic B-spline and Bézier surfaces are read once into the core's
    vectorized evaluator (:func:`read_surface`, :class:`ght_cad.surfaces.nurbs.NurbsSurface`) when it
    agrees with FreeCAD's ``value``/``getDN`` at four points to 1e-12 of the size (derivatives
    relative to their own size); planes, cylinders and cones are evaluated in numpy by OCCT's
    formulas (:func:`ght_cad.face_unroll.analytic_jet`) from their placement (``Center`` or
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
    (:func:`ght_cad.face_unroll.fd_derivative`: FreeCAD 0.20.2 has no pcurve derivative binding).
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
    """A FreeCAD face as :class:`ght_cad.face_unroll.FaceData` (the adapter of this workbench).

    Wires: ``face.OuterWire`` first, then the other wires of ``face.Wires`` (holes), each in
    ``OrderedEdges`` order, edges named ``edge<k>`` in wire order or ``edge_name(edge)`` (a solid's
    edge key, :mod:`.sheet_skin`); every edge's pcurve is traversed in its orientation and, on periodic
    surfaces, shifted by whole periods so each loop is continuous in (u, v)
    (:func:`ght_cad.face_unroll.chain_loop`) and lies in ``face.ParameterRange``.

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


def face_of_source(obj: Any) -> "Part.Face | None":
    """The face the flat pattern unrolls: the linked sub-element, the single face of the Source,
    or None when the Source is a developable feature of this workbench (its core surface is used).

    Raises:
        GHTError: no Source; a Source without faces; a sub-element that is not a face or no
            longer exists (the Source's topology changed); several faces and none selected.
    """
    src, subs = obj.Source if obj.Source else (None, [])
    if src is None:
        raise GHTError(f"{obj.Label}: no Source linked")
    subs = [s for s in (subs or []) if s]
    if not subs and hasattr(getattr(src, "Proxy", None), "surface"):
        return None
    if not subs and hasattr(getattr(src, "Proxy", None), "inside_face"):  # a GHT Plate: its inside face
        face = src.Proxy.inside_face(src)
        if face is None:
            raise GHTError(f"{src.Label} has no inside face yet (recompute it); allowed: a face ({src.Label}.FaceN) or a developable feature")
        return face
    faces = src.Shape.Faces
    if not faces:
        raise GHTError(f"{src.Label} has no faces to unroll; allowed: a face or a developable feature of this workbench")
    names = f"Face1..Face{len(faces)}"
    if subs:
        sub = subs[0]
        if not sub.startswith("Face"):
            raise GHTError(f"{src.Label}.{sub} is not a face; allowed: a face ({names})")
        k = sub[4:]
        if not k.isdigit() or not 1 <= int(k) <= len(faces):
            raise GHTError(f"{src.Label} has no {sub}; allowed: {names} (did the source's topology change? select the face again)")
        return faces[int(k) - 1]
    if len(faces) == 1:
        return faces[0]
    raise GHTError(f"{src.Label} has {len(faces)} faces; select one face ({names})")


def surface_of_source(obj: Any) -> Any:
    """Core ruled surface of a Source that is a developable feature of this workbench
    (``Source.Proxy.surface``).

    Raises:
        GHTError: the Source is a face, not a developable feature (see :func:`face_of_source`).
    """
    if face_of_source(obj) is not None:
        raise GHTError(f"{obj.Label}: the Source is a face, not a developable feature; use face_data(face)")
    return obj.Source[0].Proxy.surface(obj.Source[0])


def _planar_edge(f: Callable[[np.ndarray], np.ndarray], tol: float) -> "Part.Edge":
    """Edge of the planar curve ``f(t)`` (t ∈ [0, 1], 2-D points), exact end points."""
    from ght_cad.surfaces.bspline import fit_function

    p0, p1 = f(np.array([0.0]))[0], f(np.array([1.0]))[0]
    t = np.linspace(0.0, 1.0, 65)
    pts = f(t)
    chord = p1 - p0
    L = float(np.linalg.norm(chord))
    if L > 0:
        off = np.abs((pts[:, 0] - p0[0]) * chord[1] - (pts[:, 1] - p0[1]) * chord[0]) / L
        if float(off.max()) <= tol:
            return Part.LineSegment(App.Vector(p0[0], p0[1], 0), App.Vector(p1[0], p1[1], 0)).toShape()
    data = fit_function(f, tol=tol, degree=5, end_derivatives=([p0], [p1]))
    return edge_from_data(data)


def _grid_points(face: "Part.Face", n: int = 5) -> list[Any]:
    """Points of ``face`` on an n x n grid of its parameter range (5 %..95 %)."""
    u0, u1, v0, v1 = face.ParameterRange
    return [face.valueAt(u0 + a * (u1 - u0), v0 + b * (v1 - v0)) for a in np.linspace(0.05, 0.95, n) for b in np.linspace(0.05, 0.95, n)]


def plate_partner(shape: "Part.Shape", face: "Part.Face", rtol: float = 1e-6, inside: "Part.Face | None" = None) -> tuple["Part.Face", float, str] | None:
    r"""The plate a face belongs to (a SheetMetal-style or ``Part::Thickness`` solid, a GHT Plate).

    Among the other faces of ``shape`` with at least a quarter of the face's area, the first whose
    25 grid points lie at a constant distance (spread <= ``rtol`` x size) from the face's surface
    (``Surface.parameter`` projection) is the opposite face. The inside face is ``inside`` when it
    is one of the two (a GHT Plate knows its design face), else the smaller of the two (the
    concave side of a bend); the side is where the other face lies relative to the inside face's
    normal (``normalAt``, orientation included).

    Returns:
        ``(inside face, thickness, side)`` or None (no solid, or no opposite face).
    """
    if not shape.Solids:
        return None
    size = max(shape.BoundBox.DiagonalLength, 1e-300)
    for other in shape.Faces:
        if other.isSame(face) or other.Area < 0.25 * face.Area:
            continue
        if inside is not None and (inside.isSame(face) or inside.isSame(other)):
            inner, outer = (face, other) if inside.isSame(face) else (other, face)
        else:
            inner, outer = (face, other) if face.Area <= other.Area else (other, face)
        dist, signs = [], []
        for p in _grid_points(outer):
            try:
                u, v = inner.Surface.parameter(p)
            except Exception:  # noqa: BLE001 - no projection onto this surface
                break
            q = inner.Surface.value(u, v)
            dist.append((p - q).Length)
            signs.append(inner.normalAt(u, v).dot(p - q))
        if len(dist) < 25:
            continue
        T = float(np.mean(dist))
        if T > 1e-9 * size and float(np.ptp(dist)) <= rtol * size:
            return inner, T, ("normal" if float(np.median(signs)) > 0 else "reverse")
    return None


class FlatPatternFeature(FeatureProxy):
    """Proxy of a flat pattern (``Part::FeaturePython``)."""

    Type = "GHT::FlatPattern"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkSub", "Source", "Input", "A developable feature, or any developable face (plane, cylinder, cone, extrusion, ruled B-spline)")
        obj.addProperty("App::PropertyInteger", "BendLines", "Input", "Number of interior rulings drawn as bend lines")
        obj.BendLines = 8
        obj.addProperty("App::PropertyBool", "BestEffort", "Input", "Flatten even if the source is not developable (see MaxRelativeError)")
        obj.addProperty("App::PropertyFloat", "AreaFlat", "Output", "Area of the pattern")
        obj.addProperty("App::PropertyFloat", "Area3D", "Output", "Area of the 3-D surface")
        obj.addProperty("App::PropertyFloat", "MaxRelativeError", "Output", "Largest relative error of boundary lengths, ruling lengths and area (flat vs 3-D)")
        self.restored(obj)

    @staticmethod
    def _sheet_properties(obj: Any) -> None:
        """Sheet properties (added to documents saved before they existed)."""
        have = set(obj.PropertiesList)
        if "Thickness" not in have:
            obj.addProperty("App::PropertyLength", "Thickness", "Sheet", "Sheet thickness T (0: the surface itself, or read from the solid the face belongs to)")
        if "KFactor" not in have:
            obj.addProperty("App::PropertyFloat", "KFactor", "Sheet", "ANSI K-factor in [0, 1]: the neutral surface lies K*T from the inside face (DIN k = 2K)")
            obj.KFactor = 0.5
        if "Side" not in have:
            obj.addProperty("App::PropertyEnumeration", "Side", "Sheet", "Where the material lies: 'normal' (along the face/surface normal) or 'reverse' (against it)")
            obj.Side = SIDES
            obj.Side = "normal"
        if "ThicknessFromSolid" not in have:
            obj.addProperty("App::PropertyBool", "ThicknessFromSolid", "Sheet", "With Thickness 0 and a face of a solid plate: use the solid's thickness, inside face and side (a GHT Plate: also its KFactor)")
            obj.ThicknessFromSolid = True
        if "ThicknessUsed" not in have:
            obj.addProperty("App::PropertyFloat", "ThicknessUsed", "Output", "Sheet thickness the pattern was made with (0: none)")
        if "FormingTable" not in have:
            obj.addProperty("App::PropertyStringList", "FormingTable", "Output", "Bend lines: neutral bending radius at both ruling ends and angle turned")
        if "WholeSolid" not in have:  # documents saved before: a face as before
            obj.addProperty("App::PropertyBool", "WholeSolid", "Input", "Unfold the whole sheet solid of the Source into one blank (issue 23); a selected face is then the base face")
            obj.WholeSolid = False
        if "BendTable" not in have:
            obj.addProperty("App::PropertyStringList", "BendTable", "Output", "Whole solid: one row per bend (angle, inside radius, K, bend allowance, bend deduction, direction)")
            obj.addProperty("App::PropertyInteger", "BaseFaceUsed", "Output", "Whole solid: number of the face that kept its place (FaceN of the Source)")
            obj.addProperty("App::PropertyStringList", "CutEdges", "Output", "Whole solid: shared edges cut to open cycles of the face graph")

    def restored(self, obj: Any) -> None:
        self._sheet_properties(obj)
        set_read_only(obj, ("AreaFlat", "Area3D", "MaxRelativeError", "ThicknessUsed", "FormingTable", "BendTable",
                            "BaseFaceUsed", "CutEdges"))

    def sheet(self, obj: Any, face: Any) -> tuple[Any, Any]:
        """``(sheet or None, face to unroll)``: the Thickness/KFactor/Side properties, or with
        Thickness 0 the plate the face belongs to (:func:`plate_partner`: its inside face,
        thickness and side).

        Raises:
            SheetError: a bad K-factor or a thickness beyond a bending radius (naming the value).
        """
        from ght_cad.sheet import Sheet

        T = float(obj.Thickness.Value) if hasattr(obj.Thickness, "Value") else float(obj.Thickness)
        K = float(obj.KFactor)
        if T > 0:
            return Sheet(T, K, str(obj.Side)), face
        if face is not None and bool(obj.ThicknessFromSolid):
            src = obj.Source[0]
            proxy = getattr(src, "Proxy", None)
            is_plate = hasattr(proxy, "inside_face")  # a GHT Plate: its design face and K-factor
            found = plate_partner(src.Shape, face, inside=proxy.inside_face(src) if is_plate else None)
            if found is not None:
                inner, thickness, side = found
                if is_plate:  # the plate's exact T and K; its faces are fitted within 3e-7 T each
                    exact = float(src.Thickness.Value)
                    if not abs(thickness - exact) <= 1e-6 * exact:
                        raise GHTError(f"{obj.Label}: the faces of {src.Label} are {thickness!r} apart, not its Thickness {exact!r}; recompute {src.Label}")
                    return Sheet(exact, float(src.KFactor), side), inner
                return Sheet(thickness, K, side), inner
        Sheet(0.0, K, str(obj.Side))  # validates K and Side even without a thickness
        return None, face

    def pattern(self, obj: Any) -> Any:
        """The core :class:`ght_cad.flat_pattern.FlatPattern` of the source."""
        from ght_cad import unroll

        if int(obj.BendLines) < 0:
            raise GHTError(f"{obj.Label}: BendLines={int(obj.BendLines)} is not allowed; allowed: 0 or more bend lines")
        opts = dict(rulings=int(obj.BendLines), best_effort=bool(obj.BestEffort), samples=65)
        self._sheet_properties(obj)
        if bool(obj.WholeSolid):
            return self.blank(obj).pattern
        face = face_of_source(obj)
        sheet, face = self.sheet(obj, face)
        if face is None:
            return unroll(surface_of_source(obj), sheet=sheet, **opts)
        src, subs = obj.Source
        label = src.Label + "".join(f".{x}" for x in (subs or [])[:1] if x)
        return unroll_face_data(face_data(face), label=label, sheet=sheet, **opts)

    def blank(self, obj: Any) -> Any:
        """The whole Source solid unfolded into one blank per sheet solid
        (:func:`ght_cad.blank.unfold_skins` on the skins :func:`.sheet_skin.sheet_skins` finds):
        bends on their neutral surface at ``KFactor``, the selected face (if any) as base face.

        Raises:
            BlankError: no sheet, a sharp edge, an ambiguous skin, overlapping pieces, a bad face.
        """
        from ght_cad.blank import BlankError, unfold_skins

        from .sheet_skin import shape_of_source, sheet_skins

        src, subs = obj.Source if obj.Source else (None, [])
        if src is None:
            raise GHTError(f"{obj.Label}: no Source linked")
        base = None
        subs = [x for x in (subs or []) if x]
        if subs:
            if not (subs[0].startswith("Face") and subs[0][4:].isdigit()):
                raise BlankError(f"{src.Label}.{subs[0]} is not a face; allowed: a face (FaceN) as base face, or none")
            base = int(subs[0][4:])
        K = float(obj.KFactor)
        if not (0.0 <= K <= 1.0):
            raise BlankError(f"{obj.Label}: KFactor={K!r} is not allowed; the ANSI K-factor lies in [0, 1]")
        skins, n = sheet_skins(shape_of_source(src), base_face=base, name=str(src.Label))
        out = unfold_skins(skins, k_factor=K, base_face=base, rulings=int(obj.BendLines), face_count=n)
        self._blanks = out
        return out

    def compute(self, obj: Any) -> None:
        self._blanks = None
        pat = self.pattern(obj)
        lo = np.min([p.bbox()[0] for p in pat.panels], axis=0)
        hi = np.max([p.bbox()[1] for p in pat.panels], axis=0)
        tol = 1e-9 * max(float(np.linalg.norm(hi - lo)), 1e-300)
        faces = []
        for panel in pat.panels:
            wires = []
            for loop in panel.loops:
                edges = [
                    _planar_edge(lambda t, e=e, off=panel.offset: np.asarray(e.flat_fn(t), float) + off, tol)
                    for e in loop
                    if np.ptp(e.flat, axis=0).max() > tol  # a degenerate edge (cone apex) is a point
                ]
                wires.append(Part.Wire(edges))
            face = Part.Face(wires[0])
            if len(wires) > 1:
                face = Part.Face(wires[0]).cut(Part.makeCompound([Part.Face(w) for w in wires[1:]])).Faces[0]
            faces.append(face)
        bends = [
            Part.LineSegment(App.Vector(p[0], p[1], 0), App.Vector(q[0], q[1], 0)).toShape()
            for p, q in np.asarray(pat.bend_lines).reshape(-1, 2, 2)
        ]
        obj.AreaFlat = float(pat.area)
        obj.Area3D = float(sum(p.area_3d for p in pat.panels))
        obj.MaxRelativeError = float(pat.errors["max"])
        sh = pat.sheet
        obj.ThicknessUsed = float(sh["thickness"]) if sh else 0.0
        obj.FormingTable = pat.forming_table().splitlines() if sh else []
        blanks = getattr(self, "_blanks", None)
        if blanks is not None:  # whole solid: the bend table and what the walk did
            obj.ThicknessUsed = float(blanks.blanks[0].thickness)
            obj.BendTable = blanks.bend_table().splitlines()
            obj.BaseFaceUsed = int(blanks.blanks[0].base_face)
            obj.CutEdges = [e for b in blanks.blanks for e in b.cut_edges]
        else:
            obj.BendTable, obj.BaseFaceUsed, obj.CutEdges = [], 0, []
        obj.Shape = Part.makeCompound(faces + bends)


class ViewProviderFlatPattern(ViewProviderBase):
    icon_name = "GHT_FlatPattern"
    shape_color = (0.91, 0.85, 0.66)
    line_color = (0.7, 0.1, 0.1)
    panel_factory = staticmethod(lambda obj: info_panel(obj, ("Source",), "Edit Source and BendLines in the property "
                                                       "editor; export with Export flat pattern DXF / SVG."))


def make_flat_pattern(
    source: Any,
    sub: str = "",
    bend_lines: int = 8,
    *,
    doc: Any = None,
    name: str = "FlatPattern",
    thickness: float = 0.0,
    k_factor: float = 0.5,
    side: str = "normal",
    whole_solid: bool | None = None,
) -> Any:
    """Create the flat pattern of a developable feature (or of its face ``sub``); with a
    ``thickness`` (or a face of a solid plate) the pattern is the sheet's neutral surface.

    ``whole_solid``: unfold the whole sheet solid into one blank, ``sub`` (if given) its base face;
    None: True for a Source with a solid, no face given and no surface of its own (a Part
    feature, a PartDesign Body, an imported STEP), else False."""
    if whole_solid is None:
        proxy = getattr(source, "Proxy", None)
        own = hasattr(proxy, "surface") or hasattr(proxy, "inside_face")
        shape = getattr(source, "Shape", None)
        whole_solid = not sub and not own and shape is not None and bool(shape.Solids)
    obj = new_feature(doc or source.Document, name, FlatPatternFeature, ViewProviderFlatPattern)
    obj.WholeSolid = bool(whole_solid)
    obj.Source = (source, [sub] if sub else [])
    obj.BendLines = int(bend_lines)
    obj.Thickness = float(thickness)
    obj.KFactor = float(k_factor)
    obj.Side = side
    obj.Document.recompute()
    # lay the pattern beside its source (XY plane, to the +x side); later recomputes keep it
    src, flat = source.Shape.BoundBox, obj.Shape.BoundBox
    if src.isValid() and flat.isValid():
        gap = 0.2 * max(src.DiagonalLength, flat.DiagonalLength)
        obj.Placement = App.Placement(App.Vector(src.XMax + gap - flat.XMin, src.YMin - flat.YMin, 0), App.Rotation())
        obj.Document.recompute()  # the Placement touched it: returned up to date, as every make_*
    return obj


class CommandFlatPattern(BaseCommand):
    name = "GHT_FlatPattern"
    icon_name = "GHT_FlatPattern"
    menu_text = "Flat pattern"
    tooltip = (
        "Unroll the selected developable feature or developable face (cylinder, cone, plane, "
        "extrusion, ruled B-spline; trimmed outline and holes kept) into a planar face with bend "
        "lines (closed forms or exact quadrature along the rulings); errors vs 3-D in MaxRelativeError."
    )

    def IsActive(self) -> bool:
        import FreeCADGui as Gui

        return App.ActiveDocument is not None and bool(Gui.Selection.getSelection())

    def Activated(self) -> None:
        import FreeCADGui as Gui

        sel = Gui.Selection.getSelectionEx()[0]
        faces = [s for s in sel.SubElementNames if s.startswith("Face")]
        doc = App.ActiveDocument
        doc.openTransaction("Flat pattern")
        make_flat_pattern(sel.Object, faces[0] if faces else "", doc=doc)
        doc.commitTransaction()


register_command(CommandFlatPattern())
