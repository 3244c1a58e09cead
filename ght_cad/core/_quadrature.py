r"""The project's one Gauss–Legendre helper (issue 27; maths: "development by quadrature").

The n-point rule on [-1, 1] has the nodes ``x_k``, the zeros of the Legendre polynomial ``P_n``,
and the weights ``w_k = 2 / ((1 - x_k²) P_n'(x_k)²)``; ``Σ_k w_k f(x_k) = ∫_{-1}^{1} f`` exactly
for polynomials of degree ``2n - 1``. On [a, b]: ``t_k = a + h (x_k + 1)``, weights ``h w_k``,
``h = (b - a) / 2``.

The nodes are numpy's (:func:`numpy.polynomial.legendre.leggauss`, an eigenvalue problem of size
n), computed once per n (:func:`ght_cad.core._cache.readonly_cache`), so every caller gets the same
bits as a direct call of numpy.
"""

from __future__ import annotations

import numpy as np

from ._cache import readonly_cache


__all__ = ["leggauss", "gauss_legendre", "gauss_legendre_unit"]


@readonly_cache(maxsize=64)
def leggauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``numpy.polynomial.legendre.leggauss(n)``: nodes and weights of the n-point rule on
    [-1, 1], computed once per n (read-only arrays)."""
    return np.polynomial.legendre.leggauss(n)


def gauss_legendre(n: int, a: float = 0.0, b: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Gauss–Legendre nodes and weights on [a, b] (exact for polynomials of degree 2n-1):
    ``t = a + h (x + 1)``, ``w = h w_[-1,1]`` with ``h = (b - a) / 2`` (new, writable arrays)."""
    x, w = leggauss(int(n))
    h = 0.5 * (b - a)
    return a + h * (x + 1.0), h * w


@readonly_cache(maxsize=16)
def gauss_legendre_unit(n: int) -> tuple[np.ndarray, np.ndarray]:
    """:func:`gauss_legendre` on [0, 1], computed once per n (read-only arrays, shared)."""
    return gauss_legendre(n)
