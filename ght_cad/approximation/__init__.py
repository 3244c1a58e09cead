r"""Developable panels for a surface that is not developable (issue 24).

A double-curved target ``S(u, v)`` (anything with positions and first/second derivatives) is
covered by strips bounded by target isolines (the *seams*); each strip is an exact developable:
the rails loft (spec 5.7) between its two seam curves, whose rulings run across the strip. The
rulings follow the conjugate direction of the seams; the parameter direction the rulings run along
is chosen as the one of least normal curvature (``direction="auto"``) from the strip-count estimate

    N_dir ≈ max_x ∫_0^1 sqrt(|κ_n(y)| / (16 tol)) |S_y| dy,

(the sagitta of a ruling of length w on a surface of normal curvature κ is ``κ w² / 8``; split
both ways it gives ``κ w² / 16``), where ``y`` is the parameter the rulings run along and ``x``
the other one. For a spherical cap given in longitude/latitude this gives conical bands between
latitude circles with rulings along the meridians.

The estimate used is its conjugate form (maths 10.2, :func:`_estimate`): the rulings follow the
direction ``r = L_xy S_x - L_xx S_y`` conjugate to the seams (``L`` the second fundamental form in
the strip coordinates), which gives ``N ≈ max_x ∫ sqrt(|det II| / (16 tol |L_xx|)) dy`` (the
formula above where ``L_xy = 0``; infinite where the seams are asymptotic lines, ``L_xx = 0``).
Besides u and v it ranks **diagonal strips** (``direction="diagonal"``/``"antidiagonal"``,
:class:`_DiagonalFrame`): seams along the isolines of ``u_n + v_n`` (``u_n - v_n``) of the
normalized parameter box, cones at the two corners where they shrink to points, a seam forced on
the box's other diagonal. ``"auto"`` takes them only where they beat the better of u and v by the
factor :data:`DIAGONAL_GAIN` (the saddle ``z = x y / L`` in its own parameters: u, v 88 strips,
diagonals 5.5), never on a target closed along a parameter.

Algorithm (all kernel-free, numpy/scipy):

1. **March**: from ``y = 0``, the next seam is the largest ``y1`` whose strip, with both seams on
   the target, deviates from it by a range ``max d - min d <= 2 tol f`` (``d`` the signed distance
   of the panel's points to the target along its normal; ``f = 0.9``, lowered when step 3 fails).
   The strip's rulings are found fast by Newton on ``F(t, s) = det(a'(t), b'(s), b(s) - a(t)) = 0``
   for every t (with fans ``a(0) -> b(s)``, ``a(t) -> b(0)`` ... where ``s(t)`` leaves [0, 1]),
   the same equation :func:`ght_cad.developables.loft.developable_loft` traces.
2. **Split the deviation both ways**: every seam is moved off the target along its normal,
   ``r_j(t) = S(t, y_j) + δ_j n(t, y_j)``, by the fixed point
   ``δ_j ← δ_j - (m_{j-1} + m_j) / 2`` (``m_i = (max d + min d) / 2`` of strip i; one neighbour at
   the ends), so each panel's deviation range is centred on the target. Adjacent panels share
   the seam function ``r_j`` exactly (the same callable for both lofts): the seams are watertight up
   to the B-spline fit tolerance of the faces (1e-7 of the size).
3. **Build and measure**: each strip becomes an exact :func:`ght_cad.developables.loft.developable_loft` between
   its rails (a seam that is one point, e.g. the pole of a sphere in longitude/latitude, gives a
   cone with its apex there) and its deviation is measured both ways (panel points projected onto
   the target and target points projected onto the panel, Gauss–Newton). If a panel exceeds
   ``tol``, the march is repeated with a smaller ``f``; a result needing more than ``max_panels``
   panels raises :class:`ght_cad.core.errors.GHTError` naming the best deviation reached and its
   panel count. When already the first march needs more than ``max_panels`` strips, the best
   deviation is that of the finest march with at most ``max_panels`` strips (:func:`_march_within`:
   the smallest range limit whose march fits, found by marches alone), built and measured like
   any other result: ONE build and measure more, on failure only, not a search over ``tol``
   (where no developable joins its seams, the finest march with fewer strips is tried instead).

4. **Loft or dual fit per strip** (``method="auto"``, spec 10.1): every strip also gets the dual
   fit of the target's tangent planes along its middle curve (:mod:`ght_cad.approximation.dual`:
   a GHT dual curve, spec 5.2, fitted by least squares, its μ, ν, γ optimized by
   :func:`ght_cad.optimize.minimize`), trimmed to the strip: its boundary on the seam rows is a
   seam ``S(x, y_j) + δ(x) n`` of the same family. Strips turn dual greedily where the dual seams
   give a smaller sampled deviation and the strip and its neighbours get closer; a seam next to a
   dual strip is that strip's trimmed boundary. Every panel is the loft between its two seams, so
   neighbours share the seam curve exactly whatever their methods; if the mix misses ``tol`` the
   all-loft set is built too and the better kept. A target closed along the seams (a full turn)
   keeps the lofts: one GHT dual curve cannot close.

Inputs that are developable already (a cone, a ght_cad loft) give one panel: the first march step
tries the whole box.

Modules (issue 27, moved from ``ght_cad/approximation.py``): :mod:`.target` (targets),
:mod:`.frame` (strip coordinates), :mod:`.seams` (seams, strip rulings), :mod:`.result` (panels and
the result), :mod:`.splitting` (direction estimate, march, greedy split, offsets), :mod:`.fitting`
(loft or dual fit per strip, building a panel), :mod:`.deviation` (measuring a panel), :mod:`.dual`
(the dual fit of a strip's tangent planes; old path ``ght_cad.approximation_dual``);
:func:`approximate` stays here and reads the helpers from this module's namespace. Every name
(private ones included) is importable as ``ght_cad.approximation.<name>``.
"""

from __future__ import annotations

import math
import time
from typing import Any, Callable

import numpy as np

from ..core.errors import GHTError

# The moved names (issue 27), all importable from here.
from .target import as_target, _ght_jet, _JET, _ruled_jet, SurfaceTarget  # noqa: F401
from .frame import _DiagonalFrame, _Frame, _unit, make_frame, STRIP_DIRECTIONS, strip_uv  # noqa: F401
from .seams import (BSplineRuled, _det, _match, _ruling_deviation, _Rulings, _Seam, SeamCurve,
                    _strip_rulings, _W)  # noqa: F401
from .result import ApproximationResult, ConeStrip, Panel  # noqa: F401
from .splitting import (_choose_direction, _estimate, _estimate_curvature, _greedy, _march, _march_piece, _march_within,
                        _offsets,
                        _strip_range, DIAGONAL_GAIN, DIAGONAL_MIN_STRIPS)  # noqa: F401
from .fitting import _build_panel, _choose_methods, _dual_seams, _strip_dev  # noqa: F401
from .deviation import _measure_panel, _project_panel, _strip_grid  # noqa: F401

#: the accepted ``direction`` values of :func:`approximate`
DIRECTIONS = ("auto",) + STRIP_DIRECTIONS

__all__ = [
    "DIRECTIONS",
    "SurfaceTarget",
    "as_target",
    "approximate",
    "ApproximationResult",
    "Panel",
    "ConeStrip",
]


def _check_number(name: str, v: Any, lo: float, integer: bool = False) -> None:
    ok = isinstance(v, (int, np.integer)) if integer else isinstance(v, (int, float, np.floating, np.integer))
    if isinstance(v, bool) or not ok or not math.isfinite(float(v)) or v < lo:
        kind = "an integer" if integer else "a finite number"
        raise GHTError(f"{name}={v!r} is not allowed; it must be {kind} >= {lo:g}")


def approximate(
    target: Any,
    tol: float,
    *,
    direction: str = "auto",
    max_panels: int = 64,
    offset_degree: int = 4,
    offset_iterations: int = 2,
    safety: float = 0.9,
    method: str = "auto",
    optimizer: str | None = "igwo",
    optimizer_budget: int = 60,
    dual_degree: int = 10,
    progress: Callable[[str], None] | None = None,
    untrimmed: bool = False,
) -> ApproximationResult:
    r"""Cover ``target`` with exactly developable panels within ``tol`` (module doc).

    Strips between target isolines (seams); each strip is the developable loft between its seam
    curves ``r_j(t) = S(t, y_j) + δ_j(t) n(t, y_j)`` (spec 5.7: rulings where
    ``det(a', b', b - a) = 0``), a cone where a seam is one point. Seams are placed by a greedy
    march on the on-target deviation range (``max d - min d <= 2 tol f``) and then moved off the
    target along its normal so the deviation is split both ways; neighbouring panels share the
    seam curve ``r_j`` exactly.

    Args:
        target: GHTSurface, NurbsSurface, RuledSurface, :class:`SurfaceTarget` or a CAD face.
        tol: largest allowed deviation (both ways, model units).
        direction: one of :data:`DIRECTIONS`: ``"u"`` or ``"v"``: the parameter the rulings run
            along (the seams are isolines of the other one); ``"diagonal"``/``"antidiagonal"``:
            seams along the isolines of ``u_n + v_n`` / ``u_n - v_n`` of the normalized parameter
            box (maths 10.2); ``"auto"``: by the conjugate strip estimate (:func:`_choose_direction`).
        max_panels: largest panel count accepted.
        offset_degree: Chebyshev degree of the seam offsets δ_j(t) (0: constant).
        offset_iterations: fixed-point iterations of the offsets.
        safety: the march's share ``f`` of the deviation budget (lowered by 7 % per retry).
        method: ``"auto"`` (spec 10.1: per strip the closer of the loft and the dual fit of the tangent
            planes, step 4), ``"loft"`` or ``"dual"`` (the dual fit wherever it is usable, the loft
            only where it is not; no all-loft fallback: a finer march instead).
        optimizer: :func:`ght_cad.optimize.minimize` method for each dual fit's μ, ν, γ
            (``"igwo"``, ``"pso"``, ``"hybrid"``, ...), or None to keep ``μ = ν = γ = 0``.
        optimizer_budget: objective evaluations per strip for that optimizer.
        dual_degree: degree m of the fitted dual curves.
        progress: called with a line of text per step (e.g. ``print``).
        untrimmed: cover a trimmed CAD face's underlying surface over its whole (u, v) box
            knowingly (``info["trim"]`` records the covered fraction); without it a trimmed face
            is refused (:func:`.target.check_trim`).

    Returns:
        :class:`ApproximationResult`.

    Raises:
        GHTError: bad arguments, or no approximation within ``tol`` with at most ``max_panels``
            panels: one line ``no approximation of the target within tol=T with at most
            max_panels=N panels; best deviation reached D with n panels``. D is the smallest largest
            deviation of the results measured; when the first march already needs more than N
            strips, the deviation of the finest march with at most N strips (:func:`_march_within`,
            one build and measure more, no search over ``tol``; with fewer strips where that build
            is refused). "none" when no developable joins
            the seams (e.g. asymptotic seams: NotDevelopableError of the loft is caught there) or
            no march fits in N strips (fewer than the diagonal frame's two pieces).
    """
    _check_number("tol", tol, 0.0)
    if not tol > 0:
        raise GHTError(f"tol={tol!r} is not allowed; it must be > 0")
    _check_number("max_panels", max_panels, 1, integer=True)
    _check_number("offset_degree", offset_degree, 0, integer=True)
    _check_number("offset_iterations", offset_iterations, 0, integer=True)
    _check_number("safety", safety, 0.05)
    if direction not in DIRECTIONS:
        raise GHTError(f"direction={direction!r} is not allowed; use one of " + ", ".join(repr(d) for d in DIRECTIONS))
    if method not in ("auto", "loft", "dual"):
        raise GHTError(f"method={method!r} is not allowed; use 'auto', 'loft' or 'dual'")
    _check_number("optimizer_budget", optimizer_budget, 1, integer=True)
    _check_number("dual_degree", dual_degree, 3, integer=True)
    if optimizer is not None:
        from .dual import check_optimizer

        check_optimizer(optimizer)
    from ..developables.envelope import developable_bspline

    say = progress or (lambda s: None)
    t0 = time.perf_counter()
    tgt = as_target(target)
    info: dict[str, Any] = {"target": tgt.name, "bounds": list(tgt.bounds)}
    from .target import check_trim  # issue 24: a trimmed face only with untrimmed=True

    if (trim := check_trim(tgt, untrimmed)) is not None:
        info["trim"] = trim
    if direction == "auto":
        direction, est = _choose_direction(tgt, tol)
        # strict JSON (report.json): an infinite estimate (asymptotic seams) is written as null
        info["estimate"] = {k: (float(v) if math.isfinite(v) else None) for k, v in est.items()}
        what = f"rulings along {direction}" if direction in ("u", "v") else f"seams along the {direction} of the box"
        say(f"direction: {what} (estimated strips " + ", ".join(f"{k} {v:.3g}" for k, v in est.items()) + ")")
    frame = make_frame(tgt, direction)
    tol = float(tol)
    best: tuple[float, int] | None = None
    f = float(safety)
    history = []
    panels: list[Panel] = []
    refused: str | None = None
    def cover(ys: list[float]) -> tuple[float, list[Panel], list[Any], list[_Seam]] | None:
        """Build and measure the strips between the seams ``ys`` (steps 2-4): the best mix, or None
        when no developable joins some seams."""
        nonlocal refused
        n = len(ys) - 1
        loft_seams = _offsets(frame, ys, offset_degree, offset_iterations)
        chosen = [False] * n
        duals: list[Any] = []
        choice: list[dict[str, Any]] = [{} for _ in range(n)]
        if method != "loft" and frame.closed_x:
            # a full turn of tangent planes: one GHT dual curve cannot close, and closed seams keep
            # constant offsets; measured on the cap, the dual seams were 2.3x farther (0.48 vs 0.21)
            choice = [{"dual_ok": False, "dual_reason": "closed strip (a GHT dual curve does not close)"} for _ in range(n)]
        elif method != "loft":
            from .dual import fit_strip

            for A, B in zip(loft_seams[:-1], loft_seams[1:]):
                try:
                    duals.append(fit_strip(frame, A.y, B.y, degree=dual_degree, optimizer=optimizer,
                                           max_nfev=optimizer_budget, closed=frame.closed_x))
                except (GHTError, FloatingPointError, ValueError, np.linalg.LinAlgError):
                    duals.append(None)
            chosen, choice = _choose_methods(frame, loft_seams, duals, method)
            for c, d in zip(choice, duals):
                if d is not None:
                    c.update({"dual_ok": d.ok, "dual_reason": d.reason, "mu": d.params[0], "nu": d.params[1],
                              "gamma": d.params[2], "dual_start": d.half_range_start, "dual_optimized": d.half_range})
            say(f"  dual fits usable: {sum(1 for d in duals if d is not None and d.ok)}/{n}; chosen: {sum(chosen)}")
        mixes = [(_dual_seams(frame, loft_seams, duals, chosen), chosen)] if any(chosen) else []
        if method != "dual" or not mixes:  # "dual": no all-loft fallback (a finer march instead)
            mixes.append((loft_seams, [False] * n))
        best_mix = None
        for seams, ch in mixes:
            built, maps = [], []
            try:
                for i, (A, B) in enumerate(zip(seams[:-1], seams[1:])):
                    exact = _build_panel(frame, A, B)
                    if ch[i] and getattr(getattr(exact, "report", None), "regression", None):
                        raise GHTError(f"the dual panel {i + 1} contains its edge of regression")
                    data = developable_bspline(exact, tol=1e-7 * frame.size, degree=5)
                    surf = BSplineRuled(data)
                    out, inn, mp = _measure_panel(frame, surf, A, B)
                    th = data.info.get("theta_max_deg", math.nan)
                    built.append(Panel(surf, A.y, B.y, out, inn, max(out, inn), float(th) if math.isfinite(th) else 0.0,
                                       exact=exact, method="dual" if ch[i] else "loft", choice=dict(choice[i])))
                    maps.append(mp)
            except (GHTError, FloatingPointError) as exc:  # NotDevelopableError included: a refused mix
                say(f"  mix refused: {exc}")
                refused = f"{type(exc).__name__}: {exc}"
                continue
            w = max(p.max_deviation for p in built)
            if best_mix is None or w < best_mix[0]:
                best_mix = (w, built, maps, seams)
            if w <= tol:
                break
        return best_mix

    overshoot: int | None = None  # strips of the first march when it needs more than max_panels
    for attempt in range(8):
        ys = _march(frame, tol, f, max_panels, min_width=1e-6)
        n = len(ys) - 1
        say(f"march f={f:.3f}: {n} strips" if n <= max_panels else f"march f={f:.3f}: more than {max_panels} strips")
        if n > max_panels:
            history.append({"f": f, "panels": n, "max_deviation": None})
            if best is None:
                overshoot = n
            break
        best_mix = cover(ys)
        if best_mix is None:  # no developable between some seams: a finer march
            history.append({"f": f, "panels": n, "max_deviation": None, "error": "no developable between the seams"})
            panels = []
            f *= 0.93
            continue
        _, panels, maps, seams = best_mix
        worst = max(p.max_deviation for p in panels)
        history.append({"f": f, "panels": n, "max_deviation": worst})
        say(f"  {n} panels, max deviation {worst:.4g} (tol {tol:.4g})")
        if best is None or worst < best[0]:
            best = (worst, n)
        if worst <= tol:
            break
        f *= 0.93
    else:
        panels = []
    if overshoot is not None:
        # the best deviation within max_panels: ONE build and measure of the finest march that
        # fits (_march_within), not a search over tol; where no developable joins its seams (a
        # refusal, found while building), the finest march with fewer strips
        cap = max_panels
        while best is None and cap >= 1:
            ys = _march_within(frame, tol, f, cap, min_width=1e-6)
            if ys is None:
                break
            n = len(ys) - 1
            say(f"march needs more than {max_panels} strips at tol {tol:.4g}; measuring the finest {n}-strip covering")
            best_mix = cover(ys)
            history.append({"f": None, "panels": n, "max_deviation": None if best_mix is None else best_mix[0],
                            "best_within_max_panels": True})
            if best_mix is not None:
                best = (best_mix[0], n)
                say(f"  {n} panels, max deviation {best_mix[0]:.4g} (tol {tol:.4g})")
            cap = n - 1
        panels = []
    info["history"] = history
    if not panels or max(p.max_deviation for p in panels) > tol or len(panels) > max_panels:
        if best is None and refused is not None:
            first = refused.splitlines()[0] if refused else ""
            raise GHTError(
                f"no approximation of the target within tol={tol:g} with at most max_panels={max_panels} panels; "
                f"best deviation reached: none (no developable panel joins the seams along direction={direction!r}; "
                f"last refusal: {first[:300]}); try another direction ({', '.join(STRIP_DIRECTIONS)}) or raise tol"
            )
        if best is None:
            raise GHTError(
                f"no approximation of the target within tol={tol:g} with at most max_panels={max_panels} panels; "
                f"best deviation reached: none (the march needed more than {max_panels} strips and no march fits in "
                f"{max_panels} along direction={direction!r}); raise max_panels or tol"
            )
        raise GHTError(
            f"no approximation of the target within tol={tol:g} with at most max_panels={max_panels} panels; "
            f"best deviation reached {best[0]:.6g} with {best[1]} panels"
        )
    for p in panels:
        p.area = p.surface.area()
    dmap = {k: np.concatenate([m[k] for m in maps]) for k in maps[0]}
    info["methods"] = [p.method for p in panels]
    info["seconds"] = time.perf_counter() - t0
    seam_info = [{"y": s.y, "delta": [float(c) for c in s.coef], "point": s.point} for s in seams]
    return ApproximationResult(panels, tol, direction, frame.size, max(p.max_deviation for p in panels), dmap, seam_info, info)
