r"""Population optimizers on a box (spec section 8): PSO, GWO, I-GWO and a scipy DE baseline.

All minimize ``f`` over ``lb <= x <= ub``, evaluate the **whole population in one call**
``f(X) -> values`` with ``X`` of shape (pop, dim) and values of shape (pop,), take a seed or a
``numpy.random.Generator``, and stop on the first of

* the iteration budget ``max_iter`` or the evaluation budget ``max_nfev`` (an iteration is only
  started if it fits in ``max_nfev``),
* ``target``: the best value is ``<= target``,
* ``tol``: the best value improved by at most ``tol * max(1, |best|)`` over the last
  ``patience`` iterations (``tol = 0``, the default, disables it),
* the ``callback(state)`` returning True (cancellation); ``state`` is an
  :class:`OptimizerState` (``nit``, ``nfev``, ``x``, ``fun``, ``max_iter``).

Evaluations per iteration: PSO and GWO ``pop``, I-GWO ``2 pop`` (``X_GWO`` and ``X_DLH``),
DE ``pop``; the initial population costs ``pop`` more. Non-finite objective values count as
``+inf``. Every result is an :class:`OptimizeResult`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.errors import GHTError
# Moved to ght_cad.optimize.base, .population and .hybrid (issue 27); every name stays importable from here.
from .base import (_check_box, _COMMON_ARGS, _FinishDone, _float_option, _FORMS, _int_option, _is_number, _Run,
                   _short_repr, _Stop, as_bounds, as_generator, DEFAULT_MAX_ITER, Objective, OptimizeResult,
                   OptimizerState, vectorize)  # noqa: F401
from .hybrid import (_Box, _next_start, _one_blas_thread, _sobol, _value_and_grad_of, hybrid, METHODS)  # noqa: F401
from .population import (_gwo_candidates, _midpoint_bounds, differential_evolution, gwo, igwo, pso)  # noqa: F401

__all__ = [
    "OptimizeResult",
    "OptimizerState",
    "as_bounds",
    "as_generator",
    "pso",
    "gwo",
    "igwo",
    "differential_evolution",
    "hybrid",
    "minimize",
    "METHODS",
    "vectorize",
]


def _is_scalar_objective(fun: Any, lb: np.ndarray, ub: np.ndarray) -> bool:
    """True when ``fun`` takes one point ``(dim,)`` and returns one number (scipy's ``f(x)``).

    Probe: one call at the box centre with a 1-D point (not counted in ``nfev``). A population
    objective ``F(X: (pop, dim))`` either fails on a 1-D array or returns an array; an objective
    with ``value_and_grad`` is a population problem.
    """
    if hasattr(fun, "value_and_grad"):
        return False
    try:
        out = fun(0.5 * (lb + ub))
    except Exception:  # noqa: BLE001 - a population objective refusing a 1-D array
        return False
    return np.ndim(out) == 0


def minimize(fun: Objective, bounds: Any, method: str = "hybrid", *, vectorized: bool | None = None,
             **options: Any) -> OptimizeResult:
    """Minimize an objective over a box with the optimizer ``method`` (``hybrid``, ``pso``, ``gwo``, ``igwo``, ``de``).

    Args:
        fun: population objective ``F(X: (pop, dim)) -> (pop,)`` (with ``fun.value_and_grad`` the
            default ``hybrid`` uses exact gradients, else finite differences), or a scalar
            objective ``f(x: (dim,)) -> float`` as for ``scipy.optimize.minimize`` (evaluated
            point by point through :func:`vectorize`, ``F(X)_k = f(X_k)``).
        bounds: ``(lb, ub)``, a list of ``(low, high)`` pairs or ``scipy.optimize.Bounds``
            (:func:`as_bounds`).
        method: optimizer name (case-insensitive; ``"i-gwo"`` is accepted for ``"igwo"``); the
            default ``"hybrid"`` is Sobol' starts + L-BFGS-B finishes (:func:`hybrid`).
        vectorized: True: ``fun`` is a population objective; False: a scalar one; None (default):
            told apart by one call at the box centre with a 1-D point (a scalar result means
            scalar; an exception or an array means population; not counted in ``nfev``).
        **options: passed on (``pop_size``, ``max_iter``, ``max_nfev``, ``tol``, ``target``,
            ``seed``, ``callback``, ``x0``, method-specific options).

    Returns:
        OptimizeResult.

    Raises:
        GHTError: unknown method name, bad bounds, or any error of the chosen optimizer.
    """
    key = str(method).lower().replace("-", "").replace("_", "")
    key = {"differentialevolution": "de"}.get(key, key)
    if key not in METHODS:
        raise GHTError(f"method={method!r} is unknown; choose one of {', '.join(METHODS)}")
    if vectorized not in (None, True, False):
        raise GHTError(f"vectorized={vectorized!r} is not allowed; use None (detect), True (population) or False (f(x))")
    if not callable(fun):
        raise GHTError(f"fun={fun!r} is not callable; pass F(X: (pop, dim)) -> (pop,) or f(x: (dim,)) -> float")
    lb, ub = as_bounds(bounds)
    if vectorized is False or (vectorized is None and _is_scalar_objective(fun, lb, ub)):
        fun = vectorize(fun)
    return METHODS[key](fun, (lb, ub), **options)
