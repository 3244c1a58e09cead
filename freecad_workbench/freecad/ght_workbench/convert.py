"""Plain B-spline data from the ght_cad core -> FreeCAD ``Part`` geometry (and back to arrays).

The core hands over poles/knots/degrees (:class:`ght_cad.surfaces.bspline.BSplineCurveData`,
:class:`ght_cad.surfaces.bspline.BSplineSurfaceData`); here they become ``Part.BSplineCurve`` /
``Part.BSplineSurface`` through ``buildFromPolesMultsKnots`` (distinct knots + multiplicities,
OCCT's form). No build123d/OCP: this runs in FreeCAD's own Python.
"""

from __future__ import annotations

from typing import Any, Callable, Iterable, Sequence

import numpy as np

import FreeCAD as App
import Part

from . import _ensure_core  # noqa: F401  (makes ght_cad importable)
from ght_cad.surfaces.bspline import BSplineCurveData, BSplineSurfaceData, knots_and_multiplicities
from ght_cad.core.errors import GHTError

__all__ = [
    "vec",
    "points_array",
    "fit_curve_function",
    "curve_data",
    "part_curve",
    "part_surface",
    "edge_from_data",
    "face_from_data",
    "ruled_surface_data",
    "ruled_face",
]

# Default fitting tolerance (model units) when a feature does not set one.
DEFAULT_TOL = 1e-6


def vec(p: Sequence[float]) -> "App.Vector":
    """``App.Vector`` from a 2-D or 3-D point (2-D gets z = 0)."""
    q = [float(x) for x in p][:3]
    q += [0.0] * (3 - len(q))
    return App.Vector(*q)


def points_array(points: Iterable[Any]) -> np.ndarray:
    """(n, 3) float array from FreeCAD vectors (or any 3-sequences)."""
    return np.array([[float(p[0]), float(p[1]), float(p[2])] for p in points], dtype=float).reshape(-1, 3)


def fit_curve_function(f: Callable[[np.ndarray], np.ndarray], tol: float = DEFAULT_TOL) -> BSplineCurveData:
    """B-spline data of a vector function ``f(t)`` on [0, 1] (shape (len(t), d)), deviation <= tol.

    ``ght_cad.surfaces.bspline.fit_function``: one common knot vector for every coordinate, so a 6-D stack
    of two boundary curves keeps its pairing; the deviation is measured at matched parameters.
    """
    from ght_cad.surfaces.bspline import fit_function

    return fit_function(f, tol=tol)


def curve_data(curve: Any, tol: float = DEFAULT_TOL) -> BSplineCurveData:
    """B-spline data of a :class:`ght_cad.GHTCurve` via ``ght_cad.surfaces.bspline.curve_to_bspline``
    (same parametrization, end derivatives up to order 3 exact, deviation <= tol)."""
    from ght_cad.surfaces.bspline import curve_to_bspline

    return curve_to_bspline(curve, tol=tol)


def part_curve(data: BSplineCurveData) -> "Part.BSplineCurve":
    """``Part.BSplineCurve`` with exactly the poles, knots and degree of ``data``."""
    if data.dim not in (2, 3):
        raise GHTError(f"a CAD edge needs 2-D or 3-D poles; got dimension {data.dim}")
    knots, mults = data.distinct_knots()
    c = Part.BSplineCurve()
    poles = [vec(p) for p in data.poles]
    if data.weights is None:
        c.buildFromPolesMultsKnots(poles, [int(m) for m in mults], [float(k) for k in knots], False, int(data.degree))
    else:
        c.buildFromPolesMultsKnots(
            poles,
            [int(m) for m in mults],
            [float(k) for k in knots],
            False,
            int(data.degree),
            [float(w) for w in data.weights],
        )
    return c


def part_surface(data: BSplineSurfaceData) -> "Part.BSplineSurface":
    """``Part.BSplineSurface`` with exactly the net, knots and degrees of ``data``."""
    ku, mu = knots_and_multiplicities(data.knots_u)
    kv, mv = knots_and_multiplicities(data.knots_v)
    s = Part.BSplineSurface()
    poles = [[vec(p) for p in row] for row in data.poles]
    s.buildFromPolesMultsKnots(
        poles,
        [int(m) for m in mu],
        [int(m) for m in mv],
        [float(k) for k in ku],
        [float(k) for k in kv],
        False,
        False,
        int(data.degree_u),
        int(data.degree_v),
    )
    return s


def edge_from_data(data: BSplineCurveData) -> "Part.Edge":
    """An edge on :func:`part_curve`."""
    return part_curve(data).toShape()


def face_from_data(data: BSplineSurfaceData) -> "Part.Face":
    """A face on :func:`part_surface` with its natural bounds."""
    return Part.Face(part_surface(data))


def ruled_surface_data(surface: Any, tol: float | None = None, degree: int = 5, end_order: int = 2) -> BSplineSurfaceData:
    r"""B-spline surface data of a ruled strip ``X(u, v) = (1-v) a(u) + v b(u)`` (any ght_cad RuledSurface).

    The 6-D function ``f(u) = (a(u), b(u))`` is fitted once by ``ght_cad.surfaces.bspline.fit_function``
    (deviation <= tol at matched parameters, exact end derivatives up to ``end_order``), so both
    boundary curves share one knot vector and pole ``i`` of ``a`` and of ``b`` belong to the same
    ruling neighbourhood; the net is ``P[i, 0] = A_i``, ``P[i, 1] = B_i``, degree 1 in v. This keeps
    the a(u)–b(u) pairing that developability depends on (same data as
    ``ght_cad.cad.developable_faces.developable_surface_data``, which needs OCP).
    """
    if tol is None:
        g = surface.grid(33, 3).reshape(-1, 3)
        tol = 1e-7 * max(float(np.linalg.norm(g.max(axis=0) - g.min(axis=0))), 1e-300)

    def f(u: np.ndarray) -> np.ndarray:
        return np.hstack([surface.a(u), surface.b(u)])

    from ght_cad.surfaces.bspline import fit_function

    order = min(end_order, degree - 1)
    ends = tuple([np.concatenate([surface.a(e, r)[0], surface.b(e, r)[0]]) for r in range(order + 1)] for e in (0.0, 1.0))
    curve = fit_function(f, tol=float(tol), degree=degree, end_derivatives=ends)
    poles = np.stack([curve.poles[:, :3], curve.poles[:, 3:]], axis=1)
    return BSplineSurfaceData(
        poles, curve.knots, np.array([0.0, 0.0, 1.0, 1.0]), curve.degree, 1, max_deviation=curve.max_deviation, info=dict(curve.info)
    )


def ruled_face(surface: Any, tol: float | None = None) -> tuple["Part.Face", BSplineSurfaceData]:
    """(``Part.Face`` on :func:`ruled_surface_data`, the data)."""
    data = ruled_surface_data(surface, tol)
    return face_from_data(data), data
