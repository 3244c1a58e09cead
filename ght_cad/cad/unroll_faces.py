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
    GeomAbs_BezierSurface,
    GeomAbs_BSplineCurve,
    GeomAbs_BSplineSurface,
    GeomAbs_CN,
    GeomAbs_Cone,
    GeomAbs_Cylinder,
    GeomAbs_Plane,
    GeomAbs_SurfaceOfExtrusion,
)
from OCP.gp import gp_Pnt, gp_Pnt2d, gp_Vec, gp_Vec2d
from OCP.TColStd import TColStd_Array1OfReal
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

from ..errors import DegenerateGeometryError, GHTError, NotDevelopableError
from ..flat_pattern import BoundaryEdge, FlatPanel, FlatPattern, measure_panel
from ..ruled import RuledSurface
from ..unroll import DEFAULT_TOL_DEG, RuledDevelopment, _check_developable, broadcast_uv, metric_angles

__all__ = ["unroll_face", "FaceRuledSurface", "flat_faces", "face_ruling_direction", "face_area", "shape_faces"]


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


class _SurfEval:
    """Vectorized (Python loop) evaluation of a BRepAdaptor_Surface: points and partials."""

    def __init__(self, adaptor: BRepAdaptor_Surface) -> None:
        self.ad = adaptor
        self._p = gp_Pnt()
        self._v = [gp_Vec() for _ in range(5)]

    def value(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        out = np.empty((u.size, 3))
        for i, (uu, vv) in enumerate(zip(u.tolist(), v.tolist())):
            out[i] = self.ad.Value(uu, vv).Coord()
        return out

    def d1(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """[S_u, S_v] at the points."""
        out = [np.empty((u.size, 3)) for _ in range(2)]
        p, (du, dv) = self._p, self._v[:2]
        for i, (uu, vv) in enumerate(zip(u.tolist(), v.tolist())):
            self.ad.D1(uu, vv, p, du, dv)
            out[0][i] = du.Coord()
            out[1][i] = dv.Coord()
        return out

    def d2(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """[S, S_u, S_v, S_uu, S_vv, S_uv] at the points."""
        out = [np.empty((u.size, 3)) for _ in range(6)]
        p, (du, dv, duu, dvv, duv) = self._p, self._v
        for i, (uu, vv) in enumerate(zip(u.tolist(), v.tolist())):
            self.ad.D2(uu, vv, p, du, dv, duu, dvv, duv)
            out[0][i] = p.Coord()
            out[1][i] = du.Coord()
            out[2][i] = dv.Coord()
            out[3][i] = duu.Coord()
            out[4][i] = dvv.Coord()
            out[5][i] = duv.Coord()
        return out


class FaceRuledSurface(RuledSurface):
    r"""The ruled surface of a face whose ``ruled``-isolines are straight lines.

    With ``ruled == "v"`` (rulings along v): ``a(t) = S(u0 + t Δu, v0)``, ``b(t) = S(u0 + t Δu, v1)``,
    ``a^(r)(t) = Δu^r ∂_u^r S``; with ``ruled == "u"`` the roles of u and v swap. ``breakpoints``
    are the surface's C∞-interval ends (B-spline knots) in t.
    """

    def __init__(self, adaptor: BRepAdaptor_Surface, ruled: str, bounds: tuple[float, float, float, float]) -> None:
        if ruled not in ("u", "v"):
            raise GHTError(f"ruled={ruled!r} is not allowed; use 'u' or 'v'")
        self.ev = _SurfEval(adaptor)
        self.ruled = ruled
        self.bounds = bounds
        u0, u1, v0, v1 = bounds
        if ruled == "v":
            self.t0, self.t1, self.s0, self.s1 = u0, u1, v0, v1
        else:
            self.t0, self.t1, self.s0, self.s1 = v0, v1, u0, u1
        ks = surface_breaks(adaptor, "u" if ruled == "v" else "v")
        self.breakpoints = tuple(((ks - self.t0) / (self.t1 - self.t0)).tolist())

    def uv(self, t: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Face parameters of ruled parameters (t, s) ∈ [0, 1]²."""
        tp = self.t0 + t * (self.t1 - self.t0)
        sp = self.s0 + s * (self.s1 - self.s0)
        return (tp, sp) if self.ruled == "v" else (sp, tp)

    def ts(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Ruled parameters (t, s) of face parameters (u, v)."""
        tp, sp = (u, v) if self.ruled == "v" else (v, u)
        return (tp - self.t0) / (self.t1 - self.t0), (sp - self.s0) / (self.s1 - self.s0)

    def _edge(self, t: Any, s: float, derivative: int) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, dtype=float))
        u, v = self.uv(t, np.full_like(t, s))
        if derivative == 0:
            return self.ev.value(u, v)
        if derivative > 2:
            raise GHTError(f"derivative={derivative} is not available for faces; allowed 0, 1, 2")
        d = self.ev.d2(u, v)
        k = (1 if self.ruled == "v" else 2) if derivative == 1 else (3 if self.ruled == "v" else 4)
        return d[k] * (self.t1 - self.t0) ** derivative

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._edge(u, 0.0, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._edge(u, 1.0, derivative)


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


def _isoline_stats(ev: _SurfEval, bounds: tuple[float, float, float, float], direction: str) -> tuple[float, float]:
    r"""Straightness and openness of the isolines running along ``direction``.

    Nine isolines (fixed other parameter at 0, 1/8, ..., 1 of its range), each sampled at 33
    points ``p_0 .. p_32``, polyline length ``L = Σ |p_{k+1} - p_k|``, chord ``c = p_32 - p_0``.
    The line an isoline is compared with is its chord line when ``|c| > 1e-9 L``, else (a closed
    isoline) the best-fitting line (through the centroid along the principal axis of the points).
    The deviation of one isoline is ``max_k dist(p_k, line) / L`` (0 for a straight segment,
    ``1/π`` for a half circle, ``1/(2π)`` for a full circle); isolines with ``L = 0`` (a pole or
    an apex) are points and skipped.

    Returns:
        ``(deviation, openness)``: the largest deviation and the smallest ``|c| / L`` over the
        non-degenerate isolines (``openness`` 0 for closed isolines, 1 for straight ones);
        ``(0.0, 1.0)`` when every isoline is degenerate.
    """
    u0, u1, v0, v1 = bounds
    fixed = np.linspace(0.0, 1.0, 9)
    run = np.linspace(0.0, 1.0, 33)
    worst, openness = 0.0, 1.0
    for f in fixed:
        if direction == "v":
            u = np.full_like(run, u0 + f * (u1 - u0))
            v = v0 + run * (v1 - v0)
        else:
            u = u0 + run * (u1 - u0)
            v = np.full_like(run, v0 + f * (v1 - v0))
        p = ev.value(u, v)
        L = float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())
        if not math.isfinite(L) or L <= 1e-14 * max(1.0, float(np.abs(p).max())):
            continue  # the isoline is a point (pole, apex)
        c = p[-1] - p[0]
        chord = float(np.linalg.norm(c))
        if chord > 1e-9 * L:
            origin, axis = p[0], c / chord
        else:  # closed isoline: its best-fitting straight line
            origin = p.mean(axis=0)
            axis = np.linalg.svd(p - origin, full_matrices=False)[2][0]
        dev = float(np.linalg.norm(np.cross(p - origin, axis), axis=1).max()) / L
        worst = max(worst, dev)
        openness = min(openness, chord / L)
    return worst, openness


def _straightness(ev: _SurfEval, bounds: tuple[float, float, float, float], direction: str) -> float:
    """Largest isoline deviation from a straight line relative to the isoline length (:func:`_isoline_stats`)."""
    return _isoline_stats(ev, bounds, direction)[0]


def face_ruling_direction(face: Any) -> tuple[str | None, dict[str, float]]:
    r"""Which parameter direction of the face has straight isolines (the rulings).

    Args:
        face: a build123d/cadquery Face or TopoDS_Face.

    Returns:
        ``("v", info)`` when the v-isolines are straight (deviation ``max dist(p, line) / L``
        < 1e-9, see :func:`_isoline_stats`; a closed isoline deviates by ``1/(2π)``), ``"u"``
        likewise, ``None`` when neither. ``info`` holds ``deviation_u``, ``deviation_v`` (finite,
        relative to the isoline length) and ``openness_u``, ``openness_v`` (smallest chord /
        length; 0 for closed isolines). Planes, cylinders, cones and extrusions return ``"v"``.

    Raises:
        GHTError: not a face, or a shape with several faces.
    """
    f, ad, bounds, ev = _open_face(face)
    dv, ov = _isoline_stats(ev, bounds, "v")
    du, ou = _isoline_stats(ev, bounds, "u")
    info = {"deviation_v": dv, "deviation_u": du, "openness_v": ov, "openness_u": ou}
    if ad.GetType() in (GeomAbs_Plane, GeomAbs_Cylinder, GeomAbs_Cone, GeomAbs_SurfaceOfExtrusion):
        return "v", info
    if ad.GetType() in (GeomAbs_BSplineSurface, GeomAbs_BezierSurface):
        if ad.VDegree() == 1 and ad.NbVPoles() == 2:
            return "v", info
        if ad.UDegree() == 1 and ad.NbUPoles() == 2:
            return "u", info
    if dv <= 1e-9 and dv <= du:
        return "v", info
    if du <= 1e-9:
        return "u", info
    return None, info


def _best_effort_direction(info: dict[str, float], label: str) -> str:
    """Ruling direction for flattening a non-ruled face: the boundary isolines ``S(·, v0)``,
    ``S(·, v1)`` (rulings along v) must be distinct curves, i.e. the v-isolines must be open.
    Among directions whose isolines are clearly open (chord ≥ 1 % of the length), else merely
    open (chord > 1e-6 of the length), the straighter one is used.

    Raises:
        DegenerateGeometryError: the isolines are closed in both directions (a torus): there are
            no two distinct boundary isolines to span rulings between.
    """
    for lim in (1e-2, 1e-6):
        cands = [d for d in ("v", "u") if info[f"openness_{d}"] >= lim]
        if cands:
            return min(cands, key=lambda d: info[f"deviation_{d}"])
    raise DegenerateGeometryError(
        f"face {label!r} is not ruled (its isolines deviate from straight lines by "
        f"{info['deviation_u']:.3g} (u-isolines) and {info['deviation_v']:.3g} (v-isolines) relative to "
        "their lengths; allowed 1e-9) and cannot be flattened even with best_effort=True: its isolines are "
        f"closed in both directions (chord/length {info['openness_u']:.3g} (u) and {info['openness_v']:.3g} "
        "(v); allowed > 1e-6), so it has no two distinct boundary isolines to span rulings between; split "
        "the face (e.g. cut a torus into sectors) first"
    )


def _edge_samples(edge: Any, face: TopoDS_Face, reversed_: bool) -> tuple[Callable, Callable, float, Callable]:
    """(t -> (u, v), t -> xyz, 3-D length, t -> (u', v')) of one edge, t ∈ [0, 1] in wire order."""
    c2 = BRepAdaptor_Curve2d(edge, face)
    c3 = BRepAdaptor_Curve(edge, face)
    p0, p1 = c2.FirstParameter(), c2.LastParameter()
    if reversed_:
        p0, p1 = p1, p0

    def uv(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        out = np.array([c2.Value(p0 + x * (p1 - p0)).Coord() for x in t.tolist()]).reshape(-1, 2)
        return out[:, 0], out[:, 1]

    q0, q1 = c3.FirstParameter(), c3.LastParameter()
    if reversed_:
        q0, q1 = q1, q0

    def xyz(t: np.ndarray) -> np.ndarray:
        return np.array([c3.Value(q0 + x * (q1 - q0)).Coord() for x in t.tolist()]).reshape(-1, 3)

    tbreaks = np.zeros(0)
    if c2.GetType() == GeomAbs_BSplineCurve:
        b = c2.BSpline()
        ks = np.array([b.Knot(i) for i in range(1, b.NbKnots() + 1)])
        tb = (ks - p0) / (p1 - p0)
        tbreaks = np.sort(tb[(tb > 1e-12) & (tb < 1 - 1e-12)])

    def duv(t: np.ndarray) -> np.ndarray:
        out = np.empty((t.size, 2))
        p, vec = gp_Pnt2d(), gp_Vec2d()
        for i, x in enumerate(t.tolist()):
            c2.D1(p0 + x * (p1 - p0), p, vec)
            out[i] = vec.Coord()
        return out * (p1 - p0)

    length = 0.0 if BRep_Tool.Degenerated_s(edge) else GCPnts_AbscissaPoint.Length_s(c3, 1e-13)
    duv.breaks = tbreaks  # type: ignore[attr-defined]
    return uv, xyz, float(length), duv


def face_area(ev: _SurfEval, edges_uv: list[list[tuple[Callable, Callable]]], u_lo: float, u_breaks: np.ndarray) -> float:
    r"""3-D area ``∬_Ω |S_u × S_v| du dv`` of a trimmed face by Green's theorem in (u, v).

    ``∬_Ω f du dv = ∮_{∂Ω} P dv`` with ``P(u, v) = ∫_{u_lo}^{u} f(s, v) ds``: the outer integral by
    16 × 12-point Gauss–Legendre panels along each pcurve (split at the pcurve's knots), the inner one by 2 × 12-point panels per
    interval between ``u_breaks`` (the surface's knots), i.e. exact up to the smoothness of ``f``.
    The absolute value of the signed total over all loops is returned (orientation-free).
    """
    xg, wg = np.polynomial.legendre.leggauss(12)
    total = 0.0
    for loop in edges_uv:
        for uvf, duv in loop:
            te = np.unique(np.concatenate([np.linspace(0.0, 1.0, 17), getattr(duv, "breaks", np.zeros(0))]))
            tn = (0.5 * (te[:-1] + te[1:])[:, None] + 0.5 * np.diff(te)[:, None] * xg[None, :]).ravel()
            tw = (0.5 * np.diff(te)[:, None] * wg[None, :]).ravel()
            dv = duv(tn)[:, 1]
            if np.max(np.abs(dv)) == 0.0:
                continue
            u, v = uvf(tn)
            S, Vv, W, owner = [], [], [], []
            for i, (ui, vi) in enumerate(zip(u, v)):
                lo, hi = (u_lo, ui) if ui >= u_lo else (ui, u_lo)
                sign = 1.0 if ui >= u_lo else -1.0
                br = u_breaks[(u_breaks > lo) & (u_breaks < hi)]
                ed = np.unique(np.concatenate([[lo, hi], br, 0.5 * (np.concatenate([[lo], br]) + np.concatenate([br, [hi]]))]))
                h = 0.5 * np.diff(ed)
                s = ((ed[:-1] + h)[:, None] + h[:, None] * xg[None, :]).ravel()
                S.append(s)
                Vv.append(np.full_like(s, vi))
                W.append(sign * (h[:, None] * wg[None, :]).ravel())
                owner.append(np.full(s.size, i))
            s_all, v_all, w_all, own = (np.concatenate(x) for x in (S, Vv, W, owner))
            d = ev.d1(s_all, v_all)
            f = np.linalg.norm(np.cross(d[0], d[1]), axis=1)
            P = np.bincount(own, weights=f * w_all, minlength=tn.size)
            total += float(np.sum(P * dv * tw))
    return abs(total)


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


def _metric(ev: _SurfEval, fmap: Callable, bounds: tuple[float, float, float, float]) -> dict[str, np.ndarray]:
    """Angles between S_u, S_v (OCCT D1) and F_u, F_v on a 12 x 5 grid (:func:`ght_cad.unroll.metric_angles`)."""
    u0, u1, v0, v1 = bounds
    uu = u0 + (u1 - u0) * np.linspace(0.05, 0.95, 12)
    vv = v0 + (v1 - v0) * np.linspace(0.05, 0.95, 5)
    U, V = (x.ravel() for x in np.meshgrid(uu, vv, indexing="ij"))
    d = ev.d2(U, V)
    return metric_angles(d[1], d[2], fmap, U, V, 1e-3 * (u1 - u0), 1e-3 * (v1 - v0))


class _ClosedFormMap:
    """Development map of a plane, cylinder or cone (closed form, see module doc)."""

    def __init__(self, kind: str, R: float = 0.0, s: float = 0.0) -> None:
        self.kind, self.R, self.s = kind, R, s

    def map(self, u: Any, v: Any) -> np.ndarray:
        u, v = broadcast_uv(u, v)
        if self.kind == "plane":
            return np.stack([u, v], axis=1)
        if self.kind == "cylinder":
            return np.stack([self.R * u, v], axis=1)
        rho = self.R / self.s + v
        ang = self.s * u
        return np.stack([rho * np.cos(ang), rho * np.sin(ang)], axis=1)


def unroll_face(
    face: Any,
    *,
    best_effort: bool = False,
    tol_deg: float = DEFAULT_TOL_DEG,
    rulings: int = 16,
    samples: int = 257,
    units: str = "mm",
    label: str = "P1",
) -> FlatPattern:
    """Unroll one build123d/cadquery/OCP face (see module doc for the maps used).

    Args:
        face: a Face (build123d, cadquery) or TopoDS_Face (or a shape holding exactly one face).
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

    Returns:
        FlatPattern with one panel: all wires of the face (outer + holes) mapped to the plane.

    Raises:
        NotDevelopableError: the face is not ruled (message gives the isolines' largest distance
            from a straight line relative to their length, :func:`_isoline_stats`; a closed isoline
            gives about 0.159) or its θ_max exceeds ``tol_deg`` (message gives θ_max and DD), and
            best_effort is False.
        DegenerateGeometryError: best_effort on a non-ruled face whose isolines are closed in both
            directions (a full torus): no open boundary isolines to span rulings between.
        GHTError: not a face, or a shape with several faces.
    """
    f, ad, bounds, ev = _open_face(face)
    kind = ad.GetType()
    info: dict[str, Any] = {"best_effort": bool(best_effort)}
    ruled_surface: FaceRuledSurface | None = None
    if kind == GeomAbs_Plane:
        dmap = _ClosedFormMap("plane")
        ruled_dir: str | None = None
        info["method"] = "plane (identity in plane coordinates)"
    elif kind == GeomAbs_Cylinder:
        dmap = _ClosedFormMap("cylinder", R=ad.Cylinder().Radius())
        ruled_dir = "v"
        info["method"] = "cylinder (closed form)"
    elif kind == GeomAbs_Cone:
        cone = ad.Cone()
        dmap = _ClosedFormMap("cone", R=cone.RefRadius(), s=math.sin(cone.SemiAngle()))
        ruled_dir = "v"
        info["method"] = "cone (closed form)"
    else:
        ruled_dir, straight = face_ruling_direction(f)
        info.update(straight)
        if ruled_dir is None:
            if not best_effort:
                raise NotDevelopableError(
                    f"face {label!r} is not ruled: its isolines deviate from straight lines by "
                    f"{straight['deviation_u']:.3g} (u-isolines) and {straight['deviation_v']:.3g} "
                    "(v-isolines) relative to their lengths (allowed 1e-9; a closed isoline deviates "
                    "0.159); pass best_effort=True to flatten the ruled surface between its boundary "
                    "isolines with a distortion report"
                )
            ruled_dir = _best_effort_direction(straight, label)
        info["ruling_direction"] = ruled_dir
        ruled_surface = FaceRuledSurface(ad, ruled_dir, bounds)
        dd = _check_developable(ruled_surface, tol_deg, best_effort, f"face {label!r}")
        info["developability"] = dd.as_dict()
        dev = RuledDevelopment(ruled_surface, breakpoints=ruled_surface.breakpoints)
        info["method"] = "quadrature along rulings (adaptive Chebyshev panels)"
        info["panels"] = dev.panels
        info["quadrature_error_estimate"] = dev.quadrature_error_estimate
        rs = ruled_surface
        straight_ok = min(info["deviation_u"], info["deviation_v"]) <= 1e-9

        class _FaceMap:
            def map(self, u: Any, v: Any) -> np.ndarray:
                u, v = broadcast_uv(u, v)
                t, s = rs.ts(u, v)
                if straight_ok:  # exact ruled face: project the true point onto its ruling
                    return dev.map_points(t, ev.value(u, v))
                return dev.map(t, s)

        dmap = _FaceMap()  # type: ignore[assignment]
    # boundary loops
    loops = []
    loops_uv = []
    for w in _wires(f):
        loop = []
        loop_uv = []
        exp = BRepTools_WireExplorer(w, f)
        k = 0
        while exp.More():
            e = exp.Current()
            uvf, xyzf, L3, duvf = _edge_samples(e, f, e.Orientation() == TopAbs_REVERSED)
            loop_uv.append((uvf, duvf))

            def flat_fn(t: np.ndarray, uvf: Callable = uvf) -> np.ndarray:
                u, v = uvf(t)
                return dmap.map(u, v)

            loop.append(BoundaryEdge(name=f"edge{k}", flat_fn=flat_fn, xyz_fn=xyzf, length_3d=L3, samples=samples))
            k += 1
            exp.Next()
        if loop:
            loops.append(loop)
            loops_uv.append(loop_uv)
    # rulings (bend lines and ruling-length check) over the UV box, clipped later to the outline
    u0, u1, v0, v1 = bounds
    bends = np.zeros((0, 2, 2))
    g3 = gf = np.zeros(0)
    if ruled_dir is not None:
        tt = np.linspace(0.0, 1.0, 129)
        tb = np.arange(1, rulings + 1) / (rulings + 1)

        def ends(t: np.ndarray) -> tuple[np.ndarray, ...]:
            if ruled_dir == "v":
                uu = u0 + t * (u1 - u0)
                return uu, np.full_like(t, v0), uu, np.full_like(t, v1)
            vv = v0 + t * (v1 - v0)
            return np.full_like(t, u0), vv, np.full_like(t, u1), vv

        ua, va, ub, vb = ends(tt)
        g3 = np.linalg.norm(ev.value(ub, vb) - ev.value(ua, va), axis=1)
        gf = np.linalg.norm(dmap.map(ub, vb) - dmap.map(ua, va), axis=1)
        if rulings:
            ua, va, ub, vb = ends(tb)
            bends = np.stack([dmap.map(ua, va), dmap.map(ub, vb)], axis=1)
    u_breaks = surface_breaks(ad, "u")
    area_3d = face_area(ev, loops_uv, u0, u_breaks)
    panel = FlatPanel(
        label=label,
        loops=loops,
        bend_lines=bends,
        ruling_lengths_3d=g3,
        ruling_lengths_flat=gf,
        area_3d=area_3d,
        metric=_metric(ev, dmap.map, bounds),
        info=info,
        development=dmap,
    )
    measure_panel(panel)
    # place: bounding box at the origin
    lo, _ = panel.bbox()
    panel.translate(-lo)
    return FlatPattern([panel], units=units)


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
