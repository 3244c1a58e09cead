"""Composite curves: joints hold after construction and after every edit (spec section 4)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ght_cad import GHTCurve
from ght_cad.curves.composite import CompositeCurve
from ght_cad.curves.continuity import Continuity
from ght_cad.core.errors import GHTError, SingularJoinError

param = st.floats(-1.0, 1.0, allow_nan=False)
shape3 = st.tuples(param, param, param)


def _regular(seg: GHTCurve) -> bool:
    """All newest-point coefficients at both ends are away from zero (no singular joint)."""
    return all(
        abs(seg.newest_point_coefficient(r, end=e)) > 1e-3 for r in range(min(3, seg.degree) + 1) for e in (0, 1)
    )


def _rot(a: float) -> np.ndarray:
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def _assert_joints(cc: CompositeCurve) -> None:
    for j, (rep, c) in enumerate(zip(cc.joint_reports(), cc.continuity)):
        assert rep.satisfies(c), (j, c, str(rep), rep.c_residuals, rep.g_residuals)
        if c.geometric and c.order >= 1:
            assert rep.k == pytest.approx(cc.g_parameters[j][0], rel=1e-8)


def _assert_free_points_kept(cc: CompositeCurve, user: list[np.ndarray]) -> None:
    for i, seg in enumerate(cc.segments):
        free = [p for p in range(seg.degree + 1) if p not in cc.dependent_indices(i)]
        np.testing.assert_array_equal(seg.control_points[free], user[i][free])


@settings(max_examples=60)
@given(
    n=st.integers(1, 4),
    closed=st.booleans(),
    conts=st.lists(st.sampled_from(list(Continuity)), min_size=4, max_size=4),
    degrees=st.lists(st.integers(2, 8), min_size=4, max_size=4),
    shapes=st.lists(shape3, min_size=4, max_size=4),
    edit=st.tuples(st.integers(0, 3), shape3),
    seed=st.integers(0, 2**32 - 1),
)
def test_joints_hold_after_construction_and_set_shape(n, closed, conts, degrees, shapes, edit, seed):
    rng = np.random.default_rng(seed)
    nj = n if closed else n - 1
    conts = conts[:nj]
    degrees = list(degrees[:n])
    for j in range(1, n):
        degrees[j] = max(degrees[j], conts[j - 1].order)
    if closed:
        r_prev = conts[n - 2].order if n >= 2 else conts[0].order
        degrees[n - 1] = max(degrees[n - 1], r_prev + conts[n - 1].order + 1)
    dim = 3
    user = [rng.normal(size=(m + 1, dim)) for m in degrees]
    segs = [GHTCurve(p, *s) for p, s in zip(user, shapes[:n])]
    assume(all(_regular(s) for s in segs))
    k = list(rng.uniform(0.4, 2.5, nj))
    b2 = list(rng.uniform(-1, 1, nj))
    b3 = list(rng.uniform(-1, 1, nj))
    for j, c in enumerate(conts):
        if not c.geometric:
            k[j], b2[j], b3[j] = 1.0, 0.0, 0.0
    cc = CompositeCurve(segs, conts, closed=closed, k=k, beta2=b2, beta3=b3)
    assert cc.n_joints == nj
    _assert_joints(cc)
    _assert_free_points_kept(cc, user)
    # edit one segment's shape parameters: everything downstream is re-solved
    idx, (mu, nu, gamma) = edit
    idx %= n
    assume(_regular(segs[idx].with_shape(mu, nu, gamma)))
    before = [s.control_points.copy() for s in cc.segments]
    cc.set_shape(idx, mu=mu, nu=nu, gamma=gamma)
    assert cc.segments[idx].shape_parameters == (mu, nu, gamma)
    _assert_joints(cc)
    _assert_free_points_kept(cc, user)
    # the incremental re-solve equals a fresh solve bit for bit
    fresh_segs = list(segs)
    fresh_segs[idx] = segs[idx].with_shape(mu, nu, gamma)
    fresh = CompositeCurve(fresh_segs, conts, closed=closed, k=k, beta2=b2, beta3=b3)
    for x, y in zip(cc.segments, fresh.segments):
        np.testing.assert_array_equal(x.control_points, y.control_points)
    # upstream segments (before idx, except a closed chain's last one) are untouched
    for i in range(idx):
        np.testing.assert_array_equal(cc.segments[i].control_points, before[i])


def test_closed_circle_from_quarter_arcs():
    # gamma = -1: (1,0),(1,1),(0,1) is exactly a quarter of the unit circle
    q = GHTCurve([(1, 0), (1, 1), (0, 1)], gamma=-1)
    arcs = [q.transformed(_rot(j * math.pi / 2)) for j in range(4)]
    cc = CompositeCurve(arcs, "G0", closed=True)
    assert cc.arc_length() == pytest.approx(2 * math.pi, rel=1e-13)
    s = np.linspace(0.0, 4.0, 401)
    np.testing.assert_allclose(cc.curvature(s), 1.0, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(cc.evaluate(s), axis=1), 1.0, rtol=1e-14)
    # C∞ joints (uniform angular speed): reported C3 although only G0 was imposed
    assert [(r.c_order, r.g_order) for r in cc.joint_reports()] == [(3, 3)] * 4


def test_global_parameter():
    rng = np.random.default_rng(2)
    segs = [GHTCurve(rng.normal(size=(m + 1, 2)), 0.2, -0.1, g) for m, g in ((4, -1.0), (5, 0.3), (6, 0.9))]
    cc = CompositeCurve(segs, ["C2", "G2"], k=[1.0, 1.8], beta2=[0.0, 0.4])
    sol = cc.segments
    for j in range(3):
        np.testing.assert_array_equal(cc.evaluate(j + 0.25), sol[j].evaluate(0.25))
        np.testing.assert_array_equal(cc.derivative(j + 0.25, 3), sol[j].derivative(0.25, 3))
        np.testing.assert_allclose(cc.evaluate(float(j)), sol[j].control_points[0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(cc.evaluate(3.0), sol[2].control_points[-1], rtol=0, atol=1e-14)
    # C2 joint 0: first and second derivatives agree from both sides
    for r in (1, 2):
        np.testing.assert_allclose(sol[0].derivative(1.0, r), cc.derivative(1.0, r), rtol=1e-12, atol=1e-12)
    assert cc.evaluate(np.linspace(0, 3, 7)).shape == (7, 2)
    assert cc.arc_length() == pytest.approx(sum(s.arc_length() for s in sol), rel=1e-14)
    for bad in (-0.1, 3.01, float("nan")):
        with pytest.raises(GHTError):
            cc.evaluate(bad)
    with pytest.raises(GHTError, match=r"s=3.01 is outside the parameter domain \[0, 3\]"):
        cc.evaluate(3.01)


def test_to_dict_round_trip_is_exact_and_json():
    rng = np.random.default_rng(4)
    segs = [GHTCurve(rng.normal(size=(m + 1, 3)), *rng.uniform(-0.9, 0.9, 3)) for m in (5, 4, 7)]
    cc = CompositeCurve(segs, ["G3", "C1", "G2"], closed=True, k=[1.5, 1.0, 0.8], beta2=[0.2, 0, -0.3], beta3=[0.1, 0, 0])
    data = json.loads(json.dumps(cc.to_dict()))
    back = CompositeCurve.from_dict(data)
    assert back.closed and back.continuity == cc.continuity and back.g_parameters == cc.g_parameters
    for a, b in zip(cc.segments, back.segments):
        np.testing.assert_array_equal(a.control_points, b.control_points)
        assert a.shape_parameters == b.shape_parameters
    with pytest.raises(GHTError, match="'segments'"):
        CompositeCurve.from_dict({"foo": 1})


def test_point_edits():
    rng = np.random.default_rng(8)
    segs = [GHTCurve(rng.normal(size=(6, 2)), 0.1, 0.2, -0.5) for _ in range(3)]
    cc = CompositeCurve(segs, "G2", k=1.3, beta2=0.2)
    assert cc.dependent_indices(0) == [] and cc.dependent_indices(1) == [0, 1, 2]
    with pytest.raises(GHTError, match=r"control point 1 of segment 2 is determined by a joint"):
        cc.set_control_point(2, 1, (5.0, 5.0))
    old2 = cc.segments[2].control_points.copy()
    cc.set_control_point(1, 4, (7.0, -3.0))  # last-but-one point of segment 1 moves segment 2's start
    np.testing.assert_array_equal(cc.segments[1].control_points[4], (7.0, -3.0))
    assert not np.allclose(cc.segments[2].control_points[1:3], old2[1:3])
    np.testing.assert_array_equal(cc.segments[2].control_points[3:], old2[3:])
    _assert_joints(cc)
    cc.set_control_points(0, rng.normal(size=(9, 2)))  # a different degree is fine
    assert cc.segments[0].degree == 8
    _assert_joints(cc)
    # closed chain: the last segment's last points are dependent too
    cl = CompositeCurve(segs, ["C1", "C1", "G2"], closed=True)
    assert cl.dependent_indices(2) == [0, 1, 3, 4, 5]


def test_errors_and_failed_edit_leaves_chain_unchanged():
    q = GHTCurve([(0, 0), (1, 1), (2, 0)], 0.3, 0.3, -0.5)
    r = GHTCurve([(2, 0), (3, 1), (4, 0)], 0.0, 0.0, 0.0)
    with pytest.raises(GHTError, match="segments is empty"):
        CompositeCurve([])
    # the same segment listed twice: refused naming both places (it used to be joined to itself)
    with pytest.raises(GHTError, match=r"segments\[2\] is the same GHTCurve object as segments\[0\]"):
        CompositeCurve([q, r, q], "G1")
    chain = CompositeCurve([q, r], "G1")
    with pytest.raises(GHTError, match=r"segments\[1\] is the same GHTCurve object as segments\[0\]"):
        chain.set_segment(1, q)
    chain.set_segment(0, q)  # replacing a segment by itself is no repetition
    # a moved copy repeats the shape: allowed
    CompositeCurve([q, q.transformed(np.eye(2), (2.0, 0.0))], "G1")
    with pytest.raises(GHTError, match="segments\\[1\\] has dimension 3"):
        CompositeCurve([q, GHTCurve(np.zeros((3, 3)))])
    with pytest.raises(GHTError, match="continuity has 2 entries but the chain has 1 joints"):
        CompositeCurve([q, r], ["C1", "C1"])
    with pytest.raises(SingularJoinError, match="k=-1 at joint 0 is not allowed"):
        CompositeCurve([q, r], "G1", k=-1.0)
    with pytest.raises(GHTError, match="joint 0 is C1 but k=2"):
        CompositeCurve([q, r], ["C1"], k=[2.0])
    with pytest.raises(SingularJoinError, match=r"closed chain: segment 1 has degree 2 .* needs degree >= 3"):
        CompositeCurve([q, r], "C1", closed=True)
    with pytest.raises(SingularJoinError, match=r"closed chain: segment 0 has degree 2 .* needs degree >= 3"):
        CompositeCurve([q], "C1", closed=True)
    cc = CompositeCurve([q, r], "C1")
    before = cc.segments[1].control_points.copy()
    # degree 2 with gamma = -1, mu = -1 has c_1 = 0: the edit is refused and nothing changes
    with pytest.raises(SingularJoinError, match=r"joint 0 \(segment 0 -> 1\).*c_1"):
        cc.set_shape(1, mu=-1.0, gamma=-1.0)
    np.testing.assert_array_equal(cc.segments[1].control_points, before)
    assert cc.segments[1].shape_parameters == (0.0, 0.0, 0.0)
    with pytest.raises(GHTError, match=r"index=5 is out of range; allowed segment indices are 0..1"):
        cc.set_shape(5, mu=0.1)
    with pytest.raises(GHTError, match="mu=3 is outside"):
        cc.set_shape(0, mu=3.0)


def test_incremental_resolve_stops_early_but_matches_full_solve():
    rng = np.random.default_rng(13)
    segs = [GHTCurve(rng.normal(size=(7, 2)), 0.1, 0.2, -0.3) for _ in range(6)]
    cc = CompositeCurve(segs, "G2", k=1.1, beta2=0.1)
    before = [s.control_points.copy() for s in cc.segments]
    cc.set_shape(2, mu=-0.5)
    # segment 2 changes, 3 re-solves (its start depends on 2's end), 4.. are unchanged
    assert not np.array_equal(cc.segments[3].control_points, before[3])
    for i in (0, 1, 4, 5):
        np.testing.assert_array_equal(cc.segments[i].control_points, before[i])
    fresh = CompositeCurve([s if i != 2 else s.with_shape(mu=-0.5) for i, s in enumerate(segs)], "G2", k=1.1, beta2=0.1)
    for x, y in zip(cc.segments, fresh.segments):
        np.testing.assert_array_equal(x.control_points, y.control_points)
    # degree 2 + C2 everywhere: every point is dependent, a change runs to the end of the chain
    low = [GHTCurve(rng.normal(size=(3, 2)), 0.1, 0.2, -0.3) for _ in range(4)]
    cl = CompositeCurve(low, "C2")
    old_last = cl.segments[3].control_points.copy()
    cl.set_shape(1, gamma=0.5)
    assert not np.array_equal(cl.segments[3].control_points, old_last)
    _assert_joints(cl)


def test_set_shape_and_set_segment_on_seed_families():
    rng = np.random.default_rng(12)
    gbt = GHTCurve(rng.normal(size=(5, 2)), 0.3, -0.2, seed="gbt")
    bern = GHTCurve(rng.normal(size=(6, 2)), seed="bernstein")
    cc = CompositeCurve([gbt, bern], "G2", k=1.2, beta2=0.1)
    cc.set_shape(0, gamma=0.5)  # a GBT segment becomes a general GHT one (GBT = GHT at gamma=-1)
    assert cc.segments[0].shape_parameters == (0.3, -0.2, 0.5)
    cc.set_shape(1, mu=0.4)
    assert cc.segments[1].shape_parameters == (0.4, 0.0, 1.0)
    _assert_joints(cc)
    new = GHTCurve(rng.normal(size=(8, 2)), -0.5, 0.5, -0.9)
    cc.set_segment(1, new)
    assert cc.segments[1].degree == 7
    np.testing.assert_array_equal(cc.segments[1].control_points[3:], new.control_points[3:])
    _assert_joints(cc)
    with pytest.raises(GHTError, match="segment has dimension 3; this chain has dimension 2"):
        cc.set_segment(0, GHTCurve(np.zeros((3, 3))))


@pytest.mark.parametrize(
    "closed,degree,cont", [(False, 5, "G2"), (False, 4, "C2"), (True, 5, "G2"), (True, 7, "G3"), (False, 3, "G1")]
)
def test_through_points(closed, degree, cont):
    Q = np.array([(0, 0, 0), (1, 1, 0.5), (3, 1.2, 1), (4, 0, 0.2), (6, -1, 0)], dtype=float)
    cc = CompositeCurve.through_points(Q, degree=degree, continuity=cont, closed=closed, mu=0.2, nu=-0.3, gamma=-0.5)
    assert cc.n_segments == (5 if closed else 4) and cc.closed == closed
    s = np.arange(cc.n_segments + 1, dtype=float)
    expected = np.vstack([Q, Q[:1]]) if closed else Q
    np.testing.assert_allclose(cc.evaluate(s), expected, rtol=0, atol=1e-13)
    _assert_joints(cc)
    chords = np.linalg.norm(np.diff(expected, axis=0), axis=1)
    if cont.startswith("G"):
        assert cc.g_parameters[0][0] == pytest.approx(chords[1] / chords[0], rel=1e-14)


def test_through_points_errors():
    with pytest.raises(GHTError, match="points 1 and 2 coincide"):
        CompositeCurve.through_points([(0, 0), (1, 1), (1, 1), (2, 0)])
    with pytest.raises(GHTError, match=r"degree=4 is too low for continuity G2 \(closed\) through points; it needs degree >= 5"):
        CompositeCurve.through_points([(0, 0), (1, 1), (2, 0)], degree=4, closed=True)
    with pytest.raises(GHTError, match="points has 2 points; at least 3 are required"):
        CompositeCurve.through_points([(0, 0), (1, 1)], closed=True)
