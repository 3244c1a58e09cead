"""What every optimizer of :mod:`ght_cad.optimize.optimizers` shares: the result and state types, seeds,
bounds and option checks, and the run loop with its stopping rules (see that module's docstring).

Moved from :mod:`ght_cad.optimize.optimizers` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import functools
import inspect
import math
import time
from dataclasses import dataclass
from typing import Any, Callable, Iterator, TypedDict

import numpy as np

from ..core.errors import GHTError


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

    def drive(self, steps: Iterator[None]) -> OptimizeResult:
        """Run a population update rule to its stop and return the result.

        ``steps`` is a generator: it evaluates the initial population before its first ``yield``
        and makes one iteration (update, clip, :meth:`evaluate`) before each further ``yield``.
        After every ``yield`` the history is recorded and the stopping rules are checked
        (:meth:`record`, iteration 0 = the initial population); ``nit`` counts the iterations.
        """
        next(steps)
        msg = self.record(0)
        nit = 0
        while msg is None:
            next(steps)
            nit += 1
            msg = self.record(nit)
        steps.close()
        return self.result(nit, msg)

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


class _Options(TypedDict, total=False):
    """The keyword options every optimizer takes, documented in ``_COMMON_ARGS``; an optimizer is
    written ``f(fun, bounds, *, <own options>, **options: Unpack[_Options])`` under
    :func:`_common_interface`, which gives it these as explicit keyword parameters."""

    pop_size: int
    max_iter: int | None
    max_nfev: int | None
    tol: float
    patience: int
    target: float | None
    seed: Any
    callback: Callable[[OptimizerState], Any] | None
    x0: Any


#: Defaults of :class:`_Options`, in signature order (``pop_size``: see :func:`_common_interface`).
_OPTION_DEFAULTS: dict[str, Any] = {"pop_size": 30, "max_iter": None, "max_nfev": None, "tol": 0.0, "patience": 10,
                                    "target": None, "seed": None, "callback": None, "x0": None}


def _common_interface(pop_size: int = 30, args_doc: str = _COMMON_ARGS
                      ) -> Callable[[Callable[..., OptimizeResult]], Callable[..., OptimizeResult]]:
    """Decorator for an optimizer ``f(fun, bounds, *, <own options>, **options: Unpack[_Options])``.

    The public function has the explicit signature ``(fun, bounds, *, pop_size=<pop_size>,
    max_iter=None, max_nfev=None, tol=0.0, patience=10, target=None, seed=None, callback=None,
    x0=None, <own options>)`` (``inspect.signature``, ``help``), receives every common option
    (its default where not given) in ``**options``, so the body passes them on to :class:`_Run`,
    and has ``args_doc`` appended to its docstring. A wrong argument is a TypeError naming the
    function, as for a plain function.
    """
    def annotation(name: str) -> Any:
        a = _Options.__annotations__[name]
        return getattr(a, "__forward_arg__", a)  # the text, as in a signature under postponed annotations

    def decorate(f: Callable[..., OptimizeResult]) -> Callable[..., OptimizeResult]:
        sig = inspect.signature(f)
        own = [p for p in sig.parameters.values() if p.kind is not inspect.Parameter.VAR_KEYWORD]
        common = [inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, annotation=annotation(name),
                                    default=pop_size if name == "pop_size" else default)
                  for name, default in _OPTION_DEFAULTS.items()]
        public = sig.replace(parameters=own[:2] + common + own[2:])

        @functools.wraps(f)
        def optimizer(*args: Any, **kwargs: Any) -> OptimizeResult:
            try:
                bound = public.bind(*args, **kwargs)
            except TypeError as e:
                raise TypeError(f"{f.__name__}() {e}") from None
            bound.apply_defaults()
            return f(*bound.args, **bound.kwargs)

        optimizer.__signature__ = public  # type: ignore[attr-defined]
        optimizer.__doc__ = (f.__doc__ or "") + args_doc
        return optimizer

    return decorate
