"""A CAD face as the kernel-free unroller sees it: the surface adapter, its jets, edges and faces.

Moved from :mod:`ght_cad.unrolling.face_unroll` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ...core._vec import stack as _stack
from ...core.errors import GHTError


Bounds = tuple[float, float, float, float]
#: surface kinds with a structural ruling direction "v" (their v-isolines are straight lines)
RULED_KINDS = ("plane", "cylinder", "cone", "extrusion")
#: surface kinds whose area density ``|S_u × S_v|`` does not depend on u (a plane: constant; a
#: cylinder or cone: u is the angle about the axis), so :func:`face_area` needs no inner integral
U_FREE_DENSITY_KINDS = ("plane", "cylinder", "cone")


class SurfaceAdapter:
    """The surface of a face as the core sees it (the adapter protocol; subclass and override).

    Attributes:
        kind: "plane", "cylinder", "cone", "extrusion", "bspline", "bezier" or "other".
        radius: cylinder radius / cone reference radius R (analytic kinds only).
        semi_angle: cone semi-angle α in radians (cone only).
        ruled_hint: "v" or "u" when the surface is structurally ruled in that direction (a B-spline
            or Bézier of degree 1 with 2 poles across), else None.
        affine_ruled: the surface is affine along its rulings, ``S(u, v) = S(u, v0) + (v - v0) /
            (v1 - v0) (S(u, v1) - S(u, v0))`` (rulings along v; u likewise): an extrusion, a
            degree-1 B-spline/Bézier with equal weights across. Then a point's ruling parameter is
            its own (v - v0) / (v1 - v0) and the map needs no projection onto the ruling.
        fast_density_grid: :meth:`density_grid` (when the adapter has one) costs far less a point
            on a tensor grid than the partials at scattered points (a B-spline read into the core):
            :func:`face_area` then integrates whole knot pieces on grids.
    """

    kind: str = "other"
    fast_density_grid: bool = False
    radius: float = 0.0
    semi_angle: float = 0.0
    ruled_hint: str | None = None
    affine_ruled: bool = False

    def value(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Points ``S(u, v)``, shape (n, 3)."""
        raise NotImplementedError

    def d1(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """``[S_u, S_v]`` at the points, each (n, 3)."""
        d = self.d2(u, v)
        return [d[1], d[2]]

    def d2(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        """``[S, S_u, S_v, S_uu, S_vv, S_uv]`` at the points, each (n, 3)."""
        raise NotImplementedError

    def breaks(self, direction: str) -> np.ndarray:
        """Parameters in ``direction`` ("u" or "v") where the surface is not C∞ (B-spline knots);
        may include the ends; empty for analytic surfaces."""
        return np.zeros(0)

    def c0_breaks(self, direction: str) -> np.ndarray:
        """Parameters in ``direction`` where the surface is only C0 (B-spline knots of full
        multiplicity, e.g. a loft's joint rulings): the boundary measures are split there
        (:attr:`ght_cad.pattern.flat_pattern.BoundaryEdge.breaks`); empty when unknown."""
        return np.zeros(0)

    def jet(self, u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        """``[S]`` (order 0), ``[S, S_u, S_v]`` (1) or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` (2) at the
        points in one evaluation (override when that is cheaper than :meth:`value` + :meth:`d1`)."""
        return surface_jet(self, u, v, order, own=False)


def jets_agree(ours: Sequence[np.ndarray], theirs: Sequence[np.ndarray], floor: float = 1.0,
               rtol: float = 1e-12) -> bool:
    """A kernel's surface read into numpy checked against the kernel's own evaluation: every
    quantity ``k`` (point, partials) agrees to ``rtol`` of its own size,
    ``max |ours_k - theirs_k| <= rtol max(floor, max |theirs_k|)`` (NaN disagrees); all quantities
    equal-shaped, compared in one pass."""
    a, b = _stack(list(ours)), _stack(list(theirs))
    q = a.shape[0]
    err = np.abs(a - b).reshape(q, -1).max(axis=1)
    scale = np.maximum(np.abs(b).reshape(q, -1).max(axis=1), floor)
    return bool((err <= rtol * scale).all())


def analytic_jet(kind: str, frame: Sequence[np.ndarray], radius: float, semi_angle: float, u: Any, v: Any,
                 order: int) -> list[np.ndarray]:
    r"""``[S, S_u, S_v]`` (order <= 1) or ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` of a plane, cylinder or
    cone from its placement ``frame = (O, X, Y, Z)`` (origin and orthonormal axes, as OCCT's
    ``gp_Ax3``), by OCCT's own parametrizations (``ElSLib``), shared by the CAD adapters:

    * plane ``S = O + u X + v Y``;
    * cylinder of radius R: ``S = O + R (cos u X + sin u Y) + v Z``;
    * cone of reference radius R and semi-angle α: ``S = O + (R + v sin α)(cos u X + sin u Y) + v cos α Z``.

    Raises:
        GHTError: another ``kind``.
    """
    O, X, Y, Z = frame
    u = np.asarray(u, dtype=float).reshape(-1, 1)
    v = np.asarray(v, dtype=float).reshape(-1, 1)
    if kind == "plane":
        zero = np.zeros((u.shape[0], 3))
        out = [O + u * X + v * Y, np.broadcast_to(X, zero.shape).copy(), np.broadcast_to(Y, zero.shape).copy()]
        return out + [zero, zero.copy(), zero.copy()] if order >= 2 else out
    if kind not in ("cylinder", "cone"):
        raise GHTError(f"kind={kind!r} has no closed-form evaluation; allowed 'plane', 'cylinder', 'cone'")
    c, s = np.cos(u), np.sin(u)
    radial = c * X + s * Y
    tangent = -s * X + c * Y
    if kind == "cylinder":
        R = radius
        out = [O + R * radial + v * Z, R * tangent, np.broadcast_to(Z, radial.shape).copy()]
        if order >= 2:
            out += [-R * radial, np.zeros_like(radial), np.zeros_like(radial)]
        return out
    sa, ca = math.sin(semi_angle), math.cos(semi_angle)
    r = radius + v * sa
    out = [O + r * radial + (v * ca) * Z, r * tangent, sa * radial + ca * Z]
    if order >= 2:
        out += [-r * radial, np.zeros_like(radial), sa * tangent]
    return out


def surface_jet(ev: Any, u: np.ndarray, v: np.ndarray, order: int, own: bool = True) -> list[np.ndarray]:
    """``ev.jet(u, v, order)`` when the adapter has one (``own``), else from ``value``/``d1``/``d2``
    (adapters that are not :class:`SurfaceAdapter` subclasses, e.g. a sheet's offset surface)."""
    if own and hasattr(ev, "jet"):
        return ev.jet(u, v, order)
    if order <= 0:
        return [ev.value(u, v)]
    if order == 1:
        return [ev.value(u, v), *ev.d1(u, v)]
    return ev.d2(u, v)


@dataclass
class EdgeData:
    """One boundary edge of a face in wire order, t ∈ [0, 1].

    Attributes:
        uv: t -> (u, v) arrays (the pcurve).
        duv: t -> (n, 2) derivatives ``(du/dt, dv/dt)``.
        xyz: t -> (n, 3) points of the edge's 3-D curve.
        length_3d: 3-D length (0 for a degenerate edge, e.g. a cone apex).
        breaks: interior t where the pcurve is not C∞ (its knots), sorted.
        name: edge name.
    """

    uv: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    duv: Callable[[np.ndarray], np.ndarray]
    xyz: Callable[[np.ndarray], np.ndarray]
    length_3d: float
    breaks: np.ndarray = field(default_factory=lambda: np.zeros(0))
    name: str = ""


@dataclass
class FaceData:
    """A face for :func:`unroll_face_data`: surface, parameter bounds (u0, u1, v0, v1), wires
    (outer first, then holes; each a list of :class:`EdgeData` in traversal order). A wrong
    outer wire is tolerated: :func:`unroll_face_data` puts the loop enclosing the largest (u, v)
    area first (:func:`outer_loop_index`)."""

    surface: SurfaceAdapter
    bounds: Bounds
    wires: list[list[EdgeData]]
    #: the face's orientation is reversed: its normal is ``-(S_u × S_v)`` (sheet side, ght_cad.sheetmetal.sheet)
    reversed: bool = False
