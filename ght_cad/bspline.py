r"""B-spline curves and surfaces as plain data (poles, knots, degrees): the core's CAD currency.

The CAD adapters (:mod:`ght_cad.cad.occ`, ``freecad_workbench``) turn these into kernel objects
(``Geom_BSplineCurve``/``Geom_BSplineSurface``, ``Part.BSplineCurve``/``Part.BSplineSurface``).

A curve is ``C(t) = Σ_i N_{i,p}(t) P_i`` on a clamped knot vector ``knots`` (full, with repeated
end knots, length ``len(poles) + degree + 1``), non-rational unless ``weights`` is given.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .errors import GHTError

__all__ = ["BSplineCurveData", "BSplineSurfaceData", "knots_and_multiplicities"]


def knots_and_multiplicities(knots: np.ndarray, tol: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Split a full knot vector into distinct knots and their multiplicities (OCCT/FreeCAD form)."""
    k = np.asarray(knots, dtype=float)
    uniq = [k[0]]
    mult = [1]
    for x in k[1:]:
        if abs(x - uniq[-1]) <= tol:
            mult[-1] += 1
        else:
            uniq.append(x)
            mult.append(1)
    return np.array(uniq), np.array(mult, dtype=int)


@dataclass
class BSplineCurveData:
    """A (non-rational unless ``weights``) B-spline curve as plain arrays.

    Attributes:
        poles: (n, dim) control points.
        knots: full clamped knot vector, length n + degree + 1.
        degree: polynomial degree p.
        weights: optional (n,) rational weights.
        max_deviation: certified deviation from the exact curve it approximates (if known).
    """

    poles: np.ndarray
    knots: np.ndarray
    degree: int
    weights: np.ndarray | None = None
    max_deviation: float | None = None
    info: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.poles = np.asarray(self.poles, dtype=float)
        self.knots = np.asarray(self.knots, dtype=float)
        if self.poles.ndim != 2:
            raise GHTError(f"poles must be a (n, dim) array; got shape {self.poles.shape}")
        if self.knots.size != self.poles.shape[0] + self.degree + 1:
            raise GHTError(
                f"knot vector has {self.knots.size} entries; {self.poles.shape[0]} poles of degree "
                f"{self.degree} need {self.poles.shape[0] + self.degree + 1}"
            )

    @property
    def dim(self) -> int:
        return self.poles.shape[1]

    def distinct_knots(self) -> tuple[np.ndarray, np.ndarray]:
        """(knots, multiplicities) as OCCT and FreeCAD want them."""
        return knots_and_multiplicities(self.knots)

    def _spline(self) -> Any:
        from scipy.interpolate import BSpline

        if self.weights is None:
            return BSpline(self.knots, self.poles, self.degree, extrapolate=False)
        w = np.asarray(self.weights, dtype=float)
        return BSpline(self.knots, np.column_stack([self.poles * w[:, None], w]), self.degree, extrapolate=False)

    def evaluate(self, t: Any, derivative: int = 0) -> np.ndarray:
        """Points (or derivatives, non-rational only) at ``t`` in the knot range."""
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=float)), self.knots[0], self.knots[-1])
        sp = self._spline()
        if self.weights is None:
            return sp(tt, derivative)
        if derivative:
            raise GHTError("derivatives of rational B-splines are not provided")
        h = sp(tt)
        return h[:, :-1] / h[:, -1:]


@dataclass
class BSplineSurfaceData:
    """A non-rational tensor-product B-spline surface as plain arrays.

    Attributes:
        poles: (nu, nv, 3) control net.
        knots_u, knots_v: full clamped knot vectors.
        degree_u, degree_v: degrees.
        max_deviation: certified deviation from the exact surface (if known).
    """

    poles: np.ndarray
    knots_u: np.ndarray
    knots_v: np.ndarray
    degree_u: int
    degree_v: int
    max_deviation: float | None = None
    info: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.poles = np.asarray(self.poles, dtype=float)
        self.knots_u = np.asarray(self.knots_u, dtype=float)
        self.knots_v = np.asarray(self.knots_v, dtype=float)
        nu, nv = self.poles.shape[:2]
        if self.knots_u.size != nu + self.degree_u + 1 or self.knots_v.size != nv + self.degree_v + 1:
            raise GHTError(
                f"knot vectors of lengths {self.knots_u.size}, {self.knots_v.size} do not fit a "
                f"{nu}x{nv} net of degrees {self.degree_u}, {self.degree_v}"
            )

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        """Points S(u, v) for broadcastable 1-D arrays u, v."""
        from scipy.interpolate import BSpline

        uu, vv = np.broadcast_arrays(np.atleast_1d(np.asarray(u, float)), np.atleast_1d(np.asarray(v, float)))
        nu, nv, d = self.poles.shape
        # first along u for every column of the net, then along v
        Bu = BSpline.design_matrix(np.clip(uu, self.knots_u[0], self.knots_u[-1]), self.knots_u, self.degree_u).toarray()
        Bv = BSpline.design_matrix(np.clip(vv, self.knots_v[0], self.knots_v[-1]), self.knots_v, self.degree_v).toarray()
        return np.einsum("ki,kj,ijd->kd", Bu, Bv, self.poles)
