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

import inspect
import math
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..errors import GHTError

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

Objective = Callable[[np.ndarray], Any]

#: Iterations used when neither ``max_iter`` nor ``max_nfev`` is given.
DEFAULT_MAX_ITER = 200


@dataclass
class OptimizeResult:
    """Outcome of one optimizer run.

    Attributes:
        x: best parameters found, shape (dim,).
        fun: objective value at ``x``.
        nfev: number of objective evaluations (points, not calls).
        nit: number of iterations after the initial population.
        time: wall time in seconds.
        history: best value so far after the initial population (index 0) and after each
            iteration, shape (nit + 1,).
        history_nfev: evaluations used at the same moments, shape (nit + 1,).
        message: why the run stopped.
        method: optimizer name (``"hybrid"``, ``"pso"``, ``"gwo"``, ``"igwo"``, ``"de"``).
        success: False only if no finite value was found.
        njev: exact gradient evaluations (points; ``hybrid`` with a problem's gradients, else 0).
        history_njev: gradient evaluations at the moments of ``history`` (None: none at all).
        phases: ``(name, index into history)`` where each phase of a multi-phase method starts
            (``hybrid``: the global phase, then ``"L-BFGS-B"``); empty for one-phase methods.
    """

    x: np.ndarray
    fun: float
    nfev: int
    nit: int
    time: float
    history: np.ndarray
    history_nfev: np.ndarray
    message: str
    method: str
    success: bool = True
    njev: int = 0
    history_njev: np.ndarray | None = None
    phases: tuple[tuple[str, int], ...] = ()

    def cost(self, grad_cost: float = 0.0) -> np.ndarray:
        """Cost at the moments of ``history`` in objective evaluations: ``nfev + grad_cost · njev``."""
        c = np.asarray(self.history_nfev, dtype=float)
        if self.history_njev is not None and grad_cost:
            c = c + float(grad_cost) * np.asarray(self.history_njev, dtype=float)
        return c

    def nfev_to_reach(self, value: float, grad_cost: float = 0.0) -> float | None:
        """Evaluations after which the best value was first ``<= value`` (None if never).

        Resolution is one iteration (the history is recorded per iteration; per objective call in
        ``hybrid``'s local phase). With ``grad_cost`` an exact gradient counts as that many
        evaluations (:meth:`cost`); the result is then a float.
        """
        hit = np.nonzero(self.history <= value)[0]
        if not hit.size:
            return None
        c = self.cost(grad_cost)[hit[0]]
        return int(c) if not grad_cost else float(c)

    def __str__(self) -> str:
        return (
            f"{self.method}: fun={self.fun:.6g} nfev={self.nfev} nit={self.nit} "
            f"time={self.time:.3f}s ({self.message})"
        )


@dataclass
class OptimizerState:
    """What a callback sees after each iteration (and once after the initial population).

    Attributes:
        nit: iterations done (0 after the initial population).
        nfev: evaluations so far.
        x: best parameters so far (a copy).
        fun: best value so far.
        max_iter: the iteration budget of the run.
        method: optimizer name.
    """

    nit: int
    nfev: int
    x: np.ndarray
    fun: float
    max_iter: int
    method: str


def as_generator(seed: Any) -> np.random.Generator:
    """``numpy.random.Generator`` from ``None``, an int, a SeedSequence or a Generator (as is).

    Raises:
        GHTError: for anything else (e.g. a legacy ``RandomState``, a float).
    """
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is None or isinstance(seed, (np.random.SeedSequence, np.random.BitGenerator)):
        return np.random.default_rng(seed)
    if isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
        if seed < 0:
            raise GHTError(f"seed={seed} is negative; use an int >= 0 or a numpy.random.Generator")
        return np.random.default_rng(int(seed))
    raise GHTError(f"seed={seed!r} is not allowed; use None, an int >= 0 or a numpy.random.Generator")


def _check_box(lb: np.ndarray, ub: np.ndarray, form: str) -> str | None:
    """Why ``lb``/``ub`` are not a box (None: they are), in the words of ``form``."""
    if not (np.all(np.isfinite(lb)) and np.all(np.isfinite(ub))):
        return f"bounds lb={lb.tolist()} ub={ub.tolist()} contain non-finite values; a finite box is required"
    bad = np.nonzero(lb >= ub)[0]
    if bad.size:
        i = int(bad[0])
        return f"bounds component {i}: lb={lb[i]:g} >= ub={ub[i]:g}; need lb < ub ({form})"
    with np.errstate(over="ignore"):
        wide = np.nonzero(~np.isfinite(ub - lb))[0]
    if wide.size:
        i = int(wide[0])
        return f"bounds component {i}: the width ub - lb = {ub[i]:g} - ({lb[i]:g}) overflows; use a finite box"
    return None


_FORMS = "bounds are (lb, ub), two arrays of length dim, or a list of (low, high) pairs"


def as_bounds(bounds: Any) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bound arrays from ``(lb, ub)``, scipy-style ``(low, high)`` pairs or an
    object with ``.lb``/``.ub``.

    Args:
        bounds: one of
            * ``(lb, ub)``: two equal-length 1-D array-likes (scalars allowed for dim 1);
            * a sequence of ``dim`` pairs ``(low, high)`` (scipy's ``minimize``/``differential_evolution``
              form), e.g. ``[(-1, 1)] * 3``;
            * ``scipy.optimize.Bounds`` (anything with ``.lb`` and ``.ub``).

            Shape ``(2, dim)`` reads as ``(lb, ub)`` and ``(dim, 2)`` as pairs; a 2 x 2 that is a
            box either way is ``(lb, ub)`` when given as two numpy arrays, the same box under
            both readings, or refused as ambiguous (pass ``scipy.optimize.Bounds`` then).

    Returns:
        ``(lb, ub)`` as float arrays of shape (dim,), with ``lb < ub`` componentwise.

    Raises:
        GHTError: wrong shape, non-finite values, ``lb >= ub``, a width ``ub - lb`` that
            overflows, or an ambiguous 2 x 2.
    """
    if hasattr(bounds, "lb") and hasattr(bounds, "ub"):
        lb, ub = bounds.lb, bounds.ub
        try:
            lb = np.atleast_1d(np.asarray(lb, dtype=float))
            ub = np.atleast_1d(np.asarray(ub, dtype=float))
        except (TypeError, ValueError):
            raise GHTError(f"bounds={bounds!r} are not numeric; {_FORMS}") from None
        if lb.ndim != 1 or ub.shape != lb.shape:
            raise GHTError(f"bounds have lb shape {lb.shape} and ub shape {ub.shape}; {_FORMS}")
        readings = [("(lb, ub)", lb, ub)]
    else:
        arrays = isinstance(bounds, (list, tuple)) and len(bounds) == 2 and all(isinstance(b, np.ndarray) for b in bounds)
        try:
            A = np.asarray(bounds, dtype=float)
        except (TypeError, ValueError):
            shape = "str" if isinstance(bounds, str) else None
            if shape is None:
                try:
                    shape = np.shape(bounds)
                except ValueError:
                    shape = "ragged"
            raise GHTError(f"bounds with shape {shape} are not allowed; {_FORMS}") from None
        readings = []
        if A.ndim == 1 and A.size == 2:
            readings.append(("(lb, ub)", A[:1], A[1:]))
        elif A.ndim == 2 and A.shape[0] == 2:
            readings.append(("(lb, ub)", A[0], A[1]))
        if A.ndim == 2 and A.shape[1] == 2 and not arrays and A.shape[0] >= 1:
            readings.append(("(low, high) pairs", A[:, 0], A[:, 1]))
        if not readings:
            raise GHTError(f"bounds with shape {A.shape} are not allowed; {_FORMS}")
    if readings[0][1].size == 0:
        raise GHTError("bounds are empty; at least one parameter is needed")
    valid = [(name, lb, ub) for name, lb, ub in readings if _check_box(lb, ub, _FORMS) is None]
    if not valid:
        raise GHTError(str(_check_box(readings[0][1], readings[0][2], _FORMS)))
    if len(valid) == 2 and not (np.array_equal(valid[0][1], valid[1][1]) and np.array_equal(valid[0][2], valid[1][2])):
        raise GHTError(
            f"bounds={np.asarray(bounds).tolist()} are ambiguous: as (lb, ub) the box is "
            f"lb={valid[0][1].tolist()}, ub={valid[0][2].tolist()}; as (low, high) pairs it is "
            f"lb={valid[1][1].tolist()}, ub={valid[1][2].tolist()}; pass scipy.optimize.Bounds(lb, ub) "
            "or (lb, ub) as two numpy arrays"
        )
    return valid[0][1].copy(), valid[0][2].copy()


def vectorize(fun: Callable[[np.ndarray], float]) -> Callable[[np.ndarray], np.ndarray]:
    """Wrap a scalar objective ``f(x) -> float`` as a population objective ``F(X) -> (pop,)``.

    A convenience for objectives without a vectorized form (one Python call per point).
    """

    def F(X: np.ndarray) -> np.ndarray:
        return np.array([float(fun(x)) for x in np.asarray(X, dtype=float)])

    return F


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def _short_repr(v: Any, n: int = 60) -> str:
    r = repr(v)
    return r if len(r) <= n else r[: n - 3] + "..."


def _int_option(name: str, v: Any, lo: int, hint: str = "") -> int:
    """``v`` as an int >= lo (integral floats accepted); GHTError naming ``name=v`` otherwise."""
    if not _is_number(v) or not math.isfinite(v) or int(v) != v or v < lo:
        raise GHTError(f"{name}={v!r} is not allowed; use an integer >= {lo}{hint}")
    return int(v)


def _float_option(name: str, v: Any, *, finite: bool = True, positive: bool = False) -> float:
    """``v`` as a float (finite, and > 0 when ``positive``); GHTError naming ``name=v`` otherwise."""
    if not _is_number(v) or math.isnan(v) or (finite and not math.isfinite(v)) or (positive and not v > 0):
        what = "a finite number" if finite else "a number (not NaN)"
        raise GHTError(f"{name}={v!r} is not allowed; use {what}{' > 0' if positive else ''}")
    return float(v)


class _Stop(Exception):
    """Internal: raised inside scipy's objective to end a DE run on our stopping rules."""


class _FinishDone(Exception):
    """Internal: one local finish of :func:`hybrid` converged (ends that finish, not the run)."""


class _Run:
    """Book-keeping shared by all optimizers: budget, evaluation counting, history, stopping."""

    def __init__(
        self,
        method: str,
        fun: Objective,
        bounds: Any,
        *,
        pop_size: int,
        max_iter: int | None,
        max_nfev: int | None,
        per_agent: int,
        tol: float,
        patience: int,
        target: float | None,
        seed: Any,
        callback: Callable[[OptimizerState], Any] | None,
        x0: Any,
        min_pop: int = 4,
    ) -> None:
        self.t0 = time.perf_counter()
        self.method = method
        if not callable(fun):
            raise GHTError(f"fun={fun!r} is not callable; pass f(X: (pop, dim)) -> (pop,)")
        self.fun = fun
        self.lb, self.ub = as_bounds(bounds)
        self.dim = self.lb.size
        if isinstance(pop_size, bool) or not isinstance(pop_size, (int, np.integer)) or pop_size < min_pop:
            raise GHTError(f"pop_size={pop_size!r} is not allowed; use an integer >= {min_pop}")
        self.pop = int(pop_size)
        self.rng = as_generator(seed)
        if not _is_number(tol) or not math.isfinite(tol) or tol < 0:
            raise GHTError(f"tol={tol!r} is not allowed; use a finite number >= 0 (0 disables it)")
        self.tol = float(tol)
        self.patience = _int_option("patience", patience, 1)
        self.target = None if target is None else _float_option("target", target, finite=False)
        if callback is not None and not callable(callback):
            raise GHTError(f"callback={callback!r} is not callable")
        self.callback = callback
        self.per_iter = per_agent * self.pop
        self.max_iter = self._resolve_budget(max_iter, max_nfev, self.per_iter)
        self.max_nfev = None if max_nfev is None else int(max_nfev)  # checked by _resolve_budget
        self.x0 = None
        if x0 is not None:
            x0 = np.asarray(x0, dtype=float).reshape(-1)
            if x0.shape != (self.dim,):
                raise GHTError(f"x0 has shape {x0.shape}; expected ({self.dim},)")
            if np.any(x0 < self.lb) or np.any(x0 > self.ub) or not np.all(np.isfinite(x0)):
                raise GHTError(f"x0={x0.tolist()} is outside the bounds lb={self.lb.tolist()} ub={self.ub.tolist()}")
            self.x0 = x0
        self.nfev = 0
        self.best_f = math.inf
        self.best_x = 0.5 * (self.lb + self.ub)
        self.hist: list[float] = []
        self.hist_nfev: list[int] = []

    def _resolve_budget(self, max_iter: Any, max_nfev: Any, per_iter: int) -> int:
        limits = []
        if max_iter is not None:
            limits.append(_int_option("max_iter", max_iter, 0))
        if max_nfev is not None:
            n = _int_option("max_nfev", max_nfev, self.pop,
                            " (= pop_size; the initial population alone costs pop_size evaluations)")
            limits.append((n - self.pop) // per_iter)
        return min(limits) if limits else DEFAULT_MAX_ITER

    # -- population helpers ----------------------------------------------------------------
    def initial_population(self) -> np.ndarray:
        X = self.lb + (self.ub - self.lb) * self.rng.random((self.pop, self.dim))
        if self.x0 is not None:
            X[0] = self.x0
        return X

    def evaluate(self, X: np.ndarray) -> np.ndarray:
        """``f(X)`` with shape checks, non-finite -> +inf, counting and best-so-far tracking."""
        return self._count(X, self._values(self.fun(X), X))

    def evaluate_with_grad(self, X: np.ndarray, vg: Callable[[np.ndarray], Any]) -> tuple[np.ndarray, np.ndarray]:
        """``vg(X) -> (values, gradients)`` with the checks of :meth:`evaluate`; gradients (pop, dim)."""
        out = vg(X)
        if not (isinstance(out, tuple) and len(out) == 2):
            raise GHTError(f"value_and_grad returned {_short_repr(out)}; it must return (values (pop,), gradients (pop, dim))")
        f = self._values(out[0], X)
        try:
            G = np.asarray(out[1], dtype=float)
        except (TypeError, ValueError):
            raise GHTError(f"the gradient has values {_short_repr(out[1])}; it must be real numbers, shape {X.shape}") from None
        if G.shape != X.shape:
            raise GHTError(f"the gradient has shape {G.shape} for a population of shape {X.shape}; it must be {X.shape}")
        return self._count(X, f), G

    def _count(self, X: np.ndarray, f: np.ndarray) -> np.ndarray:
        self.nfev += X.shape[0]
        i = int(np.argmin(f))
        if f[i] < self.best_f:
            self.best_f = float(f[i])
            self.best_x = np.array(X[i], dtype=float)
        return f

    def _values(self, raw: Any, X: np.ndarray) -> np.ndarray:
        """Objective output as (pop,) floats, non-finite -> +inf; GHTError for a wrong dtype or shape."""
        f = np.asarray(raw)
        if f.dtype.kind not in "biuf":
            try:
                if f.dtype.kind in "cUSV":
                    raise TypeError
                f = f.astype(float)
            except (TypeError, ValueError):
                raise GHTError(
                    f"the objective returned values of dtype {f.dtype} ({_short_repr(raw)}); "
                    "it must return real numbers, one per row"
                ) from None
        f = f.astype(float, copy=False)
        if f.size != X.shape[0]:
            raise GHTError(
                f"the objective returned shape {f.shape} for a population of shape {X.shape}; "
                f"it must return one value per row, shape ({X.shape[0]},)"
            )
        return np.where(np.isfinite(f.reshape(-1)), f.reshape(-1), np.inf)

    # -- iteration bookkeeping -------------------------------------------------------------
    def record(self, nit: int) -> str | None:
        """Record history after iteration ``nit``; return a stop message or None."""
        self.hist.append(self.best_f)
        self.hist_nfev.append(self.nfev)
        if self.target is not None and self.best_f <= self.target:
            return f"target {self.target:g} reached"
        if self.tol > 0 and nit >= self.patience:
            old = self.hist[-1 - self.patience]
            if old - self.best_f <= self.tol * max(1.0, abs(self.best_f)):
                return f"converged: improvement <= tol={self.tol:g} over {self.patience} iterations"
        if self.callback is not None:
            state = OptimizerState(nit, self.nfev, self.best_x.copy(), self.best_f, self.max_iter, self.method)
            stop = self.callback(state)
            if stop is True or (isinstance(stop, np.bool_) and bool(stop)):  # None/other objects: go on
                return "stopped by callback"
        if nit >= self.max_iter:
            if self.max_nfev is not None and self.nfev + self.per_iter > self.max_nfev:
                return "evaluation budget max_nfev reached"
            return "iteration budget max_iter reached"
        return None

    def result(self, nit: int, message: str) -> OptimizeResult:
        return OptimizeResult(
            x=self.best_x.copy(),
            fun=self.best_f,
            nfev=self.nfev,
            nit=nit,
            time=time.perf_counter() - self.t0,
            history=np.asarray(self.hist, dtype=float),
            history_nfev=np.asarray(self.hist_nfev, dtype=int),
            message=message,
            method=self.method,
            success=bool(math.isfinite(self.best_f)),
        )


_COMMON_ARGS = """
    Args:
        fun: population objective ``f(X) -> values``, X of shape (pop, dim), values (pop,).
        bounds: ``(lb, ub)``, two arrays of length dim (or an object with ``.lb``/``.ub``).
        pop_size: number of agents (>= 4).
        max_iter: iteration budget (default 200 if ``max_nfev`` is not given either).
        max_nfev: evaluation budget (iterations that would exceed it are not started).
        tol: stop when the best value improved by <= ``tol * max(1, |best|)`` over the last
            ``patience`` iterations (0 disables).
        patience: window of the ``tol`` test, in iterations.
        target: stop as soon as the best value is ``<= target``.
        seed: None, an int or a ``numpy.random.Generator``; fixed seed -> identical run.
        callback: ``callback(state: OptimizerState)``, called after the initial population and
            each iteration; returning True stops the run (cancellation).
        x0: optional starting point placed in the initial population (so the result is never
            worse than ``f(x0)``).

    Returns:
        OptimizeResult.

    Raises:
        GHTError: bad bounds, budget, seed, population size, ``x0`` outside the bounds, or an
            objective returning the wrong shape.
"""


def pso(
    fun: Objective,
    bounds: Any,
    *,
    pop_size: int = 30,
    max_iter: int | None = None,
    max_nfev: int | None = None,
    tol: float = 0.0,
    patience: int = 10,
    target: float | None = None,
    seed: Any = None,
    callback: Callable[[OptimizerState], Any] | None = None,
    x0: Any = None,
    w_start: float = 0.9,
    w_end: float = 0.4,
    c1: float = 2.0,
    c2: float = 2.0,
    v_max: float = 0.2,
) -> OptimizeResult:
    """Particle swarm optimization (spec section 8).

    ``v ← w v + c1 r1 ∘ (pbest - x) + c2 r2 ∘ (gbest - x)``, ``|v| ≤ v_max (ub - lb)``
    componentwise, ``x ← clip(x + v, lb, ub)``; inertia ``w`` decreases linearly from
    ``w_start`` (0.9) at the first iteration to ``w_end`` (0.4) at the last; ``r1, r2 ~ U(0,1)``
    per component. Initial velocities are uniform in ``[-v_max (ub-lb), v_max (ub-lb)]``.
    """
    run = _Run("pso", fun, bounds, pop_size=pop_size, max_iter=max_iter, max_nfev=max_nfev,
               per_agent=1, tol=tol, patience=patience,
               target=target, seed=seed, callback=callback, x0=x0)
    rng, lb, ub = run.rng, run.lb, run.ub
    w_start, w_end = _float_option("w_start", w_start), _float_option("w_end", w_end)
    c1, c2 = _float_option("c1", c1), _float_option("c2", c2)
    vmax = _float_option("v_max", v_max, positive=True) * (ub - lb)
    x = run.initial_population()
    v = rng.uniform(-1.0, 1.0, x.shape) * vmax
    fx = run.evaluate(x)
    pbest, pf = x.copy(), fx.copy()
    g = int(np.argmin(pf))
    msg = run.record(0)
    nit = 0
    T = max(run.max_iter - 1, 1)
    while msg is None:
        w = w_start - (w_start - w_end) * nit / T
        r1 = rng.random(x.shape)
        r2 = rng.random(x.shape)
        v = w * v + c1 * r1 * (pbest - x) + c2 * r2 * (pbest[g] - x)
        np.clip(v, -vmax, vmax, out=v)
        x = np.clip(x + v, lb, ub)
        fx = run.evaluate(x)
        better = fx < pf
        pbest[better] = x[better]
        pf[better] = fx[better]
        g = int(np.argmin(pf))
        nit += 1
        msg = run.record(nit)
    return run.result(nit, msg)


pso.__doc__ = (pso.__doc__ or "") + _COMMON_ARGS


def _gwo_candidates(X: np.ndarray, leaders: np.ndarray, a: float, rng: np.random.Generator) -> np.ndarray:
    """``X_GWO = (X_α* + X_β* + X_δ*) / 3`` with ``X_L* = X_L - A |C X_L - X|``.

    ``A = 2 a r1 - a``, ``C = 2 r2``, fresh ``r1, r2 ~ U(0,1)`` per wolf, leader and component.
    """
    out = np.zeros_like(X)
    for L in leaders:
        r1 = rng.random(X.shape)
        r2 = rng.random(X.shape)
        A = 2.0 * a * r1 - a
        C = 2.0 * r2
        out += L - A * np.abs(C * L - X)
    out /= len(leaders)
    return out


def gwo(
    fun: Objective,
    bounds: Any,
    *,
    pop_size: int = 30,
    max_iter: int | None = None,
    max_nfev: int | None = None,
    tol: float = 0.0,
    patience: int = 10,
    target: float | None = None,
    seed: Any = None,
    callback: Callable[[OptimizerState], Any] | None = None,
    x0: Any = None,
) -> OptimizeResult:
    """Grey wolf optimizer (spec section 8).

    Leaders α, β, δ are the three best positions found so far; ``a = 2 - 2 it / max_iter``; for
    each leader ``A = 2a r1 - a``, ``C = 2 r2``, ``D = |C X_L - X|``, ``X_L* = X_L - A D``; every
    wolf moves to ``X_GWO = (X_α* + X_β* + X_δ*) / 3``, clipped to the box.
    """
    run = _Run("gwo", fun, bounds, pop_size=pop_size, max_iter=max_iter, max_nfev=max_nfev,
               per_agent=1, tol=tol, patience=patience,
               target=target, seed=seed, callback=callback, x0=x0)
    rng, lb, ub = run.rng, run.lb, run.ub
    X = run.initial_population()
    fX = run.evaluate(X)
    order = np.argsort(fX, kind="stable")[:3]
    lead_x, lead_f = X[order].copy(), fX[order].copy()
    msg = run.record(0)
    nit = 0
    T = max(run.max_iter, 1)
    while msg is None:
        a = 2.0 - 2.0 * nit / T
        X = np.clip(_gwo_candidates(X, lead_x, a, rng), lb, ub)
        fX = run.evaluate(X)
        allf = np.concatenate([lead_f, fX])
        allx = np.concatenate([lead_x, X])
        order = np.argsort(allf, kind="stable")[:3]
        lead_x, lead_f = allx[order].copy(), allf[order].copy()
        nit += 1
        msg = run.record(nit)
    return run.result(nit, msg)


gwo.__doc__ = (gwo.__doc__ or "") + _COMMON_ARGS


def _midpoint_bounds(Y: np.ndarray, X_old: np.ndarray, lb: np.ndarray, ub: np.ndarray) -> np.ndarray:
    """Out-of-bound components go to the midpoint between the old position and the violated bound."""
    Y = np.where(Y < lb, 0.5 * (X_old + lb), Y)
    return np.where(Y > ub, 0.5 * (X_old + ub), Y)


def igwo(
    fun: Objective,
    bounds: Any,
    *,
    pop_size: int = 30,
    max_iter: int | None = None,
    max_nfev: int | None = None,
    tol: float = 0.0,
    patience: int = 10,
    target: float | None = None,
    seed: Any = None,
    callback: Callable[[OptimizerState], Any] | None = None,
    x0: Any = None,
) -> OptimizeResult:
    r"""Improved grey wolf optimizer with dimension-learning-based hunting (spec section 8).

    Per iteration, with α, β, δ the three best wolves of the population (each wolf holds the
    best position it has found) and ``a = 2 - 2 it / max_iter``:

    1. ``X_GWO,i`` as in :func:`gwo`;
    2. radius ``R_i = |X_i - X_GWO,i|``, neighbourhood ``N_i = {X_j : |X_i - X_j| <= R_i}``;
    3. ``X_DLH,i,d = X_i,d + rand · (X_n,d - X_r,d)`` with ``X_n`` a random neighbour drawn per
       dimension d, ``X_r`` a random wolf (one per i: a random permutation, as in the reference
       implementation of Nadimi-Shahraki et al. 2021), ``rand ~ U(0,1)`` per component;
    4. out-of-bound components of both candidates go to the midpoint between ``X_i`` and the
       violated bound;
    5. both candidate sets are evaluated (one call of 2·pop points: ``X_GWO`` and ``X_DLH``, never
       ``X_GWO`` twice); the better candidate replaces ``X_i`` only if it improves on it.
    """
    run = _Run("igwo", fun, bounds, pop_size=pop_size, max_iter=max_iter, max_nfev=max_nfev,
               per_agent=2, tol=tol,
               patience=patience, target=target, seed=seed, callback=callback, x0=x0)
    rng, lb, ub = run.rng, run.lb, run.ub
    N, D = run.pop, run.dim
    X = run.initial_population()
    fX = run.evaluate(X)
    msg = run.record(0)
    nit = 0
    T = max(run.max_iter, 1)
    rows = np.arange(N)[:, None]
    while msg is None:
        a = 2.0 - 2.0 * nit / T
        leaders = X[np.argsort(fX, kind="stable")[:3]]
        Xg = _midpoint_bounds(_gwo_candidates(X, leaders, a, rng), X, lb, ub)
        # dimension-learning-based hunting
        radius = np.sqrt(np.sum((X - Xg) ** 2, axis=1))
        u = rng.random((N, D))
        nb = np.empty((N, D), dtype=np.intp)
        # rows in chunks: memory O(chunk * N * D), never a pop x pop x dim array
        chunk = max(1, min(N, (1 << 21) // max(N * D, 1)))
        for r0 in range(0, N, chunk):
            r1 = min(N, r0 + chunk)
            diff = X[r0:r1, None, :] - X[None, :, :]
            dist = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff))
            mask = dist <= radius[r0:r1, None]
            mask[np.arange(r1 - r0), np.arange(r0, r1)] = True  # a wolf is always its own neighbour
            count = mask.sum(axis=1)
            # k-th True entry of row i, k drawn uniformly per dimension: stable argsort puts True first
            members = np.argsort(~mask, axis=1, kind="stable")
            k = np.minimum((u[r0:r1] * count[:, None]).astype(np.intp), count[:, None] - 1)
            nb[r0:r1] = members[rows[: r1 - r0], k]
        rw = rng.permutation(N)  # one random wolf per i (a permutation, as in the reference code)
        cols = np.arange(D)[None, :]
        Xd = X + rng.random((N, D)) * (X[nb, cols] - X[rw])
        Xd = _midpoint_bounds(Xd, X, lb, ub)
        f_both = run.evaluate(np.concatenate([Xg, Xd]))
        fg, fd = f_both[:N], f_both[N:]
        use_g = fg < fd
        cand = np.where(use_g[:, None], Xg, Xd)
        fc = np.where(use_g, fg, fd)
        better = fc < fX
        X[better] = cand[better]
        fX[better] = fc[better]
        nit += 1
        msg = run.record(nit)
    return run.result(nit, msg)


igwo.__doc__ = (igwo.__doc__ or "") + _COMMON_ARGS


def differential_evolution(
    fun: Objective,
    bounds: Any,
    *,
    pop_size: int = 30,
    max_iter: int | None = None,
    max_nfev: int | None = None,
    tol: float = 0.0,
    patience: int = 10,
    target: float | None = None,
    seed: Any = None,
    callback: Callable[[OptimizerState], Any] | None = None,
    x0: Any = None,
    strategy: str = "best1bin",
    mutation: float | tuple[float, float] = (0.5, 1.0),
    recombination: float = 0.7,
    polish: bool = False,
) -> OptimizeResult:
    """Baseline: ``scipy.optimize.differential_evolution`` with the same interface and result.

    The population (``pop_size`` points, uniform in the box, ``x0`` first) is passed as ``init``;
    the objective is called vectorized (``vectorized=True``, ``updating="deferred"``, scipy >= 1.9)
    once per generation; the random stream is ``seed`` (``rng=`` on scipy >= 1.15, else
    ``seed=``). scipy's own convergence test is switched off (``tol = atol = 0``); the stopping
    rules of this module apply. ``polish`` (an L-BFGS-B finish from the best point after the
    generations, counted in ``nfev`` and kept within ``max_nfev``, recorded as one more history
    entry) is off by default so evaluation counts compare fairly.
    """
    from scipy import optimize as _so

    run = _Run("de", fun, bounds, pop_size=pop_size, max_iter=max_iter, max_nfev=max_nfev,
               per_agent=1, tol=tol, patience=patience,
               target=target, seed=seed, callback=callback, x0=x0, min_pop=5)
    init = run.initial_population()
    state = {"calls": 0, "msg": None}

    def wrapped(xT: np.ndarray) -> np.ndarray:
        X = np.asarray(xT, dtype=float)
        X = X.T if X.ndim == 2 else X.reshape(1, -1)
        f = run.evaluate(X)
        msg = run.record(state["calls"])
        state["calls"] += 1
        if msg is not None:
            state["msg"] = msg
            raise _Stop
        return f

    params = inspect.signature(_so.differential_evolution).parameters
    kw: dict[str, Any] = dict(
        strategy=strategy,
        maxiter=max(run.max_iter, 1) + 5,
        init=init,
        tol=0.0,
        atol=0.0,
        mutation=mutation,
        recombination=recombination,
        polish=False,  # our own polish below: scipy's would never run (the budget stop ends scipy first)
        updating="deferred",
    )
    if "vectorized" not in params:
        raise GHTError("scipy >= 1.9 is required for the vectorized differential_evolution baseline")
    kw["vectorized"] = True
    if "rng" in params:
        kw["rng"] = run.rng
    else:
        kw["seed"] = run.rng
    lb, ub = run.lb, run.ub
    try:
        res = _so.differential_evolution(wrapped, list(zip(lb, ub)), **kw)
        msg = f"scipy: {res.message}"
    except _Stop:
        msg = state["msg"]
    nit = max(state["calls"] - 1, 0)
    msg = msg or "scipy finished"
    stopped = msg.startswith(("stopped by callback", "target"))  # cancelled or done: no polish
    if polish and not stopped and math.isfinite(run.best_f) and (run.max_nfev is None or run.nfev < run.max_nfev):
        def one(x: np.ndarray) -> float:
            if run.max_nfev is not None and run.nfev >= run.max_nfev:
                raise _Stop
            return float(run.evaluate(np.clip(x, lb, ub).reshape(1, -1))[0])

        left = None if run.max_nfev is None else run.max_nfev - run.nfev
        try:
            _so.minimize(one, run.best_x.copy(), method="L-BFGS-B", bounds=list(zip(lb, ub)),
                         options={"maxfun": left} if left is not None else {})
        except _Stop:
            pass
        nit += 1
        run.hist.append(run.best_f)
        run.hist_nfev.append(run.nfev)
        msg += "; L-BFGS-B polish"
    return run.result(nit, msg)


differential_evolution.__doc__ = (differential_evolution.__doc__ or "") + _COMMON_ARGS

def _sobol(dim: int, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` points of a scrambled Sobol' sequence in ``[0, 1)^dim`` (scipy.stats.qmc), drawn from ``rng``."""
    import warnings

    from scipy.stats import qmc

    try:
        eng = qmc.Sobol(dim, scramble=True, rng=rng)
    except TypeError:  # scipy < 1.15
        eng = qmc.Sobol(dim, scramble=True, seed=rng)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # "balance properties" warning for n not a power of 2
        return eng.random(int(n))


class _Box:
    """The unit cube ``z ∈ [0, 1]^dim`` of the local phase; ``x = lb + z (ub - lb)`` with the ends exact."""

    def __init__(self, lb: np.ndarray, ub: np.ndarray) -> None:
        self.lb, self.ub, self.width = lb, ub, ub - lb

    def x(self, z: np.ndarray) -> np.ndarray:
        z = np.asarray(z, dtype=float)
        x = self.lb + z * self.width
        np.copyto(x, self.ub, where=z >= 1.0)  # z clipped to [0, 1], its ends mapped exactly
        np.copyto(x, self.lb, where=z <= 0.0)
        return x

    def z(self, x: np.ndarray) -> np.ndarray:
        return np.clip((np.asarray(x, dtype=float) - self.lb) / self.width, 0.0, 1.0)


def _value_and_grad_of(fun: Any, jac: Any) -> Callable[[np.ndarray], Any] | None:
    """The exact-gradient callable hybrid uses: ``jac`` if callable, ``fun.value_and_grad`` if present
    (``jac=None``), None for finite differences."""
    if isinstance(jac, str):
        if jac.lower() != "fd":
            raise GHTError(f"jac={jac!r} is not allowed; use None (exact gradients when the problem has them), "
                           "'fd' (finite differences) or a callable jac(X) -> (pop, dim)")
        return None
    if jac is not None:
        if not callable(jac):
            raise GHTError(f"jac={jac!r} is not callable; pass jac(X: (pop, dim)) -> gradients (pop, dim)")
        return lambda X: (fun(X), jac(X))
    vg = getattr(fun, "value_and_grad", None)
    return vg if callable(vg) and getattr(fun, "has_gradient", True) else None


def _one_blas_thread() -> Any:
    """Context limiting BLAS to one thread (threadpoolctl, when installed): L-BFGS-B's tiny BLAS
    calls otherwise wait on OpenBLAS worker threads (measured: 9 ms per iteration on a loaded
    2-core machine, 4-6x the whole local phase)."""
    import contextlib

    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # e.g. FreeCAD's Python: same results, only slower on a busy machine
        return contextlib.nullcontext()
    return threadpool_limits(1, user_api="blas")


def _next_start(pool_z: np.ndarray, pool_f: np.ndarray, avoid: list[np.ndarray], dim: int,
                sigma: float = 4.0) -> tuple[np.ndarray | None, float]:
    r"""Next local start by multi-level single linkage: the best finite point of the pool with no
    better point within ``r = (Γ(1+d/2) σ log N / N)^(1/d) / √π`` (unit cube, N pool points, at
    most 0.5) and at least ``r/2`` from every earlier start and minimum; (None, inf) if none is left."""
    ok = np.isfinite(pool_f)
    Z, F = pool_z[ok], pool_f[ok]
    n = max(Z.shape[0], 2)
    r = float(min(0.5, (math.gamma(1 + dim / 2) * sigma * math.log(n) / n) ** (1 / dim) / math.sqrt(math.pi)))
    order = np.argsort(F, kind="stable")
    Z, F = Z[order], F[order]
    for i in range(Z.shape[0]):
        if i and np.any(np.sqrt(((Z[:i] - Z[i]) ** 2).sum(-1)) < r):
            continue  # a better point nearby: same basin
        if any(np.sqrt(((Z[i] - a) ** 2).sum()) < 0.5 * r for a in avoid):
            continue
        return Z[i].copy(), float(F[i])
    return None, math.inf


def hybrid(
    fun: Objective,
    bounds: Any,
    *,
    pop_size: int = 32,
    max_iter: int | None = None,
    max_nfev: int | None = None,
    tol: float = 0.0,
    patience: int = 10,
    target: float | None = None,
    seed: Any = None,
    callback: Callable[[OptimizerState], Any] | None = None,
    x0: Any = None,
    starts: str = "sobol",
    global_iter: int = 10,
    local_starts: int = 4,
    jac: Any = None,
) -> OptimizeResult:
    r"""Space-filling starts, then bounded quasi-Newton finishes (spec section 8.1; the default method).

    1. **Global phase**: ``pop_size`` points of a scrambled Sobol' sequence in the box
       (``starts="sobol"``, one vectorized call; ``x0`` is added as one more point), or a short
       PSO / I-GWO run of ``global_iter`` iterations with ``pop_size`` agents
       (``starts="pso"`` / ``"igwo"``, exactly :func:`pso` / :func:`igwo`; all their points join
       the pool of candidates).
    2. **Local phase**: up to ``local_starts`` L-BFGS-B finishes (scipy), each from the best pool
       point that has no better pool point within the multi-level-single-linkage radius
       ``r = (Γ(1+d/2) σ log N / N)^(1/d) / √π`` (σ = 4, unit cube, N pool points; one start per
       basin of the sample) and lies at least ``r/2`` from earlier starts and minima. A finish
       works on the scaled problem ``f(x(z)) / |f(start)|`` over the unit cube
       ``z = (x - lb)/(ub - lb)`` (so a value like R ≈ 1e-5 does not fall under L-BFGS-B's
       tolerances; ``ftol = gtol = 1e-12``) and ends when its last 3 iterations gained at most
       ``tol`` (default 1e-5) of what the finish gained so far. A finish that ends on the box
       boundary adds 16 points of the face it lies on (its corners first when the face has at
       most 3 free parameters) to the pool, once per face: optima of shape parameters often sit
       on a face or corner of the box. Finally the best point, with its parameters within 1e-2
       (unit cube) of a bound put onto the bound, gets a last finish to tight convergence (gain
       fraction 1e-9, at most 20 iterations; it leaves a bound that is not optimal).

    Bounds are hard: ``x = lb + z (ub - lb)`` with ``z ∈ {0, 1}`` mapped exactly onto ``lb``,
    ``ub`` (L-BFGS-B keeps ``0 <= z <= 1``), so an optimum on the boundary is reached exactly.

    Gradients: ``jac=None`` uses ``fun.value_and_grad(X) -> (values, gradients)`` when the
    objective has it (the problems of :mod:`ght_cad.optimize.problems`: exact, spec 8.1), else
    forward finite differences in one vectorized call of ``dim + 1`` points per gradient (step
    ``1.5e-8`` of the box width, inwards at an upper bound), every point counted in ``nfev``;
    ``jac="fd"`` forces finite differences; a callable ``jac(X) -> (pop, dim)`` supplies them.
    Exact gradients are counted in ``njev`` (one per point), their values in ``nfev``.

    Stops on ``target``, the evaluation budget ``max_nfev`` (all phases), the iteration budget
    ``max_iter`` (L-BFGS-B iterations summed over the finishes; default 200), the callback
    (called after the global phase and every L-BFGS-B iteration), or when ``local_starts``
    finishes are done or no start is left. Non-finite values count as ``+inf`` (L-BFGS-B sees a
    large finite value there and backtracks). ``history`` holds the best value after the global
    phase (per PSO/I-GWO iteration for those starts) and after every objective call of the local
    phase; ``phases`` names where each phase starts in it; ``nit`` counts global plus local
    iterations. ``patience`` is accepted for the common interface and not used.
    """
    from scipy import optimize as _so

    run = _Run("hybrid", fun, bounds, pop_size=pop_size, max_iter=None, max_nfev=max_nfev,
               per_agent=1, tol=tol, patience=patience, target=target, seed=seed, callback=callback, x0=x0)
    starts_key = str(starts).lower().replace("-", "")
    if starts_key not in ("sobol", "pso", "igwo"):
        raise GHTError(f"starts={starts!r} is not allowed; use 'sobol', 'pso' or 'igwo'")
    local_starts = _int_option("local_starts", local_starts, 1)
    global_iter = _int_option("global_iter", global_iter, 0)
    local_iter_cap = (_int_option("max_iter", max_iter, 0) if max_iter is not None
                      else (DEFAULT_MAX_ITER if max_nfev is None else None))
    run.max_iter = local_iter_cap if local_iter_cap is not None else 0
    vg = _value_and_grad_of(fun, jac)
    box = _Box(run.lb, run.ub)
    dim = run.dim
    njev = [0]
    hist_njev: list[int] = []
    phases: list[tuple[str, int]] = []
    seen_x: list[np.ndarray] = []
    seen_f: list[np.ndarray] = []

    def record() -> None:
        run.hist.append(run.best_f)
        run.hist_nfev.append(run.nfev)
        hist_njev.append(njev[0])

    def check(nit: int) -> str | None:
        if run.target is not None and run.best_f <= run.target:
            return f"target {run.target:g} reached"
        if run.max_nfev is not None and run.nfev >= run.max_nfev:
            return "evaluation budget max_nfev reached"
        return None

    def user_callback(nit: int) -> str | None:
        if run.callback is None:
            return None
        state = OptimizerState(nit, run.nfev, run.best_x.copy(), run.best_f, run.max_iter, run.method)
        stop = run.callback(state)
        if stop is True or (isinstance(stop, np.bool_) and bool(stop)):
            return "stopped by callback"
        return None

    # -- 1. global phase ---------------------------------------------------------------------
    msg: str | None = None
    nit = 0
    if starts_key == "sobol":
        phases.append(("Sobol starts", 0))
        X = box.x(_sobol(dim, run.pop, run.rng))
        if run.x0 is not None:
            X = np.concatenate([run.x0[None, :], X])
        if run.max_nfev is not None and X.shape[0] > run.max_nfev:
            X = X[: run.max_nfev]
        f = run.evaluate(X)
        seen_x.append(X)
        seen_f.append(f)
        record()
        msg = check(0) or user_callback(0)
    else:
        phases.append((f"{starts_key.upper().replace('IGWO', 'I-GWO')} phase", 0))
        per = 2 if starts_key == "igwo" else 1

        def logged(X: np.ndarray) -> np.ndarray:
            f = run.evaluate(np.asarray(X, dtype=float))
            seen_x.append(np.array(X, dtype=float))
            seen_f.append(f)
            return f

        stop_msg: list[str] = []

        def inner_cb(state: OptimizerState) -> bool:
            record()
            m = check(state.nit) or user_callback(state.nit)
            if m:
                stop_msg.append(m)
            return bool(m)

        g_iter = global_iter
        if run.max_nfev is not None:
            g_iter = max(0, min(g_iter, (run.max_nfev - run.pop) // (per * run.pop)))
        inner = METHODS[starts_key](logged, (run.lb, run.ub), pop_size=run.pop, max_iter=g_iter,
                                    seed=run.rng, callback=inner_cb, x0=run.x0)
        nit = inner.nit
        msg = stop_msg[0] if stop_msg else None

    # -- 2. local phase: L-BFGS-B from the best distinct candidates ------------------------------
    phases.append(("L-BFGS-B", len(run.hist)))
    if msg is None and math.isfinite(run.best_f):
        pool_z = box.z(np.concatenate(seen_x))
        pool_f = np.concatenate(seen_f)
        avoid: list[np.ndarray] = []  # starts and minima already used, in z
        faces: set[tuple[int, ...]] = set()
        finishes: list[float] = []
        eps_step = 1.4901161193847656e-08
        gain_tol = float(tol) if tol > 0 else 1e-5
        local_nit = [0]
        n_face = 16

        def finish(z0: np.ndarray, f_start: float, frac: float, cap: int | None) -> tuple[np.ndarray, float]:
            """One L-BFGS-B run from z0; returns its best point (z) and value."""
            scale = abs(f_start) or 1.0
            big = 1e3 * (1.0 + abs(f_start) / scale)
            fin_hist: list[float] = []
            fin_best: list[Any] = [math.inf, z0]

            def fg(z: np.ndarray) -> tuple[float, np.ndarray]:
                x = box.x(z)
                if vg is not None:
                    f, g = run.evaluate_with_grad(x[None, :], vg)
                    njev[0] += 1
                    f0, grad = float(f[0]), g[0] * box.width
                else:
                    steps = np.where(z + eps_step <= 1.0, eps_step, -eps_step)
                    Z = np.repeat(z[None, :], dim + 1, axis=0)
                    Z[np.arange(1, dim + 1), np.arange(dim)] += steps
                    Xs = box.x(Z)
                    Xs[0] = x
                    if run.max_nfev is not None and run.nfev + Xs.shape[0] > run.max_nfev:
                        raise _Stop("evaluation budget max_nfev reached")
                    fs = run.evaluate(Xs)
                    f0 = float(fs[0])
                    with np.errstate(invalid="ignore"):
                        grad = np.where(np.isfinite(fs[1:]), (fs[1:] - f0) / steps, 0.0)
                record()
                m = check(local_nit[0])
                if m:
                    raise _Stop(m)
                if not math.isfinite(f0):
                    return big, np.zeros(dim)
                if f0 < fin_best[0]:
                    fin_best[0], fin_best[1] = f0, np.array(z, dtype=float)
                return f0 / scale, np.where(np.isfinite(grad), grad, 0.0) / scale

            def it_cb(*_a: Any) -> None:
                local_nit[0] += 1
                fin_hist.append(fin_best[0])
                m = user_callback(nit + local_nit[0])
                if m is None and local_iter_cap is not None and local_nit[0] >= local_iter_cap:
                    m = "iteration budget max_iter reached"
                if m:
                    raise _Stop(m)
                if len(fin_hist) > 3 and fin_hist[-4] - fin_hist[-1] <= frac * (f_start - fin_hist[-1]):
                    raise _FinishDone  # converged: the last 3 iterations gained <= frac of the finish's gain
                if cap is not None and len(fin_hist) >= cap:
                    raise _FinishDone

            opts: dict[str, Any] = {"ftol": 1e-12, "gtol": 1e-12, "maxls": 30}
            if local_iter_cap is not None:
                opts["maxiter"] = max(local_iter_cap - local_nit[0], 1)
            try:
                _so.minimize(fg, z0, jac=True, method="L-BFGS-B", bounds=[(0.0, 1.0)] * dim,
                             callback=it_cb, options=opts)
            except _FinishDone:
                pass
            return np.asarray(fin_best[1], dtype=float), float(fin_best[0])

        blas_one = _one_blas_thread()
        blas_one.__enter__()
        try:
            while len(finishes) < local_starts:
                z0, f_start = _next_start(pool_z, pool_f, avoid, dim)
                if z0 is None:
                    break
                zend, fend = finish(z0, f_start, gain_tol, None)
                avoid += [z0, zend]
                finishes.append(fend)
                # a minimum on the box boundary: sample the face it lies on (once per face)
                active = tuple(int(i) for i in np.nonzero((zend <= 0.0) | (zend >= 1.0))[0])
                if active and active not in faces and len(finishes) < local_starts:
                    faces.add(active)
                    free = [i for i in range(dim) if i not in active]
                    Zf = np.repeat(zend[None, :], n_face, axis=0)
                    if free:
                        Zf[:, free] = _sobol(len(free), n_face, run.rng)
                        if len(free) <= 3:  # the face's own corners first
                            corners = np.array(np.meshgrid(*[[0.0, 1.0]] * len(free), indexing="ij")).reshape(len(free), -1).T
                            Zf[: corners.shape[0], free] = corners
                    else:
                        Zf = Zf[:1]
                    if run.max_nfev is not None and run.nfev + Zf.shape[0] > run.max_nfev:
                        raise _Stop("evaluation budget max_nfev reached")
                    ff = run.evaluate(box.x(Zf))
                    record()
                    m = check(local_nit[0])
                    if m:
                        raise _Stop(m)
                    pool_z = np.concatenate([pool_z, Zf])
                    pool_f = np.concatenate([pool_f, ff])
            msg = f"{len(finishes)} L-BFGS-B finish{'es' if len(finishes) != 1 else ''} done"
            # polish: the best point with parameters within 1e-2 (unit cube) of a bound put onto it,
            # then a last finish to tight convergence (at most 20 iterations)
            zb = box.z(run.best_x)
            near = ((zb < 1e-2) & (zb > 0.0)) | ((zb > 1.0 - 1e-2) & (zb < 1.0))
            zs = np.where(near, np.round(zb), zb)
            f_best = run.best_f
            finish(zs, f_best, 1e-9, 20)  # from the snapped point: L-BFGS-B leaves a bound that is not optimal
            if run.best_f < f_best:
                msg += "; polished"
        except _Stop as stop:
            msg = str(stop)
        finally:
            blas_one.__exit__(None, None, None)
        nit += local_nit[0]
    elif msg is None:
        msg = "no finite value in the global phase"
    res_ = run.result(nit, msg)
    res_.njev = njev[0]
    res_.history_njev = np.asarray(hist_njev, dtype=int)
    res_.phases = tuple(phases)
    return res_


hybrid.__doc__ = (hybrid.__doc__ or "") + _COMMON_ARGS.replace(
    "pop_size: number of agents (>= 4).",
    "pop_size: Sobol' starts, or PSO/I-GWO agents (>= 4; default 32).").replace(
    "max_iter: iteration budget (default 200 if ``max_nfev`` is not given either).",
    "max_iter: L-BFGS-B iterations over all finishes (default 200 if ``max_nfev`` is not given either).")


#: Optimizers by name, for :func:`minimize`, the bench and the comparison table.
METHODS: dict[str, Callable[..., OptimizeResult]] = {
    "hybrid": hybrid,
    "pso": pso,
    "gwo": gwo,
    "igwo": igwo,
    "de": differential_evolution,
}


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
