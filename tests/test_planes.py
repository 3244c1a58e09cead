"""Planes as 4-vectors and the three-plane meet (spec 5.1)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from ght_cad.core.errors import DegenerateGeometryError, GHTError
from ght_cad.surfaces.planes import (
    as_planes,
    check_control_planes,
    line_of_planes,
    meet,
    meet_matrix,
    meet_point,
    normalize_plane,
    normalize_planes,
    plane_from_point_normal,
    plane_from_points,
    plane_normal,
    plane_point,
    plucker,
    signed_distance,
)

coord = st.floats(-10, 10, allow_nan=False)
vec3 = st.tuples(coord, coord, coord).map(np.array)
plane4 = st.tuples(coord, coord, coord, coord).map(np.array)


@given(vec3, vec3)
def test_point_normal_plane_contains_point(p, n):
    assume(np.linalg.norm(n) > 1e-3)
    U = plane_from_point_normal(p, n)
    # u0 + n·p = 0 (to round-off relative to the terms)
    assert abs(U[0] + U[1:] @ p) <= 1e-12 * (1 + np.linalg.norm(n) * np.linalg.norm(p))
    np.testing.assert_allclose(U[1:], n)  # the normal keeps its length
    np.testing.assert_allclose(plane_normal(U), n / np.linalg.norm(n), atol=1e-15)
    q = plane_point(U)
    assert abs(signed_distance(U, q)) <= 1e-12 * (1 + np.linalg.norm(p))


@given(vec3, vec3, vec3)
def test_three_point_plane(p0, p1, p2):
    e1, e2 = p1 - p0, p2 - p0
    assume(np.linalg.norm(np.cross(e1, e2)) > 1e-3 * (1 + np.linalg.norm(e1) * np.linalg.norm(e2)))
    U = plane_from_points(p0, p1, p2)
    assert abs(np.linalg.norm(U[1:]) - 1.0) <= 1e-14
    scale = 1 + max(np.linalg.norm(p) for p in (p0, p1, p2))
    for p in (p0, p1, p2):
        assert abs(signed_distance(U, p)) <= 1e-12 * scale


@given(plane4, plane4, plane4)
def test_meet_is_the_cofactor_vector(A, B, C):
    """X_j = (-1)^j det([A;B;C] without column j), and A·X = B·X = C·X = 0."""
    X = meet(A, B, C)
    M = np.vstack([A, B, C])
    for j in range(4):
        minor = np.delete(M, j, axis=1)
        assert abs(X[j] - (-1) ** j * np.linalg.det(minor)) <= 1e-9 * (1 + np.abs(M).max() ** 3)
    scale = 1 + np.abs(M).max() ** 4
    for P in (A, B, C):
        assert abs(P @ X) <= 1e-9 * scale


@given(plane4, plane4, plane4)
def test_meet_point_solves_the_linear_system(A, B, C):
    N = np.vstack([A[1:], B[1:], C[1:]])
    assume(abs(np.linalg.det(N)) > 1e-2 * (1 + np.abs(N).max() ** 3))
    x = meet_point(A, B, C)
    expect = np.linalg.solve(N, -np.array([A[0], B[0], C[0]]))
    np.testing.assert_allclose(x, expect, rtol=1e-8, atol=1e-8 * (1 + np.abs(expect).max()))


def test_meet_vectorized_matches_single():
    rng = np.random.default_rng(1)
    A, B, C = rng.normal(size=(3, 7, 4))
    X = meet(A, B, C)
    for i in range(7):
        np.testing.assert_allclose(X[i], meet(A[i], B[i], C[i]), rtol=1e-14)


@given(plane4, plane4, plane4)
def test_meet_is_plucker_times_meet_matrix(A, B, C):
    """``meet(A, B, C) = plucker(A, B) @ meet_matrix(C)`` (linear in C), to rounding: 1e-13 of the
    largest product |C| |A| |B|; ``p_ij = A_i B_j - A_j B_i`` in the order 01, 02, 03, 12, 13, 23."""
    p = plucker(A, B)
    pairs = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    np.testing.assert_array_equal(p, [A[i] * B[j] - A[j] * B[i] for i, j in pairs])
    scale = 1e-13 * (1 + np.abs(A).max() * np.abs(B).max() * np.abs(C).max())
    np.testing.assert_allclose(p @ meet_matrix(C), meet(A, B, C), rtol=0, atol=scale)


def test_meet_broadcasts_like_its_operands():
    """One line cut with two planes (the boundary-curve case): shapes (n,1,4), (n,1,4), (1,2,4)."""
    rng = np.random.default_rng(2)
    A, B = rng.normal(size=(2, 5, 4))
    E = rng.normal(size=(2, 4))
    X = meet(A[:, None, :], B[:, None, :], E[None, :, :])
    assert X.shape == (5, 2, 4)
    for i in range(5):
        for k in range(2):
            np.testing.assert_array_equal(X[i, k], meet(A[i], B[i], E[k]))
    M = np.hstack([meet_matrix(e) for e in E])
    np.testing.assert_allclose((plucker(A, B) @ M).reshape(5, 2, 4), X, rtol=0, atol=1e-13 * np.abs(X).max())
    with pytest.raises(GHTError, match="C has 3 components"):
        meet_matrix([1.0, 2.0, 3.0])


def test_normalization_keeps_the_plane_and_sign():
    U = np.array([-6.0, 0.0, 3.0, 4.0])
    V = normalize_plane(U)
    np.testing.assert_allclose(V, U / 5.0)
    W = normalize_planes([U, -2 * U])
    np.testing.assert_allclose(np.linalg.norm(W[:, 1:], axis=1), 1.0)
    np.testing.assert_allclose(W[1], -W[0])


def test_line_of_planes():
    A = np.array([-1.0, 1.0, 0.0, 0.0])  # x = 1
    B = np.array([-2.0, 0.0, 1.0, 0.0])  # y = 2
    p, d = line_of_planes(A, B)
    np.testing.assert_allclose(p, [1.0, 2.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(np.abs(d), [0.0, 0.0, 1.0], atol=1e-15)


# -- bad input: every message names the bad value and what is allowed ------------------------
def test_zero_normal_is_rejected():
    with pytest.raises(DegenerateGeometryError, match=r"normal=\[0., 0., 0.\] has zero length"):
        plane_from_point_normal((1, 2, 3), (0, 0, 0))
    with pytest.raises(DegenerateGeometryError, match=r"planes\[1\].*zero normal"):
        as_planes([(1, 0, 0, 1), (5, 0, 0, 0), (1, 1, 0, 0)])


def test_nan_is_rejected_with_name():
    with pytest.raises(DegenerateGeometryError, match=r"point=.*nan.*must be finite"):
        plane_from_point_normal((np.nan, 0, 0), (0, 0, 1))
    with pytest.raises(DegenerateGeometryError, match=r"planes\[2\]=.*NaN or inf"):
        check_control_planes([(0, 1, 0, 0), (0, 1, 1, 0), (np.inf, 0, 1, 0)])


def test_collinear_points_are_rejected():
    with pytest.raises(DegenerateGeometryError, match=r"collinear or coincident.*non-zero area"):
        plane_from_points((0, 0, 0), (1, 1, 1), (2, 2, 2))
    with pytest.raises(DegenerateGeometryError, match=r"collinear or coincident"):
        plane_from_points((1, 0, 0), (1, 0, 0), (0, 1, 0))


def test_parallel_and_coincident_neighbours_are_rejected():
    with pytest.raises(DegenerateGeometryError, match=r"planes\[1\]=.*planes\[2\]=.*are parallel.*must intersect in a line"):
        check_control_planes([(0, 1, 0, 0), (-1, 0, 1, 0), (-3, 0, 2, 0)])
    with pytest.raises(DegenerateGeometryError, match=r"planes\[0\]=.*planes\[1\]=.*are coincident"):
        check_control_planes([(-1, 1, 0, 0), (-2, 2, 0, 0), (0, 0, 1, 0)])
    # a flipped sign is still the same plane
    with pytest.raises(DegenerateGeometryError, match=r"are coincident"):
        check_control_planes([(-1, 1, 0, 0), (1, -1, 0, 0), (0, 0, 1, 0)])


def test_meet_point_of_planes_without_a_common_point():
    with pytest.raises(DegenerateGeometryError, match=r"do not meet in a single point.*linearly independent"):
        meet_point((0, 1, 0, 0), (-1, 1, 0, 0), (0, 0, 1, 0))
    with pytest.raises(DegenerateGeometryError, match=r"parallel or coincident"):
        line_of_planes((0, 0, 0, 1), (-3, 0, 0, 2))


def test_wrong_shapes():
    with pytest.raises(GHTError, match=r"shape \(count, 4\).*got shape \(2, 3\)"):
        as_planes([(1, 2, 3), (4, 5, 6)])
    with pytest.raises(GHTError, match=r"3 planes; at least|has 2 planes; at least 3"):
        check_control_planes([(0, 1, 0, 0), (0, 0, 1, 0)])
