"""One blank of a whole sheet solid in FreeCAD's Flat pattern feature (issue 23).

``freecadcmd -t freecad.ght_workbench.tests.fc_blank`` (see that module): a Part L-bracket
(R 3, T 2, flanges 40/25, width 50) unfolded whole into one face with the closed-form neutral
area for K = 0.42, the bend table in the feature's properties, also with a base face, in a
PartDesign Body and from STEP; a block and a sharp bend refused in one line; no traceback.
"""

from __future__ import annotations

import json
import math

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_whole_solid_flat_pattern_inside_freecad(tmp_path) -> None:
    run_fc_unittest("freecad.ght_workbench.tests.fc_blank", tmp_path, 3, timeout=300)
    d = json.loads((tmp_path / "fc_blank.json").read_text())
    closed = 50.0 * (40.0 + 25.0 + (3.0 + 0.42 * 2.0) * math.pi / 2)
    assert abs(closed - 3551.59) < 0.005  # the figure
    assert d["area"] == pytest.approx(closed, rel=1e-6) and d["area_flat"] == pytest.approx(closed, rel=1e-9)
    assert len(d["bend_table"]) == 2 and " 90 " in d["bend_table"][1]
