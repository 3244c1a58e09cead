r"""Flat-pattern outlines for CAM: every boundary edge as straight lines and circular arcs.

A developed boundary edge is known exactly only as a function ``t -> (x, y)`` (the development
map along the edge). For cutting it is written as a chain of line and arc segments, each given by
its start point, end point and DXF *bulge* ``b = tan(θ/4)`` (θ the signed sweep, > 0
counter-clockwise, 0 for a straight segment):

* **Detection of exact lines and arcs.** An edge whose densely evaluated points lie on one line or
  one circle within :data:`EXACT_REL` of the pattern's size (a straight ruling, a cone's rail
  developed to a circular arc, a cylinder's circle developed to a line) is written as that single
  line or arc (a closed circle as two half circles; arcs of at most 180°): its area and corners are those of the exact
  development.
* **Other curves: arc splines within a chord tolerance.** The edge's parameter range is cut
  adaptively into pieces ``[t0, t1]``; on each the arc through the three curve points at ``t0``,
  ``(t0 + t1)/2`` and ``t1`` is kept when the curve's points at eight more parameters of the piece
  (1/8, 3/16, 1/4, 3/8 and their mirrors) lie within ``0.9 chord_tol`` of it, else the piece is
  halved (the arc's error is nearly cubic in the piece's parameter, largest at 0.211, where the
  check at 3/16 sees 99 % of it). The arc interpolates three points,
  so its deviation is O(h³) and changes sign along the piece: the enclosed area converges far
  faster than a polyline's (whose chords all cut the same side of a convex curve).

Corners are the development's own edge end points: consecutive edges share them exactly.

Geometry of one segment (chord ``c = p1 - p0``, ``L = |c|``, midpoint ``m``, left normal
``n = rot90(c)/L``, sweep ``θ = 4 atan b``, signed curvature ``κ = 2 sin(θ/2) / L``): the circle
is ``|q - m - n cos(θ/2)/κ| = 1/|κ|`` and the distance of a point q from it is, to first order,
``g(q) = κ (|q - m|² - L²/4) / 2 - cos(θ/2) (q - m)·n`` (the straight line's distance for κ = 0,
no division by κ). The arc through ``p0, pm, p1`` has ``θ = 2α`` with α the turning angle of
``p0 -> pm -> p1`` (inscribed angle theorem), hence ``b = tan(α/2) = (d1 × d2) / (|d1||d2| + d1·d2)``.
The segment's signed area between chord and arc is ``A = L² (θ - sin θ) / (8 sin²(θ/2))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ..core.errors import GHTError

__all__ = ["EXACT_REL", "ArcChain", "arc_chain", "bulge_deviation", "bulge_polygon_area", "three_point_bulge"]

#: relative tolerance (of the pattern's size) under which an edge is taken as an exact line or arc
EXACT_REL = 1e-12

#: check parameters inside a piece [t0, t1] (fractions of its length), besides t0, the middle, t1
_CHECK = np.array([0.125, 0.1875, 0.25, 0.375, 0.625, 0.75, 0.8125, 0.875])
#: the checks must see at most this share of the tolerance: a three-point arc's error is nearly
#: cubic, ``k s (s - ½)(s - 1)``, whose largest size (at s = 0.211) the check at 3/16 sees to 99 %;
#: the margin covers the higher-order terms (hypothesis found a curve whose error the checks at
#: 1/8, 1/4 alone underestimated by 5.5 %)
_SAFETY = 0.9
#: initial pieces per smooth stretch of an edge (between its breaks)
_START_PIECES = 8
#: largest bulge of one written arc (a merged exact arc is split above it): 180°, bulge tan(45°)
_MAX_BULGE = 1.0 + 1e-12
#: pieces per edge beyond which the chord tolerance is refused as unreachable
_MAX_PIECES = 1 << 17


@dataclass
class ArcChain:
    """One edge as line/arc segments.

    Attributes:
        points: (k + 1, 2) segment end points, ``points[0]`` / ``points[-1]`` the edge's ends.
        bulges: (k,) DXF bulges ``tan(θ/4)`` of the segments (0: straight).
        kind: ``"line"`` or ``"arc"`` (the edge is exactly one line/circle arc), ``"arcs"`` (exactly
            several lines/arcs, e.g. a closed circle), ``"curve"`` (an arc
            spline within the chord tolerance) or ``"point"`` (zero-length edge, no segment).
        deviation: largest checked distance of the edge's points from the segments.
    """

    points: np.ndarray
    bulges: np.ndarray
    kind: str
    deviation: float


def three_point_bulge(p0: np.ndarray, pm: np.ndarray, p1: np.ndarray) -> np.ndarray:
    """Bulge ``tan(α/2) = (d1 × d2) / (|d1||d2| + d1·d2)`` of the arc ``p0 -> pm -> p1``
    (``d1 = pm - p0``, ``d2 = p1 - pm``, α their turning angle); (n, 2) inputs, (n,) output
    (0 where a point repeats)."""
    d1, d2 = pm - p0, p1 - pm
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    den = np.hypot(d1[:, 0], d1[:, 1]) * np.hypot(d2[:, 0], d2[:, 1]) + d1[:, 0] * d2[:, 0] + d1[:, 1] * d2[:, 1]
    out = np.zeros_like(cross)
    np.divide(cross, den, out=out, where=den > 0)
    return out


def bulge_deviation(p0: np.ndarray, p1: np.ndarray, b: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Distances of points q (n, m, 2) from the segments ``(p0, p1, b)`` ((n, 2), (n, 2), (n,);
    sweeps of at most 180°): the largest of ``|g(q)|`` (module doc: the distance from the circle
    or line), the overshoot of q's projection beyond the chord's ends and q's distance beyond the
    chord on the side away from the arc (a segment of at most 180° lies over its chord, on its
    bulge side: the last two are lower bounds of the distance to the segment, and catch a curve
    that runs back along the circle; a piece with p0 = p1: the distance from that point).
    Returns (n, m)."""
    c = p1 - p0
    L = np.hypot(c[:, 0], c[:, 1])
    Ls = np.where(L > 0, L, 1.0)
    half = 2.0 * np.arctan(b)  # θ/2
    kappa = 2.0 * np.sin(half) / Ls
    u = c / Ls[:, None]
    d = q - (0.5 * (p0 + p1))[:, None, :]
    dd = d[..., 0] ** 2 + d[..., 1] ** 2
    dn = d[..., 1] * u[:, None, 0] - d[..., 0] * u[:, None, 1]  # (q - m)·n, n = rot90(u)
    du = d[..., 0] * u[:, None, 0] + d[..., 1] * u[:, None, 1]  # along the chord from its middle
    g = np.abs(0.5 * kappa[:, None] * (dd - 0.25 * (L * L)[:, None]) - np.cos(half)[:, None] * dn)
    over = np.where((L > 0)[:, None], np.abs(du) - 0.5 * L[:, None], np.sqrt(dd))  # a closed piece: from its point
    wrong = np.sign(b)[:, None] * dn  # b > 0 (counter-clockwise): the arc lies on the side of -n
    return np.maximum(g, np.maximum(over, wrong))


def bulge_segment_area(p0: np.ndarray, p1: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Signed areas ``L² (θ - sin θ) / (8 sin²(θ/2))`` between the chords and arcs (θ = 4 atan b;
    series ``L² θ / 12 (1 - θ²/... )`` for |θ| < 1e-3, exact 0 for b = 0)."""
    c = p1 - p0
    L2 = c[:, 0] ** 2 + c[:, 1] ** 2
    th = 4.0 * np.arctan(b)
    small = np.abs(th) < 1e-3
    s2 = np.sin(0.5 * th) ** 2
    ths = np.where(small, 1.0, th)
    exact = L2 * (ths - np.sin(ths)) / (8.0 * np.where(small, 1.0, s2))
    # θ - sin θ = θ³/6 - θ⁵/120 + ..., 8 sin²(θ/2) = 2 θ² (1 - θ²/12 + ...): ratio θ/12 (1 + θ²/60 ...)
    series = L2 * th / 12.0 * (1.0 + th * th / 60.0)
    return np.where(small, series, exact)


def bulge_polygon_area(points: np.ndarray, bulges: np.ndarray) -> float:
    """Signed area of the closed chain ``points[i] -> points[i+1 mod n]`` with bulges: the
    shoelace sum of the vertices plus every segment's chord-to-arc area."""
    p = np.asarray(points, dtype=float)
    q = np.concatenate([p[1:], p[:1]])
    x, y = p[:, 0] - p[0, 0], p[:, 1] - p[0, 1]
    xq, yq = q[:, 0] - p[0, 0], q[:, 1] - p[0, 1]
    return 0.5 * float(np.sum(x * yq - xq * y)) + float(np.sum(bulge_segment_area(p, q, np.asarray(bulges, float))))


def _fit_pieces(evaluate: Callable[[np.ndarray], np.ndarray], t0: np.ndarray, t1: np.ndarray, p0: np.ndarray,
                p1: np.ndarray, tol: float) -> tuple[np.ndarray, ...]:
    """Adaptive 3-point arcs on the pieces [t0, t1] (ends p0, p1): halve every piece whose eight
    check points lie farther than ``_SAFETY tol`` from its arc (or whose sweep exceeds 180°), one
    ``evaluate`` call per level. Returns t0, p0, p1, bulge, mid points (n, 2), check points
    (n, 8, 2) and deviations of the accepted pieces, sorted by t0."""
    keep: list[tuple[np.ndarray, ...]] = []
    while t0.size:
        h = t1 - t0
        tm = t0 + 0.5 * h
        tq = t0[:, None] + h[:, None] * _CHECK[None, :]
        pts = evaluate(np.concatenate([tm, tq.ravel()]))
        n = t0.size
        pm, pq = pts[:n], pts[n:].reshape(n, _CHECK.size, 2)
        b = three_point_bulge(p0, pm, p1)
        dev = bulge_deviation(p0, p1, b, pq).max(axis=1)
        # a piece on which the edge stands still (a fan's apex inside an edge: its points are rounding
        # noise, their 3-point arc any bulge at all): every point within tol/10 of p0 -> a line, which
        # then lies within tol/10 of every point
        still = np.max(np.abs(np.concatenate([pm[:, None], pq, p1[:, None]], axis=1) - p0[:, None]), axis=(1, 2)) \
            <= 0.05 * tol
        if still.any():
            b = np.where(still, 0.0, b)
            dev = np.where(still, bulge_deviation(p0, p1, b, pq).max(axis=1), dev)
        ok = (dev <= _SAFETY * tol) & (np.abs(b) <= _MAX_BULGE)
        ok |= h <= 1e-15  # nothing left to split (a stationary or singular spot): keep as is
        if ok.any():
            keep.append((t0[ok], p0[ok], p1[ok], b[ok], pm[ok], pq[ok], dev[ok]))
        bad = ~ok
        if not bad.any():
            break
        t0 = np.concatenate([t0[bad], tm[bad]])
        t1 = np.concatenate([tm[bad], t1[bad]])
        p0, p1 = np.concatenate([p0[bad], pm[bad]]), np.concatenate([pm[bad], p1[bad]])
        if t0.size + sum(k[0].size for k in keep) > _MAX_PIECES:
            raise GHTError(f"chord_tol={tol:.3g} cannot be met within {_MAX_PIECES} arcs per edge; "
                           "allowed: a chord tolerance above the development's rounding (about 1e-12 of the size)")
    cat = [np.concatenate(parts) for parts in zip(*keep)]
    order = np.argsort(cat[0], kind="stable")
    return tuple(a[order] for a in cat)


def _merge_runs(p0: np.ndarray, p1: np.ndarray, b: np.ndarray, checks: np.ndarray, exact_tol: float
                ) -> list[tuple[int, int, float]]:
    """Group consecutive pieces lying on one circle (or line) within ``exact_tol``: returns
    ``(first, last + 1, bulge)`` per written segment; a merged run's bulge is that of the arc
    through its first start, a joint and its last end, kept when all the run's check points lie
    within ``exact_tol`` of it and its sweep is at most 180° (:data:`_MAX_BULGE`)."""
    n = b.size
    if n > 1:  # adjacent pairs on one circle (vectorized pre-test)
        pb = three_point_bulge(p0[:-1], p1[:-1], p1[1:])
        q = np.concatenate([checks[:-1], checks[1:]], axis=1)
        pair = bulge_deviation(p0[:-1], p1[1:], pb, q).max(axis=1) <= exact_tol
    else:
        pair = np.zeros(0, dtype=bool)
    out: list[tuple[int, int, float]] = []

    def run(i: int, j: int) -> None:
        if j - i == 1:
            out.append((i, j, float(b[i])))
            return
        k = (i + j) // 2
        bb = float(three_point_bulge(p0[i:i + 1], p1[k - 1:k], p1[j - 1:j])[0])
        dev = bulge_deviation(p0[i:i + 1], p1[j - 1:j], np.array([bb]), checks[i:j].reshape(1, -1, 2)).max()
        if dev <= exact_tol and abs(bb) <= _MAX_BULGE:
            out.append((i, j, bb))
        else:
            run(i, k), run(k, j)

    i = 0
    while i < n:
        j = i + 1
        while j < n and pair[j - 1]:
            j += 1
        run(i, j)
        i = j
    return out


def arc_chain(flat_fn: Callable[[np.ndarray], np.ndarray], chord_tol: float, size: float,
              breaks: Sequence[float] = (), samples: np.ndarray | None = None) -> ArcChain:
    """Lines and arcs of one edge ``t -> flat_fn(t)``, t ∈ [0, 1] (module doc).

    Args:
        flat_fn: the exact flat edge, (n,) parameters -> (n, 2) points.
        chord_tol: largest distance allowed between the edge and the arcs (model units, > 0).
        size: the pattern's size (exact lines/arcs are recognized within ``EXACT_REL · size``).
        breaks: parameters in (0, 1) where the edge is not smooth (pieces never straddle them).
        samples: optional (N + 1, 2) points ``flat_fn(k / N)`` already evaluated (reused).

    Returns:
        The :class:`ArcChain`.
    """
    if not (chord_tol > 0 and math.isfinite(chord_tol)):
        raise GHTError(f"chord_tol={chord_tol!r} is not allowed; allowed: a positive length in the pattern's units")
    exact_tol = min(EXACT_REL * size, chord_tol)
    N = 0 if samples is None else samples.shape[0] - 1

    def evaluate(t: np.ndarray) -> np.ndarray:
        if N:
            k = t * N
            idx = np.rint(k)
            if np.all(idx == k):  # on the sample grid: no evaluation
                return samples[idx.astype(np.intp)]
        return np.asarray(flat_fn(t), dtype=float)

    br = sorted(float(x) for x in breaks if 0.0 < x < 1.0)
    knots = [0.0, *br, 1.0]
    tt = np.unique(np.concatenate([np.linspace(lo, hi, _START_PIECES + 1) for lo, hi in zip(knots[:-1], knots[1:])]))
    pts = evaluate(tt)
    if float(np.max(np.abs(pts - pts[0]))) <= exact_tol:  # a zero-length edge (pointed end)
        return ArcChain(pts[[0, -1]], np.zeros(0), "point", 0.0)
    t0, p0, p1, b, pm, pq, dev = _fit_pieces(evaluate, tt[:-1], tt[1:], pts[:-1], pts[1:], chord_tol)
    checks = np.concatenate([pm[:, None, :], pq], axis=1)
    runs = _merge_runs(p0, p1, b, checks, exact_tol)
    points = np.concatenate([p0[[i for i, _, _ in runs]], p1[-1:]])
    bulges = np.array([bb for _, _, bb in runs])
    # a segment whose sagitta (L/2)|b| is within the exactness tolerance is straight
    chord = np.hypot(*(points[1:] - points[:-1]).T)
    bulges[0.5 * chord * np.abs(bulges) <= exact_tol] = 0.0
    # exact: every written segment within exact_tol (merged runs are checked so when merged)
    exact = all(j - i > 1 or dev[i] <= exact_tol for i, j, _ in runs)
    if not exact:
        kind = "curve"
    elif len(runs) == 1:
        kind = "line" if bulges[0] == 0.0 else "arc"
    else:
        kind = "arcs"
    return ArcChain(points, bulges, kind, float(dev.max()))


