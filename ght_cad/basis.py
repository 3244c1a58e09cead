r"""Degree-m GHT-Bernstein basis (spec section 2), vectorized, with analytic derivatives.

The basis of degree ``m >= 2`` is built from a degree-2 seed ``(f0, f1, f2)`` by the recursion
``b_{i,m} = (1-t) b_{i,m-1} + t b_{i-1,m-1}``; its closed form, used here, is

.. math::  b_{i,m}(t) = B_{i,n}(t) f_0(t) + B_{i-1,n}(t) f_1(t) + B_{i-2,n}(t) f_2(t),\quad n = m-2

with ``B_{j,n}`` the classical Bernstein polynomials (zero outside ``0..n``). Derivatives follow by
Leibniz' rule, ``b^{(r)}_{i,m} = Σ_s C(r,s) Σ_k B^{(r-s)}_{i-k,n} f_k^{(s)}``.
"""

from __future__ import annotations

from math import comb, factorial
from typing import Any

import numpy as np

from ._validate import as_parameter_array, check_degree
from .errors import GHTError
from .seeds import MAX_DERIVATIVE, Seed, make_seed

__all__ = ["basis", "seed_basis", "bernstein", "bernstein_recursive_basis"]


def _check_order(derivative: Any) -> int:
    try:
        r = int(derivative)
    except (TypeError, ValueError):
        raise GHTError(f"derivative={derivative!r} is not an integer; allowed orders are 0..{MAX_DERIVATIVE}") from None
    if r != derivative or not 0 <= r <= MAX_DERIVATIVE:
        raise GHTError(f"derivative={derivative!r} is not allowed; analytic derivatives exist for orders 0..{MAX_DERIVATIVE}")
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
    out = np.zeros((N, n + 1))
    if derivative > n:
        return out
    q = n - derivative
    # powers of t and (1-t) for the degree-q polynomials
    tp = np.empty((N, q + 1))
    sp = np.empty((N, q + 1))
    tp[:, 0] = 1.0
    sp[:, 0] = 1.0
    if q:
        s = 1.0 - t
        for j in range(1, q + 1):
            np.multiply(tp[:, j - 1], t, out=tp[:, j])
            np.multiply(sp[:, j - 1], s, out=sp[:, j])
    low = tp * sp[:, ::-1]
    low *= np.array([comb(q, j) for j in range(q + 1)], dtype=float)
    if derivative == 0:
        return low
    scale = factorial(n) / factorial(q)
    for l in range(derivative + 1):
        coef = scale * (-1) ** (derivative - l) * comb(derivative, l)
        out[:, l : l + q + 1] += coef * low
    return out


def seed_basis(t: np.ndarray, degree: int, seed: Seed, derivative: int = 0) -> np.ndarray:
    r"""Basis ``b^{(r)}_{i,m}(t)`` for an already-built :class:`Seed` (no validation of t).

    ``b^{(r)}_{i,m} = Σ_{s=0..r} C(r,s) Σ_{k=0..2} B^{(r-s)}_{i-k,n} f_k^{(s)}``, n = m - 2.

    Returns:
        Array of shape (len(t), degree+1).
    """
    n = degree - 2
    N = t.shape[0]
    out = np.zeros((N, degree + 1))
    for s in range(derivative + 1):
        f = seed.jet(t, s)
        B = bernstein(t, n, derivative - s)
        c = comb(derivative, s)
        for k in range(3):
            fk = f[:, k : k + 1] if c == 1 else c * f[:, k : k + 1]
            out[:, k : k + n + 1] += B * fk
    return out


def basis(
    t: Any,
    degree: int,
    mu: float = 0.0,
    nu: float = 0.0,
    gamma: float = 0.0,
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
        mu, nu, gamma: shape parameters in [-1, 1].
        derivative: derivative order 0..3 (analytic).
        seed: seed family name (``"ght"``, ``"gbt"``, ``"bernstein"`` or a registered one) or a
            :class:`Seed` instance (then mu, nu, gamma are taken from it).

    Returns:
        Array of shape (len(t), degree+1); for scalar ``t`` shape (degree+1,).

    Raises:
        GHTError: degree < 2, shape parameter outside [-1, 1], NaN/inf in t, bad derivative order.
    """
    m = check_degree(degree)
    r = _check_order(derivative)
    sd = make_seed(seed, mu, nu, gamma)
    tt, scalar = as_parameter_array(t)
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
