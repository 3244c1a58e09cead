r"""Spine (tangent) and geodesic (rectifying) developables of a GHT curve (spec 5.3, 5.4).

* Spine: ``X(t, v) = C(t) + v T(t)``, ``v ∈ [V0, V1]`` not containing 0 (C is the edge of
  regression).
* Geodesic: ``X(t, v) = C(t) + v D(t)``, ``D = (τT + κB)/sqrt(κ² + τ²)``; with ``V0 < 0 < V1`` the
  curve C lies on the strip as a geodesic (the strip a flat sheet makes when laid along C).

The curve is a linked GHT curve feature: its μ, ν, γ (task panel) reshape the developable.
"""

from __future__ import annotations

from typing import Any

import numpy as np

import FreeCAD as App

from ght_cad.core.errors import GHTError

from ._base import BaseCommand, FeatureProxy, ShapeParameterPanel, ViewProviderBase, new_feature, register_command, require_links, set_read_only
from .developable import SurfaceOutputs
from .ght_curve import core_curve

__all__ = ["SpineDevelopableFeature", "make_spine_developable", "KINDS"]

KINDS = ["Spine", "Geodesic"]


class SpineDevelopableFeature(SurfaceOutputs, FeatureProxy):
    """Proxy of a spine/geodesic developable (``Part::FeaturePython``)."""

    Type = "GHT::SpineDevelopable"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLink", "Curve", "Input", "GHT curve feature (3-D, no inflections)")
        obj.addProperty("App::PropertyEnumeration", "Kind", "Input", "Spine: tangent developable C + v T; Geodesic: rectifying developable C + v D (C is a geodesic)")
        obj.Kind = KINDS
        obj.addProperty("App::PropertyDistance", "V0", "Input", "Start of the ruling range (length units)")
        obj.addProperty("App::PropertyDistance", "V1", "Input", "End of the ruling range (length units)")
        self.add_outputs(obj)
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, self.OUTPUTS)

    def surface(self, obj: Any) -> Any:
        """The core :class:`TangentDevelopable` / :class:`RectifyingDevelopable`."""
        from ght_cad.developables.envelope import RectifyingDevelopable, TangentDevelopable

        if obj.Curve is None:
            raise GHTError(f"{obj.Label}: no Curve linked")
        if getattr(getattr(obj.Curve, "Proxy", None), "Type", "") != "GHT::Curve":
            raise GHTError(f"{obj.Label}.Curve = {obj.Curve.Label} is not a GHT curve; link a GHT curve feature")
        curve = core_curve(obj.Curve, placed=True)
        v0, v1 = float(obj.V0.Value), float(obj.V1.Value)
        if not (np.isfinite(v0) and np.isfinite(v1) and v0 < v1):
            raise GHTError(f"{obj.Label}: V0={v0:g} mm and V1={v1:g} mm are not allowed; they must be finite with V0 smaller than V1")
        cls = TangentDevelopable if obj.Kind == "Spine" else RectifyingDevelopable
        return cls(curve, v0, v1)

    def compute(self, obj: Any) -> None:
        self.build(obj, self.surface(obj))


class ViewProviderSpineDevelopable(ViewProviderBase):
    icon_name = "GHT_SpineDevelopable"
    shape_color = (0.6, 0.83, 0.6)

    def claimChildren(self) -> list:
        c = getattr(self.obj, "Curve", None)
        return [c] if c is not None else []


def _panel(obj: Any) -> ShapeParameterPanel:
    """Live preview of the linked curve's shape parameters (an unset Curve: a message instead)."""
    require_links(obj, "Curve")
    return ShapeParameterPanel(obj.Curve, title="curve of " + obj.Label)


ViewProviderSpineDevelopable.panel_factory = staticmethod(_panel)


def make_spine_developable(curve_obj: Any, kind: str = "Spine", v0: float = 2.0, v1: float = 10.0, *, doc: Any = None, name: str = "SpineDevelopable") -> Any:
    """Create a spine (``kind="Spine"``) or geodesic (``kind="Geodesic"``) developable of a GHT curve feature."""
    if kind not in KINDS:
        raise GHTError(f"kind={kind!r} is not allowed; use one of {KINDS}")
    obj = new_feature(doc or curve_obj.Document, name, SpineDevelopableFeature, ViewProviderSpineDevelopable)
    obj.Curve = curve_obj
    obj.Kind = kind
    obj.V0, obj.V1 = float(v0), float(v1)
    obj.Document.recompute()
    return obj


class CommandSpineDevelopable(BaseCommand):
    name = "GHT_SpineDevelopable"
    icon_name = "GHT_SpineDevelopable"
    menu_text = "Spine/geodesic developable"
    tooltip = (
        "Developable strip along the selected GHT curve: Kind = Spine (tangent developable, v in "
        "[V0, V1] away from the curve) or Geodesic (the curve is a geodesic of the strip)."
    )

    def Activated(self) -> None:
        import FreeCADGui as Gui

        from .ght_curve import GHTCurveFeature, make_ght_curve

        doc = App.ActiveDocument
        curves = [o for o in Gui.Selection.getSelection() if isinstance(getattr(o, "Proxy", None), GHTCurveFeature)]
        doc.openTransaction("Spine developable")
        if curves:
            curve = curves[0]
        else:
            curve = make_ght_curve([(0, 0, 0), (10, 0, 5), (20, 10, 5), (25, 20, 0)], doc=doc)
        obj = make_spine_developable(curve, "Geodesic", -3.0, 3.0, doc=doc)
        doc.commitTransaction()
        self.open_panel(obj)


register_command(CommandSpineDevelopable())
