r"""Developable surface from control planes (spec section 5.2) as a B-spline face.

Control planes ``U_0..U_m`` (4-vectors ``(u0, u1, u2, u3)``: ``u0 + u1 x + u2 y + u3 z = 0``) come
from linked plane features / planar faces (``Planes``, each scaled by ``PlaneWeights[i]``) or from
``PlaneCoordinates`` (4 numbers per plane). The dual curve ``U(t) = Σ b_{i,m}(t; μ,ν,γ) U_i``
envelopes a developable surface whose rulings ``U ∩ U'`` are cut by the two boundary planes
``E_a, E_b`` (``BoundaryPlanes`` links or ``BoundaryCoordinates``): ``a(t) = U ∩ U' ∩ E_a``,
``b(t) = U ∩ U' ∩ E_b``; the face is the B-spline fit of the paired (a, b) with degree 1 across.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

import FreeCAD as App
import Part

from ght_cad.core.errors import GHTError

from ._base import (
    BaseCommand,
    FeatureProxy,
    ShapeParameterPanel,
    ViewProviderBase,
    add_shape_parameters,
    check_shape,
    float_list,
    link_sub_list,
    new_feature,
    register_command,
    set_read_only,
    tolerance_property,
)
from .convert import ruled_face

__all__ = ["DevelopableFeature", "make_developable", "plane_from_link", "SurfaceOutputs"]

# Exact quarter cylinder of radius 10 and height 20 at γ = -1, μ = ν = 0 (spec section 1).
DEFAULT_PLANES = [(-10.0, 1.0, 0.0, 0.0), (-10.0, 1.0, 1.0, 0.0), (-10.0, 0.0, 1.0, 0.0)]
DEFAULT_BOUNDARY = [(0.0, 0.0, 0.0, 1.0), (-20.0, 0.0, 0.0, 1.0)]


def plane_from_link(obj: Any, sub: str = "") -> np.ndarray:
    """Plane 4-vector ``(-n·p, n)`` (unit normal n through p) of a plane feature or a planar face."""
    if sub:
        face = obj.Shape.getElement(sub)
    elif obj.isDerivedFrom("App::Plane") or obj.isDerivedFrom("PartDesign::Plane"):
        pl = obj.getGlobalPlacement()
        n = pl.Rotation.multVec(App.Vector(0, 0, 1))
        p = pl.Base
        return np.array([-n.dot(p), n.x, n.y, n.z])
    elif hasattr(obj, "Shape") and len(obj.Shape.Faces) == 1:
        face = obj.Shape.Faces[0]
    else:
        raise GHTError(f"{obj.Label}{'.' + sub if sub else ''} is not a plane feature or a single planar face")
    if not isinstance(face, Part.Face) or not isinstance(face.Surface, Part.Plane):
        raise GHTError(f"{obj.Label}.{sub or 'Face1'} is not planar ({type(getattr(face, 'Surface', None)).__name__})")
    u0, u1, v0, v1 = face.ParameterRange
    n = face.normalAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
    p = face.valueAt(0.5 * (u0 + u1), 0.5 * (v0 + v1))
    return np.array([-n.dot(p), n.x, n.y, n.z])


def _planes(links: Sequence[Any], coords: Sequence[float], what: str) -> np.ndarray:
    if links:
        out = []
        for obj, subs in links:
            subs = [s for s in subs if s] or [""]
            out += [plane_from_link(obj, s) for s in subs]
        return np.array(out)
    arr = np.asarray(list(coords), dtype=float)
    if arr.size == 0:
        link = "BoundaryPlanes" if what.startswith("Boundary") else "Planes"
        raise GHTError(f"no planes: {link} links nothing (deleted?) and {what} is empty; link planes or give 4 numbers (u0, u1, u2, u3) per plane")
    if arr.size % 4:
        raise GHTError(f"{what} has {arr.size} numbers; give 4 per plane (u0, u1, u2, u3)")
    return arr.reshape(-1, 4)


class SurfaceOutputs:
    """Mixin: developability outputs of a ruled-surface feature (spec section 5)."""

    OUTPUTS = ("ThetaMax", "ThetaRms", "DD", "R", "MaxDeviation")

    def add_outputs(self, obj: Any) -> None:
        obj.addProperty("App::PropertyFloat", "Tolerance", "Conversion", "Maximum deviation of the B-spline face from the exact surface (0: 1e-7 of its size)")
        obj.addProperty("App::PropertyAngle", "ThetaMax", "Developability", "max θ(u) = angle(n_a, n_b) along the rulings (0 for a developable)")
        obj.addProperty("App::PropertyAngle", "ThetaRms", "Developability", "sqrt(∫ θ(u)² du)")
        obj.addProperty("App::PropertyFloat", "DD", "Developability", "degree of developability ∫ cos θ(u) du (1 = developable)")
        obj.addProperty("App::PropertyFloat", "R", "Developability", "objective ∫ (1 - n_a·n_b) du")
        obj.addProperty("App::PropertyFloat", "MaxDeviation", "Conversion", "deviation of the face from the exact surface")
        set_read_only(obj, self.OUTPUTS)

    def build(self, obj: Any, surface: Any) -> None:
        tol = tolerance_property(obj, zero_means="1e-7 of the surface size")
        face, data = ruled_face(surface, tol)
        dev = surface.developability()
        obj.ThetaMax, obj.ThetaRms, obj.DD, obj.R = dev.theta_max, dev.theta_rms, dev.dd, dev.R
        obj.MaxDeviation = float(data.max_deviation or 0.0)
        obj.Shape = face


class DevelopableFeature(SurfaceOutputs, FeatureProxy):
    """Proxy of a developable surface from control planes (``Part::FeaturePython``)."""

    Type = "GHT::Developable"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkSubList", "Planes", "Input", "Control planes U_0..U_m (plane features or planar faces, in order); overrides PlaneCoordinates")
        obj.addProperty("App::PropertyFloatList", "PlaneWeights", "Input", "Scale of each linked control plane (acts like a rational weight; e.g. sqrt(2) for an exact cylinder's middle plane)")
        obj.addProperty("App::PropertyFloatList", "PlaneCoordinates", "Input", "Control planes as 4-vectors u0, u1, u2, u3 (u0 + u1 x + u2 y + u3 z = 0), 4 numbers per plane")
        obj.addProperty("App::PropertyLinkSubList", "BoundaryPlanes", "Input", "Two boundary planes E_a, E_b cutting the rulings; overrides BoundaryCoordinates")
        obj.addProperty("App::PropertyFloatList", "BoundaryCoordinates", "Input", "Boundary planes E_a, E_b as 4-vectors (8 numbers)")
        obj.addProperty("App::PropertyBool", "Normalize", "Input", "Rescale every control plane to a unit normal first")
        add_shape_parameters(obj)
        obj.addProperty("App::PropertyInteger", "Degree", "Output", "Degree m of the dual curve (number of control planes - 1)")
        self.add_outputs(obj)
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, ("Degree",) + self.OUTPUTS)

    def control_planes(self, obj: Any) -> tuple[np.ndarray, np.ndarray]:
        """(control planes (m+1, 4), boundary planes (2, 4)) from links or coordinates."""
        planes = _planes(obj.Planes, obj.PlaneCoordinates, "PlaneCoordinates")
        if len(obj.PlaneWeights) and not obj.Planes:
            raise GHTError(
                f"{obj.Label}.PlaneWeights scales linked Planes only; with PlaneCoordinates scale the 4 numbers of a "
                "plane instead and clear PlaneWeights"
            )
        if obj.Planes and len(obj.PlaneWeights):
            w = np.asarray(list(obj.PlaneWeights), dtype=float)
            if w.size != planes.shape[0]:
                raise GHTError(f"PlaneWeights has {w.size} values for {planes.shape[0]} planes")
            for i, x in enumerate(w):
                if not np.isfinite(x) or x == 0.0:
                    raise GHTError(f"{obj.Label}.PlaneWeights[{i}]={x!r} is not allowed; weights must be finite and non-zero")
            planes = planes * w[:, None]
        boundary = _planes(obj.BoundaryPlanes, obj.BoundaryCoordinates, "BoundaryCoordinates")
        return planes, boundary

    def surface(self, obj: Any) -> Any:
        """The core :class:`ght_cad.developables.envelope.EnvelopeDevelopable` of the feature."""
        from ght_cad import developable_from_planes

        planes, boundary = self.control_planes(obj)
        return developable_from_planes(planes, boundary, float(obj.Mu), float(obj.Nu), float(obj.Gamma), normalize=bool(obj.Normalize))

    def compute(self, obj: Any) -> None:
        surf = self.surface(obj)
        obj.Degree = len(surf.planes) - 1 if hasattr(surf, "planes") else 0
        self.build(obj, surf)


class ViewProviderDevelopable(ViewProviderBase):
    icon_name = "GHT_Developable"
    shape_color = (0.5, 0.7, 0.9)

    def claimChildren(self) -> list:
        links = list(getattr(self.obj, "Planes", [])) + list(getattr(self.obj, "BoundaryPlanes", []))
        return [o for o, _ in links]


ViewProviderDevelopable.panel_factory = staticmethod(lambda obj: ShapeParameterPanel(obj, title="developable surface"))


def make_developable(
    planes: Any = None,
    boundary_planes: Any = None,
    mu: float = 0.0,
    nu: float = 0.0,
    gamma: float = 0.0,
    *,
    weights: Sequence[float] | None = None,
    doc: Any = None,
    name: str = "Developable",
) -> Any:
    """Create a developable surface from control planes.

    Args:
        planes: (m+1, 4) plane 4-vectors, or links ``[(plane_obj, ""), (obj, ["Face2"]), ...]``.
        boundary_planes: two 4-vectors or two links (E_a, E_b).
        mu, nu, gamma: shape parameters in [-1, 1].
        weights: scale per linked control plane.

    Returns:
        The recomputed feature (``ThetaMax``/``DD`` report its developability).
    """
    check_shape(mu, nu, gamma)
    obj = new_feature(doc, name, DevelopableFeature, ViewProviderDevelopable)
    planes = DEFAULT_PLANES if planes is None else planes
    boundary_planes = DEFAULT_BOUNDARY if boundary_planes is None else boundary_planes

    def is_links(v: Any) -> bool:
        return len(v) > 0 and isinstance(v[0], tuple) and hasattr(v[0][0], "TypeId")

    if is_links(planes):
        obj.Planes = link_sub_list(planes)
        if weights is not None:
            obj.PlaneWeights = [float(w) for w in weights]
    else:
        obj.PlaneCoordinates = float_list(planes)
    if is_links(boundary_planes):
        obj.BoundaryPlanes = link_sub_list(boundary_planes)
    else:
        obj.BoundaryCoordinates = float_list(boundary_planes)
    obj.Mu, obj.Nu, obj.Gamma = float(mu), float(nu), float(gamma)
    obj.Document.recompute()
    return obj


class CommandDevelopable(BaseCommand):
    name = "GHT_Developable"
    icon_name = "GHT_Developable"
    menu_text = "Developable from planes"
    tooltip = (
        "Developable surface enveloped by GHT-blended control planes: select >= 3 control planes "
        "(plane features or planar faces) and then 2 boundary planes, in order. With nothing "
        "selected: the exact quarter cylinder (γ = -1) r = 10, H = 20 from plane coordinates."
    )

    def Activated(self) -> None:
        import FreeCADGui as Gui

        links = []
        for sel in Gui.Selection.getSelectionEx():
            faces = [s for s in sel.SubElementNames if s.startswith("Face")]
            links += [(sel.Object, [s]) for s in faces] if faces else [(sel.Object, "")]
        doc = App.ActiveDocument
        doc.openTransaction("Developable")
        if len(links) >= 5:
            obj = make_developable(links[:-2], links[-2:], doc=doc)
        else:
            obj = make_developable(gamma=-1.0, doc=doc)
        doc.commitTransaction()
        self.open_panel(obj)


register_command(CommandDevelopable())
