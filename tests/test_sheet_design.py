"""Design files with a [sheet] table (spec 6.1): unroll, run (plate solid in model.step, forming
chart, report), T = 0 bit for bit, bad values refused with exit 2 and nothing written."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main

R, H, T, K = 240.0, 100.0, 4.0, 0.42

BASE = f"""
name = "quarter-cylinder"
units = "mm"

[surface]
type = "planes"
planes = [[-{R}, 1, 0, 0], [-{R}, 1, 1, 0], [-{R}, 0, 1, 0]]
boundary_planes = [[0, 0, 0, 1], [-{H}, 0, 0, 1]]
gamma = -1.0
normalize = false
"""


def _design(tmp_path: Path, sheet: str, name: str = "d.toml") -> Path:
    p = tmp_path / name
    p.write_text(BASE + ("\n[sheet]\n" + sheet if sheet else ""))
    return p


def _unroll(path: Path, capsys, *extra: str) -> tuple[int, dict, str]:
    rc = main(["unroll", str(path), "--json", *extra])
    cap = capsys.readouterr()
    return rc, json.loads(cap.out), cap.err


def test_unroll_design_with_sheet(tmp_path, capsys) -> None:
    rc, res, err = _unroll(_design(tmp_path, f"thickness = {T}\nk_factor = {K}\n"), capsys)
    assert rc == EXIT_OK, err
    (sh,) = res["sheet"]
    a = next(e for e in sh["edges"] if e["edge"] == "a")
    assert a["flat"] == pytest.approx(0.5 * math.pi * (R + K * T), rel=1e-9)
    assert a["outside"] == pytest.approx(0.5 * math.pi * (R + T), rel=1e-9)
    rc, res, err = _unroll(_design(tmp_path, f"thickness = {T}\ndin_k_factor = {2 * K}\nside = \"reverse\"\n", "r.toml"), capsys)
    assert rc == EXIT_OK, err
    a = next(e for e in res["sheet"][0]["edges"] if e["edge"] == "a")
    assert a["flat"] == pytest.approx(0.5 * math.pi * (R - K * T), rel=1e-9)


def test_thickness_zero_is_the_plain_pattern(tmp_path) -> None:
    import numpy as np

    from ght_cad.app.design import build_surface, load_design, unroll_surface

    plain = unroll_surface(build_surface(load_design(_design(tmp_path, "", "p.toml"))))
    zero = unroll_surface(build_surface(load_design(_design(tmp_path, "thickness = 0.0\nk_factor = 0.3\n", "z.toml"))))
    assert zero.sheet is None
    for a, b in zip(plain.outlines, zero.outlines):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(plain.bend_lines, zero.bend_lines)
    assert plain.dxf_r12_text() == zero.dxf_r12_text()


@pytest.mark.slow
def test_run_writes_the_plate_solid_and_forming_chart(tmp_path, capsys) -> None:
    from ght_cad.cad.occ import is_valid, volume
    from ght_cad.cad.sheet_solid import read_step_face_names

    out = tmp_path / "out"
    rc = main(["run", str(_design(tmp_path, f"thickness = {T}\nk_factor = {K}\n")), "--out", str(out)])
    assert rc == EXIT_OK, capsys.readouterr().err
    shape, names = read_step_face_names(out / "model.step")
    assert is_valid(shape)
    assert sorted(names.values()) == ["edge1", "edge2", "edge3", "edge4", "inside", "outside"]
    assert volume(shape) == pytest.approx(0.25 * math.pi * ((R + T) ** 2 - R**2) * H, rel=1e-6)
    rep = json.loads((out / "report.json").read_text())
    assert rep["plate"]["solids"] == 1 and rep["plate"]["thickness"] == T
    assert rep["flat_pattern"]["sheet"][0]["forming"][0]["radius_a"] == pytest.approx(R + K * T, rel=1e-9)
    assert (out / "forming.png").read_bytes()[:4] == b"\x89PNG"
    md = (out / "report.md").read_text()
    assert "### Sheet" in md and "neutral (cut)" in md


@pytest.mark.parametrize(
    "sheet, word",
    [
        ("thickness = -1.0\n", "sheet.thickness"),
        ("thickness = nan\n", "sheet.thickness"),
        ("k_factor = 0.4\n", "sheet.thickness"),
        ("thickness = 1.0\nk_factor = 1.5\n", "sheet.k_factor"),
        ("thickness = 1.0\nk_factor = 0.4\ndin_k_factor = 0.8\n", "sheet.din_k_factor"),
        ("thickness = 1.0\nside = \"up\"\n", "sheet.side"),
        ("thickness = 1.0\ncolour = 1\n", "sheet.colour"),
        ("thickness = 300.0\nk_factor = 1.0\n", "bending radius 240"),
    ],
)
def test_bad_sheet_tables_exit_2_and_write_nothing(tmp_path, capsys, sheet: str, word: str) -> None:
    out = tmp_path / "out"
    rc = main(["run", str(_design(tmp_path, sheet)), "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == EXIT_USAGE and word in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_export_and_surface_step_are_the_plate(tmp_path, capsys) -> None:
    from ght_cad.cad.occ import is_valid, volume
    from ght_cad.cad.sheet_solid import read_step_face_names

    d = _design(tmp_path, f"thickness = {T}\nk_factor = {K}\n")
    exact = 0.25 * math.pi * ((R + T) ** 2 - R**2) * H
    for argv, path in ((["export", str(d), str(tmp_path / "e.step")], tmp_path / "e.step"),
                       (["surface", str(d), "--step", str(tmp_path / "s.step")], tmp_path / "s.step")):
        assert main(argv) == EXIT_OK, capsys.readouterr().err
        shape, names = read_step_face_names(path)
        assert is_valid(shape) and "inside" in names.values()
        assert volume(shape) == pytest.approx(exact, rel=1e-6)
    rc = main(["unroll", str(d), "--forming-png", str(tmp_path / "roll.png")])
    assert rc == EXIT_OK and (tmp_path / "roll.png").read_bytes()[:4] == b"\x89PNG"
