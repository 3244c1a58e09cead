"""One blank from pieces meeting tangentially (issue 23, ght_cad.join_panels): a cylinder cut
along a wavy curve into two ruled pieces (any parameter direction) unrolls to its rectangle; a
fold (G0) keeps its panels with matching marks; a blank that would overlap itself in the flat is
kept apart; with a sheet the blank is the neutral rectangle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ght_cad.sheetmetal.join_panels import outline_self_overlap, rigid_motion_onto
from ght_cad.surfaces.ruled import FunctionRuledSurface
from ght_cad.sheetmetal.sheet import Sheet
from ght_cad.unrolling.unroll import unroll_composite

R, THETA, H = 50.0, 2.0, 60.0


def _arc(u: np.ndarray, k: int, z: float | np.ndarray = 0.0) -> np.ndarray:
    """k-th u-derivative of (R cos Θu, R sin Θu, z) (z's derivatives given by the caller)."""
    ph = THETA * u + k * math.pi / 2
    out = np.stack([R * THETA**k * np.cos(ph), R * THETA**k * np.sin(ph), np.zeros_like(u)], axis=1)
    out[:, 2] = z
    return out


def _seam(u: np.ndarray, k: int) -> np.ndarray:
    """k-th derivative of the seam height h(u) = 20 + 8 sin(3u) + 5 u²."""
    s = 8 * 3**k * np.sin(3 * u + k * math.pi / 2)
    return s + (20 + 5 * u * u if k == 0 else 10 * u if k == 1 else 10.0 if k == 2 else 0.0)


def _piece(lower: bool, reverse_u: bool = False, swap_ab: bool = False) -> FunctionRuledSurface:
    """The part of the cylinder below (above) the seam; parameter reversed and/or rails swapped."""
    sgn = -1.0 if reverse_u else 1.0

    def at(u: np.ndarray, k: int, which: str) -> np.ndarray:
        uu = 1.0 - u if reverse_u else u
        if which == "floor":
            return sgn**k * _arc(uu, k, 0.0)
        if which == "seam":
            return sgn**k * _arc(uu, k, _seam(uu, k))
        return sgn**k * _arc(uu, k, H if k == 0 else 0.0)

    rails = ("floor", "seam") if lower else ("seam", "top")
    if swap_ab:
        rails = rails[::-1]
    return FunctionRuledSurface(lambda u, k: at(u, k, rails[0]), lambda u, k: at(u, k, rails[1]))


def _rectangle_checks(pn, width: float, height: float) -> None:
    loop = pn.loop_polylines()[0]
    assert outline_self_overlap(loop) == 0
    # the blank is a rectangle: its extents along the first edge's chord and across it
    first = pn.loops[0][0].flat
    d = (first[-1] - first[0]) / np.linalg.norm(first[-1] - first[0])
    ext = np.ptp(loop @ np.array([d, [-d[1], d[0]]]).T, axis=0)
    np.testing.assert_allclose(sorted(ext), sorted([width, height]), rtol=1e-12)
    assert math.isclose(pn.area_flat, width * height, rel_tol=1e-12)


@pytest.mark.parametrize("reverse_u, swap_ab", [(False, False), (True, False), (False, True), (True, True)])
def test_cylinder_cut_along_a_curve_is_one_rectangle(reverse_u: bool, swap_ab: bool) -> None:
    """Both pieces developed on their own and placed across the curved seam: one panel, the
    rectangle R Θ × H (area to 1e-12, sides to 1e-9: the outline polygon), the flat area the sum
    of the pieces' to 1e-12, the seam drawn as marks, whatever the second piece's parameter
    direction (the placement reflects it where its development is mirrored)."""
    parts = [_piece(True), _piece(False, reverse_u, swap_ab)]
    apart = unroll_composite(parts, labels=["lower", "upper"], rulings=4)
    pat = unroll_composite(parts, labels=["lower", "upper"], rulings=4, join=True)
    (pn,) = pat.panels
    assert pn.label == "lower+upper"
    assert math.isclose(pn.area_flat, sum(p.area_flat for p in apart.panels), rel_tol=1e-12)
    _rectangle_checks(pn, R * THETA, H)
    assert pat.errors["max"] < 1e-12
    (j,) = pn.info["joints"]
    assert j["kind"] == "mark" and j["tangency_deg"] < 1e-9 and j["fit"] < 1e-9 * H
    assert len(pn.marks) == 32 and len(pn.bend_lines) == 8
    # the development map of the blank: part 0 at u in [0, 1], part 1 at [1, 2]
    y = pn.map(np.array([0.5, 1.5]), np.array([0.0, 0.0]))
    assert np.all(np.isfinite(y))


def test_fold_keeps_panels_with_marks_and_flat_continuation_joins() -> None:
    """Two unit squares sharing an edge: folded 90° (G0) they stay two panels marked E1; in one
    plane they are one 2 × 1 blank with the shared edge as a bend line."""
    def lin(p0, d):
        return lambda u, k: (np.asarray(p0, float) + np.outer(u, d)) if k == 0 else np.outer(np.ones_like(u) if k == 1 else np.zeros_like(u), d)

    sq = FunctionRuledSurface(lin([0, 0, 0], [1, 0, 0]), lin([0, 1, 0], [1, 0, 0]))
    folded = FunctionRuledSurface(lin([1, 0, 0], [0, 0, 1]), lin([1, 1, 0], [0, 0, 1]))
    flat = FunctionRuledSurface(lin([1, 0, 0], [1, 0, 0]), lin([1, 1, 0], [1, 0, 0]))
    pat = unroll_composite([sq, folded], labels=["s", "f"], rulings=0, join=True)
    assert [p.label for p in pat.panels] == ["s", "f"]
    assert [t[2] for t in pat.labels].count("E1") == 2
    pat = unroll_composite([sq, flat], labels=["s", "f"], rulings=0, join=True)
    (pn,) = pat.panels
    _rectangle_checks(pn, 2.0, 1.0)
    assert len(pn.bend_lines) == 1 and math.isclose(float(np.linalg.norm(np.diff(pn.bend_lines[0], axis=0))), 1.0, rel_tol=1e-12)


def _helix_band(turn: int) -> FunctionRuledSurface:
    """Turn ``turn`` of the tangent developable of the helix c(t) = (cos t, sin t, 0.3 t) between
    the offsets 0.3 c'(t) and 1.5 c'(t) along its tangents."""
    s = 2 * math.pi

    def c(t: np.ndarray, k: int) -> np.ndarray:
        ph = t + k * math.pi / 2
        out = np.stack([np.cos(ph), np.sin(ph), np.zeros_like(t)], axis=1)
        out[:, 2] = 0.3 * t if k == 0 else (0.3 if k == 1 else 0.0)
        return out

    def rail(off: float):
        return lambda u, k: s**k * (c(s * (turn + u), k) + off * c(s * (turn + u), k + 1))

    return FunctionRuledSurface(rail(0.3), rail(1.5))


def test_blank_that_overlaps_itself_is_kept_apart() -> None:
    """Two turns of a helical tangent-developable band are one smooth sheet in 3-D, but its
    development winds round more than once: the joined outline crosses itself, so the two turns
    stay separate panels (marked E1 on the shared ruling) and say why."""
    pat = unroll_composite([_helix_band(0), _helix_band(1)], labels=["t1", "t2"], rulings=2, join=True)
    assert [p.label for p in pat.panels] == ["t1", "t2"]
    assert all("overlaps itself" in p.info["join"] for p in pat.panels)
    assert [t[2] for t in pat.labels].count("E1") == 2
    one = unroll_composite([_helix_band(0)], labels=["t1"], rulings=2, join=True)
    assert "join" not in one.panels[0].info


def test_sheet_blank_is_the_neutral_rectangle() -> None:
    """With a sheet (T = 2, K = 0.4) the joined blank is the neutral surface's rectangle
    (R + σ K T) Θ × H, σ the side of the pieces' normal (outward +1), to 1e-12; its sheet entry holds
    every part's edges (renamed) and one forming row per part (constant radius)."""
    parts = [_piece(True), _piece(False)]
    n = parts[0].normal(np.array([0.5]), np.array([0.5]))[0]
    sigma = 1.0 if n @ _arc(np.array([0.5]), 0)[0] > 0 else -1.0
    pat = unroll_composite(parts, labels=["lower", "upper"], rulings=4, sheet=Sheet(2.0, 0.4), join=True)
    (pn,) = pat.panels
    _rectangle_checks(pn, (R + sigma * 0.8) * THETA, H)
    sh = pn.info["sheet"]
    assert {e["edge"] for e in sh["edges"]} == {f"{p}:{e}" for p in ("lower", "upper")
                                               for e in ("a", "b", "ruling u=0", "ruling u=1")}
    assert len(sh["forming"]) == 2 and all(r["line"] == 0 for r in sh["forming"])
    assert sh["forming"][1]["position"] > sh["forming"][0]["position"]


def test_rigid_motion_onto_maps_the_chord() -> None:
    rng = np.random.default_rng(3)
    for det in (1.0, -1.0):
        q0, q1 = rng.normal(size=2), rng.normal(size=2)
        a = rng.uniform(0, 2 * math.pi)
        d = np.array([math.cos(a), math.sin(a)]) * np.linalg.norm(q1 - q0)
        p0 = rng.normal(size=2)
        M, t = rigid_motion_onto(p0, p0 + d, q0, q1, det)
        np.testing.assert_allclose(M @ q0 + t, p0, atol=1e-14)
        np.testing.assert_allclose(M @ q1 + t, p0 + d, atol=1e-14)
        assert math.isclose(np.linalg.det(M), det, rel_tol=1e-14) and np.allclose(M.T @ M, np.eye(2), atol=1e-15)


_WALL = """
name = "cylinder-wall"
units = "mm"

[[curves]]
name = "foot"
control_points = [[0, 0, 0], [100, 60, 0], [200, -20, 0], [300, 40, 0]]

[[curves]]
name = "seam"
control_points = [[0, 0, 30], [100, 60, 70], [200, -20, 10], [300, 40, 45]]

[[curves]]
name = "top"
control_points = [[0, 0, 120], [100, 60, 120], [200, -20, 120], [300, 40, 120]]

[[surfaces]]
name = "lower"
type = "rails"
curve_a = "foot"
curve_b = "seam"

[[surfaces]]
name = "upper"
type = "rails"
curve_a = "seam"
curve_b = "top"

[unroll]
rulings = 6
"""


@pytest.mark.slow
@pytest.mark.parametrize("sheet", ["", "\n[sheet]\nthickness = 2.0\nk_factor = 0.4\n"])
def test_design_surfaces_meeting_g1_along_a_rail_are_one_blank(sheet: str) -> None:
    """Two `rails` lofts over one planar profile (every rail has the same x, y control points: one
    general cylinder) share the wavy seam rail and meet G1 there: one blank `lower+upper`, the
    rectangle (profile length) x 120 (with a sheet: the neutral profile, whose length equals the
    profile's here because the profile's end tangents are parallel), area = sum of the per-surface
    panels to 1e-12; `per-surface` keeps two panels marked E1."""
    from ght_cad.app.design import build_surfaces, parse_design_text, unroll_surfaces

    d = parse_design_text(_WALL + sheet, "wall.toml")
    pat = unroll_surfaces(build_surfaces(d))
    apart = unroll_surfaces(build_surfaces(parse_design_text(_WALL.replace("rulings = 6", 'rulings = 6\npanels = "per-surface"')
                                                             + sheet, "wall.toml")))
    assert [p.label for p in apart.panels] == ["lower", "upper"] and [t[2] for t in apart.labels].count("E1") == 2
    (pn,) = pat.panels
    assert pn.label == "lower+upper" and pat.errors["max"] < 1e-12
    assert math.isclose(pn.area_flat, sum(p.area_flat for p in apart.panels), rel_tol=1e-12)
    foot = next(e for e in pn.loops[0] if e.name == "lower:a")
    _rectangle_checks(pn, foot.length_flat, 120.0)
    (j,) = pn.info["joints"]
    assert j["kind"] == "mark" and j["tangency_deg"] < 1e-6
    assert ("sheet" in pn.info) == bool(sheet)


def test_plated_composite_design_is_one_neutral_blank() -> None:
    """The two duct strips with a [sheet]: one blank of the neutral strips (they share the neutral
    joint ruling), area = the per-strip neutral panels' sum to 1e-12, one sheet entry with both
    strips' edges and bend lines numbered on."""
    from pathlib import Path

    from ght_cad.app.design import build_surface, parse_design_text, unroll_surface

    text = (Path(__file__).resolve().parents[1] / "examples" / "design_duct_two_strips.toml").read_text()
    text += "\n[sheet]\nthickness = 0.01\nk_factor = 0.4\n"
    (pn,) = unroll_surface(build_surface(parse_design_text(text, "p.toml"))).panels
    apart = unroll_surface(build_surface(parse_design_text(text.replace("[unroll]\n", '[unroll]\npanels = "per-surface"\n'), "p.toml")))
    assert len(apart.panels) == 2
    assert math.isclose(pn.area_flat, sum(p.area_flat for p in apart.panels), rel_tol=1e-12)
    sh = pn.info["sheet"]
    assert sh["thickness"] == 0.01 and len(sh["edges"]) == 8
    lines = [r["line"] for r in sh["forming"] if r["line"]]
    assert lines == list(range(1, len(lines) + 1)) and len(lines) == sum(len(p.info["sheet"]["forming"]) for p in apart.panels)
