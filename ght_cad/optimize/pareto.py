r"""Pareto front of the fairness measures (AL, En, CVEn) from an archive of non-dominated points.

Method (documented choice): a **weighted-sum sweep with an archive**. For every weight vector
``w`` of a simplex lattice (``divisions`` steps per objective, e.g. 15 vectors for 3 objectives
and 4 divisions) a single-objective optimizer minimizes ``Σ_k w_k F_k(x) / F_k(x_ref)`` (each
measure scaled by its value at the base design, so the weights are comparable). **Every point
the optimizers evaluate** (not only the final optima) goes into a :class:`ParetoArchive` that
keeps the non-dominated ones: ``x`` dominates ``y`` iff ``F(x) <= F(y)`` componentwise with at
least one strict inequality. Weighted sums alone find only the convex part of a front; the
archive also keeps non-convex parts that the runs pass through. When the archive exceeds
``max_size`` it drops the most crowded points (smallest crowding distance, the extreme points of
each objective are always kept).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..core.errors import GHTError
from .optimizers import OptimizeResult, as_generator, minimize

__all__ = [
    "nondominated",
    "crowding_distance",
    "simplex_weights",
    "ParetoArchive",
    "ParetoResult",
    "pareto_front",
]


def nondominated(F: Any) -> np.ndarray:
    """Boolean mask of the rows of ``F`` (n, k) not dominated by any other row (minimization).

    Row i is dominated iff some row j has ``F_j <= F_i`` everywhere and ``F_j < F_i`` somewhere.
    Duplicated rows do not dominate each other (all copies are kept). Rows with NaN/inf are never
    in the front.
    """
    F = np.asarray(F, dtype=float)
    if F.ndim != 2:
        raise GHTError(f"F has shape {F.shape}; expected (n_points, n_objectives)")
    finite = np.all(np.isfinite(F), axis=1)
    mask = np.zeros(F.shape[0], dtype=bool)
    G = F[finite]
    if G.shape[0] == 0:
        return mask
    le = np.all(G[:, None, :] <= G[None, :, :], axis=2)   # le[j, i]: F_j <= F_i
    lt = np.any(G[:, None, :] < G[None, :, :], axis=2)
    dominated = np.any(le & lt, axis=0)
    mask[np.nonzero(finite)[0]] = ~dominated
    return mask


def crowding_distance(F: Any) -> np.ndarray:
    """NSGA-II crowding distance of each row of ``F`` (extremes of every objective get inf)."""
    F = np.asarray(F, dtype=float)
    n, k = F.shape
    d = np.zeros(n)
    if n <= 2:
        return np.full(n, np.inf)
    for j in range(k):
        order = np.argsort(F[:, j], kind="stable")
        span = F[order[-1], j] - F[order[0], j]
        d[order[0]] = d[order[-1]] = np.inf
        if span > 0:
            d[order[1:-1]] += (F[order[2:], j] - F[order[:-2], j]) / span
    return d


def simplex_weights(n_obj: int, divisions: int) -> np.ndarray:
    """All weight vectors ``(i_1, ..., i_k) / divisions`` with non-negative integers summing to
    ``divisions`` (a simplex lattice), shape (C(divisions + k - 1, k - 1), k)."""
    if n_obj < 1 or divisions < 1:
        raise GHTError(f"n_obj={n_obj}, divisions={divisions}: both must be >= 1")
    rows = [c for c in itertools.product(range(divisions + 1), repeat=n_obj) if sum(c) == divisions]
    return np.array(sorted(rows, reverse=True), dtype=float) / divisions


class ParetoArchive:
    """Non-dominated archive of (parameters, objective vectors).

    Args:
        n_obj: number of objectives.
        max_size: cap; beyond it the most crowded points are dropped (extremes kept). The
            archive is always mutually non-dominated; without pruning it is exactly the
            non-dominated set of every point offered. After pruning, a later point that only a
            dropped point dominated can enter (the usual price of a bounded archive).

    Attributes:
        x: archived parameters, shape (n, dim).
        f: their objective vectors, shape (n, n_obj).
    """

    def __init__(self, n_obj: int, max_size: int = 1000) -> None:
        if int(max_size) < 2:
            raise GHTError(f"max_size={max_size} is too small; use >= 2")
        self.n_obj = int(n_obj)
        self.max_size = int(max_size)
        self.x: np.ndarray | None = None
        self.f = np.empty((0, self.n_obj))
        self.seen = 0

    def __len__(self) -> int:
        return self.f.shape[0]

    def add(self, X: Any, F: Any) -> None:
        """Offer points ``X`` (n, dim) with objectives ``F`` (n, n_obj); keep the non-dominated.

        Incremental, O(archive size × batch size): the batch is filtered on its own, then new
        points dominated by (or equal to) an archived point are dropped, then archived points
        dominated by a new point are removed. Non-finite objective vectors are ignored.
        """
        X = np.atleast_2d(np.asarray(X, dtype=float))
        F = np.atleast_2d(np.asarray(F, dtype=float))
        if F.shape != (X.shape[0], self.n_obj):
            raise GHTError(f"F has shape {F.shape}; expected ({X.shape[0]}, {self.n_obj})")
        self.seen += X.shape[0]
        keep = nondominated(F)
        X, F = X[keep], F[keep]
        if F.shape[0]:
            _, first = np.unique(F, axis=0, return_index=True)
            first.sort()
            X, F = X[first], F[first]
        if self.x is None:
            self.x, self.f = X, F
        elif F.shape[0]:
            A = self.f
            le = np.all(A[:, None, :] <= F[None, :, :], axis=2)     # archived j <= new i
            lt = np.any(A[:, None, :] < F[None, :, :], axis=2)
            eq = np.all(A[:, None, :] == F[None, :, :], axis=2)
            new_ok = ~np.any((le & lt) | eq, axis=0)
            X, F = X[new_ok], F[new_ok]
            if F.shape[0]:
                le2 = np.all(F[:, None, :] <= A[None, :, :], axis=2)  # new i <= archived j
                lt2 = np.any(F[:, None, :] < A[None, :, :], axis=2)
                old_ok = ~np.any(le2 & lt2, axis=0)
                self.x = np.concatenate([self.x[old_ok], X])
                self.f = np.concatenate([A[old_ok], F])
        if self.f.shape[0] > self.max_size:
            self._prune()

    def _prune(self) -> None:
        """Drop the most crowded points, one at a time (extremes have infinite distance)."""
        x, f = self.x, self.f
        while f.shape[0] > self.max_size:
            excess = f.shape[0] - self.max_size
            cd = crowding_distance(f)
            # remove up to half the excess per pass, then recompute distances
            drop = np.argsort(cd, kind="stable")[: max(1, excess // 2)]
            keep = np.ones(f.shape[0], dtype=bool)
            keep[drop] = False
            x, f = x[keep], f[keep]
        self.x, self.f = x, f


@dataclass
class ParetoResult:
    """A Pareto front.

    Attributes:
        x: parameters of the front, shape (n, dim) (sorted by the first objective).
        f: objective vectors, shape (n, n_obj).
        names: objective names.
        parameter_names: names of the free parameters.
        weights: the weight vectors of the sweep.
        reference: objective values at the base design (the scales of the weighted sums).
        runs: the single-objective results, one per weight vector.
        nfev: total evaluations.
    """

    x: np.ndarray
    f: np.ndarray
    names: tuple[str, ...]
    parameter_names: tuple[str, ...]
    weights: np.ndarray
    reference: np.ndarray
    runs: list[OptimizeResult] = field(default_factory=list)
    nfev: int = 0

    def table(self) -> str:
        """Markdown table of the front."""
        head = "| " + " | ".join(self.parameter_names + self.names) + " |"
        sep = "|" + "---|" * (len(self.parameter_names) + len(self.names))
        rows = [
            "| " + " | ".join(f"{v:.4f}" for v in xi) + " | " + " | ".join(f"{v:.6g}" for v in fi) + " |"
            for xi, fi in zip(self.x, self.f)
        ]
        return "\n".join([head, sep] + rows)


def pareto_front(
    problem: Any,
    method: str = "igwo",
    *,
    divisions: int = 4,
    pop_size: int = 20,
    max_iter: int = 50,
    seed: Any = 0,
    max_size: int = 1000,
    callback: Callable[[Any], Any] | None = None,
    **options: Any,
) -> ParetoResult:
    r"""Pareto front of ``problem.measures`` (AL, En, CVEn) by a weighted-sum sweep with an archive.

    For each lattice weight ``w`` (:func:`simplex_weights`), minimize
    ``Σ_k w_k F_k(x) / F_k(x_ref)`` with ``method``; all evaluated points feed a
    :class:`ParetoArchive` (see the module docstring).

    Args:
        problem: a fairness problem (has ``measures(X) -> (pop, 3)``, ``bounds``, ``x0``, ``names``);
            with an ``admissible(X) -> bool mask`` method (e.g. a dual-curve problem with boundary
            planes) rows whose surface cannot be built get ``+inf`` and never enter the front.
        method: optimizer name for :func:`~ght_cad.optimize.minimize`.
        divisions: lattice divisions (3 objectives: 4 -> 15 runs).
        pop_size, max_iter: per run.
        seed: int or Generator; each run gets its own child stream.
        max_size: archive cap.
        callback: passed to every run (returning True stops that run).
        **options: more optimizer options.

    Returns:
        ParetoResult.

    Raises:
        GHTError: a problem without ``measures``, or a reference value that is zero/non-finite.
    """
    if not hasattr(problem, "measures"):
        raise GHTError(f"{type(problem).__name__} has no measures(X); a Pareto front needs a multi-objective problem")
    names = tuple(getattr(problem, "measure_names", ("AL", "En", "CVEn")))
    x_ref = np.asarray(problem.x0, dtype=float)
    ref = np.asarray(problem.measures(x_ref[None])[0], dtype=float)
    if not (np.all(np.isfinite(ref)) and np.all(ref > 0)):
        raise GHTError(f"measures at the base design are {ref.tolist()}; they must be finite and > 0 to scale the weights")
    check = getattr(problem, "admissible", None)
    W = simplex_weights(len(ref), divisions)
    archive = ParetoArchive(len(ref), max_size)
    archive.add(x_ref[None], ref[None])
    rng = as_generator(seed)
    children = rng.integers(0, 2**63 - 1, size=W.shape[0])
    runs = []
    nfev = 1
    for w, child in zip(W, children):
        def f(X: np.ndarray, w: np.ndarray = w) -> np.ndarray:
            M = np.asarray(problem.measures(X), dtype=float)
            if check is not None:  # designs whose surface cannot be built never enter the front
                M = np.where(check(X)[:, None], M, np.inf)
            archive.add(X, M)
            with np.errstate(invalid="ignore"):  # inf * weight 0 -> NaN, counted as +inf
                v = (M / ref) @ w
            return np.where(np.all(np.isfinite(M), axis=1), v, np.inf)

        r = minimize(f, problem.bounds, method, pop_size=pop_size, max_iter=max_iter, seed=int(child),
                     callback=callback, **options)
        runs.append(r)
        nfev += r.nfev
    order = np.argsort(archive.f[:, 0], kind="stable")
    return ParetoResult(
        x=archive.x[order], f=archive.f[order], names=names, parameter_names=tuple(problem.names),
        weights=W, reference=ref, runs=runs, nfev=nfev,
    )
