r"""Planes as 4-vectors and the three-plane meet (spec section 5.1).

A plane is the 4-vector ``U = (u0, u1, u2, u3)`` meaning ``{x : u0 + u1 x + u2 y + u3 z = 0}``;
``U`` and ``ρU`` (ρ ≠ 0) are the same plane. ``(u1, u2, u3)`` is its normal. Three planes
``A, B, C`` meet in the homogeneous point

.. math::  X_j = (-1)^j \det([A; B; C] \text{ without column } j),\quad j = 0..3,

with Cartesian coordinates ``(X1, X2, X3) / X0`` (``X0 = 0``: the point is at infinity, i.e.
the three normals are coplanar).

Note on scale: as a *plane*, ``ρU`` equals ``U``; as a *control plane* of a dual curve the scale
acts like a rational weight (the spec's exact quarter cylinder uses ``(-r, 1, 1, 0)`` whose normal is
not unit). :func:`normalize_planes` rescales to unit normals when a scale-free representation is
wanted (objectives, spec section 7).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..core.errors import DegenerateGeometryError, GHTError

__all__ = [
    "plane_from_point_normal",
    "plane_from_points",
    "normalize_plane",
    "normalize_planes",
    "as_plane",
    "as_planes",
    "check_control_planes",
    "plane_normal",
    "plane_point",
    "signed_distance",
    "meet",
    "meet_matrix",
    "plucker",
    "meet_point",
    "line_of_planes",
    "PARALLEL_TOL",
]

#: sine of the angle below which two plane normals count as parallel (and a line as parallel to a plane)
PARALLEL_TOL = 1e-9


def _fmt(v: Any) -> str:
    return np.array2string(np.asarray(v, dtype=float), precision=6, separator=", ")


def _vec(name: str, value: Any, size: int) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise GHTError(f"{name}={value!r} is not a vector of {size} numbers") from None
    if arr.size != size:
        raise GHTError(f"{name} has {arr.size} components; expected {size}")
    if not np.all(np.isfinite(arr)):
        raise DegenerateGeometryError(f"{name}={_fmt(arr)} contains NaN or inf; all components must be finite")
    return arr


def plane_from_point_normal(point: Any, normal: Any) -> np.ndarray:
    r"""Plane through ``point`` with normal ``normal``: ``U = (-n·p, n1, n2, n3)``.

    The normal keeps its length (no normalization); use :func:`normalize_plane` for a unit normal.

    Args:
        point: a point ``p`` of the plane (3 numbers).
        normal: a non-zero normal ``n`` (3 numbers).

    Returns:
        The plane 4-vector, shape (4,).

    Raises:
        DegenerateGeometryError: zero normal, or NaN/inf in the input.
    """
    p = _vec("point", point, 3)
    n = _vec("normal", normal, 3)
    if not np.linalg.norm(n) > 0.0:
        raise DegenerateGeometryError(f"normal={_fmt(n)} has zero length; a plane needs a non-zero normal")
    return np.concatenate([[-float(n @ p)], n])


def plane_from_points(p0: Any, p1: Any, p2: Any) -> np.ndarray:
    r"""Plane through three points: normal ``n = (p1 - p0) × (p2 - p0)``, ``U = (-n·p0, n)``.

    The result is scaled to a unit normal (the cross product's length has no meaning here).

    Raises:
        DegenerateGeometryError: the points are collinear or coincident (``|n|`` below
            ``1e-12 |p1 - p0| |p2 - p0|``), or contain NaN/inf.
    """
    a = _vec("p0", p0, 3)
    b = _vec("p1", p1, 3)
    c = _vec("p2", p2, 3)
    e1, e2 = b - a, c - a
    n = np.cross(e1, e2)
    scale = np.linalg.norm(e1) * np.linalg.norm(e2)
    if not np.linalg.norm(n) > 1e-12 * scale or scale == 0.0:
        raise DegenerateGeometryError(
            f"points p0={_fmt(a)}, p1={_fmt(b)}, p2={_fmt(c)} are collinear or coincident; "
            "three points define a plane only when they span a triangle of non-zero area"
        )
    n = n / np.linalg.norm(n)
    return np.concatenate([[-float(n @ a)], n])


def as_plane(U: Any, name: str = "plane") -> np.ndarray:
    """Check and return one plane 4-vector (finite, non-zero normal).

    Raises:
        DegenerateGeometryError: NaN/inf or zero normal, naming ``name``.
        GHTError: not 4 numbers.
    """
    u = _vec(name, U, 4)
    if not np.linalg.norm(u[1:]) > 0.0:
        raise DegenerateGeometryError(
            f"{name}={_fmt(u)} has zero normal (u1, u2, u3) = 0; it is not a plane"
        )
    return u


def as_planes(planes: Any, name: str = "planes", *, min_count: int = 1) -> np.ndarray:
    """Check and return a (k, 4) array of planes (each finite with a non-zero normal).

    Raises:
        GHTError: wrong shape or too few planes.
        DegenerateGeometryError: a plane with NaN/inf or zero normal (its index is named).
    """
    try:
        arr = np.array(planes, dtype=float)
    except (TypeError, ValueError):
        raise GHTError(f"{name} could not be read as an array of plane 4-vectors") from None
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise GHTError(f"{name} must have shape (count, 4) (one 4-vector u0 + u1 x + u2 y + u3 z per plane); got shape {arr.shape}")
    if arr.shape[0] < min_count:
        raise GHTError(f"{name} has {arr.shape[0]} planes; at least {min_count} are required")
    for i, u in enumerate(arr):
        as_plane(u, f"{name}[{i}]")
    return arr


def check_control_planes(planes: Any, name: str = "planes", *, tol: float = PARALLEL_TOL) -> np.ndarray:
    r"""Validate control planes of a dual curve: finite, non-zero normals, no parallel neighbours.

    Neighbours ``U_i, U_{i+1}`` whose unit normals satisfy ``|n_i × n_{i+1}| <= tol`` are parallel
    (their line of intersection is at infinity) or coincident; both are rejected because the
    ruling at the ends (``U_0 ∩ U_1``, ``U_{m-1} ∩ U_m``) would not exist.

    Raises:
        DegenerateGeometryError: naming the offending index/indices and values.
    """
    arr = as_planes(planes, name, min_count=3)
    for i in range(arr.shape[0] - 1):
        n0 = arr[i, 1:] / np.linalg.norm(arr[i, 1:])
        n1 = arr[i + 1, 1:] / np.linalg.norm(arr[i + 1, 1:])
        s = float(np.linalg.norm(np.cross(n0, n1)))
        if s <= tol:
            d0 = arr[i, 0] / np.linalg.norm(arr[i, 1:])
            d1 = arr[i + 1, 0] / np.linalg.norm(arr[i + 1, 1:]) * float(np.sign(n0 @ n1))
            kind = "coincident" if abs(d0 - d1) <= 1e-12 * max(1.0, abs(d0)) else "parallel"
            raise DegenerateGeometryError(
                f"neighbouring control planes {name}[{i}]={_fmt(arr[i])} and {name}[{i+1}]={_fmt(arr[i+1])} "
                f"are {kind} (sine of the angle between their normals = {s:.3g} <= {tol:g}); "
                "neighbouring control planes must intersect in a line"
            )
    # a pencil: every control plane through one line (rank 2 of the 4-vectors); every U(t) and U'(t)
    # then contain that line, so every ruling is that one line and the surface has no width
    unit = arr / np.linalg.norm(arr, axis=1, keepdims=True)
    sv = np.linalg.svd(unit, compute_uv=False)
    if sv[2] <= tol * sv[0]:
        raise DegenerateGeometryError(
            f"the control planes ({name}) all pass through one line (a pencil of planes: singular values of the "
            f"normalized 4-vectors {sv[0]:.3g}, {sv[1]:.3g}, {sv[2]:.3g}); every ruling would be that line; "
            "control planes must not all share a line"
        )
    return arr


def normalize_plane(U: Any) -> np.ndarray:
    """``U / |(u1, u2, u3)|``: the same plane with a unit normal (sign kept)."""
    u = as_plane(U)
    return u / np.linalg.norm(u[1:])


def normalize_planes(planes: Any) -> np.ndarray:
    """Each row divided by the length of its normal (sign kept), shape (k, 4)."""
    arr = as_planes(planes)
    return arr / np.linalg.norm(arr[:, 1:], axis=1, keepdims=True)


def plane_normal(U: Any) -> np.ndarray:
    """Unit normal ``(u1, u2, u3) / |(u1, u2, u3)|``."""
    u = as_plane(U)
    return u[1:] / np.linalg.norm(u[1:])


def plane_point(U: Any) -> np.ndarray:
    """The point of the plane closest to the origin, ``-u0 n / |n|²``."""
    u = as_plane(U)
    return -u[0] * u[1:] / float(u[1:] @ u[1:])


def signed_distance(U: Any, points: Any) -> np.ndarray:
    """Signed distances ``(u0 + n·x) / |n|`` of points (shape (..., 3)) from plane ``U``."""
    u = as_plane(U)
    x = np.asarray(points, dtype=float)
    return (u[0] + x @ u[1:]) / np.linalg.norm(u[1:])


def meet(A: Any, B: Any, C: Any) -> np.ndarray:
    r"""Homogeneous meet point of three planes, ``X_j = (-1)^j det([A; B; C] without column j)``.

    Vectorized: ``A, B, C`` broadcast over leading dimensions, last dimension 4. The map is
    trilinear and alternating, so derivatives follow by the product rule (used by
    :mod:`ght_cad.developables.envelope`). ``X`` satisfies ``A·X = B·X = C·X = 0``. Computed from the
    Plücker coordinates ``p_ij = A_i B_j - A_j B_i`` of ``A ∧ B`` by expanding each 3×3 minor along
    the row of ``C``: ``det(cols i<j<k) = C_k p_ij - C_j p_ik + C_i p_jk``.

    Returns:
        Array of shape (..., 4); ``X0 = 0`` for a point at infinity, ``X = 0`` when the three
        planes share a line.
    """
    C = np.asarray(C, dtype=float)
    p = plucker(A, B)
    # x0 = c3 p12 - c2 p13 + c1 p23, x1 = -(c3 p02 - c2 p03 + c0 p23),
    # x2 = c3 p01 - c1 p03 + c0 p13, x3 = -(c2 p01 - c1 p02 + c0 p12)
    terms = C[..., _MEET_C] * p[..., _MEET_P]
    x = terms[..., 0] - terms[..., 1]
    x += terms[..., 2]
    x[..., 1::2] *= -1.0
    return x


def plucker(A: Any, B: Any) -> np.ndarray:
    r"""Plücker coordinates ``p_ij = A_i B_j - A_j B_i`` of the line ``A ∧ B`` of two planes.

    Args:
        A, B: plane 4-vectors, shape (..., 4); leading dimensions broadcast.

    Returns:
        Array of shape (..., 6) in the order ``(p01, p02, p03, p12, p13, p23)``.
    """
    A = np.asarray(A, dtype=float)
    B = np.asarray(B, dtype=float)
    return A[..., _PL_I] * B[..., _PL_J] - A[..., _PL_J] * B[..., _PL_I]


def meet_matrix(C: Any) -> np.ndarray:
    r"""The (6, 4) matrix ``M(C)`` with ``meet(A, B, C) = plucker(A, B) @ M(C)`` for one plane ``C``.

    ``meet`` is linear in ``C`` for a fixed line: ``X_j = Σ ±C_k p_..`` (see :func:`meet`); with
    several planes stack the matrices side by side to cut one line with all of them in one product.
    Equal to :func:`meet` up to rounding (the products are summed in BLAS order).

    Args:
        C: one plane 4-vector.

    Returns:
        The (6, 4) matrix.

    Raises:
        GHTError: ``C`` is not 4 finite numbers.
    """
    c = _vec("C", C, 4)
    M = np.zeros((6, 4))
    M[_MEET_P, np.arange(4)[:, None]] = _MEET_SIGN * c[_MEET_C]
    return M


# index tables of meet(): Plücker pairs (i, j), and per output j the (C index, Plücker index) triples
_PL_I = np.array([0, 0, 0, 1, 1, 2])
_PL_J = np.array([1, 2, 3, 2, 3, 3])
_MEET_C = np.array([[3, 2, 1], [3, 2, 0], [3, 1, 0], [2, 1, 0]])
_MEET_P = np.array([[3, 4, 5], [1, 2, 5], [0, 2, 4], [0, 1, 3]])
_MEET_SIGN = np.array([[1.0, -1.0, 1.0], [-1.0, 1.0, -1.0], [1.0, -1.0, 1.0], [-1.0, 1.0, -1.0]])


def meet_point(A: Any, B: Any, C: Any, *, names: Sequence[str] = ("A", "B", "C")) -> np.ndarray:
    """Cartesian meet point ``(X1, X2, X3) / X0`` of three planes.

    Raises:
        DegenerateGeometryError: the planes have no single common point (``|X0|`` below
            ``1e-12 |n_A| |n_B| |n_C|``), naming the planes.
    """
    a = as_plane(A, names[0])
    b = as_plane(B, names[1])
    c = as_plane(C, names[2])
    X = meet(a, b, c)
    scale = np.linalg.norm(a[1:]) * np.linalg.norm(b[1:]) * np.linalg.norm(c[1:])
    if not abs(X[0]) > 1e-12 * scale:
        raise DegenerateGeometryError(
            f"planes {names[0]}={_fmt(a)}, {names[1]}={_fmt(b)}, {names[2]}={_fmt(c)} do not meet in a "
            f"single point (det of their normals = {X[0]:.3g}); their normals must be linearly independent"
        )
    return X[1:] / X[0]


def line_of_planes(A: Any, B: Any) -> tuple[np.ndarray, np.ndarray]:
    r"""Line ``A ∩ B`` as (point closest to the origin, unit direction ``n_A × n_B / |..|``).

    Raises:
        DegenerateGeometryError: parallel or coincident planes.
    """
    a = as_plane(A, "A")
    b = as_plane(B, "B")
    d = np.cross(a[1:], b[1:])
    if not np.linalg.norm(d) > PARALLEL_TOL * np.linalg.norm(a[1:]) * np.linalg.norm(b[1:]):
        raise DegenerateGeometryError(
            f"planes A={_fmt(a)} and B={_fmt(b)} are parallel or coincident; they have no line of intersection"
        )
    # third plane through the origin with normal d closes the system
    p = meet_point(a, b, np.concatenate([[0.0], d]))
    return p, d / np.linalg.norm(d)
