"""Which isolines of a face are straight: isoline statistics, the ruling direction, best effort.

Moved from :mod:`ght_cad.unrolling.face_unroll` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ...core.errors import DegenerateGeometryError
from .adapter import Bounds, RULED_KINDS, SurfaceAdapter


def _isoline_points(ev: SurfaceAdapter, bounds: Bounds, directions: Sequence[str]) -> dict[str, np.ndarray]:
    """Points of the nine isolines along each of ``directions`` (fixed other parameter at 0, 1/8,
    ..., 1 of its range, 33 points each): ``{direction: (9, 33, 3)}``, one surface evaluation."""
    u0, u1, v0, v1 = bounds
    run = np.linspace(0.0, 1.0, 33)
    us, vs = [], []
    for direction in directions:
        for f in np.linspace(0.0, 1.0, 9):
            if direction == "v":
                us.append(np.full_like(run, u0 + f * (u1 - u0)))
                vs.append(v0 + run * (v1 - v0))
            else:
                us.append(u0 + run * (u1 - u0))
                vs.append(np.full_like(run, v0 + f * (v1 - v0)))
    p = np.asarray(ev.value(np.concatenate(us), np.concatenate(vs)), dtype=float).reshape(len(directions), 9, 33, 3)
    return {d: p[k] for k, d in enumerate(directions)}


def isoline_stats(ev: SurfaceAdapter, bounds: Bounds, direction: str, points: np.ndarray | None = None) -> tuple[float, float]:
    r"""Straightness and openness of the isolines running along ``direction``.

    Nine isolines (fixed other parameter at 0, 1/8, ..., 1 of its range), each sampled at 33
    points ``p_0 .. p_32``, polyline length ``L = Σ |p_{k+1} - p_k|``, chord ``c = p_32 - p_0``.
    The line an isoline is compared with is its chord line when ``|c| > 1e-9 L``, else (a closed
    isoline) the best-fitting line (through the centroid along the principal axis of the points).
    The deviation of one isoline is ``max_k dist(p_k, line) / L`` (0 for a straight segment,
    ``1/π`` for a half circle, ``1/(2π)`` for a full circle); isolines with ``L = 0`` (a pole or
    an apex) are points and skipped.

    Args:
        ev: the surface.
        bounds: (u0, u1, v0, v1).
        direction: "u" (isolines along u) or "v".

        points: the isolines' points (:func:`_isoline_points`) when already evaluated.

    Returns:
        ``(deviation, openness)``: the largest deviation and the smallest ``|c| / L`` over the
        non-degenerate isolines (``openness`` 0 for closed isolines, 1 for straight ones);
        ``(0.0, 1.0)`` when every isoline is degenerate.
    """
    if points is None:
        points = _isoline_points(ev, bounds, (direction,))[direction]
    worst, openness = 0.0, 1.0
    lengths = np.linalg.norm(np.diff(points, axis=1), axis=2).sum(axis=1)
    with np.errstate(invalid="ignore", over="ignore"):
        scale = np.maximum(1.0, np.abs(points).max(axis=(1, 2)))
        good = np.isfinite(lengths) & ~(lengths <= 1e-14 * scale)  # else the isoline is a point (pole, apex)
    if not good.any():
        return worst, openness
    p, L = points[good], lengths[good]
    c = p[:, -1] - p[:, 0]
    chord = np.linalg.norm(c, axis=1)
    origin, axis = p[:, 0].copy(), c / np.where(chord > 0, chord, 1.0)[:, None]
    for k in np.nonzero(~(chord > 1e-9 * L))[0]:  # closed isoline: its best-fitting straight line
        origin[k] = p[k].mean(axis=0)
        axis[k] = np.linalg.svd(p[k] - origin[k], full_matrices=False)[2][0]
    dev = np.linalg.norm(np.cross(p - origin[:, None, :], axis[:, None, :]), axis=2).max(axis=1) / L
    return max(worst, float(dev.max())), min(openness, float((chord / L).min()))


def ruling_direction(surface: SurfaceAdapter, bounds: Bounds) -> tuple[str | None, dict[str, float]]:
    r"""Which parameter direction of the face has straight isolines (the rulings).

    Args:
        surface: the face's surface.
        bounds: its parameter bounds (u0, u1, v0, v1).

    Returns:
        ``("v", info)`` when the v-isolines are straight (deviation ``max dist(p, line) / L``
        < 1e-9, see :func:`isoline_stats`; a closed isoline deviates by ``1/(2π)``), ``"u"``
        likewise, ``None`` when neither. ``info`` holds ``deviation_u``, ``deviation_v``,
        ``openness_u``, ``openness_v`` and ``end_length_u``, ``end_length_v``
        (:func:`end_isoline_length`). Planes, cylinders, cones and extrusions return ``"v"``,
        a structurally ruled B-spline/Bézier its ``ruled_hint``, without measuring: their ``info``
        holds only the ruled direction's ``deviation`` (0) and ``openness`` (1) and
        ``ruled_by: "structure"``.
    """
    hint = "v" if surface.kind in RULED_KINDS else surface.ruled_hint
    if hint in ("u", "v"):
        # ruled by construction (an extrusion; a B-spline/Bézier of degree 1 with 2 poles across:
        # for fixed u, a rational-linear function of v is a straight segment), nothing to measure
        return hint, {f"deviation_{hint}": 0.0, f"openness_{hint}": 1.0, "ruled_by": "structure"}
    pts = _isoline_points(surface, bounds, ("v", "u"))
    dv, ov = isoline_stats(surface, bounds, "v", pts["v"])
    du, ou = isoline_stats(surface, bounds, "u", pts["u"])
    info = {"deviation_v": dv, "deviation_u": du, "openness_v": ov, "openness_u": ou}
    info.update({f"end_length_{d}": end_isoline_length(surface, bounds, d, pts[d]) for d in ("u", "v")})
    if dv <= 1e-9 and dv <= du:
        return "v", info
    if du <= 1e-9:
        return "u", info
    return None, info


def end_isoline_length(ev: SurfaceAdapter, bounds: Bounds, direction: str, points: np.ndarray | None = None) -> float:
    r"""How far the two end isolines along ``direction`` are from being points.

    For ``direction == "u"``: the u-isolines ``S(·, v0)`` and ``S(·, v1)`` (the boundary curves
    of rulings along v), each a 33-point polyline length, ``max(L(v0), L(v1)) / max_k L_k`` over
    the nine isolines of :func:`isoline_stats`: 0 when both end isolines are points (the poles
    of a full sphere), 1 when one of them is the longest.

    Args:
        ev: the surface.
        bounds: (u0, u1, v0, v1).
        direction: "u" or "v".
        points: the isolines' points (:func:`_isoline_points`) when already evaluated.

    Returns:
        The ratio in [0, 1] (1.0 when every isoline is a point).
    """
    if points is None:
        points = _isoline_points(ev, bounds, (direction,))[direction]
    lengths = [L if math.isfinite(L) else 0.0
               for L in np.linalg.norm(np.diff(points, axis=1), axis=2).sum(axis=1).tolist()]
    top = max(lengths)
    return max(lengths[0], lengths[-1]) / top if top > 0 else 1.0


def best_effort_direction(info: dict[str, float], label: str) -> str:
    """Ruling direction for flattening a non-ruled face: the boundary isolines ``S(·, v0)``,
    ``S(·, v1)`` (rulings along v) must be distinct curves, i.e. the v-isolines must be open, and
    must not both be points (``end_length_u`` > 1e-6, :func:`end_isoline_length`: rulings
    between the two poles of a full sphere span no area). Among directions whose isolines are
    clearly open (chord ≥ 1 % of the length), else merely open (chord > 1e-6 of the length), the
    straighter one is used.

    Raises:
        DegenerateGeometryError: no direction qualifies (a torus: isolines closed both ways; a
            full sphere: meridians open but both latitude ends are poles): there are no two
            distinct boundary curves to span rulings between.
    """
    other = {"u": "v", "v": "u"}
    spans = [d for d in ("v", "u") if info.get(f"end_length_{other[d]}", 1.0) > 1e-6]
    for lim in (1e-2, 1e-6):
        cands = [d for d in spans if info[f"openness_{d}"] >= lim]
        if cands:
            return min(cands, key=lambda d: info[f"deviation_{d}"])
    why = []
    if info["openness_u"] < 1e-6 and info["openness_v"] < 1e-6:
        why.append(
            f"its isolines are closed in both directions (chord/length {info['openness_u']:.3g} (u) and "
            f"{info['openness_v']:.3g} (v); allowed > 1e-6)"
        )
    for d in ("u", "v") if not why else ():
        if info[f"openness_{d}"] < 1e-6:
            why.append(f"its {d}-isolines are closed (chord/length {info[f'openness_{d}']:.3g}; allowed > 1e-6)")
        elif d not in spans:
            why.append(
                f"its {d}-isolines run between two points (both end {other[d]}-isolines are points: length "
                f"ratio {info[f'end_length_{other[d]}']:.3g}; allowed > 1e-6)"
            )
    raise DegenerateGeometryError(
        f"face {label!r} is not ruled (its isolines deviate from straight lines by "
        f"{info['deviation_u']:.3g} (u-isolines) and {info['deviation_v']:.3g} (v-isolines) relative to "
        "their lengths; allowed 1e-9) and cannot be flattened even with best_effort=True: "
        + " and ".join(why)
        + ", so it has no two distinct boundary curves to span rulings between; split the face (e.g. cut "
        "a torus or a sphere into sectors) first"
    )
