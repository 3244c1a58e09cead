r"""Developable loft between two rails (spec section 5.7): a parametric feature on two edges.

The rails are two linked edges (``RailA``, ``RailB``: an edge of a sketch, of a GHT curve or of
any Part feature). The core :func:`ght_cad.developables.loft.developable_loft` traces the rulings
``a(t)–b(σ(t))`` with ``F(t, σ) = det(a'(t), b'(σ), b(σ) - a(t)) = 0`` solved to round-off and adds
fans (cones with apex at a rail end) so both rails are covered over their whole length. The
feature's Shape is one B-spline face per segment (main part and fans, degree 1 across the
rulings, :meth:`ght_cad.developables.loft.DevelopableLoft.bspline_data`) sewn into one shell.

Rails: a GHT curve feature gives its exact :class:`ght_cad.GHTCurve` (placed), so its μ, ν, γ
reshape the loft and the *Optimization* feature (Problem ``Loft``) can optimize them for the fan
share, the fairness of the ruling field or the edge of regression; any other edge goes through
:class:`PartEdgeRail`: ``r(t) = C(p(t))``, ``p = p_0 + t (p_1 - p_0)`` over
``edge.ParameterRange`` (from ``p_1`` for a reversed edge), ``r^(k)(t) = (dp/dt)^k C^(k)(p)``
from ``edge.derivative1At/2At/3At``. The feature recomputes when a rail changes; the
*Flat pattern* of it is the core's one-panel development (fans included).
"""

from __future__ import annotations

from typing import Any

import numpy as np

import FreeCAD as App
import Part

from ght_cad.core.errors import GHTError

from ._base import BaseCommand, FeatureProxy, ViewProviderBase, failed, new_feature, register_command, set_read_only, tolerance_property
from .convert import face_from_data

__all__ = ["DevelopableLoftFeature", "PartEdgeRail", "make_developable_loft", "rail_from_link", "ORIENTATIONS", "OUTPUTS"]

ORIENTATIONS = ["auto", "same", "reversed"]
OUTPUTS = ("Segments", "FanShare", "ThetaMax", "FResidual", "Area", "MaxDeviation", "RegressionRulings", "DegenerateRulings", "Report")


class PartEdgeRail:
    r"""A FreeCAD ``Part.Edge`` as a loft rail on t ∈ [0, 1] (orders 0..3).

    ``r(t) = edge.valueAt(p)``, ``r^(k)(t) = (dp/dt)^k edge.derivative<k>At(p)`` with
    ``p = p_0 + t (p_1 - p_0)`` (``p = p_1 - t (p_1 - p_0)`` for an edge whose Orientation is
    Reversed: the rail runs from the edge's start vertex to its end vertex).

    Raises:
        GHTError: a degenerated edge or an unbounded parameter range.
    """

    def __init__(self, edge: "Part.Edge", name: str = "rail") -> None:
        if edge.Degenerated:
            raise GHTError(f"{name} is a degenerated edge (a point); a rail must be a curve")
        p0, p1 = (float(x) for x in edge.ParameterRange)
        if not (np.isfinite(p0) and np.isfinite(p1) and p1 > p0):
            raise GHTError(f"{name} has the parameter range [{p0:g}, {p1:g}]; a rail needs a bounded edge")
        self.edge, self.name = edge, name
        self.p_range = (p0, p1)
        self.reversed = edge.Orientation == "Reversed"
        self._fns = (edge.valueAt, edge.derivative1At, edge.derivative2At, edge.derivative3At)

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        """``r^(order)(t)``, shape (n, 3), order 0..3."""
        from ght_cad.core._validate import as_parameter_array

        if isinstance(order, bool) or order not in (0, 1, 2, 3):
            raise GHTError(f"order={order!r} is not allowed; an edge rail gives derivatives of order 0..3")
        tt, _ = as_parameter_array(t, "t")
        p0, p1 = self.p_range
        p, dp = (p1 - tt * (p1 - p0), -(p1 - p0)) if self.reversed else (p0 + tt * (p1 - p0), p1 - p0)
        f = self._fns[order]
        out = np.array([tuple(f(x)) for x in p.tolist()], dtype=float).reshape(-1, 3)
        return out * dp**order if order else out

    def evaluate(self, t: Any) -> np.ndarray:
        """Points ``r(t)``, shape (n, 3)."""
        return self.derivative(t, 0)


def _is_ght_curve(obj: Any) -> bool:
    return getattr(getattr(obj, "Proxy", None), "Type", "") == "GHT::Curve"


def rail_from_link(link: Any, what: str) -> Any:
    """The core rail of a ``LinkSub`` ``(object, ["EdgeN"])``: the exact GHTCurve of a GHT curve
    feature (placed), else :class:`PartEdgeRail` of the named edge (or of the object's only edge).

    Raises:
        GHTError: no link, a sub-element that is not an edge or no longer exists, or an object
            with several edges and none named.
    """
    obj, subs = link if link else (None, [])
    if obj is None:
        raise GHTError(f"{what} is not linked; select two edges (of sketches, GHT curves or any Part feature)")
    subs = [s for s in (subs or []) if s]
    edges = obj.Shape.Edges if hasattr(obj, "Shape") else []
    if _is_ght_curve(obj) and (not subs or subs[0] == "Edge1"):
        from .ght_curve import core_curve

        return core_curve(obj, placed=True)
    names = f"Edge1..Edge{len(edges)}" if edges else "no edges"
    if subs:
        sub = subs[0]
        k = sub[4:] if sub.startswith("Edge") else ""
        if not k.isdigit() or not 1 <= int(k) <= len(edges):
            raise GHTError(f"{what} = {obj.Label}.{sub} is not an edge of it ({names}); select the edge again")
        return PartEdgeRail(edges[int(k) - 1], f"{what} ({obj.Label}.{sub})")
    if len(edges) != 1:
        raise GHTError(f"{what} = {obj.Label} has {names}; link one edge ({obj.Label}.EdgeN)")
    return PartEdgeRail(edges[0], f"{what} ({obj.Label})")


def _sewn(faces: list, tol: float, closed: bool) -> "Part.Shape":
    """Faces sewn along the joint rulings into one shell (one face: itself, or with a seam when
    closed around); the number of shared edges is checked."""
    if len(faces) == 1 and not closed:
        return faces[0]
    comp = Part.makeCompound([f.copy() for f in faces])
    comp.sewShape(tol)
    if len(faces) == 1:
        face = comp.Faces[0] if len(comp.Faces) == 1 else None
        if face is None or not face.isValid():
            raise GHTError("sewing the closed one-segment loft did not give one valid face")
        return face
    shells = [comp] if comp.ShapeType == "Shell" else comp.Shells
    expected = len(faces) - 1 + (1 if closed else 0)
    if len(shells) != 1 or len(shells[0].Faces) != len(faces):
        raise GHTError(f"sewing the {len(faces)} loft faces gave {len(shells)} shells; expected one")
    shell = shells[0]
    shared = sum(1 for e in shell.Edges if len([f for f in shell.Faces if any(e.isSame(g) for g in f.Edges)]) == 2)
    if shared != expected:
        raise GHTError(f"the sewn loft shell has {shared} shared edges; {expected} joint rulings expected")
    if not shell.isValid():
        raise GHTError("the sewn loft shell is not valid")
    return shell


class DevelopableLoftFeature(FeatureProxy):
    """Proxy of a developable loft between two rails (``Part::FeaturePython``)."""

    Type = "GHT::DevelopableLoft"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkSub", "RailA", "Input", "First rail: an edge of a sketch, a GHT curve or any Part feature")
        obj.addProperty("App::PropertyLinkSub", "RailB", "Input", "Second rail: an edge of a sketch, a GHT curve or any Part feature")
        obj.addProperty("App::PropertyEnumeration", "Orientation", "Loft", "auto: try both; same: s grows with t; reversed: rail B is traced from its end")
        obj.Orientation = ORIENTATIONS
        obj.addProperty("App::PropertyInteger", "Branch", "Loft", "-1: automatic (no edge of regression, smallest fan share); k >= 0: candidate k of the Report")
        obj.Branch = -1
        obj.addProperty("App::PropertyFloat", "Tolerance", "Conversion", "Maximum deviation of the faces from the exact loft (0: 1e-7 of its size)")
        obj.addProperty("App::PropertyStringList", "Segments", "Loft", "Segments along the rails: fan_a (apex on rail A), fan_b (apex on rail B), main")
        obj.addProperty("App::PropertyFloat", "FanShare", "Loft", "Fan area / loft area (0: rulings end to end)")
        obj.addProperty("App::PropertyAngle", "ThetaMax", "Developability", "max θ over the sampled rulings (round-off expected)")
        obj.addProperty("App::PropertyFloat", "FResidual", "Developability", "max |F| / (|a'| |b'| |b - a|) of the rulings (round-off expected)")
        obj.addProperty("App::PropertyFloat", "Area", "Loft", "3-D area of the loft")
        obj.addProperty("App::PropertyFloat", "MaxDeviation", "Conversion", "Deviation of the faces' rail edges from the exact rails (certified)")
        obj.addProperty("App::PropertyInteger", "RegressionRulings", "Loft", "Sampled rulings with the edge of regression between the rails (0: none)")
        obj.addProperty("App::PropertyInteger", "DegenerateRulings", "Loft", "Sampled rulings of zero length or along a rail tangent")
        obj.addProperty("App::PropertyString", "Report", "Loft", "Summary of the loft construction")
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, OUTPUTS)

    def rails(self, obj: Any) -> tuple[Any, Any]:
        """The two core rails (see :func:`rail_from_link`)."""
        return rail_from_link(obj.RailA, f"{obj.Label}.RailA"), rail_from_link(obj.RailB, f"{obj.Label}.RailB")

    def surface(self, obj: Any) -> Any:
        """The core :class:`ght_cad.developables.loft.DevelopableLoft` (the Flat pattern unrolls it)."""
        from ght_cad.developables.loft import developable_loft

        if obj.Orientation not in ORIENTATIONS:
            raise GHTError(f"{obj.Label}.Orientation={obj.Orientation!r} is not allowed; use one of {ORIENTATIONS}")
        if int(obj.Branch) < -1:
            raise GHTError(f"{obj.Label}.Branch={obj.Branch} is not allowed; use -1 (automatic) or a candidate index >= 0")
        branch = "auto" if int(obj.Branch) == -1 else int(obj.Branch)
        a, b = self.rails(obj)
        return developable_loft(a, b, orientation=str(obj.Orientation), branch=branch)

    def compute(self, obj: Any) -> None:
        loft = self.surface(obj)
        tol = tolerance_property(obj, zero_means="1e-7 of the segment size")
        datas = loft.bspline_data(tol=tol)
        faces = [face_from_data(d) for d in datas]
        for i, f in enumerate(faces):
            if not f.isValid():
                raise GHTError(f"the B-spline face of loft segment {i} ({loft.segments[i].kind}) is not valid")
        u = np.array([0.0, 1.0])
        A, B = loft.a(u), loft.b(u)
        pts = np.vstack([loft.a(np.linspace(0, 1, 65)), loft.b(np.linspace(0, 1, 65))])
        size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))) or 1.0
        sew_tol = 1e-6 * size
        closed = max(float(np.linalg.norm(A[0] - A[1])), float(np.linalg.norm(B[0] - B[1]))) <= sew_tol
        shape = _sewn(faces, sew_tol, closed)
        rep = loft.report
        obj.Segments = [sg.kind for sg in loft.segments]
        obj.FanShare = float(rep.fan_share)
        obj.ThetaMax = float(rep.theta_max_deg)
        obj.FResidual = float(rep.f_residual_max)
        obj.Area = float(rep.area)
        obj.MaxDeviation = max(float(d.max_deviation or 0.0) for d in datas)
        obj.RegressionRulings = len(rep.regression)
        obj.DegenerateRulings = len(rep.degenerate_rulings)
        obj.Report = str(rep)
        obj.Shape = shape


class LoftPanel:
    """Task panel of a developable loft: the rails, the construction report, and what to change
    where; a clear message instead of a report when a rail link is unset or the loft failed."""

    #: the most recently opened panel (for macros and the GUI check)
    last: "LoftPanel | None" = None

    def __init__(self, obj: Any) -> None:
        from ._base import _qt

        QtCore, QtWidgets = _qt()
        LoftPanel.last = self
        self.obj = obj
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle(f"{obj.Label}: developable loft")
        layout = QtWidgets.QVBoxLayout(self.form)
        self.label = QtWidgets.QLabel(self.text())
        self.label.setWordWrap(True)
        self.label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        layout.addWidget(self.label)

    @property
    def message(self) -> str:
        return self.label.text()

    def text(self) -> str:
        """What the panel says: unset links first, then a failed recompute, else the report."""
        obj = self.obj
        missing = [n for n in ("RailA", "RailB") if not getattr(obj, n) or getattr(obj, n)[0] is None]
        if missing:
            return (
                f"{obj.Label}: {' and '.join(missing)} {'is' if len(missing) == 1 else 'are'} not linked. "
                "Set them in the property editor (Input → RailA, RailB: an edge of a sketch, a GHT curve or any "
                "Part feature), or select two edges and run 'Developable loft' again."
            )
        if failed(obj):
            return f"{obj.Label}: the last recompute failed: {obj.getStatusString()}"
        rails = ", ".join(f"{n} = {getattr(obj, n)[0].Label}.{(getattr(obj, n)[1] or [''])[0]}".rstrip(".") for n in ("RailA", "RailB"))
        return (
            f"{rails}\n{obj.Report}\nEdit Orientation, Branch and Tolerance in the property editor; the shape "
            "parameters of GHT curve rails reshape the loft (double-click the curve)."
        )

    def accept(self) -> bool:
        import FreeCADGui as Gui

        Gui.Control.closeDialog()
        if Gui.ActiveDocument is not None:
            Gui.ActiveDocument.resetEdit()
        return True

    reject = accept

    def getStandardButtons(self) -> int:
        from ._base import _qt

        _, QtWidgets = _qt()
        return int(QtWidgets.QDialogButtonBox.Close)


class ViewProviderDevelopableLoft(ViewProviderBase):
    icon_name = "GHT_DevelopableLoft"
    shape_color = (0.55, 0.78, 0.85)
    panel_factory = staticmethod(lambda obj: LoftPanel(obj))

    def claimChildren(self) -> list:
        return []


def make_developable_loft(rail_a: Any, rail_b: Any, *, orientation: str = "auto", tolerance: float = 0.0, doc: Any = None, name: str = "DevelopableLoft") -> Any:
    """Create a developable loft between two rails.

    Args:
        rail_a, rail_b: ``(object, "EdgeN")`` links, or an object whose shape is one edge (a GHT
            curve feature, a single-edge sketch or Part feature).
        orientation: ``"auto"``, ``"same"`` or ``"reversed"`` (see :func:`ght_cad.developables.loft.developable_loft`).
        tolerance: face deviation (0: 1e-7 of the segment size).

    Returns:
        The recomputed feature (in the error state, with the reason in the Report view, when no
        developable joins the rails).
    """
    if orientation not in ORIENTATIONS:
        raise GHTError(f"orientation={orientation!r} is not allowed; use one of {ORIENTATIONS}")

    def link(r: Any) -> tuple:
        if isinstance(r, tuple):
            obj, sub = r
            return (obj, [sub] if isinstance(sub, str) and sub else list(sub or []))
        return (r, [])

    first = link(rail_a)[0]
    obj = new_feature(doc or first.Document, name, DevelopableLoftFeature, ViewProviderDevelopableLoft)
    obj.RailA = link(rail_a)
    obj.RailB = link(rail_b)
    obj.Orientation = orientation
    obj.Tolerance = float(tolerance)
    obj.Document.recompute()
    return obj


class CommandDevelopableLoft(BaseCommand):
    name = "GHT_DevelopableLoft"
    icon_name = "GHT_DevelopableLoft"
    menu_text = "Developable loft"
    tooltip = (
        "Exact developable surface between two selected edges (rails: edges of sketches, GHT curves or any "
        "Part feature): rulings with a common tangent plane at both ends, fans at the rail ends, one shell; "
        "feeds Flat pattern and Optimization (Problem Loft)."
    )

    def Activated(self) -> None:
        from ._base import selected_links

        links = selected_links("Edge")
        if len(links) != 2:
            App.Console.PrintError(f"Developable loft: select exactly two edges (rails); {len(links)} selected\n")
            return
        doc = App.ActiveDocument
        doc.openTransaction("Developable loft")
        make_developable_loft(links[0], links[1], doc=doc)  # a failure is reported by the feature itself
        doc.commitTransaction()


register_command(CommandDevelopableLoft())
