r"""Flat pattern (development) of a developable feature or ruled face, with bend lines (spec 6).

The source is a developable feature of this workbench (its exact core surface is unrolled) or
any face on a non-rational B-spline surface of degree 1 in one direction (a ruled face, e.g. one
re-imported from STEP): its two boundary pole rows give ``a(u)`` and ``b(u)`` exactly.
:func:`ght_cad.unroll` develops it by quadrature along the rulings (near machine precision);
every boundary edge of the pattern is fitted as a planar B-spline edge (straight ones become
line segments) and the interior rulings become bend-line edges. The shape is a compound of the
planar face and the bend lines in the XY plane (move it with ``Placement``).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

import FreeCAD as App
import Part

from ._base import BaseCommand, FeatureProxy, ViewProviderBase, new_feature, register_command, set_read_only
from .convert import edge_from_data

__all__ = ["FlatPatternFeature", "make_flat_pattern", "surface_of_source", "ruled_surface_from_face"]


def ruled_surface_from_face(face: "Part.Face") -> Any:
    """Exact :class:`ght_cad.ruled.FunctionRuledSurface` of a ruled non-rational B-spline face.

    Raises:
        ValueError: the face is not on a B-spline surface of degree 1 with 2 poles in u or v.
    """
    from ght_cad.bspline import BSplineCurveData
    from ght_cad.ruled import FunctionRuledSurface

    surf = face.Surface
    if not isinstance(surf, Part.BSplineSurface):
        surf = face.toNurbs().Faces[0].Surface
    if surf.isURational() or surf.isVRational():
        raise ValueError("rational B-spline faces are not supported; convert to a non-rational ruled face")
    poles = np.array([[[p.x, p.y, p.z] for p in row] for row in surf.getPoles()])

    def full(knots: list, mults: list) -> np.ndarray:
        k = np.repeat(np.asarray(knots, dtype=float), np.asarray(mults, dtype=int))
        return (k - k[0]) / (k[-1] - k[0])

    if surf.VDegree == 1 and surf.NbVPoles == 2:
        knots, degree = full(surf.getUKnots(), surf.getUMultiplicities()), surf.UDegree
        rows = poles[:, 0], poles[:, 1]
    elif surf.UDegree == 1 and surf.NbUPoles == 2:
        knots, degree = full(surf.getVKnots(), surf.getVMultiplicities()), surf.VDegree
        rows = poles[0], poles[1]
    else:
        raise ValueError(
            f"the face is not ruled: B-spline degrees ({surf.UDegree}, {surf.VDegree}) with "
            f"{surf.NbUPoles}x{surf.NbVPoles} poles; need degree 1 with 2 poles in one direction"
        )
    da, db = BSplineCurveData(rows[0], knots, degree), BSplineCurveData(rows[1], knots, degree)
    return FunctionRuledSurface(lambda u, r: da.evaluate(u, r), lambda u, r: db.evaluate(u, r))


def surface_of_source(obj: Any) -> Any:
    """Core ruled surface of the flat pattern's ``Source`` (feature proxy surface, else the face)."""
    src, subs = obj.Source if obj.Source else (None, [])
    if src is None:
        raise ValueError(f"{obj.Label}: no Source linked")
    subs = [s for s in (subs or []) if s]
    if not subs and hasattr(getattr(src, "Proxy", None), "surface"):
        return src.Proxy.surface(src)
    face = src.Shape.getElement(subs[0]) if subs else (src.Shape.Faces[0] if len(src.Shape.Faces) == 1 else None)
    if face is None:
        raise ValueError(f"{src.Label} has {len(src.Shape.Faces)} faces; select one face")
    return ruled_surface_from_face(face)


def _planar_edge(f: Callable[[np.ndarray], np.ndarray], tol: float) -> "Part.Edge":
    """Edge of the planar curve ``f(t)`` (t ∈ [0, 1], 2-D points), exact end points."""
    from ght_cad.bspline import fit_function

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


class FlatPatternFeature(FeatureProxy):
    """Proxy of a flat pattern (``Part::FeaturePython``)."""

    Type = "GHT::FlatPattern"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkSub", "Source", "Input", "A developable feature, or a ruled B-spline face")
        obj.addProperty("App::PropertyInteger", "BendLines", "Input", "Number of interior rulings drawn as bend lines")
        obj.BendLines = 8
        obj.addProperty("App::PropertyBool", "BestEffort", "Input", "Flatten even if the source is not developable (see MaxRelativeError)")
        obj.addProperty("App::PropertyFloat", "AreaFlat", "Output", "Area of the pattern")
        obj.addProperty("App::PropertyFloat", "Area3D", "Output", "Area of the 3-D surface")
        obj.addProperty("App::PropertyFloat", "MaxRelativeError", "Output", "Largest relative error of boundary lengths, ruling lengths and area (flat vs 3-D)")
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, ("AreaFlat", "Area3D", "MaxRelativeError"))

    def pattern(self, obj: Any) -> Any:
        """The core :class:`ght_cad.flat_pattern.FlatPattern` of the source."""
        from ght_cad import unroll

        return unroll(surface_of_source(obj), rulings=max(int(obj.BendLines), 0), best_effort=bool(obj.BestEffort), samples=65)

    def compute(self, obj: Any) -> None:
        pat = self.pattern(obj)
        lo = np.min([p.bbox()[0] for p in pat.panels], axis=0)
        hi = np.max([p.bbox()[1] for p in pat.panels], axis=0)
        tol = 1e-9 * max(float(np.linalg.norm(hi - lo)), 1e-300)
        faces = []
        for panel in pat.panels:
            wires = []
            for loop in panel.loops:
                edges = [_planar_edge(lambda t, e=e, off=panel.offset: np.asarray(e.flat_fn(t), float) + off, tol) for e in loop]
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
        obj.Shape = Part.makeCompound(faces + bends)


class ViewProviderFlatPattern(ViewProviderBase):
    icon_name = "GHT_FlatPattern"
    shape_color = (0.91, 0.85, 0.66)
    line_color = (0.7, 0.1, 0.1)


def make_flat_pattern(source: Any, sub: str = "", bend_lines: int = 8, *, doc: Any = None, name: str = "FlatPattern") -> Any:
    """Create the flat pattern of a developable feature (or of its face ``sub``)."""
    obj = new_feature(doc or source.Document, name, FlatPatternFeature, ViewProviderFlatPattern)
    obj.Source = (source, [sub] if sub else [])
    obj.BendLines = int(bend_lines)
    obj.Document.recompute()
    # lay the pattern beside its source (XY plane, to the +x side); later recomputes keep it
    src, flat = source.Shape.BoundBox, obj.Shape.BoundBox
    if src.isValid() and flat.isValid():
        gap = 0.2 * max(src.DiagonalLength, flat.DiagonalLength)
        obj.Placement = App.Placement(App.Vector(src.XMax + gap - flat.XMin, src.YMin - flat.YMin, 0), App.Rotation())
    return obj


class CommandFlatPattern(BaseCommand):
    name = "GHT_FlatPattern"
    icon_name = "GHT_FlatPattern"
    menu_text = "Flat pattern"
    tooltip = (
        "Unroll the selected developable feature or ruled face into a planar face with bend lines "
        "(exact development by quadrature along the rulings); errors vs 3-D in MaxRelativeError."
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
