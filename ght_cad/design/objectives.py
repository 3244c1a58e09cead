r"""Fairness measures of curves and composites (spec section 7), shared by the report and the optimizer.
"""

from __future__ import annotations

import functools
from typing import Any, Sequence

import numpy as np

from ..errors import GHTError
from .schema import PLANE_OBJECTIVES


@functools.lru_cache(maxsize=8)
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Cached Gauss–Legendre nodes/weights on [0, 1] (numpy's leggauss costs an eigensolve)."""
    from ..curve import gauss_legendre

    t, w = gauss_legendre(n)
    t.setflags(write=False)
    w.setflags(write=False)
    return t, w


def dual_curve_objectives(curve: Any, nodes: int = 64) -> dict[str, float]:
    r"""Fairness of a curve (spec section 7) by ``nodes``-point Gauss–Legendre quadrature.

    ``AL = ∫|X'|``, ``En = ∫|X''|²``, ``CVEn = ∫|X'''|²`` with analytic derivatives.
    """
    t, w = _gauss_legendre(nodes)
    d1 = curve.derivative(t, 1)
    d2 = curve.derivative(t, 2)
    d3 = curve.derivative(t, 3)
    return {
        "AL": float(np.sum(w * np.linalg.norm(d1, axis=1))),
        "En": float(np.sum(w * np.sum(d2 * d2, axis=1))),
        "CVEn": float(np.sum(w * np.sum(d3 * d3, axis=1))),
    }


def _fairness_value(vals: dict[str, float], objective: str, weights: Sequence[float]) -> float:
    """``AL``, ``En``, ``CVEn`` or ``weighted`` = ``w0 AL + w1 En + w2 CVEn`` from the three measures."""
    if objective == "weighted":
        return float(weights[0] * vals["AL"] + weights[1] * vals["En"] + weights[2] * vals["CVEn"])
    return float(vals[objective])


def composite_dual_objectives(composite: Any, objective: str = "CVEn", weights: Sequence[float] = (1.0, 0.0, 0.0),
                              nodes: int = 64) -> tuple[float, list[dict[str, float]]]:
    r"""Fairness of a composite developable: the sum over strips of its dual curve's measure.

    For strip ``s`` with dual curve ``U_s`` *as built* (strip 0 from its planes, strip i > 0 with
    its first ``r+1`` control planes re-solved by the join; no rescaling afterwards, the plane
    scale being a weight of the surface), ``AL_s = ∫_0^1 |U_s'|``, ``En_s = ∫_0^1 |U_s''|²``,
    ``CVEn_s = ∫_0^1 |U_s'''|²`` (:func:`dual_curve_objectives`: ``nodes``-point Gauss–Legendre,
    analytic derivatives) and ``F = Σ_s f(AL_s, En_s, CVEn_s)`` with ``f`` the chosen measure or
    ``w0 AL + w1 En + w2 CVEn``.

    Args:
        composite: a :class:`ght_cad.developable.CompositeDevelopable` of enveloping developables.
        objective: ``AL``, ``En``, ``CVEn`` or ``weighted``.
        weights: ``(w0, w1, w2)`` for ``weighted``.
        nodes: Gauss–Legendre nodes per strip.

    Returns:
        ``(F, per_strip)`` with ``per_strip[s] = {"AL", "En", "CVEn", "value"}``.

    Raises:
        GHTError: an objective that is not one of AL, En, CVEn, weighted.
    """
    if objective not in PLANE_OBJECTIVES:
        raise GHTError(f"objective={objective!r} is not allowed for a composite; allowed: {', '.join(PLANE_OBJECTIVES)}")
    per = []
    for seg in composite.segments:
        vals = dual_curve_objectives(seg.dual_curve, nodes)
        vals["value"] = _fairness_value(vals, objective, weights)
        per.append(vals)
    return float(sum(v["value"] for v in per)), per
