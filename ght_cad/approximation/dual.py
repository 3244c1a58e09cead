r"""Dual fit of a strip's tangent planes (issue 24; spec sections 3, 5.2, 10 and 10.1).

Along the middle curve ``c(x) = S(x, y_m)`` of a strip ``y_lo <= y <= y_hi`` of the target, the
tangent planes ``T(x) = (-n·c, n)`` and their derivatives ``T'(x) = (-n_x·c, n_x)`` (``n·c_x = 0``)
form a one-parameter family of planes (spec 10). A GHT dual curve (spec 3 with 4-D control
points, spec 5.2) ``U(t) = Σ_{i=0..m} b_{i,m}(t; μ, ν, γ) U_i`` is fitted to it by linear least
squares with ``t = x``:

    min_U  Σ_k |U(x_k) - T(x_k) + s e_0|² + w_d² |U'(x_k) - T'(x_k)|²,

``e_0 = (1, 0, 0, 0)``; ``s`` moves every plane by ``s`` along its unit normal (``Σ b_{i,m} = 1``,
so the shift of the control planes is the shift of ``U(t)``), used to centre the deviation on
the target. Its envelope (rulings ``U ∩ U'``, spec 5.2) is an exact developable that touches the
target approximately along ``c`` (Chen, Lee, Leopoldseder, Pottmann, Randrup, Wallner 1999).

**Deviation along the target normals.** The normal line ``S(x, y) + h n(x, y)`` meets the ruling
``U(t) ∩ U'(t)`` where both planes contain it:

    h(t) = -U(t)·(1, S) / (U_n(t)·n),    g(t) = U'(t)·(1, S) + h(t) U'_n(t)·n = 0

(``U_n`` the normal part of ``U``): ``g`` is bracketed on a t grid and its root nearest ``t = x``
refined by the Illinois rule; ``h`` is then the signed distance of the envelope from the target
along ``n``. On a grid of the strip this gives the deviation range ``[min h, max h]``, and on
the two seam rows it gives the **trimmed boundary**: the seam ``r(x) = S(x, y_j) + δ(x) n(x, y_j)``
with ``δ = h`` lies on the envelope, which is the seam family of :mod:`ght_cad.approximation` —
so the envelope trimmed to its strip is bounded by two seam curves that the neighbouring panels
can share exactly (the panel is then the loft between them, spec 5.7, whose rulings are the
envelope's).

**Edge of regression.** ``R(t) = U ∩ U' ∩ U''`` (spec 5.2); a fit whose regression point lies
near the target inside the strip (projected parameter ``y_lo < y_R < y_hi``, distance below the
strip width) is rejected.

**Shape parameters.** ``μ, ν, γ ∈ [-1, 1]`` enter through the basis; they are chosen to minimize
the half range ``(max h - min h) / 2`` (the deviation after centring) with
:func:`ght_cad.optimize.minimize` (I-GWO by default, spec 8), starting from ``(0, 0, 0)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core._cache import readonly_cache
from ..curves.basis import basis

__all__ = ["DualFit", "PlaneSamples", "tangent_planes", "fit_dual_planes", "normal_hits", "fit_strip", "check_optimizer"]


def check_optimizer(name: Any) -> None:
    """Raise :class:`ght_cad.core.errors.GHTError` unless ``name`` is a :func:`ght_cad.optimize.minimize` method."""
    from ..core.errors import GHTError
    from ..optimize import METHODS

    key = str(name).lower().replace("-", "").replace("_", "")
    if not isinstance(name, str) or key not in METHODS:
        raise GHTError(f"optimizer={name!r} is not allowed; use None or one of {', '.join(METHODS)}")


_T_PAD = 0.1  # the dual curve's parameter t = _T_PAD + x (1 - 2 _T_PAD): rulings beyond the seam ends


def _t_of_x(x: np.ndarray) -> np.ndarray:
    return _T_PAD + np.asarray(x, dtype=float) * (1.0 - 2.0 * _T_PAD)


@dataclass
class PlaneSamples:
    r"""The target along ``c(x) = S(x, y_m)``: points ``c``, unit normals ``n`` and ``n_t = dn/dt``
    (t the dual-curve parameter), the centre ``p0`` of the points and the lever arm ``ell`` (half
    the strip width): what :func:`fit_dual_planes` fits."""

    t: np.ndarray
    c: np.ndarray
    n: np.ndarray
    n_t: np.ndarray
    p0: np.ndarray
    ell: float

    def planes(self) -> np.ndarray:
        """Tangent planes ``T = (-n·c, n)`` (spec 10), (len(t), 4)."""
        return np.hstack([-np.sum(self.n * self.c, 1)[:, None], self.n])


def tangent_planes(frame: Any, x: np.ndarray, y: float, ell: float) -> PlaneSamples:
    r"""Samples of the tangent planes ``T(x) = (-n·c, n)`` of the target along ``c(x) = S(x, y)``
    with ``n_t = n_x / (1 - 2 pad)`` (``T_x = (-n_x·c, n_x)`` since ``n·c_x = 0``)."""
    x = np.asarray(x, dtype=float).ravel()
    yy = np.full(x.size, float(y))
    j = frame.jet(x, yy, 2)
    n = frame.normal(x, yy, j[:3])
    nx = frame.normal_dx(x, yy, j)
    c = j[0]
    return PlaneSamples(_t_of_x(x), c, n, nx / (1.0 - 2.0 * _T_PAD), c.mean(axis=0), float(ell))


#: how many argument tuples of :func:`_basis_matrices` are kept (least recently used dropped first)
_BASIS_CACHE_SIZE = 64


@readonly_cache(maxsize=_BASIS_CACHE_SIZE)
def _basis_matrices(t_bytes: bytes, shape: tuple[int, ...], m: int, p_bytes: bytes, k: int) -> tuple[np.ndarray, ...]:
    """``(b^{(0)}_{i,m}(t; μ, ν, γ), ..., b^{(k)})`` for ``t`` and ``(μ, ν, γ)`` given by their bytes
    (the cache key of the project's one scheme, :func:`ght_cad.core._cache.readonly_cache`)."""
    t = np.frombuffer(t_bytes, dtype=float).reshape(shape)
    mu, nu, gamma = np.frombuffer(p_bytes, dtype=float)
    return tuple(basis(t, m, float(mu), float(nu), float(gamma), derivative=r) for r in range(k + 1))


def _basis_pair(t: np.ndarray, m: int, p: tuple[float, float, float], k: int = 1) -> list[np.ndarray]:
    """``[b^{(0)}_{i,m}(t; μ, ν, γ), ..., b^{(k)}]`` (read-only arrays), remembered for the last
    :data:`_BASIS_CACHE_SIZE` arguments: a strip's fit measures the same (μ, ν, γ) at the same
    parameters several times (``centred``: the plane fit and the normal hits of every pass; the
    saddle: 1,245 calls, 418 distinct, 70 % of the basis time). The values are those a new
    evaluation gives, bit for bit (the key is the arguments' bytes)."""
    t = np.ascontiguousarray(t, dtype=float)
    p_bytes = np.asarray(p, dtype=float).reshape(3).tobytes()
    return list(_basis_matrices(t.tobytes(), t.shape, int(m), p_bytes, int(k)))


def fit_dual_planes(ps: PlaneSamples, degree: int, params: tuple[float, float, float],
                    shift: Any = 0.0) -> tuple[np.ndarray, float]:
    r"""Control planes ``U_0..U_m`` of the dual fit and its RMS residual (a length).

    Linear least squares in ``vec(U_i)`` (coordinates centred at ``p0``, ``c̄ = c - p0``) with rows

    * point on plane, ``U(t_k)·(1, c̄_k) = -s`` (the plane moved by ``s`` along its normal);
    * normal, ``ℓ (U_n(t_k) - n_k) = 0``: a normal error ε tilts the plane by ``ℓ ε`` at the
      strip's seams, ``ℓ`` half the strip width;
    * ruling through the curve, ``U'(t_k)·(1, c̄_k) / |n_t| = 0`` (the tangent plane's
      characteristic line ``T ∩ T'`` passes through ``c``: ``T'·(1, c) = -n_x·c + n_x·c = 0``);
    * turning, ``0.1 ℓ (U_n'(t_k) - n_t,k) = 0``.
    """
    B0, B1 = _basis_pair(ps.t, degree, params, 1)
    K, m1 = B0.shape
    cb = np.hstack([np.ones((K, 1)), ps.c - ps.p0])
    ell = ps.ell
    wr = 1.0 / np.maximum(np.linalg.norm(ps.n_t, axis=1), 1e-9)
    rows = [np.einsum("ki,kc->kic", B0, cb).reshape(K, -1), (wr[:, None, None] * np.einsum("ki,kc->kic", B1, cb)).reshape(K, -1)]
    rhs = [-np.broadcast_to(np.asarray(shift, dtype=float), (K,)), np.zeros(K)]
    for d in range(1, 4):
        e = np.zeros(4)
        e[d] = 1.0
        rows.append(ell * np.einsum("ki,c->kic", B0, e).reshape(K, -1))
        rhs.append(ell * ps.n[:, d - 1])
        rows.append(0.1 * ell * np.einsum("ki,c->kic", B1, e).reshape(K, -1))
        rhs.append(0.1 * ell * ps.n_t[:, d - 1])
    A = np.vstack(rows)
    r = np.concatenate(rhs)
    sol, *_ = np.linalg.lstsq(A, r, rcond=None)
    P = sol.reshape(m1, 4)
    res = A @ sol - r
    P = P.copy()
    P[:, 0] -= P[:, 1:] @ ps.p0  # back from centred coordinates: u0 = u0' - n·p0
    return P, float(np.sqrt(np.mean(res * res)))


def _dual(P: np.ndarray, t: np.ndarray, params: tuple[float, float, float], k: int) -> list[np.ndarray]:
    return [b @ P for b in _basis_pair(np.clip(t, 0.0, 1.0), P.shape[0] - 1, params, k)]


def normal_hits(P: np.ndarray, params: tuple[float, float, float], S: np.ndarray, n: np.ndarray, x: np.ndarray,
                nt: int = 129, iters: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    r"""Where the normal lines ``S + h n`` meet the envelope of ``U(t)`` (module doc).

    Args:
        P: control planes (m+1, 4); params: (μ, ν, γ).
        S, n: (N, 3) target points and unit normals; x: (N,) their seam parameters (start guess t = x).

    Returns:
        ``(h, t, ok)``: signed distances along n, ruling parameters, and whether a root was found.
    """
    tg = np.linspace(0.0, 1.0, nt)
    U0, U1 = _dual(P, tg, params, 1)
    S1 = np.hstack([np.ones((S.shape[0], 1)), S])

    with np.errstate(divide="ignore", invalid="ignore"):
        h_grid = -(S1 @ U0.T) / (n @ U0[:, 1:].T)  # (N, nt)
        G = S1 @ U1.T + h_grid * (n @ U1[:, 1:].T)

    def g_at(t: np.ndarray) -> np.ndarray:
        Ua, Ub = _dual(P, t, params, 1)
        with np.errstate(divide="ignore", invalid="ignore"):
            hh = -np.sum(Ua * S1, 1) / np.sum(Ua[:, 1:] * n, 1)
        return np.sum(Ub * S1, 1) + hh * np.sum(Ub[:, 1:] * n, 1)

    sc = np.sign(G[:, :-1]) * np.sign(G[:, 1:]) <= 0
    sc &= np.isfinite(G[:, :-1]) & np.isfinite(G[:, 1:])
    mid = 0.5 * (tg[:-1] + tg[1:])
    dist = np.where(sc, np.abs(mid[None, :] - _t_of_x(x)[:, None]), np.inf)
    k = np.argmin(dist, axis=1)
    ok = np.isfinite(dist[np.arange(x.size), k])
    lo, hi = tg[k], tg[k + 1]
    glo, ghi = G[np.arange(x.size), k], G[np.arange(x.size), k + 1]
    if iters == 0:  # linear interpolation in the bracket of the grid (the optimizer's fast measure)
        den = ghi - glo
        frac = np.clip(np.where(np.abs(den) > 0, -glo / np.where(np.abs(den) > 0, den, 1.0), 0.5), 0.0, 1.0)
        r = np.arange(x.size)
        h = h_grid[r, k] + frac * (h_grid[r, k + 1] - h_grid[r, k])
        t = lo + frac * (hi - lo)
        ok &= np.isfinite(h)
        return h, t, ok
    t = lo.copy()
    for _ in range(iters):  # Illinois (modified regula falsi) on the bracket
        den = ghi - glo
        t = np.where(np.abs(den) > 0, (lo * ghi - hi * glo) / np.where(np.abs(den) > 0, den, 1.0), 0.5 * (lo + hi))
        t = np.clip(t, np.minimum(lo, hi), np.maximum(lo, hi))
        gt = g_at(t)
        left = np.sign(gt) == np.sign(glo)
        lo, glo, hi, ghi = (np.where(left, t, lo), np.where(left, gt, glo), np.where(left, hi, t), np.where(left, ghi, gt))
        ghi = np.where(left, 0.5 * ghi, ghi)
        glo = np.where(left, glo, 0.5 * glo)
    Ua = _dual(P, t, params, 0)[0]
    with np.errstate(divide="ignore", invalid="ignore"):
        h = -np.sum(Ua * S1, 1) / np.sum(Ua[:, 1:] * n, 1)
    ok &= np.isfinite(h)
    return h, t, ok


@dataclass
class DualFit:
    """One strip's dual fit.

    Attributes:
        ok: usable (roots everywhere on the strip's grid, no edge of regression in the strip).
        reason: why not, when not ok.
        planes: control planes (m+1, 4); params: (μ, ν, γ); shift: plane offset s (module doc).
        half_range: ``(max h - min h) / 2`` after optimization (the deviation after centring).
        half_range_start: the same at ``μ = ν = γ = 0`` (before optimization).
        delta_lo, delta_hi: Chebyshev coefficients (in ``2x - 1``) of the trimmed boundary's seam
            offsets ``δ(x) = h(x, y_lo)``, ``h(x, y_hi)``.
        residual: RMS plane residual of the least-squares fit.
        nfev: objective evaluations of the optimizer.
    """

    ok: bool
    reason: str = ""
    planes: np.ndarray | None = None
    params: tuple[float, float, float] = (0.0, 0.0, 0.0)
    shift: float = 0.0  # the largest plane offset |s(x)|
    half_range: float = math.inf
    half_range_start: float = math.inf
    delta_lo: np.ndarray = field(default_factory=lambda: np.zeros(1))
    delta_hi: np.ndarray = field(default_factory=lambda: np.zeros(1))
    residual: float = math.nan
    nfev: int = 0

    def as_dict(self) -> dict[str, Any]:
        return {"ok": self.ok, "reason": self.reason, "mu": self.params[0], "nu": self.params[1],
                "gamma": self.params[2], "shift": self.shift, "half_range": self.half_range,
                "half_range_start": self.half_range_start, "residual": self.residual, "nfev": self.nfev}


class _StripGrid:
    """Target samples of a strip: rows ``y_lo .. y_hi`` (row 0 and row -1 are the seams)."""

    def __init__(self, frame: Any, y_lo: float, y_hi: float, nx: int, ny: int) -> None:
        self.x = np.linspace(0.0, 1.0, nx)
        self.y = np.linspace(y_lo, y_hi, ny)
        X, Y = np.meshgrid(self.x, self.y, indexing="ij")
        self.X, self.Y = X.ravel(), Y.ravel()
        j = frame.jet(self.X, self.Y, 1)
        self.S = j[0]
        self.n = frame.normal(self.X, self.Y, j)
        self.shape = X.shape


def _regression_in_strip(frame: Any, P: np.ndarray, params: tuple[float, float, float], y_lo: float, y_hi: float) -> bool:
    """The edge of regression ``U ∩ U' ∩ U''`` near the target inside the strip (module doc)."""
    from ..surfaces.planes import meet

    x0 = np.linspace(0.0, 1.0, 33)
    t = _t_of_x(x0)
    U = _dual(P, t, params, 2)
    R = meet(U[0], U[1], U[2])
    fin = np.abs(R[:, 0]) > 1e-12 * np.linalg.norm(R, axis=1)
    if not np.any(fin):
        return False
    Xr = R[fin, 1:] / R[fin, :1]
    x, y, d = frame.project(Xr, x0[fin], np.full(int(fin.sum()), 0.5 * (y_lo + y_hi)))
    width = float(np.max(np.linalg.norm(frame.jet(np.array([0.5]), np.array([y_hi]), 0)[0]
                                        - frame.jet(np.array([0.5]), np.array([y_lo]), 0)[0], axis=1)))
    S = frame.jet(x, y, 0)[0]
    dist = np.linalg.norm(Xr - S, axis=1)
    inside = (y > y_lo + 1e-9) & (y < y_hi - 1e-9) & (x > 0) & (x < 1) & (dist < width)
    return bool(np.any(inside))


def fit_strip(frame: Any, y_lo: float, y_hi: float, *, degree: int = 6, optimizer: str | None = "igwo",
              max_nfev: int = 120, seed: int = 0, closed: bool = False, delta_degree: int = 10) -> DualFit:
    r"""Dual fit of the strip ``y_lo <= y <= y_hi`` (module doc): least-squares dual curve of the
    tangent planes along ``y_m = (y_lo + y_hi) / 2``, shape parameters optimized for the half range
    of ``h``, centred by the plane shift ``s = (max h + min h) / 2`` (two passes), trimmed to the
    seam rows.

    Args:
        frame: the target in strip coordinates (:class:`ght_cad.approximation._Frame`).
        degree: dual-curve degree m >= 2.
        optimizer: a :func:`ght_cad.optimize.minimize` method for (μ, ν, γ), or None (keep 0, 0, 0).
        max_nfev: the optimizer's evaluation budget.
        closed: the target is closed along x: the seam offsets are constants (their means), so the
            seams stay closed.
        delta_degree: Chebyshev degree of the trimmed seam offsets.
    """
    from ..optimize.hybrid import _one_blas_thread  # tiny least squares: no BLAS thread waits

    with _one_blas_thread():
        return _fit_strip(frame, y_lo, y_hi, degree, optimizer, max_nfev, seed, closed, delta_degree)


def _fit_strip(frame: Any, y_lo: float, y_hi: float, degree: int, optimizer: str | None, max_nfev: int, seed: int,
               closed: bool, delta_degree: int) -> DualFit:
    ym = 0.5 * (y_lo + y_hi)
    xs = np.linspace(0.0, 1.0, 4 * degree + 9)
    grid = _StripGrid(frame, y_lo, y_hi, 33, 5)
    sh = grid.shape
    ell = 0.5 * float(np.median(np.linalg.norm(grid.S.reshape(sh + (3,))[:, -1] - grid.S.reshape(sh + (3,))[:, 0], axis=1)))
    ps = tangent_planes(frame, xs, ym, ell)

    def measure(p: tuple[float, float, float], shift: Any = 0.0) -> tuple[float, float, np.ndarray, np.ndarray, float]:
        """(local half range max_x (max_y h - min_y h) / 2, max |h|, local centres at the grid's x,
        control planes, residual)."""
        P, res = fit_dual_planes(ps, degree, p, shift)
        h, _, ok = normal_hits(P, p, grid.S, grid.n, grid.X)
        # a few isolated misses (a root on a bracket's end) are skipped; more mean the envelope
        # does not cover the strip
        if np.mean(ok) < 0.97 or not np.all(ok.reshape(sh).any(axis=1)):
            return math.inf, math.inf, np.zeros(sh[0]), P, res
        H = np.where(ok, h, np.nan).reshape(sh)
        lo, hi = np.nanmin(H, axis=1), np.nanmax(H, axis=1)
        h = h[ok]
        return 0.5 * float(np.max(hi - lo)), float(np.max(np.abs(h))), 0.5 * (lo + hi), P, res

    def centred(p: tuple[float, float, float], passes: int) -> tuple[float, np.ndarray, np.ndarray, float]:
        """Centre the deviation station by station (the planes pass through ``c + s(x) n``):
        (max |h|, s at the samples, control planes, residual)."""
        shift = np.zeros(xs.size)
        local, dev, centre, P, res = measure(p)
        for _ in range(passes):
            if not math.isfinite(local):
                break
            shift = shift - np.interp(xs, grid.x, centre)
            local, dev, centre, P, res = measure(p, shift)
        return (dev if math.isfinite(local) else math.inf), shift, P, res

    zero = (0.0, 0.0, 0.0)
    start = centred(zero, 3)
    best_p, best = zero, start
    nfev = 0
    if optimizer is not None:
        from ..optimize import minimize

        def F(Xp: np.ndarray) -> np.ndarray:
            return np.array([min(centred(tuple(float(v) for v in row), 1)[0], 1e300) for row in np.atleast_2d(Xp)])

        r = minimize(F, [(-1.0, 1.0)] * 3, method=optimizer, vectorized=True, seed=seed, max_nfev=max_nfev,
                     pop_size=10, x0=np.zeros(3))
        nfev = int(r.nfev)
        if math.isfinite(r.fun):
            cand = tuple(float(v) for v in r.x)
            got = centred(cand, 3)
            if got[0] < best[0]:
                best_p, best = cand, got
    half, shift, P, res = best
    if not math.isfinite(half):
        return DualFit(False, "the envelope misses some normal lines of the strip", half_range_start=start[0], nfev=nfev)
    if half > ell:
        return DualFit(False, f"the fitted envelope deviates by {half:.4g}, more than half the strip width {ell:.4g}",
                       P, best_p, 0.0, half, start[0], nfev=nfev)
    start = start[0]
    if _regression_in_strip(frame, P, best_p, y_lo, y_hi):
        return DualFit(False, "the edge of regression enters the strip", P, best_p, 0.0, half, start, nfev=nfev)
    # trimmed boundary: the envelope on the two seam rows, as seam offsets δ(x)
    xd = 0.5 - 0.5 * np.cos(np.linspace(0.0, math.pi, 4 * delta_degree + 9))
    deltas = []
    for yj in (y_lo, y_hi):
        yy = np.full(xd.size, yj)
        j = frame.jet(xd, yy, 1)
        n = frame.normal(xd, yy, j)
        h, _, ok = normal_hits(P, best_p, j[0], n, xd, iters=14)
        # the seam's Chebyshev series carries over a few misses at the very ends (where the
        # least-squares envelope stops short of the strip by a fraction of a ruling spacing)
        if np.mean(ok) < 0.9 or xd[ok].min() > 0.05 or xd[ok].max() < 0.95:
            return DualFit(False, "the envelope misses the seam's normal lines", P, best_p, 0.0, half, start, nfev=nfev)
        if closed:
            deltas.append(np.array([float(np.mean(h[ok]))]))
        else:
            deltas.append(np.polynomial.chebyshev.chebfit(2 * xd[ok] - 1, h[ok], delta_degree))
    return DualFit(True, "", P, best_p, float(np.max(np.abs(shift))), half, start, deltas[0], deltas[1], res, nfev)
