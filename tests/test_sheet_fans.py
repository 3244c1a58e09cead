"""Neutral-surface flat patterns (spec 6.1) of developable lofts WITH FANS (spec 5.7), against an
independent reference built piece by piece between the loft's joint rulings.

The reference uses positions only: the neutral edges ``a + δ n``, ``b + δ n`` with
``n = ((a' + b')/2) × g / |...|`` (first derivatives; no ``a''``, ``n'`` or finite differences)
sampled on every smooth piece ``[λ_k, λ_{k+1}]`` (8192 chords), lengths by Romberg-extrapolated
chord sums and areas by Romberg-extrapolated sums of the ruling quads' vector areas
``½ |(b_{i+1} - a_i) × (a_{i+1} - b_i)|``. Before the measures were split at the breakpoints, the
report of the hull plate (T = 4, K = 0.4) said 5.8e-10 (boundary) and 9.1e-10 (area) while the
development itself was exact; the dory's chine plate said 2.1e-7.
"""

from __future__ import annotations

import numpy as np
import pytest

from ght_cad import GHTCurve
from ght_cad.developables.loft import developable_loft
from ght_cad.sheetmetal.sheet import OffsetRuledSurface, Sheet, ruling_normal
from ght_cad.unrolling.unroll import ruled_area, unroll

#: relative tolerance of the neutral pattern against the reference (measured: below 4e-15)
FAN_RTOL = 1e-12

SHEER = [[0, -900, 1200], [1500, -1250, 1150], [3000, -1300, 1180], [4500, -1100, 1300]]
CHINE = [[0, -700, 300], [1500, -1050, 200], [3000, -1150, 250], [4500, -950, 450]]


@pytest.fixture(scope="module")
def lofts():
    """The hull plate of examples/design_hull_plate.toml (fan_b, main, fan_b) in both rail orders:
    swapping the rails flips the normal, so the material lies on the same (convex) side of the
    fans' apex with side "normal" on one and side "reverse" on the other."""
    chine, sheer = GHTCurve(CHINE), GHTCurve(SHEER)
    return {"normal": developable_loft(chine, sheer), "reverse": developable_loft(sheer, chine)}


def _romberg(values: list[float]) -> float:
    """Two Richardson steps on h², h²/4, h²/16 values (O(h⁶))."""
    l1, l2, l4 = values
    r1, r2 = (4 * l2 - l1) / 3, (4 * l4 - l2) / 3
    return (16 * r2 - r1) / 15


def _chords(p: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(p, axis=0), axis=1).sum())


def _quads(a: np.ndarray, b: np.ndarray) -> float:
    return float(0.5 * np.linalg.norm(np.cross(b[1:] - a[:-1], a[1:] - b[:-1]), axis=1).sum())


def reference(surface, delta: float, m: int = 8192) -> dict[str, float]:
    """Lengths of the neutral edges a, b and the neutral area, piece by piece (module doc)."""
    cuts = [0.0, *surface.breakpoints, 1.0]
    out = {"a": 0.0, "b": 0.0, "area": 0.0}
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        u = np.linspace(lo, hi, m + 1)
        n = ruling_normal(surface, u, order=0)[0]
        a, b = surface.a(u) + delta * n, surface.b(u) + delta * n
        for step_vals, key in (([_chords(a[::s]) for s in (4, 2, 1)], "a"), ([_chords(b[::s]) for s in (4, 2, 1)], "b")):
            out[key] += _romberg(step_vals)
        out["area"] += _romberg([_quads(a[::s], b[::s]) for s in (4, 2, 1)])
    return out


def test_reference_is_exact_on_the_design_surface(lofts) -> None:
    """The reference itself (δ = 0) against the loft's own closed-form quantities: rails' lengths
    by quadrature of |a'|, area by ruled_area (piecewise Gauss–Legendre)."""
    s = lofts["normal"]
    ref = reference(s, 0.0)
    pan = unroll(s, rulings=4).panels[0]
    la = next(e for e in pan.loops[0] if e.name == "a").length_3d
    assert ref["a"] == pytest.approx(la, rel=FAN_RTOL)
    assert ref["area"] == pytest.approx(ruled_area(s), rel=FAN_RTOL)


@pytest.mark.parametrize("side", ["normal", "reverse"])
@pytest.mark.parametrize("T,K", [(1.0, 0.5), (4.0, 0.4), (12.0, 0.3)])
def test_neutral_pattern_of_a_fan_loft_is_exact(lofts, side: str, T: float, K: float) -> None:
    s = lofts[side]
    kinds = [g.kind for g in s.segments]  # fans at both ends (apex on the sheer: fan_b, or fan_a reversed)
    assert kinds in (["fan_b", "main", "fan_b"], ["fan_a", "main", "fan_a"])
    sheet = Sheet(T, K, side)
    delta = sheet.neutral_offset
    assert delta == pytest.approx((1 if side == "normal" else -1) * K * T, rel=1e-15)
    ref = reference(s, delta)
    pat = unroll(s, sheet=sheet, rulings=6, samples=1025)
    pan = pat.panels[0]
    edges = {e.name: e for e in pan.loops[0]}
    # the pattern's flat lengths and area against the independent 3-D reference
    for name in ("a", "b"):
        assert edges[name].length_flat == pytest.approx(ref[name], rel=FAN_RTOL), name
        assert edges[name].length_3d == pytest.approx(ref[name], rel=FAN_RTOL), name
    assert pan.area_flat == pytest.approx(ref["area"], rel=FAN_RTOL)
    # the development map itself, read piece by piece (not through the report's measures)
    dev = pan.development
    cuts = [0.0, *s.breakpoints, 1.0]
    flat_len = {"a": 0.0, "b": 0.0}
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        u = np.linspace(lo, hi, 4097)
        for name, v in (("a", 0.0), ("b", 1.0)):
            p = dev.map(u, np.full_like(u, v))
            flat_len[name] += _romberg([_chords(p[::st]) for st in (4, 2, 1)])
    for name in ("a", "b"):
        assert flat_len[name] == pytest.approx(ref[name], rel=FAN_RTOL), name
    # the neutral fans' apex edge is an arc of radius |δ| (the offset turns the apex into an arc):
    # the b edge is longer than the design's by |δ| × the turning of the fans' normals
    assert ref["b"] > next(e for e in unroll(s, rulings=0).panels[0].loops[0] if e.name == "b").length_3d
    # and the pattern's own report says round-off
    assert pat.errors["boundary_length"] <= FAN_RTOL
    assert pat.errors["area"] <= FAN_RTOL
    # the sheet's inside / neutral / outside lengths (piecewise quadrature) against the reference
    for e in pat.sheet["edges"]:
        if e["edge"] in ("a", "b"):
            assert e["neutral"] == pytest.approx(ref[e["edge"]], rel=FAN_RTOL)
            assert e["flat"] == pytest.approx(ref[e["edge"]], rel=FAN_RTOL)
            for key, t in (("inside", 0.0), ("outside", sheet.outside_offset)):
                assert e[key] == pytest.approx(reference(s, t, m=2048)[e["edge"]], rel=FAN_RTOL), key


def test_offset_surface_keeps_the_breakpoints(lofts) -> None:
    s = lofts["normal"]
    off = OffsetRuledSurface(s, 1.6)
    assert off.breakpoints == s.breakpoints and len(s.breakpoints) == 2


def _arc_then_line(t: np.ndarray) -> np.ndarray:
    """A G1 curve: a quarter circle of radius 0.01 for t ∈ [0, 0.3] (speed 0.0524), then its tangent
    line of length 2 (speed 2.86): curvature and speed jump at t = 0.3."""
    t = np.asarray(t, dtype=float)
    th = np.minimum(t, 0.3) / 0.3 * (np.pi / 2)
    arc = 0.01 * np.stack([np.sin(th), 1 - np.cos(th)], axis=-1)
    s = np.maximum(t - 0.3, 0.0) / 0.7 * 2.0
    return arc + np.stack([np.zeros_like(s), s], axis=-1)


def test_boundary_edge_with_breaks_measures_a_g1_curve_exactly() -> None:
    from ght_cad.pattern.flat_pattern import BoundaryEdge, piecewise_romberg_length, piecewise_samples

    exact = 0.01 * np.pi / 2 + 2.0
    whole = BoundaryEdge("e", _arc_then_line, _arc_then_line, samples=257)
    whole.measure()
    pieces = BoundaryEdge("e", _arc_then_line, _arc_then_line, samples=257, breaks=(0.3,))
    pieces.measure()
    assert pieces.length_flat == pytest.approx(exact, rel=1e-14)
    assert pieces.length_3d == pytest.approx(exact, rel=1e-14)  # no length given: measured piecewise
    assert abs(whole.length_flat - exact) > 1e-9 * exact  # one rule across the break: O(h³)
    assert pieces.flat.shape == (257, 2)  # the outline polyline is unchanged
    t = piecewise_samples((0.3, 0.0, 1.0, 0.3), 8)
    assert t.tolist() == np.concatenate([np.linspace(0, 0.3, 9)[:-1], np.linspace(0.3, 1, 9)]).tolist()
    assert piecewise_samples((), 8) is None
    assert piecewise_romberg_length(_arc_then_line(t), 8) == pytest.approx(exact, rel=1e-6)


def test_metric_check_does_not_difference_across_a_joint() -> None:
    """The dory's bottom plate (examples/design_dory_multichine_plated.toml, keel to chine) has a
    joint ruling at λ = 0.85656, 1.5e-3 from the metric grid's u = 0.85478: the 5-point stencil
    (h = 1e-3) straddled it and the first-fundamental-form check said 0.29° (a measure's artifact:
    the development is exact); samples are now kept off the joints."""
    from pathlib import Path

    import tomllib

    from ght_cad.app.design import build_surfaces
    from ght_cad.app.design.schema import parse_design

    path = Path(__file__).resolve().parents[1] / "examples" / "design_dory_multichine_plated.toml"
    design = parse_design(tomllib.loads(path.read_text()), str(path))
    bottom = next(b for b in build_surfaces(design) if b.design.surface.name == "bottom").surface
    grid = np.linspace(0.02, 0.98, 24)
    assert any(abs(g - b) < 2e-3 for g in grid for b in bottom.breakpoints)  # the case this guards
    pat = unroll(bottom, rulings=0)
    assert pat.errors["angle_deg"] <= 1e-6
    assert pat.errors["boundary_length"] <= FAN_RTOL and pat.errors["area"] <= FAN_RTOL
