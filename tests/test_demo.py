"""`ght-cad demo --out DIR`: every output exists and is checked against a recomputation.

The demo runs once (module-scoped fixture) as a subprocess, like a user would run it.
"""

from __future__ import annotations

import json
import struct
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from ght_cad.curves.plotting import SIZES

from dxf_read import dxf_outline_areas, svg_outline_areas

pytestmark = pytest.mark.slow  # the whole demo pipeline in a subprocess

EXPECTED_FILES = {
    "model.step",
    "flat_pattern.dxf",
    "flat_pattern.svg",
    "report.json",
    "report.md",
    "basis.png",
    "curve.png",
    "curvature.png",
    "surface.png",
    "flat_pattern.png",
    "convergence.png",
}


def png_size(path: Path) -> tuple[int, int]:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict, subprocess.CompletedProcess]:
    out = tmp_path_factory.mktemp("demo") / "demo-out"
    proc = subprocess.run(
        [sys.executable, "-m", "ght_cad.app.cli", "demo", "--out", str(out), "--json"],
        capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, proc.stderr
    report = json.loads((out / "report.json").read_text())
    return out, report, proc


def test_every_output_is_written(demo) -> None:
    out, report, proc = demo
    names = {p.name for p in out.iterdir()}
    assert names == EXPECTED_FILES  # nothing missing, no temporary leftovers
    assert set(report["files"]) == EXPECTED_FILES
    assert not list(out.parent.glob(".*ght-cad-tmp"))
    stdout = json.loads(proc.stdout)
    assert stdout["ok"] is True and stdout["name"] == report["name"] == "bilge-plate"


def test_pngs_have_their_fixed_size(demo) -> None:
    out, _, _ = demo
    for name in ("basis", "curve", "curvature", "surface", "flat_pattern", "convergence"):
        p = out / f"{name}.png"
        assert png_size(p) == SIZES[name], name
        assert p.stat().st_size > 10_000, name


def test_step_reimports_valid_and_matches_report(demo) -> None:
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer

    from ght_cad.cad.occ import is_valid, read_step

    out, report, _ = demo
    shape = read_step(out / "model.step")
    assert is_valid(shape)
    faces = []
    ex = TopExp_Explorer(shape, TopAbs_FACE)
    while ex.More():
        faces.append(ex.Current())
        ex.Next()
    assert len(faces) == 1
    g = GProp_GProps()
    BRepGProp.SurfaceProperties_s(faces[0], g)
    # the face is a certified B-spline fit (1e-7 of the size): areas agree far below 1e-6
    assert g.Mass() == pytest.approx(report["surface"]["area_3d"], rel=1e-6)
    assert g.Mass() == pytest.approx(report["brep"]["area"], rel=1e-9)
    n_edges = 0
    ex = TopExp_Explorer(shape, TopAbs_EDGE)
    while ex.More():
        n_edges += 1
        ex.Next()
    assert n_edges >= 4 + report["brep"]["curve_edges"]  # face boundary + the two sheer curves


def test_dxf_parses_and_its_area_matches_the_report(demo) -> None:
    import ezdxf

    out, report, _ = demo
    doc = ezdxf.readfile(out / "flat_pattern.dxf")
    assert doc.header["$INSUNITS"] == 4  # millimetres, as the design says
    outlines = [e for e in doc.modelspace().query("LWPOLYLINE") if e.dxf.layer == "OUTLINE"]
    assert len(outlines) == 1 and outlines[0].closed
    # lines and arcs of the exact outline (curved edges within the 1e-3 mm chord tolerance): the
    # area measured on ezdxf's path is the exact one
    assert dxf_outline_areas(out / "flat_pattern.dxf")[0] == pytest.approx(report["flat_pattern"]["area"], rel=1e-8)
    # the flat pattern of an exact developable has the area of the surface
    assert report["flat_pattern"]["area"] == pytest.approx(report["surface"]["area_3d"], rel=1e-9)
    assert len(doc.modelspace().query("LINE[layer=='BEND']")) == report["flat_pattern"]["bend_lines"] > 0


def test_svg_parses(demo) -> None:
    out, report, _ = demo
    root = ET.parse(out / "flat_pattern.svg").getroot()
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    paths = root.findall(".//{http://www.w3.org/2000/svg}g[@id='OUTLINE']/{http://www.w3.org/2000/svg}path")
    assert len(paths) == 1
    assert svg_outline_areas(out / "flat_pattern.svg")[0] == pytest.approx(report["flat_pattern"]["area"], rel=1e-8)


def test_report_developability_matches_recomputation(demo) -> None:
    from ght_cad import developable_from_planes

    _, report, _ = demo
    s = report["surface"]
    sh = s["shape_parameters"]
    # rebuild from the written planes (already normalized) and the optimized shape parameters
    surf = developable_from_planes(s["control_planes"], s["boundary_planes"], sh["mu"], sh["nu"], sh["gamma"])
    d = surf.developability()
    rep = report["developability"]
    assert d.dd == pytest.approx(rep["dd"], abs=1e-12)
    assert d.theta_max == pytest.approx(rep["theta_max"], abs=1e-9)
    assert rep["dd"] > 1 - 1e-12 and rep["theta_max"] < 1e-6  # an envelope of planes is developable
    u = np.linspace(0, 1, 257)
    assert float(surf.ruling_lengths(u).max()) == pytest.approx(s["ruling_length_max"], rel=1e-12)


def test_report_optimization_is_consistent(demo) -> None:
    from ght_cad import GHTCurve
    from ght_cad.app.design import dual_curve_objectives, parse_design_text
    from ght_cad.app.demo import default_design_text
    from ght_cad.surfaces.planes import normalize_planes

    _, report, _ = demo
    o = report["optimization"]
    design = parse_design_text(default_design_text())
    U = normalize_planes(np.asarray(design.surface.planes, float))
    best = o["best_parameters"]
    val = dual_curve_objectives(GHTCurve(U, best["mu"], best["nu"], best["gamma"]))["CVEn"]
    assert val == pytest.approx(o["best_value"], rel=1e-12)
    init = dual_curve_objectives(GHTCurve(U, design.surface.mu, design.surface.nu, design.surface.gamma))["CVEn"]
    assert init == pytest.approx(o["initial_value"], rel=1e-12)
    h = np.array(o["history"])
    assert np.all(np.diff(h) <= 0) and h[-1] == pytest.approx(o["best_value"], rel=1e-12)
    assert o["best_value"] < o["initial_value"]


def test_report_curves_and_joins_match_recomputation(demo) -> None:
    from ght_cad import GHTCurve
    from ght_cad.curves.continuity import measure_continuity

    _, report, _ = demo
    curves = {c["name"]: GHTCurve(c["control_points"], c["mu"], c["nu"], c["gamma"]) for c in report["curves"]}
    for c in report["curves"]:
        assert curves[c["name"]].arc_length() == pytest.approx(c["arc_length"], rel=1e-12)
    (j,) = report["joins"]
    rep = measure_continuity(curves[j["first"]], curves[j["second"]])
    assert rep.g_order >= 2 and j["achieved_G"] >= 2 and j["satisfied"]


def test_markdown_report_states_the_numbers(demo) -> None:
    out, report, _ = demo
    md = (out / "report.md").read_text()
    assert f"{report['developability']['dd']:.12f}" in md
    assert f"{report['flat_pattern']['report']['area']['max']:.3e}" in md
    for f in EXPECTED_FILES - {"report.md"}:
        assert f"]({f})" in md
