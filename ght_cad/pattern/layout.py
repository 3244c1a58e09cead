"""Laying flat panels out on a sheet, and the matching marks of the edges two panels share.

Moved from :mod:`ght_cad.pattern.flat_pattern` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from ..core.errors import GHTError
from ..core._vec import einsum as _einsum
from ..core._vec import stack as _stack
from .model import BoundaryEdge, FlatPanel, _inside


#: 3-D arc-length fractions of the edge-mark ticks (double tick near the start)
MARK_FRACTIONS = (0.2, 0.25, 0.5, 0.75)


def layout_panels(panels: Sequence[FlatPanel], gap: float | None = None) -> None:
    """Place panels in rows (shelves) along +x, ``gap`` between bounding boxes (in place).

    Up to four panels stay in one row; with more, a row is closed when it would exceed
    ``max(widest panel, 1.5 sqrt(Σ bbox areas))``, so the sheet stays roughly square.
    """
    sizes = [p.bbox() for p in panels]
    big = max(float(np.max(hi - lo)) for lo, hi in sizes)
    g = 0.05 * big if gap is None else float(gap)
    if not (math.isfinite(g) and g >= 0):
        raise GHTError(f"gap={gap!r} is not allowed; it must be a finite length >= 0")
    dims = [hi - lo for lo, hi in sizes]
    row_width = max(max(float(d[0]) for d in dims), 1.5 * math.sqrt(sum(float(d[0] * d[1]) for d in dims)))
    if len(panels) <= 4:
        row_width = math.inf
    x = 0.0
    y = 0.0
    row_h = 0.0
    for p, (lo, hi) in zip(panels, sizes):
        w, h = float(hi[0] - lo[0]), float(hi[1] - lo[1])
        if x > 0 and x + w > row_width:
            y -= row_h + g
            x, row_h = 0.0, 0.0
        p.translate(np.array([x - lo[0], y - hi[1]]))
        x += w + g
        row_h = max(row_h, h)


def _polyline_param(poly: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of pts to polyline and fractional sample index of the nearest point."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    den = np.maximum(_einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(_einsum("kij,ij->ki", pts[:, None, :] - a[None], ab) / den, 0, 1)
    proj = a[None] + t[..., None] * ab[None]
    dist = np.linalg.norm(pts[:, None, :] - proj, axis=2)
    j = np.argmin(dist, axis=1)
    return dist[np.arange(len(pts)), j], j + t[np.arange(len(pts)), j]


def _interp_polyline(poly: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Point and unit tangent at fractional sample index s."""
    i = np.clip(np.floor(s).astype(int), 0, len(poly) - 2)
    f = s - i
    p = poly[i] + f[:, None] * (poly[i + 1] - poly[i])
    t = poly[i + 1] - poly[i]
    return p, t / np.linalg.norm(t, axis=1, keepdims=True)


def _sagitta3(poly: np.ndarray) -> float:
    """Chord-to-curve deviation estimate of an open 3-D polyline: a quarter of the largest
    distance of a vertex from its neighbours' chord (κ h²/8 for spacing h)."""
    if len(poly) < 3:
        return 0.0
    a, b, c = poly[:-2], poly[1:-1], poly[2:]
    ac = c - a
    n = np.linalg.norm(ac, axis=1)
    ok = n > 0
    d = np.linalg.norm(np.cross(b - a, ac), axis=1)[ok] / n[ok]
    return float(d.max() / 4) if d.size else 0.0


def _shared_edge_candidates(boxes: np.ndarray, radii: np.ndarray) -> list[np.ndarray]:
    r"""Per edge i, the edges j > i (ascending) whose 3-D bounding boxes could pass the shared-edge test.

    Two edges within Hausdorff distance ``tol`` of each other (every sample of each within ``tol``
    of the other polyline, which lies in its own bounding box) have bounding boxes
    ``[lo, hi]`` with ``|lo_i - lo_j|_∞ <= tol`` and ``|hi_i - hi_j|_∞ <= tol``: the 6-vectors
    ``(lo, hi)`` are within ``tol`` in the max norm. With ``tol_ij = max(r_i, r_j)``, a ball of
    radius ``r_i`` around every edge's 6-vector (a k-d tree, ``scipy.spatial.cKDTree``) finds
    every such pair from the edge with the larger radius: a superset of the pairs that pass,
    found in ``O(n log n)`` for edges spread in space (instead of all ``n (n - 1) / 2`` pairs).

    Args:
        boxes: (n, 6) ``(lo, hi)`` per edge.
        radii: (n,) search radius per edge (already widened for round-off).

    Returns:
        n int arrays, sorted.
    """
    from scipy.spatial import cKDTree

    n = len(boxes)
    if n == 0:
        return []
    tree = cKDTree(boxes)
    hits = tree.query_ball_point(boxes, r=radii, p=np.inf)
    a = np.repeat(np.arange(n), [len(h) for h in hits])
    b = np.concatenate([np.asarray(h, dtype=np.intp) for h in hits]) if n else np.zeros(0, np.intp)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keep = lo != hi
    pairs = np.unique(_stack([lo[keep], hi[keep]], axis=1), axis=0) if keep.any() else np.zeros((0, 2), np.intp)
    starts = np.searchsorted(pairs[:, 0], np.arange(n + 1))
    return [pairs[starts[i]:starts[i + 1], 1] for i in range(n)]


def shared_edge_pairs(panels: Sequence[FlatPanel], rel_tol: float = 1e-5) -> list[tuple[int, BoundaryEdge, int, BoundaryEdge]]:
    """Boundary edges shared in 3-D by two panels (or the two sides of a seam in one panel).

    Two edges match when every 3-D sample of each lies within ``rel_tol`` · model size (plus the
    polyline sagitta) of the other. Edges are paired greedily in boundary order (edge i with the
    first unpaired j > i that matches). Candidate pairs come from a k-d tree over the edges'
    bounding boxes (:func:`_shared_edge_candidates`), so the cost grows like ``n log n`` with the
    number of edges for panels spread in space; the pairs are exactly those of testing all pairs.

    Returns:
        ``(panel index, edge, panel index, edge)`` per shared edge, in boundary order.
    """
    allpts = np.concatenate([e.xyz for p in panels for lp in p.loops for e in lp], axis=0)
    size = float(np.max(allpts.max(axis=0) - allpts.min(axis=0)))
    pairs: list[tuple[int, BoundaryEdge, int, BoundaryEdge]] = []
    items = [(pi, e) for pi, p in enumerate(panels) for lp in p.loops for e in lp]
    sags = [_sagitta3(e.xyz) for _, e in items]
    used: set[int] = set()
    # cheap prefilter on the end points (either direction; closed edges must both be closed); the
    # exact test below runs on the survivors only
    starts = np.array([e.xyz[0] for _, e in items]).reshape(-1, 3)
    ends = np.array([e.xyz[-1] for _, e in items]).reshape(-1, 3)
    gap = np.linalg.norm(starts - ends, axis=1)
    sag = np.asarray(sags, dtype=float)
    live = np.array([e.length_3d != 0 for _, e in items], dtype=bool)
    boxes = np.array([np.concatenate([e.xyz.min(axis=0), e.xyz.max(axis=0)]) for _, e in items]).reshape(-1, 6)
    base = rel_tol * size
    # widened by 1e-6 relative and 1e-12 model sizes: round-off in the distances of the exact test
    cands = _shared_edge_candidates(boxes, (base + sag) * (1 + 1e-6) + 1e-12 * size)

    def dist(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return np.linalg.norm(q - p, axis=1)

    for i in range(len(items)):
        if not live[i] or i in used:
            continue
        js = cands[i]
        if not js.size:
            continue
        tols = base + np.maximum(sag[i], sag[js])
        c1 = gap[i] <= tols
        ok = live[js] & (c1 == (gap[js] <= tols))
        fwd = np.maximum(dist(starts[i], starts[js]), dist(ends[i], ends[js]))
        bwd = np.maximum(dist(starts[i], ends[js]), dist(ends[i], starts[js]))
        ok &= c1 | (np.minimum(fwd, bwd) <= tols)
        for j in js[ok].tolist():
            (pi, e1), (pj, e2) = items[i], items[j]
            if i in used or j in used:
                continue
            tol = base + max(sags[i], sags[j])
            d12, _ = _polyline_param(e2.xyz, e1.xyz)
            if d12.max() > tol:
                continue
            d21, _ = _polyline_param(e1.xyz, e2.xyz)
            if d21.max() > tol:
                continue
            used.update((i, j))
            pairs.append((pi, e1, pj, e2))
    return pairs


def mark_shared_edges(panels: Sequence[FlatPanel], rel_tol: float = 1e-5) -> int:
    """Give boundary edges shared in 3-D by two panels matching marks (in place).

    The edges of :func:`shared_edge_pairs` (every 3-D sample of each within ``rel_tol`` · model
    size, plus the polyline sagitta, of the other). Both get a label ``E<k>`` and ticks across the
    edge at the points of 3-D arc-length fraction 0.2, 0.25, 0.5, 0.75 (the same 3-D points on
    both panels; the double tick near the start makes the joining direction unambiguous). Ticks
    reach ``tick = min(0.02 × largest panel extent, 0.1 × smallest extent of this panel)`` to each
    side of the edge; the label, ``1.5 tick`` high, sits ``3 tick`` inside the panel.

    Returns:
        Number of shared edges found.
    """
    pairs = shared_edge_pairs(panels, rel_tol)
    if not pairs:
        return 0
    tick_all = 0.02 * max(float(np.max(hi - lo)) for lo, hi in (p.bbox() for p in panels))
    for k, (pi, e1, pj, e2) in enumerate(pairs, start=1):
        cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(e1.xyz, axis=0), axis=1))])
        frac_idx = np.interp(np.array(MARK_FRACTIONS) * cum[-1], cum, np.arange(len(cum)))
        p3, _ = _interp_polyline(e1.xyz, frac_idx)
        _, s2 = _polyline_param(e2.xyz, p3)
        for panel, edge, s in ((panels[pi], e1, frac_idx), (panels[pj], e2, s2)):
            loops = panel.loop_polylines()
            lo, hi = panel.bbox()
            tick = min(tick_all, 0.1 * float(np.min(hi - lo)))  # a narrow panel gets smaller marks
            pos, tan = _interp_polyline(edge.flat + panel.offset, s)
            nrm = _stack([-tan[:, 1], tan[:, 0]], axis=1)
            probe = pos[2] + 2 * tick * nrm[2]
            if not _inside(probe[None], loops)[0]:
                nrm = -nrm
            for q, nv in zip(pos, nrm):
                panel.marks.append(np.array([q - tick * nv, q + tick * nv]))
            tp = pos[2] + 3 * tick * nrm[2]
            panel.texts.append((float(tp[0]), float(tp[1]), f"E{k}", 1.5 * tick))
    return len(pairs)
