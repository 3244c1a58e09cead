r"""Flat pattern (development) of a developable feature or of any developable face, with bend lines (spec 6).

The source is a developable feature of this workbench (its exact core ruled surface is unrolled
by :func:`ght_cad.unroll`, quadrature along the rulings) or any face of any FreeCAD object whose
surface is developable: the lateral face of a ``Part::Cylinder`` / ``Part::Cone`` (closed-form
maps), a plane, a surface of extrusion, a ruled B-spline or Bézier face (``Part::RuledSurface``,
re-imported STEP), trimmed or with holes. Faces go through the kernel-free
:func:`ght_cad.unrolling.face_unroll.unroll_face_data` (the same code that unrolls build123d/OCP faces)
via the adapter :mod:`.face_reader` (:func:`face_data`): FreeCAD's ``face.Surface`` (B-spline and
Bézier surfaces read into the core's :mod:`ght_cad.surfaces.nurbs`, others evaluated with
``value``/``getDN``), every wire (``OuterWire`` first) in ``OrderedEdges`` order with its pcurve
``face.curveOnSurface(edge)``, the edges' 3-D curves and lengths. The face's real outline and
holes are kept. Non-developable faces (sphere, torus, twisted loft) are refused with the
isolines' deviation or θ_max / DD unless ``BestEffort``.

Sheet metal (spec 6.1): with ``Thickness`` T > 0, ``KFactor`` K and ``Side`` (material along the
face/surface normal or against it) the pattern is the development of the neutral surface
``S ± K T n`` (:mod:`ght_cad.sheetmetal.sheet`); with Thickness 0 and a face of a solid plate (a SheetMetal
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
from ght_cad.unrolling.face_unroll import unroll_face_data

from ._base import BaseCommand, FeatureProxy, ViewProviderBase, info_panel, new_feature, register_command, set_read_only
from .convert import edge_from_data
# the face reader moved to .face_reader (issue 27: sheet_skin uses it without importing this module);
# every name it had here is imported back
from .face_reader import _KINDS, FreeCADSurface, _CurveEval, _Edge, _placement, _vec, face_data, read_curve, read_surface  # noqa: F401

__all__ = [
    "FlatPatternFeature",
    "make_flat_pattern",
    "surface_of_source",
    "face_of_source",
    "face_data",
    "FreeCADSurface",
    "plate_partner",
]

#: the Side property's values (ght_cad.sheetmetal.sheet.SIDES): material along / against the face normal
SIDES = ["normal", "reverse"]

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
        from ght_cad.sheetmetal.sheet import Sheet

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
        """The core :class:`ght_cad.pattern.flat_pattern.FlatPattern` of the source."""
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
        (:func:`ght_cad.sheetmetal.blank.unfold_skins` on the skins :func:`.sheet_skin.sheet_skins` finds):
        bends on their neutral surface at ``KFactor``, the selected face (if any) as base face.

        Raises:
            BlankError: no sheet, a sharp edge, an ambiguous skin, overlapping pieces, a bad face.
        """
        from ght_cad.sheetmetal.blank import BlankError, unfold_skins

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
        # Part::Feature moves its Shape with the new Placement at once; the pattern itself does not
        # change, so the touch the Placement set is cleared instead of computing the pattern again
        # (a second recompute doubled the cost of every new flat pattern)
        obj.Placement = App.Placement(App.Vector(src.XMax + gap - flat.XMin, src.YMin - flat.YMin, 0), App.Rotation())
        obj.purgeTouched()  # returned up to date, as every make_*
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
