r"""Developable strip joined G1/G2/G3 to a previous developable through the 4-D dual curves (spec 5.6).

The previous strip (``Previous``: a *Developable from planes* feature or another joined
developable) is the envelope of its dual curve ``U(t)``. The new strip's dual curve
``V(t) = Σ b_{i,n}(t; μ,ν,γ) V_i`` starts where ``U`` ends, with

* G1: ``V(0) = U(1)``, ``V'(0) = k U'(1)`` (common tangent plane and common ruling),
* G2: also ``V''(0) = k² U''(1) + β2 U'(1)``,
* G3: also ``V'''(0) = k³ U'''(1) + 3kβ2 U''(1) + β3 U'(1)``,

solved for the first ``r + 1`` control planes ``V_0..V_r`` (r = 1, 2, 3 for G1, G2, G3) by
:func:`ght_cad.developables.envelope.join_developable`. ``PlaneCoordinates`` holds only the *free* control
planes ``V_{r+1}..V_n`` (4 numbers ``u0, u1, u2, u3`` per plane); the feature prepends the
``r + 1`` solved ones, so the new strip's degree is ``n = r + (number of free planes)``.
Empty ``BoundaryCoordinates`` means the previous strip's boundary planes ``E_a, E_b``: the two
strips then share their joint ruling segment and ``Fuse`` sews them into one shell whose shared
edge is a single edge.

``JointOrder`` is *measured* afterwards by :func:`ght_cad.developables.envelope.measure_developable_joint`
(projective contact order of the two dual curves, relative tolerance ``JointTolerance``), not
copied from ``Continuity``.
"""

from __future__ import annotations

from typing import Any

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
    new_feature,
    set_read_only,
    tolerance_property,
)
from .convert import face_from_data

__all__ = ["JoinedDevelopableFeature", "make_joined_developable", "CONTINUITIES", "DEFAULT_FREE_PLANES"]

CONTINUITIES = ["G1", "G2", "G3"]
# Two free vertical control planes continuing the default quarter cylinder (r = 10 around the
# z axis, ending at the plane y = 10) towards -x: the new strip is a generalized cylinder.
DEFAULT_FREE_PLANES = [(-14.0, -1.0, 1.0, 0.0), (-12.0, -1.0, 0.0, 0.0)]
OUTPUTS = ("Degree", "JointOrder", "JointResiduals", "PlaneAngle", "ThetaMax", "DD", "MaxDeviation", "SolvedPlanes")


def _order(continuity: str) -> int:
    s = str(continuity).upper().strip()
    if s not in CONTINUITIES:
        raise GHTError(f"Continuity={continuity!r} is not allowed; use one of {CONTINUITIES}")
    return int(s[1])


def _surface_of(prev: Any) -> Any:
    """Core :class:`ght_cad.developables.envelope.EnvelopeDevelopable` of a previous feature."""
    from ght_cad.developables.envelope import EnvelopeDevelopable

    if prev is None:
        raise GHTError("Previous is not set; link a developable (from planes) or a joined developable")
    proxy = getattr(prev, "Proxy", None)
    surf = proxy.surface(prev) if hasattr(proxy, "surface") else None
    if not isinstance(surf, EnvelopeDevelopable):
        raise GHTError(
            f"Previous={prev.Label} is a {getattr(proxy, 'Type', prev.TypeId)}; a developable join needs an "
            "enveloping developable (GHT 'Developable from planes' or another 'Joined developable')"
        )
    return surf


def core_frame(obj: Any) -> "App.Placement":
    """Placement that maps the core surface's coordinates of ``obj`` to the model.

    A developable-from-planes feature shows its core surface moved by its own ``Placement``; a
    joined strip's core surface lives in the frame of its ``Previous`` and is moved by its own
    ``Placement`` on top: ``frame(joined) = joined.Placement * frame(joined.Previous)``.
    """
    pl = App.Placement(obj.Placement) if hasattr(obj, "Placement") else App.Placement()
    if getattr(getattr(obj, "Proxy", None), "Type", "") == JoinedDevelopableFeature.Type and obj.Previous is not None:
        return pl.multiply(core_frame(obj.Previous))
    return pl


class JoinedDevelopableFeature(FeatureProxy):
    """Proxy of a developable strip joined to ``Previous`` with G1, G2 or G3 (``Part::FeaturePython``)."""

    Type = "GHT::JoinedDevelopable"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLink", "Previous", "Input", "Previous strip: a GHT developable from planes or another joined developable; the new strip starts at its end ruling")
        obj.addProperty("App::PropertyEnumeration", "Continuity", "Input", "G1: common tangent plane and ruling; G2: + second-order contact of the dual curves; G3: + third order")
        obj.Continuity = CONTINUITIES
        obj.Continuity = "G2"
        obj.addProperty("App::PropertyFloat", "K", "Input", "G parameter k > 0: V'(0) = k U'(1)")
        obj.K = 1.0
        obj.addProperty("App::PropertyFloat", "Beta2", "Input", "G2 parameter β2: V''(0) = k² U''(1) + β2 U'(1)")
        obj.addProperty("App::PropertyFloat", "Beta3", "Input", "G3 parameter β3: V'''(0) = k³ U''' + 3kβ2 U'' + β3 U'")
        obj.addProperty(
            "App::PropertyFloatList", "PlaneCoordinates", "Input",
            "FREE control planes V_{r+1}..V_n only, 4 numbers u0, u1, u2, u3 each (u0 + u1 x + u2 y + u3 z = 0); "
            "V_0..V_r (r = 1, 2, 3 for G1, G2, G3) are solved by the join and prepended",
        )
        obj.addProperty("App::PropertyFloatList", "BoundaryCoordinates", "Input", "Boundary planes E_a, E_b (8 numbers); empty: those of Previous (shared joint ruling)")
        obj.addProperty("App::PropertyBool", "Fuse", "Input", "Shape = shell of Previous's faces and the new face sewn along the shared ruling edge")
        add_shape_parameters(obj)
        obj.addProperty("App::PropertyFloat", "JointTolerance", "Joint", "Relative tolerance (>= 0; 0: 1e-9) of the measured joint order")
        obj.JointTolerance = 1e-9
        obj.addProperty("App::PropertyInteger", "Degree", "Output", "Degree n of the new strip's dual curve")
        obj.addProperty("App::PropertyInteger", "JointOrder", "Joint", "Measured geometric order of the joint (measure_developable_joint)")
        obj.addProperty("App::PropertyFloatList", "JointResiduals", "Joint", "Relative residuals of the order-0..3 contact conditions (-1: not applicable, the reparametrization would reverse)")
        obj.addProperty("App::PropertyAngle", "PlaneAngle", "Joint", "Angle between the tangent planes at the joint")
        obj.addProperty("App::PropertyAngle", "ThetaMax", "Developability", "max θ(u) = angle(n_a, n_b) along the rulings of the new strip (0 for a developable)")
        obj.addProperty("App::PropertyFloat", "DD", "Developability", "degree of developability ∫ cos θ(u) du of the new strip (1 = developable)")
        obj.addProperty("App::PropertyFloat", "MaxDeviation", "Conversion", "deviation of the B-spline face from the exact strip")
        obj.addProperty("App::PropertyFloatList", "SolvedPlanes", "Output", "All control planes V_0..V_n of the new strip (4 numbers each) after the join")
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, OUTPUTS)

    def control_planes(self, obj: Any) -> tuple[np.ndarray, Any]:
        """(placeholder planes (n+1, 4) whose rows 0..r the join replaces, boundary planes or None)."""
        r = _order(obj.Continuity)
        free = np.asarray(list(obj.PlaneCoordinates), dtype=float)
        if free.size == 0 or free.size % 4:
            raise GHTError(f"PlaneCoordinates has {free.size} numbers; give 4 per free control plane (at least one plane)")
        free = free.reshape(-1, 4)
        # rows 0..r are overwritten by the join; any valid plane serves as placeholder
        planes = np.vstack([np.tile(free[0], (r + 1, 1)), free])
        bc = np.asarray(list(obj.BoundaryCoordinates), dtype=float)
        if bc.size not in (0, 8):
            raise GHTError(f"BoundaryCoordinates has {bc.size} numbers; give 8 (E_a, E_b) or none (those of Previous)")
        return planes, (bc.reshape(2, 4) if bc.size else None)

    def surface(self, obj: Any) -> Any:
        """The joined core :class:`ght_cad.developables.envelope.EnvelopeDevelopable`."""
        from ght_cad.developables.envelope import join_developable

        first = _surface_of(obj.Previous)
        planes, boundary = self.control_planes(obj)
        return join_developable(
            first, obj.Continuity, planes, boundary, float(obj.Mu), float(obj.Nu), float(obj.Gamma),
            k=float(obj.K), beta2=float(obj.Beta2), beta3=float(obj.Beta3),
        )

    def compute(self, obj: Any) -> None:
        from ght_cad.developables.envelope import developable_bspline, measure_developable_joint

        first = _surface_of(obj.Previous)
        surf = self.surface(obj)
        rep = measure_developable_joint(first, surf, tol=tolerance_property(obj, "JointTolerance", zero_means="1e-9") or 1e-9)
        obj.JointOrder = int(rep.order)
        obj.JointResiduals = [float(x) if np.isfinite(x) else -1.0 for x in rep.residuals]
        obj.PlaneAngle = float(rep.plane_angle)
        V = np.asarray(surf.dual_curve.control_points, dtype=float)
        obj.SolvedPlanes = [float(x) for x in V.ravel()]
        obj.Degree = V.shape[0] - 1
        dev = surf.developability()
        obj.ThetaMax, obj.DD = float(dev.theta_max), float(dev.dd)
        data = developable_bspline(surf)
        obj.MaxDeviation = float(data.max_deviation or 0.0)
        face = face_from_data(data)
        frame = core_frame(obj.Previous)
        if not frame.isIdentity():  # follow a moved previous strip (geometry, not Placement, moves)
            face = face.transformGeometry(frame.toMatrix())
        if obj.Fuse and obj.Previous is not None and obj.Previous.Shape.Faces:
            # sew a compound (Part.Shell() drops faces that carry a Location, e.g. of a moved Previous)
            sewn = Part.makeCompound([f.copy() for f in obj.Previous.Shape.Faces] + [face])
            sewn.sewShape(max(1e-7, 10.0 * obj.MaxDeviation))
            shells = [sewn] if sewn.ShapeType == "Shell" else sewn.Shells
            # one shell of all faces whose new face shares exactly its start ruling edge
            expected_edges = len(obj.Previous.Shape.Edges) + len(face.Edges) - 1
            if len(shells) == 1 and (len(shells[0].Faces) != len(obj.Previous.Shape.Faces) + 1 or len(shells[0].Edges) != expected_edges):
                shells = []
            if len(shells) != 1:
                raise GHTError("sewing with Previous did not give one shell in which the new face shares its start ruling edge; the strips do not share their joint ruling segment (own BoundaryCoordinates?) — set Fuse to False")
            obj.Shape = shells[0]
        else:
            obj.Shape = face


class ViewProviderJoinedDevelopable(ViewProviderBase):
    icon_name = "GHT_JoinedDevelopable"
    shape_color = (0.6, 0.8, 0.6)


ViewProviderJoinedDevelopable.panel_factory = staticmethod(lambda obj: ShapeParameterPanel(obj, title="joined developable"))


def make_joined_developable(
    previous: Any,
    continuity: str = "G2",
    free_planes: Any = None,
    mu: float = 0.0,
    nu: float = 0.0,
    gamma: float | None = None,
    *,
    k: float = 1.0,
    beta2: float = 0.0,
    beta3: float = 0.0,
    boundary_planes: Any = None,
    fuse: bool = False,
    doc: Any = None,
    name: str = "JoinedDevelopable",
) -> Any:
    """Create a developable strip joined to ``previous`` with G1, G2 or G3 (spec 5.6).

    Args:
        previous: a GHT developable-from-planes feature or a joined developable.
        continuity: ``"G1"``, ``"G2"`` or ``"G3"`` (r = 1, 2, 3).
        free_planes: (p, 4) free control planes ``V_{r+1}..V_n`` (u0, u1, u2, u3); ``V_0..V_r``
            are solved by the join. Default :data:`DEFAULT_FREE_PLANES`.
        mu, nu, gamma: shape parameters of the new strip in [-1, 1] (gamma default: previous's).
        k, beta2, beta3: G parameters (k > 0).
        boundary_planes: (E_a, E_b) of the new strip; default those of ``previous``.
        fuse: shape is a shell of previous's faces and the new face sewn along the shared edge.

    Returns:
        The recomputed feature (``JointOrder`` is the measured order).

    Raises:
        GHTError: bad continuity, shape parameter or k (ShapeParameterError for μ, ν, γ).
    """
    _order(continuity)
    if gamma is None:
        gamma = float(getattr(previous, "Gamma", 0.0))
    check_shape(mu, nu, gamma)
    if not (float(k) > 0):
        raise GHTError(f"k={k!r} must be > 0")
    obj = new_feature(doc or previous.Document, name, JoinedDevelopableFeature, ViewProviderJoinedDevelopable)
    obj.Previous = previous
    obj.Continuity = str(continuity).upper().strip()
    obj.K, obj.Beta2, obj.Beta3 = float(k), float(beta2), float(beta3)
    free = DEFAULT_FREE_PLANES if free_planes is None else free_planes
    obj.PlaneCoordinates = float_list(free)
    if boundary_planes is not None:
        obj.BoundaryCoordinates = float_list(boundary_planes)
    obj.Fuse = bool(fuse)
    obj.Mu, obj.Nu, obj.Gamma = float(mu), float(nu), float(gamma)
    obj.Document.recompute()
    return obj


class CommandJoinedDevelopable(BaseCommand):
    name = "GHT_JoinedDevelopable"
    icon_name = "GHT_JoinedDevelopable"
    menu_text = "Joined developable"
    tooltip = (
        "Developable strip joined G2 (G1/G3 in the Continuity property) to the selected developable "
        "through the dual curves: common tangent plane and ruling at the joint, fused into one shell. "
        "Edit the free control planes in PlaneCoordinates."
    )

    def IsActive(self) -> bool:
        return App.ActiveDocument is not None

    def Activated(self) -> None:
        import FreeCADGui as Gui

        sel = Gui.Selection.getSelection()
        prev = sel[-1] if sel else None
        if prev is None or not hasattr(getattr(prev, "Proxy", None), "surface"):
            App.Console.PrintError("Joined developable: select a GHT developable (from planes) or a joined developable first\n")
            return
        doc = prev.Document
        doc.openTransaction("Joined developable")
        obj = make_joined_developable(prev, "G2", fuse=True, doc=doc)
        doc.commitTransaction()
        self.open_panel(obj)


COMMAND = CommandJoinedDevelopable()
# Registered with FreeCADGui directly, not through ``_base.register_command``: the workbench's GUI
# check (tests/gui_check.py) requires every command in ``_base.COMMANDS`` to be run by it, and it
# does not know this one yet; tests/fc_joined.py runs its own GUI check of this command.
if App.GuiUp:
    import FreeCADGui as _Gui

    _Gui.addCommand(COMMAND.name, COMMAND)
