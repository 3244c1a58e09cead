r"""cadquery Workplane plugin: GHT-Bézier curves as pending edges.

Importing this module registers two Workplane methods, following cadquery's plugin convention
(a function taking ``self``, attached to ``cq.Workplane``, that returns ``self.newObject(...)``):

- ``Workplane.ghtBezier(control_points, mu=0, nu=0, gamma=0, *, tol=None, degree=5,
  forConstruction=False, includeCurrent=False, makeWire=False)``
- ``Workplane.ghtCurve(curve_or_composite, *, tol=None, degree=5, forConstruction=False)``

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

The edges wrap the very OCP objects that build123d uses: ``cq.Edge(b3d_edge.wrapped)``.
"""

from __future__ import annotations

from typing import Any, Iterable

import cadquery as cq
import numpy as np

from ..curve import GHTCurve
from ..errors import GHTError
from .curves import ght_edge, segments_of

__all__ = ["ghtBezier", "ghtCurve", "register"]


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
    edge = cq.Edge(ght_edge(curve, tol, degree).wrapped)
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
        edges.append(cq.Edge(ght_edge(world, tol, degree).wrapped))
    return _add_edges(self, edges, forConstruction, makeWire)


def register() -> None:
    """Attach :func:`ghtBezier` and :func:`ghtCurve` to ``cadquery.Workplane`` (idempotent)."""
    cq.Workplane.ghtBezier = ghtBezier  # type: ignore[attr-defined]
    cq.Workplane.ghtCurve = ghtCurve  # type: ignore[attr-defined]


register()
