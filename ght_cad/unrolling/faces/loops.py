"""A face's boundary loops in (u, v): areas, the outer loop, chaining, derivatives, edge samples and
the rulings clipped to the loops.

Moved from :mod:`ght_cad.unrolling.face_unroll` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

from typing import Any, Callable, Sequence

import numpy as np

from ...core._vec import stack as _stack
from ...core.errors import DegenerateGeometryError
from ...pattern.model import _point_in_polygon, _unit_samples, BoundaryEdge
from .area import _edge_nodes


def loop_uv_area(loop: list[tuple[Callable, Callable]]) -> float:
    r"""Signed area a loop encloses in the parameter plane, ``∮ u dv`` (16 × 12-point
    Gauss–Legendre panels per edge, split at the pcurve's knots: exact for polynomial pieces).

    Args:
        loop: per edge ``(t -> (u, v), t -> (u', v'))`` in traversal order.

    Returns:
        The signed (u, v)-area (positive counter-clockwise).
    """
    total = 0.0
    for uvf, duv in loop:
        tn, tw = _edge_nodes(getattr(duv, "breaks", None))
        u, _ = uvf(tn)
        total += float(np.sum(np.asarray(u, dtype=float) * duv(tn)[:, 1] * tw))
    return total


def outer_loop_index(loops_uv: list[list[tuple[Callable, Callable]]]) -> int:
    """Index of the outer loop of a face: the one enclosing the largest (u, v)-area
    ``|∮ u dv|`` (:func:`loop_uv_area`; the outer boundary of a face's parameter domain encloses
    its holes). 0 when there are no loops.

    Args:
        loops_uv: per loop, per edge ``(t -> (u, v), t -> (u', v'))``.

    Returns:
        The index in ``loops_uv``.
    """
    if len(loops_uv) < 2:
        return 0
    return int(np.argmax([abs(loop_uv_area(lp)) for lp in loops_uv]))


def fd_derivative(fun: Callable[[np.ndarray], np.ndarray], t: np.ndarray, breaks: Sequence[float] = (), h: float = 1e-4) -> np.ndarray:
    r"""Derivative of a piecewise-smooth ``fun: t -> (n, k)`` on [0, 1] by 5-point differences.

    Central ``(-f(t+2h) + 8 f(t+h) - 8 f(t-h) + f(t-2h)) / 12h`` (O(h⁴)) with
    ``h = min(h, d/2.5)`` where ``d`` is the distance of t to the nearest break or end, so the
    stencil never straddles a knot; at a break or end (``d < 1e-9``) the one-sided 5-point formula
    ``(-25 f0 + 48 f1 - 36 f2 + 16 f3 - 3 f4) / 12h`` (O(h⁴)) pointing into [0, 1] is used.

    Args:
        fun: the function (vectorized over t).
        t: points in [0, 1].
        breaks: interior points where ``fun`` is not smooth.
        h: largest step.

    Returns:
        (n, k) derivatives.
    """
    t = np.atleast_1d(np.asarray(t, dtype=float))
    knots = np.unique(np.concatenate([[0.0, 1.0], np.asarray(breaks, dtype=float)]))
    dist = np.min(np.abs(t[:, None] - knots[None, :]), axis=1)
    step = np.minimum(h, dist / 2.5)
    out = np.empty((t.size, np.asarray(fun(t[:1])).shape[1]))
    central = dist >= 1e-9
    if central.any():
        tc, hc = t[central], step[central][:, None]
        f = [np.asarray(fun(tc + k * hc[:, 0])) for k in (-2, -1, 1, 2)]
        out[central] = (f[0] - 8 * f[1] + 8 * f[2] - f[3]) / (12 * hc)
    if (~central).any():
        tb = t[~central]
        sgn = np.where(tb < 0.5, 1.0, -1.0)
        hb = h * sgn
        f = [np.asarray(fun(tb + k * hb)) for k in range(5)]
        out[~central] = (-25 * f[0] + 48 * f[1] - 36 * f[2] + 16 * f[3] - 3 * f[4]) / (12 * hb[:, None])
    return out


def chain_loop(
    ends: list[tuple[np.ndarray, np.ndarray]], periods: tuple[float, float], tol: float | Sequence[float]
) -> list[tuple[bool, np.ndarray]]:
    r"""Make a wire's pcurves one continuous loop in (u, v).

    A seam edge of a periodic surface has two pcurves a period apart and a kernel may hand out the
    other one (or an edge in the other direction): walking the wire, each edge is kept or reversed
    and shifted by whole periods ``(k_u P_u, k_v P_v)`` so that it starts where the previous one
    ended (within ``tol``).

    Args:
        ends: per edge its (start, end) uv points in the given direction.
        periods: (P_u, P_v), 0 for a non-periodic direction.
        tol: matching tolerance in (u, v): one number, or ``(tol_u, tol_v)`` (u and v often have
            different units, e.g. an angle and a length: give each a tolerance relative to its
            own range).

    Returns:
        Per edge ``(reverse, shift)`` (an edge matching both ways, e.g. a closed isoline spanning a
        whole period, takes the smaller shift, then its given direction). Edges that cannot be
        matched are kept as given.
    """
    P = np.asarray(periods, dtype=float)

    def shift_to(p: np.ndarray, q: np.ndarray) -> np.ndarray | None:
        d = q - p
        k = np.where(P > 0, np.round(d / np.where(P > 0, P, 1.0)), 0.0)
        s = k * P
        return s if np.all(np.abs(d - s) <= np.asarray(tol, dtype=float)) else None

    out: list[tuple[bool, np.ndarray]] = [(False, np.zeros(2))]
    if not ends:
        return []
    a0, b0 = ends[0]
    if len(ends) > 1:  # the first edge given in the other direction: the second one starts at its start
        a1, b1 = ends[1]
        if shift_to(a1, b0) is None and shift_to(b1, b0) is None and (
            shift_to(a1, a0) is not None or shift_to(b1, a0) is not None
        ):
            out[0] = (True, np.zeros(2))
            a0, b0 = b0, a0
    cur = b0
    for a, b in ends[1:]:
        fwd, rev = shift_to(a, cur), shift_to(b, cur)
        # an edge spanning a whole period matches both ways: prefer the smaller shift, then forward
        if rev is not None and (fwd is None or np.abs(rev).sum() < np.abs(fwd).sum()):
            out.append((True, rev))
            cur = a + rev
        elif fwd is not None:
            out.append((False, fwd))
            cur = b + fwd
        else:
            out.append((False, np.zeros(2)))
            cur = b
    return out


def clip_rulings_uv(polygons: Sequence[np.ndarray], c: np.ndarray, lo: float, hi: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    r"""Clip the rulings ``x = c_k``, ``y ∈ [lo, hi]`` of the parameter plane to a face's loops.

    A face's rulings are straight in its parameters (rulings along v: the lines u = c_k), so
    bend lines are clipped where they are exact: every loop edge ``A → B`` of the (u, v)
    polygons with ``(A_x <= c) != (B_x <= c)`` (half-open: a vertex on the line counts once)
    crosses at ``y = A_y + (c - A_x)(B_y - A_y) / (B_x - A_x)``; sorted along each ruling the
    crossings pair up into the inside intervals (even–odd over all loops: holes cut them), each
    clamped to [lo, hi].

    Args:
        polygons: the loops as closed (m, 2) polylines (x across the rulings, y along them).
        c: the rulings' positions, (k,).
        lo, hi: the rulings' extent along y.

    Returns:
        ``(ruling index, y0, y1)`` per inside interval, in ruling order then along y; None when
        some ruling crosses the loops an odd number of times (a polyline that is not closed).
    """
    A = np.concatenate(polygons)
    B = np.concatenate([np.concatenate([p[1:], p[:1]]) for p in polygons])
    # (A_x <= c) != (B_x <= c)  <=>  min(A_x, B_x) <= c < max(A_x, B_x): the crossing rulings of an
    # edge are a run of the sorted c, found by bisection (no rulings x edges table)
    by_c = np.argsort(c, kind="stable")
    cs = c[by_c]
    first = np.searchsorted(cs, np.minimum(A[:, 0], B[:, 0]), side="left")
    cnt = np.searchsorted(cs, np.maximum(A[:, 0], B[:, 0]), side="left") - first
    j = np.repeat(np.arange(A.shape[0]), cnt)
    k = by_c[np.repeat(first, cnt) + (np.arange(j.size) - np.repeat(np.cumsum(cnt) - cnt, cnt))]
    y = A[j, 1] + (c[k] - A[j, 0]) * (B[j, 1] - A[j, 1]) / (B[j, 0] - A[j, 0])
    order = np.lexsort((y, k))
    k, y = k[order], y[order]
    if np.any(np.bincount(k, minlength=c.size) % 2):
        return None
    k, y0, y1 = k[::2], np.maximum(y[::2], lo), np.minimum(y[1::2], hi)
    keep = y1 - y0 > 1e-12 * (hi - lo)
    return k[keep], y0[keep], y1[keep]


def _strided_memo(fun: Callable[[np.ndarray], np.ndarray]) -> Callable[[np.ndarray], np.ndarray]:
    """``fun`` (pointwise in t) remembering its last result: a parameter array equal to the last
    one or to every k-th entry of it (the outline's 257 samples after the length's 513) is
    answered by slicing (the same values, not recomputed). ``f.seed(t, r)`` stores ``r = fun(t)``
    computed elsewhere (all edges of a face in one map call, :func:`_seed_edge_samples`)."""
    last: list[Any] = [None, None]

    def f(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        t0, r0 = last
        if t0 is not None and t.ndim == 1 and t.size > 1 and t0.size >= t.size and (t0.size - 1) % (t.size - 1) == 0:
            k = (t0.size - 1) // (t.size - 1)
            if (t0[::k] == t).all():  # numpy.array_equal (same shapes here), without its overhead
                return r0[::k].copy()
        r = np.asarray(fun(t), dtype=float)
        last[0], last[1] = t.copy(), r
        return r.copy()

    def seed(t: np.ndarray, r: np.ndarray) -> None:
        last[0], last[1] = np.array(t, dtype=float), np.asarray(r, dtype=float)

    f.seed = seed  # type: ignore[attr-defined]
    return f


def _edge_sample_uv(loops: list[list[BoundaryEdge]], loops_uv: list[list[tuple[Callable, Callable]]],
                    samples: int) -> tuple[list[BoundaryEdge], np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """The edges with memos, their ``samples`` outline parameters ``t_i = i / (samples - 1)`` and
    all edges' (u, v) there, concatenated (edge by edge)."""
    edges = [(e, uvf) for loop, luv in zip(loops, loops_uv) for e, (uvf, _) in zip(loop, luv)
             if hasattr(e.flat_fn, "seed")]
    t = _unit_samples(samples)
    if not edges or samples < 2:
        return [], t, (np.zeros(0), np.zeros(0))
    uvs = [uvf(t) for _, uvf in edges]
    us = [_as_shape(u, t.shape) for u, _ in uvs]
    vs = [_as_shape(v, t.shape) for _, v in uvs]
    return [e for e, _ in edges], t, (np.concatenate(us), np.concatenate(vs))


def _c0_crossings(uvf: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], c0u: np.ndarray,
                  c0v: np.ndarray) -> tuple[float, ...]:
    """Edge parameters ``t`` in (0, 1) where a straight isoline edge (v constant and u affine in t,
    or the other way round: the rails and rulings of a B-spline face) crosses a knot line where the
    surface is only C0 (``c0u``/``c0v``, :meth:`SurfaceAdapter.c0_breaks`): ``t = (k - u(0)) /
    (u(1) - u(0))``. There the edge's parameter speed jumps (a loft's joint ruling), so its
    measures are split there (:attr:`ght_cad.pattern.flat_pattern.BoundaryEdge.breaks`). Other edges: ()."""
    u, v = (np.asarray(x, dtype=float) for x in uvf(np.array([0.0, 0.5, 1.0])))
    out: list[float] = []
    for along, fixed, ks in ((u, v, c0u), (v, u, c0v)):
        span = float(along[2] - along[0])
        if not ks.size or span == 0.0:
            continue
        tol = 1e-12 * abs(span)
        if float(np.ptp(fixed)) <= tol and abs(float(along[1]) - 0.5 * float(along[0] + along[2])) <= tol:
            t = (np.asarray(ks, dtype=float) - float(along[0])) / span
            out += [float(x) for x in t if 1e-9 < x < 1.0 - 1e-9]
    return tuple(sorted(out))


def _flat1(t: Any) -> np.ndarray:
    """``t`` as a 1-D float array (``np.atleast_1d(np.asarray(t, float)).ravel()``, the same
    array object when it is one already)."""
    t = np.asarray(t, dtype=float)
    return t if t.ndim == 1 else t.reshape(-1)


def _as_shape(x: Any, shape: tuple[int, ...]) -> np.ndarray:
    """``np.broadcast_to(np.asarray(x, float), shape)``, the array itself when it has that shape."""
    x = np.asarray(x, dtype=float)
    return x if x.shape == shape else np.broadcast_to(x, shape)


def _seed_edge_samples(edges: list[BoundaryEdge], t: np.ndarray, flat: np.ndarray) -> None:
    """Seed the edges' memos with their outline samples' flat points ``flat`` (edge by edge, as
    from :func:`_edge_sample_uv`): the same pointwise values as one map call per edge, without
    the per-call overhead."""
    n = t.size
    for k, e in enumerate(edges):
        e.flat_fn.seed(t, flat[k * n:(k + 1) * n])  # type: ignore[attr-defined]


def _loop_points(loop: list[tuple[Callable, Callable]], n: int) -> np.ndarray:
    """(u, v) points of a loop, ``n`` per edge (end points excluded), shape (m, 2)."""
    t = (np.arange(n) + 0.5) / n
    return np.concatenate([_stack([np.asarray(x, dtype=float) for x in uvf(t)], axis=1) for uvf, _ in loop])


def _check_holes_inside(loops_uv: list[list[tuple[Callable, Callable]]], label: str) -> None:
    """Every hole loop must lie inside the outer loop in (u, v) (a face's holes do; a hole outside
    means inconsistent pcurves, e.g. one shifted by a period, and would be drawn outside the
    outline while the area stays right).

    Raises:
        DegenerateGeometryError: more than half of a hole's sample points lie outside the outer loop.
    """
    if len(loops_uv) < 2:
        return
    outer = _loop_points(loops_uv[0], 64)
    for k, loop in enumerate(loops_uv[1:], start=1):
        inside = _point_in_polygon(_loop_points(loop, 8), outer)
        if inside.mean() < 0.5:
            raise DegenerateGeometryError(
                f"face {label!r}: wire {k + 1} (a hole) lies outside the outer wire in the face's (u, v) "
                f"parameters ({inside.mean():.0%} of its points inside; allowed: holes inside the outer wire): "
                "the face's pcurves are inconsistent (one shifted by a period?); repair the face (e.g. "
                "Part > Check geometry, or re-import it) before unrolling"
            )


def _with_breaks(duv: Callable[[np.ndarray], np.ndarray], breaks: np.ndarray) -> Callable[[np.ndarray], np.ndarray]:
    def f(t: np.ndarray) -> np.ndarray:
        return duv(t)

    f.breaks = np.asarray(breaks, dtype=float)  # type: ignore[attr-defined]
    return f
