r"""Shape-parameter optimization of a design's surface (spec sections 7, 8) through :mod:`ght_cad.optimize`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from ..errors import GHTError
from .build import _initial_shape, _joined_curves, _make_composite, _make_surface, build_curves, make_loft
from .objectives import _gauss_legendre, composite_dual_objectives, composite_dual_objectives_grad, dual_curve_objectives
from .schema import (METHODS, SHAPE_NAMES, Design, DesignError, OptimizeSpec, _Checker, _composite_parameters,
                     _objectives_for, _shape_names, default_objective)


@dataclass
class OptimizationOutcome:
    """Result of :func:`optimize_design`."""

    method: str
    objective: str
    parameters: list[str]
    x: np.ndarray
    best_value: float
    initial_value: float
    history: np.ndarray
    nfev: int
    nit: int
    time: float
    shape: dict[str, float]
    weights: list[float]
    #: composite only: per strip ``name``, ``initial``/``best`` measures (AL, En, CVEn, value)
    strips: list[dict[str, Any]] | None = None
    #: composite only: per joint ``first``, ``second``, ``requested``, ``achieved_G`` (after), ``satisfied``
    joints: list[dict[str, Any]] | None = None
    #: exact gradients evaluated (one per point; 0 with finite differences or a population method)
    njev: int = 0

    def summary(self) -> dict[str, Any]:
        """Plain-data form for the report (``optimization`` block); composites add ``strips``
        (before/after per strip) and ``joints`` (requested vs measured order after optimization)."""
        extra: dict[str, Any] = {}
        if self.strips is not None:
            extra["strips"] = [dict(x) for x in self.strips]
        if self.joints is not None:
            extra["joints"] = [dict(x) for x in self.joints]
        return {**{
            "method": self.method,
            "objective": self.objective,
            "weights": list(self.weights) if self.objective == "weighted" else None,
            "parameters": list(self.parameters),
            "best_parameters": {k: float(v) for k, v in zip(self.parameters, self.x)},
            "best_value": float(self.best_value),
            "initial_value": float(self.initial_value),
            "nfev": int(self.nfev),
            "iterations": int(self.nit),
            "time_s": float(self.time),
            "history": [float(h) for h in self.history],
        }, **extra}


def _composite_joint_rows(design: Design, composite: Any) -> list[dict[str, Any]]:
    """Requested vs measured order (:func:`ght_cad.developable.measure_developable_joint`) per joint."""
    segs = design.surface.segments if design.surface is not None else None
    assert segs
    rows = []
    for i, (g, rep) in enumerate(zip(segs[1:], composite.joints())):
        req = g.continuity or "G1"
        rows.append({"first": segs[i].name, "second": g.name, "requested": req, "achieved_G": int(rep.order),
                     "satisfied": bool(rep.satisfies(req))})
    return rows


def _composite_candidate(design: Design, shape: dict[str, float]) -> Any:
    """The composite of ``shape`` (:func:`_make_composite`, every strip checked on construction),
    refused unless every joint measures at least its requested order.

    Raises:
        GHTError: a singular join, a degenerate strip, or a joint below its requested order.
    """
    from ..errors import SingularJoinError

    comp = _make_composite(design, shape)
    for row in _composite_joint_rows(design, comp):
        if not row["satisfied"]:
            raise SingularJoinError(f"joint {row['first']} -> {row['second']} measures G{row['achieved_G']}, "
                                    f"requested {row['requested']}")
    return comp


def composite_objective(design: Design, shape: dict[str, float], objective: str = "CVEn",
                        weights: Sequence[float] = (1.0, 0.0, 0.0)) -> float:
    r"""Objective of one candidate of a composite design: ``F`` of :func:`composite_dual_objectives`.

    The strips are built exactly as for the geometry (strip 0 from its planes, strip i > 0 joined
    G1/G2/G3 to strip i-1, every strip checked on construction) and every joint is measured
    (:func:`ght_cad.developable.measure_developable_joint`).

    Args:
        design: a validated design with a ``composite`` surface.
        shape: ``{"<segment>.mu|nu|gamma": value}``; missing names keep the file's values.
        objective: ``AL``, ``En``, ``CVEn`` or ``weighted``.
        weights: ``(w0, w1, w2)`` for ``weighted``.

    Returns:
        ``F``, or ``+inf`` for a candidate whose join is singular, whose strip degenerates (parallel
        planes, stationary dual curve, edge of regression inside, ...) or whose joint measures
        below its requested order.

    Raises:
        DesignError: the design's surface is not a composite.
    """
    if design.surface is None or design.surface.type != "composite":
        raise DesignError(f"{design.source}: key 'surface.type': composite_objective needs type = \"composite\"")
    sh = dict(_initial_shape(design, {}))
    sh.update(shape)
    try:
        with np.errstate(all="ignore"):
            value = composite_dual_objectives(_composite_candidate(design, sh), objective, weights)[0]
    except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
        return math.inf
    return value if math.isfinite(value) else math.inf


def _objective_fn(design: Design, curves: dict[str, Any], spec: OptimizeSpec) -> Callable[[dict[str, float]], float]:
    surf = design.surface
    assert surf is not None
    if surf.type == "composite":
        def fc(sh: dict[str, float]) -> float:
            return composite_objective(design, sh, spec.objective, spec.weights)

        return fc
    if surf.type == "planes":
        from ..curve import GHTCurve
        from ..planes import normalize_planes

        U = normalize_planes(np.asarray(surf.planes, dtype=float))
        w = np.asarray(spec.weights, dtype=float)

        def f(sh: dict[str, float]) -> float:
            # the surface is built (and checked) first: a candidate whose strip degenerates (stationary
            # dual curve at a box corner, edge of regression inside, ...) raises and gets +inf in F
            _make_surface(design, curves, sh)
            vals = dual_curve_objectives(GHTCurve(U, sh["mu"], sh["nu"], sh["gamma"]))
            if spec.objective == "weighted":
                return float(w[0] * vals["AL"] + w[1] * vals["En"] + w[2] * vals["CVEn"])
            return vals[spec.objective]

        return f
    rejoin = bool({str(surf.curve_a), str(surf.curve_b)} & {j.second for j in design.joins})
    if surf.type == "rails":
        return _rails_objective_fn(design, curves, spec, rejoin)
    from ..ruled import developability_from_jets

    t, wq = _gauss_legendre(64)

    def g(sh: dict[str, float]) -> float:
        # a boundary curve that is a join's 'second' is re-solved for the candidate's shape
        # parameters (as build_curves(design, shape) does for the result)
        cv = _joined_curves(design, sh, measure=False)[0] if rejoin else curves
        s = _make_surface(design, cv, sh)
        return developability_from_jets(s.a(t), s.a(t, 1), s.b(t), s.b(t, 1), wq)[3]  # (θ_max, θ_rms, DD, R)

    return g


def composite_value_and_grad(design: Design, shape: dict[str, float], names: Sequence[str],
                             objective: str = "CVEn", weights: Sequence[float] = (1.0, 0.0, 0.0)
                             ) -> tuple[float, np.ndarray]:
    r""":func:`composite_objective` and its exact gradient with respect to the shape parameters
    ``names`` (``"<segment>.mu|nu|gamma"``), the joins differentiated as re-solved for every
    candidate (:func:`ght_cad.design.objectives.composite_dual_objectives_grad`, spec 8.1).

    Returns:
        ``(F, ∂F/∂names)``; ``(+inf, 0)`` for a candidate that :func:`composite_objective` rejects.
    """
    segs = design.surface.segments if design.surface is not None else None
    if not segs or design.surface is None or design.surface.type != "composite":
        raise DesignError(f"{design.source}: key 'surface.type': composite_value_and_grad needs type = \"composite\"")
    sh = dict(_initial_shape(design, {}))
    sh.update(shape)
    idx = {f"{g.name}.{k}": (s, j) for s, g in enumerate(segs) for j, k in enumerate(SHAPE_NAMES)}
    zero = np.zeros(len(names))
    try:
        with np.errstate(all="ignore"):
            comp = _composite_candidate(design, sh)
            value = composite_dual_objectives(comp, objective, weights)[0]
            joins = [(g.continuity or "G1", g.k, g.beta2, g.beta3) for g in segs[1:]]
            _, dF = composite_dual_objectives_grad(comp, joins, objective, weights)
    except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
        return math.inf, zero
    g = np.array([dF[idx[n]] for n in names], dtype=float)
    if not (math.isfinite(value) and np.all(np.isfinite(g))):
        return math.inf, zero
    return float(value), g


def _value_and_grad_fn(design: Design, curves: dict[str, Any], spec: OptimizeSpec, names: Sequence[str],
                       shape_of: Callable[[np.ndarray], dict[str, float]]
                       ) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
    """Population ``value_and_grad(X) -> ((pop,), (pop, dim))`` of the design objective where it is
    exact (composite; rails through :class:`ght_cad.loft.LoftProblem`), else None."""
    surf = design.surface
    assert surf is not None
    if surf.type == "rails":
        return _rails_value_and_grad_fn(design, curves, spec, names, shape_of)
    if surf.type != "composite":
        return None

    def vg(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        X = np.atleast_2d(np.asarray(X, dtype=float))
        f = np.empty(X.shape[0])
        G = np.zeros(X.shape)
        for i, x in enumerate(X):
            f[i], G[i] = composite_value_and_grad(design, shape_of(x), names, spec.objective, spec.weights)
        return f, G

    return vg


def _rails_value_and_grad_fn(design: Design, curves: dict[str, Any], spec: OptimizeSpec, names: Sequence[str],
                             shape_of: Callable[[np.ndarray], dict[str, float]]
                             ) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
    r"""``value_and_grad`` of a ``rails`` objective (:func:`_rails_objective_fn`): the same loft and
    measures, and the exact gradient :meth:`ght_cad.loft.LoftProblem.gradient_of` (implicit-function
    derivative of the traced branch, moving breakpoints). Where the loft's structure is not
    locally fixed (:class:`ght_cad.loft.LoftGradientFallback`) forward differences of step 1e-7
    inwards, their evaluations counted in ``vg.extra_nfev``. None when a rail is re-solved by a
    join for every candidate (the join is not differentiated here: finite differences).
    """
    from ..loft import LOFT_OBJECTIVES, LoftGradientFallback, LoftProblem

    surf = design.surface
    assert surf is not None
    if {str(surf.curve_a), str(surf.curve_b)} & {j.second for j in design.joins}:
        return None
    if spec.objective == "weighted":
        weights = {k: float(w) for k, w in zip(LOFT_OBJECTIVES, spec.weights) if w > 0}
    else:
        weights = {spec.objective: 1.0}
    problem = LoftProblem(curves[surf.curve_a], curves[surf.curve_b], weights)
    h = _rails_objective_fn(design, curves, spec, False)
    all6 = [f"{r}.{k}" for r in ("a", "b") for k in SHAPE_NAMES]
    idx = [all6.index(n) for n in names]

    def one(x: np.ndarray) -> tuple[float, np.ndarray]:
        sh = shape_of(x)
        try:
            with np.errstate(all="ignore"):
                ca = curves[surf.curve_a].with_shape(sh["a.mu"], sh["a.nu"], sh["a.gamma"])
                cb = curves[surf.curve_b].with_shape(sh["b.mu"], sh["b.nu"], sh["b.gamma"])
                lf = make_loft(surf, ca, cb, samples=CANDIDATE_LOFT_SAMPLES)
                m = problem.measures_of(lf)
                value = float(sum(w * m[k] for k, w in weights.items()))
        except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
            return math.inf, np.zeros(len(names))
        if not math.isfinite(value):
            return math.inf, np.zeros(len(names))
        try:
            with np.errstate(all="ignore"):
                return value, problem.gradient_of(lf, ca, cb)[idx]
        except (LoftGradientFallback, GHTError) as exc:
            vg.fallbacks.append(str(exc))  # type: ignore[attr-defined]
        g = np.zeros(len(names))
        for j in range(len(names)):
            step = 1e-7 if x[j] + 1e-7 <= 1.0 else -1e-7
            y = np.array(x, dtype=float)
            y[j] += step
            try:
                with np.errstate(all="ignore"):
                    fj = h(shape_of(y))
            except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
                fj = math.inf
            vg.extra_nfev += 1  # type: ignore[attr-defined]
            g[j] = (fj - value) / step if math.isfinite(fj) else 0.0
        return value, g

    def vg(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        X = np.atleast_2d(np.asarray(X, dtype=float))
        f = np.empty(X.shape[0])
        G = np.zeros(X.shape)
        for i, x in enumerate(X):
            f[i], G[i] = one(x)
        return f, G

    vg.extra_nfev = 0  # type: ignore[attr-defined]
    vg.fallbacks = []  # type: ignore[attr-defined]
    return vg


#: rulings sampled per loft segment for the report of an optimizer candidate (the result is rebuilt
#: with the default)
CANDIDATE_LOFT_SAMPLES = 33


def _rails_objective_fn(design: Design, curves: dict[str, Any], spec: OptimizeSpec,
                        rejoin: bool) -> Callable[[dict[str, float]], float]:
    r"""Objective of a ``rails`` surface over the rails' shape parameters: the developable loft of
    the candidate rails (:func:`ght_cad.developable_loft`) measured by
    :meth:`ght_cad.loft.LoftProblem.measures_of`: ``fan_share`` = fan area / loft area,
    ``fairness`` = ``∫_0^1 |d'(λ)|² dλ`` (d the unit ruling direction), ``regression`` =
    ``∫ max(0, 1 - c/margin)² dλ`` (c the distance of the edge-of-regression parameter ``v*`` from
    [0, 1]), or ``weighted`` = ``w0 fan_share + w1 fairness + w2 regression``. A candidate without a
    loft raises (``+inf`` in :func:`optimize_design`)."""
    from ..loft import LOFT_OBJECTIVES, LoftProblem

    surf = design.surface
    assert surf is not None
    if spec.objective == "weighted":
        weights = {k: float(w) for k, w in zip(LOFT_OBJECTIVES, spec.weights) if w > 0}
    else:
        weights = {spec.objective: 1.0}
    problem = LoftProblem(curves[surf.curve_a], curves[surf.curve_b], weights)

    def h(sh: dict[str, float]) -> float:
        cv = _joined_curves(design, sh, measure=False)[0] if rejoin else curves
        ca = cv[surf.curve_a].with_shape(sh["a.mu"], sh["a.nu"], sh["a.gamma"])
        cb = cv[surf.curve_b].with_shape(sh["b.mu"], sh["b.nu"], sh["b.gamma"])
        m = problem.measures_of(make_loft(surf, ca, cb, samples=CANDIDATE_LOFT_SAMPLES))
        return float(sum(w * m[k] for k, w in weights.items()))

    return h


def optimize_design(design: Design, overrides: dict[str, Any] | None = None, *, progress: bool = True,
                    curves: dict[str, Any] | None = None, exact_gradients: bool = True) -> OptimizationOutcome:
    r"""Minimize the design's objective over its shape parameters (box ``[-1, 1]^k``).

    Objectives: for a ``planes`` surface the fairness of the dual curve of unit-normal control
    planes (``AL = ∫|U'|``, ``En = ∫|U''|²``, ``CVEn = ∫|U'''|²`` or ``w·(AL, En, CVEn)``); for a
    ``composite`` the sum over strips of the same measure of each strip's dual curve as built
    (after the joins, :func:`composite_dual_objectives`), every joint keeping its requested
    G1/G2/G3 order; for a ``curves`` strip the developability objective
    ``R = ∫(1 - n_a·n_b) du`` (spec 5, 7); for a ``rails`` surface the loft objectives fan share,
    ruling-field fairness ``∫|d'|²`` or edge-of-regression distance (:func:`_rails_objective_fn`)
    over the two rails' shape parameters. Optimizers: PSO, GWO, I-GWO of
    :mod:`ght_cad.optimize` (spec 8). The start values (those of the file) are in the first
    population and the result is never worse than them; candidates whose surface degenerates
    (singular join, edge of regression inside a strip, ...) get ``+inf``.

    Args:
        design: validated design with a [surface] table.
        overrides: replaces ``method``, ``objective``, ``iterations``, ``population``, ``seed``.
        progress: progress bar on a terminal.
        curves: already built curves (joins applied).
        exact_gradients: give the optimizer the exact gradient where one exists (composites:
            :func:`composite_value_and_grad`; rails: :meth:`ght_cad.loft.LoftProblem.value_and_grad`);
            ``False`` leaves the objective a plain callable (``hybrid`` then uses finite differences).

    Returns:
        :class:`OptimizationOutcome` (for a composite with ``strips``: the measures of every strip
        before and after, and ``joints``: requested vs measured order after optimization).

    Raises:
        DesignError: no [surface], or an override that is not allowed.
        GHTError: no admissible shape parameters found.
    """
    from ..optimize import minimize
    from ..progress import Progress

    if design.surface is None:
        if design.surfaces:
            raise DesignError(f"{design.source}: key 'surfaces': optimization works on one surface and the design "
                              f"has {len(design.surfaces)} [[surfaces]]; allowed: a design with one surface")
        raise DesignError(f"{design.source}: key 'surface': missing; optimization needs a [surface] table")
    stype = design.surface.type
    spec = design.optimize or OptimizeSpec(
        objective=default_objective(stype),
        parameters=list(_shape_names(design.surface)),
    )
    spec = OptimizeSpec(**{**spec.__dict__})
    for k, v in (overrides or {}).items():
        setattr(spec, k, v)
    # validate overrides with the same rules as the file
    ck = _Checker(design.source + " (command-line override)")
    objs = _objectives_for(stype)
    spec.method = ck.string({"method": spec.method}, "method", "optimize", choices=METHODS)
    spec.objective = ck.string({"objective": spec.objective}, "objective", "optimize", choices=objs)
    spec.iterations = ck.integer({"iterations": spec.iterations}, "iterations", "optimize", 40, lo=1, hi=5000)
    spec.population = ck.integer({"population": spec.population}, "population", "optimize", 20, lo=4, hi=500)
    spec.seed = ck.integer({"seed": spec.seed}, "seed", "optimize", 1, lo=0, hi=2**32 - 1)
    if stype == "composite":
        spec.parameters = _composite_parameters(ck, {"parameters": list(spec.parameters)}, design.surface)
    if curves is None:
        curves, _ = build_curves(design)
    base = _initial_shape(design, curves)
    f = _objective_fn(design, curves, spec)
    names = list(spec.parameters)

    def shape_of(x: np.ndarray) -> dict[str, float]:
        sh = dict(base)
        sh.update({k: float(np.clip(v, -1.0, 1.0)) for k, v in zip(names, x)})
        return sh

    def F(X: np.ndarray) -> np.ndarray:
        # one candidate at a time: each builds (and checks) its own strips and joins
        out = np.empty(X.shape[0])
        for i, x in enumerate(X):
            try:
                with np.errstate(all="ignore"):
                    out[i] = f(shape_of(x))
            except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
                out[i] = np.inf  # a degenerate candidate (singular join, edge of regression, ...) is rejected
            if not np.isfinite(out[i]):
                out[i] = np.inf
        return out

    vg = _value_and_grad_fn(design, curves, spec, names, shape_of) if exact_gradients else None
    if vg is not None:
        F.value_and_grad = vg  # type: ignore[attr-defined]
    x0 = np.array([base[k] for k in names])
    initial = float(F(x0[None, :])[0])
    bounds = (-np.ones(len(names)), np.ones(len(names)))
    with Progress(spec.iterations, f"optimizing ({spec.method}, {spec.objective})",
                  enabled=None if progress else False) as bar:
        res = minimize(F, bounds, method=spec.method, pop_size=spec.population, max_iter=spec.iterations,
                       seed=spec.seed, callback=bar.callback, x0=x0)
    if not np.isfinite(res.fun):
        raise GHTError(f"{design.source}: optimization found no admissible shape parameters")
    x = np.clip(np.asarray(res.x, dtype=float), -1.0, 1.0)
    best = float(res.fun)
    if initial <= best:  # never report something worse than the start
        x, best = x0, initial
    out = OptimizationOutcome(spec.method, spec.objective, names, x, best, initial, np.asarray(res.history),
                              int(res.nfev), int(res.nit), float(res.time), shape_of(x), list(spec.weights))
    out.njev = int(getattr(res, "njev", 0) or 0)
    out.nfev += int(getattr(vg, "extra_nfev", 0))  # finite-difference fallbacks of an exact gradient
    if stype == "composite":
        out.strips, out.joints = _composite_before_after(design, spec, base, out.shape)
    return out


def _composite_before_after(design: Design, spec: OptimizeSpec, before: dict[str, float],
                            after: dict[str, float]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Per strip the measures before/after optimization; per joint requested vs measured order after."""
    segs = design.surface.segments if design.surface is not None else None
    assert segs
    try:
        _, per0 = composite_dual_objectives(_make_composite(design, before), spec.objective, spec.weights)
    except GHTError:
        per0 = [None] * len(segs)
    comp = _make_composite(design, after)
    _, per1 = composite_dual_objectives(comp, spec.objective, spec.weights)
    strips = []
    for g, a, b in zip(segs, per0, per1):
        strips.append({
            "name": g.name,
            "initial_parameters": {k: float(before[f"{g.name}.{k}"]) for k in SHAPE_NAMES},
            "best_parameters": {k: float(after[f"{g.name}.{k}"]) for k in SHAPE_NAMES},
            "initial_value": None if a is None else a["value"],
            "best_value": b["value"],
            "initial_measures": None if a is None else {k: a[k] for k in ("AL", "En", "CVEn")},
            "best_measures": {k: b[k] for k in ("AL", "En", "CVEn")},
        })
    return strips, _composite_joint_rows(design, comp)
