"""Comparison of optimizers on the same problems: statistics over seeds and a text table.

For each problem and method, ``seeds`` independent runs with the same population size and
iteration budget give the best, median and worst final value, the mean evaluation count and the
median wall time. **Evaluations to reach the same value**: the common target of a problem is

    target = f_best + rtol · (f_init - f_best)

with ``f_best`` the best value of all runs of all methods and ``f_init`` the median best value
of the initial populations (so ``rtol = 1e-3`` means 99.9 % of the achievable improvement); for
each run the evaluations after which its best value was first ``<= target`` (per-iteration
resolution); a run that never reaches it counts as infinite; the median over seeds is reported
with its ratio to the baseline method (``de`` by default; < 1 means fewer evaluations).
Exact gradient evaluations (``hybrid`` on a problem with ``value_and_grad``) count as
``grad_cost`` objective evaluations each (:meth:`OptimizeResult.cost`; the bench measures it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from ..core.errors import GHTError
from .optimizers import METHODS, OptimizeResult

__all__ = ["MethodStats", "BudgetSweep", "budget_sweep", "compare", "format_table", "set_target"]


@dataclass
class MethodStats:
    """Statistics of one method on one problem over several seeds."""

    problem: str
    method: str
    best: float
    median: float
    worst: float
    nfev: float
    time: float
    target: float = math.nan
    nfev_to_target: float = math.inf
    reached: int = 0
    ratio: float = math.nan
    grad_cost: float = 0.0
    runs: list[OptimizeResult] = field(default_factory=list, repr=False)


def compare(
    problems: Mapping[str, tuple[Callable[[np.ndarray], Any], Any]],
    methods: Sequence[str] = ("pso", "gwo", "igwo", "de"),
    *,
    seeds: Sequence[int] = tuple(range(10)),
    pop_size: int = 30,
    max_iter: int = 200,
    baseline: str = "de",
    rtol: float = 1e-3,
    x0: Mapping[str, Any] | None = None,
    progress: Callable[[str, str, int], Any] | None = None,
    variants: Mapping[str, Callable[..., OptimizeResult]] | None = None,
    grad_cost: Mapping[str, float] | None = None,
) -> list[MethodStats]:
    """Run every method on every problem for every seed and summarize.

    Args:
        problems: ``name -> (objective, bounds)``.
        methods: names in :data:`~ght_cad.optimize.METHODS`.
        seeds: one run per seed (the same seeds for every method).
        pop_size, max_iter: the same budget for every method (I-GWO spends 2 pop per iteration;
            compare ``nfev``).
        baseline: method whose evaluations-to-target are the ratios' denominator.
        rtol: fraction of the achievable improvement left at the target (see module docstring).
        x0: optional ``name -> starting point`` placed in every initial population.
        progress: ``progress(problem, method, seed)`` called before each run.
        variants: further methods by label, ``label -> opt(fun, bounds, *, pop_size, max_iter,
            seed, x0) -> OptimizeResult`` (e.g. ``hybrid`` with finite differences, DE with
            ``polish=True``); their labels may appear in ``methods``.
        grad_cost: ``problem name -> evaluations one exact gradient costs`` (default 0).

    Returns:
        One :class:`MethodStats` per (problem, method), in input order.

    Raises:
        GHTError: unknown method names or no seeds.
    """
    table = {**METHODS, **(variants or {})}
    for m in methods:
        if m not in table:
            raise GHTError(f"method {m!r} is unknown; choose from {', '.join(table)}")
    if not len(seeds):
        raise GHTError("seeds is empty; give at least one seed")
    out: list[MethodStats] = []
    for pname, (fun, bounds) in problems.items():
        rows = []
        for m in methods:
            runs = []
            for s in seeds:
                if progress is not None:
                    progress(pname, m, s)
                runs.append(table[m](fun, bounds, pop_size=pop_size, max_iter=max_iter, seed=int(s),
                                     x0=None if x0 is None else x0.get(pname)))
            vals = np.array([r.fun for r in runs])
            rows.append(MethodStats(
                problem=pname, method=m, best=float(vals.min()), median=float(np.median(vals)),
                worst=float(vals.max()), nfev=float(np.mean([r.nfev for r in runs])),
                time=float(np.median([r.time for r in runs])), runs=runs,
                grad_cost=float((grad_cost or {}).get(pname, 0.0)),
            ))
        set_target(rows, rtol, baseline)
        out.extend(rows)
    return out


def set_target(rows: Sequence[MethodStats], rtol: float = 1e-3, baseline: str = "de") -> float:
    """(Re)compute target, evaluations to target and ratios of the rows of ONE problem, in place.

    ``target = f_best + rtol (f_init - f_best)`` (module docstring); returns the target.

    Raises:
        GHTError: rows of several problems, or ``rtol`` outside [0, 1].
    """
    if len({r.problem for r in rows}) != 1:
        raise GHTError("set_target needs the rows of exactly one problem")
    if not 0.0 <= float(rtol) <= 1.0:
        raise GHTError(f"rtol={rtol!r} is not allowed; use a fraction in [0, 1]")
    f_best = min(r.best for r in rows)
    f_init = float(np.median([run.history[0] for r in rows for run in r.runs]))
    target = f_best + rtol * (f_init - f_best) if math.isfinite(f_init) else f_best
    for r in rows:
        hits = [run.nfev_to_reach(target, r.grad_cost) for run in r.runs]
        n = np.array([math.inf if h is None else h for h in hits], dtype=float)
        r.target = target
        r.reached = int(np.sum(np.isfinite(n)))
        r.nfev_to_target = float(np.median(n))
        r.ratio = math.nan
    base = next((r for r in rows if r.method == baseline), None)
    for r in rows:
        if base is not None and math.isfinite(base.nfev_to_target) and base.nfev_to_target > 0:
            r.ratio = r.nfev_to_target / base.nfev_to_target
    return target


def format_table(rows: Sequence[MethodStats], fmt: str = "markdown") -> str:
    """The comparison as a Markdown (``fmt="markdown"``) or plain-text table.

    Columns: problem, method, best, median, worst, mean nfev, median time, target, median
    evaluations to reach the target (runs reaching it / runs), ratio to the baseline.
    """
    head = ["problem", "method", "best", "median", "worst", "nfev", "time [s]", "target",
            "nfev to target", "ratio"]
    body = []
    for r in rows:
        body.append([
            r.problem, r.method, f"{r.best:.4g}", f"{r.median:.4g}", f"{r.worst:.4g}", f"{r.nfev:.0f}",
            f"{r.time:.3f}", f"{r.target:.4g}",
            ("never" if not math.isfinite(r.nfev_to_target) else f"{r.nfev_to_target:.0f}")
            + f" ({r.reached}/{len(r.runs)})",
            "-" if not math.isfinite(r.ratio) else f"{r.ratio:.2f}",
        ])
    if fmt == "markdown":
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        lines += ["| " + " | ".join(b) + " |" for b in body]
        return "\n".join(lines)
    if fmt == "text":
        widths = [max(len(h), *(len(b[i]) for b in body)) if body else len(h) for i, h in enumerate(head)]
        fmt_row = lambda cells: "  ".join(c.ljust(w) for c, w in zip(cells, widths))  # noqa: E731
        return "\n".join([fmt_row(head), fmt_row(["-" * w for w in widths])] + [fmt_row(b) for b in body])
    raise GHTError(f"fmt={fmt!r} is not allowed; use 'markdown' or 'text'")


@dataclass
class BudgetSweep:
    """Fewest evaluations with which one method reaches a target, over populations and schedules.

    Attributes:
        method: optimizer name.
        target: the value to reach.
        nfev: median (over seeds) evaluations to the first best value ``<= target`` at the best
            (pop_size, max_iter) of the grid; ``inf`` if no grid point has a median that reaches it.
        pop_size, max_iter: where that minimum was found (None if never).
        table: ``(pop_size, max_iter) -> median evaluations to target`` for every grid point.
    """

    method: str
    target: float
    nfev: float
    pop_size: int | None
    max_iter: int | None
    table: dict[tuple[int, int], float] = field(default_factory=dict, repr=False)


def budget_sweep(
    fun: Callable[[np.ndarray], Any],
    bounds: Any,
    method: str,
    target: float,
    *,
    pop_sizes: Sequence[int] = (10, 15, 20, 30),
    max_iters: Sequence[int] = (7, 10, 14, 20, 28, 40, 56, 80, 113, 160),
    seeds: Sequence[int] = tuple(range(10)),
) -> BudgetSweep:
    r"""Evaluations a method needs to reach ``target`` when its population and schedule fit the task.

    PSO's inertia ``w`` (0.9 → 0.4) and GWO/I-GWO's ``a`` (2 → 0) run over ``max_iter``
    iterations (spec section 8), so a run only exploits at the end of its schedule and the
    first-hit count of one long run overstates what the method needs. For every grid point
    ``(pop_size, max_iter)`` this runs every seed and takes the median, over seeds, of the
    evaluations after which the best value is first ``<= target`` (``inf`` for a run that never
    gets there):

        N(method) = min over (pop_size, max_iter) of median_seeds n_hit(pop_size, max_iter, seed)

    Methods without a schedule (``de``) still get the population sweep; their ``max_iter`` only
    caps the run, so give them the largest value only (``max_iters=(max(grid),)``).

    Args:
        fun, bounds: the problem.
        method: name in :data:`~ght_cad.optimize.METHODS`.
        target: the value to reach.
        pop_sizes, max_iters: the grid.
        seeds: one run per seed and grid point.

    Returns:
        BudgetSweep.

    Raises:
        GHTError: unknown method, empty grid or no seeds.
    """
    if method not in METHODS:
        raise GHTError(f"method {method!r} is unknown; choose from {', '.join(METHODS)}")
    if not len(pop_sizes) or not len(max_iters) or not len(seeds):
        raise GHTError("pop_sizes, max_iters and seeds must each hold at least one value")
    out = BudgetSweep(method=method, target=float(target), nfev=math.inf, pop_size=None, max_iter=None)
    for pop in pop_sizes:
        for it in max_iters:
            hits = []
            for s in seeds:
                run = METHODS[method](fun, bounds, pop_size=int(pop), max_iter=int(it), seed=int(s))
                h = run.nfev_to_reach(target)
                hits.append(math.inf if h is None else float(h))
            med = float(np.median(hits))
            out.table[(int(pop), int(it))] = med
            if med < out.nfev:
                out.nfev, out.pop_size, out.max_iter = med, int(pop), int(it)
    return out
