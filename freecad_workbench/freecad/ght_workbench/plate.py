r"""The exact solid plate of a developable feature (spec 6.1): six B-spline faces sewn into a solid.

A sheet of thickness ``T`` on the core surface ``X(u, v)`` of a developable feature of this
workbench (``Source``: from planes, joined, loft, spine/geodesic) fills
``{X(u, v) + t n(u) : t between 0 and σT}`` (``σ = +1`` for ``Side = normal``, -1 for ``reverse``;
n is constant along a ruling). :func:`ght_cad.sheetmetal.plate.plate_bspline` gives its six ruled faces as
plain B-spline data (``inside`` = the design surface, ``outside`` = the offset ``X + σT n``, the
walls over the two boundary curves and the two planar end walls; degree 1 across, faces that meet
share their boundary poles exactly); here they become ``Part.BSplineSurface`` faces
(:func:`convert.part_surface`), are sewn (``sewShape`` at ``min(1e-6 max(size, T), 1e-3 T)``, the
OCP adapter's rule, :func:`ght_cad.cad.sheet_solid.plate_solid`), checked to be one closed shell
of 12 shared edges, made a ``Part.Solid``, oriented outwards (``Volume > 0``) and checked
(``isValid()``). This is not OCCT's thickening (``Part::Thickness``), which is approximate and
fails on lofts with fans (cone apexes).

Volumes. ``ClosedFormVolume`` is :func:`ght_cad.sheetmetal.plate.plate_volume`,
``V = T A + σ (T²/2) ∫ 2H dA``. FreeCAD's ``Shape.Volume`` (``ShapeVolume``) integrates each
B-spline face with ONE Gauss rule over its whole parameter box (OCCT's default rule), which reads
the C0 joint rulings of a loft with fans about 1.5e-3 low. ``Volume`` is therefore FreeCAD's
``Shape.Volume`` of a copy whose four long faces are split at every knot of their u direction
(``BSplineSurface.segment``; every piece one polynomial span, integrated exactly by the default
rule's order), the equivalent of the OCP adapter's splitting before it integrates
(:func:`ght_cad.cad.occ.volume`); ``VolumeError = Volume / ClosedFormVolume - 1``.

The Flat pattern feature takes a plate as ``Source`` (the whole feature: its inside face; or any
face of it): with ``Thickness`` 0 and ``ThicknessFromSolid`` it finds the inside face and the
thickness (:func:`flat_pattern.plate_partner`) and uses the plate's ``KFactor``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import FreeCAD as App
import Part

from ght_cad.core.errors import GHTError

from ._base import BaseCommand, FeatureProxy, ViewProviderBase, info_panel, new_feature, register_command, set_read_only

__all__ = ["PlateFeature", "make_plate", "plate_shape", "split_volume", "SIDES", "FACE_NAMES"]

SIDES = ["normal", "reverse"]
#: the solid's faces in ``Shape.Faces`` order (checked after sewing): FaceNames output
FACE_NAMES = ("inside", "outside", "wall_a", "wall_b", "end0", "end1")
OUTPUTS = ("Volume", "ClosedFormVolume", "VolumeError", "ShapeVolume", "MaxDeviation", "FaceNames", "InsideFace")


def _sew(faces: list, tol: float, what: str) -> "Part.Shell":
    """One closed shell of ``faces`` sewn at ``tol`` in which every non-degenerate edge is shared by
    exactly two faces."""
    comp = Part.makeCompound([f.copy() for f in faces])
    comp.sewShape(tol)
    shells = [comp] if comp.ShapeType == "Shell" else comp.Shells
    if len(shells) != 1 or len(shells[0].Faces) != len(faces):
        raise GHTError(f"sewing the {len(faces)} faces of {what} gave {len(shells)} shells; expected one closed shell")
    shell = shells[0]
    free = [e for e in shell.Edges if not e.Degenerated and sum(1 for f in shell.Faces if any(e.isSame(g) for g in f.Edges)) != 2]
    if free or not shell.isClosed():
        raise GHTError(f"sewing the faces of {what} left {len(free)} free or multiple edges; expected one closed shell")
    return shell


def _solid(shell: "Part.Shell", what: str) -> "Part.Solid":
    solid = Part.Solid(shell)
    if solid.Volume < 0:
        solid.reverse()
    if not solid.Volume > 0:
        raise GHTError(f"{what} is not oriented outwards (volume {solid.Volume!r} <= 0)")
    if not solid.isValid():
        raise GHTError(f"{what} is not a valid solid (Shape.isValid() is False)")
    return solid


def sew_tolerance(size: float, thickness: float) -> float:
    """``min(1e-6 max(size, T), 1e-3 T)``: the faces share their poles, so sewing only absorbs
    rounding, and must stay below the thickness (the distance of unrelated edges)."""
    return min(1e-6 * max(size, thickness), 1e-3 * thickness)


def plate_shape(data: Any, thickness: float, what: str = "the plate") -> tuple["Part.Solid", list["Part.BSplineSurface"]]:
    """The solid of :class:`ght_cad.sheetmetal.plate.PlateBSplineData` (module doc) and its six surfaces.

    Raises:
        GHTError: a face that is not a valid B-rep, a shell that does not close, an invalid or
            inside-out solid.
    """
    from .convert import part_surface

    surfaces = [part_surface(d) for _, d in data.faces]
    faces = []
    for (name, _), s in zip(data.faces, surfaces):
        f = Part.Face(s)
        if not f.isValid():
            raise GHTError(f"the {name} face of {what} (thickness={thickness!r}) is not a valid B-rep")
        faces.append(f)
    tol = sew_tolerance(float(data.info["size"]), thickness)
    return _solid(_sew(faces, tol, what), what), surfaces


def split_volume(surfaces: list["Part.BSplineSurface"], tol: float, what: str = "the plate") -> float:
    """FreeCAD's ``Shape.Volume`` of the plate rebuilt with its first four faces split at every
    u knot (module doc): each piece one polynomial span, so OCCT's default Gauss rule (order
    ``2 (p + 1)`` per face) integrates it exactly up to round-off."""
    faces = []
    for s in surfaces[:4]:
        knots = [float(k) for k in s.getUKnots()]
        for lo, hi in zip(knots[:-1], knots[1:]):
            c = s.copy()
            c.segment(lo, hi, 0.0, 1.0)
            faces.append(Part.Face(c))
    faces += [Part.Face(s) for s in surfaces[4:]]
    return float(_solid(_sew(faces, tol, what + " (split at its knots)"), what).Volume)


def _is_plate(obj: Any) -> bool:
    return getattr(getattr(obj, "Proxy", None), "Type", "") == PlateFeature.Type


class PlateFeature(FeatureProxy):
    """Proxy of the exact solid plate of a developable feature (``Part::FeaturePython``)."""

    Type = "GHT::Plate"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLink", "Source", "Input", "A developable feature of this workbench (from planes, joined, loft, spine/geodesic): its surface is the inside face")
        obj.addProperty("App::PropertyLength", "Thickness", "Sheet", "Sheet thickness T > 0")
        obj.Thickness = 1.0
        obj.addProperty("App::PropertyFloat", "KFactor", "Sheet", "ANSI K-factor in [0, 1] for the flat pattern (neutral surface K*T from the inside face); does not change the solid")
        obj.KFactor = 0.5
        obj.addProperty("App::PropertyEnumeration", "Side", "Sheet", "Where the material lies: 'normal' (along the surface normal) or 'reverse' (against it)")
        obj.Side = SIDES
        obj.Side = "normal"
        obj.addProperty("App::PropertyFloat", "Volume", "Output", "Volume by FreeCAD's Shape.Volume on a copy split at the faces' knots (module doc)")
        obj.addProperty("App::PropertyFloat", "ClosedFormVolume", "Output", "T A + σ (T²/2) ∫ 2H dA (ght_cad.plate.plate_volume)")
        obj.addProperty("App::PropertyFloat", "VolumeError", "Output", "Volume / ClosedFormVolume - 1")
        obj.addProperty("App::PropertyFloat", "ShapeVolume", "Output", "FreeCAD's own Shape.Volume of the solid as built (default rule: about 1.5e-3 low on a loft with fans)")
        obj.addProperty("App::PropertyFloat", "MaxDeviation", "Output", "Certified deviation of the faces' boundary curves from the exact ones")
        obj.addProperty("App::PropertyStringList", "FaceNames", "Output", "Name of each face of the solid (Face1..Face6)")
        obj.addProperty("App::PropertyString", "InsideFace", "Output", "The inside (design) face of the solid, e.g. Face1")
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, OUTPUTS)

    # -- the core --------------------------------------------------------------------------
    def design_surface(self, obj: Any) -> Any:
        """The Source's core ruled surface (as :func:`flat_pattern.surface_of_source` reads it).

        Raises:
            GHTError: no Source, or a Source that is not a developable feature of this workbench.
        """
        src = obj.Source
        if src is None:
            raise GHTError(f"{obj.Label}: no Source linked; link a developable feature (from planes, joined, loft, spine/geodesic)")
        proxy = getattr(src, "Proxy", None)
        if not hasattr(proxy, "surface") or getattr(proxy, "Type", "") in ("GHT::FlatPattern", "GHT::Optimization"):
            raise GHTError(f"{obj.Label}.Source = {src.Label} is not a developable feature of this workbench; "
                           "allowed: Developable from planes, Joined developable, Developable loft, Spine/geodesic developable")
        return proxy.surface(src)

    def sheet(self, obj: Any) -> Any:
        """The :class:`ght_cad.sheetmetal.sheet.Sheet` of the properties (T > 0).

        Raises:
            SheetError: T <= 0, K outside [0, 1], an unknown side (naming the property).
        """
        from ght_cad.sheetmetal.sheet import Sheet, SheetError

        T = float(obj.Thickness.Value)
        if not (math.isfinite(T) and T > 0):
            raise SheetError(f"{obj.Label}.Thickness={T!r} mm is not allowed; a plate needs a thickness > 0")
        K = float(obj.KFactor)
        if not (math.isfinite(K) and 0.0 <= K <= 1.0):
            raise SheetError(f"{obj.Label}.KFactor={K!r} is not allowed; the ANSI K-factor lies in [0, 1] (DIN k = 2K)")
        return Sheet(T, K, str(obj.Side))

    def inside_face(self, obj: Any) -> "Part.Face | None":
        """The inside face of the current Shape (the one the Flat pattern unrolls), or None."""
        name = str(getattr(obj, "InsideFace", "") or "")
        k = name[4:] if name.startswith("Face") else ""
        faces = obj.Shape.Faces
        return faces[int(k) - 1] if k.isdigit() and 1 <= int(k) <= len(faces) else None

    def compute(self, obj: Any) -> None:
        from ght_cad.sheetmetal.plate import plate_bspline, plate_volume
        from ght_cad.surfaces.ruled import RuledSurface
        from ght_cad.sheetmetal.sheet import check_offset

        from .joined_developable import core_frame

        surface = self.design_surface(obj)
        if not isinstance(surface, RuledSurface):
            raise GHTError(f"{obj.Label}.Source = {obj.Source.Label} gives a {type(surface).__name__}, not a ruled surface")
        sheet = self.sheet(obj)
        check_offset(surface, sheet, f"{obj.Source.Label}")
        data = plate_bspline(surface, sheet)
        T = sheet.thickness
        solid, surfaces = plate_shape(data, T, f"the plate {obj.Label}")
        # which face of the sewn solid is which: the solid's faces lie on the surfaces (six, or
        # five/four without the end wall of a pointed end: data.faces leaves those out)
        built = [name for name, _ in data.faces]
        names = []
        for f in solid.Faces:  # which surface each face of the sewn solid lies on
            p = f.valueAt(*_mid(f))
            names.append(built[int(np.argmin([(s.value(*s.parameter(p)) - p).Length for s in surfaces]))])
        if sorted(names) != sorted(built):
            raise GHTError(f"the faces of the plate {obj.Label} could not be told apart ({names})")
        tol = sew_tolerance(float(data.info["size"]), T)
        volume = split_volume(surfaces, tol, f"the plate {obj.Label}")
        closed = plate_volume(surface, sheet)
        frame = core_frame(obj.Source)
        if not frame.isIdentity():  # the Source shows its core surface moved by its placement
            solid = solid.transformShape(frame.toMatrix(), True) or solid
        obj.Volume = volume
        obj.ClosedFormVolume = float(closed)
        obj.VolumeError = float(volume / closed - 1.0)
        obj.ShapeVolume = float(solid.Volume)
        obj.MaxDeviation = float(data.max_deviation)
        obj.FaceNames = names
        obj.InsideFace = f"Face{names.index('inside') + 1}"
        obj.Shape = solid


def _mid(face: "Part.Face") -> tuple[float, float]:
    u0, u1, v0, v1 = face.ParameterRange
    return 0.5 * (u0 + u1), 0.5 * (v0 + v1)


class ViewProviderPlate(ViewProviderBase):
    icon_name = "GHT_Plate"
    shape_color = (0.72, 0.74, 0.8)

    def claimChildren(self) -> list:
        s = getattr(self.obj, "Source", None)
        return [s] if s is not None else []


ViewProviderPlate.panel_factory = staticmethod(lambda obj: info_panel(obj, ("Source",), "Edit Thickness, KFactor and Side in the "
                                                                "property editor; Volume vs ClosedFormVolume in VolumeError."))


def make_plate(source: Any, thickness: float = 1.0, k_factor: float = 0.5, side: str = "normal", *, doc: Any = None, name: str = "Plate") -> Any:
    """Create the exact plate of thickness ``thickness`` on the developable feature ``source``."""
    if side not in SIDES:
        raise GHTError(f"side={side!r} is not allowed; use one of {SIDES}")
    obj = new_feature(doc or source.Document, name, PlateFeature, ViewProviderPlate)
    obj.Source = source
    obj.Thickness = float(thickness)
    obj.KFactor = float(k_factor)
    obj.Side = side
    obj.Document.recompute()
    return obj


class CommandPlate(BaseCommand):
    name = "GHT_Plate"
    icon_name = "GHT_Plate"
    menu_text = "Plate"
    tooltip = (
        "Exact solid plate of the selected developable feature (from planes, joined, loft, "
        "spine/geodesic): Thickness on the material Side, six B-spline faces sewn into a solid "
        "(not OCCT's approximate thickening); Volume vs the closed form in VolumeError."
    )

    def IsActive(self) -> bool:
        import FreeCADGui as Gui

        return App.ActiveDocument is not None and any(hasattr(getattr(o, "Proxy", None), "surface") for o in Gui.Selection.getSelection())

    def Activated(self) -> None:
        import FreeCADGui as Gui

        src = next(o for o in Gui.Selection.getSelection() if hasattr(getattr(o, "Proxy", None), "surface"))
        doc = App.ActiveDocument
        doc.openTransaction("Plate")
        make_plate(src, doc=doc)
        doc.commitTransaction()


register_command(CommandPlate())
