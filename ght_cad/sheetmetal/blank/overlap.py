r"""Overlap detection: crossing outline segments, and the overlap area of crossing faces by
Green's theorem. Moved from ``ght_cad/sheetmetal/blank.py`` (issue 27); every name is importable from
:mod:`ght_cad.sheetmetal.blank`."""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from .placement import _Motion


def _segments(polys: Sequence[np.ndarray]) -> np.ndarray:
    return np.concatenate([np.stack([p, np.roll(p, -1, axis=0)], axis=1) for p in polys], axis=0)


def _crossings(segs: np.ndarray, eps: float) -> np.ndarray:
    """Index pairs (i, j), i < j, of segments that cross properly (interior points, beyond ``eps``
    of their ends in parameter)."""
    p, r = segs[:, 0], segs[:, 1] - segs[:, 0]
    n = len(segs)
    i, j = np.triu_indices(n, 1)
    # bounding boxes first
    lo = np.minimum(segs[:, 0], segs[:, 1])
    hi = np.maximum(segs[:, 0], segs[:, 1])
    ok = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    i, j = i[ok], j[ok]
    den = r[i, 0] * r[j, 1] - r[i, 1] * r[j, 0]
    w = p[j] - p[i]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (w[:, 0] * r[j, 1] - w[:, 1] * r[j, 0]) / den
        t = (w[:, 0] * r[i, 1] - w[:, 1] * r[i, 0]) / den
    hit = (np.abs(den) > 1e-300) & (s > eps) & (s < 1 - eps) & (t > eps) & (t < 1 - eps)
    return np.stack([i[hit], j[hit]], axis=1)


def _oriented(loops: Sequence[np.ndarray]) -> list[np.ndarray]:
    """A region's loops with the outer loop counter-clockwise and the holes clockwise."""
    from ...pattern.flat_pattern import _shoelace

    out = []
    for i, lp in enumerate(loops):
        ccw = _shoelace(lp) > 0
        out.append(lp if ccw == (i == 0) else lp[::-1])
    return out


def _overlap_area(a: Sequence[np.ndarray], b: Sequence[np.ndarray]) -> float:
    r"""Area of the intersection of two polygonal regions (loops: outer first, then holes) by
    Green's theorem: ``∂(A ∩ B) = (∂A ∩ B) ∪ (∂B ∩ A)``, so with ``∂A``, ``∂B`` oriented (outer
    loop counter-clockwise, holes clockwise)

        area(A ∩ B) = ½ Σ_{s ⊂ ∂A ∩ B} (x_0 y_1 - x_1 y_0) + ½ Σ_{s ⊂ ∂B ∩ A} (x_0 y_1 - x_1 y_0),

    the boundary segments clipped to the other region (:func:`ght_cad.pattern.flat_pattern.clip_segments`).
    Exact for the polygons (the outline polylines of the faces)."""
    from ...pattern.flat_pattern import clip_segments

    total = 0.0
    for p, q in ((a, b), (b, a)):
        segs = clip_segments(_segments(_oriented(p)), list(q))
        if len(segs):
            total += 0.5 * float(np.sum(segs[:, 0, 0] * segs[:, 1, 1] - segs[:, 1, 0] * segs[:, 0, 1]))
    return total


def _overlaps(loops: list[list[Any]], panels: dict[int, Any], motion: dict[int, _Motion],
              order: list[int]) -> tuple[str, float] | None:
    """None when the blank's loops do not cross each other or themselves; else (the faces whose
    edges cross, the overlap area). The area is the sum over the pairs of distinct faces whose
    edges cross of their placed outlines' intersection area (:func:`_overlap_area`, exact for the
    outline polygons); a face crossing only itself is estimated on a 200 x 200 grid over the
    blank's box (cells covered twice)."""
    from ...pattern.flat_pattern import _inside

    polys, owner = [], []
    for loop in loops:
        pts, who = [], []
        for e in loop:
            q = e.flat_fn(np.linspace(0.0, 1.0, 33))[:-1]
            pts.append(q)
            who.extend([e.name.split(":", 1)[0]] * len(q))
        polys.append(np.concatenate(pts, axis=0))
        owner.append(who)
    allpts = np.concatenate(polys)
    segs = _segments(polys)
    cross = _crossings(segs, 1e-9)
    # a crossing closer than 1e-9 of the size to a segment end is a touching joint, not an overlap
    if not len(cross):
        return None
    names = [w for who in owner for w in who]
    faces = sorted({names[a] for a, b in cross} | {names[b] for a, b in cross}, key=lambda s: int(s[1:]))
    placed = {n: [motion[n](lp) for lp in panels[n].loop_polylines()] for n in order}
    pairs = sorted({tuple(sorted((int(names[a][1:]), int(names[b][1:])))) for a, b in cross})
    distinct = [(i, j) for i, j in pairs if i != j]
    if distinct:
        return ", ".join(faces), float(sum(_overlap_area(placed[i], placed[j]) for i, j in distinct))
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    g = 200
    xs = lo[0] + (np.arange(g) + 0.5) / g * (hi[0] - lo[0])
    ys = lo[1] + (np.arange(g) + 0.5) / g * (hi[1] - lo[1])
    X, Y = np.meshgrid(xs, ys)
    pts = np.stack([X.ravel(), Y.ravel()], axis=1)
    count = np.zeros(len(pts), dtype=int)
    for n in order:
        count += _inside(pts, placed[n]).astype(int)
    cell = (hi[0] - lo[0]) * (hi[1] - lo[1]) / g ** 2
    return ", ".join(faces), float((count > 1).sum() * cell)
