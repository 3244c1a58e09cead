"""Shape-parameter optimization (spec sections 5, 7, 8).

* :mod:`.optimizers`: PSO, GWO, I-GWO (numpy, vectorized over the population) and a scipy
  ``differential_evolution`` baseline, one interface, one :class:`OptimizeResult`.
* :mod:`.problems`: ready objectives over named shape parameters (``"a.mu"``, ``"b.gamma"``, ...):
  quasi-developable strips (R), fairness (AL, En, CVEn) of dual curves and interpolation curves.
* :mod:`.pareto`: non-dominated archive and Pareto front of (AL, En, CVEn).
* :mod:`.pipeline`: problem -> optimized object -> B-rep face, STEP, flat pattern, plot.
"""

from __future__ import annotations

from .optimizers import (
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

__all__ = [
    "METHODS",
    "OptimizerState",
    "OptimizeResult",
    "as_bounds",
    "differential_evolution",
    "gwo",
    "igwo",
    "minimize",
    "pso",
    "vectorize",
]
