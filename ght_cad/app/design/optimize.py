r"""Shape-parameter optimization of a design's surface (spec sections 7, 8) through :mod:`ght_cad.optimize`.

**Sheet rule.** A design with a ``[sheet]`` of thickness ``T > 0`` is optimized over the shape
parameters the sheet can be made from: every candidate surface gets the check the run applies
to the built surface (:func:`ght_cad.app.design.build.check_sheet`: :func:`ght_cad.sheetmetal.sheet.check_offset`
on every part, 513 rulings, both ends of each), on the sheet of thickness ``(1 + SHEET_MARGIN) T``
(same K, same side), and a refused candidate gets ``+inf`` like a degenerate one. With
``T' = (1 + m) T`` the accepted candidates satisfy, at every checked ruling end,

    |K T| (1 + m) < |ρ_0|,    ρ_0 (ρ_0 + σ T (1 + m)) > 0,    no apex with the material on its concave side,

so a result on the boundary of the feasible set (a bending radius equal to ``|K T|``) is held
``m |K T|`` inside it, and the strict check of the build (``|K T| < |ρ_0|``) still passes when
the result is rebuilt the way the run builds it (a loft traced again, the curves rebuilt from the
optimized parameters: the same surface to round-off, about 1e-12 relative). The optimizer's result
is then built and checked exactly as the run will build and check it (:func:`_run_surface`,
:func:`check_sheet` with the sheet itself); if that check refused it, the next best accepted
candidates are tried (``final_check_fallbacks`` of the report), so the returned shape parameters
always pass the final check.
"""

from __future__ import annotations

import heapq
import itertools
import math
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from ...core.errors import GHTError
from .build import (_initial_shape, _joined_curves, _make_composite, _make_surface, build_curves, build_surface, check_sheet,
                    make_loft)
from .objectives import _gauss_legendre, composite_dual_objectives, composite_dual_objectives_grad, dual_curve_objectives
from .schema import (METHODS, SHAPE_NAMES, Design, DesignError, OptimizeSpec, _Checker, _composite_parameters,
                     _objectives_for, _shape_names, default_objective)


#: ``accept(surface, shape)``: called with every candidate surface before it is measured; raising a
#: GHTError rejects the candidate (``+inf``). The optimizer passes its sheet rule (:class:`_SheetGuard`).
Acceptor = Callable[[Any, dict[str, float]], Any]


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
    #: ``[sheet]`` with T > 0 only: the sheet rule's record (:func:`_sheet_summary`): the sheet,
    #: candidates checked and refused (per rule), the start's check, the result's smallest bending
    #: radius against ``|K T|``
    sheet: dict[str, Any] | None = None

    def summary(self) -> dict[str, Any]:
        """Plain-data form for the report (``optimization`` block); composites add ``strips``
        (before/after per strip) and ``joints`` (requested vs measured order after optimization)."""
        extra: dict[str, Any] = {}
        if self.strips is not None:
            extra["strips"] = [dict(x) for x in self.strips]
        if self.joints is not None:
            extra["joints"] = [dict(x) for x in self.joints]
        if self.sheet is not None:
            extra["sheet"] = dict(self.sheet)
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
    """Requested vs measured order (:func:`ght_cad.developables.envelope.measure_developable_joint`) per joint."""
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
    from ...core.errors import SingularJoinError

    comp = _make_composite(design, shape)
    for row in _composite_joint_rows(design, comp):
        if not row["satisfied"]:
            raise SingularJoinError(f"joint {row['first']} -> {row['second']} measures G{row['achieved_G']}, "
                                    f"requested {row['requested']}")
    return comp


def composite_objective(design: Design, shape: dict[str, float], objective: str = "CVEn",
                        weights: Sequence[float] = (1.0, 0.0, 0.0), *, accept: Acceptor | None = None) -> float:
    r"""Objective of one candidate of a composite design: ``F`` of :func:`composite_dual_objectives`.

    The strips are built exactly as for the geometry (strip 0 from its planes, strip i > 0 joined
    G1/G2/G3 to strip i-1, every strip checked on construction) and every joint is measured
    (:func:`ght_cad.developables.envelope.measure_developable_joint`).

    Args:
        design: a validated design with a ``composite`` surface.
        shape: ``{"<segment>.mu|nu|gamma": value}``; missing names keep the file's values.
        objective: ``AL``, ``En``, ``CVEn`` or ``weighted``.
        weights: ``(w0, w1, w2)`` for ``weighted``.
        accept: ``accept(composite, shape)`` called with the candidate before it is measured;
            raising a GHTError rejects it (the optimizer's sheet rule). None: no further check.

    Returns:
        ``F``, or ``+inf`` for a candidate whose join is singular, whose strip degenerates (parallel
        planes, stationary dual curve, edge of regression inside, ...), whose joint measures
        below its requested order or that ``accept`` refuses.

    Raises:
        DesignError: the design's surface is not a composite.
    """
    if design.surface is None or design.surface.type != "composite":
        raise DesignError(f"{design.source}: key 'surface.type': composite_objective needs type = \"composite\"")
    sh = dict(_initial_shape(design, {}))
    sh.update(shape)
    try:
        with np.errstate(all="ignore"):
            comp = _composite_candidate(design, sh)
            if accept is not None:
                accept(comp, sh)
            value = composite_dual_objectives(comp, objective, weights)[0]
    except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
        return math.inf
    return value if math.isfinite(value) else math.inf


def _objective_fn(design: Design, curves: dict[str, Any], spec: OptimizeSpec,
                  accept: Acceptor | None = None) -> Callable[[dict[str, float]], float]:
    """The design objective of one candidate ``shape -> value`` (raises for a degenerate one); with
    ``accept`` every candidate surface is passed to it before it is measured (the sheet rule)."""
    surf = design.surface
    assert surf is not None
    if surf.type == "composite":
        def fc(sh: dict[str, float]) -> float:
            return composite_objective(design, sh, spec.objective, spec.weights, accept=accept)

        return fc
    if surf.type == "planes":
        from ...curves.curve import GHTCurve
        from ...surfaces.planes import normalize_planes

        U = normalize_planes(np.asarray(surf.planes, dtype=float))
        w = np.asarray(spec.weights, dtype=float)

        def f(sh: dict[str, float]) -> float:
            # the surface is built (and checked) first: a candidate whose strip degenerates (stationary
            # dual curve at a box corner, edge of regression inside, ...) raises and gets +inf in F
            s = _make_surface(design, curves, sh)
            if accept is not None:
                accept(s, sh)
            vals = dual_curve_objectives(GHTCurve(U, sh["mu"], sh["nu"], sh["gamma"]))
            if spec.objective == "weighted":
                return float(w[0] * vals["AL"] + w[1] * vals["En"] + w[2] * vals["CVEn"])
            return vals[spec.objective]

        return f
    rejoin = bool({str(surf.curve_a), str(surf.curve_b)} & {j.second for j in design.joins})
    if surf.type == "rails":
        return _rails_objective_fn(design, curves, spec, rejoin, accept)
    from ...surfaces.ruled import developability_from_jets

    t, wq = _gauss_legendre(64)

    def g(sh: dict[str, float]) -> float:
        # a boundary curve that is a join's 'second' is re-solved for the candidate's shape
        # parameters (as build_curves(design, shape) does for the result)
        cv = _joined_curves(design, sh, measure=False)[0] if rejoin else curves
        s = _make_surface(design, cv, sh)
        if accept is not None:
            accept(s, sh)
        return developability_from_jets(s.a(t), s.a(t, 1), s.b(t), s.b(t, 1), wq)[3]  # (θ_max, θ_rms, DD, R)

    return g


def composite_value_and_grad(design: Design, shape: dict[str, float], names: Sequence[str],
                             objective: str = "CVEn", weights: Sequence[float] = (1.0, 0.0, 0.0), *,
                             accept: Acceptor | None = None) -> tuple[float, np.ndarray]:
    r""":func:`composite_objective` and its exact gradient with respect to the shape parameters
    ``names`` (``"<segment>.mu|nu|gamma"``), the joins differentiated as re-solved for every
    candidate (:func:`ght_cad.app.design.objectives.composite_dual_objectives_grad`, spec 8.1).

    Args:
        design, shape, objective, weights, accept: as in :func:`composite_objective`.
        names: the free shape parameters (the gradient's components, in this order).

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
            if accept is not None:
                accept(comp, sh)
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
                       shape_of: Callable[[np.ndarray], dict[str, float]], accept: Acceptor | None = None
                       ) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
    """Population ``value_and_grad(X) -> ((pop,), (pop, dim))`` of the design objective where it is
    exact (composite; rails through :class:`ght_cad.optimize.problems.loft.LoftProblem`), else None. With ``accept``
    (the sheet rule) a refused candidate gets ``(+inf, 0)``, as in the plain objective."""
    surf = design.surface
    assert surf is not None
    if surf.type == "rails":
        return _rails_value_and_grad_fn(design, curves, spec, names, shape_of, accept)
    if surf.type != "composite":
        return None

    def vg(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        X = np.atleast_2d(np.asarray(X, dtype=float))
        f = np.empty(X.shape[0])
        G = np.zeros(X.shape)
        for i, x in enumerate(X):
            f[i], G[i] = composite_value_and_grad(design, shape_of(x), names, spec.objective, spec.weights,
                                                  accept=accept)
        return f, G

    return vg


def _rails_value_and_grad_fn(design: Design, curves: dict[str, Any], spec: OptimizeSpec, names: Sequence[str],
                             shape_of: Callable[[np.ndarray], dict[str, float]], accept: Acceptor | None = None
                             ) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]] | None:
    r"""``value_and_grad`` of a ``rails`` objective (:func:`_rails_objective_fn`): the same loft and
    measures, and the exact gradient :meth:`ght_cad.optimize.problems.loft.LoftProblem.gradient_of` (implicit-function
    derivative of the traced branch, moving breakpoints). Where the loft's structure is not
    locally fixed (:class:`ght_cad.optimize.problems.loft.LoftGradientFallback`) forward differences of step 1e-7
    inwards, their evaluations counted in ``vg.extra_nfev``. None when a rail is re-solved by a
    join for every candidate (the join is not differentiated here: finite differences). ``accept``
    (the sheet rule) sees every candidate loft before it is measured; a refused one gets
    ``(+inf, 0)``. The forward-difference neighbours of a fallback are objective values only (no
    sheet check: they are gradient probes, not candidates).
    """
    from ...optimize.problems.loft import LOFT_OBJECTIVES, LoftGradientFallback, LoftProblem

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
                if accept is not None:
                    accept(lf, sh)
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
                        rejoin: bool, accept: Acceptor | None = None) -> Callable[[dict[str, float]], float]:
    r"""Objective of a ``rails`` surface over the rails' shape parameters: the developable loft of
    the candidate rails (:func:`ght_cad.developable_loft`) measured by
    :meth:`ght_cad.optimize.problems.loft.LoftProblem.measures_of`: ``fan_share`` = fan area / loft area,
    ``fairness`` = ``∫_0^1 |d'(λ)|² dλ`` (d the unit ruling direction), ``regression`` =
    ``∫ max(0, 1 - c/margin)² dλ`` (c the distance of the edge-of-regression parameter ``v*`` from
    [0, 1]), or ``weighted`` = ``w0 fan_share + w1 fairness + w2 regression``. A candidate without a
    loft, or one ``accept`` refuses (the sheet rule), raises (``+inf`` in :func:`optimize_design`)."""
    from ...optimize.problems.loft import LOFT_OBJECTIVES, LoftProblem

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
        lf = make_loft(surf, ca, cb, samples=CANDIDATE_LOFT_SAMPLES)
        if accept is not None:
            accept(lf, sh)
        m = problem.measures_of(lf)
        return float(sum(w * m[k] for k, w in weights.items()))

    return h

#: relative margin of the optimizer's sheet rule: candidates are checked on the sheet of thickness
#: ``(1 + SHEET_MARGIN) T`` (module doc), so an optimum on the boundary ``|ρ_0| = |K T|`` keeps
#: ``|ρ_0| >= (1 + 1e-6) |K T|``: far above the round-off between a candidate and the surface the
#: run rebuilds (about 1e-12 relative), far below any tolerance of a sheet part (1e-6 of a 1 mm
#: radius is a nanometre)
SHEET_MARGIN = 1e-6

#: accepted candidates kept (the best, by value) for the final check's fallbacks
_SHEET_KEEP = 16


class _SheetGuard:
    r"""The sheet rule of the optimizer's candidates (module doc) and its record.

    Called as ``guard(surface, shape)`` with every candidate surface: :func:`check_sheet` on the
    sheet of thickness ``(1 + SHEET_MARGIN) T``; a refusal is counted per rule and re-raised (the
    candidate gets ``+inf``); the refused candidate whose limiting radius came closest to its bound
    (``|ρ_0| / |K T|``, ``|ρ_0| / T`` for the material through a centre, 0 at an apex) is kept for
    the message when nothing passes. :meth:`keep` holds the best accepted candidates by value.
    """

    def __init__(self, design: Design, sheet: Any) -> None:
        from ...sheetmetal.sheet import Sheet

        self.design = design
        self.sheet = sheet
        self.strict = Sheet(sheet.thickness * (1.0 + SHEET_MARGIN), sheet.k_factor, sheet.side)
        self.checked = 0
        self.refused: dict[str, int] = {"radius": 0, "centre": 0, "apex": 0}
        #: (score, rule, radius, bound, shape) of the refused candidate closest to passing
        self.closest: tuple[float, str, float, float, dict[str, float]] | None = None
        self._kept: list[tuple[float, int, np.ndarray]] = []  # max-heap on value (negated), at most _SHEET_KEEP
        self._tie = itertools.count()

    def __call__(self, surface: Any, shape: dict[str, float]) -> float:
        from ...sheetmetal.sheet import SheetError

        self.checked += 1
        try:
            return check_sheet(self.design, surface, sheet=self.strict)
        except SheetError as exc:
            rule = exc.constraint or "radius"
            self.refused[rule] = self.refused.get(rule, 0) + 1
            radius = float(exc.radius or 0.0)
            bound = {"radius": abs(self.sheet.neutral_offset), "centre": self.sheet.thickness}.get(rule, 0.0)
            score = radius / bound if bound > 0 else 0.0
            if self.closest is None or score > self.closest[0]:
                self.closest = (score, rule, radius, bound, dict(shape))
            raise

    @property
    def n_refused(self) -> int:
        """Candidates the sheet refused."""
        return int(sum(self.refused.values()))

    def keep(self, X: np.ndarray, f: np.ndarray) -> None:
        """Remember the best accepted (finite-valued) candidates of a population."""
        for x, v in zip(np.atleast_2d(X), np.asarray(f, dtype=float).reshape(-1)):
            if math.isfinite(v):
                item = (-float(v), next(self._tie), np.array(x, dtype=float))
                if len(self._kept) < _SHEET_KEEP:
                    heapq.heappush(self._kept, item)
                elif item[0] > self._kept[0][0]:
                    heapq.heapreplace(self._kept, item)

    def kept(self) -> list[tuple[float, np.ndarray]]:
        """The kept candidates ``(value, x)``, best first."""
        return [(-v, x) for v, _, x in sorted(self._kept, key=lambda it: (-it[0], it[1]))]


def _run_surface(design: Design, curves: dict[str, Any], shape: dict[str, float]) -> Any:
    """The surface of ``shape`` as :func:`ght_cad.app.design.run_design` builds the result (the curves of
    a ``curves``/``rails`` strip rebuilt with the shape parameters, joins re-applied)."""
    assert design.surface is not None
    cv = build_curves(design, shape)[0] if design.surface.type in ("curves", "rails") else curves
    return build_surface(design, shape, curves=cv).surface


def _verified_radius(design: Design, curves: dict[str, Any], shape: dict[str, float]) -> float:
    """The run's sheet check (:func:`check_sheet`, no margin) of the surface the run builds for
    ``shape`` (:func:`_run_surface`): the smallest bending radius.

    Raises:
        SheetError: the run would refuse the sheet on this surface.
        GHTError: the surface cannot be built.
    """
    return check_sheet(design, _run_surface(design, curves, shape))


def thickness_factor(design: Design, surface: Any, *, rtol: float = 1e-4, upto: float = 1e6) -> tuple[float, str | None]:
    r"""How much thicker a sheet the surface would still carry: the largest ``f`` with
    :func:`check_sheet` passing for the sheet ``(f T, K, side)``, and the rule that refuses beyond it.

    The rules are monotone in T (``|K f T| < |ρ_0|``, ``|ρ_0| > f T`` where the material lies on the
    concave side; the apex rule does not depend on T), so ``f = min(min |ρ_0| / |K T|,
    min_concave |ρ_0| / T)``, found by doubling and bisection on the check itself (about 20 checks).

    Args:
        design: a design with a ``[sheet]`` of thickness ``T > 0``.
        surface: a built surface that passes the design's sheet (``f >= 1``).
        rtol: relative width of the final bracket.
        upto: largest factor tried (``f`` is reported as ``upto`` when even that passes).

    Returns:
        ``(f, rule)``: f to ``rtol`` (the lower end of the bracket, a factor that passes), and the
        refusing rule beyond it (``"radius"``, ``"centre"``; None when ``upto`` passes).

    Raises:
        DesignError: the design has no sheet with T > 0.
        SheetError: the sheet itself is refused (``f < 1``).
        GHTError: ``rtol`` not in (0, 1) or ``upto`` not a finite number > 2.
    """
    from ...sheetmetal.sheet import Sheet, SheetError

    if not (isinstance(rtol, (int, float)) and 0.0 < rtol < 1.0):
        raise GHTError(f"rtol={rtol!r} is not allowed; it must be a number in (0, 1)")
    if not (isinstance(upto, (int, float)) and math.isfinite(upto) and upto > 2.0):
        raise GHTError(f"upto={upto!r} is not allowed; it must be a finite number > 2")
    if design.sheet is None or not design.sheet.thickness > 0:
        raise DesignError(f"{design.source}: key 'sheet': thickness_factor needs a [sheet] with thickness > 0")
    sh = design.sheet.to_sheet()

    def passes(f: float) -> str | None:
        try:
            check_sheet(design, surface, sheet=Sheet(sh.thickness * f, sh.k_factor, sh.side))
        except SheetError as exc:
            return exc.constraint or "radius"
        return None

    check_sheet(design, surface)
    lo, hi, rule = 1.0, 2.0, passes(2.0)
    while rule is None:
        if hi >= upto:
            return upto, None
        lo, hi = hi, min(2.0 * hi, upto)
        rule = passes(hi)
    while hi - lo > rtol * lo:
        mid = 0.5 * (lo + hi)
        r = passes(mid)
        if r is None:
            lo = mid
        else:
            hi, rule = mid, r
    return lo, rule


def _fmt_shape(shape: dict[str, float], names: Sequence[str]) -> str:
    return ", ".join(f"{k}={shape[k]:.6g}" for k in names)


def _sheet_infeasible(design: Design, spec: OptimizeSpec, guard: _SheetGuard, names: Sequence[str],
                      start: dict[str, Any], rejected_results: int = 0) -> GHTError:
    """The one-line error when no candidate passed the sheet rule (or none passed the final check)."""
    from ...sheetmetal.sheet import SheetError

    sh = guard.sheet
    kt = abs(sh.neutral_offset)
    counts = ", ".join(f"{n} by {_RULE_TEXT[k]}" for k, n in guard.refused.items() if n)
    head = (f"{design.source}: key 'sheet': the optimizer ({spec.method}, population {spec.population}, "
            f"{spec.iterations} iterations) found no shape parameters of "
            f"{', '.join(names)} in [-1, 1] whose surface can be made from this sheet (thickness={sh.thickness:g}, "
            f"k_factor={sh.k_factor:g}, side={sh.side!r}, |K*T|={kt:.6g}): {guard.n_refused} of {guard.checked} "
            f"candidate surfaces refused ({counts or 'none'})")
    if rejected_results:
        head += f", and {rejected_results} accepted candidate(s) refused by the final check"
    if guard.closest is not None:
        score, rule, radius, bound, shape = guard.closest
        if rule == "apex":
            head += ("; limiting constraint: every candidate has an apex (a cone point, a loft fan) with the material "
                     "on its concave side")
            allowed = "the material on the convex side (sheet.side flipped), or rails whose loft has no fan"
        else:
            what = "|K*T|" if rule == "radius" else "T"
            head += (f"; limiting constraint: {_RULE_TEXT[rule]}; the closest candidate ({_fmt_shape(shape, names)}) "
                     f"has the bending radius {radius:.6g} against {what}={bound:.6g}")
            allowed = (f"a sheet with {what} < {radius:.6g} (thickness or k_factor)" if rule == "radius"
                       else f"a thickness below {radius:.6g} or the other side")
            allowed += ", other curves or planes, or a larger search (optimize.population, optimize.iterations)"
        head += f"; allowed: {allowed}"
    if start.get("error"):
        head += f"; the start design is refused too: {start['error']}"
    return SheetError(head)


def _check_start(design: Design, curves: dict[str, Any], shape: dict[str, float], progress: bool) -> dict[str, Any]:
    """The run's sheet check of the start design (the file's shape parameters): ``feasible``
    (None when the start has no surface), ``min_bending_radius``, ``error`` (the check's message).
    A refused start is said at once on a terminal (one ``note`` line on stderr) when ``progress``."""
    import sys

    from ...core.progress import progress_enabled
    from ...sheetmetal.sheet import SheetError

    try:
        r = _verified_radius(design, curves, shape)
    except SheetError as exc:
        msg = " ".join(str(exc).split())
        if progress and progress_enabled():
            sys.stderr.write(f"ght-cad: note: {design.source}: the start design cannot be made from the sheet ({msg}); "
                             "searching the box for shape parameters that can\n")
            sys.stderr.flush()
        return {"feasible": False, "min_bending_radius": exc.radius, "error": msg}
    except GHTError:
        return {"feasible": None, "min_bending_radius": None, "error": None}
    return {"feasible": True, "min_bending_radius": r, "error": None}


def _sheet_summary(guard: _SheetGuard, start: dict[str, Any], rmin: float, rejected: int,
                   factor: tuple[float, str | None]) -> dict[str, Any]:
    """The ``sheet`` block of the optimization report (see :attr:`OptimizationOutcome.sheet`)."""
    kt = abs(guard.sheet.neutral_offset)
    return {
        **guard.sheet.as_dict(),
        "k_t": kt,
        "rule": (f"every candidate surface passes ght_cad.sheet.check_offset (513 rulings, both ends, every part) "
                 f"on the sheet of thickness (1 + {SHEET_MARGIN:g}) T; the result passes the run's check (thickness T)"),
        "margin": SHEET_MARGIN,
        "candidates_checked": guard.checked,
        "candidates_refused": guard.n_refused,
        "refused_by": dict(guard.refused),
        "active": guard.n_refused > 0,
        "initial_feasible": start.get("feasible"),
        "initial_min_bending_radius": start.get("min_bending_radius"),
        "initial_error": start.get("error"),
        "min_bending_radius": rmin,
        "min_radius_over_k_t": rmin / kt if kt > 0 else math.inf,
        "thickness_factor": factor[0],
        "limiting_rule": factor[1],
        "final_check_fallbacks": rejected,
    }


#: the rules of :func:`ght_cad.sheetmetal.sheet.check_offset` in words
_RULE_TEXT = {
    "radius": "the neutral offset |K*T| reaching a bending radius",
    "centre": "the material reaching a centre of curvature",
    "apex": "the material on the concave side of an apex",
}


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

    With a ``[sheet]`` of thickness ``T > 0`` every candidate surface is also checked against the
    sheet (the module's sheet rule: the run's :func:`check_sheet` on the sheet ``(1 + SHEET_MARGIN) T``)
    and a refused one gets ``+inf``; the result is then checked exactly as the run will check it
    (next best accepted candidates if that refuses it), so it can always be made from the sheet.
    The start design is checked first (as the run would); a refused start is reported (a line on a
    terminal, ``sheet.initial_error``) and the search goes on for shape parameters that pass. A
    start that passes is never replaced by a worse result. Without a sheet (or ``T = 0``) nothing
    changes: same candidates, same evaluations, same result.

    Args:
        design: validated design with a [surface] table.
        overrides: replaces ``method``, ``objective``, ``iterations``, ``population``, ``seed``.
        progress: progress bar on a terminal.
        curves: already built curves (joins applied).
        exact_gradients: give the optimizer the exact gradient where one exists (composites:
            :func:`composite_value_and_grad`; rails: :meth:`ght_cad.optimize.problems.loft.LoftProblem.value_and_grad`);
            ``False`` leaves the objective a plain callable (``hybrid`` then uses finite differences).

    Returns:
        :class:`OptimizationOutcome` (for a composite with ``strips``: the measures of every strip
        before and after, and ``joints``: requested vs measured order after optimization; with a
        sheet ``sheet``: candidates checked and refused, the start's check, the result's smallest
        bending radius against ``|K T|``).

    Raises:
        DesignError: no [surface], or an override that is not allowed.
        SheetError: with a sheet, no candidate the sheet can be made from was found (the message
            names the limiting rule and the closest candidate's radius against ``|K T|``).
        GHTError: no admissible shape parameters found.
    """
    from ...optimize import minimize
    from ...core.progress import Progress

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
    sheet = design.sheet.to_sheet() if design.sheet is not None and design.sheet.thickness > 0 else None
    guard = _SheetGuard(design, sheet) if sheet is not None else None
    f = _objective_fn(design, curves, spec, guard)
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
        if guard is not None:
            guard.keep(X, out)
        return out

    vg = _value_and_grad_fn(design, curves, spec, names, shape_of, guard) if exact_gradients else None
    if vg is not None:
        if guard is None:
            F.value_and_grad = vg  # type: ignore[attr-defined]
        else:
            def vg_kept(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
                fx, G = vg(X)
                guard.keep(X, fx)
                return fx, G

            F.value_and_grad = vg_kept  # type: ignore[attr-defined]
    x0 = np.array([base[k] for k in names])
    start: dict[str, Any] = {}
    if guard is not None:
        start = _check_start(design, curves, shape_of(x0), progress)
    initial = float(F(x0[None, :])[0])
    if guard is not None and start.get("feasible") and not math.isfinite(initial):
        # the run accepts the start but it lies within the margin of the bound: measured without the rule
        try:
            with np.errstate(all="ignore"):
                initial = float(_objective_fn(design, curves, spec)(shape_of(x0)))
        except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
            initial = math.inf
        if not math.isfinite(initial):
            initial = math.inf
    bounds = (-np.ones(len(names)), np.ones(len(names)))
    with Progress(spec.iterations, f"optimizing ({spec.method}, {spec.objective})",
                  enabled=None if progress else False) as bar:
        res = minimize(F, bounds, method=spec.method, pop_size=spec.population, max_iter=spec.iterations,
                       seed=spec.seed, callback=bar.callback, x0=x0)
    nfev = int(res.nfev) + int(getattr(vg, "extra_nfev", 0))
    start_ok = guard is not None and bool(start.get("feasible")) and math.isfinite(initial)
    if not np.isfinite(res.fun) and not start_ok:
        if guard is not None and guard.n_refused:
            raise _sheet_infeasible(design, spec, guard, names, start)
        raise GHTError(f"{design.source}: key 'optimize.parameters': optimization found no admissible shape parameters "
                       f"(every candidate of {spec.method} over {', '.join(names)} gave a surface that cannot be built); "
                       "allowed: parameters and bounds where the surface builds (check the curves or planes)")
    x = np.clip(np.asarray(res.x, dtype=float), -1.0, 1.0)
    best = float(res.fun)
    rmin = math.nan
    rejected = 0
    if guard is not None:
        # the result as the run will build and check it; the next best accepted candidates if refused
        tried: list[tuple[float, np.ndarray]] = [(best, x)] if math.isfinite(best) else []
        tried += [(v, np.clip(c, -1.0, 1.0)) for v, c in guard.kept() if not np.array_equal(np.clip(c, -1.0, 1.0), x)]
        if start_ok:  # never worse than a start the run accepts
            tried = [(v, c) for v, c in tried if v < initial] + [(initial, x0)]
        surf = None
        for v, c in tried:
            try:
                surf = _run_surface(design, curves, shape_of(c))
                rmin = check_sheet(design, surf)
            except GHTError:
                rejected += 1
                continue
            x, best = c, float(v)
            break
        else:
            raise _sheet_infeasible(design, spec, guard, names, start, rejected)
    elif initial <= best:  # never report something worse than the start
        x, best = x0, initial
    out = OptimizationOutcome(spec.method, spec.objective, names, x, best, initial, np.asarray(res.history),
                              int(res.nfev), int(res.nit), float(res.time), shape_of(x), list(spec.weights))
    out.njev = int(getattr(res, "njev", 0) or 0)
    out.nfev = nfev  # with the finite-difference fallbacks of an exact gradient
    if guard is not None:
        out.sheet = _sheet_summary(guard, start, rmin, rejected, thickness_factor(design, surf))
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
