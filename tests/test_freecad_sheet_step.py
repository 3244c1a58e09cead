"""The plate solids ght_cad writes to STEP are valid in FreeCAD with the closed-form volume (1e-6):
a quarter-cylinder plate and a quarter cone-frustum plate; the exact plate of a hull loft with fans
is valid, has six faces and its Flat pattern (thickness from the solid) is the core's neutral
pattern (1e-9) (fc_sheet_step)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_plates_from_ght_cad_are_valid_in_freecad(tmp_path) -> None:
    from ght_cad.cad.sheet_solid import plate_solid, write_plate_step
    from ght_cad.surfaces.ruled import CurvePairRuledSurface
    from ght_cad.sheetmetal.sheet import Sheet, ruling_normal
    from tests.test_sheet import cylinder, quarter

    r, h, T = 240.0, 100.0, 4.0
    write_plate_step(plate_solid(cylinder(r, h), Sheet(T, 0.42)), tmp_path / "cylinder_plate.step")
    r1, r2, H = 200.0, 400.0, 300.0
    cone = CurvePairRuledSurface(quarter(r1, 0.0), quarter(r2, H))
    n = ruling_normal(cone, np.array([0.5]), 0)[0][0]
    side = "normal" if n[:2] @ cone.evaluate(0.5, 0.5)[:2] > 0 else "reverse"
    write_plate_step(plate_solid(cone, Sheet(T, 0.42, side)), tmp_path / "cone_plate.step")
    ell = math.hypot(r2 - r1, H)
    from ght_cad.developables.loft import developable_loft
    from ght_cad.unrolling.unroll import unroll
    from tests.test_loft import CHINE, SHEER

    loft, K = developable_loft(CHINE, SHEER), 0.4
    write_plate_step(plate_solid(loft, Sheet(T, K)), tmp_path / "hull_plate.step")
    cases = [
        {"file": "cylinder_plate.step", "volume": 0.25 * math.pi * ((r + T) ** 2 - r**2) * h},
        {"file": "cone_plate.step", "volume": 0.5 * math.pi * ell * T * ((r1 + r2) / 2 + T * H / ell / 2)},
        {"file": "hull_plate.step", "volume": None, "T": T, "K": K, "flat_area": unroll(loft, sheet=Sheet(T, K)).area},
    ]
    (tmp_path / "plates.json").write_text(json.dumps(cases))
    run_fc_unittest("freecad.ght_workbench.tests.fc_sheet_step", tmp_path, 1, timeout=300)
