r"""Fairness measures of curves and composites (spec section 7), shared by the report and the optimizer.
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ...core._cache import readonly_cache
from ...core._quadrature import gauss_legendre_unit as _gauss_legendre  # noqa: F401  (the name design re-exports)
from ...core.errors import GHTError
from .schema import PLANE_OBJECTIVES




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
        composite: a :class:`ght_cad.developables.envelope.CompositeDevelopable` of enveloping developables.
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


@readonly_cache(maxsize=16)
def _population_basis(nodes: int, degree: int) -> Any:
    """Cached :class:`ght_cad.optimize.problems.PopulationBasis` on ``nodes`` Gauss–Legendre nodes."""
    from ...optimize.problems import PopulationBasis

    return PopulationBasis(_gauss_legendre(nodes)[0], degree)


@readonly_cache(maxsize=16)
def _end_basis(degree: int) -> Any:
    """Cached :class:`ght_cad.optimize.problems.PopulationBasis` at the two ends ``t = 0, 1``."""
    from ...optimize.problems import PopulationBasis

    return PopulationBasis(np.array([0.0, 1.0]), degree)


def _target_coefficients(continuity: Any, k: float, beta2: float, beta3: float) -> list[list[float]]:
    r"""``T_r = Σ_j c[r][j] U^(j)(1)`` of :func:`ght_cad.curves.continuity.join_targets`, r = 1..order
    (C: ``T_r = U^(r)(1)``; G1 ``k U'``, G2 ``k² U'' + β2 U'``, G3 ``k³ U''' + 3kβ2 U'' + β3 U'``)."""
    from ...curves.continuity import Continuity

    cont = Continuity.parse(continuity)
    r = cont.order
    if not cont.geometric:
        rows = [[0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    else:
        rows = [[0.0, k, 0.0, 0.0], [0.0, beta2, k * k, 0.0], [0.0, beta3, 3.0 * k * beta2, k**3]]
    return [[0.0] * 4] + rows[:r]


def composite_dual_objectives_grad(composite: Any, joins: Sequence[tuple[Any, float, float, float]],
                                   objective: str = "CVEn", weights: Sequence[float] = (1.0, 0.0, 0.0),
                                   nodes: int = 64) -> tuple[float, np.ndarray]:
    r"""``F`` of :func:`composite_dual_objectives` and its exact gradient ``∂F/∂(μ_s, ν_s, γ_s)``
    (spec 8.1), shape (strips, 3), through the joins re-solved for every parameter set.

    Strip ``s`` has dual curve ``U_s(t) = Σ_i b_{i,m}(t; θ_s) P_{s,i}``. Strip 0's control planes are
    fixed; strip ``s > 0`` joined with order ``r`` to strip ``s-1`` has (:func:`ght_cad.curves.continuity.join`)
    ``P_{s,0} = P_{s-1,m}`` and for ``q = 1..r``

    ``P_{s,q} = (T_q - Σ_{i<q} β^{(q)}_i P_{s,i}) / β^{(q)}_q``, ``β^{(q)}_i = b^{(q)}_{i}(0; θ_s)``,
    ``T_q = Σ_j c_{qj} U_{s-1}^{(j)}(1)``, ``U_{s-1}^{(j)}(1) = Σ_i b^{(j)}_i(1; θ_{s-1}) P_{s-1,i}``,

    so by forward differentiation along the chain (every parameter ``p`` of strips ``<= s``)

    ``∂U^{(j)}_{s-1}(1) = ∂_p b^{(j)}(1; θ_{s-1}) P_{s-1} + b^{(j)}(1; θ_{s-1}) ∂P_{s-1}``,
    ``∂P_{s,q} = (∂T_q - Σ_{i<q} (∂β^{(q)}_i P_{s,i} + β^{(q)}_i ∂P_{s,i}) - ∂β^{(q)}_q P_{s,q}) / β^{(q)}_q``

    (``∂β`` only for ``p ∈ θ_s``), the other rows fixed. The measures then follow as for one curve:
    ``∂AL = Σ_j w_j U'·∂U'/|U'|``, ``∂En = 2 Σ_j w_j U''·∂U''``, ``∂CVEn = 2 Σ_j w_j U'''·∂U'''`` with
    ``∂U^{(r)} = ∂b^{(r)} P + b^{(r)} ∂P`` (closed-form basis derivatives,
    :meth:`ght_cad.optimize.problems.PopulationBasis.parameter_derivatives`), and ``∂F`` sums them
    with the objective's weights.

    Args:
        composite: the composite as built (its strips' dual curves give the control planes ``P_s``).
        joins: per strip ``s >= 1`` its ``(continuity, k, beta2, beta3)`` with strip ``s - 1``.
        objective, weights, nodes: as :func:`composite_dual_objectives`.

    Returns:
        ``(F, dF)``, ``dF[s, j] = ∂F/∂θ_{s,j}``, ``θ = (μ, ν, γ)``.

    Raises:
        GHTError: an objective that is not one of AL, En, CVEn, weighted; a join count that does not
            match the strips.
    """
    if objective not in PLANE_OBJECTIVES:
        raise GHTError(f"objective={objective!r} is not allowed for a composite; allowed: {', '.join(PLANE_OBJECTIVES)}")
    segs = list(composite.segments)
    S = len(segs)
    if len(joins) != S - 1:
        raise GHTError(f"{len(joins)} joins given for {S} strips; give one (continuity, k, beta2, beta3) per strip after the first")
    if objective == "weighted":
        wm = np.asarray(weights, dtype=float)
    else:
        wm = np.array([1.0 if objective == k else 0.0 for k in ("AL", "En", "CVEn")])
    _, wq = _gauss_legendre(nodes)
    total = 0.0
    grad = np.zeros((S, 3))
    prev: tuple[np.ndarray, np.ndarray, dict, dict] | None = None  # P, dP, end rows, end row derivatives
    for s, seg in enumerate(segs):
        c = seg.dual_curve
        P = np.asarray(c.control_points, dtype=float)
        m = P.shape[0] - 1
        th = tuple(np.array([float(v)]) for v in (c.mu, c.nu, c.gamma))
        dP = np.zeros((S, 3) + P.shape)  # ∂P_s/∂θ_{p, j}
        if s > 0:
            assert prev is not None
            Pa, dPa, ea, dea = prev
            cont, k, b2, b3 = joins[s - 1]
            coef = _target_coefficients(cont, float(k), float(b2), float(b3))
            r = len(coef) - 1
            eb = _end_basis(m)(*th, range(r + 1))
            deb = _end_basis(m).parameter_derivatives(*th, range(r + 1))
            # ∂U_{s-1}^{(j)}(1) for all parameters, (S, 3, dim)
            dU = {j: np.einsum("i,pjid->pjd", ea[j][0, 1], dPa) for j in range(r + 1)}
            for j in range(r + 1):
                dU[j][s - 1] += np.einsum("qi,id->qd", dea[j][:, 0, 1], Pa)
            dP[:, :, 0] = dPa[:, :, -1]
            for q in range(1, r + 1):
                row = eb[q][0, 0]
                cq = row[q]
                dT = sum(coef[q][j] * dU[j] for j in range(1, r + 1) if coef[q][j] != 0.0)
                acc = dT - np.einsum("i,pjid->pjd", row[:q], dP[:, :, :q])
                drow = deb[q][:, 0, 0]  # (3, m+1): own parameters only
                acc[s] -= drow[:, :q] @ P[:q] + drow[:, q:q + 1] * P[q][None, :]
                dP[:, :, q] = acc / cq
        # measures and their derivatives on the Gauss–Legendre nodes
        Bm = _population_basis(nodes, m)(*th, (1, 2, 3))
        dBm = _population_basis(nodes, m).parameter_derivatives(*th, (1, 2, 3))
        vals = np.empty(3)
        dvals = np.zeros((S, 3, 3))
        for r_ in (1, 2, 3):
            D = Bm[r_][0] @ P  # (N, dim)
            dD = np.einsum("nk,pjkd->pjnd", Bm[r_][0], dP)
            dD[s] += np.einsum("jnk,kd->jnd", dBm[r_][:, 0], P)
            sq = np.sum(D * D, axis=-1)
            dot = np.einsum("nd,pjnd->pjn", D, dD)
            if r_ == 1:
                nrm = np.sqrt(sq)
                vals[0] = nrm @ wq
                with np.errstate(divide="ignore", invalid="ignore"):
                    dvals[:, :, 0] = np.where(nrm > 0, dot / nrm, 0.0) @ wq
            else:
                vals[r_ - 1] = sq @ wq
                dvals[:, :, r_ - 1] = 2.0 * (dot @ wq)
        total += float(vals @ wm)
        grad += dvals @ wm
        ends = _end_basis(m)(*th, range(4))
        dends = _end_basis(m).parameter_derivatives(*th, range(4))
        prev = (P, dP, ends, dends)
    return total, grad
