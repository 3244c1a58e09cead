r"""Development (unrolling) of developable ruled surfaces by quadrature along the rulings (spec 6).

A ruled surface ``X(u, v) = a(u) + v g(u)`` with ``g = b - a``, ruling length ``L = |g|`` and unit
ruling ``d = g / L`` is developable when its tangent plane is constant along each ruling. Then the
orthonormal tangent frame ``(d, e)``, ``e = n × d``, ``n = a' × d / |a' × d|``, maps to a plane
frame ``(D, D⊥)``, ``D = (cos φ, sin φ)``, ``D⊥ = (-sin φ, cos φ)``, and the development is the
solution of three 1-D integrals:

    φ(u) = ∫_0^u w,          w = d' · e                 (geodesic turning of the ruling)
    A(u) = ∫_0^u (p D + q D⊥),  p = a' · d,  q = a' · e   (|A'| = |a'|, angle(A', D) = angle(a', d))
    Y(u, v) = A(u) + v L(u) D(u)                          (flat image of X(u, v))

so ``b(u) ↦ B(u) = A(u) + L(u) D(u)``. The integrands are smooth; they are represented on adaptive
panels by Chebyshev interpolants of degree 24 (first-kind nodes) and integrated spectrally
(Clenshaw–Curtis), panels being split until the trailing Chebyshev coefficients are below
``1e-13`` of the pattern size, which gives positions to near machine precision — not the O(h²) of
a triangle strip. The result is checked (not assumed): ruling lengths, boundary lengths (Romberg
extrapolated chord sums), area (Green's theorem, Romberg) and the angles of the first fundamental
form are compared with their 3-D values in :class:`ght_cad.pattern.flat_pattern.DistortionReport`.

This module holds the development of one ruled surface (no sheet, no CAD face):
:class:`RuledDevelopment`, the checks of the result and :func:`unroll_ruled_surface`; the public
entry points (:func:`ght_cad.unroll.unroll`, :func:`ght_cad.unroll.unroll_ruled` with a sheet,
:func:`ght_cad.unroll.unroll_composite`) are in :mod:`ght_cad.unroll`, which imports every name
back. Moved from :mod:`ght_cad.unrolling.unroll` (issue 27) so that the sheet (:mod:`ght_cad.sheetmetal.sheet`), the
face unrolling and the panel joiner use the development without importing ``ght_cad.unroll``,
which uses them (the import cycle unroll -> sheet -> unroll, unroll -> join_panels -> unroll).
numpy only.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Sequence

import numpy as np

from ..curves.curve import gauss_legendre, integrate
from ..core.errors import DegenerateGeometryError, NotDevelopableError
from ..core._vec import cross as _cross
from ..core._vec import einsum as _einsum
from ..core._vec import stack as _stack
from ..core._vec import dot as _dot
from ..core._vec import norm as _norm
from ..core._vec import unique_inverse as _unique_inverse
from ..pattern.flat_pattern import BoundaryEdge, FlatPanel, FlatPattern, measure_panel
from ..surfaces.ruled import RuledSurface

__all__ = [
    "RuledDevelopment",
    "unroll_ruled_surface",
    "ruled_area",
    "DEFAULT_TOL_DEG",
    "RULED_EDGE_UV",
    "broadcast_uv",
    "first_nodes",
    "metric_angles",
    "metric_stencil",
]

#: default developability tolerance on θ_max (degrees) above which unroll refuses a surface
DEFAULT_TOL_DEG = 0.01

_N = 24  # Chebyshev degree per panel
_K = np.arange(_N + 1)
_X = np.cos(np.pi * (_K + 0.5) / (_N + 1))  # first-kind nodes on [-1, 1]
_V = np.polynomial.chebyshev.chebvander(_X, _N)  # (N+1, N+1)
_VI = np.polynomial.chebyshev.chebvander(_X, _N + 1)  # for evaluating integrated series at nodes
#: Chebyshev integration as a matrix: ``_INT @ c`` = ``chebint(c, lbnd=-1)`` (the integral from -1,
#: degree N + 1), the same linear map without chebint's per-call overhead
_INT = np.polynomial.chebyshev.chebint(np.eye(_N + 1), lbnd=-1, axis=0)  # (N+2, N+1)
#: T_j(1) = 1 for the N + 2 terms of an integrated series: its value at a panel's right end
_ONES = np.ones(_N + 2)


#: the initial panel ends (4 equal panels; the surface's breakpoints are added)
_EDGES0 = np.linspace(0.0, 1.0, 5)


def _chebint(c: np.ndarray) -> np.ndarray:
    """``∫_{-1}^x`` of the series ``c`` (P, N+1, m) along axis 1: (P, N+2, m)."""
    return _einsum("ij,pjm->pim", _INT, c)


def _coefficients(f: np.ndarray) -> np.ndarray:
    """Chebyshev coefficients of samples ``f`` (P, N+1, m) at the first-kind nodes."""
    c = (2.0 / (_N + 1)) * _einsum("kj,pkm->pjm", _V, f)
    c[:, 0, :] *= 0.5
    return c


def _clenshaw(c: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Σ_j c[i, j, :] T_j(x[i]) for per-point coefficient rows c (n, deg+1, m)."""
    b1 = np.zeros((c.shape[0], c.shape[2]))
    b2 = np.zeros_like(b1)
    x2 = 2.0 * x[:, None]
    for j in range(c.shape[1] - 1, 0, -1):
        b1, b2 = c[:, j, :] + x2 * b1 - b2, b1
    return c[:, 0, :] + x[:, None] * b1 - b2


def _cheb_rows_of(x: np.ndarray, m: int) -> np.ndarray:
    """``T_j(x)`` for j < m, shape (m, len(x)), by ``T_{j+1} = 2x T_j - T_{j-1}`` along contiguous rows."""
    T = np.empty((m, x.size))
    T[0] = 1.0
    if m > 1:
        T[1] = x
    x2 = 2.0 * x
    for j in range(2, m):
        np.multiply(x2, T[j - 1], out=T[j])
        T[j] -= T[j - 2]
    return T


class _PanelSeries:
    """Piecewise Chebyshev series on panels ``edges`` (indefinite integrals or plain values)."""

    def __init__(self, edges: np.ndarray, coefs: np.ndarray, offsets: np.ndarray | None = None) -> None:
        self.edges = edges
        self.coefs = coefs  # (P, deg+1, m)
        self.offsets = offsets  # (P, m) value at each panel's left end (integrals) or None

    def __call__(self, u: np.ndarray, ascending: bool = False) -> np.ndarray:
        """The series at ``u`` (n, m). With few panels (many points a panel) the points are taken in
        ascending order (``ascending``: ``u`` is sorted already, the map's distinct parameters), so
        each panel's are a contiguous run (:meth:`_ascending`); else Clenshaw per point."""
        u = np.asarray(u, dtype=float).ravel()
        P = self.edges.size - 1
        if P <= 64 and u.size > 4 * P:
            if ascending:
                return self._ascending(u)
            order = np.argsort(u, kind="stable")
            out = np.empty((u.size, self.coefs.shape[2]))
            out[order] = self._ascending(u[order])
            return out
        idx = np.minimum(np.maximum(np.searchsorted(self.edges, u, side="right") - 1, 0), self.edges.size - 2)  # np.clip, without its overhead
        lo, hi = self.edges[idx], self.edges[idx + 1]
        x = np.minimum(np.maximum((2.0 * u - lo - hi) / (hi - lo), -1.0), 1.0)
        out = np.empty((u.size, self.coefs.shape[2]))
        step = 8192
        for s in range(0, u.size, step):
            sl = slice(s, s + step)
            out[sl] = _clenshaw(self.coefs[idx[sl]], x[sl])
        if self.offsets is not None:
            out += self.offsets[idx]
        return out

    def _ascending(self, u: np.ndarray) -> np.ndarray:
        """:meth:`__call__` of sorted ``u``: the same arithmetic on contiguous runs per panel
        (panel p holds ``edges[p] <= u < edges[p + 1]``, the end panels continued outside)."""
        edges = self.edges.tolist()
        P = len(edges) - 1
        bounds = [0, *np.searchsorted(u, self.edges[1:-1], side="left").tolist(), u.size]
        x = np.empty(u.size)
        for p in range(P):
            s, e = bounds[p], bounds[p + 1]
            if e > s:
                lo, hi = edges[p], edges[p + 1]
                xs = x[s:e]
                np.multiply(u[s:e], 2.0, out=xs)
                xs -= lo
                xs -= hi
                xs /= hi - lo
                np.minimum(np.maximum(xs, -1.0, out=xs), 1.0, out=xs)
        T = _cheb_rows_of(x, self.coefs.shape[1])
        out = np.empty((u.size, self.coefs.shape[2]))
        for p in range(P):
            s, e = bounds[p], bounds[p + 1]
            if e > s:
                np.matmul(T[:, s:e].T, self.coefs[p], out=out[s:e])
                if self.offsets is not None:
                    out[s:e] += self.offsets[p]
        return out


def _frame(surface: RuledSurface, u: np.ndarray) -> dict[str, np.ndarray]:
    """Ruling frame quantities at ``u``: L, L', d, e, n, p = a'·d, q = a'·e, w = d'·e, normal part."""
    a1, g, g1 = surface.edge_jets(u)
    L = _norm(g)
    if not (L > 0).all():
        i = int(np.argmin(L))
        raise DegenerateGeometryError(
            f"ruling length |b(u) - a(u)| = {L[i]:.3g} at u={u[i]:.6g}: the rulings must have positive length"
        )
    d = g / L[:, None]
    L1 = _dot(d, g1)
    d1 = (g1 - d * L1[:, None]) / L[:, None]
    c = _cross(a1, d)
    scale = _norm(a1)
    # a stationary directrix (the apex of a cone, e.g. a loft's fan with apex on rail a): the
    # tangent plane along the ruling is spanned by d and b' (X_u × X_v = v b' × g there)
    b1 = a1 + g1
    b1l = _norm(b1)
    apex = scale <= 1e-12 * b1l
    if apex.any():
        c = np.where(apex[:, None], _cross(b1, d), c)
        scale = np.where(apex, b1l, scale)
    cn = _norm(c)
    if not (cn > 1e-12 * np.maximum(scale, 1e-300)).all():
        i = int(np.argmin(cn / np.maximum(scale, 1e-300)))
        raise DegenerateGeometryError(
            f"the directrix is tangent to the ruling (|a' x d| = {cn[i]:.3g}) at u={u[i]:.6g}; "
            "a' must be transversal to the rulings"
        )
    n = c / cn[:, None]
    e = _cross(n, d)
    return {
        "L": L,
        "L1": L1,
        "d": d,
        "e": e,
        "n": n,
        "p": _dot(a1, d),
        "q": _dot(a1, e),
        "w": _dot(d1, e),
        "wn": _dot(d1, n),
    }


def _initial_edges(breakpoints: Sequence[float]) -> np.ndarray:
    """:class:`RuledDevelopment`'s first panel ends: 4 equal panels, cut at the breakpoints in (0, 1)."""
    bp = [b for b in breakpoints if 1e-12 < b < 1 - 1e-12]
    return np.unique(np.concatenate([_EDGES0, bp])) if bp else _EDGES0.copy()


def _panel_nodes(edges: np.ndarray) -> np.ndarray:
    """The Chebyshev nodes of the panels between ``edges``, panel by panel (P (N+1) values)."""
    lo, hi = edges[:-1], edges[1:]
    h = 0.5 * (hi - lo)
    return ((0.5 * (lo + hi))[:, None] + h[:, None] * _X[None, :]).ravel()


def first_nodes(breakpoints: Sequence[float] = ()) -> np.ndarray:
    """The parameters where :class:`RuledDevelopment` with these ``breakpoints`` first evaluates
    its surface (a caller evaluating boundary jets ahead, :meth:`ght_cad.unrolling.face_unroll.
    FaceRuledSurface.prefetch`, gives it these)."""
    return _panel_nodes(_initial_edges(breakpoints))


class RuledDevelopment:
    r"""The development map ``Y(u, v) = A(u) + v L(u) D(u)`` of a ruled surface (see module doc).

    Args:
        surface: the ruled surface; its parameter domain is u ∈ [0, 1].
        breakpoints: parameters in (0, 1) where a, b are not smooth (B-spline knots); panels
            start there.
        tol: relative tolerance of the spectral integration (w.r.t. the pattern size).
        max_panels: cap on the number of Chebyshev panels.
        place: translate the map so that the bounding box of the boundaries ``Y(u, 0)``,
            ``Y(u, 1)`` (257 samples) sits at the origin; False: ``A(0)`` stays at the origin (a
            caller that places the panel itself, as the face unrolling does, skips the samples).

    Raises:
        DegenerateGeometryError: zero-length rulings or a directrix tangent to a ruling.
    """

    def __init__(
        self,
        surface: RuledSurface,
        *,
        breakpoints: Sequence[float] = (),
        tol: float = 1e-13,
        max_panels: int = 2048,
        place: bool = True,
    ) -> None:
        self.surface = surface
        edges = _initial_edges(breakpoints)
        for _ in range(40):
            P = edges.size - 1
            lo, hi = edges[:-1], edges[1:]
            h = 0.5 * (hi - lo)
            fr = _frame(surface, _panel_nodes(edges))
            stage1 = _stack([fr["w"], fr["p"], fr["q"]], axis=-1).reshape(P, _N + 1, 3)
            c1 = _coefficients(stage1)
            # φ at the nodes: integrate w spectrally, panel offsets by cumulative sums
            cw = _chebint(c1[:, :, :1] * h[:, None, None])
            tot_w = _einsum("pjm,j->pm", cw, _ONES)  # value at x = +1 (T_j(1) = 1)
            off_w = np.concatenate([[0.0], np.cumsum(tot_w[:, 0])])[:-1]
            phi = _einsum("kj,pjm->pkm", _VI, cw)[:, :, 0] + off_w[:, None]
            cphi, sphi = np.cos(phi), np.sin(phi)
            D = _stack([cphi, sphi], axis=-1)
            Dp = _stack([-sphi, cphi], axis=-1)
            Ap = stage1[:, :, 1:2] * D + stage1[:, :, 2:3] * Dp
            c2 = _coefficients(Ap)
            size = float(np.sum(np.abs(c1[:, 0, 1:]).max(axis=1) * 2 * h)) + float(fr["L"].max())
            tail1 = np.abs(c1[:, -3:, :]).max(axis=1)  # (P, 3)
            tail2 = np.abs(c2[:, -3:, :]).max(axis=(1, 2))
            err = np.maximum(tail1[:, 0] * float(fr["L"].max()), np.maximum(tail1[:, 1:].max(axis=1), tail2)) * 2 * h
            bad = err > tol * size
            if not bad.any() or P >= max_panels:
                break
            mids = 0.5 * (lo[bad] + hi[bad])
            edges = np.unique(np.concatenate([edges, mids]))
        self.edges = edges
        self.panels = edges.size - 1
        self.quadrature_error_estimate = float(err.max() / size) if size > 0 else 0.0
        #: max over the final nodes of |d'·n| L (0 on a developable: d' lies in the tangent plane)
        self.normal_turning_max = float(np.max(np.abs(fr["wn"]) * fr["L"]))
        cA = _chebint(c2 * h[:, None, None])
        totA = _einsum("pjm,j->pm", cA, _ONES)
        offA = np.concatenate([np.zeros((1, 2)), np.cumsum(totA, axis=0)])[:-1]
        offw = off_w[:, None]
        self._phi = _PanelSeries(edges, cw, offw)
        self._A = _PanelSeries(edges, cA, offA)
        #: φ and A as one series (columns φ, A_x, A_y): the map evaluates both at once
        self._phiA = _PanelSeries(edges, np.concatenate([cw, cA], axis=2), np.concatenate([offw, offA], axis=1))
        # rigid placement: a-edge chord along +x, bounding box at the origin (applied in .map)
        self._t = np.zeros(2)
        chord = totA.sum(axis=0)  # A(1) - A(0): the panels' integrals (A(0) = 0)
        if math.hypot(chord[0], chord[1]) > 1e-9 * max(size, 1e-300):
            ang = -math.atan2(chord[1], chord[0])
        else:
            ang = math.pi / 2 - float(self._phi(np.array([0.0]))[0, 0])
        ca, sa = math.cos(ang), math.sin(ang)
        self._R = np.array([[ca, -sa], [sa, ca]])
        if not place:
            return
        uu = np.linspace(0, 1, 257)
        # map(u, 0) and map(u, 1) (A and A + L D) from one evaluation of the series and lengths at uu
        L = self.surface.ruling_lengths(uu)
        r = self._phiA(uu)
        ph = r[:, 0] + math.atan2(self._R[1, 0], self._R[0, 0])
        A = r[:, 1:3] @ self._R.T + self._t
        pts = np.concatenate([A, A + L[:, None] * _stack([np.cos(ph), np.sin(ph)], axis=-1)])
        self._t = -pts.min(axis=0)

    def phi(self, u: Any) -> np.ndarray:
        """Direction angle φ(u) of the flat ruling (after placement), radians."""
        uu = np.atleast_1d(np.asarray(u, dtype=float))
        return self._phi(uu)[:, 0] + math.atan2(self._R[1, 0], self._R[0, 0])

    def ruling_direction(self, u: Any) -> np.ndarray:
        """Unit flat ruling direction ``D(u)``, shape (n, 2)."""
        ph = self.phi(u)
        return _stack([np.cos(ph), np.sin(ph)], axis=-1)

    def directrix(self, u: Any) -> np.ndarray:
        """Flat image ``A(u)`` of the directrix, shape (n, 2)."""
        uu = np.atleast_1d(np.asarray(u, dtype=float))
        return self._A(uu) @ self._R.T + self._t

    def map(self, u: Any, v: Any) -> np.ndarray:
        """Flat image ``Y(u, v) = A(u) + v L(u) D(u)`` of ``X(u, v)``; u, v broadcast, shape (n, 2)."""
        uu, vv = broadcast_uv(u, v)
        uu, vv = uu.ravel(), vv.ravel()
        # L, φ and A depend on u only: evaluated once per distinct u (points along one ruling, a
        # ruling edge's samples or a difference stencil's v steps, share them)
        tu, inv = _unique_inverse(uu) if uu.size > 64 else (uu, None)
        L = self.surface.ruling_lengths(tu)
        r = self._phiA(tu, ascending=inv is not None)  # the same values as phi(tu), directrix(tu)
        ph = r[:, 0] + math.atan2(self._R[1, 0], self._R[0, 0])
        A = r[:, 1:3] @ self._R.T + self._t
        LD = L[:, None] * _stack([np.cos(ph), np.sin(ph)], axis=-1)
        if inv is not None:
            inv = inv.ravel()
            A, LD = A[inv], LD[inv]
        return A + vv[:, None] * LD

    def map_points(self, u: Any, points: np.ndarray) -> np.ndarray:
        """Flat image of 3-D points lying on the rulings at ``u`` (projected onto the ruling)."""
        uu = np.atleast_1d(np.asarray(u, float))
        a = self.surface.a(uu)
        g = self.surface.ruling(uu)
        s = _einsum("ij,ij->i", np.asarray(points, float) - a, g) / _einsum("ij,ij->i", g, g)
        return self.map(uu, s)


def _ruled_edges(surface: RuledSurface, dev: RuledDevelopment, samples: int) -> list[BoundaryEdge]:
    """The four boundary edges in order around the panel: a(u), ruling u=1, b(u) reversed, ruling u=0."""

    def curve_len(which: str) -> float:
        f = (lambda t: np.linalg.norm(surface.a(t, 1), axis=1)) if which == "a" else (
            lambda t: np.linalg.norm(surface.b(t, 1), axis=1)
        )
        return sum(integrate(f, lo, hi, rtol=1e-14) for lo, hi in _smooth_pieces(surface))

    def edge(name: str, uv: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], length: float,
             breaks: tuple[float, ...]) -> BoundaryEdge:
        def flat(t: np.ndarray) -> np.ndarray:
            u, v = uv(t)
            return dev.map(u, v)

        def xyz(t: np.ndarray) -> np.ndarray:
            u, v = uv(t)
            return surface.evaluate(u, v)

        return BoundaryEdge(name=name, flat_fn=flat, xyz_fn=xyz, length_3d=length, samples=samples, breaks=breaks)

    La = curve_len("a")
    Lb = curve_len("b")
    g0, g1 = surface.ruling_lengths(np.array([0.0, 1.0]))
    lengths = {"a": La, "ruling u=1": float(g1), "b": Lb, "ruling u=0": float(g0)}
    # the boundary curves' joints (the surface's breakpoints; edge b runs t = 1 - u): their flat
    # lengths and the area are measured piece by piece (BoundaryEdge.breaks)
    bp = tuple(lo for lo, _ in _smooth_pieces(surface)[1:])
    breaks = {"a": bp, "ruling u=1": (), "b": tuple(sorted(1.0 - b for b in bp)), "ruling u=0": ()}
    return [edge(name, uv, lengths[name], breaks[name]) for name, uv in RULED_EDGE_UV.items()]


#: the four boundary edges of a ruled panel in order around it, ``t -> (u, v)``: a(u), ruling u=1,
#: b(u) reversed, ruling u=0
RULED_EDGE_UV: dict[str, Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]] = {
    "a": lambda t: (t, np.zeros_like(t)),
    "ruling u=1": lambda t: (np.ones_like(t), t),
    "b": lambda t: (1.0 - t, np.ones_like(t)),
    "ruling u=0": lambda t: (np.zeros_like(t), 1.0 - t),
}


def _smooth_pieces(surface: RuledSurface) -> list[tuple[float, float]]:
    """Sub-intervals of [0, 1] between the surface's ``breakpoints`` (where a, b are not smooth)."""
    bp = sorted(b for b in getattr(surface, "breakpoints", ()) if 0.0 < b < 1.0)
    edges = [0.0, *bp, 1.0]
    return [(lo, hi) for lo, hi in zip(edges[:-1], edges[1:]) if hi > lo]


def ruled_area(surface: RuledSurface, rtol: float = 1e-14) -> float:
    """3-D area ``∫_0^1 ∫_0^1 |(a' + v g') × g| dv du`` (Gauss–Legendre in v, adaptive in u,
    piecewise between the surface's ``breakpoints``)."""
    tv, wv = gauss_legendre(16)

    def f(u: np.ndarray) -> np.ndarray:
        a1 = surface.a(u, 1)
        g = surface.ruling(u)
        g1 = surface.ruling(u, 1)
        xu = a1[:, None, :] + tv[None, :, None] * g1[:, None, :]
        return np.linalg.norm(np.cross(xu, g[:, None, :]), axis=2) @ wv

    return sum(integrate(f, lo, hi, rtol=rtol) for lo, hi in _smooth_pieces(surface))


def broadcast_uv(u: Any, v: Any) -> tuple[np.ndarray, np.ndarray]:
    """Surface parameters for a development map, shared by ruled surfaces and faces.

    Args:
        u, v: scalars or arrays.

    Returns:
        ``(u, v)`` as float arrays of at least one dimension, broadcast to a common shape (two
        float arrays of the same shape are returned as they are, as ``numpy.broadcast_arrays``
        does, without its per-call overhead: this sits on every map call of the unrolling).
    """
    if type(u) is np.ndarray and type(v) is np.ndarray and u.ndim and u.shape == v.shape \
            and u.dtype == np.float64 and v.dtype == np.float64:
        return u, v
    return np.broadcast_arrays(np.atleast_1d(np.asarray(u, float)), np.atleast_1d(np.asarray(v, float)))


def _fd5(fun: Callable[[float], np.ndarray], h: float) -> np.ndarray:
    """5-point central difference ``(-f(2h) + 8 f(h) - 8 f(-h) + f(-2h)) / 12h`` (O(h⁴))."""
    return (-fun(2 * h) + 8 * fun(h) - 8 * fun(-h) + fun(-2 * h)) / (12 * h)


def metric_stencil(u: np.ndarray, v: np.ndarray, hu: float, hv: float) -> tuple[np.ndarray, np.ndarray]:
    """The (u, v) points of :func:`metric_angles`' two 5-point differences, concatenated:
    ``u + 2hu, u + hu, u - hu, u - 2hu`` (at v), then ``v + 2hv ... v - 2hv`` (at u)."""
    return (np.concatenate([u + s for s in (2 * hu, hu, -hu, -2 * hu)] + [u] * 4),
            np.concatenate([v] * 4 + [v + s for s in (2 * hv, hv, -hv, -2 * hv)]))


def metric_angles(
    xu: np.ndarray, xv: np.ndarray, flat_map: Callable[[np.ndarray, np.ndarray], np.ndarray],
    u: np.ndarray, v: np.ndarray, hu: float, hv: float,
) -> dict[str, np.ndarray]:
    r"""First-fundamental-form check: angle of the 3-D partials ``X_u, X_v`` against the flat ``Y_u, Y_v``.

    ``angle = atan2(|p × q|, p·q)``; the flat partials come from a 5-point central difference of
    ``flat_map(u, v)`` with steps ``hu``, ``hv`` (O(h⁴)), independent of how the map was built.
    Shared by the ruled-surface and the face unrolling.

    Args:
        xu, xv: 3-D partials at the sample points, shape (n, 3).
        flat_map: the development map ``(u, v) -> (n, 2)``.
        u, v: the sample parameters (n,).
        hu, hv: finite-difference steps.

    Returns:
        ``{"angle_3d", "angle_flat", "xu_len", "yu_len"}``, each (n,).
    """
    # the eight stencil points of both differences in one call of the map (it is pointwise)
    n = u.size
    F = np.asarray(flat_map(*metric_stencil(u, v, hu, hv)), dtype=float)
    F = F.reshape(8, n, 2)
    yu = (-F[0] + 8 * F[1] - 8 * F[2] + F[3]) / (12 * hu)
    yv = (-F[4] + 8 * F[5] - 8 * F[6] + F[7]) / (12 * hv)
    a3 = np.arctan2(_norm(_cross(xu, xv)), _dot(xu, xv))
    a2 = np.arctan2(np.abs(yu[:, 0] * yv[:, 1] - yu[:, 1] * yv[:, 0]), _dot(yu, yv))
    return {"angle_3d": a3, "angle_flat": a2, "xu_len": _norm(xu), "yu_len": _norm(yu)}


def _metric_samples(surface: RuledSurface, dev: RuledDevelopment, n: int = 24,
                    breakpoints: Sequence[float] = ()) -> dict[str, np.ndarray]:
    """First-fundamental-form check on an n × 5 grid (:func:`metric_angles`): 3-D partials
    analytic, flat partials with step h = 1e-3 (in the unit parameter square).

    The 5-point difference spans ``u ± 2h``; at a breakpoint the map is only C0 in u (a
    parameter kink: a loft's fan joint, where one rail point starts or stops moving), so a
    stencil across it measures the kink, not the development (0.29° on the dory's bottom loft,
    sample 0.8548 beside the joint 0.8566). A sample closer than ``2.5 h`` to a breakpoint is
    therefore moved to ``2.5 h`` from it on its own side; without breakpoints the grid is
    ``u = 0.02 .. 0.98``."""
    h = 1e-3
    u = np.linspace(0.02, 0.98, n)
    bp = np.array(sorted(b for b in breakpoints if 0.0 < b < 1.0), dtype=float)
    if bp.size:
        k = np.abs(u[:, None] - bp[None, :]).argmin(axis=1)
        d = u - bp[k]
        u = np.where(np.abs(d) < 2.5 * h, bp[k] + np.where(d >= 0.0, 2.5 * h, -2.5 * h), u)
    v = np.linspace(0.0, 1.0, 5)
    U, Vv = np.meshgrid(u, v, indexing="ij")
    U, Vv = U.ravel(), Vv.ravel()
    xu, xv = surface.partials(U, Vv)
    # at a cone's apex on a boundary (X_u = 0) the angle is undefined: leave those points out
    keep = np.linalg.norm(xu, axis=1) > 1e-9 * np.linalg.norm(xv, axis=1)
    return metric_angles(xu[keep], xv[keep], dev.map, U[keep], Vv[keep], h, h)


def _check_developable(surface: RuledSurface, tol_deg: float, best_effort: bool, what: str) -> Any:
    dev = surface.developability()
    if not (dev.theta_max <= tol_deg) and not best_effort:
        raise NotDevelopableError(
            f"{what} is not developable within tol_deg={tol_deg:g}: theta_max={dev.theta_max:.6g} deg, "
            f"theta_rms={dev.theta_rms:.6g} deg, developability degree DD={dev.dd:.12f} (1 = developable), "
            f"R={dev.R:.3g}; pass best_effort=True to flatten it anyway with a distortion report"
        )
    return dev


def unroll_ruled_surface(
    surface: RuledSurface,
    *,
    best_effort: bool = False,
    tol_deg: float = DEFAULT_TOL_DEG,
    rulings: int = 16,
    samples: int = 257,
    units: str = "mm",
    label: str = "P1",
    breakpoints: Sequence[float] = (),
) -> FlatPattern:
    r"""The development of the surface itself (no sheet): :func:`ght_cad.unroll.unroll_ruled` without ``sheet``.

    ``Y(u, v) = A(u) + v |g(u)| D(u)`` with ``φ = ∫ d'·e``, ``A = ∫ (a'·d) D + (a'·e) D⊥`` (module
    doc); the panel's outline is a(u), the ruling u = 1, b(u) reversed and the ruling u = 0.

    Args:
        surface: the ruled surface (u, v ∈ [0, 1]).
        best_effort, tol_deg, rulings, samples, units, label: as in :func:`ght_cad.unroll.unroll`.
        breakpoints: parameters where a, b are not smooth (B-spline knots).

    Returns:
        Single-panel FlatPattern; ``pattern.map(u, v)`` is the development map.

    Raises:
        NotDevelopableError: ``θ_max > tol_deg`` and not best_effort (message: θ_max, θ_rms, DD).
        DegenerateGeometryError: a zero-length ruling or a directrix tangent to a ruling.
    """
    dd = _check_developable(surface, tol_deg, best_effort, f"surface {label!r}")
    dev = RuledDevelopment(surface, breakpoints=breakpoints)
    edges = _ruled_edges(surface, dev, samples)
    ur = (np.arange(1, rulings + 1) / (rulings + 1)) if rulings > 0 else np.zeros(0)
    p0 = dev.map(ur, np.zeros_like(ur))
    p1 = dev.map(ur, np.ones_like(ur))
    bends = _stack([p0, p1], axis=1) if ur.size else np.zeros((0, 2, 2))
    uu = np.linspace(0.0, 1.0, 129)
    ruling_3d = surface.ruling_lengths(uu)
    ruling_flat = np.linalg.norm(dev.map(uu, np.ones_like(uu)) - dev.map(uu, np.zeros_like(uu)), axis=1)
    metric = _metric_samples(surface, dev, breakpoints=tuple(breakpoints) + tuple(getattr(surface, "breakpoints", ())))
    panel = FlatPanel(
        label=label,
        loops=[edges],
        bend_lines=bends,
        ruling_lengths_3d=ruling_3d,
        ruling_lengths_flat=ruling_flat,
        area_3d=ruled_area(surface),
        metric=metric,
        info={
            "method": "quadrature along rulings (adaptive Chebyshev/Clenshaw-Curtis panels)",
            "panels": dev.panels,
            "quadrature_error_estimate": dev.quadrature_error_estimate,
            # max |d' · n| L: the out-of-tangent-plane turning that a best-effort flattening drops
            "normal_turning_max": dev.normal_turning_max,
            "developability": dd.as_dict(),
            "best_effort": bool(best_effort),
        },
        development=dev,
    )
    measure_panel(panel)
    return FlatPattern([panel], units=units)
