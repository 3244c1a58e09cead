"""The developable examples run end to end and export valid, developable STEP geometry."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("OCP")

from ght_cad.cad.developable_faces import face_developability, joint_normal_deviation, shell_faces  # noqa: E402
from ght_cad.cad.occ import is_valid, read_step  # noqa: E402

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f"_example_{name}", EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_ship_hull_plate(tmp_path):
    report = _load("ship_hull_plate").main(tmp_path)
    assert report["valid"]
    assert report["theta_max_exact_deg"] <= 1e-9 and report["residual_exact"] <= 1e-10
    assert report["theta_max_face_deg"] <= 0.01
    assert report["flat_errors"]["max"] <= 1e-9
    step = Path(report["step"])
    assert step.parent == tmp_path and step.stat().st_size > 0
    shape = read_step(step)
    assert is_valid(shape) and len(shell_faces(shape)) == 1
    assert face_developability(shape).theta_max <= 0.01
    assert Path(report["dxf"]).stat().st_size > 0


def test_duct_transition(tmp_path):
    report = _load("duct_transition").main(tmp_path)
    assert report["valid"] and report["faces"] == 2
    assert report["joint_order"] == 2  # built with a G2 join of the dual curves
    assert max(report["theta_max_faces_deg"]) <= 0.01
    assert max(report["joint_normal_jump_deg"]) <= 1e-6
    shape = read_step(report["step"])
    assert is_valid(shape) and len(shell_faces(shape)) == 2
    assert max(joint_normal_deviation(shape)) <= 1e-6
    assert report["flat_errors"]["max"] <= 1e-9
    # one blank of both strips (issue 23): its area is the sum of the strips' 3-D areas
    assert report["flat_panels"] == 1 and len(report["strip_areas_3d"]) == 2
    assert abs(report["flat_area"] - sum(report["strip_areas_3d"])) <= 1e-12 * report["flat_area"]
    assert sorted(tmp_path.iterdir()) == sorted([Path(report["step"]), Path(report["dxf"])])  # only its own files
