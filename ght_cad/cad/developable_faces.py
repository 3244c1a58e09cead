r"""Developable surfaces as B-rep: one B-spline face per strip, shells for composites (spec 5).

A developable strip ``X(u, v) = (1-v) a(u) + v b(u)`` becomes ONE B-spline surface of degree 1
across the rulings (``knots_v = [0, 0, 1, 1]``) whose u-direction poles come from *compatible
directrix poles*: the two boundary curves are fitted TOGETHER as one 6-D function
``f(u) = (a(u), b(u))`` by :func:`ght_cad.surfaces.bspline.fit_function` (one common knot vector, deviation
measured at matched parameters), so pole pair ``i`` of a and b spans one ruling. End values and
derivatives up to order 2 are reproduced exactly (joint rulings and tangent planes of composites
match exactly). Fitting the boundaries separately, or lofting by arc length, would break
developability (spec 5.2).

The developability of a face is measured from the face itself: OCCT normals
(``BRepLProp_SLProps``) at both ends of sampled rulings, ``θ(u) = angle(n(u, v0), n(u, v1))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from OCP.BRep import BRep_Tool
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
from OCP.BRepLProp import BRepLProp_SLProps
from OCP.BRepTools import BRepTools
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.gp import gp_Pnt
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_REVERSED, TopAbs_SHELL
from OCP.TopExp import TopExp, TopExp_Explorer
from ._ocp import TopoDS
from ._ocp import TopTools_IndexedDataMapOfShapeListOfShape

from ..surfaces.bspline import BSplineSurfaceData
from ..developables.envelope import _size, developable_bspline
from ..core.errors import ConversionError, GHTError
from ..surfaces.ruled import RuledSurface
from .occ import is_valid, make_face, shape_class, unwrap

__all__ = [
    "planes_from_build123d",
    "developable_surface_data",
    "developable_face",
    "composite_shell",
    "FaceDevelopability",
    "face_developability",
    "joint_normal_deviation",
    "shell_faces",
    "sew_shell",
]


def planes_from_build123d(plane_or_face: Any) -> np.ndarray:
    r"""Plane 4-vector ``U = (-n·o, n)`` of a build123d ``Plane`` or a planar ``Face``.

    ``n`` is the unit normal (``Plane.z_dir``, or the face's normal with its orientation) and ``o``
    a point of the plane (``Plane.origin``, or the face's centre).

    Raises:
        GHTError: a face that is not planar, or an object that is neither.
    """
    from build123d import Face, GeomType, Plane

    if isinstance(plane_or_face, Plane):
        n = np.array(tuple(plane_or_face.z_dir), dtype=float)
        o = np.array(tuple(plane_or_face.origin), dtype=float)
    elif isinstance(plane_or_face, Face):
        face = plane_or_face
        if face.geom_type != GeomType.PLANE:
            raise GHTError(f"face of type {face.geom_type} is not planar; only planar faces define a plane")
        o = np.array(tuple(face.center()), dtype=float)
        n = np.array(tuple(face.normal_at(face.center())), dtype=float)
    else:
        raise GHTError(
            f"planes_from_build123d needs a build123d Plane or planar Face, got {type(plane_or_face).__name__}"
        )
    n = n / np.linalg.norm(n)
    return np.concatenate([[-float(n @ o)], n])


def developable_surface_data(surface: RuledSurface, **kwargs: Any) -> BSplineSurfaceData:
    """Alias of :func:`ght_cad.developables.envelope.developable_bspline` (core, no CAD kernel needed)."""
    return developable_bspline(surface, **kwargs)


def developable_face(
    surface: RuledSurface,
    *,
    tol: float | None = None,
    degree: int = 5,
    end_order: int = 2,
    theta_tol_deg: float = 1e-3,
) -> Any:
    r"""One valid build123d ``Face``: the B-spline surface of :func:`ght_cad.developables.envelope.developable_bspline`
    (compatible directrix poles, degree 1 across the rulings, θ_max <= ``theta_tol_deg``).

    Raises:
        ConversionError: fit failure or a face that fails ``BRepCheck_Analyzer``.
    """
    data = developable_bspline(surface, tol=tol, degree=degree, end_order=end_order, theta_tol_deg=theta_tol_deg)
    face = make_face(data)
    if not is_valid(face):
        raise ConversionError(f"the B-spline face of {surface!r} is not a valid B-rep (BRepCheck_Analyzer)")
    return face


def composite_shell(composite: Any, *, tol: float | None = None, degree: int = 5, sew_tol: float | None = None) -> Any:
    r"""A build123d ``Shell`` of one developable face per segment, sewn along the joint rulings.

    Joint rulings are exact end poles of both faces (end values are interpolated), so sewing with a
    tolerance of ``1e-6`` times the size merges them into shared edges.

    Args:
        composite: :class:`ght_cad.developables.envelope.CompositeDevelopable` or a sequence of ruled surfaces.
        tol: fit tolerance per face (default relative 1e-7).
        degree: B-spline degree.
        sew_tol: sewing tolerance (default ``1e-6`` times the largest face size).

    Raises:
        ConversionError: sewing did not give one valid shell with ``len(segments) - 1`` shared edges.
    """
    from build123d import Shell

    segs = list(getattr(composite, "segments", composite))
    faces = [developable_face(s, tol=tol, degree=degree) for s in segs]
    if len(faces) == 1:
        return Shell([faces[0]])
    size = max(_size(s) for s in segs)
    return sew_shell(faces, float(sew_tol if sew_tol is not None else 1e-6 * size), len(faces) - 1)


def sew_shell(faces: list, sew_tol: float, shared_edges: int) -> Any:
    """A ``Shell`` (build123d's, else cadquery's) of ``faces`` sewn with ``BRepBuilderAPI_Sewing(sew_tol)``.

    Raises:
        ConversionError: sewing gave no or several shells, a number of shared edges other than
            ``shared_edges`` (the joint rulings), or a shell that fails ``BRepCheck_Analyzer``.
    """
    Shell = shape_class("Shell")

    sewing = BRepBuilderAPI_Sewing(float(sew_tol))
    for f in faces:
        sewing.Add(unwrap(f))
    sewing.Perform()
    sewn = sewing.SewedShape()
    exp = TopExp_Explorer(sewn, TopAbs_SHELL)
    shells = []
    while exp.More():
        shells.append(TopoDS.Shell_s(exp.Current()))
        exp.Next()
    if len(shells) != 1:
        raise ConversionError(f"sewing the {len(faces)} developable faces gave {len(shells)} shells; expected one")
    shell = Shell(shells[0])
    shared = len(_internal_edges(shells[0]))
    if shared != shared_edges:
        raise ConversionError(f"the sewn shell has {shared} shared edges; {shared_edges} joint rulings expected")
    if not is_valid(shell):
        raise ConversionError("the sewn shell is not a valid B-rep (BRepCheck_Analyzer)")
    return shell


# ----------------------------------------------------------------------------------------------
# measurements on B-rep faces
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class FaceDevelopability:
    """Developability of a face measured with OCCT normals at both ends of sampled rulings.

    Attributes:
        theta_max, theta_rms: degrees.
        dd: mean of cos θ.
        rulings: number of sampled rulings.
    """

    theta_max: float
    theta_rms: float
    dd: float
    rulings: int


def _faces_of(shape: Any) -> list[Any]:
    s = unwrap(shape)
    out = []
    exp = TopExp_Explorer(s, TopAbs_FACE)
    while exp.More():
        out.append(TopoDS.Face_s(exp.Current()))
        exp.Next()
    return out


def _normal(adaptor: BRepAdaptor_Surface, u: float, v: float, reversed_: bool) -> np.ndarray:
    props = BRepLProp_SLProps(adaptor, u, v, 1, 1e-12)
    if not props.IsNormalDefined():
        raise GHTError(f"OCCT normal undefined at (u, v) = ({u:g}, {v:g}) of the face")
    n = props.Normal()
    vec = np.array([n.X(), n.Y(), n.Z()])
    return -vec if reversed_ else vec


def _ruling_end_normal(ad: BRepAdaptor_Surface, s: float, w: float, w_other: float, rev: bool, across_u: bool) -> np.ndarray:
    """Normal at the end ``w`` of the ruling at ``s``. Where the boundary curve there is collapsed
    (the apex of a cone-like fan: the derivative across the ruling is below 1e-9 of the one along
    it) the normal is taken ``1e-6`` of the ruling inward: a developable's tangent plane is
    constant along the ruling, so that is the limit normal (OCCT's normal at the singular point
    itself can point anywhere: 70° off on a fan face, so a merely defined normal is not enough)."""
    from OCP.gp import gp_Pnt, gp_Vec

    x = w
    for frac in (0.0, 1e-6):
        x = w + frac * (w_other - w)
        uv = (x, s) if across_u else (s, x)
        p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
        ad.D1(uv[0], uv[1], p, du, dv)
        along, across = (du, dv) if across_u else (dv, du)
        if across.Magnitude() > 1e-9 * along.Magnitude():
            break
    return _normal(ad, *((x, s) if across_u else (s, x)), rev)


def face_developability(face: Any, rulings: int = 129) -> FaceDevelopability:
    r"""θ along the rulings of a face, from OCCT normals at both ends of each ruling.

    The ruling direction is the parameter direction of degree 1 of the face's B-spline surface
    (``BRep_Tool.Surface``); for every sampled parameter ``s`` of the other direction the normals
    ``n(s, w_min)`` and ``n(s, w_max)`` (``BRepLProp_SLProps``) give ``θ(s) = angle``; at an end
    where the boundary is collapsed (the apex of a cone-like fan) the normal ``1e-6`` of the ruling
    inward is used (:func:`_ruling_end_normal`).

    Raises:
        GHTError: a shape without a face, or a surface of degree > 1 in both directions.
    """
    faces = _faces_of(face)
    if len(faces) != 1:
        raise GHTError(f"face_developability needs exactly one face; the shape has {len(faces)}")
    f = faces[0]
    surf = BRep_Tool.Surface_s(f)
    try:
        du, dv = surf.UDegree(), surf.VDegree()
    except AttributeError:
        raise GHTError(f"the face's surface {type(surf).__name__} is not a B-spline surface") from None
    if dv == 1:
        across_u = False
    elif du == 1:
        across_u = True
    else:
        raise GHTError(f"the face's B-spline surface has degrees ({du}, {dv}); no direction is ruled (degree 1)")
    umin, umax, vmin, vmax = BRepTools.UVBounds_s(f)
    ad = BRepAdaptor_Surface(f)
    rev = f.Orientation() == TopAbs_REVERSED
    th = []
    for s in np.linspace(0.0, 1.0, rulings):
        if across_u:  # rulings along u, sample v
            v = vmin + s * (vmax - vmin)
            n0, n1 = _ruling_end_normal(ad, v, umin, umax, rev, True), _ruling_end_normal(ad, v, umax, umin, rev, True)
        else:
            u = umin + s * (umax - umin)
            n0, n1 = _ruling_end_normal(ad, u, vmin, vmax, rev, False), _ruling_end_normal(ad, u, vmax, vmin, rev, False)
        th.append(math.degrees(math.atan2(np.linalg.norm(np.cross(n0, n1)), float(n0 @ n1))))
    t = np.array(th)
    return FaceDevelopability(float(t.max()), float(np.sqrt(np.mean(t**2))), float(np.mean(np.cos(np.radians(t)))), rulings)


def _internal_edges(shell: Any) -> list[tuple[Any, list[Any]]]:
    amap = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(unwrap(shell), TopAbs_EDGE, TopAbs_FACE, amap)
    out = []
    for i in range(1, amap.Extent() + 1):
        faces = [TopoDS.Face_s(x) for x in amap.FindFromIndex(i)]
        # the same face may be listed twice for a seam edge; count distinct faces
        distinct = []
        for fc in faces:
            if not any(fc.IsSame(g) for g in distinct):
                distinct.append(fc)
        if len(distinct) == 2:
            out.append((TopoDS.Edge_s(amap.FindKey(i)), distinct))
    return out


def joint_normal_deviation(shell: Any, samples: int = 33) -> list[float]:
    r"""Largest angle (degrees) between the two faces' normals along every shared edge.

    Points along each edge that two faces share are projected onto both faces' surfaces
    (``GeomAPI_ProjectPointOnSurf``) and the oriented OCCT normals compared: 0 for a
    tangent-plane continuous (G1) joint.

    Returns:
        One maximum angle per shared edge.
    """
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    out = []
    for edge, (fa, fb) in _internal_edges(shell):
        c = BRepAdaptor_Curve(edge)
        t0, t1 = c.FirstParameter(), c.LastParameter()
        worst = 0.0
        for t in np.linspace(t0, t1, samples):
            p = c.Value(float(t))
            ns = []
            for fc in (fa, fb):
                proj = GeomAPI_ProjectPointOnSurf(gp_Pnt(p.X(), p.Y(), p.Z()), BRep_Tool.Surface_s(fc))
                u, v = proj.LowerDistanceParameters()
                ns.append(_normal(BRepAdaptor_Surface(fc), u, v, fc.Orientation() == TopAbs_REVERSED))
            ang = math.degrees(math.atan2(np.linalg.norm(np.cross(ns[0], ns[1])), float(ns[0] @ ns[1])))
            worst = max(worst, ang)
        out.append(worst)
    return out


def shell_faces(shell: Any) -> list[Any]:
    """The faces of a shell (or any shape) as OCP ``TopoDS_Face`` objects."""
    return _faces_of(shell)
