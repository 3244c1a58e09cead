"""Plate solids written by ght_cad (``write_plate_step``) read in FreeCAD: valid, closed-form volume.

The pytest driver (tests/test_freecad_sheet_step.py) writes ``$GHT_FC_OUT/plates.json`` (file
name, closed-form volume) and the STEP files before launching FreeCAD.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_sheet_step``
"""

from __future__ import annotations

import json
import os
import unittest

import Part

OUT = os.environ.get("GHT_FC_OUT", "")


class PlateStepTest(unittest.TestCase):
    def test_plates_valid_with_closed_form_volume(self):
        cases = json.load(open(os.path.join(OUT, "plates.json")))
        self.assertGreaterEqual(len(cases), 2)
        for case in cases:
            shape = Part.read(os.path.join(OUT, case["file"]))
            self.assertTrue(shape.isValid(), case["file"])
            self.assertEqual(len(shape.Solids), 1, case["file"])
            self.assertAlmostEqual(shape.Volume / case["volume"], 1.0, delta=1e-6, msg=case["file"])
            self.assertEqual(len(shape.Faces), 6, case["file"])


if __name__ == "__main__":
    unittest.main()
