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

This module is the OCP adapter of the kernel-free implementation :mod:`ght_cad.face_unroll`
(shared with the FreeCAD workbench): it describes a ``TopoDS_Face`` as a
:class:`ght_cad.face_unroll.FaceData` (surface evaluator from ``BRepAdaptor_Surface``, pcurves
from ``BRepAdaptor_Curve2d``, 3-D lengths from ``GCPnts_AbscissaPoint``).
"""

from __future__ import annotations

import functools
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
from OCP.TColStd import TColStd_Array1OfReal
from OCP.TopAbs import TopAbs_FACE, TopAbs_REVERSED, TopAbs_WIRE
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS, TopoDS_Face, TopoDS_Shape

from .. import face_unroll as _core
from ..errors import GHTError
from ..face_unroll import EdgeData, FaceData, SurfaceAdapter, face_area, unroll_face_data
from ..flat_pattern import FlatPattern
from ..unroll import DEFAULT_TOL_DEG

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
    """A BRepAdaptor_Surface as :class:`ght_cad.face_unroll.SurfaceAdapter`: kind, radius and
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
            self._nurbs = _Nurbs.of(adaptor)
            if self._nurbs is not None and not self._agrees():
                self._nurbs = None  # pragma: no cover - a representation we do not read right: use OCCT
            if self._nurbs is not None and self.ruled_hint is not None:
                w = self._nurbs.cw[..., 3]  # equal weights across the rulings: affine along them
                self.affine_ruled = bool(np.all(w[:, 0] == w[:, 1]) if self.ruled_hint == "v" else np.all(w[0] == w[1]))
        elif kind == GeomAbs_SurfaceOfExtrusion:
            self.affine_ruled = True  # C(u) + v D

    _nurbs: "_Nurbs | None" = None

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
            ours = self._nurbs.eval(uu, vv, 1)
            p, (du, dv) = self._p, self._v[:2]
            rows = []
            for u, v in zip(uu.tolist(), vv.tolist()):
                self.ad.D1(u, v, p, du, dv)
                rows.append(p.Coord() + du.Coord() + dv.Coord())
            a = np.array(rows, dtype=float)
            theirs = [a[:, 0:3], a[:, 3:6], a[:, 6:9]]
        else:
            ours, theirs = self.d2(uu, vv), self._occ_d2(uu, vv)
        for a, b in zip(ours, theirs):
            scale = max(1.0, float(np.abs(b).max()), self.radius)
            if not float(np.abs(a - b).max()) <= 1e-12 * scale:
                return False
        return True

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

    def _analytic(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """[S, S_u, S_v, S_uu, S_vv, S_uv] (up to ``order``) of a plane, cylinder or cone."""
        O, X, Y, Z = self._ax  # type: ignore[misc]
        u = np.asarray(u, dtype=float)[:, None]
        v = np.asarray(v, dtype=float)[:, None]
        if self.kind == "plane":
            zero = np.zeros((u.shape[0], 3))
            out = [O + u * X + v * Y, np.broadcast_to(X, zero.shape).copy(), np.broadcast_to(Y, zero.shape).copy()]
            return out + [zero, zero.copy(), zero.copy()] if order >= 2 else out
        c, s = np.cos(u), np.sin(u)
        radial = c * X + s * Y
        tangent = -s * X + c * Y
        if self.kind == "cylinder":
            R = self.radius
            out = [O + R * radial + v * Z, R * tangent, np.broadcast_to(Z, radial.shape).copy()]
            if order >= 2:
                out += [-R * radial, np.zeros_like(radial), np.zeros_like(radial)]
            return out
        sa, ca = math.sin(self.semi_angle), math.cos(self.semi_angle)
        r = self.radius + v * sa
        out = [O + r * radial + (v * ca) * Z, r * tangent, sa * radial + ca * Z]
        if order >= 2:
            out += [-r * radial, np.zeros_like(radial), sa * tangent]
        return out

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


class _Nurbs:
    r"""Vectorized evaluation of a (rational) B-spline or Bézier surface read once from OCCT.

    Homogeneous poles ``C_ij = (w_ij P_ij, w_ij)`` on clamped knots ``U`` (degree p), ``V``
    (degree q). Derivatives use the difference nets of the derivative surfaces (NURBS book
    eq. 3.17), ``C^{(k)}_i = (p-k+1) (C^{(k-1)}_{i+1} - C^{(k-1)}_i) / (U_{i+p+1} - U_{i+k})``, so
    ``∂^k_u H(u, v) = Σ_a Σ_b N_{i-p+k+a, p-k}(u) M_{j-q+b, q}(v) C^{(k)}_{i-p+a, j-q+b}`` with ``i``,
    ``j`` the knot spans of u and v, and only the ``(p-k+1)(q+1)`` non-zero basis functions per
    point (Cox–de Boor triangle, :func:`_basis`; the lower degrees come out of the same triangle).
    Outside the knot range the end polynomial pieces are continued. Values and first derivatives
    (the bulk of the evaluations) come from each knot-span patch converted once to a tensor
    Chebyshev series (:meth:`_patch_hom`: one gather of (p+1)(q+1) coefficients per point instead
    of a Cox–de Boor triangle; agrees with the triangle to ~1e-14 relative), second derivatives
    from the difference nets. ``H = (A, W)``, ``S = A / W``,
    ``S_u = (A_u - W_u S) / W``, ``S_uu = (A_uu - 2 W_u S_u - W_uu S) / W``,
    ``S_uv = (A_uv - W_u S_v - W_v S_u - W_uv S) / W`` (v likewise). Periodic surfaces are left
    to OCCT (:meth:`of` returns None).
    """

    def __init__(self, uknots: np.ndarray, vknots: np.ndarray, pu: int, pv: int, cw: np.ndarray) -> None:
        self.U, self.V = np.asarray(uknots, dtype=float), np.asarray(vknots, dtype=float)
        self.pu, self.pv = int(pu), int(pv)
        self.cw = cw  # (nu, nv, 4)
        w = cw[..., 3]
        #: the common weight when all weights are equal (a polynomial surface), else None
        self.weight: float | None = float(w.flat[0]) if np.all(w == w.flat[0]) else None
        self._nets: dict[tuple[int, int], np.ndarray] | None = None  # built on first use (:attr:`nets`)
        self.patches: tuple[np.ndarray, ...] | None = None
        su, sv = _spans(self.U, self.pu), _spans(self.V, self.pv)
        if su.size * sv.size * (self.pu + 1) * (self.pv + 1) <= 2_000_000 and max(self.pu, self.pv) <= 25:
            Mu, Mv = _cheb_basis_of(self.U, self.pu), _cheb_basis_of(self.V, self.pv)
            rows = su[:, None] - self.pu + np.arange(self.pu + 1)[None, :]  # (nsu, a)
            cols = sv[:, None] - self.pv + np.arange(self.pv + 1)[None, :]  # (nsv, b)
            win = cw[rows[:, None, :, None], cols[None, :, None, :]]  # (nsu, nsv, a, b, 4)
            pt = np.einsum("sea,stabk->stebk", Mu, win)
            pt = np.einsum("tfb,stebk->stefk", Mv, pt)
            cu, hu = 0.5 * (self.U[su] + self.U[su + 1]), 0.5 * (self.U[su + 1] - self.U[su])
            cv, hv = 0.5 * (self.V[sv] + self.V[sv + 1]), 0.5 * (self.V[sv + 1] - self.V[sv])
            self.patches = (self.U[su], cu, hu, self.V[sv], cv, hv,
                            np.ascontiguousarray(pt.reshape(su.size * sv.size, -1)))
            #: the patches as a (u-span, e) x (v-span, f, k) matrix (:meth:`_patch_hom`)
            self.patches_u = np.ascontiguousarray(np.moveaxis(pt, 2, 1).reshape(su.size * (self.pu + 1), -1))
            if su.size == 1 and sv.size == 1 and self.weight is not None:
                #: one polynomial patch: ``S = Σ_ef T_e(x) T_f(y) Q_ef`` with ``Q = P / w`` as an
                #: ((e, f), xyz) matrix, and the patch's centre and half-widths (:meth:`_poly_patch`)
                self.poly_patch = (np.ascontiguousarray(pt[0, 0, :, :, :3].reshape(-1, 3) / self.weight),
                                   float(cu[0]), float(hu[0]), float(cv[0]), float(hv[0]))

    @property
    def nets(self) -> dict[tuple[int, int], np.ndarray]:
        """The difference nets ``{(ku, kv): C^(ku, kv)}`` of the derivatives up to order 2 (class
        doc), made on first use: values and first derivatives come from the patches."""
        if self._nets is None:
            nets = {(0, 0): self.cw}
            # (target, source, axis, k): ∂_u, ∂_uu, ∂_v, ∂_vv, then ∂_u of the ∂_v net
            for tgt, src, axis, k in (((1, 0), (0, 0), 0, 1), ((2, 0), (1, 0), 0, 2), ((0, 1), (0, 0), 1, 1),
                                      ((0, 2), (0, 1), 1, 2), ((1, 1), (0, 1), 0, 1)):
                if k <= (self.pu, self.pv)[axis] and src in nets:
                    nets[tgt] = _diff_net(nets[src], (self.U, self.V)[axis], (self.pu, self.pv)[axis], k, axis)
            self._nets = nets
        return self._nets

    @classmethod
    def of(cls, ad: BRepAdaptor_Surface) -> "_Nurbs | None":
        """The evaluator of the adaptor's B-spline/Bézier surface (None: periodic, or another kind)."""
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
        return cls(uk, vk, pu, pv, cw)

    def _hom(self, su: np.ndarray, Nu: np.ndarray, sv: np.ndarray, Nv: np.ndarray, ku: int, kv: int) -> np.ndarray:
        """``∂^ku_u ∂^kv_v H`` from the non-zero basis functions ``Nu`` (n, pu-ku+1) and ``Nv``
        (n, pv-kv+1) at the spans ``su``, ``sv``; shape (n, 4)."""
        net = self.nets.get((ku, kv))
        n = su.size
        if net is None or Nu is None or Nv is None:
            return np.zeros((n, 4))
        A, B = Nu.shape[1], Nv.shape[1]
        idx = ((su - self.pu)[:, None, None] + np.arange(A)[None, :, None]) * net.shape[1] + (
            (sv - self.pv)[:, None, None] + np.arange(B)[None, None, :])
        poles = np.take(net.reshape(-1, 4), idx.ravel(), axis=0).reshape(n, A * B, 4)
        w = (Nu[:, :, None] * Nv[:, None, :]).reshape(n, A * B)
        return np.einsum("nj,njk->nk", w, poles)

    def eval(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """``[S]``, ``[S, S_u, S_v]`` or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` for ``order`` 0, 1, 2
        (in chunks of 1024 points: small work arrays stay in cache)."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        step = 1024
        if u.size <= step:
            return self._eval(u, v, order)
        parts = [self._eval(u[i:i + step], v[i:i + step], order) for i in range(0, u.size, step)]
        return [np.concatenate([p[k] for p in parts]) for k in range(len(parts[0]))]

    poly_patch: tuple[np.ndarray, float, float, float, float] | None = None

    def _eval(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        if self.poly_patch is not None and order <= 1:
            return self._poly_patch(u, v, order)
        if self.patches is not None and order <= 1:
            return _rational(self._patch_hom(u, v, order), order)
        su, Nu = _basis(self.U, self.pu, u, order)
        sv, Nv = _basis(self.V, self.pv, v, order)
        H = self._hom(su, Nu[0], sv, Nv[0], 0, 0)
        W = H[:, 3:4]
        S = H[:, :3] / W
        if order == 0:
            return [S]
        Hu, Hv = self._hom(su, Nu[1], sv, Nv[0], 1, 0), self._hom(su, Nu[0], sv, Nv[1], 0, 1)
        Su = (Hu[:, :3] - Hu[:, 3:4] * S) / W
        Sv = (Hv[:, :3] - Hv[:, 3:4] * S) / W
        if order == 1:
            return [S, Su, Sv]
        Huu = self._hom(su, Nu[2], sv, Nv[0], 2, 0)
        Hvv = self._hom(su, Nu[0], sv, Nv[2], 0, 2)
        Huv = self._hom(su, Nu[1], sv, Nv[1], 1, 1)
        Suu = (Huu[:, :3] - 2 * Hu[:, 3:4] * Su - Huu[:, 3:4] * S) / W
        Svv = (Hvv[:, :3] - 2 * Hv[:, 3:4] * Sv - Hvv[:, 3:4] * S) / W
        Suv = (Huv[:, :3] - Hu[:, 3:4] * Sv - Hv[:, 3:4] * Su - Huv[:, 3:4] * S) / W
        return [S, Su, Sv, Suu, Svv, Suv]


    def _poly_patch(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """``[S]`` or ``[S, S_u, S_v]`` of one polynomial patch (:attr:`poly_patch`): the tensor
        Chebyshev rows ``T_e(x) T_f(y)`` (and ``T'_e T_f / h_u``, ``T_e T'_f / h_v``) of all points
        stacked into one matrix product with ``Q`` (continued polynomially outside the patch)."""
        Q, cu, hu, cv, hv = self.poly_patch  # type: ignore[misc]
        Tu = _cheb_rows((u - cu) / hu, self.pu, order, hu)
        Tv = _cheb_rows((v - cv) / hv, self.pv, order, hv)
        A, B, n = self.pu + 1, self.pv + 1, u.size
        if order == 0:
            return [((Tu[0][:, None, :] * Tv[0][None, :, :]).reshape(A * B, n)).T @ Q]
        K = np.empty((A, B, 3, n))
        np.multiply(Tu[0][:, None, :], Tv[0][None, :, :], out=K[:, :, 0])
        np.multiply(Tu[1][:, None, :], Tv[0][None, :, :], out=K[:, :, 1])
        np.multiply(Tu[0][:, None, :], Tv[1][None, :, :], out=K[:, :, 2])
        R = K.reshape(A * B, 3 * n).T @ Q  # (3n, 3): S, S_u, S_v
        return [R[:n], R[n:2 * n], R[2 * n:]]

    def density_grid(self, s: np.ndarray, v: np.ndarray) -> np.ndarray | None:
        """Area density ``|S_u × S_v|`` on the grid ``s × v``, shape (len(s), len(v)), from the
        patches: the u-series once per s, then one small product per v-span (coordinates kept
        component-major); None without patches."""
        if self.patches is None:
            return None
        starts_u, cu, hu, starts_v, cv, hv, pt = self.patches
        A, B = self.pu + 1, self.pv + 1
        iu = np.minimum(np.maximum(np.searchsorted(starts_u, s, side="right") - 1, 0), starts_u.size - 1)
        iv = np.minimum(np.maximum(np.searchsorted(starts_v, v, side="right") - 1, 0), starts_v.size - 1)
        Tu = _cheb_t((s - cu[iu]) / hu[iu], self.pu, 1, hu[iu])
        Tv = _cheb_t((v - cv[iv]) / hv[iv], self.pv, 1, hv[iv])
        # equal weights: S_u = A_u / w, S_v = A_v / w, the density needs neither S nor W
        K = 3 if self.weight is not None else 4
        if starts_u.size == 1:  # one u-span: no per-point copy of its coefficients
            P = pt.reshape(1, starts_v.size, A, B, 4)[0][..., :K]  # (v-span, e, f, k)
            G = [np.ascontiguousarray(np.einsum("ie,sefk->skif", T, P)) for T in Tu]  # (v-span, k, i, f)
        else:
            P = pt.reshape(starts_u.size, starts_v.size, A, B, 4)[iu][..., :K]  # (i, v-span, e, f, k)
            G = [np.ascontiguousarray(np.einsum("ie,isefk->skif", T, P)) for T in Tu]
        ms, mv = s.size, v.size
        if K == 3 and self.pv == 1 and starts_v.size == 1:
            # degree 1 in v: S_u = U0 + y U1 (y = the patch's Chebyshev variable, T_1(y) = y) and
            # S_v = V1 / h_v do not depend on v beyond that, so |S_u × S_v|² = a + b y + c y² with
            # C0 = U0 × S_v, C1 = U1 × S_v, a = |C0|², b = 2 C0·C1, c = |C1|², per s only
            U0, U1 = G[1][0][..., 0], G[1][0][..., 1]  # (k, i)
            Sv = G[0][0][..., 1] / hv[0]
            C0 = np.stack([U0[1] * Sv[2] - U0[2] * Sv[1], U0[2] * Sv[0] - U0[0] * Sv[2], U0[0] * Sv[1] - U0[1] * Sv[0]])
            C1 = np.stack([U1[1] * Sv[2] - U1[2] * Sv[1], U1[2] * Sv[0] - U1[0] * Sv[2], U1[0] * Sv[1] - U1[1] * Sv[0]])
            scale = 1.0 / (self.weight * self.weight)  # type: ignore[operator]
            abc = np.stack([np.einsum("ki,ki->i", C0, C0), 2.0 * np.einsum("ki,ki->i", C0, C1),
                            np.einsum("ki,ki->i", C1, C1)], axis=1) * scale  # (i, 3)
            y = Tv[0][:, 1]
            r = abc @ np.stack([np.ones_like(y), y, y * y])  # a + b y + c y² on the grid, one product
            return np.sqrt(np.maximum(r, 0.0, out=r), out=r)
        keys = ((1, 0), (0, 1)) if K == 3 else ((0, 0), (1, 0), (0, 1))
        spans = np.unique(iv)
        if spans.size == 1:  # one v-span: (k i, f) @ (f, j) is already component-major
            sv = int(spans[0])
            H = {(ku, kv): (G[ku][sv].reshape(K * ms, B) @ Tv[kv].T).reshape(K, ms, mv) for ku, kv in keys}
        else:
            H = {key: np.empty((K, ms, mv)) for key in keys}
            for sv in spans.tolist():
                sel = np.nonzero(iv == sv)[0]
                for (ku, kv), out in H.items():
                    out[:, :, sel] = (G[ku][sv].reshape(K * ms, B) @ Tv[kv][sel].T).reshape(K, ms, sel.size)
        if K == 3:
            Su, Sv = H[(1, 0)], H[(0, 1)]
            scale = 1.0 / (self.weight * self.weight)
        else:
            W = H[(0, 0)][3]
            S = H[(0, 0)][:3] / W
            Su = (H[(1, 0)][:3] - H[(1, 0)][3] * S) / W
            Sv = (H[(0, 1)][:3] - H[(0, 1)][3] * S) / W
            scale = 1.0
        cx = Su[1] * Sv[2] - Su[2] * Sv[1]
        cy = Su[2] * Sv[0] - Su[0] * Sv[2]
        cz = Su[0] * Sv[1] - Su[1] * Sv[0]
        r = cx * cx + cy * cy + cz * cz
        if scale != 1.0:
            r *= scale
        return np.sqrt(r, out=r)

    def _patch_hom(self, u: np.ndarray, v: np.ndarray, order: int) -> dict[tuple[int, int], np.ndarray]:
        """``∂^ku_u ∂^kv_v H`` for ku + kv <= order from the Chebyshev patches: on the knot-span
        patch of (u, v), ``H = Σ_e Σ_f T_e(x) T_f(y) P_ef`` with ``x = (u - c_u) / h_u``,
        ``y = (v - c_v) / h_v`` (the end patches continued outside the knot range)."""
        starts_u, cu, hu, starts_v, cv, hv, pt = self.patches  # type: ignore[misc]
        iu = np.minimum(np.maximum(np.searchsorted(starts_u, u, side="right") - 1, 0), starts_u.size - 1)
        iv = np.minimum(np.maximum(np.searchsorted(starts_v, v, side="right") - 1, 0), starts_v.size - 1)
        Tu = _cheb_t((u - cu[iu]) / hu[iu], self.pu, order, hu[iu])
        Tv = _cheb_t((v - cv[iv]) / hv[iv], self.pv, order, hv[iv])
        nsu, nsv, A, B = starts_u.size, starts_v.size, self.pu + 1, self.pv + 1
        out = {}
        if nsu == 1 and nsv == 1:
            # one patch (a Bézier surface, a B-spline without interior knots): plain 2-D products
            M = self.patches_u  # (e, (f, k))
            for ku in range(order + 1):
                X = (Tu[ku] @ M).reshape(u.size, B, 4)
                for kv in range(order + 1 - ku):
                    T = Tv[kv]
                    h = T[:, 0, None] * X[:, 0]
                    for f in range(1, B):
                        h += T[:, f, None] * X[:, f]
                    out[(ku, kv)] = h
            return out
        P = np.take(pt, iu * starts_v.size + iv, axis=0).reshape(u.size, self.pu + 1, self.pv + 1, 4)
        for ku in range(order + 1):
            tmp = np.einsum("ne,nefk->nfk", Tu[ku], P)
            for kv in range(order + 1 - ku):
                out[(ku, kv)] = np.einsum("nf,nfk->nk", Tv[kv], tmp)
        return out


def _rational(H: dict[tuple[int, int], np.ndarray], order: int) -> list[np.ndarray]:
    """``[S]``, ``[S, S_u, S_v]`` or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` from the homogeneous
    derivatives ``H[(ku, kv)] = (A, W)`` (class doc of :class:`_Nurbs`)."""
    W = H[(0, 0)][:, 3:4]
    S = H[(0, 0)][:, :3] / W
    if order == 0:
        return [S]
    Hu, Hv = H[(1, 0)], H[(0, 1)]
    Su = (Hu[:, :3] - Hu[:, 3:4] * S) / W
    Sv = (Hv[:, :3] - Hv[:, 3:4] * S) / W
    if order == 1:
        return [S, Su, Sv]
    Huu, Hvv, Huv = H[(2, 0)], H[(0, 2)], H[(1, 1)]
    Suu = (Huu[:, :3] - 2 * Hu[:, 3:4] * Su - Huu[:, 3:4] * S) / W
    Svv = (Hvv[:, :3] - 2 * Hv[:, 3:4] * Sv - Hvv[:, 3:4] * S) / W
    Suv = (Huv[:, :3] - Hu[:, 3:4] * Sv - Hv[:, 3:4] * Su - Huv[:, 3:4] * S) / W
    return [S, Su, Sv, Suu, Svv, Suv]


def _array1(arr: Any) -> np.ndarray:
    """A ``TColStd_Array1OfReal`` as a numpy array (read once, whatever its bounds)."""
    return np.array([arr.Value(i) for i in range(arr.Lower(), arr.Upper() + 1)], dtype=float)


def _spans(U: np.ndarray, p: int) -> np.ndarray:
    """Indices i of the non-empty knot spans ``U_i < U_{i+1}``, p <= i < m."""
    i = np.arange(p, U.size - p - 1)
    return i[U[i + 1] > U[i]]


def _cheb_basis_of(U: np.ndarray, p: int) -> np.ndarray:
    """:func:`_cheb_basis` on all non-empty spans of the knot vector ``U``, remembered for the
    last 64 knot vectors (a pure function of them; faces share a few, e.g. Bézier knots)."""
    return _cheb_basis_cached(np.asarray(U, dtype=float).tobytes(), int(p))


@functools.lru_cache(maxsize=64)
def _cheb_basis_cached(key: bytes, p: int) -> np.ndarray:
    U = np.frombuffer(key, dtype=float)
    M = _cheb_basis(U, p, _spans(U, p))
    M.flags.writeable = False
    return M


def _cheb_basis(U: np.ndarray, p: int, spans: np.ndarray) -> np.ndarray:
    """Chebyshev coefficients ``M[s, e, a]`` of the non-zero basis functions ``N_{i-p+a, p}`` on each
    span ``i = spans[s]`` in the local variable ``x = (u - c) / h`` ∈ [-1, 1]: interpolation at the
    p+1 first-kind Chebyshev points (exact: the pieces are polynomials of degree p)."""
    k = np.arange(p + 1)
    xk = np.cos(np.pi * (k + 0.5) / (p + 1))
    c, h = 0.5 * (U[spans] + U[spans + 1]), 0.5 * (U[spans + 1] - U[spans])
    uk = (c[:, None] + h[:, None] * xk[None, :]).ravel()
    _, lev = _basis(U, p, uk, 0)
    N = lev[0].reshape(spans.size, p + 1, p + 1)  # (s, node k, a)
    T = np.cos(np.outer(k, np.pi * (k + 0.5) / (p + 1)))  # T_e(x_k), (e, k)
    M = (2.0 / (p + 1)) * np.einsum("ek,ska->sea", T, N)
    M[:, 0, :] *= 0.5
    return M


def _cheb_rows(x: np.ndarray, p: int, order: int, h: float) -> list[np.ndarray]:
    """``[T_e(x)]`` and, for ``order`` 1, ``[d/du T_e]`` (``x = (u - c) / h``, h one number), each
    (p+1, n) with one row per e: the recurrences of :func:`_cheb_t` along contiguous rows."""
    T = np.empty((p + 1, x.size))
    T[0] = 1.0
    if p >= 1:
        T[1] = x
    x2 = 2.0 * x
    for e in range(1, p):
        np.multiply(x2, T[e], out=T[e + 1])
        T[e + 1] -= T[e - 1]
    if order < 1:
        return [T]
    D = np.empty_like(T)
    D[0] = 0.0
    if p >= 1:
        D[1] = 1.0
    for e in range(1, p):
        D[e + 1] = 2.0 * T[e] + x2 * D[e] - D[e - 1]
    D *= 1.0 / h
    return [T, D]


def _cheb_t(x: np.ndarray, p: int, order: int, h: np.ndarray) -> list[np.ndarray]:
    """``[T_e(x)]``, then ``d/du`` and ``d²/du²`` of them (``x = (u - c) / h``), each (n, p+1), by
    the recurrences ``T_{e+1} = 2x T_e - T_{e-1}``, ``T'_{e+1} = 2 T_e + 2x T'_e - T'_{e-1}``,
    ``T''_{e+1} = 4 T'_e + 2x T''_e - T''_{e-1}``."""
    n = x.size
    out = [np.empty((n, p + 1)) for _ in range(order + 1)]
    T = out[0]
    T[:, 0] = 1.0
    if p >= 1:
        T[:, 1] = x
    x2 = 2.0 * x
    for e in range(1, p):
        T[:, e + 1] = x2 * T[:, e] - T[:, e - 1]
    if order >= 1:
        D = out[1]
        D[:, 0] = 0.0
        if p >= 1:
            D[:, 1] = 1.0
        for e in range(1, p):
            D[:, e + 1] = 2.0 * T[:, e] + x2 * D[:, e] - D[:, e - 1]
    if order >= 2:
        D2 = out[2]
        D2[:, 0] = 0.0
        if p >= 1:
            D2[:, 1] = 0.0
        for e in range(1, p):
            D2[:, e + 1] = 4.0 * out[1][:, e] + x2 * D2[:, e] - D2[:, e - 1]
    for k in range(1, order + 1):
        out[k] /= (h ** k)[:, None]
    return out


def _basis(U: np.ndarray, p: int, x: np.ndarray, kmax: int) -> tuple[np.ndarray, list[np.ndarray | None]]:
    """Knot spans ``i`` of ``x`` (``U_i <= x < U_{i+1}``, clipped to [p, m-1]) and, for k = 0..kmax,
    the non-zero basis functions of degree ``p - k`` there, ``N_{i-p+k .. i, p-k}(x)`` (n, p-k+1);
    None where ``k > p`` (Cox–de Boor triangle, NURBS book A2.2, vectorized over x)."""
    m = U.size - p - 1
    span = np.minimum(np.maximum(np.searchsorted(U, x, side="right") - 1, p), m - 1)
    levels = [np.ones((x.size, 1))]
    if p == 0:
        return span, [levels[0]] + [None] * kmax
    # right_r = U_{i+r} - x, left_r = x - U_{i+1-r} for r = 1..p
    right = np.take(U, span[:, None] + np.arange(1, p + 1)[None, :]) - x[:, None]
    left = x[:, None] - np.take(U, span[:, None] + 1 - np.arange(1, p + 1)[None, :])
    for j in range(1, p + 1):
        r = right[:, :j]  # right[r+1], r = 0..j-1
        lf = left[:, j - 1::-1]  # left[j-r]
        temp = levels[-1] / (r + lf)
        nxt = np.zeros((x.size, j + 1))
        nxt[:, :j] = r * temp
        nxt[:, 1:] += lf * temp
        levels.append(nxt)
    return span, [levels[p - k] if k <= p else None for k in range(kmax + 1)]


def _diff_net(net: np.ndarray, knots: np.ndarray, p: int, k: int, axis: int) -> np.ndarray:
    """The k-th difference net along ``axis`` from the (k-1)-th: ``(p-k+1) (C_{i+1} - C_i) /
    (U_{i+p+1} - U_{i+k})`` (0 where the knot difference is 0: those basis functions vanish)."""
    n = net.shape[axis]
    i = np.arange(n - 1)
    den = knots[i + p + 1] - knots[i + k]
    fac = np.where(den > 0, (p - k + 1) / np.where(den > 0, den, 1.0), 0.0)
    shape = [1, 1, 1]
    shape[axis] = n - 1
    return np.diff(net, axis=axis) * fac.reshape(shape)


class FaceRuledSurface(_core.FaceRuledSurface):
    r"""The ruled surface of a face whose ``ruled``-isolines are straight lines
    (:class:`ght_cad.face_unroll.FaceRuledSurface` of a ``BRepAdaptor_Surface``).

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
        < 1e-9, see :func:`ght_cad.face_unroll.isoline_stats`; a closed isoline deviates by ``1/(2π)``), ``"u"``
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
    if kind == GeomAbs_Line:
        lin = c.Line()
        Pc, Dc = lin.Location().Coord(), lin.Direction().Coord()
        P, D = np.array(Pc), np.array(Dc)

        def f(p: np.ndarray) -> np.ndarray:
            return P + p[:, None] * D

        def f1(x: float) -> list[float]:  # the same formula at one parameter, in plain floats
            return [a + x * b for a, b in zip(Pc, Dc)]
        scale = max(1.0, *(abs(x) for x in Pc))
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
        nc = _NurbsCurve.of(c, dim)
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


class _NurbsCurve:
    r"""A (rational) B-spline or Bézier curve adaptor (2-D or 3-D) read once from OCCT and evaluated
    in numpy: homogeneous poles ``C_i = (w_i P_i, w_i)``, ``H(p) = Σ_a N_{i-d+a, d}(p) C_{i-d+a}``
    (Cox–de Boor, :func:`_basis`), ``H' = Σ_a N_{i-d+1+a, d-1}(p) C'_{i-d+a}`` with the difference
    poles ``C'_i = d (C_{i+1} - C_i) / (U_{i+d+1} - U_{i+1})``; ``P = A / W``,
    ``P' = (A' - W' P) / W``. Periodic curves: None (left to OCCT)."""

    def __init__(self, knots: np.ndarray, degree: int, cw: np.ndarray) -> None:
        self.U, self.p, self.cw = knots, degree, cw
        self.d1 = _diff_net(cw[:, None, :], knots, degree, 1, 0)[:, 0, :] if degree >= 1 else None

    @classmethod
    def of(cls, c: Any, dim: int) -> "_NurbsCurve | None":
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
        return cls(U, p, cw)

    def _hom(self, x: np.ndarray, order: int) -> list[np.ndarray]:
        span, lev = _basis(self.U, self.p, x, order)
        out = []
        for k, net in zip(range(order + 1), (self.cw, self.d1)):
            if lev[k] is None or net is None:
                out.append(np.zeros((x.size, self.cw.shape[1])))
                continue
            idx = (span - self.p)[:, None] + np.arange(lev[k].shape[1])[None, :]
            out.append(np.einsum("na,nak->nk", lev[k], np.take(net, idx, axis=0)))
        return out

    def value(self, x: np.ndarray) -> np.ndarray:
        """Points at the curve parameters ``x``, (n, dim)."""
        x = np.asarray(x, dtype=float).ravel()
        H = self._hom(x, 0)[0]
        return H[:, :-1] / H[:, -1:]

    def derivative(self, x: np.ndarray) -> np.ndarray:
        """First derivatives at ``x``, (n, dim)."""
        x = np.asarray(x, dtype=float).ravel()
        H, H1 = self._hom(x, 1)
        W = H[:, -1:]
        P = H[:, :-1] / W
        return (H1[:, :-1] - H1[:, -1:] * P) / W


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
    numpy (:func:`_curve_eval`, :class:`_NurbsCurve`),
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
    """Unroll one build123d/cadquery/OCP face by :func:`ght_cad.face_unroll.unroll_face_data`
    (closed forms for plane/cylinder/cone, quadrature along the rulings otherwise; see module doc).

    Args:
        face: a Face (build123d, cadquery) or TopoDS_Face (or a shape holding exactly one face).
        best_effort, tol_deg, rulings, samples, units, label: as for
            :func:`ght_cad.face_unroll.unroll_face_data` (flatten a non-developable face with a
            distortion report; largest θ_max in degrees; bend lines; points per edge; length
            unit; panel label).
        sheet: a :class:`ght_cad.sheet.Sheet`: unroll the face's neutral surface (side relative
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


def face_data(f: TopoDS_Face, ev: _SurfEval, bounds: tuple[float, float, float, float]) -> FaceData:
    """The face as :class:`ght_cad.face_unroll.FaceData`: every wire (outer first) traversed by
    ``BRepTools_WireExplorer``, each edge's pcurve, 3-D curve and length (:func:`_edge_samples`)."""
    wires = []
    for w in _wires(f):
        loop = []
        exp = BRepTools_WireExplorer(w, f)
        k = 0
        while exp.More():
            e = exp.Current()
            uvf, xyzf, L3, duvf = _edge_samples(e, f, e.Orientation() == TopAbs_REVERSED)
            loop.append(EdgeData(uv=uvf, duv=duvf, xyz=xyzf, length_3d=L3, breaks=duvf.breaks, name=f"edge{k}"))
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
