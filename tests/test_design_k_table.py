"""``[sheet] k_factor_table`` in design files (issue 23): K read from a table by the design
surface's R/T (ansi | din | a file | inline rows, the semantics of ``--k-factor-table`` and
:func:`ght_cad.blank.k_factor_table`), giving exactly the neutral-surface figures of the explicit
``k_factor`` the table holds at that R/T; bad values exit 2 naming the file and the key.

The surface is examples/design_duct.toml's exact quarter cone (radius 400 -> 200 over 400, apex
height 800, semi-angle atan(1/2)): its smallest bending radius across the rulings is at the top
circle, ``ρ = r / cos α = 200 sqrt(5) / 2 = 223.607``; with T = 10 the inside radius is ρ with the
material on the convex side (side = "normal") and ρ - T on the concave side ("reverse"), so
R/T = 22.36 or 21.36 and a table stepping at R/T = 22 gives different K on the two sides."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from ght_cad.sheetmetal.blank import K_TABLES
from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main

DUCT = (Path(__file__).parent.parent / "examples" / "design_duct.toml").read_text().split("[outputs]")[0]
RHO = 200.0 * math.sqrt(5.0) / 2.0  # smallest bending radius of the cone
T = 10.0


def _design(tmp_path: Path, name: str, sheet: str) -> Path:
    p = tmp_path / f"{name}.toml"
    p.write_text(DUCT + "[sheet]\nthickness = 10\n" + sheet + "\n")
    return p


def _unroll(path: Path, capsys) -> tuple[int, dict]:
    rc = main(["unroll", str(path), "--json"])
    return rc, json.loads(capsys.readouterr().out)


def _figures(res: dict) -> str:
    """The neutral-surface figures: errors, per-panel sheet (edges inside/neutral/outside, forming rows)."""
    return json.dumps({"errors": res["errors"], "sheet": res["sheet"]}, sort_keys=True)


@pytest.mark.parametrize("side, ratio, k", [("normal", RHO / T, 0.45), ("reverse", (RHO - T) / T, 0.30)])
def test_inline_table_equals_explicit_k(tmp_path: Path, capsys, side: str, ratio: float, k: float) -> None:
    table = _design(tmp_path, "table", f'side = "{side}"\nk_factor_table = [[0, 0.30], [22, 0.45]]')
    rc, a = _unroll(table, capsys)
    assert rc == EXIT_OK, a
    explicit = _design(tmp_path, "explicit", f'side = "{side}"\nk_factor = {k}')
    rc, b = _unroll(explicit, capsys)
    assert rc == EXIT_OK, b
    assert a["sheet"][0]["k_factor"] == k
    assert abs(a["sheet"][0]["min_bending_radius"] / RHO - 1) < 1e-6  # the R the table was read at
    assert _figures(a) == _figures(b)
    # and the figures do depend on K (a table read at the wrong R/T would show)
    other = _design(tmp_path, "other", f'side = "{side}"\nk_factor = {0.75 - k}')
    rc, c = _unroll(other, capsys)
    assert _figures(c) != _figures(a)
    from ght_cad.app.design import build_surface, load_design

    built = build_surface(load_design(table))
    assert abs(built.design.sheet.k_factor_ratio / ratio - 1) < 1e-6


def test_named_and_file_tables(tmp_path: Path, capsys) -> None:
    """'ansi' and 'din' (R/T = 22.4 >= 3 and >= 5: K = 0.5 both) and a file of DIN rows relative to
    the design file (k = 0.9 from R/T = 20: K = 0.45)."""
    for name in ("ansi", "din"):
        rc, a = _unroll(_design(tmp_path, name, f'k_factor_table = "{name.upper()}"'), capsys)
        assert rc == EXIT_OK and a["sheet"][0]["k_factor"] == K_TABLES[name](RHO, T) == 0.5
    (tmp_path / "tables").mkdir()
    (tmp_path / "tables" / "k.txt").write_text("din\n0 0.6\n20, 0.9\n")
    rc, a = _unroll(_design(tmp_path, "file", 'k_factor_table = "tables/k.txt"'), capsys)
    assert rc == EXIT_OK, a
    rc, b = _unroll(_design(tmp_path, "explicit", "k_factor = 0.45"), capsys)
    assert a["sheet"][0]["k_factor"] == 0.45 and _figures(a) == _figures(b)


@pytest.mark.parametrize("value, says", [
    ('"nosuch"', "neither a built-in table nor a file"),
    ("[[0, 1.5]]", "outside [0, 1]"),
    ("[[1, 0.4]]", "must start at 0"),
    ("[[0, 0.4], [2]]", "row 2"),
    ("3", "expected a string or an array"),
])
def test_bad_tables_exit_2_naming_file_and_key(tmp_path: Path, capsys, value: str, says: str) -> None:
    p = _design(tmp_path, "bad", f"k_factor_table = {value}")
    rc = main(["unroll", str(p), "--json"])
    err = json.loads(capsys.readouterr().out)["error"]
    assert rc == EXIT_USAGE and "\n" not in err
    assert str(p) in err and "key 'sheet.k_factor_table'" in err and says in err, err
    assert "allowed: 'ansi', 'din', a file" in err


def test_table_and_k_factor_together_refused(tmp_path: Path, capsys) -> None:
    p = _design(tmp_path, "both", 'k_factor = 0.4\nk_factor_table = "ansi"')
    rc = main(["unroll", str(p), "--json"])
    err = json.loads(capsys.readouterr().out)["error"]
    assert rc == EXIT_USAGE and "sheet.k_factor_table" in err and "one of k_factor" in err, err


@pytest.mark.slow
def test_run_plate_and_pattern_use_the_table(tmp_path: Path) -> None:
    """``ght-cad run``: the plate report carries the K read (0.45 at R/T = 22.36) and the table; the
    flat pattern equals the explicit K's."""
    from ght_cad.app.design import load_design, run_design

    reports = []
    for name, sheet in (("table", "k_factor_table = [[0, 0.30], [22, 0.45]]"), ("explicit", "k_factor = 0.45")):
        p = _design(tmp_path, name, sheet)
        p.write_text(p.read_text() + '\n[outputs]\nfiles = ["json"]\nfigures = []\n')
        reports.append(run_design(load_design(p), tmp_path / f"out_{name}", progress=False))
    a, b = (json.loads(json.dumps(r, default=str)) for r in reports)
    assert a["plate"]["k_factor"] == 0.45 and abs(a["plate"]["k_factor_ratio"] - RHO / T) < 1e-6
    assert a["plate"]["k_factor_table"]["k_factors"] == [0.30, 0.45]
    assert a["flat_pattern"]["errors"] == b["flat_pattern"]["errors"]
    assert a["flat_pattern"]["sheet"] == b["flat_pattern"]["sheet"]
    assert a["design"]["sheet"]["k_factor_table"] == [[0.0, 0.30], [22.0, 0.45]]


@pytest.mark.slow  # three two-surface sheet unrolls (~30 s on a loaded machine)
def test_surfaces_read_the_table_at_their_own_thickness() -> None:
    """``[[surfaces]]`` (tests/test_join_panels.py's wall: two lofts, smallest bending radius
    148.77 on both): the table is read per surface at its own R/T, so with T = 2 (R/T = 74.1 or
    74.4 by side) K = 0.4 and with a ``[surfaces.sheet] thickness = 1`` override (R/T = 147.8 or
    148.8) K = 0.5; the patterns equal those of the explicit per-surface K."""
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from test_join_panels import _WALL

    from ght_cad.app.design import build_surfaces, parse_design_text, unroll_surfaces

    def pattern(upper: str, sheet: str):
        txt = _WALL.replace('curve_b = "top"\n', 'curve_b = "top"\n\n[surfaces.sheet]\n' + upper + "\n")
        txt = txt.replace("rulings = 6", 'rulings = 6\npanels = "per-surface"') + "\n[sheet]\nthickness = 2.0\n" + sheet + "\n"
        return unroll_surfaces(build_surfaces(parse_design_text(txt, "wall.toml")))

    a = pattern("thickness = 1.0", "k_factor_table = [[0, 0.4], [100, 0.5]]")
    b = pattern("thickness = 1.0\nk_factor = 0.5", "k_factor = 0.4")
    sheets = [p.info["sheet"] for p in a.panels]
    assert [(s["thickness"], s["k_factor"]) for s in sheets] == [(2.0, 0.4), (1.0, 0.5)]
    assert all(abs(s["min_bending_radius"] - 148.77) < 0.01 for s in sheets)
    assert json.dumps([p.info["sheet"] for p in a.panels], sort_keys=True, default=str) == \
        json.dumps([p.info["sheet"] for p in b.panels], sort_keys=True, default=str)
    assert [p.area_flat for p in a.panels] == [p.area_flat for p in b.panels]
    # a per-surface k_factor wins over the table
    c = pattern("thickness = 1.0\nk_factor = 0.33", "k_factor_table = [[0, 0.4], [100, 0.5]]")
    assert [p.info["sheet"]["k_factor"] for p in c.panels] == [0.4, 0.33]


@pytest.mark.slow
def test_optimize_checks_with_the_largest_k_and_the_result_with_its_own(tmp_path: Path) -> None:
    """With ``[optimize]`` the candidates are checked with the table's largest K (|K T| = 0.45 x 10)
    and the result's plate carries the K of its own R/T."""
    from ght_cad.app.design import load_design, run_design

    p = _design(tmp_path, "opt", "k_factor_table = [[0, 0.30], [22, 0.45]]")
    p.write_text(p.read_text() + '\n[optimize]\nmethod = "pso"\npopulation = 4\niterations = 2\n\n'
                 '[outputs]\nfiles = ["json"]\nfigures = []\n')
    r = run_design(load_design(p), tmp_path / "out", progress=False)
    assert r["optimization"]["sheet"]["k_t"] == pytest.approx(4.5, rel=1e-12)
    ratio = r["plate"]["k_factor_ratio"]
    assert r["plate"]["k_factor"] == (0.45 if ratio >= 22 else 0.30)
