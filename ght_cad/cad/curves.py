r"""build123d adapters: GHT-Bézier curves, composite curves and patches as Edges, Wires and Faces.

Every shape holds a *certified* B-spline (:func:`ght_cad.surfaces.bspline.curve_to_bspline`,
:meth:`ght_cad.surfaces.patch.GHTSurface.to_bspline`): maximum deviation from the exact GHT geometry at
matched parameters below ``tol`` (default ``1e-7 ×`` bounding-box diagonal), parametrization kept
(the edge's parameter is the curve's t ∈ [0, 1]) and end derivatives up to order
``min(3, degree-1)`` exact, so G2/G3 joints stay G2/G3 in the B-rep. The conversion record is
attached as ``shape.ght_bspline``; it follows the shape when the shape is moved, rotated, mirrored
or scaled, and is dropped when the shape's geometry changes otherwise (:mod:`ght_cad.cad.certified`).

Algebra mode: :func:`ght_edge`, :func:`ght_wire`, :func:`ght_face` return plain build123d shapes.
Builder mode: :class:`GHTBezierLine` (an Edge) and :class:`GHTCompositeLine` (a Wire) add
themselves to the active ``BuildLine`` like build123d's own ``Bezier``/``Spline``, so they work
inside ``BuildSketch``/``BuildPart`` too. cadquery shapes share the same OCP objects:
``cadquery.Edge(edge.wrapped)`` / ``build123d.Edge(cq_edge.wrapped)`` wrap, never copy.

Keeping edges exact in builders: build123d's builders and boolean operations "clean" their
results with ``ShapeUpgrade_UnifySameDomain(shape, True, True, True)``, whose last flag
(ConcatBSplines) merges tangent-continuous B-spline edges into one *re-approximated* edge: a
smooth GHT chain then loses its certified deviation (we measured 1.5e-4 on a chain of radius 3).
Run builder code inside :func:`exact_edges` (``with exact_edges(): with BuildPart(): ...``),
which keeps build123d's clean-up (history, warnings, ``SkipClean``) but without B-spline
concatenation. Algebra-mode ``extrude``/``revolve``
on :func:`ght_wire` faces do not concatenate. In cadquery pass ``clean=False`` to
``extrude``/``revolve``/booleans for the same reason.
"""

from __future__ import annotations

import contextlib
from typing import Any, Iterator, Sequence

import numpy as np
from build123d import Edge, Face, Mode, Vector, Wire
from build123d.objects_curve import BaseEdgeObject, BaseLineObject
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeVertex, BRepBuilderAPI_MakeWire
from OCP.gp import gp_Pnt

from ..surfaces.bspline import BSplineCurveData, curve_to_bspline
from ..curves.curve import GHTCurve
from ..core.errors import GHTError
from ..surfaces.patch import GHTSurface
from ._chain import _as_curve, segments_of
from .certified import certified, certify
from .occ import geom_bspline_curve, make_face

__all__ = [
    "ght_edge",
    "ght_wire",
    "ght_face",
    "segments_of",
    "GHTBezierLine",
    "GHTCompositeLine",
    "exact_edges",
    "ght_shape",
    "export_step",
]


def _unify_keeping_bsplines(shape: Any, unify_edges: bool = True, unify_faces: bool = True,
                            concat_bsplines: bool = True) -> Any:
    """``ShapeUpgrade_UnifySameDomain`` as build123d constructs it, with ``ConcatBSplines`` off."""
    from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain

    return ShapeUpgrade_UnifySameDomain(shape, unify_edges, unify_faces, False)


def _unify_bindings() -> list[Any]:
    """The loaded build123d modules whose global ``ShapeUpgrade_UnifySameDomain`` is OCCT's (or
    already ours, in a nested block): ``Shape.clean`` and the boolean operations construct it."""
    import sys

    from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain

    return [m for name, m in list(sys.modules.items())
            if m is not None and (name == "build123d" or name.startswith("build123d."))
            and getattr(m, "ShapeUpgrade_UnifySameDomain", None) in (ShapeUpgrade_UnifySameDomain, _unify_keeping_bsplines)]


@contextlib.contextmanager
def exact_edges() -> Iterator[None]:
    """Inside the block, build123d's clean-ups keep tangent B-spline edges as they are.

    build123d cleans builder results (``Shape.clean``) and boolean results (``Shape._bool_op``)
    with ``ShapeUpgrade_UnifySameDomain(shape, True, True, True)``, whose last flag (ConcatBSplines)
    merges G1-connected B-spline edges into one re-approximated edge (1.5e-4 off a GHT chain of
    radius 3). In the block build123d's own ``clean`` and booleans run unchanged -- shape history
    merged, "Unable to clean" warnings, ``SkipClean`` (also nested in the block) -- except that the
    ``ShapeUpgrade_UnifySameDomain`` they construct is built with ``ConcatBSplines=False``
    (:func:`_unify_keeping_bsplines`, bound as the modules' global name for the block). The
    previous bindings are restored on exit (also on error); blocks nest. Not thread-safe.

    Example:
        >>> with exact_edges():                        # doctest: +SKIP
        ...     with BuildPart() as part:
        ...         with BuildSketch():
        ...             with BuildLine():
        ...                 GHTCompositeLine(composite)
        ...             make_face()
        ...         extrude(amount=2)
    """
    import build123d  # noqa: F401  (all of build123d's modules bound before they are rebound)

    saved = [(m, m.ShapeUpgrade_UnifySameDomain) for m in _unify_bindings()]
    if not saved:  # pragma: no cover - a build123d that no longer constructs it by that name
        raise GHTError("exact_edges: no build123d module constructs ShapeUpgrade_UnifySameDomain by name; "
                       "this build123d version is not supported by exact_edges")
    for m, _ in saved:
        m.ShapeUpgrade_UnifySameDomain = _unify_keeping_bsplines
    try:
        yield
    finally:
        for m, previous in saved:
            m.ShapeUpgrade_UnifySameDomain = previous


def _xyz(p: np.ndarray) -> np.ndarray:
    q = np.zeros(3)
    q[: p.size] = p
    return q


def ght_edge(curve: GHTCurve, tol: float | None = None, degree: int = 5) -> Edge:
    r"""build123d ``Edge`` on the certified B-spline of a GHT curve (2-D curves lie in z = 0).

    ``|P(t) - C(t)| <= tol`` for all t (default tol = 1e-7 × bounding-box diagonal), the edge's
    parameter equals t, ``C^(r) = P^(r)`` at both ends for r <= min(3, degree-1).

    Args:
        curve: the GHT-Bézier curve (dimension 2 or 3).
        tol: maximum deviation.
        degree: B-spline degree.

    Returns:
        ``Edge`` with the conversion record in ``edge.ght_bspline`` (a BSplineCurveData).

    Raises:
        GHTError: not a 2-D/3-D GHTCurve, bad tol; ConversionError: unreachable tol.
    """
    data = curve_to_bspline(_as_curve(curve), tol, degree)
    return certify(Edge(BRepBuilderAPI_MakeEdge(geom_bspline_curve(data)).Edge()), ght_bspline=data)


def _wire_edges(curves: Any, tol: float | None, degree: int, closed: bool | None) -> tuple[Any, list[BSplineCurveData]]:
    segs, flag = segments_of(curves)
    if closed is None and flag:
        closed = True  # a closed composite; an open one may still close geometrically
    starts = np.array([_xyz(s.evaluate(0.0)) for s in segs])
    ends = np.array([_xyz(s.evaluate(1.0)) for s in segs])
    allpts = np.vstack([np.vstack([s.control_points for s in segs]).min(axis=0), np.vstack([s.control_points for s in segs]).max(axis=0)])
    diag = float(np.linalg.norm(allpts[1] - allpts[0])) or 1.0
    gap_tol = 1e-9 * diag
    for i in range(len(segs) - 1):
        gap = float(np.linalg.norm(ends[i] - starts[i + 1]))
        if gap > gap_tol:
            raise GHTError(
                f"segment {i} ends at {ends[i].tolist()} but segment {i+1} starts at "
                f"{starts[i+1].tolist()} (gap {gap:.3g} > {gap_tol:.3g}): join them with C0 or better"
            )
    closing_gap = float(np.linalg.norm(ends[-1] - starts[0]))
    if closed is None:
        closed = len(segs) > 1 and closing_gap <= gap_tol
    if closed and closing_gap > gap_tol:
        raise GHTError(f"the chain is not closed: last end and first start differ by {closing_gap:.3g}")
    # shared vertices: joint i sits between segment i-1 and segment i
    nodes = [starts[0]] + [0.5 * (ends[i] + starts[i + 1]) for i in range(len(segs) - 1)]
    nodes.append(starts[0] if closed else ends[-1])
    verts = [BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex() for p in nodes[:-1]]
    verts.append(verts[0] if closed else BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, nodes[-1]))).Vertex())
    mk = BRepBuilderAPI_MakeWire()
    datas = []
    for i, seg in enumerate(segs):
        data = curve_to_bspline(seg, tol, degree)
        datas.append(data)
        me = BRepBuilderAPI_MakeEdge(geom_bspline_curve(data), verts[i], verts[i + 1])
        if not me.IsDone():
            raise GHTError(f"OCCT could not build the edge of segment {i} (error {me.Error()})")
        mk.Add(me.Edge())
        if not mk.IsDone():
            raise GHTError(f"OCCT could not add segment {i} to the wire (error {mk.Error()})")
    return mk.Wire(), datas


def ght_wire(
    curves: Any, tol: float | None = None, degree: int = 5, *, closed: bool | None = None
) -> Wire:
    r"""build123d ``Wire`` from a chain of GHT segments (a CompositeCurve or a list of GHTCurves).

    One certified B-spline edge per segment (see :func:`ght_edge`); consecutive edges share one
    vertex, the joint ``P_A(1) = P_B(0)`` (checked to 1e-9 × the chain's size). Because every
    edge keeps its curve's end derivatives up to order ``min(3, degree-1)``, the continuity of
    each joint (C1..C3/G1..G3) carries over to the B-rep.

    Args:
        curves: ``CompositeCurve`` (uses ``.segments`` and ``.closed``), GHTCurve or sequence.
        tol: maximum deviation per segment (default 1e-7 × each segment's box diagonal).
        degree: B-spline degree.
        closed: True requires a closed chain (error otherwise); default: closed for a closed
            composite, else closed when the last end meets the first start (to 1e-9 × the
            chain's size).

    Returns:
        ``Wire`` with ``wire.ght_bspline`` = list of BSplineCurveData.

    Raises:
        GHTError: gaps between segments, a requested closure that does not close, bad input.
    """
    w, datas = _wire_edges(curves, tol, degree, closed)
    return certify(Wire(w), ght_bspline=datas)


def ght_face(patch: GHTSurface, tol: float | None = None, degree: int = 5) -> Face:
    r"""build123d ``Face`` on the certified B-spline surface of a GHT patch.

    ``|S(u,v) - S~(u,v)| <= tol`` (default 1e-7 × bounding-box diagonal; see
    :meth:`ght_cad.surfaces.patch.GHTSurface.to_bspline` for the bound).

    Returns:
        ``Face`` with ``face.ght_bspline`` = the BSplineSurfaceData.
    """
    if not isinstance(patch, GHTSurface):
        raise GHTError(f"expected a GHTSurface, got {type(patch).__name__}")
    if patch.dim != 3:
        raise GHTError(f"a CAD face needs a 3-D patch; this patch has dim={patch.dim}")
    data = patch.to_bspline(tol, degree)
    return certify(make_face(data), ght_bspline=data)


def ght_shape(obj: Any, tol: float | None = None, degree: int = 5) -> Any:
    """The CAD shape of a ght_cad object: GHTCurve → Edge, CompositeCurve or list of curves →
    Wire, GHTSurface → Face; build123d/cadquery/OCP shapes are returned unchanged.

    Raises:
        GHTError: an object of another type.
    """
    if isinstance(obj, GHTCurve):
        return ght_edge(obj, tol, degree)
    if isinstance(obj, GHTSurface):
        return ght_face(obj, tol, degree)
    if hasattr(obj, "wrapped") or type(obj).__module__.startswith("OCP"):
        return obj
    if hasattr(obj, "segments") or isinstance(obj, (list, tuple)):
        return ght_wire(obj, tol, degree)
    raise GHTError(
        f"cannot make a CAD shape from a {type(obj).__name__}; expected GHTCurve, CompositeCurve, "
        "a list of GHTCurves, GHTSurface or a build123d/cadquery/OCP shape"
    )


def export_step(objects: Any, path: Any, tol: float | None = None, degree: int = 5) -> str:
    """Write GHT curves, composite curves, patches and/or CAD shapes to one STEP file, atomically.

    Each object goes through :func:`ght_shape` (certified B-splines), then
    :func:`ght_cad.cad.occ.write_step` (validity check, quiet OCCT, atomic write).

    Args:
        objects: one object or a list of them (a list of GHTCurves counts as several edges; wrap
            it in a CompositeCurve or a tuple inside the list to get one wire).
        path: target file.
        tol, degree: conversion tolerance and B-spline degree.

    Returns:
        The path written.
    """
    from .occ import write_step

    items = list(objects) if isinstance(objects, list) else [objects]
    return write_step([ght_shape(o, tol, degree) for o in items], path)


def _point(p: Any) -> tuple[float, float, float]:
    """One point as three floats: a build123d ``Vector`` or 2/3 numbers of any kind (Python or
    numpy scalars of any dtype; build123d's ``Vector`` reads numpy integers as nothing)."""
    if isinstance(p, Vector):
        return (p.X, p.Y, p.Z)
    try:
        arr = np.asarray(p, dtype=float)
    except (TypeError, ValueError):
        raise GHTError(f"control point {p!r} is not a point; use 2 or 3 numbers or a Vector") from None
    if arr.ndim != 1 or arr.size not in (2, 3):
        raise GHTError(f"control point {p!r} has shape {arr.shape}; a point has 2 or 3 coordinates")
    return (float(arr[0]), float(arr[1]), float(arr[2]) if arr.size == 3 else 0.0)


def _is_point_list(p: Any) -> bool:
    if isinstance(p, np.ndarray):
        return p.ndim == 2
    return isinstance(p, (list, tuple)) and bool(p) and isinstance(p[0], (list, tuple, Vector, np.ndarray))


def _points(pts: Sequence[Any]) -> np.ndarray:
    """Control points given as separate arguments and/or sequences of points, as an (n, 3) array."""
    flat: list[Any] = []
    for p in pts:
        if _is_point_list(p):
            flat.extend(list(p))
        else:
            flat.append(p)
    return np.array([_point(p) for p in flat], dtype=float)


@certified
class GHTBezierLine(BaseEdgeObject):
    r"""Line object: a GHT-Bézier curve ``P(t) = Σ b_{i,m}(t; μ,ν,γ) P_i`` as one certified edge.

    Use inside ``BuildLine`` (and hence ``BuildSketch``/``BuildPart``) like build123d's
    ``Bezier``; outside a builder it is simply an ``Edge``. Wrap the builders in
    :func:`exact_edges` so that build123d's clean-up does not re-approximate tangent-continuous
    edges (see the module docstring).

    Args:
        *control_points: three or more points (VectorLike, or one sequence of them), or a single
            :class:`~ght_cad.curves.curve.GHTCurve` (then mu, nu, gamma are ignored).
        mu, nu, gamma: shape parameters in [-1, 1].
        tol: maximum deviation of the B-spline (default 1e-7 × bounding-box diagonal).
        degree: B-spline degree.
        mode: combination mode.

    Attributes:
        ght_curve: the exact GHTCurve; ght_bspline: its BSplineCurveData.
    """

    _applies_to = BaseEdgeObject._applies_to

    def __init__(
        self,
        *control_points: Any,
        mu: float = 0.0,
        nu: float = 0.0,
        gamma: float = 0.0,
        tol: float | None = None,
        degree: int = 5,
        mode: Mode = Mode.ADD,
    ) -> None:
        if len(control_points) == 1 and isinstance(control_points[0], GHTCurve):
            curve = control_points[0]
        else:
            curve = GHTCurve(_points(control_points), mu, nu, gamma)
        edge = ght_edge(curve, tol, degree)
        super().__init__(edge, mode=mode)
        self.ght_curve = curve
        self.ght_bspline = edge.ght_bspline


@certified
class GHTCompositeLine(BaseLineObject):
    r"""Line object: a chain of GHT segments (CompositeCurve or list of GHTCurves) as one Wire.

    Use inside ``BuildLine``; ``BuildSketch``'s ``make_face()`` turns a closed chain into a face.
    See :func:`ght_wire` for the arguments, and wrap the builders in :func:`exact_edges` (build123d
    would otherwise merge the smooth chain into one re-approximated edge).
    """

    _applies_to = BaseLineObject._applies_to

    def __init__(
        self,
        curves: Any,
        tol: float | None = None,
        degree: int = 5,
        *,
        closed: bool | None = None,
        mode: Mode = Mode.ADD,
    ) -> None:
        wire = ght_wire(curves, tol, degree, closed=closed)
        super().__init__(wire, mode=mode)
        self.ght_bspline = wire.ght_bspline

