r"""Degree-m GHT-Bernstein basis (spec section 2), vectorized, with analytic derivatives.

The basis of degree ``m >= 2`` is built from a degree-2 seed ``(f0, f1, f2)`` by the recursion
``b_{i,m} = (1-t) b_{i,m-1} + t b_{i-1,m-1}``; its closed form, used here, is

.. math::  b_{i,m}(t) = B_{i,n}(t) f_0(t) + B_{i-1,n}(t) f_1(t) + B_{i-2,n}(t) f_2(t),\quad n = m-2

with ``B_{j,n}`` the classical Bernstein polynomials (zero outside ``0..n``). Derivatives follow by
Leibniz' rule, ``b^{(r)}_{i,m} = Σ_s C(r,s) Σ_k B^{(r-s)}_{i-k,n} f_k^{(s)}``.
"""

from __future__ import annotations

from math import comb, factorial
from typing import Any, Sequence

import numpy as np

from ..core._cache import readonly_cache
from ..core._validate import as_parameter_array, check_degree, check_unit_interval
from ..core.errors import GHTError
from .seeds import MAX_DERIVATIVE, Seed, ght_seed_parameter_derivatives, make_seed

__all__ = [
    "basis",
    "seed_basis",
    "seed_basis_derivatives",
    "evaluate_derivatives",
    "basis_from_jets",
    "bernstein",
    "bernstein_log",
    "bernstein_recursive_basis",
    "parameter_jets",
    "basis_parameter_derivatives",
]

_CHUNK = 1 << 15


def _check_order(derivative: Any, max_order: int = MAX_DERIVATIVE) -> int:
    """``derivative`` as an int in ``0..max_order``; GHTError naming the value otherwise."""
    try:
        r = int(derivative)
    except (TypeError, ValueError):
        raise GHTError(f"derivative={derivative!r} is not an integer; allowed orders are 0..{max_order}") from None
    if r != derivative or not 0 <= r <= max_order:
        raise GHTError(f"derivative={derivative!r} is not allowed; analytic derivatives exist for orders 0..{max_order}")
    return r


def bernstein(t: np.ndarray, n: int, derivative: int = 0) -> np.ndarray:
    r"""Classical Bernstein polynomials ``B_{j,n}(t) = C(n,j) t^j (1-t)^{n-j}`` and derivatives.

    ``B^{(r)}_{j,n} = n!/(n-r)! Σ_{l=0..r} (-1)^{r-l} C(r,l) B_{j-l,n-r}``.

    Args:
        t: 1-D array of parameters.
        n: polynomial degree (>= 0).
        derivative: order r >= 0.

    Returns:
        Array of shape (len(t), n+1).
    """
    t = np.asarray(t, dtype=float)
    N = t.shape[0]
    if derivative > n:
        return np.zeros((N, n + 1))
    q = n - derivative
    # degree-q values C(q,j) t^j (1-t)^(q-j) from the powers of t and (1-t)
    if q == 0:
        low = np.ones((N, 1))
    elif q == 1:
        low = np.stack([1.0 - t, t], axis=1)
    elif q > MAX_DIRECT_DEGREE:
        low = bernstein_log(t, q)
    else:
        tp = np.empty((N, q + 1))
        sp = np.empty((N, q + 1))
        tp[:, 0] = 1.0
        sp[:, 0] = 1.0
        s = 1.0 - t
        for j in range(1, q + 1):
            np.multiply(tp[:, j - 1], t, out=tp[:, j])
            np.multiply(sp[:, j - 1], s, out=sp[:, j])
        low = tp * sp[:, ::-1]
        low *= _binomials(q)
    if derivative == 0:
        return low
    out = np.zeros((N, n + 1))
    scale = factorial(n) / factorial(q)
    for l in range(derivative + 1):
        coef = scale * (-1) ** (derivative - l) * comb(derivative, l)
        out[:, l : l + q + 1] += coef * low
    return out


#: above this degree the Bernstein values are computed in log space (:func:`bernstein_log`):
#: C(n, n/2) exceeds the float range from n = 1030 on, and 2^-n nears it; up to 500 the direct
#: product of powers keeps full precision
MAX_DIRECT_DEGREE = 500


def bernstein_log(t: np.ndarray, n: int) -> np.ndarray:
    r"""``B_{j,n}(t) = C(n,j) t^j (1-t)^{n-j}`` for any degree n, through logarithms.

    ``log B_{j,n} = lnΓ(n+1) - lnΓ(j+1) - lnΓ(n-j+1) + j log t + (n-j) log(1-t)``, exponentiated
    (no overflow of C(n,j), no underflow of the powers before the product; values below the
    float range come out as 0). The relative error is about ``n · 1e-16`` per value.

    Args:
        t: 1-D array of parameters in [0, 1].
        n: degree >= 0.

    Returns:
        Array of shape (len(t), n+1).
    """
    from scipy.special import gammaln

    t = np.asarray(t, dtype=float)
    j = np.arange(n + 1, dtype=float)
    logc = gammaln(n + 1.0) - gammaln(j + 1.0) - gammaln(n - j + 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        lt = np.log(t)[:, None]
        ls = np.log1p(-t)[:, None]
        # 0 * log 0 = 0: t^0 = 1 also at t = 0 (and (1-t)^0 at t = 1)
        a = np.where(j == 0, 0.0, j * lt)
        b = np.where(j == n, 0.0, (n - j) * ls)
    return np.exp(logc + a + b)


@readonly_cache(maxsize=64)
def _binomials(q: int) -> np.ndarray:
    """``[C(q, 0), ..., C(q, q)]`` as a read-only float array."""
    return np.array([comb(q, j) for j in range(q + 1)], dtype=float)


def basis_from_jets(bern: Sequence[np.ndarray], jets: Sequence[Sequence[np.ndarray]], derivative: int) -> np.ndarray:
    r"""Leibniz' rule ``b^{(r)}_{i,m} = Σ_{s=0..r} C(r,s) Σ_{k=0..2} B^{(r-s)}_{i-k,n} f_k^{(s)}``.

    The one implementation of the closed form (section 2), shared by :func:`seed_basis`,
    :func:`seed_basis_derivatives` and the population-vectorized optimizer problems.

    Args:
        bern: ``bern[q]`` = Bernstein derivative matrices ``B^{(q)}_{j,n}(t)``, shape (N, n+1), q = 0..r.
        jets: ``jets[s] = (f0^(s), f1^(s), f2^(s))``, each of shape (..., N, 1) (leading axes,
            e.g. P parameter sets, broadcast), s = 0..r.
        derivative: order r.

    Returns:
        Array of shape (..., N, n+3).
    """
    r = int(derivative)
    n1 = bern[0].shape[1]
    lead = np.broadcast_shapes(*(f.shape for f in jets[0]))[:-1]
    out = np.zeros(lead + (n1 + 2,))
    for s in range(r + 1):
        B = bern[r - s]
        c = comb(r, s)
        for k in range(3):
            fk = jets[s][k] if c == 1 else c * jets[s][k]
            out[..., k : k + n1] += B * fk
    return out


def _columns(f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return f[:, 0:1], f[:, 1:2], f[:, 2:3]


def seed_basis(t: np.ndarray, degree: int, seed: Seed, derivative: int = 0) -> np.ndarray:
    r"""Basis ``b^{(r)}_{i,m}(t)`` for an already-built :class:`Seed` (no validation of t).

    ``b^{(r)}_{i,m} = Σ_{s=0..r} C(r,s) Σ_{k=0..2} B^{(r-s)}_{i-k,n} f_k^{(s)}``, n = m - 2.

    Returns:
        Array of shape (len(t), degree+1).
    """
    n = degree - 2
    jets = [_columns(seed.jet(t, s)) for s in range(derivative + 1)]
    bern = [bernstein(t, n, q) for q in range(derivative + 1)]
    return basis_from_jets(bern, jets, derivative)


def seed_basis_derivatives(t: np.ndarray, degree: int, seed: Seed, max_order: int) -> list[np.ndarray]:
    r"""``[b^{(0)}, ..., b^{(K)}]`` of :func:`seed_basis` in one pass (no validation of t).

    One seed evaluation for all orders (:meth:`Seed.jets`: one sin/cos pass for the GHT family)
    and one Bernstein matrix ``B^{(q)}_{j,n}`` per order, combined by Leibniz' rule
    ``b^{(r)}_{i,m} = Σ_s C(r,s) Σ_k B^{(r-s)}_{i-k,n} f_k^{(s)}``. Orders above 3 need a seed that
    provides them (the GHT family does, for every order).

    Args:
        t: 1-D parameter array.
        degree: basis degree m >= 2.
        seed: the seed.
        max_order: K >= 0.

    Returns:
        List of K+1 arrays of shape (len(t), degree+1).

    Raises:
        GHTError: an order the seed does not provide.
    """
    n = degree - 2
    jets = [_columns(f) for f in seed.jets(t, max_order)]
    bern = [bernstein(t, n, q) for q in range(max_order + 1)]
    return [basis_from_jets(bern, jets, r) for r in range(max_order + 1)]


def evaluate_derivatives(t: np.ndarray, control_points: np.ndarray, seed: Seed, max_order: int) -> list[np.ndarray]:
    r"""``[P(t), P'(t), ..., P^(K)(t)]``, ``P^(r) = Σ_i b^{(r)}_{i,m}(t) P_i``, in one pass (no validation of t).

    The fast path for several derivative orders at the same parameters, by the compact form
    ``P = f0 Q0 + f1 Q1 + f2 Q2 = Q1 + f0 (Q0 - Q1) + f2 (Q2 - Q1)`` (``Q_k`` the degree-n Bézier
    curve on ``P_k..P_{k+n}``, n = m-2, and ``f1 = 1 - f0 - f2``) and Leibniz' rule

    ``P^(r) = Q1^(r) + Σ_s C(r,s) (f0^(s) (Q0 - Q1)^(r-s) + f2^(s) (Q2 - Q1)^(r-s))``,

    where the q-th derivative of a degree-n Bézier curve is the degree-(n-q) curve on the scaled
    differences ``n!/(n-q)! Δ^q``. One seed evaluation for all orders (:meth:`Seed.f0_f2_jets`:
    one sin/cos pass for the GHT family) and one Bernstein matrix per order; equal to the
    basis-matrix products ``seed_basis(t, m, seed, r) @ P`` up to rounding.

    Args:
        t: 1-D parameter array.
        control_points: (m+1, dim) array, m >= 2.
        seed: the curve's seed.
        max_order: K >= 0 (above 3 only for seeds that provide it).

    Returns:
        List of K+1 arrays of shape (len(t), dim).

    Raises:
        GHTError: an order the seed does not provide.
    """
    P = np.asarray(control_points, dtype=float)
    K = int(max_order)
    if t.size > _CHUNK:
        out = [np.empty((t.size, P.shape[1])) for _ in range(K + 1)]
        for lo in range(0, t.size, _CHUNK):
            sl = slice(lo, lo + _CHUNK)
            for o, part in zip(out, evaluate_derivatives(t[sl], P, seed, K)):
                o[sl] = part
        return out
    n = P.shape[0] - 3
    N, dim = t.size, P.shape[1]
    jets = seed.f0_f2_jets(t, K)
    Q: list[np.ndarray | None] = [
        np.matmul(bernstein(t, n - q), Dq) if Dq is not None else None  # (3, N, dim)
        for q, Dq in enumerate(_compact_differences(P, K))
    ]
    out = []
    for r in range(K + 1):
        Qr = Q[r]
        acc = Qr[2].copy() if Qr is not None else np.zeros((N, dim))
        for s in range(r + 1):
            Qq = Q[r - s]
            if Qq is None:
                continue
            f0, f2 = jets[s]
            term = f0[:, None] * Qq[0]
            term += f2[:, None] * Qq[1]
            c = comb(r, s)
            if c != 1:
                term *= c
            acc += term
        out.append(acc)
    return out


def _compact_differences(P: np.ndarray, K: int) -> list[np.ndarray | None]:
    """Control points of ``(Q0 - Q1)^(q)``, ``(Q2 - Q1)^(q)``, ``Q1^(q)`` for q = 0..K, each (3, n-q+1, dim)
    (``n!/(n-q)! Δ^q`` of the blocks; None for q > n), read-only. Kept for the last 32 control
    polygons (:func:`ght_cad.core._cache.readonly_cache`, keyed by the polygon's bytes)."""
    P = np.asarray(P, dtype=float)
    return _compact_differences_of(P.shape, int(K), P.tobytes())


@readonly_cache(maxsize=32)
def _compact_differences_of(shape: tuple[int, ...], K: int, data: bytes) -> list[np.ndarray | None]:
    """:func:`_compact_differences` of the float polygon of ``shape`` stored in ``data`` (C order)."""
    P = np.frombuffer(data, dtype=float).reshape(shape)
    n = P.shape[0] - 3
    P1 = P[1 : n + 2]
    D = np.stack([P[: n + 1] - P1, P[2 : n + 3] - P1, P1])
    out: list[np.ndarray | None] = []
    for q in range(K + 1):
        if q > n:
            out.append(None)
            continue
        if q:
            D = (n - q + 1) * np.diff(D, axis=1)
        out.append(D)
    return out


def basis(
    t: Any,
    degree: int,
    mu: float | None = None,
    nu: float | None = None,
    gamma: float | None = None,
    derivative: int = 0,
    *,
    seed: str | Seed = "ght",
) -> np.ndarray:
    r"""GHT-Bernstein basis functions of degree ``m`` (spec section 2), or their derivatives.

    ``b_{i,m}(t) = B_{i,n}(t) f0(t) + B_{i-1,n}(t) f1(t) + B_{i-2,n}(t) f2(t)``, ``n = m - 2``,
    with the GHT seed ``f0 = (1-w)(1-s)(1-μs) + w(1-t)^2``, ``f2 = (1-w)(1-c)(1-νc) + w t^2``,
    ``f1 = 1 - f0 - f2``, ``s = sin(πt/2)``, ``c = cos(πt/2)``, ``w = (1+γ)/2``.

    Args:
        t: parameter value(s) in [0, 1] (scalar or 1-D array).
        degree: basis degree m >= 2.
        mu, nu, gamma: shape parameters in [-1, 1] (None: the seed family's default, 0 for GHT).
        derivative: derivative order 0..3 (analytic).
        seed: seed family name (``"ght"``, ``"gbt"``, ``"bernstein"`` or a registered one) or a
            :class:`Seed` instance (then mu, nu, gamma are taken from it).

    Returns:
        Array of shape (len(t), degree+1); for scalar ``t`` shape (degree+1,).

    Raises:
        GHTError: degree < 2, shape parameter outside [-1, 1], NaN/inf or t outside [0, 1], bad
            derivative order.
    """
    m = check_degree(degree)
    r = _check_order(derivative)
    sd = make_seed(seed, mu, nu, gamma)
    tt, scalar = as_parameter_array(t)
    check_unit_interval("t", tt, slack=1e-9)  # outside [0, 1] the basis is not a partition of non-negative functions
    out = seed_basis(tt, m, sd, r)
    return out[0] if scalar else out


def bernstein_recursive_basis(t: Any, degree: int, seed: Seed) -> np.ndarray:
    """Reference evaluation by the recursion ``b_{i,m} = (1-t) b_{i,m-1} + t b_{i-1,m-1}``.

    Slow and only for cross-checking the closed form in tests.
    """
    tt, _ = as_parameter_array(t)
    b = seed.jet(tt, 0)
    for _m in range(3, check_degree(degree) + 1):
        nb = np.zeros((tt.size, b.shape[1] + 1))
        nb[:, :-1] += (1.0 - tt)[:, None] * b
        nb[:, 1:] += tt[:, None] * b
        b = nb
    return b


def parameter_jets(t: np.ndarray, mu: Any, nu: Any, gamma: Any, max_order: int) -> list[list[tuple[np.ndarray, np.ndarray, np.ndarray]]]:
    r"""Seed jets differentiated by the shape parameters, ready for :func:`basis_from_jets`.

    ``out[j][s] = (∂f0^(s)/∂θ_j, ∂f1^(s)/∂θ_j, ∂f2^(s)/∂θ_j)`` for ``θ = (μ, ν, γ)``, s = 0..K, from
    :func:`ght_cad.curves.seeds.ght_seed_parameter_derivatives` (``∂f1 = -∂f0 - ∂f2``, ``∂f0/∂ν = ∂f2/∂μ = 0``).
    Parameters broadcast against ``t`` as in :func:`ght_cad.curves.seeds.ght_seed_jet`; each entry gets a
    trailing axis of length 1 so that it broadcasts against Bernstein columns.
    """
    d = ght_seed_parameter_derivatives(t, mu, nu, gamma, max_order)
    out: list[list[tuple[np.ndarray, np.ndarray, np.ndarray]]] = [[], [], []]
    for d0mu, d0ga, d2nu, d2ga in d:
        z = np.zeros_like(d0mu)[..., None]
        out[0].append((d0mu[..., None], -d0mu[..., None], z))
        out[1].append((z, -d2nu[..., None], d2nu[..., None]))
        out[2].append((d0ga[..., None], -(d0ga + d2ga)[..., None], d2ga[..., None]))
    return out


def basis_parameter_derivatives(t: Any, degree: int, mu: float = 0.0, nu: float = 0.0, gamma: float = 0.0,
                                derivative: int = 0) -> np.ndarray:
    r"""Derivatives of the GHT basis ``b^{(r)}_{i,m}(t)`` with respect to ``μ, ν, γ`` (spec 8.1).

    ``∂b^{(r)}_{i,m}/∂θ = Σ_{s=0..r} C(r,s) Σ_{k=0..2} B^{(r-s)}_{i-k,n} ∂f_k^{(s)}/∂θ``, ``n = m-2``,
    with the closed-form seed derivatives of :func:`ght_cad.curves.seeds.ght_seed_parameter_derivatives`
    (``f0`` is bilinear in (μ, w), ``f2`` in (ν, w), ``w = (1+γ)/2``).

    Args:
        t: parameter value(s) in [0, 1] (scalar or 1-D array).
        degree: basis degree m >= 2.
        mu, nu, gamma: shape parameters in [-1, 1].
        derivative: t-derivative order r, 0..3.

    Returns:
        Array of shape (3, len(t), degree+1): ``∂/∂μ``, ``∂/∂ν``, ``∂/∂γ``; for scalar ``t`` (3, degree+1).

    Raises:
        GHTError: as :func:`basis`.
    """
    m = check_degree(degree)
    r = _check_order(derivative)
    make_seed("ght", mu, nu, gamma)  # validates the shape parameters
    tt, scalar = as_parameter_array(t)
    check_unit_interval("t", tt, slack=1e-9)
    bern = [bernstein(tt, m - 2, q) for q in range(r + 1)]
    out = np.stack([basis_from_jets(bern, jets, r) for jets in parameter_jets(tt, mu, nu, gamma, r)])
    return out[:, 0] if scalar else out
