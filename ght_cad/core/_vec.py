"""Small vector kernels over the last axis (length 3), used on the hot paths of unrolling.

``numpy.cross`` and ``numpy.linalg.norm`` spend most of their time on axis handling when the
arrays hold a few hundred points; these do the same arithmetic directly.
"""

from __future__ import annotations

import numpy as np

#: ``numpy.einsum`` (explicit subscripts, no ``optimize``: one call of its C routine), public API
#: only. Against the private ``numpy._core.multiarray.c_einsum`` it wraps, alternating blocks of
#: bench_unroll's cone and envelope unrolls (30 and 1,000 rulings) gave median time ratio 0.99
#: (min 0.89, 8 blocks each, numpy 2.4.6): the wrapper's cost is below this machine's noise
einsum = np.einsum


def cross(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``x × y`` over the last axis (length 3), with broadcasting.

    ``(x₁y₂ - x₂y₁, x₂y₀ - x₀y₂, x₀y₁ - x₁y₀)`` per point: the arithmetic of ``numpy.cross``
    (the same results bit for bit) without its axis handling.
    """
    x0, x1, x2 = x[..., 0], x[..., 1], x[..., 2]
    y0, y1, y2 = y[..., 0], y[..., 1], y[..., 2]
    if x.shape == y.shape and x.dtype == y.dtype:  # the usual case, without broadcast_shapes' overhead
        out = np.empty(x.shape, dtype=x.dtype)
    else:
        out = np.empty(np.broadcast_shapes(x.shape, y.shape), dtype=np.result_type(x, y))
    np.subtract(x1 * y2, x2 * y1, out=out[..., 0])
    np.subtract(x2 * y0, x0 * y2, out=out[..., 1])
    np.subtract(x0 * y1, x1 * y0, out=out[..., 2])
    return out


def dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``Σ_k x_k y_k`` over the last axis (row-wise dot product)."""
    return einsum("...k,...k->...", x, y)


def norm(x: np.ndarray) -> np.ndarray:
    """Euclidean norm over the last axis, ``sqrt(Σ_k x_k²)``."""
    return np.sqrt(einsum("...k,...k->...", x, x))


def unique_inverse(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``numpy.unique(a, return_inverse=True)`` of a 1-D float array (the same two arrays), by a
    stable argsort: the map's parameters arrive as runs of sorted samples, where the stable
    (radix/merge) sort is 3-6x faster than ``numpy.unique``'s quicksort (1,800 parameters:
    11 µs against 65 µs); ``a[perm]`` sorted, ``mask`` the first of each value, inverse by
    ``cumsum(mask) - 1`` scattered back through ``perm``."""
    perm = a.argsort(kind="stable")
    s = a[perm]
    mask = np.empty(s.size, dtype=bool)
    if s.size:
        mask[0] = True
        np.not_equal(s[1:], s[:-1], out=mask[1:])
    inv = np.empty(s.size, dtype=np.intp)
    inv[perm] = np.cumsum(mask) - 1
    return s[mask], inv


def stack(arrays: "list[np.ndarray] | tuple[np.ndarray, ...]", axis: int = 0) -> np.ndarray:
    """``numpy.stack(arrays, axis)`` (the same array) of equal-shaped, equal-dtype arrays by one
    ``empty`` and a copy per array: numpy's version spends ~4 µs a call on its generic checks,
    on the unrolling's hot path (11 calls a face). Anything else goes to ``numpy.stack``."""
    first = arrays[0]
    if type(first) is not np.ndarray or not all(type(a) is np.ndarray and a.shape == first.shape
                                                and a.dtype == first.dtype for a in arrays):
        return np.stack(arrays, axis=axis)
    nd = first.ndim + 1
    ax = axis + nd if axis < 0 else axis
    if not 0 <= ax < nd:
        return np.stack(arrays, axis=axis)
    out = np.empty(first.shape[:ax] + (len(arrays),) + first.shape[ax:], dtype=first.dtype)
    lead = (slice(None),) * ax
    for i, a in enumerate(arrays):
        out[lead + (i,)] = a
    return out
