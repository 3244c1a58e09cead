r"""The sheet as a solid plate (spec 6.1) through OCCT, and plates read back from STEP.

:func:`plate_solid` makes the plate of thickness ``T`` on the material side of the design surface.

* A developable :class:`~ght_cad.surfaces.ruled.RuledSurface` (``method="exact"``, the default) gets its
  plate built exactly: the region ``{X(u, v) + t n(u), t between 0 and σT}`` (n is constant along
  each ruling) is bounded by six ruled B-spline faces from ONE joint fit of the four boundary
  curves ``a, b, a + σT n, b + σT n`` (:func:`ght_cad.sheetmetal.plate.plate_bspline`, tolerance
  ``3e-7 T``): ``inside`` (the design surface), ``outside`` (the offset ``S + σT n``, again
  developable with the same rulings), the two rail walls ``c(u) + t n(u)`` (over a fan's apex
  ``P`` the cone patch between ``P`` and the arc ``P + σT n(u)``) and the two planar end walls.
  Faces that meet share their boundary curves pole for pole; they are sewn
  (``BRepBuilderAPI_Sewing``), made a solid (``BRepBuilderAPI_MakeSolid``), oriented
  (``ShapeFix_Solid``) and checked (``BRepCheck_Analyzer``). A surface with ``breakpoints`` (a
  loft's fans and main part) gets one face per side all the same: its pieces are fitted
  separately and joined with knots of multiplicity p (C0 across the joint rulings), so the faces
  keep their names and a reader finds one inside face to unroll. OCCT's thickening
  (``BRepOffset_MakeOffset``) fails on such C0 faces and at a fan's apex.
* ``method="offset"`` (a RuledSurface's single B-spline face, fit tolerance ``3e-7 T``) and any
  build123d/cadquery/OCP face are thickened by ``BRepOffset_MakeOffset`` (skin mode, thickening:
  the outside face is the offset surface ``S + σ T n``, the side faces are swept along the
  normals of the boundary edges). Faces are classified by the distance of their parameter-box
  centre point from the design surface: below ``T/4`` the inside face, above ``3T/4`` the
  outside face, the rest the edge faces.

A fit deviation ``d`` changes the volume by about ``d / T`` relative, so a thin plate needs a fit
far tighter than the surface's size; measured (:attr:`PlateSolid.volume` against
:func:`ght_cad.sheetmetal.plate.plate_volume`): the exact plates of quarter cylinders, a cone frustum and the
demo strips within 2e-10 to 2.3e-9, the thickened ones within 3e-8 to 1.4e-6; building is 1.3-2x
the time of thickening (30-70 ms against 15-70 ms per plate).

:func:`write_plate_step` writes the solid through XCAF (``STEPCAFControl_Writer``) with the faces
named ``inside``, ``outside`` and ``edge1..edgeN`` (STEP ``ADVANCED_FACE`` names);
:func:`read_step_face_names` reads the names back and :func:`plate_faces` finds the inside and
outside faces of a plate solid read from STEP (by those names, else geometrically: the two largest
faces at a constant distance from each other) and the thickness between them.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepGProp import BRepGProp
from OCP.BRepOffset import BRepOffset_MakeOffset, BRepOffset_Skin
from OCP.BRepTools import BRepTools
from OCP.GeomAbs import GeomAbs_Arc
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf
from OCP.GProp import GProp_GProps
from OCP.BRep import BRep_Tool
from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Face, TopoDS_Shape
from ._ocp import TopoDS

from ..core.errors import GHTError
from ..surfaces.ruled import RuledSurface
from ..sheetmetal.sheet import Sheet, SheetError, make_sheet
from .occ import is_valid, quiet_occt, unwrap

#: how :func:`plate_solid` makes the solid of a RuledSurface: "exact" (its six faces built and sewn)
#: or "offset" (OCCT's thickening of its B-spline face)
PLATE_METHODS = ("exact", "offset")

__all__ = ["PLATE_METHODS", "PlateSolid", "plate_solid", "write_plate_step", "read_step_face_names", "plate_faces", "PlateFaces"]


@dataclass
class PlateSolid:
    """A thickened plate: the solid and its classified faces.

    Attributes:
        solid: the OCP ``TopoDS_Solid``.
        inside: the design face (inside face of the sheet).
        outside: the offset face ``S + σ T n``.
        edges: the side faces (exact plate: ``[wall_a, end1, wall_b, end0]``, the walls over
            boundary a, the end ruling u = 1, boundary b and the end ruling u = 0).
        sheet: the sheet.
        data: the exact plate's :class:`ght_cad.sheetmetal.plate.PlateBSplineData` (None when thickened by
            OCCT).
        surface: the exact plate's design surface (None when thickened by OCCT).
    """

    solid: TopoDS_Shape
    inside: TopoDS_Face
    outside: TopoDS_Face
    edges: list[TopoDS_Face]
    sheet: Sheet
    data: Any = None
    surface: Any = None
    #: the solid's name in STEP (None: unnamed); its faces are then named ``<name>.inside``, ...
    name: str | None = None

    def named_faces(self) -> list[tuple[str, TopoDS_Face]]:
        """``[("inside", f), ("outside", f), ("edge1", f), ...]``, each prefixed ``<name>.`` when the
        plate has a :attr:`name`."""
        pre = f"{self.name}." if self.name else ""
        return [(pre + "inside", self.inside), (pre + "outside", self.outside)] + [
            (f"{pre}edge{i + 1}", f) for i, f in enumerate(self.edges)]

    @property
    def volume(self) -> float:
        """Volume by OCCT's Gauss integration (:func:`ght_cad.cad.occ.volume`): the exact plate's
        by the adaptive rule (``eps = 1e-12``: within 3e-9 of :attr:`closed_form_volume` where the
        default rule was off by up to 9.4e-6), a thickened face's by the default rule."""
        from .occ import volume

        return volume(self.solid, eps=1e-12) if self.data is not None else volume(self.solid)

    @property
    def closed_form_volume(self) -> float | None:
        r"""``V = T A + σ (T²/2) ∫ 2H dA`` of the exact plate's design surface
        (:func:`ght_cad.sheetmetal.plate.plate_volume`); None for a thickened face."""
        if self.surface is None:
            return None
        from ..sheetmetal.plate import plate_volume

        return plate_volume(self.surface, self.sheet)

    def to_build123d(self) -> Any:
        """The solid as a build123d ``Solid``."""
        from build123d import Solid

        return Solid(self.solid)

    def to_cadquery(self) -> Any:
        """The solid as a cadquery ``Solid``."""
        import cadquery as cq

        return cq.Solid(self.solid)


def _faces(shape: TopoDS_Shape) -> list[TopoDS_Face]:
    out = []
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        out.append(TopoDS.Face_s(exp.Current()))
        exp.Next()
    return out


def _centre_area(face: TopoDS_Face) -> tuple[np.ndarray, float]:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    c = props.CentreOfMass()
    return np.array([c.X(), c.Y(), c.Z()]), float(props.Mass())


def _distance_to_surface(face: TopoDS_Face, point: np.ndarray) -> float:
    from OCP.gp import gp_Pnt

    proj = GeomAPI_ProjectPointOnSurf(gp_Pnt(*map(float, point)), BRep_Tool.Surface_s(face))
    return float(proj.LowerDistance()) if proj.NbPoints() else math.inf


def _face_sheet_check(face: TopoDS_Face, sheet: Sheet, label: str) -> None:
    """The core's curvature check on a CAD face (:class:`ght_cad.sheetmetal.sheet.FaceSheet`)."""
    from ..sheetmetal.sheet import FaceSheet
    from .unroll_faces import _open_face, face_data

    f, _, bounds, ev = _open_face(face)
    FaceSheet(face_data(f, ev, bounds), sheet, label)


def plate_solid(
    surface_or_face: Any,
    sheet: Sheet | None = None,
    *,
    thickness: float | None = None,
    k_factor: float | None = None,
    side: str = "normal",
    label: str = "plate",
    method: str = "exact",
) -> PlateSolid:
    r"""The plate of thickness T on the design surface as a valid solid (module doc).

    For a RuledSurface with ``method="exact"`` the solid is the region
    ``{X(u, v) + t n(u) : t between 0 and σT}`` bounded by its six exact faces, volume
    ``V = T A + σ (T²/2) ∫ 2H dA`` (:func:`ght_cad.sheetmetal.plate.plate_volume`).

    Args:
        surface_or_face: a developable :class:`~ght_cad.surfaces.ruled.RuledSurface` (fans and other
            breakpoints included) or a build123d/cadquery/OCP face (thickened by OCCT).
        sheet: the sheet, or give ``thickness``, ``k_factor``, ``side``
            (:func:`ght_cad.sheetmetal.sheet.make_sheet`; K does not change the solid).
        label: name for messages.
        method: for a RuledSurface: ``"exact"`` (the six faces built and sewn, module doc) or
            ``"offset"`` (OCCT's thickening of its single B-spline face; fails on a loft with
            fans). Faces are always thickened by OCCT.

    Returns:
        :class:`PlateSolid` (``BRepCheck_Analyzer`` valid); for the exact plate
        ``edges = [wall_a, end1, wall_b, end0]`` and ``data`` its
        :class:`ght_cad.sheetmetal.plate.PlateBSplineData`.

    Raises:
        SheetError: no thickness, T = 0, or a thickness beyond a bending radius or on the concave
            side of an apex (:func:`ght_cad.sheetmetal.sheet.check_offset`, before OCCT runs).
        GHTError: an unknown ``method``; OCCT failed to make a valid solid.
    """
    if method not in PLATE_METHODS:
        raise GHTError(f"method={method!r} is not allowed; allowed: {', '.join(repr(m) for m in PLATE_METHODS)}")
    if sheet is None:
        sheet = make_sheet(thickness, k_factor, side=side)
    if sheet is None or sheet.is_zero:
        raise SheetError(f"thickness={None if sheet is None else sheet.thickness!r} is not allowed for a solid plate; give a thickness > 0")
    if isinstance(surface_or_face, RuledSurface):
        from ..sheetmetal.sheet import check_offset

        check_offset(surface_or_face, sheet, f"surface {label!r}")
        if method == "exact":
            return _exact_plate(surface_or_face, sheet, label)
        from .developable_faces import developable_face

        face = unwrap(developable_face(surface_or_face, tol=3e-7 * sheet.thickness))
    else:
        shape = unwrap(surface_or_face)
        if not isinstance(shape, TopoDS_Shape) or shape.IsNull():
            raise GHTError(f"cannot thicken a {type(surface_or_face).__name__}; give a RuledSurface or a face")
        faces = _faces(shape)
        if len(faces) != 1:
            raise GHTError(f"the shape has {len(faces)} faces; a plate is made from exactly one face")
        face = faces[0]
        _face_sheet_check(face, sheet, label)
    return _offset_plate(face, sheet, label)


def _offset_plate(face: TopoDS_Face, sheet: Sheet, label: str) -> PlateSolid:
    """The plate of one CAD face by OCCT's thickening (``BRepOffset_MakeOffset``, module doc)."""
    T = sheet.thickness
    # OCCT's offset tolerance: 1e-7 first; a few faces (measured: a quarter cone frustum r 200..400,
    # T = 4, fitted as a degree-5 B-spline) give an invalid solid there and a valid one at 1e-6, so
    # the tolerance is raised step by step up to 1e-5 (far below any sheet tolerance) before refusing.
    solid = None
    for offset_tol in (1e-7, 1e-6, 1e-5):
        with quiet_occt():
            mo = BRepOffset_MakeOffset()
            # skin mode, no intersection/self-intersection, arc joins, thickening (a solid), keep edges
            mo.Initialize(face, sheet.outside_offset, offset_tol, BRepOffset_Skin, False, False, GeomAbs_Arc, True, False)
            mo.MakeOffsetShape()
        if not mo.IsDone():
            raise GHTError(f"OCCT could not thicken {label!r} by thickness={T!r} (BRepOffset error {mo.Error()})")
        solid = mo.Shape()
        if solid.ShapeType() != TopAbs_SOLID:
            exp = TopExp_Explorer(solid, TopAbs_SOLID)
            if not exp.More():
                raise GHTError(f"thickening {label!r} by thickness={T!r} gave no solid")
            solid = TopoDS.Solid_s(exp.Current())
        if is_valid(solid):
            break
    else:
        raise GHTError(f"thickening {label!r} by thickness={T!r} gave an invalid solid (BRepCheck_Analyzer, "
                       f"offset tolerances 1e-7 to 1e-5 tried)")
    inside, outside, edges = None, None, []
    for f in _faces(solid):
        u0, u1, v0, v1 = BRepTools.UVBounds_s(f)  # a point on the face (its centre of mass is not)
        c = np.array(BRepAdaptor_Surface(f).Value(0.5 * (u0 + u1), 0.5 * (v0 + v1)).Coord())
        d = _distance_to_surface(face, c)
        if f.IsSame(face) or d < 0.25 * T:
            inside = f if inside is None else inside
        elif d > 0.75 * T and outside is None:
            outside = f
        else:
            edges.append(f)
    if inside is None or outside is None:
        raise GHTError(f"the thickened plate {label!r} has no inside/outside face pair")
    return PlateSolid(solid, inside, outside, edges, sheet)


def _exact_plate(surface: RuledSurface, sheet: Sheet, label: str) -> PlateSolid:
    """The exact plate of a developable (module doc): the six B-spline faces of
    :func:`ght_cad.sheetmetal.plate.plate_bspline`, sewn, made a solid and oriented."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeSolid, BRepBuilderAPI_Sewing
    from OCP.ShapeFix import ShapeFix_Solid
    from OCP.TopAbs import TopAbs_SHELL

    from ..sheetmetal.plate import plate_bspline
    from .occ import make_face

    T = sheet.thickness
    data = plate_bspline(surface, sheet)
    size = float(data.info["size"])
    faces = []
    for name, d in data.faces:
        f = unwrap(make_face(d))
        if not is_valid(f):
            raise GHTError(f"the {name} face of the plate {label!r} (thickness={T!r}) is not a valid B-rep (BRepCheck_Analyzer)")
        faces.append((name, f))
    # the faces share their boundary curves pole for pole: a sewing tolerance far below T only
    # has to absorb rounding (and must stay below the thickness, the distance of unrelated edges)
    sew_tol = min(1e-6 * max(size, T), 1e-3 * T)
    with quiet_occt():
        sewing = BRepBuilderAPI_Sewing(sew_tol)
        for _, f in faces:
            sewing.Add(f)
        sewing.Perform()
        sewn = sewing.SewedShape()
    shells = []
    exp = TopExp_Explorer(sewn, TopAbs_SHELL)
    while exp.More():
        shells.append(TopoDS.Shell_s(exp.Current()))
        exp.Next()
    if len(shells) != 1 or sewing.NbFreeEdges() or sewing.NbMultipleEdges():
        raise GHTError(f"sewing the six faces of the plate {label!r} (thickness={T!r}) gave {len(shells)} shells, "
                       f"{sewing.NbFreeEdges()} free and {sewing.NbMultipleEdges()} multiple edges; expected one closed shell")
    with quiet_occt():
        solid = BRepBuilderAPI_MakeSolid(shells[0]).Solid()
        fix = ShapeFix_Solid(solid)
        fix.Perform()
        solid = fix.Solid()
    if solid.ShapeType() != TopAbs_SOLID:
        exp = TopExp_Explorer(solid, TopAbs_SOLID)
        if not exp.More():
            raise GHTError(f"the sewn shell of the plate {label!r} (thickness={T!r}) gave no solid")
        solid = TopoDS.Solid_s(exp.Current())
    if not is_valid(solid):
        raise GHTError(f"the exact plate {label!r} (thickness={T!r}) is not a valid solid (BRepCheck_Analyzer)")
    from .occ import volume

    if not volume(solid, eps=1e-6) > 0:
        raise GHTError(f"the exact plate {label!r} (thickness={T!r}) is not oriented outwards (volume <= 0)")
    in_solid = _faces(solid)
    found: dict[str, TopoDS_Face] = {}
    for name, f in faces:
        mod = sewing.Modified(f)
        hit = next((g for g in in_solid if g.IsSame(mod)), None)
        if hit is None:
            raise GHTError(f"the {name} face of the plate {label!r} is missing from the sewn solid")
        found[name] = hit
    return PlateSolid(solid, found["inside"], found["outside"], [found[n] for n in ("wall_a", "end1", "wall_b", "end0") if n in found],
                      sheet, data, surface)


def write_plate_step(plate: PlateSolid | list[PlateSolid], path: str | os.PathLike, *, units: str = "mm",
                     extra: list[Any] | None = None, product: str | None = None) -> str:
    """Write plate solid(s) to STEP with named faces, atomically.

    The solids go through ``STEPControl_Writer``; each face's ``ADVANCED_FACE`` entity (found by
    ``STEPConstruct::FindEntity`` in the writer's finder process) is named ``inside``,
    ``outside`` or ``edge1..edgeN`` (:meth:`PlateSolid.named_faces`; ``<name>.inside``, ... and the
    solid itself ``<name>`` for a plate with a :attr:`PlateSolid.name`).

    Args:
        plate: one plate or several (written as a compound).
        path: target file.
        units: length unit of the coordinates (mm, cm, m, in, ft).
        extra: more shapes written with the plates (e.g. the design's curve edges).
        product: the STEP product's name (default the file name without its suffix).

    Raises:
        GHTError: an invalid solid, an unknown unit or a failed write (the target is untouched).
    """
    from OCP.BRep import BRep_Builder
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPConstruct import STEPConstruct
    from OCP.STEPControl import STEPControl_AsIs
    from OCP.TCollection import TCollection_HAsciiString
    from OCP.TopoDS import TopoDS_Compound

    from ..core.io import atomic_path
    from .occ import STEP_UNITS, _stem, name_products, step_writer

    plates = plate if isinstance(plate, list) else [plate]
    if units not in STEP_UNITS:
        raise GHTError(f"units={units!r} is not a STEP length unit; allowed: {', '.join(STEP_UNITS)}")
    for i, p in enumerate(plates):
        if not is_valid(p.solid):
            raise GHTError(f"plate #{i + 1} is not a valid solid (BRepCheck_Analyzer); not exported to {path}")
    more = [unwrap(x) for x in (extra or [])]
    if len(plates) == 1 and not more:
        shape = plates[0].solid
    else:
        shape = TopoDS_Compound()
        bb = BRep_Builder()
        bb.MakeCompound(shape)
        for p in plates:
            bb.Add(shape, p.solid)
        for x in more:
            bb.Add(shape, x)
    with step_writer(units) as writer:
        writer.Transfer(shape, STEPControl_AsIs)
        name_products(writer, product if product is not None else _stem(path))
        finder = writer.WS().TransferWriter().FinderProcess()
        for p in plates:
            if p.name:  # the solid's MANIFOLD_SOLID_BREP carries the plate's name
                item = STEPConstruct.FindEntity_s(finder, p.solid)
                if item is not None and hasattr(item, "SetName"):
                    item.SetName(TCollection_HAsciiString(p.name))
            for name, f in p.named_faces():
                item = STEPConstruct.FindEntity_s(finder, f)
                if item is None:
                    raise GHTError(f"the STEP entity of face {name!r} was not found; not exported to {path}")
                item.SetName(TCollection_HAsciiString(name))
        with atomic_path(path) as tmp:
            if writer.Write(str(tmp)) != IFSelect_RetDone:
                raise GHTError(f"OCCT failed to write STEP file {path}")
    return str(path)


def read_step_face_names(path: str | os.PathLike) -> tuple[TopoDS_Shape, dict[int, str]]:
    """Read a STEP file: the shape and ``{face index (0-based, TopExp order): name}`` of the faces
    whose ``ADVANCED_FACE`` entity has a non-empty name (e.g. from :func:`write_plate_step`).

    Raises:
        GHTError: the file cannot be read.
    """
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader

    with quiet_occt():
        reader = STEPControl_Reader()
        if reader.ReadFile(str(path)) != IFSelect_RetDone:
            raise GHTError(f"could not read STEP file {path}")
        reader.TransferRoots()
        shape = reader.OneShape()
    tr = reader.WS().TransferReader()
    names: dict[int, str] = {}
    for k, f in enumerate(_faces(shape)):
        # mode 1 finds the face's entity when the root is the solid itself; in a compound (the
        # plate with the design's curve edges) only the search below the roots (-1) finds it
        ent = tr.EntityFromShapeResult(f, 1) or tr.EntityFromShapeResult(f, -1)
        if ent is None:
            continue
        nm = getattr(ent, "Name", None)
        if nm is None:
            continue
        text = nm().ToCString() if nm() is not None else ""
        if text:
            names[k] = text
    return shape, names


@dataclass
class PlateFaces:
    """The inside and outside faces of a plate solid and the thickness between them.

    Attributes:
        inside, outside: the two faces (``TopoDS_Face``); inside = the concave (shorter) one.
        inside_index, outside_index: their 0-based indices among the shape's faces.
        thickness: mean distance of the outside face's points from the inside face's surface.
        spread: max - min of that distance (0 for a true plate).
        how: "names" (STEP face names) or "geometry".
        side: the sheet side relative to the inside face's normal (orientation included).
    """

    inside: TopoDS_Face
    outside: TopoDS_Face
    inside_index: int
    outside_index: int
    thickness: float
    spread: float
    how: str
    side: str
    info: dict[str, Any] = field(default_factory=dict)


def _offset_distance(inner: TopoDS_Face, outer: TopoDS_Face, n: int = 5) -> tuple[np.ndarray, float]:
    """Distances of an n x n grid of points of ``outer`` (inside its UV box, 5 %..95 %) from
    ``inner``'s surface, and the sign of the side relative to inner's face normal."""
    from OCP.gp import gp_Pnt, gp_Vec

    ad = BRepAdaptor_Surface(outer)
    u0, u1, v0, v1 = BRepTools.UVBounds_s(outer)
    surf = BRep_Tool.Surface_s(inner)
    inner_ad = BRepAdaptor_Surface(inner)
    rev = -1.0 if inner.Orientation() == 1 else 1.0  # TopAbs_REVERSED == 1
    dist, signs = [], []
    for a in np.linspace(0.05, 0.95, n):
        for b in np.linspace(0.05, 0.95, n):
            p = ad.Value(u0 + a * (u1 - u0), v0 + b * (v1 - v0))
            proj = GeomAPI_ProjectPointOnSurf(p, surf)
            if not proj.NbPoints():
                continue
            dist.append(proj.LowerDistance())
            uu, vv = proj.LowerDistanceParameters()
            q, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
            inner_ad.D1(uu, vv, q, du, dv)
            nrm = du.Crossed(dv)
            signs.append(rev * (gp_Vec(q, p).Dot(nrm)))
    return np.asarray(dist), (1.0 if np.median(signs) > 0 else -1.0) if signs else 1.0


def plate_faces(shape: Any, names: dict[int, str] | None = None, *, rtol: float = 1e-6) -> PlateFaces | None:
    """Find the inside/outside faces of a plate solid (module doc), or None if it is no plate.

    By names: faces named ``inside`` and ``outside`` (or ``<plate>.inside`` and ``<plate>.outside``
    of one plate name), when they lie at a constant distance (as below; the names then also say
    which is the inside, right where the geometric rule is not: material on the concave side).
    Else geometrically: among pairs of the
    largest faces (each at least a quarter of the largest's area), the pair whose points lie at a
    constant distance (spread <= ``rtol`` × size, distance > 0) from the other's surface; the face
    with the smaller area is the inside (the concave side of a bend).

    Returns:
        :class:`PlateFaces` with the thickness between them (mean of 25 sampled distances).
    """
    faces = _faces(unwrap(shape))
    if len(faces) < 2:
        return None
    areas = [_centre_area(f)[1] for f in faces]
    size = max(math.sqrt(a) for a in areas)
    pairs: list[tuple[int, int, str]] = []
    if names:
        def plate_of(v: str, what: str) -> str | None:
            return "" if v == what else v[: -len(what) - 1] if v.endswith("." + what) else None

        ins = {plate_of(v, "inside"): k for k, v in names.items() if plate_of(v, "inside") is not None}
        outs = {plate_of(v, "outside"): k for k, v in names.items() if plate_of(v, "outside") is not None}
        both = [q for q in ins if q in outs]
        n_in = sum(1 for v in names.values() if plate_of(v, "inside") is not None)
        if len(both) == 1 and n_in == 1:
            pairs.append((ins[both[0]], outs[both[0]], "names"))
    # then by geometry (also when the named pair is not at a constant distance: names written by
    # another tool, or an OCCT-thickened plate whose faces were told apart wrongly)
    big = sorted(range(len(faces)), key=lambda k: -areas[k])
    big = [k for k in big if areas[k] >= 0.25 * areas[big[0]]][:6]
    for i in range(len(big)):
        for j in range(i + 1, len(big)):
            a, b = big[i], big[j]
            inner, outer = (a, b) if areas[a] <= areas[b] else (b, a)
            pairs.append((inner, outer, "geometry"))
    for inner, outer, how in pairs:
        d, sign = _offset_distance(faces[inner], faces[outer])
        if d.size == 0:
            continue
        T = float(np.mean(d))
        spread = float(np.ptp(d))
        if T > 1e-9 * size and spread <= rtol * size:
            return PlateFaces(faces[inner], faces[outer], inner, outer, T, spread, how,
                              "normal" if sign > 0 else "reverse", {"areas": (areas[inner], areas[outer])})
    return None
