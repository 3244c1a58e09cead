"""The example scripts and design files run and their outputs are checked."""

from __future__ import annotations

import importlib.util
import json
import math
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from dxf_read import entity_area, outline_bulges

pytestmark = pytest.mark.slow  # every example script in a subprocess

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def load(name: str):
    spec = importlib.util.spec_from_file_location(f"example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def step_ok(path: str | Path) -> None:
    from ght_cad.cad.occ import is_valid, read_step

    assert Path(path).read_text(errors="replace").startswith("ISO-10303-21")
    assert is_valid(read_step(path))


def test_build123d_builder(tmp_path: Path) -> None:
    res = load("build123d_builder").main(tmp_path)
    step_ok(res["step"])
    assert res["valid"]
    # certified B-spline edges (1e-7 of the size) of exact GHT quarter circles
    assert res["volume_rel_error"] < 1e-7
    assert res["corner_length_rel_error"] < 1e-6


def test_build123d_algebra(tmp_path: Path) -> None:
    import ezdxf

    res = load("build123d_algebra").main(tmp_path)
    step_ok(res["step"])
    assert res["valid"] and res["solids"] == 4
    # the face's boundary curves are certified to 1e-7 x size (B-spline fit tolerance); a boundary
    # moved by at most d changes the area by at most about d * perimeter, i.e. <= ~2e-7 relative
    # here (the value itself, ~8e-9, depends on where the fit puts its knots)
    assert res["face_area_rel_error"] < 2e-7
    assert res["pattern_area_rel_error"] < 1e-12 and res["pattern_errors"]["max"] < 1e-12
    assert res["theta_max_deg"] < 1e-9
    # offset volume of a sheet: T*A (1 + O(T * curvature)); here T * max curvature < 0.01
    assert res["sheet_volume_rel_error"] < 0.01
    zmin, zmax = res["duct_bbox_z"]  # the frustum spans z = 0..400; the sheet adds at most T = 2
    assert -2.0 - 1e-6 <= zmin <= 1e-6 and 400 - 1e-6 <= zmax <= 402 + 1e-6
    ezdxf.readfile(res["dxf"])
    assert ET.parse(res["svg"]).getroot().tag.endswith("svg")


def test_cadquery_script(tmp_path: Path) -> None:
    pytest.importorskip("cadquery")  # the [cadquery] world (OCP 7.9)
    res = load("cadquery_script").main(tmp_path)
    step_ok(res["step"])
    assert res["valid"] and res["volume_rel_error"] < 1e-7


@pytest.mark.parametrize("name", ["build123d_builder", "cadquery_script"])
def test_scripts_run_as_programs(name: str, tmp_path: Path) -> None:
    pytest.importorskip(name.split("_")[0])
    proc = subprocess.run([sys.executable, str(EXAMPLES / f"{name}.py"), str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "valid: True" in proc.stdout
    assert len(list(tmp_path.glob("*.step"))) == 1


def test_design_duct_closed_form(tmp_path: Path) -> None:
    """The duct design is an exact quarter cone frustum: its pattern is an annular sector."""
    import ezdxf

    from ght_cad.app.cli import main

    out = tmp_path / "duct"
    assert main(["run", str(EXAMPLES / "design_duct.toml"), "--out", str(out), "--no-progress"]) == 0
    r = json.loads((out / "report.json").read_text())
    assert {p.name for p in out.iterdir()} == {"model.step", "flat_pattern.dxf", "flat_pattern.svg", "report.json",
                                               "report.md", "basis.png", "surface.png", "flat_pattern.png"}
    step_ok(out / "model.step")
    rho2 = math.hypot(400.0, 800.0)
    rho1 = rho2 / 2
    angle = (math.pi / 2) * 400.0 / rho2
    area = 0.5 * angle * (rho2**2 - rho1**2)
    assert r["flat_pattern"]["area"] == pytest.approx(area, rel=1e-12)
    assert r["surface"]["area_3d"] == pytest.approx(area, rel=1e-12)
    # the DXF outline: its area and its diameter are the annular sector's
    doc = ezdxf.readfile(out / "flat_pattern.dxf")
    (poly,) = [e for e in doc.modelspace().query("LWPOLYLINE") if e.dxf.layer == "OUTLINE"]
    pts = np.array([p[:2] for p in poly.get_points()])
    # two exact arcs and two lines (the 4 corners): the area measured on ezdxf's path is exact
    assert len(pts) == 4 and np.count_nonzero(outline_bulges(poly)) == 2
    assert entity_area(poly) == pytest.approx(area, rel=1e-12)
    diam = max(float(np.max(np.linalg.norm(pts - p, axis=1))) for p in pts)
    # farthest pair: outer corner to outer corner, or inner corner to the opposite outer corner
    expected = max(2 * rho2 * math.sin(angle / 2), math.sqrt(rho1**2 + rho2**2 - 2 * rho1 * rho2 * math.cos(angle)))
    assert diam == pytest.approx(expected, rel=1e-9)


def test_design_hull_plate_optimizes_developability(tmp_path: Path) -> None:
    from ght_cad.app.cli import main

    out = tmp_path / "hull"
    assert main(["run", str(EXAMPLES / "design_hull_plate_quasi.toml"), "--out", str(out), "--no-progress"]) == 0
    r = json.loads((out / "report.json").read_text())
    step_ok(out / "model.step")
    o = r["optimization"]
    assert o["objective"] == "R" and o["best_value"] < o["initial_value"]
    assert r["developability"]["R"] == pytest.approx(o["best_value"], rel=1e-9)
    assert r["developability"]["dd"] > r["developability_initial"]["dd"]
    assert r["joins"][0]["satisfied"] and r["joins"][0]["achieved_G"] >= 1
    # best-effort pattern of a quasi-developable strip: distortion small but measured, not zero
    assert 0 < r["flat_pattern"]["errors"]["max"] < 1e-3
