"""One blank per bent part (issue 23): ``ght_cad.unfold`` and ``ght-cad unroll part.step`` on sheet
solids built in build123d here (tests/sheet_parts.py), against the closed-form neutral blank
``Σ flats + Σ (R + K T) A``."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

pytest.importorskip("build123d")
import build123d as bd  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))
from sheet_parts import Profile, bracket, profile_solid, u_channel, z_profile  # noqa: E402

import ght_cad  # noqa: E402
from ght_cad.sheetmetal.blank import K_TABLES, BlankError, k_factor_table  # noqa: E402
from ght_cad.cad.occ import write_step  # noqa: E402
from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main  # noqa: E402

K = 0.42
HOLE = [(1, 30.0, 10.0)]  # a 10 mm hole in the U-channel's base


def _check_blank(res, prof: Profile, k: float, hole_area: float = 0.0) -> None:
    assert len(res.pattern.panels) == 1 and len(res.blanks) == 1
    panel = res.pattern.panels[0]
    want = prof.blank_area(k) - hole_area
    assert abs(panel.area_flat / want - 1) < 1e-6, (panel.area_flat, want)
    b = res.blanks[0]
    assert len(b.bends) == len(prof.bends)
    # every bend: two bend lines (tangent lines) at distance (R + K T) A, to 1e-9 relative
    by_radius = sorted(b.bends, key=lambda r: r["inside_radius"])
    for row, (a, r, _) in zip(by_radius, sorted(prof.bends, key=lambda x: x[1])):
        ba = (r + k * prof.thickness) * a
        assert abs(row["bend_lines_distance"] / ba - 1) < 1e-9, (row, ba)
        assert abs(row["bend_allowance"] / ba - 1) < 1e-9
        assert abs(row["angle_deg"] - math.degrees(a)) < 1e-9 and abs(row["inside_radius"] - r) < 1e-9
        bd_ = 2 * (r + prof.thickness) * math.tan(a / 2) - ba
        assert abs(row["bend_deduction"] - bd_) < 1e-9 * (r + prof.thickness)
    assert panel.bend_lines.shape == (2 * len(prof.bends), 2, 2)
    assert res.pattern.errors["max"] < 1e-9


def test_bracket_is_one_blank() -> None:
    """The issue's L-bracket: one panel of 3551.59 mm² (not one 40 x 50 flange)."""
    prof = bracket()
    res = ght_cad.unfold(profile_solid(prof), k_factor=K)
    _check_blank(res, prof, K)
    assert abs(res.pattern.area - 3551.59) < 0.005
    assert res.blanks[0].bends[0]["direction"] == "up"


def test_u_channel_two_radii_and_hole() -> None:
    prof = u_channel()
    res = ght_cad.unfold(profile_solid(prof, HOLE), k_factor=K)
    _check_blank(res, prof, K, math.pi * 25.0)
    assert len(res.pattern.panels[0].loops) == 2  # the outline and the hole


def test_z_profile_bends_up_and_down() -> None:
    prof = z_profile()
    res = ght_cad.unfold(profile_solid(prof), k_factor=K)
    _check_blank(res, prof, K)
    assert sorted(r["direction"] for r in res.blanks[0].bends) == ["down", "up"]


def test_base_face_and_k_table() -> None:
    """Another base face gives a congruent blank; a K table picks K by R/T per bend."""
    prof = u_channel()
    solid = profile_solid(prof)
    a = ght_cad.unfold(solid, k_factor=K)
    other = [n for n in a.blanks[0].faces if n != a.blanks[0].base_face][-1]
    b = ght_cad.unfold(solid, k_factor=K, base_face=other)
    assert b.blanks[0].base_face == other
    assert abs(b.pattern.area / a.pattern.area - 1) < 1e-12
    t = ght_cad.unfold(solid, k_factor_table="ansi")
    ks = sorted((r["inside_radius"], r["k_factor"]) for r in t.blanks[0].bends)
    assert ks == [(pytest.approx(3.0), 0.43), (pytest.approx(5.0), 0.43)]  # R/T = 1.5 and 2.5
    assert K_TABLES["ansi"](1.0, 2.0) == 0.38 and K_TABLES["ansi"](7.0, 2.0) == 0.50
    assert abs(K_TABLES["din"](2.0, 1.0) - (0.65 + 0.5 * math.log10(2.0)) / 2) < 1e-4
    want = sum(flat for flat in prof.flats) + sum((r + 0.43 * prof.thickness) * a for a, r, _ in prof.bends)
    assert abs(t.pattern.area / (want * prof.width) - 1) < 1e-9


def test_k_table_file(tmp_path: Path) -> None:
    f = tmp_path / "k.txt"
    f.write_text("# din\n0 0.8\n2.0, 1.0\n")
    tab = k_factor_table(f)
    assert tab(1.0, 1.0) == 0.4 and tab(3.0, 1.0) == 0.5
    f.write_text("0 0.3\n1 x\n")
    with pytest.raises(BlankError, match=r"k.txt:2"):
        k_factor_table(f)


def _run(argv, capsys):
    rc = main(argv + ["--json"])
    return rc, json.loads(capsys.readouterr().out)


def test_cli_default_two_parts_and_outputs(tmp_path: Path, capsys) -> None:
    """``ght-cad unroll two.step``: two blanks (bracket, Z), DXF with the bend lines, flat plate STEP."""
    step = tmp_path / "two.step"
    write_step([profile_solid(bracket()), profile_solid(z_profile()).translate((0, 0, 100))], step)
    dxf, plate = tmp_path / "two.dxf", tmp_path / "plate.step"
    rc, res = _run(["unroll", str(step), "--k-factor", str(K), "--dxf", str(dxf), "--plate-step", str(plate)], capsys)
    assert rc == EXIT_OK, res
    assert res["panels"] == 2 and len(res["blanks"]) == 2
    areas = sorted(b["area"] for b in res["blanks"])
    want = sorted([bracket().blank_area(K), z_profile().blank_area(K)])
    assert all(abs(a / w - 1) < 1e-6 for a, w in zip(areas, want))
    assert sorted(len(b["bends"]) for b in res["blanks"]) == [1, 2]
    import ezdxf

    doc = ezdxf.readfile(dxf)
    assert len([e for e in doc.modelspace() if e.dxf.layer == "BEND" and e.dxftype() == "LINE"]) == 6
    texts = sorted(e.dxf.text for e in doc.modelspace() if e.dxf.layer == "BEND" and e.dxftype() == "TEXT")
    assert len(texts) == 3 and all(" deg R" in t for t in texts), texts
    assert sum(" UP " in t for t in texts) == 2 and sum(" DOWN " in t for t in texts) == 1, texts
    # the flat plates: volume = area x T
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    from ght_cad.app.design.step_input import _read_step_in

    shape, _, _ = _read_step_in(plate, None)
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape, props)
    vol = bracket().blank_area(K) * 2.0 + z_profile().blank_area(K) * 1.5
    assert abs(props.Mass() / vol - 1) < 1e-6


def test_cli_default_without_k_factor(tmp_path: Path, capsys) -> None:
    step = tmp_path / "bracket.step"
    write_step(profile_solid(bracket()), step)
    rc, res = _run(["unroll", str(step)], capsys)
    assert rc == EXIT_OK and res["panels"] == 1
    assert abs(res["area"] / bracket().blank_area(0.5) - 1) < 1e-6
    rc, res = _run(["unroll", str(step), "--thickness", "3"], capsys)
    assert rc == EXIT_USAGE and "2 thick" in res["error"]


def test_block_and_sharp_bend_are_refused(tmp_path: Path, capsys) -> None:
    """A block and a bend of zero radius: exit 2 naming the solid/edge, no output written."""
    block = tmp_path / "block.step"
    write_step(bd.Box(40, 30, 20), block)
    out = tmp_path / "x.dxf"
    rc, res = _run(["unroll", str(block), "--dxf", str(out)], capsys)
    assert rc == EXIT_USAGE and "no sheet" in res["error"] and "block.step" in res["error"] and "20" in res["error"]
    assert not out.exists()
    cube = tmp_path / "cube.step"
    write_step(bd.Box(10, 10, 10), cube)
    rc, res = _run(["unroll", str(cube)], capsys)
    assert rc == EXIT_USAGE and "no sheet" in res["error"]
    pts = [(0, 0), (40, 0), (40, 25), (42, 25), (42, -2), (0, -2)]
    sharp = bd.Solid.extrude(bd.Face(bd.Wire.make_polygon([bd.Vector(x, y, 0) for x, y in pts])), bd.Vector(0, 0, 50))
    step = tmp_path / "sharp.step"
    write_step(sharp, step)
    rc, res = _run(["unroll", str(step), "--k-factor", "0.4", "--dxf", str(out)], capsys)
    assert rc == EXIT_USAGE and not out.exists()
    assert "sharp edge E" in res["error"] and "90 deg" in res["error"], res["error"]
    with pytest.raises(BlankError, match="sharp edge"):
        ght_cad.unfold(sharp)


def test_blank_options_need_a_sheet_solid(tmp_path: Path, capsys) -> None:
    step = tmp_path / "bracket.step"
    write_step(profile_solid(bracket()), step)
    rc, res = _run(["unroll", str(step), "--face", "1", "--base-face", "1"], capsys)
    assert rc == EXIT_USAGE and "--base-face" in res["error"]
    rc, res = _run(["unroll", str(step), "--base-face", "99"], capsys)
    assert rc == EXIT_USAGE and "F99" in res["error"]
    rc, res = _run(["unroll", str(step), "--face", "1"], capsys)  # a face selection: per-face unroll as before
    assert rc == EXIT_OK and res["panels"] == 1 and abs(res["area"] - 2000.0) < 1e-9


def test_tray_four_flanges_corner_reliefs() -> None:
    from sheet_parts import tray

    solid, area = tray()
    res = ght_cad.unfold(solid, k_factor=K)
    assert len(res.pattern.panels) == 1 and not res.blanks[0].cut_edges
    assert abs(res.pattern.area / area(K) - 1) < 1e-6
    ba = (3.0 + K * 2.0) * math.pi / 2
    rows = res.blanks[0].bends
    assert len(rows) == 4 and all(r["direction"] == "up" for r in rows)
    assert all(abs(r["bend_lines_distance"] / ba - 1) < 1e-9 for r in rows)


@pytest.mark.parametrize("sign", [-1, 1])
def test_freeform_bend_either_side(sign: int) -> None:
    """A spline bend (extrusion face and its exact offset): inside length + K T × turn angle."""
    from sheet_parts import freeform_bend

    from sheet_parts import bezier_length

    solid, area = freeform_bend(sign)
    res = ght_cad.unfold(solid, k_factor=K)
    assert len(res.pattern.panels) == 1
    assert abs(res.pattern.area / area(K) - 1) < 1e-9, (res.pattern.area, area(K))  # measured 2.2e-16 (the closed form with the Bézier length by quadrature)
    row = res.blanks[0].bends[0]
    assert abs(row["angle_deg"] - 90.0) < 1e-6 and row["kind"] not in ("cylinder", "cone")
    # the two tangent lines lie (inside length of the spline + K T × turn angle) apart: 1e-9 (measured 2e-16)
    inside = bezier_length([(30, 0), (40, 0), (50, 10), (50, 20)]) - (2.0 * math.pi / 2 if sign > 0 else 0.0)
    want = inside + K * 2.0 * math.pi / 2
    assert abs(row["bend_lines_distance"] / want - 1) < 1e-9, (row["bend_lines_distance"], want)
    assert res.pattern.panels[0].bend_lines.shape[0] > 2  # tangent lines + rulings


def test_centre_bend_lines_and_outside_base_face() -> None:
    """``bend_lines="centre"``: one line a bend, half way between the tangent lines; a base face on
    the outside skin unfolds the outside skin to the same neutral blank."""
    prof = u_channel()
    solid = profile_solid(prof)
    tan = ght_cad.unfold(solid, k_factor=K)
    cen = ght_cad.unfold(solid, k_factor=K, bend_lines="centre")
    assert cen.pattern.panels[0].bend_lines.shape == (2, 2, 2)
    assert abs(cen.pattern.area / tan.pattern.area - 1) < 1e-12
    skin_faces = tan.blanks[0].faces
    from ght_cad.cad.unfold_solid import sheet_skins

    skins, _ = sheet_skins(solid)
    partner = {f.number: f.partner for f in skins[0].faces}
    out_base = partner[tan.blanks[0].base_face]
    o = ght_cad.unfold(solid, k_factor=K, base_face=out_base)
    assert o.blanks[0].base_face == out_base and set(o.blanks[0].faces).isdisjoint(skin_faces)
    assert abs(o.pattern.area / (prof.blank_area(K)) - 1) < 1e-6
    for row in o.blanks[0].bends:
        a = math.radians(row["angle_deg"])
        assert abs(row["bend_lines_distance"] / ((row["inside_radius"] + K * 2.0) * a) - 1) < 1e-9


def test_cone_segment_bend() -> None:
    from sheet_parts import cone_bend

    solid, area = cone_bend()
    res = ght_cad.unfold(solid, k_factor=K)
    assert len(res.pattern.panels) == 1
    assert abs(res.pattern.area / area(K) - 1) < 1e-6, (res.pattern.area, area(K))
    row = res.blanks[0].bends[0]
    assert row["kind"] == "cone" and abs(row["angle_deg"] - 90.0) < 1e-9
    bl = res.pattern.panels[0].bend_lines
    assert bl.shape == (2, 2, 2)
    # the tangent lines are the cone's end rulings: each of slant length W / cos α, and in the flat
    # they meet at the developed sector angle (π/2) sin α (the cone turns π/2 about its axis,
    # α = atan((8 - 3)/40) its semi-angle): both to 1e-9 relative
    al = math.atan(5.0 / 40.0)
    d = bl[:, 1] - bl[:, 0]
    lengths = np.linalg.norm(d, axis=1)
    assert np.all(np.abs(lengths / (40.0 / math.cos(al)) - 1) < 1e-9), lengths
    cos = abs(float(d[0] @ d[1])) / (lengths[0] * lengths[1])
    sector = math.pi / 2 * math.sin(al)
    assert abs(math.acos(min(cos, 1.0)) / sector - 1) < 1e-9, (math.acos(min(cos, 1.0)), sector)


def test_overlap_refusal_and_split(monkeypatch) -> None:
    """The crossing detector finds a figure eight's crossing and none on a square; a blank whose
    pieces overlap is refused naming the faces and the area, or split into one panel per face with
    matching marks (the detector's verdict forced here: an extruded profile's strip cannot overlap)."""
    import ght_cad.sheetmetal.blank as blank

    eight = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], dtype=float)
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert len(blank._crossings(blank._segments([eight]), 1e-9)) == 1
    assert len(blank._crossings(blank._segments([square]), 1e-9)) == 0
    solid = profile_solid(bracket())
    monkeypatch.setattr(blank, "_overlaps", lambda *a: ("F1, F3", 12.5))
    with pytest.raises(BlankError, match=r"overlap .*F1, F3.*12\.5"):
        ght_cad.unfold(solid, k_factor=K)
    res = ght_cad.unfold(solid, k_factor=K, allow_split=True)
    assert len(res.pattern.panels) == 3
    assert abs(res.pattern.area / bracket().blank_area(K) - 1) < 1e-9
    assert sum(len(p.marks) for p in res.pattern.panels) > 0
