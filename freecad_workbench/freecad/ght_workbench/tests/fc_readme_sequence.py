"""The workbench README's scripting sequence, run as written (headless, no recompute of our own in
between): every ``make_*`` returns a feature that is up to date (not Touched), so the exports that
follow accept it. ``make_flat_pattern`` used to return its feature Touched (its Placement was set
after the recompute) and the DXF export refused it.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_readme_sequence``
"""

from __future__ import annotations

import os
import tempfile
import unittest

import FreeCAD as App

from freecad.ght_workbench import _base
from freecad.ght_workbench.tests.fc_loft import _sketch

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_readme_")


class ReadmeSequenceTest(unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("ReadmeSequence")   # the active document of the README's calls

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def assert_up_to_date(self, obj):
        self.assertFalse(_base.failed(obj), f"{obj.Name}: {obj.State}")
        self.assertNotIn("Touched", obj.State, f"{obj.Name} is returned Touched")

    def test_the_readme_scripting_sequence(self):
        from freecad.ght_workbench import developable, developable_loft, export, flat_pattern, ght_curve
        from freecad.ght_workbench import joined_developable, optimization, plate

        points = [(0, 0, 0), (10, 20, 0), (30, 20, 5), (40, 0, 0)]
        planes = [(-10, 1, 0, 0), (-10, 1, 1, 0), (-10, 0, 1, 0)]
        boundary_planes = [(0, 0, 0, 1), (-20, 0, 0, 1)]
        made = []

        def check(obj):  # right after each call: a later make_* recomputes the document
            self.assert_up_to_date(obj)
            made.append(obj)
            return obj

        curve = check(ght_curve.make_ght_curve(points, 0.3, -0.2, 0.1))
        feature = check(developable.make_developable(planes, boundary_planes, 0.0, 0.0, -1.0))
        flat = check(flat_pattern.make_flat_pattern(feature))
        joined = check(joined_developable.make_joined_developable(feature, "G2", None, fuse=True))
        sketch_a, sketch_b = _sketch(self.doc, "SketchA", 5.0, 0.0), _sketch(self.doc, "SketchB", 2.0, 6.0)
        loft = check(developable_loft.make_developable_loft((sketch_a, "Edge1"), (sketch_b, "Edge1")))
        plate_obj = check(plate.make_plate(feature, 1.0, 0.5, "normal"))
        plate_flat = check(flat_pattern.make_flat_pattern(plate_obj))
        opt = check(optimization.make_optimization([curve], "Fairness", PopulationSize=8, MaxIterations=5))
        for obj in made:
            self.assert_up_to_date(obj)
        optimization.run_optimization(opt)
        step = export.export_step([curve, feature, joined, loft, plate_obj, flat], os.path.join(OUT, "readme.step"))
        dxf = export.export_flat_pattern_dxf(flat, os.path.join(OUT, "readme.dxf"))
        dxf2 = export.export_flat_pattern_dxf(plate_flat, os.path.join(OUT, "readme_plate.dxf"))
        for path in (step, dxf, dxf2):
            self.assertGreater(os.path.getsize(path), 1000, path)
