r"""Developable approximation (issue 24): a parametric feature that covers a selected face of any
object (a Part feature, a PartDesign Body, an imported STEP) with exactly developable panels.

The algorithm is the core's :func:`ght_cad.approximation.approximate` (strips between target
isolines, each an exact developable loft between its two seam curves, spec 5.7; seams moved off
the target so the deviation is split both ways; the direction of least normal curvature). This
module only adapts FreeCAD to it and back:

* :func:`face_target`: a ``Part.Face`` as the core's target protocol
  (:class:`ght_cad.approximation.SurfaceTarget`: ``jet(u, v, order)`` = ``[S, S_u, S_v, S_uu,
  S_vv, S_uv]`` and the face's parameter box ``face.ParameterRange``), through the workbench's
  surface adapter :class:`.flat_pattern.FreeCADSurface`: a non-periodic B-spline/Bézier surface is
  read into the core's NURBS evaluator, planes/cylinders/cones are evaluated in closed form; a
  periodic B-spline surface is made non-periodic on a copy (same parameters, ``setUNotPeriodic``);
  other surfaces (a ``Part.Sphere``, torus, surface of revolution, offset) go through
  ``face.toNurbs()`` (OCCT's exact NURBS conversion of the face, its pcurves converted with it, so
  the parameter box is the converted face's). Whatever cannot be read that way is evaluated point
  by point by FreeCAD (``value``/``getDN``: correct, slow).
* :func:`face_trim`: how much of its surface's (u, v) box the face covers (``face.Area`` over the
  area of ``face.Surface.toShape(u0, u1, v0, v1)``) and its holes (``len(face.Wires) - 1``): the
  core covers the whole box, so a trimmed face is refused unless the property ``Untrimmed`` is
  set (then Report records the fraction).
* the panels (the core's :class:`~ght_cad.surfaces.bspline.BSplineSurfaceData`, degree 1 across the
  rulings, fitted to 1e-7 of the size) become ``Part.BSplineSurface`` faces
  (:func:`.convert.face_from_data`) joined into one shell along their seams at 1e-6 of the target
  size (:func:`panel_shell`: adjacent panels are lofted from the same seam curve).

Properties Direction and Method are enumerations of what the core accepts, read from the core
(``ght_cad.approximation.DIRECTIONS``: the design files' ``APPROX_DIRECTIONS`` and ``ght-cad
approximate --direction`` are the same list; the workbench, a kernel-layer module, reads the core's
rather than the application's, tests/test_import_layers.py) when a feature is made or a document
opened, so a direction the core learns later is offered in old documents too. During a recompute the core's progress lines drive FreeCAD's
``Base.ProgressIndicator`` (the status bar's busy bar in the GUI, one step per line; each line also
goes to the log, ``Console.PrintLog``: the Report view with "Log messages" on); headless the
indicator is left out (:data:`SHOW_PROGRESS`): FreeCAD's console sequencer would print its text
among the Report lines. FreeCAD 0.20 lets only the outermost sequencer draw: in a document
recompute that is the document's own "Recompute..." (one step per object) and the indicator is
silent; it shows when the feature is recomputed alone (``obj.recompute()``, "Recompute object").

Per-panel outputs are listed in the order of the Shape's faces (``PanelDeviations[i]`` is
``Face{i+1}``). :meth:`DevelopableApproximationFeature.surface` gives the panels' exact
developables in that order, so the *Flat pattern* feature (Source = this feature) unrolls all
panels onto one sheet with seam marks, as ``ght-cad approximate`` does, and the existing DXF/SVG
export takes it. (The fitted B-spline faces are not unrolled: a loft's fan can be 1e-10 of the
parameter range wide, and at its apex, where the rail's derivative vanishes, the development's
θ check reads 90°.)
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import FreeCAD as App
import Part

from ght_cad.core.errors import GHTError

from ._base import (BaseCommand, FeatureProxy, ViewProviderBase, failed, info_panel, new_feature, register_command, selected_links, set_read_only,
                    tolerance_property)
from .convert import face_from_data

__all__ = ["DevelopableApproximationFeature", "face_target", "target_face",
           "make_developable_approximation", "flat_patterns_of", "panel_shell", "DIRECTIONS", "METHODS", "OUTPUTS"]



def _core_choices(name: str, default: tuple[str, ...]) -> list[str]:
    """``ght_cad.approximation.<name>`` (the choices the core accepts), ``default`` for a core
    without that constant."""
    import ght_cad.approximation as core

    return list(getattr(core, name, default))


#: the parameter the rulings run along (u, v) or seams along the isolines of u+v / u-v of the parameter box
#: (diagonal, antidiagonal): the choices the core accepts (``ght_cad.approximation.DIRECTIONS``)
DIRECTIONS = _core_choices("DIRECTIONS", ("auto", "u", "v"))
#: how each strip is fitted (ght_cad.approximate's ``method``): the closer of both, the rails loft, the dual fit
METHODS = _core_choices("METHODS", ("auto", "loft", "dual"))
#: drive ``FreeCAD.Base.ProgressIndicator`` during a recompute: None = only with the GUI up (headless,
#: FreeCAD's console sequencer prints the text and percentages to stdout), True = always, False = never
SHOW_PROGRESS: bool | None = None
OUTPUTS = ("PanelCount", "MaxDeviation", "PanelDeviations", "PanelMaxOut", "PanelMaxIn", "PanelThetaMax", "PanelAreas",
           "PanelMethods", "DirectionUsed", "Report")


def _readable(face: "Part.Face") -> Any:
    """The :class:`.flat_pattern.FreeCADSurface` of ``face`` when it is evaluated in numpy (a
    B-spline/Bézier read into the core, or a plane/cylinder/cone in closed form), else None; a
    periodic B-spline surface is tried again on a non-periodic copy (same parameters)."""
    from .flat_pattern import FreeCADSurface

    surf = FreeCADSurface(face)
    if surf.path != "freecad":
        return surf
    s = face.Surface
    if type(s).__name__ == "BSplineSurface" and (s.isUPeriodic() or s.isVPeriodic()):
        c = s.copy()
        if c.isUPeriodic():
            c.setUNotPeriodic()
        if c.isVPeriodic():
            c.setVNotPeriodic()
        surf = FreeCADSurface(Part.Face(c))
        if surf.path != "freecad":
            return surf
    return None


def face_target(face: "Part.Face", name: str = "face") -> Any:
    """A FreeCAD face as the core's approximation target (module doc).

    Returns:
        :class:`ght_cad.approximation.SurfaceTarget` on the face's parameter box, with
        ``path`` set to how it is evaluated (``"nurbs"``, ``"analytic"``, ``"nurbs (toNurbs)"``
        or ``"freecad"``).

    Raises:
        GHTError: a face without a parameter box (infinite).
    """
    from ght_cad.approximation import SurfaceTarget

    from .flat_pattern import FreeCADSurface

    src, how = face, ""
    surf = _readable(face)
    if surf is None:
        try:
            converted = face.toNurbs().Faces
        except Exception:  # noqa: BLE001 - OCCT could not convert it: evaluate through FreeCAD
            converted = []
        if len(converted) == 1:
            surf = _readable(converted[0])
            if surf is not None:
                src, how = converted[0], " (toNurbs)"
    if surf is None:
        surf = FreeCADSurface(face)
    bounds = tuple(float(x) for x in src.ParameterRange)
    if not all(np.isfinite(bounds)):
        raise GHTError(f"{name} has the parameter range {bounds}; an approximation target must be a bounded face")
    target = SurfaceTarget(lambda u, v, k: surf.jet(u, v, min(k, 2)), bounds, f"{name} ({surf.type_name})",
                           trim=face_trim(face))
    target.path = surf.path + how
    return target


def face_trim(face: "Part.Face") -> dict[str, float]:
    r"""How much of its surface's (u, v) box a FreeCAD face covers (the OCP adapter's
    :func:`ght_cad.cad.approximate.face_trim` with FreeCAD's Part API):
    ``{"covered": face.Area / A_box, "holes": len(face.Wires) - 1}``, ``A_box`` the area of
    ``face.Surface.toShape(u0, u1, v0, v1)`` over the face's ``ParameterRange``. A face whose trim
    is its box gives ``covered = 1`` (to round-off) and no holes."""
    u0, u1, v0, v1 = (float(x) for x in face.ParameterRange)
    try:
        box = float(face.Surface.toShape(u0, u1, v0, v1).Area)
    except Exception:  # noqa: BLE001 - a surface FreeCAD cannot restrict: treated as its box
        box = 0.0
    covered = float(face.Area) / box if box > 0 and math.isfinite(box) else 1.0
    return {"covered": covered, "holes": max(len(face.Wires) - 1, 0)}


def target_face(link: Any, what: str) -> "Part.Face":
    """The face of a ``LinkSub`` ``(object, ["FaceN"])`` (or the object's only face).

    Raises:
        GHTError: no link, a sub-element that is not a face or no longer exists, an object with
            several faces and none named.
    """
    obj, subs = link if link else (None, [])
    if obj is None:
        raise GHTError(f"{what} is not linked; select one face (of a Part feature, a Body or an imported STEP)")
    faces = obj.Shape.Faces if hasattr(obj, "Shape") else []
    names = f"Face1..Face{len(faces)}" if faces else "no faces"
    subs = [s for s in (subs or []) if s]
    if subs:
        k = subs[0][4:] if subs[0].startswith("Face") else ""
        if not k.isdigit() or not 1 <= int(k) <= len(faces):
            raise GHTError(f"{what} = {obj.Label}.{subs[0]} is not a face of it ({names}); select the face again")
        return faces[int(k) - 1]
    if len(faces) != 1:
        raise GHTError(f"{what} = {obj.Label} has {names}; link one face ({obj.Label}.FaceN)")
    return faces[0]


def _shell_order(shape: "Part.Shape", nets: list[np.ndarray], tol: float) -> list[int]:
    """For every face of ``shape`` the index of the panel whose B-spline net (poles, (n, 2, 3)) it
    carries: joining keeps the surfaces, not necessarily the order.

    Raises:
        GHTError: a face that matches no net or several, or two faces the same net.
    """
    order = []
    for i, f in enumerate(shape.Faces, 1):
        poles = np.array([[tuple(p) for p in row] for row in f.Surface.getPoles()], dtype=float)
        hits = [k for k, n in enumerate(nets) if n.shape == poles.shape and float(np.abs(n - poles).max()) <= tol]
        if len(hits) != 1 or hits[0] in order:
            raise GHTError(f"Face{i} of the panel shell matches {len(hits)} panels; expected exactly one")
        order.append(hits[0])
    return order


def _open_seam(shell: "Part.Shape", order: list[int]) -> str | None:
    """The first seam (two panels that follow each other in seam order) whose faces share no edge
    of ``shell``, as text; None when every seam is joined."""
    face_of = {k: i for i, k in enumerate(order)}
    for k in range(len(order) - 1):
        fa, fb = shell.Faces[face_of[k]], shell.Faces[face_of[k + 1]]
        if not any(e.isSame(g) for e in fa.Edges for g in fb.Edges):
            return f"the seam between panels {k + 1} and {k + 2} (Face{face_of[k] + 1}, Face{face_of[k + 1] + 1}) is open"
    return None


def _joined(faces: list, tol: float, how: str) -> "Part.Shape | None":
    """The faces joined by ``sewShape`` (``how="sew"``) or by the general fuse (``"fuse"``), as one
    shell; None when sewing gave several."""
    if how == "sew":
        comp = Part.makeCompound([f.copy() for f in faces])
        comp.sewShape(tol)
        shells = [comp] if comp.ShapeType == "Shell" else comp.Shells
        return shells[0] if len(shells) == 1 else None
    return Part.Shell(faces[0].generalFuse(faces[1:], tol)[0].Faces)


def panel_shell(faces: list, nets: list[np.ndarray], tol: float) -> tuple["Part.Shape", list[int]]:
    """The panel faces (in seam order, with their B-spline nets) joined into one shell along their
    seams, and for every face of it the index of its panel (:func:`_shell_order`).

    Adjacent panels are lofted from the same seam curve; their faces agree along it to the fit
    tolerance (1e-7 of the size). First ``sewShape(tol)``; where that does not give one valid shell
    with every seam a shared edge, OCCT's general fuse with the fuzzy value ``tol`` (FreeCAD's
    ``generalFuse``), which merges the coincident seam edges. FreeCAD 0.20's sewing (OCCT 7.6)
    joined the five open strips of a 1 m dome but none of the eight seams of the spherical cap's
    nine bands closed around (at any tolerance up to 1 mm); the fuse joined all eight there but
    left a self-intersecting wire in one of the dome's strips. One face is returned as it is (a
    band closed around carries its own seam edge).

    Raises:
        GHTError: neither way gave one valid shell of the panels with every seam joined (the
            reasons of both).
    """
    if len(faces) == 1:
        return faces[0], [0]
    why = []
    for how in ("sew", "fuse"):
        shell = _joined(faces, float(tol), how)
        if shell is None or len(shell.Faces) != len(faces):
            why.append(f"{how}: {0 if shell is None else len(shell.Faces)} faces in one shell")
            continue
        if not shell.isValid():
            why.append(f"{how}: not a valid shell")
            continue
        order = _shell_order(shell, nets, 1e-3 * tol)
        open_seam = _open_seam(shell, order)
        if open_seam is None:
            return shell, order
        why.append(f"{how}: {open_seam}")
    raise GHTError(f"the {len(faces)} panels could not be joined into one shell at {tol:.3g} ({'; '.join(why)})")


class DevelopableApproximationFeature(FeatureProxy):
    """Proxy of a developable approximation of a face (``Part::FeaturePython``)."""

    Type = "GHT::DevelopableApproximation"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkSub", "Target", "Input", "The double-curved face to cover: a face of a Part feature, a Body or an imported STEP")
        obj.addProperty("App::PropertyFloat", "Tolerance", "Approximation", "Largest deviation of the panels from the target, both ways (model units, > 0)")
        obj.Tolerance = 1.0
        obj.addProperty("App::PropertyInteger", "MaxPanels", "Approximation", "Largest panel count accepted (>= 1); more needed: the feature fails naming the best deviation")
        obj.MaxPanels = 64
        self._method_properties(obj)
        obj.addProperty("App::PropertyInteger", "PanelCount", "Result", "Number of developable panels (faces of the shell)")
        obj.addProperty("App::PropertyFloat", "MaxDeviation", "Result", "Largest deviation of a panel from the target, both ways (the core's measure)")
        obj.addProperty("App::PropertyFloatList", "PanelDeviations", "Result", "Per panel (FaceN order): max deviation both ways")
        obj.addProperty("App::PropertyFloatList", "PanelMaxOut", "Result", "Per panel: largest deviation outside the target (along its normal)")
        obj.addProperty("App::PropertyFloatList", "PanelMaxIn", "Result", "Per panel: largest deviation inside the target")
        obj.addProperty("App::PropertyFloatList", "PanelThetaMax", "Result", "Per panel: developability θ_max in degrees (round-off expected)")
        obj.addProperty("App::PropertyFloatList", "PanelAreas", "Result", "Per panel: 3-D area")
        obj.addProperty("App::PropertyString", "DirectionUsed", "Result", "The strip direction used (u, v, diagonal or antidiagonal)")
        obj.addProperty("App::PropertyString", "Report", "Result", "Summary of the approximation")
        self.restored(obj)

    @staticmethod
    def _method_properties(obj: Any) -> None:
        """Direction, Method and PanelMethods, their choices the core's (:data:`DIRECTIONS`,
        :data:`METHODS`): added to documents saved before they existed (Method "loft", what those
        documents were computed with), and an enumeration saved with fewer choices than the core has
        now gets the new ones, its value kept."""
        if "Direction" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Direction", "Approximation", "Parameter of the target the rulings run "
                            f"along: {', '.join(DIRECTIONS)} (auto: least normal curvature)")
            obj.Direction = DIRECTIONS
            obj.Direction = "auto"
        if "Method" not in obj.PropertiesList:
            obj.addProperty("App::PropertyEnumeration", "Method", "Approximation", "Per strip: auto (the closer of the rails loft "
                            "and the dual fit of the target's tangent planes, spec 10.1), loft or dual")
            obj.Method = METHODS
            obj.Method = "auto" if "PanelCount" not in obj.PropertiesList else "loft"
        for name, choices in (("Direction", DIRECTIONS), ("Method", METHODS)):
            if list(obj.getEnumerationsOfProperty(name) or []) != choices:
                value = str(getattr(obj, name))
                setattr(obj, name, list(choices))
                if value in choices:
                    setattr(obj, name, value)
        if "Untrimmed" not in obj.PropertiesList:
            obj.addProperty("App::PropertyBool", "Untrimmed", "Approximation", "Cover a trimmed face (holes, or an outline "
                            "inside its surface's (u, v) box) over the whole box of its surface knowingly; false: a "
                            "trimmed face is refused")
            obj.Untrimmed = False
        if "PanelMethods" not in obj.PropertiesList:
            obj.addProperty("App::PropertyStringList", "PanelMethods", "Result", "Per panel: loft or dual (how its seams were found)")

    def restored(self, obj: Any) -> None:
        self._method_properties(obj)
        set_read_only(obj, OUTPUTS)

    def surface(self, obj: Any) -> list[Any]:
        """The panels' exact developables (:class:`ght_cad.developables.loft.DevelopableLoft` or
        :class:`ght_cad.approximation.ConeStrip`) in FaceN order: the *Flat pattern* feature
        (Source = this feature) unrolls them all onto one sheet, as ``ght-cad approximate`` does.
        They are kept from the last successful recompute (together with the Shape); after a
        document is opened they are made again from the same inputs (the core is deterministic)
        and matched to the saved Shape's faces.

        Raises:
            GHTError: no panels yet, or the saved faces are not those of the inputs (recompute).
        """
        panels = getattr(self, "_exact", None)
        if panels is None:
            if obj.Shape.isNull() or not obj.Shape.Faces:
                raise GHTError(f"{obj.Label} has no panels yet; recompute it")
            res, _ = self.run(obj)
            try:
                order = _shell_order(obj.Shape, [p.surface.data.poles for p in res.panels], 1e-9 * res.size)
            except GHTError:
                raise GHTError(f"{obj.Label}: its saved panels are not those of its inputs; recompute it") from None
            panels = self._exact = [_exact(res.panels[k]) for k in order]
        return list(panels)

    def run(self, obj: Any) -> tuple[Any, str]:
        """``(the core's ApproximationResult, how the target is evaluated)`` for the inputs.

        Raises:
            GHTError: an unset or stale Target, a bad Tolerance or MaxPanels, no approximation
                within Tolerance with at most MaxPanels panels (the best deviation reached).
        """
        from ght_cad.approximation import approximate
        from ght_cad.approximation.target import TRIM_ALLOWED, TrimmedTargetError, trim_words

        face = target_face(obj.Target, f"{obj.Label}.Target")
        tol = tolerance_property(obj)
        max_panels = int(obj.MaxPanels)
        if max_panels < 1:
            raise GHTError(f"{obj.Label}.MaxPanels={max_panels} is not allowed; it must be an integer >= 1")
        label = f"{obj.Target[0].Label}.{(obj.Target[1] or ['Face1'])[0]}"
        target = face_target(face, label)
        try:
            with _RecomputeProgress(f"{obj.Label}: developable approximation") as say:
                res = approximate(target, tol, direction=str(obj.Direction), max_panels=max_panels,
                                  method=str(obj.Method), progress=say, untrimmed=bool(obj.Untrimmed))
        except TrimmedTargetError as exc:
            raise GHTError(f"{obj.Label}.Target = {label} is {trim_words(exc.covered, exc.holes)}; {TRIM_ALLOWED}, or "
                           f"set {obj.Label}.Untrimmed = True to cover its surface over the whole (u, v) box knowingly") from None
        except GHTError as exc:  # name the feature's properties, not the core's arguments
            raise GHTError(f"{' '.join(str(exc).split())} (properties Tolerance, MaxPanels)") from None
        return res, target.path

    def compute(self, obj: Any) -> None:
        res, path = self.run(obj)
        faces = [face_from_data(p.surface.data) for p in res.panels]
        for i, f in enumerate(faces, 1):
            if not f.isValid():
                raise GHTError(f"the B-spline face of panel {i} is not valid")
        shape, order = panel_shell(faces, [p.surface.data.poles for p in res.panels], 1e-6 * res.size)
        panels = [res.panels[k] for k in order]
        obj.PanelCount = len(panels)
        obj.MaxDeviation = float(res.max_deviation)
        obj.PanelDeviations = [float(p.max_deviation) for p in panels]
        obj.PanelMaxOut = [float(p.max_out) for p in panels]
        obj.PanelMaxIn = [float(p.max_in) for p in panels]
        obj.PanelThetaMax = [float(p.theta_max_deg) for p in panels]
        obj.PanelAreas = [float(p.area) for p in panels]
        obj.PanelMethods = [str(getattr(p, "method", "loft")) for p in panels]
        obj.DirectionUsed = res.direction
        obj.Report = (f"{len(panels)} developable panel{'s' if len(panels) != 1 else ''} within {res.max_deviation:.4g} (Tolerance {res.tol:g}), rulings along "
                      f"{res.direction}, Method {obj.Method} ({obj.PanelMethods.count('loft')} loft, {obj.PanelMethods.count('dual')} dual), target "
                      f"evaluated by {path}, {res.info.get('seconds', 0.0):.1f} s")
        trim = res.info.get("trim")
        if trim and (trim["holes"] or trim["covered"] < 1.0 - 1e-6):
            obj.Report += (f"; Untrimmed: the trimmed target ({trim['covered']:.4g} of its (u, v) box, {trim['holes']} "
                           "hole(s)) covered over its whole box")
        obj.Shape = shape
        self._exact = [_exact(p) for p in panels]  # not saved (FeatureProxy.__getstate__): see surface


class _RecomputeProgress:
    """Context manager giving the core's ``progress`` callback: every line goes to the log
    (``Console.PrintLog``, "<text>: <line>") and, when :data:`SHOW_PROGRESS` says so, advances a
    ``FreeCAD.Base.ProgressIndicator`` started with ``text`` and 0 steps (a busy bar: the core's
    line count is not known ahead). The indicator is stopped on the way out whatever happens; one
    that cannot be made or fed (an older FreeCAD, no sequencer) is dropped. The user aborting it in
    the GUI (Esc) gives a :class:`GHTError` (one Report line, the feature in the error state)."""

    def __init__(self, text: str) -> None:
        self.text = text
        self.indicator: Any = None
        self.lines = 0

    def __enter__(self) -> Any:
        show = bool(App.GuiUp) if SHOW_PROGRESS is None else SHOW_PROGRESS
        if show:
            try:
                self.indicator = App.Base.ProgressIndicator()
                self.indicator.start(self.text, 0)
            except Exception:  # noqa: BLE001 - no indicator: the log lines only
                self.indicator = None
        return self.say

    def say(self, line: str) -> None:
        self.lines += 1
        App.Console.PrintLog(f"{self.text}: {' '.join(str(line).split())}\n")
        if self.indicator is None:
            return
        try:
            self.indicator.next()
        except BaseException as exc:  # noqa: BLE001 - FreeCAD's abort (Esc) is not an Exception
            self.stop()
            if isinstance(exc, Exception) and "abort" not in str(exc).lower():
                return  # the indicator broke: go on without it
            raise GHTError(f"{self.text}: cancelled by the user") from None

    def stop(self) -> None:
        if self.indicator is not None:
            try:
                self.indicator.stop()
            except Exception:  # noqa: BLE001 - stopped already
                pass
            self.indicator = None

    def __exit__(self, *exc: Any) -> None:
        self.stop()


def _exact(panel: Any) -> Any:
    """A panel's exact developable (its fitted B-spline surface when the core kept none)."""
    return panel.exact if panel.exact is not None else panel.surface


class ViewProviderDevelopableApproximation(ViewProviderBase):
    icon_name = "GHT_DevelopableApproximation"
    shape_color = (0.62, 0.80, 0.62)
    panel_factory = staticmethod(lambda obj: info_panel(obj, ("Target",), f"{obj.Report}\nEdit Tolerance, MaxPanels, "
                                                        "Direction and Method in the property editor; its Flat pattern holds every panel."))

    def claimChildren(self) -> list:
        """Its flat patterns (Flat pattern features whose Source is this feature) sit under it."""
        obj = self.obj
        if obj is None:
            return []
        return flat_patterns_of(obj)


def flat_patterns_of(obj: Any) -> list[Any]:
    """The Flat pattern features whose Source is ``obj``."""
    return [o for o in obj.InList if getattr(getattr(o, "Proxy", None), "Type", "") == "GHT::FlatPattern"]


def make_developable_approximation(
    target: Any,
    tolerance: float = 1.0,
    *,
    max_panels: int = 64,
    direction: str = "auto",
    method: str = "auto",
    untrimmed: bool = False,
    flat_pattern: bool = False,
    doc: Any = None,
    name: str = "DevelopableApproximation",
) -> Any:
    """Create a developable approximation of a face.

    Args:
        target: ``(object, "FaceN")``, or an object whose shape is one face.
        tolerance: largest deviation both ways (model units, > 0).
        max_panels: largest panel count accepted.
        direction: one of :data:`DIRECTIONS` (the core's: ``"auto"``, ``"u"``, ``"v"``, ...): the
            parameter the rulings run along.
        method: ``"auto"``, ``"loft"`` or ``"dual"`` (:data:`METHODS`): how each strip is fitted.
        untrimmed: property ``Untrimmed``: cover a trimmed face over its surface's whole (u, v) box.
        flat_pattern: also make the *Flat pattern* of all panels (a child in the tree,
            :func:`flat_patterns_of`).

    Returns:
        The recomputed feature (in the error state, with the reason in the Report view, when no
        approximation within the tolerance and panel count exists).

    Raises:
        GHTError: a direction not in :data:`DIRECTIONS`.
    """
    if direction not in DIRECTIONS:
        raise GHTError(f"direction={direction!r} is not allowed; use one of {DIRECTIONS}")
    if method not in METHODS:
        raise GHTError(f"method={method!r} is not allowed; use one of {METHODS}")
    src, sub = target if isinstance(target, tuple) else (target, "")
    obj = new_feature(doc or src.Document, name, DevelopableApproximationFeature, ViewProviderDevelopableApproximation)
    obj.Target = (src, [sub] if sub else [])
    obj.Tolerance = float(tolerance)
    obj.MaxPanels = int(max_panels)
    obj.Direction = direction
    obj.Method = method
    obj.Untrimmed = bool(untrimmed)
    obj.Document.recompute()
    if flat_pattern and not failed(obj):  # a failed approximation has no panels to unroll
        from .flat_pattern import make_flat_pattern

        make_flat_pattern(obj, doc=obj.Document, name=f"{obj.Name}Flat")
    return obj


class CommandDevelopableApproximation(BaseCommand):
    name = "GHT_DevelopableApproximation"
    icon_name = "GHT_DevelopableApproximation"
    menu_text = "Developable approximation"
    tooltip = (
        "Cover the selected double-curved face (of a Part feature, a Body or an imported STEP) with exactly developable "
        "panels within Tolerance: one shell of B-spline panels (degree 1 across the rulings) and the flat pattern of "
        "all panels; per-panel deviations in the properties."
    )

    def IsActive(self) -> bool:
        import FreeCADGui as Gui

        return App.ActiveDocument is not None and bool(Gui.Selection.getSelection())

    def Activated(self) -> None:
        links = selected_links("Face")
        if len(links) != 1:
            App.Console.PrintError(f"Developable approximation: select exactly one face; {len(links)} selected\n")
            return
        doc = App.ActiveDocument
        doc.openTransaction("Developable approximation")
        make_developable_approximation(links[0], flat_pattern=True, doc=doc)  # a failure is reported by the feature itself
        doc.commitTransaction()


register_command(CommandDevelopableApproximation())
