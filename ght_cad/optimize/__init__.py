"""Shape-parameter optimization (spec sections 5, 7, 8).

* :mod:`.optimizers`: PSO, GWO, I-GWO (numpy, vectorized over the population) and a scipy
  ``differential_evolution`` baseline, one interface, one :class:`OptimizeResult`.
* :mod:`.problems`: ready objectives over named shape parameters (``"a.mu"``, ``"b.gamma"``, ...):
  quasi-developable strips (R), fairness (AL, En, CVEn) of dual curves and interpolation curves.
* :mod:`.pareto`: non-dominated archive and Pareto front of (AL, En, CVEn).
* :mod:`.pipeline`: problem -> optimized object -> B-rep face, STEP, flat pattern, plot.
* :mod:`.compare`: statistics over seeds and the comparison table; :mod:`.plots`: PNG figures.

Everything here imports numpy/scipy only; CAD kernels and matplotlib load inside functions.

Example:
    >>> from ght_cad.optimize import igwo, optimize_design
    >>> from ght_cad.optimize.problems import default_strip_problem
    >>> p = default_strip_problem()
    >>> r = igwo(p, p.bounds, pop_size=20, max_iter=60, seed=0, x0=p.x0)   # doctest: +SKIP
    >>> p.report(p.x0)["theta_max"], p.report(r.x)["theta_max"]          # doctest: +SKIP
    (11.27, 0.22)
"""

from __future__ import annotations

from .optimizers import (
    hybrid,
    METHODS,
    OptimizerState,
    OptimizeResult,
    as_bounds,
    differential_evolution,
    gwo,
    igwo,
    minimize,
    pso,
    vectorize,
)
from .pareto import ParetoArchive, ParetoResult, pareto_front
from .pipeline import DesignResult, optimize_design
from .problems import (
    CurveFairnessProblem,
    DualCurveFairnessProblem,
    InterpolationFairnessProblem,
    StripProblem,
)

__all__ = [
    "METHODS",
    "OptimizerState",
    "OptimizeResult",
    "as_bounds",
    "differential_evolution",
    "hybrid",
    "gwo",
    "igwo",
    "minimize",
    "pso",
    "vectorize",
    "ParetoArchive",
    "ParetoResult",
    "pareto_front",
    "DesignResult",
    "optimize_design",
    "StripProblem",
    "DualCurveFairnessProblem",
    "CurveFairnessProblem",
    "InterpolationFairnessProblem",
]
