r"""Composite curve feature: GHT segments joined with a continuity per joint (spec section 4).

``Segments`` links GHT curve features in order; joint j (between segment j and j+1) gets
``Continuity[j]`` ("C0".."C3", "G0".."G3") and, for G orders, ``K[j]`` (``R'(0) = k P'(1)``).
Each following segment is re-solved with :func:`ght_cad.curves.continuity.join` against the already
joined previous one (its first r+1 control points move, the rest and its own μ, ν, γ stay), and
the measured order of every joint (:func:`ght_cad.curves.continuity.measure_continuity`) is reported in
``JointOrders``. The linked segments themselves are not modified; the shape is a wire of B-spline
edges whose end derivatives equal the GHT curves' (``curve_to_bspline`` imposes the end jets).
"""

from __future__ import annotations

from typing import Any, Sequence

import FreeCAD as App
import Part

from ght_cad.core.errors import GHTError

from ._base import BaseCommand, FeatureProxy, ShapeParameterPanel, ViewProviderBase, new_feature, register_command, require_links, set_read_only, tolerance_property
from .convert import DEFAULT_TOL, curve_data, edge_from_data
from .ght_curve import core_curve

__all__ = ["CompositeCurveFeature", "make_composite_curve", "joined_curves"]


def joined_curves(obj: Any) -> list:
    """The segments as :class:`ght_cad.GHTCurve` objects after imposing each joint's continuity."""
    from ght_cad.curves.continuity import join

    segs = list(obj.Segments)
    if len(segs) < 2:
        raise GHTError(f"a composite curve needs >= 2 segments; {obj.Label} has {len(segs)}")
    for i, seg in enumerate(segs):
        if getattr(getattr(seg, "Proxy", None), "Type", "") != "GHT::Curve":
            raise GHTError(f"{obj.Label}.Segments[{i}] = {seg.Label} is not a GHT curve; link GHT curve features only")
        if seg in segs[:i]:
            raise GHTError(f"{obj.Label}.Segments[{i}] = {seg.Label} is already Segments[{segs.index(seg)}]; "
                             "allowed: each curve once (copy the curve to repeat its shape)")
    n = len(segs) - 1
    conts = list(obj.Continuity)
    ks = [float(x) for x in obj.K] or [1.0] * n
    for name, vals in (("Continuity", conts), ("K", ks)):
        if len(vals) != n:
            raise GHTError(
                f"{obj.Label}.{name} has {len(vals)} value{'s' if len(vals) != 1 else ''} for {n} joint{'s' if n != 1 else ''}; "
                f"give exactly one per joint (segments - 1){' or none for k = 1' if name == 'K' else ''}"
            )
    curves = [core_curve(segs[0], placed=True)]
    for j, seg in enumerate(segs[1:]):
        cont, k = conts[j], ks[j]
        b = core_curve(seg, placed=True)
        kw = {"k": k} if cont.upper().startswith("G") and cont[1:] != "0" else {}
        curves.append(join(curves[-1], cont, b, **kw))
    return curves


class CompositeCurveFeature(FeatureProxy):
    """Proxy of a composite GHT curve (``Part::FeaturePython``)."""

    Type = "GHT::CompositeCurve"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkList", "Segments", "Input", "GHT curve features, in order (each is joined to the previous one)")
        obj.addProperty("App::PropertyStringList", "Continuity", "Joints", "Continuity per joint: C0..C3 or G0..G3")
        obj.addProperty("App::PropertyFloatList", "K", "Joints", "G-joint tangent ratio k > 0 per joint (R'(0) = k P'(1)); empty: k = 1 at every joint")
        obj.addProperty("App::PropertyFloat", "Tolerance", "Conversion", "Maximum deviation (> 0) of each B-spline edge")
        obj.Tolerance = DEFAULT_TOL
        obj.addProperty("App::PropertyStringList", "JointOrders", "Output", "Measured continuity per joint, e.g. C1/G2")
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, ("JointOrders",))

    def compute(self, obj: Any) -> None:
        from ght_cad.curves.continuity import measure_continuity

        curves = joined_curves(obj)
        tol = tolerance_property(obj)
        edges = [edge_from_data(curve_data(c, tol=tol)) for c in curves]
        orders = []
        for a, b in zip(curves[:-1], curves[1:]):
            rep = measure_continuity(a, b, tol=1e-7)
            orders.append(f"C{rep.c_order}/G{rep.g_order}")
        obj.JointOrders = orders
        obj.Shape = Part.Wire(edges)


class ViewProviderCompositeCurve(ViewProviderBase):
    icon_name = "GHT_CompositeCurve"
    line_color = (0.1, 0.45, 0.2)
    line_width = 2.5

    def claimChildren(self) -> list:
        return list(getattr(self.obj, "Segments", []))


def _panel(obj: Any) -> ShapeParameterPanel:
    """Live preview of the last segment's shape parameters (the joint re-solves as they change)."""
    require_links(obj, "Segments")
    return ShapeParameterPanel(obj.Segments[-1], title="last segment of " + obj.Label)


ViewProviderCompositeCurve.panel_factory = staticmethod(_panel)


def make_composite_curve(
    segments: Sequence[Any], continuity: Sequence[str] | str = "C1", k: Sequence[float] | None = None, *, doc: Any = None, name: str = "CompositeCurve"
) -> Any:
    """Create a composite curve from GHT curve features.

    Args:
        segments: >= 2 GHT curve features in order.
        continuity: one string per joint, or one for all joints ("C0".."C3", "G0".."G3").
        k: G tangent ratios per joint (default 1).

    Returns:
        The recomputed feature; its ``JointOrders`` holds the measured continuity.
    """
    from ght_cad.curves.continuity import Continuity

    n = len(segments) - 1
    conts = [continuity] * n if isinstance(continuity, str) else list(continuity)
    if len(conts) != n:
        raise GHTError(f"{len(conts)} continuity values for {n} joints")
    conts = [Continuity.parse(c).value for c in conts]
    obj = new_feature(doc or segments[0].Document, name, CompositeCurveFeature, ViewProviderCompositeCurve)
    obj.Segments = list(segments)
    obj.Continuity = conts
    obj.K = [1.0] * n if k is None else [float(x) for x in k]
    if App.GuiUp:
        for s in segments:
            s.ViewObject.Visibility = False
    obj.Document.recompute()
    return obj


class CommandCompositeCurve(BaseCommand):
    name = "GHT_CompositeCurve"
    icon_name = "GHT_CompositeCurve"
    menu_text = "Composite curve"
    tooltip = (
        "Join the selected GHT curves (in selection order) into one composite curve; "
        "continuity per joint (C0..C3, G0..G3) in the Continuity property, default G1. "
        "With nothing selected, two demo segments are created."
    )

    def Activated(self) -> None:
        import FreeCADGui as Gui

        from .ght_curve import GHTCurveFeature, make_ght_curve

        doc = App.ActiveDocument
        segs = [o for o in Gui.Selection.getSelection() if isinstance(getattr(o, "Proxy", None), GHTCurveFeature)]
        doc.openTransaction("Composite curve")
        if len(segs) < 2:
            a = make_ght_curve([(0, 0, 0), (10, 15, 0), (25, 15, 0), (30, 0, 0)], doc=doc)
            b = make_ght_curve([(30, 0, 0), (35, -10, 0), (50, -10, 0), (60, 0, 0)], gamma=-0.5, doc=doc)
            segs = [a, b]
        obj = make_composite_curve(segs, "G1", doc=doc)
        doc.commitTransaction()
        self.open_panel(obj)


register_command(CommandCompositeCurve())
