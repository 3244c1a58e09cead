"""Input validation shared by the whole package (clear messages naming the bad value)."""

from __future__ import annotations

import math
import numbers
from typing import Any

import numpy as np

from .errors import DegenerateGeometryError, GHTError, ShapeParameterError

__all__ = [
    "check_shape_parameter",
    "check_degree",
    "check_finite_array",
    "check_points",
    "as_parameter_array",
    "is_real",
]


def is_real(value: Any) -> bool:
    """True for a real number of any kind except bool: Python int/float and numpy scalars of
    every integer and floating dtype (``np.int64`` is not an ``int``, ``np.float32`` not a ``float``)."""
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def _exact(v: float) -> str:
    """Shortest text that reads back as ``v`` (``repr``), without a trailing ``.0``: 3 -> '3',
    -1.0000001 -> '-1.0000001' (``:g`` would print '-1', hiding why it is outside [-1, 1])."""
    r = repr(float(v))
    return r[:-2] if r.endswith(".0") else r


def check_shape_parameter(name: str, value: Any) -> float:
    """Return ``value`` as float after checking it is finite and in [-1, 1].

    Raises:
        ShapeParameterError: naming the parameter, its value and the allowed range.
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ShapeParameterError(
            f"{name}={value!r} is not a number; shape parameters must be real numbers in [-1, 1]"
        ) from None
    if not math.isfinite(v):
        raise ShapeParameterError(f"{name}={v} is not finite; allowed range is [-1, 1]")
    if v < -1.0 or v > 1.0:
        raise ShapeParameterError(
            f"{name}={_exact(v)} is outside the allowed range [-1, 1] "
            "(outside it the GHT basis loses non-negativity)"
        )
    return v


def check_degree(degree: Any, minimum: int = 2) -> int:
    """Return ``degree`` as int after checking it is an integer >= ``minimum``.

    Raises:
        GHTError: naming the bad degree and the allowed values.
    """
    if isinstance(degree, bool) or not isinstance(degree, numbers.Integral):
        if isinstance(degree, numbers.Real) and float(degree).is_integer():
            degree = int(degree)
        else:
            raise GHTError(f"degree={degree!r} is not an integer; degree must be an integer >= {minimum}")
    degree = int(degree)
    if degree < minimum:
        raise GHTError(f"degree={degree} is not allowed; degree must be an integer >= {minimum}")
    return degree


#: largest coordinate magnitude of control points: products of up to six coordinates (areas, the
#: determinants of the developability measures, squared lengths of derivatives of high degree) stay
#: far from float overflow (1.8e308); 1e300 gave an infinite arc length with numpy warnings
MAX_COORDINATE = 1e50


def check_finite_array(name: str, arr: np.ndarray) -> np.ndarray:
    """Raise if ``arr`` holds NaN or inf, naming the first offending index."""
    bad = ~np.isfinite(arr)
    if bad.any():
        idx = tuple(int(i) for i in np.argwhere(bad)[0])
        raise GHTError(
            f"{name} contains a non-finite value {float(arr[idx])!r} at index {idx}; all values must be finite"
        )
    return arr


def check_coordinate_range(name: str, arr: np.ndarray, limit: float = MAX_COORDINATE) -> np.ndarray:
    """Raise if an entry of the (finite) ``arr`` exceeds ``limit`` in magnitude (derivatives,
    lengths and areas computed from it would overflow), naming the first offending index."""
    big = np.abs(arr) > limit
    if big.any():
        idx = tuple(int(i) for i in np.argwhere(big)[0])
        raise GHTError(f"{name} has the value {float(arr[idx]):g} at index {idx}, beyond ±{limit:g}; allowed: "
                       f"coordinates within ±{limit:g} (lengths and areas of larger ones overflow)")
    return arr


def check_points(
    name: str,
    points: Any,
    *,
    min_count: int = 1,
    dims: tuple[int, ...] | None = None,
) -> np.ndarray:
    """Return ``points`` as a float (count, dim) array after checking shape and finiteness.

    Args:
        name: argument name used in error messages.
        points: array-like of shape (count, dim).
        min_count: smallest allowed count of points.
        dims: allowed dimensions (``None``: any dim >= 1).

    Raises:
        GHTError: wrong shape, too few points, wrong dimension or non-finite entries.
    """
    try:
        arr = np.array(points, dtype=float)
    except (TypeError, ValueError) as exc:
        raise GHTError(f"{name} could not be read as an array of numbers: {exc}") from None
    if arr.ndim != 2 or arr.shape[1] < 1:
        raise GHTError(
            f"{name} must be a 2-D array of shape (count, dim); got shape {arr.shape}"
        )
    if arr.shape[0] < min_count:
        raise GHTError(f"{name} has {arr.shape[0]} points; at least {min_count} are required")
    if dims is not None and arr.shape[1] not in dims:
        raise GHTError(f"{name} has dimension {arr.shape[1]}; allowed dimensions are {dims}")
    check_finite_array(name, arr)
    check_coordinate_range(name, arr)
    return arr


def as_parameter_array(t: Any, name: str = "t") -> tuple[np.ndarray, bool]:
    """Return (1-D float array, was_scalar) for a curve parameter argument; rejects NaN/inf."""
    try:
        arr = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise GHTError(f"{name}={t!r} is not allowed; use real numbers in [0, 1] (a scalar or a 1-D array)") from None
    scalar = arr.ndim == 0
    arr = np.atleast_1d(arr)
    if arr.ndim != 1:
        raise GHTError(f"{name} must be a scalar or a 1-D array; got shape {arr.shape}")
    if arr.size and not np.all(np.isfinite(arr)):
        check_finite_array(name, arr)
    return arr, scalar


def check_unit_interval(name: str, arr: np.ndarray, slack: float = 1e-12) -> None:
    """Raise if any entry of ``arr`` is outside [0, 1] (parameter domain)."""
    if arr.size and (arr.min() < -slack or arr.max() > 1.0 + slack):
        bad = arr[(arr < -slack) | (arr > 1 + slack)][0]
        raise GHTError(f"{name}={_exact(float(bad))} is outside the parameter domain [0, 1]")


def nonzero_norm(name: str, vec: np.ndarray, tol: float = 1e-14) -> float:
    """Return |vec|, raising DegenerateGeometryError when it vanishes."""
    n = float(np.linalg.norm(vec))
    if not n > tol:
        raise DegenerateGeometryError(f"{name} has zero length ({n:g}); it must be non-degenerate")
    return n


def affine_parts(matrix: Any, offset: Any, dim: int) -> tuple[np.ndarray, np.ndarray]:
    """Linear part ``A`` (dim, dim) and translation ``b`` (dim,) of ``x -> A x + b``.

    Args:
        matrix: (dim, dim) linear part, or a (dim+1, dim+1) homogeneous matrix.
        offset: translation b (dim,), only with a (dim, dim) matrix (None: zero).

    Raises:
        GHTError: another matrix shape, or an offset given with a homogeneous matrix.
    """
    A = np.asarray(matrix, dtype=float)
    d = dim
    if A.shape == (d + 1, d + 1):
        if offset is not None:
            raise GHTError("offset must be omitted with a homogeneous matrix")
        return A[:d, :d], A[:d, d]
    if A.shape == (d, d):
        return A, (np.zeros(d) if offset is None else np.asarray(offset, dtype=float).reshape(d))
    raise GHTError(f"matrix has shape {A.shape}; expected ({d}, {d}) or ({d+1}, {d+1})")
