"""The entry point :func:`developable_loft` (spec section 5.7): rail checks, tracing in both
orientations, choosing the branch, and the message when there is none."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...core._validate import is_real
from ...core.errors import DegenerateGeometryError, GHTError, NotDevelopableError
from .equation import _Pair
from .plot import plot_loft_sign
from .rails import _Reversed, as_rail
from .surface import DevelopableLoft
from .tracing import _Branch, _TraceFailure, _boundary_roots, _trace


# ----------------------------------------------------------------------------------------------
# entry point
# ----------------------------------------------------------------------------------------------
_ORIENTATIONS = ("auto", "same", "reversed")


def _max_distance(P: np.ndarray, rail: Any, t: np.ndarray, Q: np.ndarray) -> float:
    """max over the points P of their distance to the curve ``rail`` (samples Q at t): nearest
    sample, then Newton on ``(r(s) - p) · r'(s) = 0``."""
    s = t[np.argmin(np.linalg.norm(P[:, None, :] - Q[None, :, :], axis=2), axis=1)]
    for _ in range(4):
        r0, r1, r2 = rail.derivative(s, 0), rail.derivative(s, 1), rail.derivative(s, 2)
        e = r0 - P
        den = np.einsum("ij,ij->i", r1, r1) + np.einsum("ij,ij->i", e, r2)
        with np.errstate(divide="ignore", invalid="ignore"):
            ds = np.where(den > 0, np.einsum("ij,ij->i", e, r1) / np.where(den > 0, den, 1.0), 0.0)
        s = np.clip(s - ds, 0.0, 1.0)
    return float(np.max(np.linalg.norm(rail.derivative(s, 0) - P, axis=1)))


def _check_rails(ra: Any, rb: Any, samples: int = 129) -> float:
    """Sample both rails: finite values, regular tangents, not coincident; returns the size."""
    t = np.linspace(0.0, 1.0, samples)
    pts = {}
    for name, r in (("rail_a", ra), ("rail_b", rb)):
        try:
            P = r.derivative(t, 0)
            D = r.derivative(t, 1)
        except GHTError:
            raise
        except Exception as exc:  # a user callable failing: say which rail
            raise GHTError(f"{name} could not be evaluated on t ∈ [0, 1]: {type(exc).__name__}: {exc}") from exc
        for what, arr in (("position", P), ("derivative", D)):
            bad = ~np.all(np.isfinite(arr), axis=1)
            if bad.any():
                i = int(np.argmax(bad))
                raise GHTError(f"{name} {what} is not finite at t={t[i]:.6g}: {arr[i].tolist()}; rails must be finite")
        ext = float(np.linalg.norm(P.max(axis=0) - P.min(axis=0)))
        speed = np.linalg.norm(D, axis=1)
        if ext <= 0 or not np.any(speed > 0):
            raise DegenerateGeometryError(f"{name} is a single point {P[0].tolist()}; a rail must be a curve of positive length")
        pts[name] = (P, speed, ext)
    Pa, sa, ea = pts["rail_a"]
    Pb, sb, eb = pts["rail_b"]
    allp = np.vstack([Pa, Pb])
    size = float(np.linalg.norm(allp.max(axis=0) - allp.min(axis=0)))
    for name, sp in (("rail_a", sa), ("rail_b", sb)):
        low = sp <= 1e-9 * size
        if low.any():
            i = int(np.argmax(low))
            raise DegenerateGeometryError(
                f"{name} has a zero tangent (|r'| = {sp[i]:.3g}) at t={t[i]:.6g}; a loft needs regular rails "
                "(split the rail there or re-parametrize it)"
            )
    if _max_distance(Pa, rb, t, Pb) <= 1e-9 * size and _max_distance(Pb, ra, t, Pa) <= 1e-9 * size:
        raise DegenerateGeometryError("rail_a and rail_b coincide (every point of one lies on the other); give two distinct rails")
    return size


def developable_loft(
    rail_a: Any,
    rail_b: Any,
    *,
    orientation: str = "auto",
    branch: str | int = "auto",
    max_step: float = 1.0 / 16,
    step_tol: float = 2e-3,
    samples: int = 257,
    boundary_samples: int = 513,
    sign_png: Any = None,
) -> DevelopableLoft:
    r"""The exact developable loft between two rails (spec section 5.7).

    Traces the branch of ``F(t, s) = det(a'(t), b'(s), b(s) - a(t)) = 0`` from a zero of F on a
    lower-left side of the (t, s) square (s = 0 or t = 0) as an increasing ``s = σ(t)`` by
    predictor–corrector continuation in ``λ = (t + s)/2`` with Newton correction to round-off, to
    an upper-right side, and adds fans (cones with apex at a rail end) along the sides so both
    rails are covered over [0, 1] (module doc).

    Args:
        rail_a, rail_b: GHTCurve objects, :class:`CallableRail` or objects with ``evaluate(t)``
            and ``derivative(t, order)`` on [0, 1] (see :func:`as_rail`).
        orientation: ``"same"`` (s increases with t), ``"reversed"`` (rail b is traced from its
            end: s decreases with t) or ``"auto"``: both, keep the better branch.
        branch: ``"auto"`` keeps, among the branches that join the lower-left to the upper-right
            sides, the one without an edge of regression between the rails and with the smallest
            fan share; an integer picks ``report.candidates[i]`` (in the order they were found).
        max_step: largest continuation step in λ.
        step_tol: largest corrector displacement (in t + s) of an accepted step.
        samples: rulings per segment sampled for the report (θ, degenerate rulings, regression).
        boundary_samples: samples per side when looking for the zeros of F on the lower-left sides.
        sign_png: a path; when no loft exists, :func:`plot_loft_sign` writes the sign of F there
            before the error is raised (the message names the file).

    Returns:
        :class:`DevelopableLoft` with ``segments``, ``report``, ``sigma``, ``developability``.

    Raises:
        NotDevelopableError: no branch of F = 0 joins the rails over their whole length (the
            message says where the branches go; :func:`plot_loft_sign` draws the sign of F).
        DegenerateGeometryError: coincident rails, a rail that is a point or has a zero tangent,
            coplanar rails (F ≡ 0).
        GHTError: bad options or rails that cannot be evaluated.
    """
    if orientation not in _ORIENTATIONS:
        raise GHTError(f"orientation={orientation!r} is not allowed; use one of {_ORIENTATIONS}")
    if not (branch == "auto" or (isinstance(branch, (int, np.integer)) and not isinstance(branch, bool) and branch >= 0)):
        raise GHTError(f"branch={branch!r} is not allowed; use 'auto' or a candidate index >= 0")
    for nm, v, lo, hi in (("max_step", max_step, 1e-6, 0.5), ("step_tol", step_tol, 1e-8, 0.1)):
        if not (is_real(v) and math.isfinite(v) and lo <= v <= hi):
            raise GHTError(f"{nm}={v!r} is not allowed; it must be a number in [{lo:g}, {hi:g}]")
    for nm, v, lo in (("samples", samples, 9), ("boundary_samples", boundary_samples, 17)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise GHTError(f"{nm}={v!r} is not allowed; it must be an integer >= {lo}")
    ra = as_rail(rail_a, "rail_a")
    rb = as_rail(rail_b, "rail_b")
    size = _check_rails(ra, rb)
    orients = {"auto": (False, True), "same": (False,), "reversed": (True,)}[orientation]
    found: list[tuple[_Pair, _Branch]] = []
    cands: list[dict[str, Any]] = []
    zero_everywhere = True
    for rev in orients:
        pair = _Pair(ra, _Reversed(rb) if rev else rb, size)
        grid = np.linspace(0.0, 1.0, 33)
        T, S = np.meshgrid(grid, grid, indexing="ij")
        fv = pair.f(T.ravel(), S.ravel())
        if np.max(np.abs(fv)) > 1e-10:
            zero_everywhere = False
        for start in _boundary_roots(pair, boundary_samples):
            given = (start[0], 1.0 - start[1] if rev else start[1])
            entry: dict[str, Any] = {"orientation": "reversed" if rev else "same", "start": list(given)}
            try:
                br = _trace(pair, start, rev, max_step, step_tol)
            except _TraceFailure as exc:
                entry["refused"] = str(exc) if not rev else str(exc) + " (rail_b reversed: s there is 1 - s on rail_b)"
                cands.append(entry)
                continue
            entry["end"] = [br.end[0], 1.0 - br.end[1] if rev else br.end[1]]
            entry["index"] = len(found)
            found.append((pair, br))
            cands.append(entry)
    if zero_everywhere:
        raise DegenerateGeometryError(
            "F(t, s) = det(a', b', b - a) vanishes on the whole square: the rails are coplanar (every ruled "
            "surface between them is planar); use a planar face instead of a loft"
        )
    def refuse() -> NotDevelopableError:
        msg = _no_branch_message(ra, rb, size, cands, orients)
        if sign_png is not None:
            path = plot_loft_sign(ra, rb, sign_png)
            msg = msg.replace("ght_cad.developables.loft.plot_loft_sign(rail_a, rail_b, 'sign.png') draws", f"{path} shows")
        return NotDevelopableError(msg)

    if not found:
        raise refuse()
    lofts = []
    # with several candidates, rank them on a coarse report (65 rulings, areas to 1e-9) and build
    # the full report for the chosen one only
    coarse = branch == "auto" and len(found) > 1
    for i, (pair, br) in enumerate(found):
        if branch != "auto" and i != branch:
            continue
        try:
            lf = DevelopableLoft(rail_a, rail_b, pair, br, samples=min(samples, 65) if coarse else samples,
                                 candidates=cands, area_rtol=1e-9 if coarse else 1e-13)
            lf._index = i
            folds = lf.joint_folds()
            if folds:
                raise NotDevelopableError(
                    "the fans fold back over the main part at the joint ruling(s) "
                    + ", ".join(f"t={f['t']:.6g}, s={f['s']:.6g}" for f in folds)
                )
            lofts.append(lf)
        except NotDevelopableError as exc:
            for c in cands:
                if c.get("index") == i:
                    c["refused"] = str(exc)
    if branch != "auto" and not lofts:
        raise GHTError(f"branch={branch} is not a usable candidate; candidates: {cands}")
    if not lofts:
        raise refuse()
    for lf in lofts:
        for c in cands:
            if c.get("index") == lf._index:
                c["fan_share"] = lf.report.fan_share
                c["regression_inside"] = bool(lf.report.regression)
    best = min(lofts, key=lambda lf: (bool(lf.report.regression), round(lf.report.fan_share, 9),
                                      len(lf.segments)))
    if coarse:
        index = best._index
        best = DevelopableLoft(rail_a, rail_b, best._pair, best._branch, samples=samples, candidates=cands)
        best._index = index
        for c in cands:
            if c.get("index") == index:
                c["fan_share"] = best.report.fan_share
    best.report.candidates = cands
    return best


def _no_branch_message(ra: Any, rb: Any, size: float, cands: list[dict[str, Any]], orients: tuple[bool, ...]) -> str:
    what = "in either orientation of rail_b" if len(orients) == 2 else ("with rail_b reversed" if orients[0] else "with rail_b as given")
    head = (
        "no developable joins the rails over their whole length: no branch of F(t, s) = det(a'(t), b'(s), "
        f"b(s) - a(t)) = 0 runs from a lower-left side (t = 0 or s = 0) to an upper-right side (t = 1 or s = 1) "
        f"of the parameter square as an increasing curve, {what}"
    )
    if not cands:
        pair = _Pair(ra, rb, size)
        g = np.linspace(0.0, 1.0, 65)
        T, S = np.meshgrid(g, g, indexing="ij")
        f = pair.f(T.ravel(), S.ravel())
        pos = float(np.mean(f > 0))
        tail = (f"; F has no zero on the lower-left sides (F/(|a'||b'||b-a|) ranges over [{f.min():.3g}, {f.max():.3g}] "
                f"on the square, positive on {100 * pos:.0f}% of it)")
    else:
        tail = "; branches found: " + "; ".join(
            f"from (t, s) = ({c['start'][0]:.6g}, {c['start'][1]:.6g}) [{c['orientation']}]: {c.get('refused', 'refused')}"
            for c in cands
        )
    return head + tail + ". ght_cad.developables.loft.plot_loft_sign(rail_a, rail_b, 'sign.png') draws the sign of F over the square."

