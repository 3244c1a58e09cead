"""The DXF/SVG chord tolerance everywhere a design is run: the design file's ``[outputs] chord_tol``,
``--chord-tol`` on ``run``, ``export``, ``batch`` and ``demo`` (the option takes precedence over the
file), and their validation (exit 2, one line naming the file and key or the option).

The freeform pattern is the hopper transition (``examples/design_hopper_transition.toml``): an
exact developable loft whose rails develop to curves that are neither lines nor circles, so its
outline is arcs through points of the exact edges within the chord tolerance ``tol``
(:func:`ght_cad.outline_arcs.arc_chain`). Every point of such an outline lies within ``tol`` of the
exact flat edge, so the enclosed areas differ by at most ``tol x perimeter`` (the band of width
``tol`` around the boundary); the rulings and corners are exact.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from ght_cad.app.cli import main
from ght_cad.core.errors import GHTError

from dxf_read import dxf_outline_areas, outline_bulges, outline_entities, outline_vertices, svg_outline_areas

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
HOPPER = (EXAMPLES / "design_hopper_transition.toml").read_text()
#: the hopper with only the flat-pattern files (no STEP, no figures: fast, and no CAD kernel needed)
FILES_ONLY = '[outputs]\nfiles = ["dxf", "svg", "json"]\nfigures = []\n'


def hopper_design(path: Path, name: str = "hopper-transition", chord_tol: str | None = None) -> Path:
    """The hopper design at ``path`` with DXF/SVG/JSON outputs and ``[outputs] chord_tol`` if given."""
    text = HOPPER[:HOPPER.index("[outputs]")].replace('name = "hopper-transition"', f'name = "{name}"')
    text += FILES_ONLY + (f"chord_tol = {chord_tol}\n" if chord_tol is not None else "")
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def hopper():
    """The hopper's exact flat pattern (built from the design file, as ``run`` builds it)."""
    from ght_cad.app.design import build_surfaces, load_design, unroll_surfaces

    return unroll_surfaces(build_surfaces(load_design(EXAMPLES / "design_hopper_transition.toml")))


def dxf_vertex_count(path: Path) -> int:
    (ent,) = outline_entities(path)
    return len(outline_vertices(ent))


def assert_dxf_written_at(path: Path, hopper, tol: float) -> None:
    """The DXF outline is the pattern's outline at ``tol``: the same bulges (hence the same arcs and vertex count)."""
    (ent,) = outline_entities(path)
    ((_, bulges),) = hopper.outline_arcs(tol)
    np.testing.assert_allclose(outline_bulges(ent), bulges, rtol=1e-12, atol=1e-15)


@pytest.mark.slow
def test_design_file_chord_tol_sets_the_dxf_tolerance(hopper, tmp_path: Path, capsys) -> None:
    """``[outputs] chord_tol = 1e-2`` and ``= 1e-4`` in the design file (``ght-cad run``): each DXF's
    area measured on ezdxf's path is the exact flat area within ``chord_tol x perimeter`` (and its SVG
    the same), the outline is the pattern's outline at that tolerance, and the finer tolerance
    writes more vertices and a closer area. Measured (perimeter 4,510 mm, area 1.27e6 mm²): 1e-2 ->
    36 vertices, area 0.18 mm² off (bound 45 mm²); 1e-4 -> 168 vertices, 1.0e-3 mm² off (bound 0.45 mm²)."""
    exact = hopper.area
    perimeter = sum(e.length_flat for e in hopper.panels[0].loops[0])
    counts, errors = {}, {}
    for tol in (1e-2, 1e-4):
        design = hopper_design(tmp_path / f"h{tol:g}.toml", chord_tol=repr(tol))
        out = tmp_path / f"out{tol:g}"
        assert main(["run", str(design), "--out", str(out), "--no-progress"]) == 0, capsys.readouterr().err
        dxf = out / "flat_pattern.dxf"
        (area,) = dxf_outline_areas(dxf)
        (svg_area,) = svg_outline_areas(out / "flat_pattern.svg")
        assert abs(area - exact) <= tol * perimeter, (tol, area - exact)
        assert abs(svg_area - exact) <= tol * perimeter, (tol, svg_area - exact)
        assert_dxf_written_at(dxf, hopper, tol)
        report = json.loads((out / "report.json").read_text())
        assert report["design"]["outputs"]["chord_tol"] == tol
        counts[tol], errors[tol] = dxf_vertex_count(dxf), abs(area - exact)
    assert counts[1e-4] > counts[1e-2], counts
    assert errors[1e-4] < errors[1e-2], errors


@pytest.mark.slow
def test_option_takes_precedence_over_the_file(hopper, tmp_path: Path, capsys) -> None:
    """The file says 1e-2, ``--chord-tol 1e-4`` wins on ``run`` and ``export``; without the option
    ``export`` uses the file's value."""
    design = hopper_design(tmp_path / "h.toml", chord_tol="1e-2")
    assert main(["run", str(design), "--out", str(tmp_path / "o"), "--no-progress", "--chord-tol", "1e-4"]) == 0
    assert_dxf_written_at(tmp_path / "o" / "flat_pattern.dxf", hopper, 1e-4)
    assert main(["export", str(design), str(tmp_path / "e4.dxf"), "--chord-tol", "1e-4"]) == 0
    assert_dxf_written_at(tmp_path / "e4.dxf", hopper, 1e-4)
    assert main(["export", str(design), str(tmp_path / "e2.dxf")]) == 0
    assert_dxf_written_at(tmp_path / "e2.dxf", hopper, 1e-2)
    capsys.readouterr()


@pytest.mark.parametrize("value, says", [("0", "out of range"), ("-1e-3", "out of range"), ("nan", "not finite"),
                                         ("inf", "not finite"), ('"0.1"', "expected a number"),
                                         ("true", "expected a number")])
def test_bad_file_chord_tol_is_refused(value: str, says: str, tmp_path: Path, capsys) -> None:
    """A non-positive, NaN, infinite or non-number ``[outputs] chord_tol``: exit 2 before anything
    runs, one stderr line naming the file, the key and what is allowed; nothing written."""
    design = hopper_design(tmp_path / "bad.toml", chord_tol=value)
    out = tmp_path / "out"
    assert main(["run", str(design), "--out", str(out)]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "bad.toml" in line and "outputs.chord_tol" in line and says in line and "> 0" in line, line
    assert not out.exists()


@pytest.mark.parametrize("command", ["batch", "demo", "run", "export"])
@pytest.mark.parametrize("value", ["0", "-1", "nan", "inf"])
def test_bad_chord_tol_option_is_refused(command: str, value: str, tmp_path: Path, capsys) -> None:
    """``--chord-tol`` 0, negative, NaN or inf on every command that has it: exit 2, one line
    naming the option and what is allowed; no output folder or file appears."""
    design = str(hopper_design(tmp_path / "h.toml"))
    out = str(tmp_path / "out")
    argv = {"batch": ["batch", design, "--out", out], "demo": ["demo", "--quick", "--out", out],
            "run": ["run", design, "--out", out], "export": ["export", design, out + ".dxf"]}[command]
    assert main([*argv, f"--chord-tol={value}"]) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "--chord-tol" in line and "allowed: a positive length" in line, line
    assert sorted(p.name for p in tmp_path.iterdir()) == ["h.toml"]


def test_run_batch_refuses_a_bad_chord_tol(tmp_path: Path) -> None:
    """The API: ``run_batch(chord_tol=...)`` not > 0 or not finite raises GHTError naming it."""
    from ght_cad.app.batch import run_batch

    design = hopper_design(tmp_path / "h.toml")
    for bad in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(GHTError, match="chord_tol"):
            run_batch([design], tmp_path / "out", jobs=1, progress=False, chord_tol=bad)
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_batch_passes_the_option_to_every_design(hopper, tmp_path: Path, capsys) -> None:
    """``ght-cad batch a.toml b.toml --chord-tol 1e-4``: both designs' DXFs are written at 1e-4,
    also ``b`` whose file says 1e-2 (the option takes precedence); without the option each design
    keeps its own (a: the 1e-3 mm default, b: 1e-2)."""
    a = hopper_design(tmp_path / "a.toml", name="a")
    b = hopper_design(tmp_path / "b.toml", name="b", chord_tol="1e-2")
    assert main(["batch", str(a), str(b), "--out", str(tmp_path / "o"), "--jobs", "2", "--no-progress",
                 "--chord-tol", "1e-4"]) == 0, capsys.readouterr().err
    for name in ("a", "b"):
        assert_dxf_written_at(tmp_path / "o" / name / "flat_pattern.dxf", hopper, 1e-4)
    assert main(["batch", str(a), str(b), "--out", str(tmp_path / "d"), "--jobs", "2", "--no-progress"]) == 0
    assert_dxf_written_at(tmp_path / "d" / "a" / "flat_pattern.dxf", hopper, 1e-3)
    assert_dxf_written_at(tmp_path / "d" / "b" / "flat_pattern.dxf", hopper, 1e-2)
    capsys.readouterr()


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_demo_accepts_chord_tol(tmp_path: Path, capsys) -> None:
    """``ght-cad demo --quick --chord-tol 0.5``: the demo plate's curved edges are written within
    0.5 mm: the DXF area is the exact one of report.json within 0.5 mm x perimeter (the perimeter
    measured on ezdxf's flattening of the default run's outline, +1 %), with fewer outline vertices
    than at the default 1e-3 mm."""
    from ezdxf import path as ezpath

    counts, areas, exact = {}, {}, {}
    for tol, argv in ((1e-3, []), (0.5, ["--chord-tol", "0.5"])):
        out = tmp_path / f"demo{tol:g}"
        assert main(["demo", "--quick", "--no-progress", "--out", str(out), *argv]) == 0, capsys.readouterr().err
        exact[tol] = json.loads((out / "report.json").read_text())["flat_pattern"]["area"]
        (ent,) = outline_entities(out / "flat_pattern.dxf")
        counts[tol] = len(outline_vertices(ent))
        (areas[tol],) = dxf_outline_areas(out / "flat_pattern.dxf")
        if tol == 1e-3:
            poly = np.array([(v.x, v.y) for v in ezpath.make_path(ent).flattening(1e-3)])
            perimeter = 1.01 * float(np.sum(np.linalg.norm(np.diff(poly, axis=0), axis=1)))
    assert exact[0.5] == exact[1e-3]  # the same plate: only the outline's tolerance differs
    for tol in areas:
        assert abs(areas[tol] - exact[tol]) <= tol * perimeter, (tol, areas[tol] - exact[tol])
    assert counts[0.5] < counts[1e-3], counts
