r"""Unroll build123d / cadquery / OCP faces (planes, cylinders, cones, extrusions, ruled B-splines).

Development maps ``F(u, v)`` from the face's own parameters to the plane:

* plane: ``F(u, v) = (u, v)`` (gp_Pln parameters are orthonormal coordinates);
* cylinder of radius R: ``F(u, v) = (R u, v)``;
* cone with reference radius R and semi-angle α, ``s = sin α``: the slant distance from the apex
  is ``ρ(v) = R/s + v`` and ``F(u, v) = ρ(v) (cos(s u), sin(s u))`` (annular sector of angle
  ``s Δu``: for a full cone ``2π r / ρ``);
* every other face whose isolines in one parameter direction are straight (surface of linear
  extrusion, B-spline/Bézier of degree 1 in one direction, ...): a
  :class:`FaceRuledSurface` ``a(t) = S(u(t), v0)``, ``b(t) = S(u(t), v1)`` with derivatives from
  OCCT ``D2``, developed by quadrature along the rulings (:class:`ght_cad.unroll.RuledDevelopment`);
  a point ``S(u, v)`` maps to ``A(t) + s |g| D(t)`` where ``s`` is its projection onto the ruling.

Holes and trimmed boundaries are kept: every wire of the face is traversed in order
(``BRepTools_WireExplorer``), each edge's pcurve ``(u(p), v(p))`` is sampled and mapped through
``F``; 3-D reference lengths come from the edges' own 3-D curves (``GCPnts_AbscissaPoint``) and the
3-D area by Green's theorem in (u, v) with Gauss–Legendre quadrature (:func:`face_area`;
OCCT's ``BRepGProp`` is only ~1e-8 accurate on extrusions).

This module is the OCP adapter of the kernel-free implementation :mod:`ght_cad.unrolling.face_unroll`
(shared with the FreeCAD workbench): it describes a ``TopoDS_Face`` as a
:class:`ght_cad.unrolling.face_unroll.FaceData` (surface evaluator from ``BRepAdaptor_Surface``, pcurves
from ``BRepAdaptor_Curve2d``, 3-D lengths from ``GCPnts_AbscissaPoint``).
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d, BRepAdaptor_Surface
from OCP.BRepTools import BRepTools, BRepTools_WireExplorer
from OCP.GCPnts import GCPnts_AbscissaPoint
from OCP.GeomAbs import (
    GeomAbs_BezierCurve,
    GeomAbs_BezierSurface,
    GeomAbs_BSplineCurve,
    GeomAbs_BSplineSurface,
    GeomAbs_Circle,
    GeomAbs_CN,
    GeomAbs_Cone,
    GeomAbs_Cylinder,
    GeomAbs_Line,
    GeomAbs_Plane,
    GeomAbs_SurfaceOfExtrusion,
)
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d
from ._ocp import TColStd_Array1OfReal
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape
from ._ocp import TopoDS

from ..unrolling import face_unroll as _core
from ..core.errors import GHTError
from ..unrolling.face_unroll import EdgeData, FaceData, SurfaceAdapter, face_area, unroll_face_data
from ..pattern.flat_pattern import FlatPattern
from ..surfaces.nurbs import NurbsCurve, NurbsSurface
from ..unrolling.unroll import DEFAULT_TOL_DEG

__all__ = ["unroll_face", "FaceRuledSurface", "flat_faces", "face_ruling_direction", "face_area", "face_data", "shape_faces"]


def shape_faces(shape: Any) -> list[TopoDS_Face]:
    """The faces of a build123d/cadquery/OCP shape (a face gives itself).

    Raises:
        GHTError: not a shape, or a shape without faces.
    """
    raw = shape.wrapped if hasattr(shape, "wrapped") else shape
    if not isinstance(raw, TopoDS_Shape) or raw.IsNull():
        raise GHTError(f"cannot unroll a {type(shape).__name__}; expected a build123d/cadquery Face or TopoDS_Face")
    if raw.ShapeType() == TopAbs_FACE:
        return [TopoDS.Face_s(raw)]
    exp = TopExp_Explorer(raw, TopAbs_FACE)
    faces = []
    while exp.More():
        faces.append(TopoDS.Face_s(exp.Current()))
        exp.Next()
    if not faces:
        raise GHTError(f"the {type(shape).__name__} has no faces to unroll")
    return faces


def _topods_face(face: Any) -> TopoDS_Face:
    faces = shape_faces(face)
    if len(faces) == 1:
        return faces[0]
    raise GHTError(
        f"the shape has {len(faces)} faces; unroll takes one face (use unroll_composite(list_of_faces) "
        "for several)"
    )


def _open_face(face: Any) -> tuple[TopoDS_Face, BRepAdaptor_Surface, tuple[float, float, float, float], "_SurfEval"]:
    """The face, its surface adaptor, its (u0, u1, v0, v1) parameter bounds and an evaluator."""
    f = _topods_face(face)
    ad = BRepAdaptor_Surface(f)
    return f, ad, BRepTools.UVBounds_s(f), _SurfEval(ad)


_KINDS = {
    GeomAbs_Plane: "plane",
    GeomAbs_Cylinder: "cylinder",
    GeomAbs_Cone: "cone",
    GeomAbs_SurfaceOfExtrusion: "extrusion",
    GeomAbs_BSplineSurface: "bspline",
    GeomAbs_BezierSurface: "bezier",
}


class _SurfEval(SurfaceAdapter):
    """A BRepAdaptor_Surface as :class:`ght_cad.unrolling.face_unroll.SurfaceAdapter`: kind, radius and
    semi-angle from OCCT, read once.

    Planes, cylinders and cones are evaluated in numpy from their (located) ``gp_Ax3`` position
    ``(O, X, Y, Z)``, radius R and semi-angle α by OCCT's own formulas (``ElSLib``): plane
    ``O + u X + v Y``; cylinder ``O + R (cos u X + sin u Y) + v Z``; cone
    ``O + (R + v sin α)(cos u X + sin u Y) + v cos α Z``, with their partials. The formulas are
    checked against ``BRepAdaptor_Surface.D2`` at three points when the face is opened (agreement
    to 1e-12 of the face's size, else the OCCT loop is used). Other surfaces: a Python loop over
    ``D0``/``D1``/``D2``.
    """

    def __init__(self, adaptor: BRepAdaptor_Surface) -> None:
        self.ad = adaptor
        self._p = gp_Pnt()
        self._v = [gp_Vec() for _ in range(5)]
        self._ax: tuple[np.ndarray, ...] | None = None
        self._breaks: dict[str, np.ndarray] = {}
        kind = adaptor.GetType()
        self.kind = _KINDS.get(kind, "other")
        if kind == GeomAbs_Cylinder:
            cyl = adaptor.Cylinder()
            self.radius = cyl.Radius()
            self._set_axes(cyl.Position())
        elif kind == GeomAbs_Cone:
            cone = adaptor.Cone()
            self.radius, self.semi_angle = cone.RefRadius(), cone.SemiAngle()
            self._set_axes(cone.Position())
        elif kind == GeomAbs_Plane:
            self._set_axes(adaptor.Plane().Position())
        elif kind in (GeomAbs_BSplineSurface, GeomAbs_BezierSurface):
            if adaptor.VDegree() == 1 and adaptor.NbVPoles() == 2:
                self.ruled_hint = "v"
            elif adaptor.UDegree() == 1 and adaptor.NbUPoles() == 2:
                self.ruled_hint = "u"
            self._nurbs = _nurbs_of(adaptor)
            if self._nurbs is not None and not self._agrees():
                self._nurbs = None  # pragma: no cover - a representation we do not read right: use OCCT
            if self._nurbs is not None and self.ruled_hint is not None:
                w = self._nurbs.cw[..., 3]  # equal weights across the rulings: affine along them
                self.affine_ruled = bool(np.all(w[:, 0] == w[:, 1]) if self.ruled_hint == "v" else np.all(w[0] == w[1]))
        elif kind == GeomAbs_SurfaceOfExtrusion:
            self.affine_ruled = True  # C(u) + v D

    _nurbs: "NurbsSurface | None" = None

    def _probe(self) -> tuple[np.ndarray, np.ndarray]:
        ad = self.ad
        u0, u1, v0, v1 = ad.FirstUParameter(), ad.LastUParameter(), ad.FirstVParameter(), ad.LastVParameter()
        lo = [max(u0, -1e3), max(v0, -1e3)]
        hi = [min(u1, 1e3), min(v1, 1e3)]
        return (np.array([lo[0], 0.5 * (lo[0] + hi[0]), 0.3 * lo[0] + 0.7 * hi[0], hi[0]]),
                np.array([lo[1], 0.6 * lo[1] + 0.4 * hi[1], hi[1], 0.2 * lo[1] + 0.8 * hi[1]]))

    def _agrees(self) -> bool:
        """The numpy evaluation matches OCCT at four points to 1e-12 of the size (derivatives
        relative to their own size): an analytic surface's ``D2``; a B-spline's values and first
        derivatives (``D1``), which check the poles, weights and knots as read (its second
        derivatives come from the same data through the difference nets)."""
        uu, vv = self._probe()
        if self._nurbs is not None:
            p, (du, dv) = self._p, self._v[:2]
            rows = []
            for u, v in zip(uu.tolist(), vv.tolist()):
                self.ad.D1(u, v, p, du, dv)
                rows.append(p.Coord() + du.Coord() + dv.Coord())
            a = np.array(rows, dtype=float)
            return _core.jets_agree(self._nurbs.eval(uu, vv, 1), [a[:, 0:3], a[:, 3:6], a[:, 6:9]], max(1.0, self.radius))
        return _core.jets_agree(self.d2(uu, vv), self._occ_d2(uu, vv), max(1.0, self.radius))

    def _set_axes(self, ax3: Any) -> None:
        """Numpy evaluation from ``(O, X, Y, Z)`` after checking it against OCCT at three points."""
        self._ax = tuple(np.array(x.Coord()) for x in (ax3.Location(), ax3.XDirection(), ax3.YDirection(),
                                                        ax3.Direction()))
        if not self._agrees():
            self._ax = None  # pragma: no cover - an OCCT convention we do not know: use OCCT itself

    def breaks(self, direction: str) -> np.ndarray:
        if direction not in self._breaks:
            self._breaks[direction] = surface_breaks(self.ad, direction)
        return self._breaks[direction]

    def c0_breaks(self, direction: str) -> np.ndarray:
        return self._nurbs.c0_knots(direction) if self._nurbs is not None else np.zeros(0)

    def _analytic(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """[S, S_u, S_v, S_uu, S_vv, S_uv] (up to ``order``) of a plane, cylinder or cone
        (:func:`ght_cad.unrolling.face_unroll.analytic_jet`)."""
        return _core.analytic_jet(self.kind, self._ax, self.radius, self.semi_angle, u, v, order)  # type: ignore[arg-type]

    def value(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        if self._ax is not None:
            return self._analytic(u, v, 0)[0]
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, 0)[0]
        ad = self.ad
        return np.array([ad.Value(uu, vv).Coord() for uu, vv in zip(u.tolist(), v.tolist())], dtype=float).reshape(-1, 3)

    def d1(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """[S_u, S_v] at the points."""
        if self._ax is not None:
            return self._analytic(u, v, 1)[1:3]
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, 1)[1:3]
        p, (du, dv) = self._p, self._v[:2]
        ad = self.ad
        rows = []
        for uu, vv in zip(u.tolist(), v.tolist()):
            ad.D1(uu, vv, p, du, dv)
            rows.append(du.Coord() + dv.Coord())
        a = np.array(rows, dtype=float).reshape(-1, 6)
        return [a[:, 0:3], a[:, 3:6]]

    def d2(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """[S, S_u, S_v, S_uu, S_vv, S_uv] at the points."""
        if self._ax is not None:
            return self._analytic(u, v, 2)
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, 2)
        return self._occ_d2(u, v)

    def jet(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """``[S]``, ``[S, S_u, S_v]`` or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` (order 0, 1, 2) in one pass."""
        if self._ax is not None:
            return self._analytic(u, v, order)[: (1, 3, 6)[min(order, 2)]]
        if self._nurbs is not None:
            return self._nurbs.eval(u, v, min(order, 2))
        return _core.surface_jet(self, u, v, order, own=False)

    @property
    def fast_density_grid(self) -> bool:
        """:meth:`density_grid` works on the tensor grid (a B-spline read into the core), not point
        by point: :func:`ght_cad.unrolling.face_unroll.face_area` then puts whole pieces on grids."""
        return self._ax is None and self._nurbs is not None and self._nurbs.patches is not None

    def density_grid(self, s: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``|S_u × S_v|`` at every (s_i, v_j), shape (len(s), len(v)) (a B-spline: each basis
        series evaluated once per s and once per v)."""
        s, v = np.asarray(s, dtype=float), np.asarray(v, dtype=float)
        if self._ax is None and self._nurbs is not None:
            r = self._nurbs.density_grid(s, v)
            if r is not None:
                return r
        d = self.d1(np.repeat(s, v.size), np.tile(v, s.size))
        return np.linalg.norm(np.cross(d[0], d[1]), axis=1).reshape(s.size, v.size)

    def _occ_d2(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        p, (du, dv, duu, dvv, duv) = self._p, self._v
        ad = self.ad
        rows = []
        for uu, vv in zip(u.tolist(), v.tolist()):
            ad.D2(uu, vv, p, du, dv, duu, dvv, duv)
            rows.append(p.Coord() + du.Coord() + dv.Coord() + duu.Coord() + dvv.Coord() + duv.Coord())
        a = np.array(rows, dtype=float).reshape(-1, 18)
        return [a[:, 3 * k:3 * k + 3] for k in range(6)]


def _nurbs_of(ad: BRepAdaptor_Surface) -> NurbsSurface | None:
    """The core evaluator (:class:`ght_cad.surfaces.nurbs.NurbsSurface`) of the adaptor's B-spline/Bézier
    surface, read once from OCCT (None: periodic, or another kind)."""
    if ad.GetType() == GeomAbs_BSplineSurface:
        g = ad.BSpline()
        if g.IsUPeriodic() or g.IsVPeriodic():
            return None
        nu, nv = g.NbUPoles(), g.NbVPoles()
        uk, vk = _array1(g.UKnotSequence()), _array1(g.VKnotSequence())
        pu, pv = g.UDegree(), g.VDegree()
    elif ad.GetType() == GeomAbs_BezierSurface:
        g = ad.Bezier()
        nu, nv = g.NbUPoles(), g.NbVPoles()
        pu, pv = g.UDegree(), g.VDegree()
        uk = np.r_[np.zeros(pu + 1), np.ones(pu + 1)]
        vk = np.r_[np.zeros(pv + 1), np.ones(pv + 1)]
    else:
        return None
    P = g.Poles()  # rows along u, columns along v
    cw = np.empty((nu, nv, 4))
    cw[..., :3] = np.array([P.Value(i, j).Coord() for i in range(P.LowerRow(), P.UpperRow() + 1)
                            for j in range(P.LowerCol(), P.UpperCol() + 1)], dtype=float).reshape(nu, nv, 3)
    if g.IsURational() or g.IsVRational():
        cw[..., 3] = np.array([[g.Weight(i, j) for j in range(1, nv + 1)] for i in range(1, nu + 1)], dtype=float)
        cw[..., :3] *= cw[..., 3:]
    else:
        cw[..., 3] = 1.0
    if uk.size != nu + pu + 1 or vk.size != nv + pv + 1:
        return None  # pragma: no cover - not a clamped flat knot vector
    return NurbsSurface(uk, vk, pu, pv, cw)


def _array1(arr: Any) -> np.ndarray:
    """A ``TColStd_Array1OfReal`` as a numpy array (read once, whatever its bounds)."""
    return np.array([arr.Value(i) for i in range(arr.Lower(), arr.Upper() + 1)], dtype=float)


class FaceRuledSurface(_core.FaceRuledSurface):
    r"""The ruled surface of a face whose ``ruled``-isolines are straight lines
    (:class:`ght_cad.unrolling.face_unroll.FaceRuledSurface` of a ``BRepAdaptor_Surface``).

    With ``ruled == "v"`` (rulings along v): ``a(t) = S(u0 + t Δu, v0)``, ``b(t) = S(u0 + t Δu, v1)``,
    ``a^(r)(t) = Δu^r ∂_u^r S``; with ``ruled == "u"`` the roles of u and v swap. ``breakpoints``
    are the surface's C∞-interval ends (B-spline knots) in t.
    """

    def __init__(self, adaptor: BRepAdaptor_Surface, ruled: str, bounds: tuple[float, float, float, float]) -> None:
        super().__init__(_SurfEval(adaptor), ruled, bounds)


def surface_breaks(ad: BRepAdaptor_Surface, direction: str) -> np.ndarray:
    """Parameters in ``direction`` where the surface is not C∞: B-spline knots (of the surface or
    of an extrusion's basis curve), else OCCT's C∞ interval ends."""
    kind = ad.GetType()
    if kind == GeomAbs_BSplineSurface:
        bs = ad.BSpline()
        if direction == "u":
            return np.array([bs.UKnot(i) for i in range(1, bs.NbUKnots() + 1)])
        return np.array([bs.VKnot(i) for i in range(1, bs.NbVKnots() + 1)])
    if kind == GeomAbs_SurfaceOfExtrusion and direction == "u":
        bc = ad.BasisCurve()
        if bc.GetType() == GeomAbs_BSplineCurve:
            b = bc.BSpline()
            return np.array([b.Knot(i) for i in range(1, b.NbKnots() + 1)])
    if direction == "u":
        n = ad.NbUIntervals(GeomAbs_CN)
        arr = TColStd_Array1OfReal(1, n + 1)
        ad.UIntervals(arr, GeomAbs_CN)
    else:
        n = ad.NbVIntervals(GeomAbs_CN)
        arr = TColStd_Array1OfReal(1, n + 1)
        ad.VIntervals(arr, GeomAbs_CN)
    return np.array([arr.Value(i) for i in range(1, n + 2)])


def face_ruling_direction(face: Any) -> tuple[str | None, dict[str, float]]:
    r"""Which parameter direction of the face has straight isolines (the rulings).

    Args:
        face: a build123d/cadquery Face or TopoDS_Face.

    Returns:
        ``("v", info)`` when the v-isolines are straight (deviation ``max dist(p, line) / L``
        < 1e-9, see :func:`ght_cad.unrolling.face_unroll.isoline_stats`; a closed isoline deviates by ``1/(2π)``), ``"u"``
        likewise, ``None`` when neither. ``info`` holds ``deviation_u``, ``deviation_v`` (finite,
        relative to the isoline length) and ``openness_u``, ``openness_v`` (smallest chord /
        length; 0 for closed isolines). Planes, cylinders, cones and extrusions return ``"v"``.

    Raises:
        GHTError: not a face, or a shape with several faces.
    """
    _, _, bounds, ev = _open_face(face)
    return _core.ruling_direction(ev, bounds)


def _curve_eval(c: Any, dim: int) -> Callable[[np.ndarray], np.ndarray] | None:
    """Numpy evaluation of a line or circle adaptor (2-D or 3-D) by OCCT's formulas (``ElCLib``):
    line ``P + p D``, circle ``O + R (cos p X + sin p Y)``; None for other curves or when the
    formula disagrees with the adaptor's ``Value`` by more than 1e-12 of the curve's size at two
    parameters."""
    kind = c.GetType()
    if kind == GeomAbs_Line:  # gp_Lin(2d)'s parametrization P + p D is its definition: nothing to check
        lin = c.Line()
        P, D = np.array(lin.Location().Coord()), np.array(lin.Direction().Coord())

        def f(p: np.ndarray) -> np.ndarray:
            return P + p[:, None] * D
        return f
    elif kind == GeomAbs_Circle:
        circ = c.Circle()
        ax = circ.Position()
        Oc, Xc, Yc = (x.Coord() for x in (ax.Location(), ax.XDirection(), ax.YDirection()))
        O, X, Y = np.array(Oc), np.array(Xc), np.array(Yc)
        R = circ.Radius()

        def f(p: np.ndarray) -> np.ndarray:
            return O + R * (np.cos(p)[:, None] * X + np.sin(p)[:, None] * Y)

        def f1(x: float) -> list[float]:
            cx, sx = math.cos(x), math.sin(x)
            return [o + R * (cx * a + sx * b) for o, a, b in zip(Oc, Xc, Yc)]
        scale = max(1.0, max(abs(x) for x in Oc) + R)
    elif kind in (GeomAbs_BSplineCurve, GeomAbs_BezierCurve):
        nc = _nurbs_curve_of(c, dim)
        if nc is None:
            return None
        def f(p: np.ndarray) -> np.ndarray:
            return nc.value(p)
        scale = max(1.0, float(np.abs(nc.cw[:, :dim] / nc.cw[:, dim:]).max()))
        ps = np.linspace(c.FirstParameter(), c.LastParameter(), 5)
        if float(np.abs(f(ps) - np.array([c.Value(x).Coord() for x in ps.tolist()])).max()) > 1e-12 * scale:
            return None  # pragma: no cover - a representation we do not read right: use OCCT
        f.derivative = nc.derivative  # type: ignore[attr-defined]
        return f
    else:
        return None
    for x in (c.FirstParameter(), c.LastParameter()):  # the formula checked at the ends, in plain floats
        if abs(x) < 1e50:
            if max(abs(a - b) for a, b in zip(f1(x), c.Value(x).Coord())) > 1e-12 * scale:
                return None  # pragma: no cover - a convention we do not know: evaluate by OCCT
    return f


def _nurbs_curve_of(c: Any, dim: int) -> NurbsCurve | None:
    """The core evaluator (:class:`ght_cad.surfaces.nurbs.NurbsCurve`) of a B-spline/Bézier curve adaptor
    (2-D or 3-D), read once from OCCT (None: periodic)."""
    if c.GetType() == GeomAbs_BSplineCurve:
        g = c.BSpline()
        if g.IsPeriodic():
            return None
        seq = g.KnotSequence()
        U = np.array([seq.Value(i) for i in range(seq.Lower(), seq.Upper() + 1)])
    else:
        g = c.Bezier()
        U = np.r_[np.zeros(g.Degree() + 1), np.ones(g.Degree() + 1)]
    n, p = g.NbPoles(), g.Degree()
    if U.size != n + p + 1:
        return None  # pragma: no cover - not a clamped flat knot vector
    cw = np.empty((n, dim + 1))
    for i in range(1, n + 1):
        w = g.Weight(i)
        cw[i - 1, :dim] = np.array(g.Pole(i).Coord()) * w
        cw[i - 1, dim] = w
    return NurbsCurve(U, p, cw)


def _memo(fun: Callable[[np.ndarray], Any]) -> Callable[[np.ndarray], Any]:
    """``fun`` with its last four results kept (the same sample parameters are asked for by the
    outline, the area, the outer-loop test and the distortion report)."""
    cache: dict[bytes, Any] = {}

    def f(t: np.ndarray) -> Any:
        t = np.asarray(t, dtype=float)
        key = t.tobytes()
        if key not in cache:
            if len(cache) >= 4:
                cache.pop(next(iter(cache)))
            cache[key] = fun(t)
        r = cache[key]
        return tuple(x.copy() for x in r) if isinstance(r, tuple) else r.copy()

    return f


def _edge_samples(edge: Any, face: TopoDS_Face, reversed_: bool) -> tuple[Callable, Callable, float, Callable]:
    """(t -> (u, v), t -> xyz, 3-D length, t -> (u', v')) of one edge, t ∈ [0, 1] in wire order.

    Line, circle and non-periodic B-spline/Bézier curves (pcurve and 3-D curve) are evaluated in
    numpy (:func:`_curve_eval`, :class:`ght_cad.surfaces.nurbs.NurbsCurve`),
    others point by point through OCCT; results are memoized per parameter array (:func:`_memo`).
    """
    c2 = BRepAdaptor_Curve2d(edge, face)
    # the edge's own 3-D curve (as FreeCAD's adapter), not BRepAdaptor_Curve(edge, face), which is
    # the pcurve's image S(u(p), v(p)) and made the boundary-length check nearly tautological
    # (a boolean's edge differs from it within the edge tolerance: 4.7e-7 relative on a 0.01 mm edge)
    c3 = BRepAdaptor_Curve(edge)
    p0, p1 = c2.FirstParameter(), c2.LastParameter()
    if reversed_:
        p0, p1 = p1, p0
    f2 = _curve_eval(c2, 2)

    @_memo
    def uv(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p = p0 + t * (p1 - p0)
        if f2 is not None:
            out = f2(p)
        else:
            out = np.array([c2.Value(x).Coord() for x in p.tolist()], dtype=float).reshape(-1, 2)
        return out[:, 0], out[:, 1]

    q0, q1 = c3.FirstParameter(), c3.LastParameter()
    if reversed_:
        q0, q1 = q1, q0
    f3: list[Any] = []  # the 3-D curve's evaluator, read on first use (a single panel needs none)

    @_memo
    def xyz(t: np.ndarray) -> np.ndarray:
        if not f3:
            f3.append(_curve_eval(c3, 3))
        q = q0 + t * (q1 - q0)
        if f3[0] is not None:
            return f3[0](q)
        return np.array([c3.Value(x).Coord() for x in q.tolist()], dtype=float).reshape(-1, 3)

    tbreaks = np.zeros(0)
    if c2.GetType() == GeomAbs_BSplineCurve:
        b = c2.BSpline()
        ks = np.array([b.Knot(i) for i in range(1, b.NbKnots() + 1)])
        tb = (ks - p0) / (p1 - p0)
        tbreaks = np.sort(tb[(tb > 1e-12) & (tb < 1 - 1e-12)])

    line2 = c2.GetType() == GeomAbs_Line and f2 is not None
    if line2:
        d2 = np.array(c2.Line().Direction().Coord())

    @_memo
    def duv(t: np.ndarray) -> np.ndarray:
        if line2:
            out = np.empty((t.size, 2))
            out[:] = d2 * (p1 - p0)
            return out
        if f2 is not None and hasattr(f2, "derivative"):
            return f2.derivative(p0 + t * (p1 - p0)) * (p1 - p0)
        p, vec = gp_Pnt2d(), gp_Vec2d()
        rows = []
        for x in (p0 + t * (p1 - p0)).tolist():
            c2.D1(x, p, vec)
            rows.append(vec.Coord())
        return np.array(rows, dtype=float).reshape(-1, 2) * (p1 - p0)

    length = 0.0 if BRep_Tool.Degenerated_s(edge) else GCPnts_AbscissaPoint.Length_s(c3, 1e-13)
    duv.breaks = tbreaks  # type: ignore[attr-defined]
    return uv, xyz, float(length), duv


def _wires(face: TopoDS_Face) -> list[Any]:
    outer = BRepTools.OuterWire_s(face)
    ws = [outer]
    exp = TopExp_Explorer(face, TopAbs_WIRE)
    while exp.More():
        w = TopoDS.Wire_s(exp.Current())
        if not w.IsSame(outer):
            ws.append(w)
        exp.Next()
    return ws


def unroll_face(
    face: Any,
    *,
    best_effort: bool = False,
    tol_deg: float = DEFAULT_TOL_DEG,
    rulings: int = 16,
    samples: int = 257,
    units: str = "mm",
    label: str = "P1",
    sheet: Any = None,
) -> FlatPattern:
    """Unroll one build123d/cadquery/OCP face by :func:`ght_cad.unrolling.face_unroll.unroll_face_data`
    (closed forms for plane/cylinder/cone, quadrature along the rulings otherwise; see module doc).

    Args:
        face: a Face (build123d, cadquery) or TopoDS_Face (or a shape holding exactly one face).
        best_effort, tol_deg, rulings, samples, units, label: as for
            :func:`ght_cad.unrolling.face_unroll.unroll_face_data` (flatten a non-developable face with a
            distortion report; largest θ_max in degrees; bend lines; points per edge; length
            unit; panel label).
        sheet: a :class:`ght_cad.sheetmetal.sheet.Sheet`: unroll the face's neutral surface (side relative
            to the face's normal, orientation included).

    Returns:
        FlatPattern with one panel: all wires of the face (outer + holes) mapped to the plane.

    Raises:
        NotDevelopableError: not ruled (isoline deviation in the message) or θ_max > tol_deg
            (θ_max and DD in the message), unless best_effort.
        DegenerateGeometryError: best_effort on a face whose isolines are all closed (a torus).
        GHTError: not a face, or a shape with several faces.
    """
    f, _, bounds, ev = _open_face(face)
    return unroll_face_data(
        face_data(f, ev, bounds),
        best_effort=best_effort,
        tol_deg=tol_deg,
        rulings=rulings,
        samples=samples,
        units=units,
        label=label,
        sheet=sheet,
    )


def face_data(f: TopoDS_Face, ev: _SurfEval, bounds: tuple[float, float, float, float],
              edge_name: Callable[[Any], str] | None = None) -> FaceData:
    """The face as :class:`ght_cad.unrolling.face_unroll.FaceData`: every wire (outer first) traversed by
    ``BRepTools_WireExplorer``, each edge's pcurve, 3-D curve and length (:func:`_edge_samples`);
    edges named ``edge<k>`` in wire order, or ``edge_name(edge)`` (e.g. the solid's edge key,
    the same in both faces sharing an edge)."""
    wires = []
    for w in _wires(f):
        loop = []
        exp = BRepTools_WireExplorer(w, f)
        k = 0
        while exp.More():
            e = exp.Current()
            uvf, xyzf, L3, duvf = _edge_samples(e, f, e.Orientation() == TopAbs_REVERSED)
            loop.append(EdgeData(uv=uvf, duv=duvf, xyz=xyzf, length_3d=L3, breaks=duvf.breaks,
                                 name=f"edge{k}" if edge_name is None else edge_name(e)))
            k += 1
            exp.Next()
        if loop:
            wires.append(loop)
    return FaceData(surface=ev, bounds=bounds, wires=wires, reversed=f.Orientation() == TopAbs_REVERSED)


def flat_faces(pattern: FlatPattern, *, spline: bool = True) -> list[Any]:
    """Planar build123d Faces (z = 0) of every panel: outer wire plus hole wires.

    Each boundary edge becomes an interpolating spline through its sampled flat points
    (``spline=False``: a polyline), so trimmed boundaries and holes are kept.

    Raises:
        GHTError: OCCT could not build a valid face from the loops.
    """
    from build123d import Edge, Face, Wire

    out = []
    for panel in pattern.panels:
        wires = []
        for loop in panel.loops:
            edges = []
            for e in loop:
                pts = e.flat + panel.offset
                if np.linalg.norm(pts[-1] - pts[0]) < 1e-12 and np.ptp(pts, axis=0).max() < 1e-12:
                    continue  # degenerate edge (apex) collapses to a point
                p3 = [(float(x), float(y), 0.0) for x, y in pts]
                if spline:
                    edges.append(Edge.make_spline(p3))
                else:
                    edges.extend(Edge.make_line(p3[i], p3[i + 1]) for i in range(len(p3) - 1))
            # consecutive edges share end points up to round-off: snap by building the wire with tolerance
            wires.append(Wire(edges))
        face = Face(wires[0], wires[1:])
        if not face.is_valid:
            raise GHTError(f"could not build a valid planar face for panel {panel.label!r}")
        out.append(face)
    return out
