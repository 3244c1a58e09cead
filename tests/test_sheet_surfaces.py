"""[sheet] with [[surfaces]] (spec 6.1): the plated multichine dory runs, one valid named plate per
surface in model.step (volumes within 1e-6 of the closed form), neutral patterns exact and as for
one surface, the material on one side of the shell whatever the rails' order and direction,
per-surface overrides, refusals naming the surface (nothing written), T = 0 as without a sheet,
and ``ght-cad unroll model.step`` finding every plate's inside face."""

from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pytest

from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main

ROOT = Path(__file__).resolve().parents[1]
PLATED = ROOT / "examples" / "design_dory_multichine_plated.toml"
KEEL = [[0, 0, 150], [1700, 0, 0], [3400, 0, 20], [5000, 0, 350]]
CHINE = [[0, -650, 250], [1700, -800, 120], [3400, -700, 160], [5000, -60, 500]]
SHEER = [[0, -800, 800], [1700, -1000, 700], [3400, -900, 750], [5000, -80, 1100]]


def _dory(sheet: str = 'thickness = 6\nk_factor = 0.44\n', *, keel=KEEL, chine=CHINE, sheer=SHEER,
          side_rails=("chine", "sheer"), side_extra: str = "", bottom_extra: str = "", figures='["flat_pattern"]') -> str:
    text = f"""
name = "dory"
[[curves]]
name = "keel"
control_points = {keel}
[[curves]]
name = "chine"
control_points = {chine}
[[curves]]
name = "sheer"
control_points = {sheer}
[[surfaces]]
name = "bottom"
type = "rails"
curve_a = "keel"
curve_b = "chine"
{bottom_extra}
[[surfaces]]
name = "side"
type = "rails"
curve_a = "{side_rails[0]}"
curve_b = "{side_rails[1]}"
{side_extra}
[unroll]
rulings = 12
samples = 1025
[outputs]
figures = {figures}
"""
    return text + ("\n[sheet]\n" + sheet if sheet is not None else "")


@functools.lru_cache(maxsize=None)
def _sheets(text: str):
    """The design, built surfaces, surface sheets and rail joints of ``text``; built once per text
    in this module (the tests only read them)."""
    from ght_cad.app.design import build_curves, build_surfaces, parse_design_text
    from ght_cad.app.design.shell_sheet import surface_sheets

    d = parse_design_text(text, "dory.toml")
    curves, _ = build_curves(d)
    builts = build_surfaces(d, curves)
    sheets, rails = surface_sheets(d, builts)
    return d, builts, sheets, rails


@pytest.fixture(scope="module")
def plated_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("plated") / "out"
    rc = main(["run", str(PLATED), "--out", str(out)])
    assert rc == EXIT_OK
    return out, json.loads((out / "report.json").read_text())


@pytest.mark.slow
def test_plated_dory_runs_two_named_valid_solids(plated_run) -> None:
    from ght_cad.cad.occ import is_valid
    from ght_cad.cad.sheet_solid import read_step_face_names
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    out, rep = plated_run
    for f in ("model.step", "flat_pattern.dxf", "flat_pattern.svg", "forming.png", "report.md"):
        assert (out / f).is_file(), f
    shape, names = read_step_face_names(out / "model.step")
    solids = []
    exp = TopExp_Explorer(shape, TopAbs_SOLID)
    while exp.More():
        solids.append(exp.Current())
        exp.Next()
    assert len(solids) == 2 and all(is_valid(s) for s in solids)
    assert {"bottom.inside", "bottom.outside", "side.inside", "side.outside"} <= set(names.values())
    pl = rep["plate"]
    assert pl["solids"] == 2 and [s["surface"] for s in pl["surfaces"]] == ["bottom", "side"]
    for s in pl["surfaces"]:  # the exact plates' volumes against T A + σ (T²/2) ∫ 2H dA
        assert s["volume"] == pytest.approx(s["volume_closed_form"], rel=1e-6)
        assert s["side"] == "normal" and s["orientation"] == 1 and s["side_on_own_normal"] == "normal"
    # material outboard on both panels (-y: the starboard half hull; -z under the bottom)
    assert pl["surfaces"][0]["material_direction"][2] < -0.9 and pl["surfaces"][1]["material_direction"][1] < -0.9
    assert pl["volume"] == pytest.approx(pl["volume_closed_form"], rel=1e-6)
    assert [s["panel"] for s in rep["flat_pattern"]["sheet"]] == ["bottom", "side"]
    assert rep["flat_pattern"]["edge_marks"] == ["E1"]  # the chine, matched on the design edges
    (j,) = pl["joints"]
    assert j["surfaces"] == ["bottom", "side"] and j["kind"] == "gap" and j["shell_consistent"]
    # equal thicknesses: |T m_i - T m_j| = 2 T sin(fold / 2) at every rail point
    assert j["outside_edge_distance_max"] == pytest.approx(12 * np.sin(np.radians(j["fold_angle_deg_max"]) / 2), rel=1e-9)
    assert "## Plates" in (out / "report.md").read_text()
    dxf = (out / "flat_pattern.dxf").read_text()
    assert "FORMING" in dxf


@pytest.mark.slow
def test_step_unroll_finds_every_plate(plated_run, capsys) -> None:
    out, rep = plated_run
    rc = main(["unroll", str(out / "model.step"), "--k-factor", "0.44", "--json"])
    res = json.loads(capsys.readouterr().out)
    assert rc == EXIT_OK
    assert res["panels"] == 2 and [p["name"] for p in res["plates"]] == ["bottom", "side"]
    assert all(p["found_by"] == "names" and p["thickness"] == pytest.approx(6.0, rel=1e-6) for p in res["plates"])
    # the STEP faces are fits of the design surfaces (3e-7 T): the same neutral patterns to 1e-6
    assert res["area"] == pytest.approx(rep["flat_pattern"]["area"], rel=1e-6)
    # a --thickness other than the plates' own is refused, naming the plate
    rc = main(["unroll", str(out / "model.step"), "--thickness", "5", "--k-factor", "0.44"])
    err = capsys.readouterr().err
    assert rc == EXIT_USAGE and "--thickness=5.0 does not match the plate solid bottom in the file" in err, err


@pytest.mark.slow
def test_neutral_patterns_as_for_one_surface() -> None:
    """Each panel is its surface's neutral pattern exactly as a single [surface] unrolls it."""
    from ght_cad.app.design import unroll_surfaces
    from ght_cad.sheetmetal.sheet import OffsetRuledSurface
    from ght_cad.unrolling.unroll import ruled_area, unroll

    d, builts, sheets, rails = _sheets(_dory())
    pat = unroll_surfaces(builts)
    for b, s, pn in zip(builts, sheets, pat.panels):
        one = unroll(b.surface, rulings=12, samples=1025, label=b.design.name, sheet=s.sheet.to_sheet()).panels[0]
        assert pn.area_flat == one.area_flat
        assert np.array_equal(pn.report.boundary_length, one.report.boundary_length)
        neutral = ruled_area(OffsetRuledSurface(b.surface, s.sheet.to_sheet().neutral_offset))
        # a loft with fans: the single-surface neutral pattern's own error (6.4e-9 measured on the
        # bottom, at the fans' C0 joint rulings); exact to 1e-9 without fans (next test)
        assert pn.area_flat == pytest.approx(neutral, rel=1e-8)
    assert len(pat.panels) == 2


# rails that are translates of each other: cylinders, rulings end to end (no fans), so the neutral
# pattern is exact to round-off
C = [[0, 0, 150], [1700, 0, 0], [3400, 0, 20], [5000, 0, 350]]
CYL = f"""
name = "cylinders"
[[curves]]
name = "keel"
control_points = {C}
[[curves]]
name = "chine"
control_points = {[[x, y - 650, z + 100] for x, y, z in C]}
[[curves]]
name = "sheer"
control_points = {[[x, y - 800, z + 650] for x, y, z in C]}
[[surfaces]]
name = "bottom"
type = "rails"
curve_a = "keel"
curve_b = "chine"
[[surfaces]]
name = "side"
type = "rails"
curve_a = "sheer"
curve_b = "chine"
[sheet]
thickness = 5
k_factor = 0.4
"""


@pytest.mark.slow
def test_neutral_patterns_exact_without_fans() -> None:
    from ght_cad.app.design import unroll_surfaces
    from ght_cad.sheetmetal.sheet import OffsetRuledSurface
    from ght_cad.unrolling.unroll import ruled_area

    d, builts, sheets, rails = _sheets(CYL)
    assert [s.orientation for s in sheets] == [1.0, -1.0]  # side's rails given the other way round
    pat = unroll_surfaces(builts)
    assert pat.errors["boundary_length"] <= 1e-9 and pat.errors["ruling_length"] <= 1e-9
    for b, s, pn in zip(builts, sheets, pat.panels):
        neutral = ruled_area(OffsetRuledSurface(b.surface, s.sheet.to_sheet().neutral_offset))
        assert pn.area_flat == pytest.approx(neutral, rel=1e-9)
    assert any(t[2] == "E1" for t in pat.labels)


@pytest.mark.slow
@pytest.mark.parametrize("variant", ["side rails swapped", "keel reversed", "sheer reversed"])
def test_material_on_the_same_side_of_the_shell(variant) -> None:
    """Flipping a rail's direction or the rail order of one surface flips that surface's own
    normal; the shell orientation follows, so the material goes the same way (to 1e-9)."""
    _, _, ref, _ = _sheets(_dory())
    kw = {"side rails swapped": dict(side_rails=("sheer", "chine")), "keel reversed": dict(keel=KEEL[::-1]),
          "sheer reversed": dict(sheer=SHEER[::-1])}[variant]
    _, _, got, rails = _sheets(_dory(**kw))
    assert len(rails) == 1
    flipped = [g.orientation != r.orientation for g, r in zip(got, ref)]
    assert any(flipped) or variant == "sheer reversed"  # reversing rail b of a loft keeps its normal
    for g, r in zip(got, ref):
        np.testing.assert_allclose(g.material, r.material, atol=1e-9)
        own = np.dot(g.normal, r.normal)
        assert (own < 0) == (g.orientation != r.orientation)
    # side_reference = "surface": each surface's own normal, so a swapped rail order moves the material
    _, _, own, _ = _sheets(_dory('thickness = 6\nside_reference = "surface"\n', side_rails=("sheer", "chine")))
    assert np.dot(own[1].material, ref[1].material) < -0.999


def test_per_surface_overrides() -> None:
    from ght_cad.app.design.shell_sheet import rail_joints

    text = _dory('thickness = 6\nk_factor = 0.44\nside = "normal"\n',
                 side_extra='[surfaces.sheet]\nthickness = 4\nk_factor = 0.3\nside = "reverse"\n')
    d, builts, sheets, rails = _sheets(text)
    assert (sheets[0].sheet.thickness, sheets[0].sheet.k_factor, sheets[0].sheet.side) == (6.0, 0.44, "normal")
    assert (sheets[1].sheet.thickness, sheets[1].sheet.k_factor, sheets[1].sheet.side) == (4.0, 0.3, "reverse")
    assert np.dot(sheets[0].material, sheets[1].material) < 0  # on different sides of the shell now
    (j,) = rail_joints(builts, sheets, rails)
    assert j["fold_angle_deg_min"] > 90  # the material directions point to different sides
    # the inline form is the same table
    d2, _, sheets2, _ = _sheets(_dory(side_extra='sheet = { thickness = 4, k_factor = 0.3, side = "reverse" }'))
    assert sheets2[1].sheet.thickness == 4.0 and sheets2[1].requested.side == "reverse"


@pytest.mark.parametrize("text, key", [
    (_dory(side_extra="[surfaces.sheet]\nthick = 4\n"), "surfaces[1].sheet.thick"),
    (_dory(side_extra='[surfaces.sheet]\nside = "inboard"\n'), "surfaces[1].sheet.side"),
    (_dory(side_extra="[surfaces.sheet]\nthickness = -1\n"), "surfaces[1].sheet.thickness"),
    (_dory(None, side_extra="[surfaces.sheet]\nthickness = 4\n"), "surfaces[1].sheet"),
    (_dory('thickness = 6\nside_reference = "hull"\n'), "sheet.side_reference"),
])
def test_bad_overrides_refused(tmp_path, capsys, text, key) -> None:
    p = tmp_path / "bad.toml"
    p.write_text(text)
    rc = main(["run", str(p), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == EXIT_USAGE and f"key '{key}'" in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_refusal_names_the_surface(tmp_path, capsys) -> None:
    # the bottom bends down to a radius of 183 mm, the side to 3844 mm: |K T| = 220 only fails the bottom
    p = tmp_path / "thick.toml"
    p.write_text(_dory("thickness = 500\nk_factor = 0.44\n"))
    rc = main(["run", str(p), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == EXIT_USAGE, err
    assert "key 'surfaces[0]' (surface 'bottom')" in err and "reaches the bending radius" in err
    assert not (tmp_path / "out").exists()
    p.write_text(_dory("thickness = 6\n", side_extra="[surfaces.sheet]\nthickness = 4000\nk_factor = 1.0\n"))
    rc = main(["run", str(p), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == EXIT_USAGE and "key 'surfaces[1]' (surface 'side')" in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_thickness_zero_and_no_sheet_are_the_plain_run() -> None:
    """T = 0 on every surface: the patterns of the design without [sheet], bit for bit, and the
    design dict of a [[surfaces]] design without [sheet] has no new keys."""
    from ght_cad.app.design import parse_design_text, unroll_surfaces
    from ght_cad.app.design.build import build_curves, build_surfaces

    def pattern(text):
        d = parse_design_text(text, "d.toml")
        return d, unroll_surfaces(build_surfaces(d, build_curves(d)[0]))

    d0, plain = pattern(_dory(None))
    _, zero = pattern(_dory("thickness = 0\n"))
    assert "sheet" not in json.dumps(d0.to_dict()["surfaces"])
    for a, b in zip(plain.panels, zero.panels):
        assert a.area_flat == b.area_flat and np.array_equal(a.report.boundary_length, b.report.boundary_length)
        assert [np.array_equal(x, y) for x, y in zip(a.loop_polylines(), b.loop_polylines())] == [True]
    assert plain.labels == zero.labels
