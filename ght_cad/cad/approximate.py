r"""OCP / build123d / cadquery side of :func:`ght_cad.approximate` (issue 24).

* :func:`face_target`: a face (build123d ``Face``, cadquery ``Face``, OCP ``TopoDS_Face``) as the
  core's :class:`ght_cad.approximation.SurfaceTarget` (its surface read into the core's NURBS
  evaluator where it is a B-spline, else evaluated through OCCT; the face's (u, v) bounding box).
* :func:`panel_faces` / :func:`panels_shell`: the panels as B-spline faces of degree 1 across the
  rulings (:func:`ght_cad.cad.occ.make_face` of each panel's
  :class:`~ght_cad.surfaces.bspline.BSplineSurfaceData`), sewn into one shell with
  ``BRepBuilderAPI_Sewing`` at ``1e-6`` of the size: adjacent panels are lofted from the same seam
  curve and their faces agree along it to the fit tolerance (1e-7 of the size).
"""

from __future__ import annotations

from typing import Any

from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
from OCP.TopAbs import TopAbs_SHELL
from OCP.TopExp import TopExp_Explorer
from ._ocp import TopoDS

from ..approximation import ApproximationResult, SurfaceTarget, approximate
from ..core.errors import ConversionError, GHTError
from .occ import is_valid, make_face
from .unroll_faces import _open_face, shape_faces

__all__ = ["face_target", "shape_target", "step_target", "approximate_face", "panel_faces", "panels_shell"]


def face_target(face: Any) -> SurfaceTarget:
    """The surface of one face as an approximation target (bounds: its (u, v) box), with its
    ``trim`` (:func:`face_trim`: the fraction of the box the face covers, its holes).

    Raises:
        GHTError: a shape with other than one face.
    """
    f, ad, bounds, ev = _open_face(face)
    if ev.kind == "bspline" and getattr(ev, "_nurbs", None) is None:
        ev = _unperiodic(ad, bounds) or ev
    return SurfaceTarget(lambda u, v, k: ev.jet(u, v, min(k, 2)), bounds, f"{ev.kind} face", trim=face_trim(f, bounds))


def face_trim(face: Any, bounds: tuple[float, float, float, float]) -> dict[str, float]:
    r"""How much of its surface's (u, v) box a face covers: ``{"covered": A_face / A_box, "holes": h}``.

    ``A_face``: the face's area (``BRepGProp.SurfaceProperties_s``); ``A_box``: the area of the
    same surface restricted to the face's (u, v) bounds ``bounds``
    (``BRepBuilderAPI_MakeFace(surface, u0, u1, v0, v1)``); ``h``: the face's wires but the outer
    one. A face whose trim is its (u, v) box gives ``covered = 1`` (to the integration's
    round-off) and ``h = 0``.
    """
    from OCP.BRep import BRep_Tool
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_WIRE

    def area(fc: Any) -> float:
        props = GProp_GProps()
        BRepGProp.SurfaceProperties_s(fc, props)
        return abs(float(props.Mass()))

    wires = 0
    exp = TopExp_Explorer(face, TopAbs_WIRE)
    while exp.More():
        wires += 1
        exp.Next()
    mk = BRepBuilderAPI_MakeFace(BRep_Tool.Surface_s(face), *bounds, 1e-7)
    box = area(mk.Face()) if mk.IsDone() else 0.0
    covered = area(face) / box if box > 0 else 1.0
    return {"covered": covered, "holes": max(wires - 1, 0)}


def _unperiodic(ad: Any, bounds: tuple[float, float, float, float]) -> Any:
    """A periodic B-spline surface (OCCT's sphere or torus conversions) as the same surface on
    clamped knots (``SetUNotPeriodic``/``SetVNotPeriodic`` keep the parameters), read into the
    core's NURBS evaluator: the evaluator of a face on it, or None when that fails."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.Geom import Geom_BSplineSurface

    g = ad.BSpline().Copy()
    if not isinstance(g, Geom_BSplineSurface):
        g = Geom_BSplineSurface.DownCast(g) if hasattr(Geom_BSplineSurface, "DownCast") else None
    if g is None:
        return None
    if g.IsUPeriodic():
        g.SetUNotPeriodic()
    if g.IsVPeriodic():
        g.SetVNotPeriodic()
    mk = BRepBuilderAPI_MakeFace(g, *bounds, 1e-7)
    if not mk.IsDone():
        return None
    ev = _open_face(mk.Face())[3]
    return ev if getattr(ev, "_nurbs", None) is not None else None


def shape_target(shape: Any, face: int = 0) -> SurfaceTarget:
    """:func:`face_target` of face number ``face`` (0-based, in ``TopExp`` order) of a shape.

    Raises:
        GHTError: ``face`` out of range (the message starts ``face=``).
    """
    faces = shape_faces(shape)
    if isinstance(face, bool) or not isinstance(face, int) or not 0 <= face < len(faces):
        raise GHTError(f"face={face!r} is not allowed; the shape has {len(faces)} face(s): use 0..{len(faces) - 1}")
    return face_target(faces[face])


def step_target(path: Any, face: int = 0) -> SurfaceTarget:
    """:func:`shape_target` of a STEP file (``ght-cad approximate`` and the design files' STEP targets).

    Raises:
        GHTError: an unreadable file, or ``face`` out of range.
    """
    from .occ import read_step

    return shape_target(read_step(path), face)


def approximate_face(shape: Any, tol: float, *, face: int = 0, **options: Any) -> ApproximationResult:
    """:func:`ght_cad.approximate` of face number ``face`` (0-based, in ``TopExp`` order) of a shape.

    Raises:
        GHTError: ``face`` out of range, or as :func:`ght_cad.approximate`.
    """
    return approximate(shape_target(shape, face), tol, **options)


def panel_faces(result: ApproximationResult) -> list[Any]:
    """One build123d ``Face`` per panel (B-spline, degree 1 across the rulings).

    Raises:
        ConversionError: a face that fails ``BRepCheck_Analyzer``.
    """
    faces = []
    for i, p in enumerate(result.panels):
        f = make_face(p.surface.data)
        if not is_valid(f):
            raise ConversionError(f"the B-spline face of panel {i + 1} is not a valid B-rep")
        faces.append(f)
    return faces


def panels_shell(result: ApproximationResult, sew_tol: float | None = None) -> Any:
    """The panels sewn into one build123d ``Shell`` (tolerance ``1e-6`` of the target size).

    Raises:
        ConversionError: sewing did not give one valid shell.
    """
    from build123d import Shell

    faces = panel_faces(result)
    tol = float(sew_tol) if sew_tol is not None else 1e-6 * result.size
    sewing = BRepBuilderAPI_Sewing(tol)
    for f in faces:
        sewing.Add(f.wrapped)
    sewing.Perform()
    sewn = sewing.SewedShape()
    if sewn.ShapeType().name == "TopAbs_FACE" and len(faces) == 1:
        from build123d import Face

        return Face(TopoDS.Face_s(sewn))
    exp = TopExp_Explorer(sewn, TopAbs_SHELL)
    shells = []
    while exp.More():
        shells.append(TopoDS.Shell_s(exp.Current()))
        exp.Next()
    if len(shells) != 1:
        raise ConversionError(f"sewing the {len(faces)} panels at {tol:.3g} gave {len(shells)} shells; expected one")
    shell = Shell(shells[0])
    if not is_valid(shell):
        raise ConversionError("the sewn shell of the panels is not a valid B-rep (BRepCheck_Analyzer)")
    return shell
