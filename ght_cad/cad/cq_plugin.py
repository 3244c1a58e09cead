r"""cadquery Workplane plugin: GHT-Bézier curves as pending edges.

Importing this module registers three Workplane methods, following cadquery's plugin convention
(a function taking ``self``, attached to ``cq.Workplane``, that returns ``self.newObject(...)``):

- ``Workplane.ghtBezier(control_points, mu=0, nu=0, gamma=0, *, tol=None, degree=5,
  forConstruction=False, includeCurrent=False, makeWire=False)``
- ``Workplane.ghtCurve(curve_or_composite, *, tol=None, degree=5, forConstruction=False)``
- ``Workplane.developableLoft(rail_a=None, rail_b=None, **options)``: the exact developable loft
  between two rails (spec 5.7) as a ``cq.Shell``/``cq.Face`` on the stack; without arguments the
  rails are the two edges (or wires) on the stack. The plain function :func:`developable_loft_cq`
  returns the shape itself.

Control points are in the workplane's local coordinates (2-D or 3-D); they are mapped to world
coordinates point by point, which is exact because a GHT-Bézier curve is affinely invariant
(the basis is a partition of unity). The curve becomes one certified B-spline edge per segment
(:func:`ght_cad.cad.curves.ght_edge`), added to the pending edges so that ``.close()``,
``.wire()``, ``.extrude()``, ``.revolve()`` work as with ``.spline()``::

    import cadquery as cq
    import ght_cad.cad.cq_plugin  # registers the methods
    solid = (cq.Workplane("XY").moveTo(0, 0)
             .ghtBezier([(1, 1), (2, 1), (3, 0)], mu=0.3, includeCurrent=True)
             .close().extrude(1))

The edges wrap the very OCP objects that build123d uses: ``cq.Edge(b3d_edge.wrapped)``. The plugin
never imports build123d (the ``[cadquery]`` extra installs cadquery alone).
"""

from __future__ import annotations

from typing import Any, Iterable

import cadquery as cq
import numpy as np

from ..surfaces.bspline import curve_to_bspline
from ..curves.curve import GHTCurve
from ..core.errors import GHTError
from ._chain import segments_of
from .occ import make_edge

__all__ = ["ghtBezier", "ghtCurve", "developableLoft", "developable_loft_cq", "register"]


def _to_world(wp: "cq.Workplane", points: np.ndarray) -> np.ndarray:
    out = []
    for p in points:
        q = np.zeros(3)
        q[: p.size] = p
        v = wp.plane.toWorldCoords(tuple(float(x) for x in q))
        out.append((v.x, v.y, v.z))
    return np.array(out)


def _local_points(wp: "cq.Workplane", control_points: Iterable[Any], include_current: bool) -> np.ndarray:
    pts = [tuple(float(x) for x in (p.toTuple() if isinstance(p, cq.Vector) else p)) for p in control_points]
    if not pts:
        raise GHTError("control_points is empty; a GHT-Bézier curve needs at least 3 points")
    width = max(len(p) for p in pts)
    if width not in (2, 3):
        raise GHTError(f"control points must be 2-D or 3-D; got {width} coordinates")
    arr = np.zeros((len(pts), 3))
    for i, p in enumerate(pts):
        arr[i, : len(p)] = p
    if include_current:
        cur = wp._findFromPoint(True)  # local coordinates of the current point
        arr = np.vstack([[cur.x, cur.y, cur.z], arr])
    return arr


def _edge(curve: GHTCurve, tol: float | None, degree: int) -> "cq.Edge":
    """``cq.Edge`` on the certified B-spline of a 3-D GHT curve (:func:`ght_cad.surfaces.bspline.curve_to_bspline`)."""
    return cq.Edge(make_edge(curve_to_bspline(curve, tol, degree)).wrapped)


def _add_edges(wp: "cq.Workplane", edges: list, forConstruction: bool, makeWire: bool) -> "cq.Workplane":
    if makeWire:
        wire = cq.Wire.assembleEdges(edges)
        if not forConstruction:
            wp._addPendingWire(wire)
        return wp.newObject([wire])
    if not forConstruction:
        for e in edges:
            wp._addPendingEdge(e)
    return wp.newObject(edges)


def ghtBezier(
    self: "cq.Workplane",
    control_points: Iterable[Any],
    mu: float = 0.0,
    nu: float = 0.0,
    gamma: float = 0.0,
    *,
    tol: float | None = None,
    degree: int = 5,
    forConstruction: bool = False,
    includeCurrent: bool = False,
    makeWire: bool = False,
) -> "cq.Workplane":
    r"""Add the GHT-Bézier curve ``P(t) = Σ b_{i,m}(t; μ,ν,γ) P_i`` as a pending edge.

    Args:
        control_points: points in local coordinates (``includeCurrent`` prepends the current
            point as ``P_0``); at least 3 in total.
        mu, nu, gamma: shape parameters in [-1, 1].
        tol: maximum B-spline deviation (default 1e-7 × bounding-box diagonal).
        degree: B-spline degree.
        forConstruction: do not add to the pending edges.
        includeCurrent: start at the current point.
        makeWire: add a wire instead of an edge.

    Returns:
        A new Workplane whose stack holds the edge (current point = the curve's end).

    Raises:
        GHTError: fewer than 3 points, bad shape parameters or tol.
    """
    local = _local_points(self, control_points, includeCurrent)
    curve = GHTCurve(_to_world(self, local), mu, nu, gamma)
    edge = _edge(curve, tol, degree)
    return _add_edges(self, [edge], forConstruction, makeWire)


def ghtCurve(
    self: "cq.Workplane",
    curve: Any,
    *,
    tol: float | None = None,
    degree: int = 5,
    forConstruction: bool = False,
    makeWire: bool = False,
) -> "cq.Workplane":
    r"""Add a GHTCurve, a CompositeCurve (``.segments``) or a list of GHTCurves as pending edges.

    Control points are read in the workplane's local coordinates and mapped to world
    coordinates (exact by affine invariance); one certified edge per segment.

    Returns:
        A new Workplane holding the edges (or one wire with ``makeWire``).

    Raises:
        GHTError: not a curve / chain, a segment that is not 2-D or 3-D, bad tol.
    """
    segs, _ = segments_of(curve)
    for i, seg in enumerate(segs):
        if seg.dim not in (2, 3):
            raise GHTError(
                f"segment {i}: the curve has dimension {seg.dim}; a Workplane edge needs 2-D or 3-D "
                "control points (local workplane coordinates)"
            )
    edges = []
    for seg in segs:
        world = seg.with_control_points(_to_world(self, seg.control_points))
        edges.append(_edge(world, tol, degree))
    return _add_edges(self, edges, forConstruction, makeWire)


def developable_loft_cq(rail_a: Any, rail_b: Any, **options: Any) -> Any:
    r"""The exact developable loft between two rails as a cadquery ``Shell`` (or ``Face``).

    Rulings ``a(t)–b(σ(t))`` with ``det(a', b', b - a) = 0`` to round-off, fans at the rail ends
    (spec 5.7); the same B-rep as :func:`ght_cad.cad.loft.developable_loft` (one B-spline face per
    segment, degree 1 across the rulings, sewn), wrapping the same OCP shape.

    Args:
        rail_a, rail_b: cadquery/build123d ``Edge``/``Wire``, OCP edges/wires or 3-D GHTCurves.
        **options: ``tol``, ``degree``, ``sew_tol`` and the core options of
            :func:`ght_cad.developables.loft.developable_loft` (``orientation``, ``branch``, ...).

    Returns:
        ``cq.Shell`` or ``cq.Face`` with ``.ght_loft`` (the core loft: report, ``unroll``).

    Raises:
        NotDevelopableError: no developable joins the rails; GHTError: bad rails or options.
    """
    from .loft import loft_between

    shape = loft_between(rail_a, rail_b, **options)
    out = cq.Shell(shape.wrapped) if shape.wrapped.ShapeType().name == "TopAbs_SHELL" else cq.Face(shape.wrapped)
    from .certified import certify

    return certify(out, ght_loft=shape.ght_loft, ght_bspline=shape.ght_bspline,
                   ght_max_deviation=shape.ght_max_deviation)


def developableLoft(self: "cq.Workplane", rail_a: Any = None, rail_b: Any = None, **options: Any) -> "cq.Workplane":
    r"""Workplane method: the exact developable loft between two rails, pushed on the stack.

    Args:
        rail_a, rail_b: the rails (see :func:`developable_loft_cq`); both None: the two edges or
            wires on the stack, in stack order (``cq.Workplane().add(e1).add(e2).developableLoft()``).
        **options: as in :func:`developable_loft_cq`.

    Returns:
        A new Workplane whose stack holds the ``Shell``/``Face``.

    Raises:
        GHTError: only one rail given, or not exactly two edges/wires on the stack.
    """
    if (rail_a is None) != (rail_b is None):
        raise GHTError("developableLoft needs two rails: give rail_a and rail_b, or neither (the two edges on the stack)")
    if rail_a is None:
        rails = [o for o in self.vals() if isinstance(o, (cq.Edge, cq.Wire))]
        if len(rails) != 2:
            raise GHTError(f"developableLoft without rails needs exactly two edges or wires on the stack; found {len(rails)}")
        rail_a, rail_b = rails
    return self.newObject([developable_loft_cq(rail_a, rail_b, **options)])


def register() -> None:
    """Attach :func:`ghtBezier`, :func:`ghtCurve` and :func:`developableLoft` to ``cadquery.Workplane`` (idempotent)."""
    cq.Workplane.ghtBezier = ghtBezier  # type: ignore[attr-defined]
    cq.Workplane.ghtCurve = ghtCurve  # type: ignore[attr-defined]
    cq.Workplane.developableLoft = developableLoft  # type: ignore[attr-defined]


register()
