"""The workbench's Joined developable feature tested inside Debian's FreeCAD (separate process).

``freecadcmd -t freecad.ght_workbench.tests.fc_joined``: G1/G2/G3 joins of a quarter cylinder and
of a cone; the measured ``JointOrder`` equals the requested order, the Part face normals of both
strips agree along the shared (single) edge of the sewn shell within 1e-6 deg, changing the
previous strip's μ recomputes the joined strip with the order kept, save/reopen, STEP round trip
and the flat pattern of the joined strip.
"""

from __future__ import annotations

import json
import os
import re
import shutil
from pathlib import Path

import pytest

from conftest import freecadcmd_or_skip
from freecad_launch import freecad_env, run_fc_unittest, run_process, summary, xvfb_run

REPO = Path(__file__).resolve().parents[1]
WB = REPO / "freecad_workbench"

pytestmark = pytest.mark.freecad


def test_joined_developable_inside_freecadcmd(tmp_path: Path) -> None:
    out = run_fc_unittest("freecad.ght_workbench.tests.fc_joined", tmp_path, min_tests=9)
    # every requested order was measured, on both geometries
    for cont, r in (("G1", 1), ("G2", 2), ("G3", 3)):
        assert re.search(rf"^.*\b{cont}: JointOrder={r} ", out, re.M), out[-3000:]
        assert f"cone {cont}: JointOrder={r} " in out, out[-3000:]
    angles = [float(a) for a in re.findall(r"normal angle=([\deE.+-]+) deg", out)]
    assert len(angles) == 6 and max(angles) < 1e-6, angles
    assert (tmp_path / "joined.step").stat().st_size > 0
    # the STEP file FreeCAD wrote is a valid two-face shell for OCP 7.9 too
    from ght_cad.cad.occ import is_valid, read_step
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from ght_cad.cad._ocp import TopTools_IndexedMapOfShape
    from OCP.TopExp import TopExp

    shape = read_step(tmp_path / "joined.step")
    assert is_valid(shape)
    counts = []
    for kind in (TopAbs_FACE, TopAbs_EDGE):
        m = TopTools_IndexedMapOfShape()
        TopExp.MapShapes_s(shape, kind, m)
        counts.append(m.Extent())
    assert counts == [2, 7], counts  # the joint ruling is one shared edge


def test_joined_command_in_gui_under_xvfb(tmp_path: Path) -> None:
    freecadcmd_or_skip()
    exe = shutil.which("freecad") or shutil.which("FreeCAD")
    if exe is None or shutil.which("xvfb-run") is None:
        if os.environ.get("CI") == "true":
            pytest.fail("the FreeCAD GUI (freecad-python3) or xvfb-run (xvfb, xauth) is missing but CI=true")
        pytest.skip("FreeCAD GUI or xvfb-run not installed")
    env = freecad_env(tmp_path)
    env.pop("PYTHONPATH", None)  # installed as a user would: the addon linked into the user's Mod folder
    mod = Path(env["HOME"]) / ".local" / "share" / "FreeCAD" / "Mod"
    mod.mkdir(parents=True)
    (mod / "ght_workbench").symlink_to(WB, target_is_directory=True)
    env["QTWEBENGINE_DISABLE_SANDBOX"] = "1"
    env["QT_QPA_PLATFORM"] = "xcb"
    env["GHT_JOINED_GUI"] = "1"
    script = WB / "freecad" / "ght_workbench" / "tests" / "fc_joined.py"
    proc = run_process(xvfb_run(exe, str(script)), env, tmp_path, 180)
    result = tmp_path / "joined_gui.json"
    assert result.exists(), f"GUI check wrote no result (rc={proc.returncode}):\n{summary(proc)}"
    res = json.loads(result.read_text())
    assert "error" not in res, res["error"]
    assert res["registered"] and res["pixmap"], res
    assert res["toolbar"] == ["GHT surfaces"], res
    assert res["created"] == ["GHT::JoinedDevelopable"], res
    assert res["joint_order"] == 2 and res["faces"] == 2 and res["valid"], res
    assert res["panel_open"] and res["icon"], res
