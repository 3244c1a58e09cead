"""Curvature analysis, combs and the GHT-vs-Bézier curvature comparison."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ght_cad import GHTCurve
from ght_cad.curves.analysis import (
    bezier_chain_like,
    compare_curvature,
    curvature,
    curvature_comb_plot,
    curvature_derivative,
    curvature_profile,
    curvature_vector,
    joint_curvatures,
    signed_curvature,
)
from ght_cad.curves.composite import CompositeCurve
from ght_cad.core.errors import GHTError

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _rot(a: float) -> np.ndarray:
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def _ellipse_quarters(a: float, b: float) -> CompositeCurve:
    """(a cos θ, b sin θ), θ = π(s)/2: exact with γ = -1 (affine image of the quarter circle)."""
    q = GHTCurve([(1, 0), (1, 1), (0, 1)], gamma=-1)
    D = np.diag([a, b])
    return CompositeCurve([q.transformed(D @ _rot(j * math.pi / 2)) for j in range(4)], "G0", closed=True)


def _ellipse_truth(a: float, b: float, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    th = 0.5 * math.pi * s
    D = a * a * np.sin(th) ** 2 + b * b * np.cos(th) ** 2
    kappa = a * b / D**1.5
    dk_dth = -1.5 * a * b * D**-2.5 * (a * a - b * b) * np.sin(2 * th)
    return kappa, dk_dth / np.sqrt(D)


def test_ellipse_curvature_closed_form_2d_and_3d():
    a, b = 3.0, 1.25
    cc = _ellipse_quarters(a, b)
    s = np.linspace(0.0, 4.0, 81)
    k_true, dk_true = _ellipse_truth(a, b, s)
    np.testing.assert_allclose(curvature(cc, s), k_true, rtol=1e-12)
    np.testing.assert_allclose(signed_curvature(cc, s), k_true, rtol=1e-12)  # counter-clockwise
    np.testing.assert_allclose(curvature_derivative(cc, s), dk_true, rtol=1e-10, atol=1e-12)
    # the same ellipse embedded in a tilted plane of 3-D space: general-dimension formulas
    R3 = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    segs3 = [seg.with_control_points(np.column_stack([seg.control_points, np.zeros(3)]) @ R3.T + (1, 2, 3)) for seg in cc]
    cc3 = CompositeCurve(segs3, "G0", closed=True)
    np.testing.assert_allclose(curvature(cc3, s), k_true, rtol=1e-12)
    inner = s[(s % 1 > 0.02) & (s % 1 < 0.98)]
    np.testing.assert_allclose(curvature_derivative(cc3, inner), _ellipse_truth(a, b, inner)[1], rtol=1e-9, atol=1e-12)
    # curvature vector points to the centre side: K · (centre - X) > 0, |K| = κ
    K = curvature_vector(cc, s)
    np.testing.assert_allclose(np.linalg.norm(K, axis=1), k_true, rtol=1e-12)
    assert np.all(np.sum(K * -cc.evaluate(s), axis=1) > 0)


def test_circle_profile():
    cc = _ellipse_quarters(2.0, 2.0)
    prof = curvature_profile(cc, 50)
    assert prof["s"].shape == prof["kappa"].shape == prof["arc_length"].shape == (4 * 49 + 1,)
    np.testing.assert_allclose(prof["kappa"], 0.5, rtol=1e-13)
    np.testing.assert_allclose(prof["dkappa_ds"], 0.0, atol=1e-12)
    np.testing.assert_allclose(prof["arc_length"], prof["s"] * math.pi, rtol=1e-13)  # |X'| = π


@settings(max_examples=25)
@given(dim=st.sampled_from([2, 3, 4]), seed=st.integers(0, 2**32 - 1), shape=st.tuples(*[st.floats(-1, 1)] * 3))
def test_curvature_derivative_matches_finite_differences(dim, seed, shape):
    rng = np.random.default_rng(seed)
    c = GHTCurve(rng.normal(size=(6, dim)), *shape)
    t = np.linspace(0.15, 0.85, 8)
    speed = np.linalg.norm(c.derivative(t, 1), axis=1)
    assume(np.all(speed > 1e-2))
    k = curvature(c, t)
    assume(np.all(k > 1e-2) and np.all(k < 1e3))

    def central(h: float) -> np.ndarray:
        return (curvature(c, t + h) - curvature(c, t - h)) / (2 * h)

    # Richardson-extrapolated central differences: truncation O(h⁴), rounding ~1e-13 κ / h
    h = 1e-4
    # no zero of κ inside the stencil (|κ| is not differentiable there)
    window = curvature(c, (t[:, None] + np.linspace(-h, h, 41)[None, :]).ravel()).reshape(t.size, 41)
    assume(np.all(window.min(axis=1) > 0.5 * k))
    fd = (4 * central(h / 2) - central(h)) / 3 / speed
    scale = np.abs(fd).max() + np.abs(k).max()
    np.testing.assert_allclose(curvature_derivative(c, t), fd, rtol=1e-5, atol=1e-7 * scale)
    if dim == 2:
        np.testing.assert_allclose(signed_curvature(c, t), c.signed_curvature(t), rtol=1e-13)


def _wave_chain(rng, shapes, degrees, k, beta2, cont="G2") -> CompositeCurve:
    segs = []
    for i, (m, sh) in enumerate(zip(degrees, shapes)):
        x = np.linspace(i, i + 1, m + 1)
        y = 0.3 * np.sin(2 * np.pi * x) + 0.1 * rng.normal(size=m + 1)
        segs.append(GHTCurve(np.column_stack([x, y]), *sh))
    return CompositeCurve(segs, cont, k=k, beta2=beta2)


def _bernstein_over_ght_ratio(seg: GHTCurve, end: float) -> float:
    """κ of the same control points with γ = 1, divided by κ with seg's own basis, at one end.

    Both are (factor) × |leg1 × leg2| / |leg1|³ of the same end legs, so the ratio is a pure basis
    factor (independent of the geometry).
    """
    return float(curvature(seg.with_shape(0.0, 0.0, 1.0), end) / curvature(seg, end))


@settings(max_examples=30)
@given(
    shapes=st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, -0.5)), min_size=3, max_size=3),
    degrees=st.lists(st.integers(3, 7), min_size=3, max_size=3),
    k=st.lists(st.floats(0.5, 2.0), min_size=2, max_size=2),
    beta2=st.lists(st.floats(-1, 1), min_size=2, max_size=2),
    seed=st.integers(0, 2**32 - 1),
)
def test_g2_ght_chain_has_no_curvature_jump_bezier_chain_on_same_points_does(shapes, degrees, k, beta2, seed):
    """What is compared: one control polygon, two bases.

    The GHT chain is joined G2 (dependent points solved for the GHT basis); the Bézier chain uses
    exactly the same control points with γ = 1. GHT: |κ_R - κ_L| <= 1e-9 κ_max at every joint.
    Bézier: the relative jump equals the basis-factor prediction |ρ_B - ρ_A| / max(ρ_A, ρ_B)
    (ρ = κ_Bézier/κ_GHT at the joint end of each segment, a property of the bases alone), so it
    vanishes only when the two factors coincide; where they differ by > 1 % the jump is > 1 %.
    """
    rng = np.random.default_rng(seed)
    cc = _wave_chain(rng, shapes, degrees, k, beta2)
    res = compare_curvature(cc, samples_per_segment=60)
    kmax = res["ght"]["kappa_max"]
    jl, jr = np.array(res["ght"]["kappa_left"]), np.array(res["ght"]["kappa_right"])
    assert np.all(np.abs(jr - jl) <= 1e-9 * kmax), (jl, jr)
    assert all(g >= 2 for _, g in res["ght"]["orders"])
    assume(np.all(np.maximum(jl, jr) > 1e-3 * kmax))  # no inflection at a joint (ratio ill-defined)
    for j in range(cc.n_joints):
        a, b = cc.joint_segments(j)
        ra, rb = _bernstein_over_ght_ratio(a, 1.0), _bernstein_over_ght_ratio(b, 0.0)
        predicted = abs(rb - ra) / max(ra, rb)
        assert res["bezier"]["relative_jump"][j] == pytest.approx(predicted, rel=1e-6, abs=1e-9)
        if predicted > 0.01:
            assert res["bezier"]["relative_jump"][j] > 0.01
            assert res["bezier"]["orders"][j][1] < 2


@pytest.mark.slow
def test_comparison_example_and_png(tmp_path):
    rng = np.random.default_rng(21)
    shapes = [(0.5, -0.8, -1.0), (-0.6, 0.7, -0.8), (0.2, 0.9, -1.0)]
    cc = _wave_chain(rng, shapes, [5, 6, 5], k=[1.3, 0.8], beta2=[0.4, -0.2])
    out = tmp_path / "cmp.png"
    res = compare_curvature(cc, out)
    assert res["path"] == str(out) and out.read_bytes()[:8] == PNG_MAGIC
    assert res["ght"]["max_relative_jump"] < 1e-10
    assert min(res["bezier"]["relative_jump"]) > 0.02
    assert res["joints"] == [1.0, 2.0]
    import matplotlib.image

    img = matplotlib.image.imread(out)
    assert img.shape[1] > 2 * img.shape[0]  # three panels side by side
    # a G1 GHT chain does jump: the measure is not trivially zero
    g1 = _wave_chain(np.random.default_rng(21), shapes, [5, 6, 5], k=[1.3, 0.8], beta2=[0.0, 0.0], cont="G1")
    assert joint_curvatures(g1)["relative_jump"].max() > 0.01


def test_bezier_chain_like():
    rng = np.random.default_rng(5)
    cc = _wave_chain(rng, [(0.3, -0.3, -1.0)] * 3, [4, 5, 6], k=[1.2, 0.9], beta2=[0.1, 0.2])
    bez = bezier_chain_like(cc)
    for g, b in zip(cc.segments, bez.segments):
        np.testing.assert_array_equal(g.control_points, b.control_points)
        assert b.shape_parameters == (0.0, 0.0, 1.0)
    t = np.linspace(0, 1, 9)
    from math import comb

    seg = bez.segments[1]
    B = np.array([[comb(5, i) * x**i * (1 - x) ** (5 - i) for i in range(6)] for x in t])
    np.testing.assert_allclose(seg.evaluate(t), B @ seg.control_points, atol=1e-14)
    res = bezier_chain_like(cc, resolve=True)
    assert res.continuity == cc.continuity and res.g_parameters == cc.g_parameters
    assert all(r.g_order >= 2 for r in res.joint_reports())
    assert joint_curvatures(res)["relative_jump"].max() < 1e-10
    # free points kept, dependent ones moved
    np.testing.assert_array_equal(res.segments[1].control_points[3:], cc.segments[1].control_points[3:])
    assert not np.allclose(res.segments[1].control_points[1:3], cc.segments[1].control_points[1:3])


def test_comb_plots(tmp_path, monkeypatch):
    rng = np.random.default_rng(9)
    segs = [GHTCurve(rng.normal(size=(6, 3)) + 2 * i, 0.1, 0.2, -0.5) for i in range(3)]
    cc3 = CompositeCurve(segs, "G2", closed=True)
    for obj, name in ((cc3, "c3.png"), (segs[0], "one.png"), (_ellipse_quarters(2, 1), "ell.png")):
        p = curvature_comb_plot(obj, tmp_path / name, samples_per_segment=40, title=name)
        assert p.read_bytes()[:8] == PNG_MAGIC
    # atomic: a failing save leaves the old file untouched and no temporary file behind
    import matplotlib.figure

    target = tmp_path / "keep.png"
    target.write_bytes(b"old")

    def boom(self, *a, **k):
        raise RuntimeError("disk full")

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", boom)
    with pytest.raises(RuntimeError, match="disk full"):
        curvature_comb_plot(cc3, target)
    assert target.read_bytes() == b"old"
    assert sorted(f.name for f in tmp_path.iterdir()) == ["c3.png", "ell.png", "keep.png", "one.png"]


def test_errors(tmp_path):
    c = GHTCurve(np.random.default_rng(0).normal(size=(4, 3)))
    with pytest.raises(GHTError, match="expected a GHTCurve or CompositeCurve, got list"):
        curvature([[0, 0]], 0.5)
    with pytest.raises(GHTError, match="signed curvature needs a 2-D curve; this curve has dim=3"):
        signed_curvature(c, 0.5)
    with pytest.raises(GHTError, match="samples_per_segment=1 is not allowed"):
        curvature_comb_plot(c, tmp_path / "x.png", samples_per_segment=1)
    with pytest.raises(GHTError, match="scale=-1 is not allowed"):
        curvature_comb_plot(c, tmp_path / "x.png", scale=-1)
    with pytest.raises(GHTError, match="compare_curvature needs a CompositeCurve"):
        compare_curvature(c)
    assert not (tmp_path / "x.png").exists()
    with pytest.raises(GHTError, match="outside the parameter domain"):
        curvature(c, 1.5)
