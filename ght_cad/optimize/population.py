"""Population optimizers on a box (spec section 8): PSO, GWO, I-GWO and the scipy DE baseline.

Moved from :mod:`ght_cad.optimize.optimizers` (issue 27; every name stays importable from there);
the stopping rules and evaluation counts are stated in that module's docstring.
"""

from __future__ import annotations

import inspect
import itertools
import math
from typing import Any, Iterator, TYPE_CHECKING

import numpy as np

from ..core.errors import GHTError
from .base import _common_interface, _float_option, _Options, _Run, _Stop, Objective, OptimizeResult

if TYPE_CHECKING:
    from typing import Unpack


@_common_interface()
def pso(
    fun: Objective,
    bounds: Any,
    *,
    w_start: float = 0.9,
    w_end: float = 0.4,
    c1: float = 2.0,
    c2: float = 2.0,
    v_max: float = 0.2,
    **options: Unpack[_Options],
) -> OptimizeResult:
    """Particle swarm optimization (spec section 8).

    ``v ← w v + c1 r1 ∘ (pbest - x) + c2 r2 ∘ (gbest - x)``, ``|v| ≤ v_max (ub - lb)``
    componentwise, ``x ← clip(x + v, lb, ub)``; inertia ``w`` decreases linearly from
    ``w_start`` (0.9) at the first iteration to ``w_end`` (0.4) at the last; ``r1, r2 ~ U(0,1)``
    per component. Initial velocities are uniform in ``[-v_max (ub-lb), v_max (ub-lb)]``.
    """
    run = _Run("pso", fun, bounds, per_agent=1, **options)
    rng, lb, ub = run.rng, run.lb, run.ub
    w_start, w_end = _float_option("w_start", w_start), _float_option("w_end", w_end)
    c1, c2 = _float_option("c1", c1), _float_option("c2", c2)
    vmax = _float_option("v_max", v_max, positive=True) * (ub - lb)

    def steps() -> Iterator[None]:
        x = run.initial_population()
        v = rng.uniform(-1.0, 1.0, x.shape) * vmax
        fx = run.evaluate(x)
        pbest, pf = x.copy(), fx.copy()
        g = int(np.argmin(pf))
        yield
        T = max(run.max_iter - 1, 1)
        for it in itertools.count():
            w = w_start - (w_start - w_end) * it / T
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
            yield

    return run.drive(steps())


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


@_common_interface()
def gwo(fun: Objective, bounds: Any, **options: Unpack[_Options]) -> OptimizeResult:
    """Grey wolf optimizer (spec section 8).

    Leaders α, β, δ are the three best positions found so far; ``a = 2 - 2 it / max_iter``; for
    each leader ``A = 2a r1 - a``, ``C = 2 r2``, ``D = |C X_L - X|``, ``X_L* = X_L - A D``; every
    wolf moves to ``X_GWO = (X_α* + X_β* + X_δ*) / 3``, clipped to the box.
    """
    run = _Run("gwo", fun, bounds, per_agent=1, **options)
    rng, lb, ub = run.rng, run.lb, run.ub

    def steps() -> Iterator[None]:
        X = run.initial_population()
        fX = run.evaluate(X)
        order = np.argsort(fX, kind="stable")[:3]
        lead_x, lead_f = X[order].copy(), fX[order].copy()
        yield
        T = max(run.max_iter, 1)
        for it in itertools.count():
            a = 2.0 - 2.0 * it / T
            X = np.clip(_gwo_candidates(X, lead_x, a, rng), lb, ub)
            fX = run.evaluate(X)
            allf = np.concatenate([lead_f, fX])
            allx = np.concatenate([lead_x, X])
            order = np.argsort(allf, kind="stable")[:3]
            lead_x, lead_f = allx[order].copy(), allf[order].copy()
            yield

    return run.drive(steps())


def _midpoint_bounds(Y: np.ndarray, X_old: np.ndarray, lb: np.ndarray, ub: np.ndarray) -> np.ndarray:
    """Out-of-bound components go to the midpoint between the old position and the violated bound."""
    Y = np.where(Y < lb, 0.5 * (X_old + lb), Y)
    return np.where(Y > ub, 0.5 * (X_old + ub), Y)


@_common_interface()
def igwo(fun: Objective, bounds: Any, **options: Unpack[_Options]) -> OptimizeResult:
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
    run = _Run("igwo", fun, bounds, per_agent=2, **options)
    rng, lb, ub = run.rng, run.lb, run.ub
    N, D = run.pop, run.dim

    def steps() -> Iterator[None]:
        X = run.initial_population()
        fX = run.evaluate(X)
        yield
        T = max(run.max_iter, 1)
        rows = np.arange(N)[:, None]
        for it in itertools.count():
            a = 2.0 - 2.0 * it / T
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
            yield

    return run.drive(steps())


@_common_interface()
def differential_evolution(
    fun: Objective,
    bounds: Any,
    *,
    strategy: str = "best1bin",
    mutation: float | tuple[float, float] = (0.5, 1.0),
    recombination: float = 0.7,
    polish: bool = False,
    **options: Unpack[_Options],
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

    run = _Run("de", fun, bounds, per_agent=1, min_pop=5, **options)
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
