r"""GHT-Bézier curve feature: ``P(t) = Σ_{i=0..m} b_{i,m}(t; μ, ν, γ) P_i`` as a B-spline edge.

Control points come from a list (``ControlPoints``) or from linked geometry (``Source``: selected
vertices, a sketch's points or any shape's vertices, in order). The core evaluates the curve and
``ght_cad.surfaces.bspline.curve_to_bspline`` turns it into B-spline data within ``Tolerance``; that data
becomes a ``Part.BSplineCurve``.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

import FreeCAD as App
import Part

from ._base import (
    BaseCommand,
    FeatureProxy,
    ShapeParameterPanel,
    ViewProviderBase,
    add_shape_parameters,
    check_shape,
    link_sub_list,
    new_feature,
    register_command,
    set_read_only,
    tolerance_property,
)
from .convert import DEFAULT_TOL, curve_data, edge_from_data, points_array
from ght_cad.core.errors import GHTError

__all__ = ["GHTCurveFeature", "make_ght_curve", "points_from_links", "core_curve"]


def points_from_links(links: Sequence[tuple[Any, Sequence[str]]]) -> list["App.Vector"]:
    """Points of linked geometry, in order: named vertices, else a sketch's Part.Point geometries,
    else a points cloud, else every vertex of the shape."""
    pts: list[App.Vector] = []
    for obj, subs in links:
        subs = [s for s in (subs or []) if s]
        if subs:
            nv = len(obj.Shape.Vertexes)
            for s in subs:
                if s.startswith("Vertex") and s[6:].isdigit() and not 1 <= int(s[6:]) <= nv:
                    raise GHTError(f"Source: {obj.Label} has no {s} (it has {nv} vertices); link existing vertices, a sketch or a shape")
                el = obj.Shape.getElement(s)
                if not isinstance(el, Part.Vertex):
                    raise GHTError(f"{obj.Label}.{s} is a {type(el).__name__}; select vertices or a sketch")
                pts.append(App.Vector(el.Point))
            continue
        if obj.isDerivedFrom("Sketcher::SketchObject"):
            geo = [g for g in obj.Geometry if isinstance(g, Part.Point)]
            if geo:
                pts += [obj.getGlobalPlacement().multVec(App.Vector(g.X, g.Y, g.Z)) for g in geo]
                continue
        if hasattr(obj, "Points") and hasattr(obj.Points, "Points"):
            pts += [App.Vector(p) for p in obj.Points.Points]
            continue
        pts += [App.Vector(v.Point) for v in obj.Shape.Vertexes]
    return pts


def core_curve(obj: Any, placed: bool = False) -> Any:
    """The :class:`ght_cad.GHTCurve` a GHT curve feature describes (3-D control points).

    Args:
        obj: a GHT curve feature.
        placed: move the control points by the feature's ``Placement`` (what the user sees after
            moving the curve with the placement dialog). The GHT basis sums to 1 (spec section 1),
            so moving the control points rigidly moves the curve: ``P(t; g·P_i) = g·P(t; P_i)``.
            Features built on a curve (composite, spine, optimization) use ``placed=True``; the
            curve's own shape is built unplaced and FreeCAD applies its Placement on top.
    """
    from ght_cad import GHTCurve

    pts = obj.ControlPoints
    if placed and hasattr(obj, "Placement") and not obj.Placement.isIdentity():
        pts = [obj.Placement.multVec(App.Vector(p)) for p in pts]
    return GHTCurve(points_array(pts), float(obj.Mu), float(obj.Nu), float(obj.Gamma))


class GHTCurveFeature(FeatureProxy):
    """Proxy of a GHT curve (``Part::FeaturePython``)."""

    Type = "GHT::Curve"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkSubList", "Source", "Input", "Vertices, a sketch or a shape whose points become the control points (overrides ControlPoints)")
        obj.addProperty("App::PropertyVectorList", "ControlPoints", "Input", "Control points P_0..P_m (m >= 2)")
        add_shape_parameters(obj)
        obj.addProperty("App::PropertyFloat", "Tolerance", "Conversion", "Maximum deviation (> 0) of the B-spline edge from the exact GHT curve")
        obj.Tolerance = DEFAULT_TOL
        obj.addProperty("App::PropertyInteger", "Degree", "Output", "Degree m = number of control points - 1")
        obj.addProperty("App::PropertyFloat", "CurveLength", "Output", "Arc length ∫|P'(t)|dt of the exact curve")
        obj.addProperty("App::PropertyFloat", "MaxDeviation", "Output", "Deviation of the B-spline from the exact curve")
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, ("Degree", "CurveLength", "MaxDeviation"))

    def compute(self, obj: Any) -> None:
        if obj.Source:
            pts = points_from_links(obj.Source)
            if [tuple(p) for p in pts] != [tuple(p) for p in obj.ControlPoints]:
                obj.ControlPoints = pts
        tol = tolerance_property(obj)
        pts = points_array(obj.ControlPoints)
        if len(pts) >= 2:
            spread = float(np.max(np.linalg.norm(pts - pts[0], axis=1)))
            if spread <= 1e-12 * max(1.0, float(np.max(np.abs(pts)))):
                raise GHTError(
                    f"{obj.Label}.ControlPoints: all {len(pts)} points coincide at {tuple(pts[0])}; the curve would be a "
                    "single point (at least two control points must differ)"
                )
        curve = core_curve(obj)
        data = curve_data(curve, tol=tol)
        obj.Shape = edge_from_data(data)
        obj.Degree = curve.degree
        obj.CurveLength = float(curve.arc_length())
        obj.MaxDeviation = float(data.max_deviation) if data.max_deviation is not None else 0.0


class ViewProviderGHTCurve(ViewProviderBase):
    icon_name = "GHT_Curve"
    line_color = (0.1, 0.3, 0.55)
    line_width = 2.0

    def claimChildren(self) -> list:
        return []


def _panel(obj: Any) -> ShapeParameterPanel:
    return ShapeParameterPanel(obj, title="GHT curve")


ViewProviderGHTCurve.panel_factory = staticmethod(_panel)


def make_ght_curve(
    control_points: Any = None,
    mu: float = 0.0,
    nu: float = 0.0,
    gamma: float = 0.0,
    *,
    source: Any = None,
    doc: Any = None,
    name: str = "GHTCurve",
) -> Any:
    """Create a GHT curve feature.

    Args:
        control_points: (m+1, 2|3) points (m >= 2), unless ``source`` is given.
        mu, nu, gamma: shape parameters in [-1, 1].
        source: ``[(obj, ["Vertex1", ...]), (sketch, [])]`` links that supply the points.
        doc: target document (default: the active one).

    Returns:
        The recomputed ``Part::FeaturePython`` object.
    """
    check_shape(mu, nu, gamma)
    obj = new_feature(doc, name, GHTCurveFeature, ViewProviderGHTCurve)
    if control_points is not None:
        pts = np.asarray(control_points, dtype=float)
        obj.ControlPoints = [App.Vector(*(list(p) + [0.0] * (3 - len(p)))[:3]) for p in pts]
    if source is not None:
        obj.Source = link_sub_list(source)
    obj.Mu, obj.Nu, obj.Gamma = float(mu), float(nu), float(gamma)
    obj.Document.recompute()
    return obj


class CommandGHTCurve(BaseCommand):
    name = "GHT_Curve"
    icon_name = "GHT_Curve"
    menu_text = "GHT curve"
    tooltip = (
        "GHT-Bézier curve from the selected vertices (in selection order) or sketch points; "
        "with nothing selected, a default degree-3 curve. Shape parameters μ, ν, γ ∈ [-1, 1]."
    )

    def Activated(self) -> None:
        import FreeCADGui as Gui

        links = []
        for sel in Gui.Selection.getSelectionEx():
            links.append((sel.Object, [s for s in sel.SubElementNames if s.startswith("Vertex")]))
        doc = App.ActiveDocument
        doc.openTransaction("GHT curve")
        if links and len(points_from_links(links)) >= 3:
            obj = make_ght_curve(source=links, doc=doc)
        else:
            obj = make_ght_curve([(0, 0, 0), (10, 20, 0), (30, 20, 0), (40, 0, 0)], doc=doc)
        doc.commitTransaction()
        self.open_panel(obj)


register_command(CommandGHTCurve())
