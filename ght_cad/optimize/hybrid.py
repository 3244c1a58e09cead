"""The hybrid optimizer: Sobol' or population starts finished by L-BFGS-B (spec section 8), and
:data:`METHODS`, the optimizers by name.

Moved from :mod:`ght_cad.optimize.optimizers` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from typing import Any, Callable, TYPE_CHECKING

import numpy as np

from ..core.errors import GHTError
from .base import (_COMMON_ARGS, _common_interface, _FinishDone, _int_option, _Options, _Run, _Stop, DEFAULT_MAX_ITER,
                   Objective, OptimizeResult, OptimizerState)
from .population import differential_evolution, gwo, igwo, pso

if TYPE_CHECKING:
    from typing import Unpack


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


@_common_interface(pop_size=32, args_doc=_COMMON_ARGS.replace(
    "pop_size: number of agents (>= 4).",
    "pop_size: Sobol' starts, or PSO/I-GWO agents (>= 4; default 32).").replace(
    "max_iter: iteration budget (default 200 if ``max_nfev`` is not given either).",
    "max_iter: L-BFGS-B iterations over all finishes (default 200 if ``max_nfev`` is not given either)."))
def hybrid(
    fun: Objective,
    bounds: Any,
    *,
    starts: str = "sobol",
    global_iter: int = 10,
    local_starts: int = 4,
    jac: Any = None,
    **options: Unpack[_Options],
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

    max_iter, max_nfev, tol = options["max_iter"], options["max_nfev"], options["tol"]
    run = _Run("hybrid", fun, bounds, per_agent=1, **{**options, "max_iter": None})
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


#: Optimizers by name, for :func:`minimize`, the bench and the comparison table.
METHODS: dict[str, Callable[..., OptimizeResult]] = {
    "hybrid": hybrid,
    "pso": pso,
    "gwo": gwo,
    "igwo": igwo,
    "de": differential_evolution,
}
