"""The 3-D area of a trimmed face by Green's theorem in (u, v) with Gauss-Legendre quadrature.

Moved from :mod:`ght_cad.unrolling.face_unroll` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from typing import Any, Callable

import numpy as np

from ...core._cache import readonly_cache
from ...core._quadrature import leggauss
from ...core._vec import cross as _cross, norm as _norm, stack as _stack
from .adapter import SurfaceAdapter, U_FREE_DENSITY_KINDS


def _gauss12() -> tuple[np.ndarray, np.ndarray]:
    """12-point Gauss–Legendre nodes and weights on [-1, 1] (:func:`ght_cad.core._quadrature.leggauss`:
    computed once; read-only arrays)."""
    return leggauss(12)


def face_area(
    ev: SurfaceAdapter,
    edges_uv: list[list[tuple[Callable, Callable]]],
    u_lo: float,
    u_breaks: np.ndarray,
    u_span: float | None = None,
) -> float:
    r"""3-D area ``∬_Ω |S_u × S_v| du dv`` of a trimmed face by Green's theorem in (u, v).

    ``∬_Ω f du dv = ∮_{∂Ω} P dv`` with ``P(u, v) = ∫_{u_lo}^{u} f(s, v) ds``: the outer integral by
    16 × 12-point Gauss–Legendre panels along each pcurve (split at the pcurve's knots, the
    ``breaks`` attribute of ``duv``), the inner one by 12-point panels, at least 2 per interval
    between ``u_breaks`` (the surface's knots) and none wider than ``u_span / 8`` (an analytic
    but non-polynomial ``f``, e.g. an extruded ellipse over its whole period), i.e. exact up to
    the smoothness of ``f``. On a plane, cylinder or cone (``ev.kind``; u the angle about the axis)
    ``f`` does not depend on u and ``P(u, v) = (u - u_lo) f(u_lo, v)`` in closed form. Along an
    edge with constant u (an isoline of the parameter box) every node has the same inner nodes:
    the density is evaluated on that grid (``ev.density_grid(s, v)`` when the adapter has it).

    Args:
        ev: the surface (``d1``).
        edges_uv: per loop, per edge ``(t -> (u, v), t -> (u', v'))``.
        u_lo: lower limit of the inner integral (any u; the face's u0).
        u_breaks: the surface's u breaks.
        u_span: the face's u range ``u1 - u0`` (None: no width limit for the inner panels).

    Returns:
        ``|I_0| - Σ_{k≥1} |I_k|`` where ``I_k = ∮_{loop k} P dv`` (the first loop is the outer
        one, the others holes): independent of the loops' orientations.
    """
    xg, wg = _gauss12()
    u_breaks = np.asarray(u_breaks, dtype=float)
    # outer nodes of every edge of every loop; then one surface evaluation for all inner nodes
    parts = []  # (loop, outer weights dv * tw, u, v) per edge
    for k, loop in enumerate(edges_uv):
        for uvf, duv in loop:
            tn, tw = _edge_nodes(getattr(duv, "breaks", None))
            dv = duv(tn)[:, 1]
            if not dv.any():
                continue
            u, v = uvf(tn)
            parts.append((k, dv * tw, np.asarray(u, dtype=float), np.asarray(v, dtype=float)))
    totals = [0.0] * len(edges_uv)
    if not parts:
        return 0.0
    u = np.concatenate([p[2] for p in parts])
    v = np.concatenate([p[3] for p in parts])
    if getattr(ev, "kind", "other") in U_FREE_DENSITY_KINDS:
        # |S_u × S_v| does not depend on u: P(u, v) = (u - u_lo) f(u_lo, v) exactly
        d = ev.d1(np.full_like(v, u_lo), v)
        P = (u - u_lo) * np.linalg.norm(np.cross(d[0], d[1]), axis=1)
    else:
        P = np.zeros(u.size)
        general = np.ones(u.size, dtype=bool)
        grid = getattr(ev, "density_grid", None)
        i = 0
        for _, _, uu, vv in parts if grid is not None else ():
            m = uu.size
            if m and (uu == uu[0]).all():  # an edge along v (u constant): its inner nodes are shared
                # (none on u = u_lo, where P = 0)
                s_n, w_n = _inner_nodes_at(float(uu[0]), u_lo, u_breaks, u_span) if uu[0] != u_lo else (np.zeros(0),) * 2
                if s_n.size:
                    f = grid(s_n, vv)
                    P[i:i + m] = w_n @ f
                general[i:i + m] = False
            i += m
        if general.any():
            ug, vg = u[general], v[general]
            if grid is not None and getattr(ev, "fast_density_grid", False):
                P[general] = _inner_integrals_by_pieces(ev, ug, vg, u_lo, u_breaks, u_span)
            else:
                P[general] = _inner_integrals(ev, ug, vg, u_lo, u_breaks, u_span)
    i = 0
    for k, wdv, uu, _ in parts:
        totals[k] += float(np.sum(P[i:i + uu.size] * wdv))
        i += uu.size
    totals = [abs(t) for t in totals]
    return totals[0] - sum(totals[1:]) if totals else 0.0


@readonly_cache(maxsize=1)
def _edge_nodes_plain() -> tuple[np.ndarray, np.ndarray]:
    """:func:`_edge_nodes` without breaks (computed once; read-only arrays)."""
    return _edge_nodes_at(np.linspace(0.0, 1.0, 17))


def _edge_nodes_at(te: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    xg, wg = _gauss12()
    h = 0.5 * np.diff(te)
    return ((0.5 * (te[:-1] + te[1:])[:, None] + h[:, None] * xg[None, :]).ravel(), (h[:, None] * wg[None, :]).ravel())


def _edge_nodes(breaks: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights along an edge, t ∈ [0, 1]: 16 equal panels, also cut at
    the pcurve's ``breaks``, 12 points each."""
    if breaks is None or not len(breaks):
        return _edge_nodes_plain()
    return _edge_nodes_at(np.unique(np.concatenate([np.linspace(0.0, 1.0, 17), breaks])))


def _inner_nodes_at(u: float, u_lo: float, u_breaks: np.ndarray, u_span: float | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_inner_nodes` of one u (an edge with constant u): the nodes ``s`` and weights ``w``
    of ``∫_{u_lo}^{u} f(s, v) ds``, by the same panels and the same arithmetic, with the panel
    ends made in plain floats (one u: the array bookkeeping cost more than the nodes)."""
    xg, wg = _gauss12()
    lo, hi = min(u, u_lo), max(u, u_lo)
    sign = 1.0 if u >= u_lo else -1.0
    cuts = [lo, *sorted(b for b in np.asarray(u_breaks, dtype=float).tolist() if lo < b < hi), hi]
    a_s, b_s = [], []
    for a, b in zip(cuts[:-1], cuts[1:]):
        m = 0.5 * (a + b)
        for x0, x1 in ((a, m), (m, b)):
            if not x1 > x0:
                continue
            cnt = max(1, math.ceil((x1 - x0) * 8.0 / abs(u_span))) if u_span else 1
            step = (x1 - x0) / cnt
            a_s += [x0 + j * step for j in range(cnt)]
            b_s += [x0 + (j + 1) * step for j in range(cnt)] if u_span else [x1]
    A, B = np.array(a_s), np.array(b_s)
    h = 0.5 * (B - A)
    return ((A + h)[:, None] + h[:, None] * xg[None, :]).ravel(), (sign * h[:, None] * wg[None, :]).ravel()


def _inner_integrals(ev: SurfaceAdapter, u: np.ndarray, v: np.ndarray, u_lo: Any, u_breaks: np.ndarray,
                     u_span: float | None) -> np.ndarray:
    """``P(u_i, v_i) = ∫_{u_lo}^{u_i} |S_u × S_v|(s, v_i) ds`` point by point (:func:`_inner_nodes`,
    one evaluation of the partials at all nodes)."""
    xg, wg = _gauss12()
    s_all, v_all, w_all, own = _inner_nodes(u, v, u_lo, u_breaks, u_span, xg, wg)
    if not s_all.size:
        return np.zeros(u.size)
    d = ev.d1(s_all, v_all)
    f = _norm(_cross(d[0], d[1]))
    return np.bincount(own, weights=f * w_all, minlength=u.size)


def _inner_integrals_by_pieces(ev: SurfaceAdapter, u: np.ndarray, v: np.ndarray, u_lo: float,
                               u_breaks: np.ndarray, u_span: float | None) -> np.ndarray:
    r""":func:`_inner_integrals` with the same panels, the whole pieces on a grid.

    For ``u_i >= u_lo`` the interval ``[u_lo, u_i]`` cut at the breaks is ``[K_0, K_1], ...,
    [K_{m_i}, u_i]`` with ``K_0 = u_lo`` and ``K_1 < K_2 < ...`` the breaks: every piece but the
    last is the same for all points below which it lies, so its nodes ``s_j`` (the same halves and
    panels) serve all points on one tensor grid ``|S_u × S_v|(s_j, v_i)`` (``ev.density_grid``:
    each basis series once per s and once per v, about 10x cheaper a point than the partials at
    scattered points), ``P_i = Σ_{j < m_i} Σ w_j f(s_j, v_i) + ∫_{K_{m_i}}^{u_i}``, the last piece point
    by point. Points with ``u_i < u_lo`` go point by point. A trimmed B-spline loft face of 5
    spans: 112,000 scattered partials (48 ms an unroll) became a grid and 12 nodes a point."""
    out = np.empty(u.size)
    below = u < u_lo
    if below.any():
        out[below] = _inner_integrals(ev, u[below], v[below], u_lo, u_breaks, u_span)
    up = ~below
    if not up.any():
        return out
    uu, vv = u[up], v[up]
    br = np.unique(np.asarray(u_breaks, dtype=float))
    br = br[(br > u_lo) & (br < float(uu.max()))]
    K = np.concatenate([[float(u_lo)], br])
    m = np.searchsorted(br, uu, side="left")  # breaks strictly below u_i: the whole pieces
    total = np.zeros(uu.size)
    if br.size:
        nodes = [_inner_nodes_at(float(K[j + 1]), float(K[j]), np.zeros(0), u_span) for j in range(br.size)]
        s_all = np.concatenate([sn for sn, _ in nodes])
        w_all = np.concatenate([wn for _, wn in nodes])
        starts = np.cumsum([0] + [sn.size for sn, _ in nodes[:-1]])
        step = max(1, int(2_000_000 // max(s_all.size, 1)))  # grid memory: at most ~16 MB at once
        for a in range(0, uu.size, step):
            sl = slice(a, a + step)
            G = ev.density_grid(s_all, vv[sl])  # (nodes, points)
            S = np.add.reduceat(G * w_all[:, None], starts, axis=0)  # (pieces, points)
            C = np.concatenate([np.zeros((1, S.shape[1])), np.cumsum(S, axis=0)])
            total[sl] = C[m[sl], np.arange(S.shape[1])]
    last = _inner_integrals(ev, uu, vv, K[m], np.zeros(0), u_span)
    out[up] = total + last
    return out


def _inner_nodes(u: np.ndarray, v: np.ndarray, u_lo: Any, u_breaks: np.ndarray, u_span: float | None,
                 xg: np.ndarray, wg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    r"""Gauss–Legendre nodes of ``P(u_i, v_i) = ∫_{u_lo}^{u_i} f(s, v_i) ds`` for all i at once.

    Per i: the interval between ``u_lo`` and ``u_i`` cut at the ``u_breaks`` inside it, each piece
    halved, each half cut into ``max(1, ceil(8 L / |u_span|))`` equal panels (L its length; one
    panel without ``u_span``), ``len(xg)`` nodes per panel, weights signed by ``u_i >= u_lo``.

    Returns:
        (s, v, w, owner): node parameters, their v, weights, and the index i each belongs to.
    """
    n = u.size
    lo = np.minimum(u, u_lo)
    hi = np.maximum(u, u_lo)
    sign = np.where(u >= u_lo, 1.0, -1.0)
    br = np.broadcast_to(u_breaks, (n, u_breaks.size))
    inside = (br > lo[:, None]) & (br < hi[:, None])
    # every row: lo, the breaks inside (others pushed to hi, giving empty pieces), hi; sorted
    cuts = np.sort(np.concatenate([lo[:, None], np.where(inside, br, hi[:, None]), hi[:, None]], axis=1), axis=1)
    a, b = cuts[:, :-1], cuts[:, 1:]
    m = 0.5 * (a + b)
    a = _stack([a, m], axis=2).reshape(n, -1)  # halves [a, m], [m, b]
    b = _stack([m, b], axis=2).reshape(n, -1)
    owner = np.repeat(np.arange(n), a.shape[1])
    a, b = a.ravel(), b.ravel()
    keep = b > a
    a, b, owner = a[keep], b[keep], owner[keep]
    if u_span:
        cnt = np.maximum(1, np.ceil((b - a) * 8.0 / abs(u_span))).astype(int)
        rep = np.repeat(np.arange(a.size), cnt)
        j = np.arange(rep.size) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        step = (b - a)[rep] / cnt[rep]
        a, b, owner = a[rep] + j * step, a[rep] + (j + 1) * step, owner[rep]
    h = 0.5 * (b - a)
    s = ((a + h)[:, None] + h[:, None] * xg[None, :]).ravel()
    w = (sign[owner][:, None] * h[:, None] * wg[None, :]).ravel()
    own = np.repeat(owner, xg.size)
    return s, v[own], w, own
