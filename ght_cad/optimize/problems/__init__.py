r"""Ready objectives over named shape parameters (spec sections 5, 7, 8).

Every problem is a callable ``problem(X) -> values`` on a population ``X`` of shape
(pop, dim) whose columns are the *free* shape parameters ``problem.names`` (e.g.
``("a.mu", "b.gamma")``); the other shape parameters keep their base values. Bounds default to
the admissible box ``[-1, 1]`` and can be narrowed. Evaluation is vectorized over the
population: the GHT seed jets ``f0^(r), f2^(r)`` are computed for all parameter sets at the
Gauss–Legendre nodes at once (:func:`population_basis`), and the basis matrices are contracted
with the control points in one ``einsum``.

Problems:

* :class:`StripProblem` (problem 1): the ruled strip ``X(u,v) = (1-v) A(u) + v B(u)`` between
  two 3-D GHT curves paired by their common parameter; objective the developability measure
  ``R = ∫ (1 - n_a·n_b) du`` (spec section 5), 64-node Gauss–Legendre.
* :class:`DualCurveFairnessProblem` (problem 2): fairness ``AL = ∫|U'|``, ``En = ∫|U''|²``,
  ``CVEn = ∫|U'''|²`` (spec section 7) of the dual curve of normalized control planes, singly
  or as a weighted sum; :meth:`~DualCurveFairnessProblem.build` gives the enveloping
  developable between two boundary planes.
* :class:`CurveFairnessProblem`: the same measures for a 3-D (any-dim) GHT curve with a fixed
  control polygon, and :class:`InterpolationFairnessProblem` for the curve of degree ``k-1``
  through ``k`` given points (control points re-solved for every parameter set).

Modules: :mod:`.base` (shape-parameter names, the population basis, :class:`Problem`),
:mod:`.strip` (problem 1), :mod:`.fairness` (problem 2), :mod:`.loft` (the developable loft's
rails, with exact gradients). Every name is importable from ``ght_cad.optimize.problems`` as before.
"""

from __future__ import annotations

from .base import (
    FAIRNESS_MEASURES,
    SHAPE_NAMES,
    CurveParameterJets,
    PopulationBasis,
    Problem,
    _columns,
    _split,
    ght_seed_jets,
    population_basis,
)
from .fairness import (
    CurveFairnessProblem,
    DualCurveFairnessProblem,
    EnvelopeStrip,
    FairnessProblem,
    InterpolationFairnessProblem,
    _weights,
    default_dual_problem,
    default_interpolation_problem,
)
from .loft import LOFT_OBJECTIVES, LoftGradientFallback, LoftProblem, loft_measures_and_gradients
from .strip import StripProblem, _StripKernel, cone_strip_problem, default_strip_problem, wave_strip_problem

__all__ = [
    "ght_seed_jets",
    "population_basis",
    "PopulationBasis",
    "Problem",
    "StripProblem",
    "FairnessProblem",
    "DualCurveFairnessProblem",
    "CurveFairnessProblem",
    "InterpolationFairnessProblem",
    "FAIRNESS_MEASURES",
    "EnvelopeStrip",
    "default_strip_problem",
    "default_dual_problem",
    "default_interpolation_problem",
    "wave_strip_problem",
    "cone_strip_problem",
    "LoftProblem",
    "LOFT_OBJECTIVES",
    "LoftGradientFallback",
    "loft_measures_and_gradients",
]
