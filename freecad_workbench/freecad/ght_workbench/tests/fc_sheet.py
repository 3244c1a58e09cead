"""Sheet thickness on Flat pattern features inside FreeCAD (headless, spec 6.1).

* a Part::Cylinder quarter face with Thickness/KFactor/Side: flat area φ (r ± K T) h (1e-9);
* a plate made by FreeCAD (``makeThickness`` of a quarter cylinder, either face picked, Thickness
  0): thickness, inside face and side read from the solid, same pattern; written to STEP
  (``$GHT_FC_OUT/fc_plate.step``) for the pytest driver to unroll with the core;
* a developable feature of this workbench as Source: the core's neutral pattern;
* a bad K-factor refuses naming the value; the DXF carries layer FORMING; save/reopen keeps it.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_sheet``
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import unittest

import FreeCAD as App
import Part

from freecad.ght_workbench import export, flat_pattern
from freecad.ght_workbench.tests.fc_features import _recompute, _reopen
from freecad.ght_workbench.tests.refusal import RefusalAssertions
from ght_cad.sheetmetal.sheet import SheetError

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_")
R, H, T, K = 240.0, 100.0, 4.0, 0.42


def _cyl_face_name(obj) -> list[str]:
    return [f"Face{i + 1}" for i, f in enumerate(obj.Shape.Faces) if type(f.Surface).__name__ == "Cylinder"]


class SheetTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("sheet")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def _quarter_cylinder(self):
        c = self.doc.addObject("Part::Cylinder", "Cyl")
        c.Radius, c.Height, c.Angle = R, H, 90
        self.doc.recompute()
        return c

    def test_thickness_properties_on_a_cylinder_face(self):
        c = self._quarter_cylinder()
        (face,) = _cyl_face_name(c)
        for side, sign in (("normal", 1.0), ("reverse", -1.0)):
            fp = flat_pattern.make_flat_pattern(c, face, 4, doc=self.doc, name=f"FP_{side}", thickness=T, k_factor=K, side=side)
            self.assertEqual(_recompute(self.doc), [])
            self.assertAlmostEqual(fp.AreaFlat / (0.5 * math.pi * (R + sign * K * T) * H), 1.0, delta=1e-9)
            self.assertEqual(fp.ThicknessUsed, T)
            self.assertIn(f"{R + sign * K * T:.9g}", "\n".join(fp.FormingTable))
            self.assertLess(fp.MaxRelativeError, 1e-12)
        # T = 0: the face itself
        fp0 = flat_pattern.make_flat_pattern(c, face, 4, doc=self.doc, name="FP0")
        self.assertAlmostEqual(fp0.AreaFlat / (0.5 * math.pi * R * H), 1.0, delta=1e-12)
        self.assertEqual(fp0.ThicknessUsed, 0.0)
        self.assertEqual(list(fp0.FormingTable), [])
        # the DXF (R12 in FreeCAD's Python) has the forming labels on their own layer
        path = os.path.join(OUT, "fc_sheet.dxf")
        export.export_flat_pattern_dxf(self.doc.getObject("FP_normal"), path)
        text = open(path).read()
        self.assertIn("FORMING", text)
        self.assertIn(f"R{R + K * T:.4g} A90.00deg", text)

    def test_plate_solid_made_by_freecad(self):
        cyl = Part.makeCylinder(R + T, H, App.Vector(0, 0, 0), App.Vector(0, 0, 1), 90)
        rem = [f for f in cyl.Faces if type(f.Surface).__name__ != "Cylinder"]
        plate = cyl.makeThickness(rem, -T, 1e-7)
        self.assertTrue(plate.isValid())
        self.assertAlmostEqual(plate.Volume / (0.25 * math.pi * ((R + T) ** 2 - R**2) * H), 1.0, delta=1e-9)
        obj = self.doc.addObject("Part::Feature", "Plate")
        obj.Shape = plate
        self.doc.recompute()
        names = _cyl_face_name(obj)
        self.assertEqual(len(names), 2)
        areas = []
        for k, name in enumerate(names):  # inside or outside face picked: the same neutral pattern
            fp = flat_pattern.make_flat_pattern(obj, name, 4, doc=self.doc, name=f"FPplate{k}", k_factor=K)
            self.assertEqual(_recompute(self.doc), [])
            self.assertAlmostEqual(fp.ThicknessUsed, T, delta=1e-9 * T)
            areas.append(fp.AreaFlat)
        for a in areas:
            self.assertAlmostEqual(a / (0.5 * math.pi * (R + K * T) * H), 1.0, delta=1e-9)
        # ThicknessFromSolid off: the picked face itself
        fp.ThicknessFromSolid = False
        self.assertEqual(_recompute(self.doc), [])
        self.assertEqual(fp.ThicknessUsed, 0.0)
        plate.exportStep(os.path.join(OUT, "fc_plate.step"))
        with open(os.path.join(OUT, "fc_plate.json"), "w") as fh:
            json.dump({"R": R, "H": H, "T": T, "K": K, "area": areas[0]}, fh)

    def test_developable_feature_source(self):
        """A quarter cylinder r = 10, h = 20 from linked plane features: the feature's core surface
        with Thickness 1, KFactor 0.5 unrolls as the core does; width φ (10 ± 0.5) by the side."""
        from freecad.ght_workbench import developable
        from freecad.ght_workbench.tests.fc_features import quarter_cylinder_planes
        from ght_cad import unroll
        from ght_cad.sheetmetal.sheet import Sheet

        p0, p1, p2 = quarter_cylinder_planes(self.doc)
        box = self.doc.addObject("Part::Box", "Box")
        box.Length, box.Width, box.Height = 3, 3, 20
        self.doc.recompute()
        bottom, top = (f"Face{i + 1}" for z in (0.0, 20.0) for i, f in enumerate(box.Shape.Faces)
                       if abs(f.CenterOfMass.z - z) < 1e-9 and abs(abs(f.normalAt(0, 0).z) - 1) < 1e-12)
        dev = developable.make_developable([(p0, ""), (p1, ""), (p2, "")], [(box, [bottom]), (box, [top])], gamma=-1.0,
                                           weights=[1.0, math.sqrt(2), 1.0], doc=self.doc)
        areas = {}
        for side in ("normal", "reverse"):
            fp = flat_pattern.make_flat_pattern(dev, "", 4, doc=self.doc, name=f"FPdev_{side}", thickness=1.0, k_factor=0.5, side=side)
            self.assertEqual(_recompute(self.doc), [])
            core = unroll(dev.Proxy.surface(dev), sheet=Sheet(1.0, 0.5, side), rulings=4)
            self.assertAlmostEqual(fp.AreaFlat / core.area, 1.0, delta=1e-12)
            areas[side] = fp.AreaFlat
        exact = sorted(0.5 * math.pi * (10.0 + s * 0.5) * 20.0 for s in (-1.0, 1.0))
        got = sorted(areas.values())
        for g, e in zip(got, exact):
            self.assertAlmostEqual(g / e, 1.0, delta=1e-9)

    def test_bad_k_factor_names_the_value(self):
        c = self._quarter_cylinder()
        (face,) = _cyl_face_name(c)
        fp = flat_pattern.make_flat_pattern(c, face, 4, doc=self.doc, name="FPbad", thickness=T, k_factor=K)
        fp.KFactor = 1.5
        with self.assertRaisesRegex(SheetError, r"k_factor=1.5 is not allowed"):
            fp.Proxy.pattern(fp)
        # the feature is in error with the same message: one console line, no traceback
        self.assert_refused_as(self.doc, fp, lambda: fp.Proxy.pattern(fp), r"k_factor=1.5 is not allowed")
        fp.KFactor = K
        fp.Thickness = 250.0  # beyond the inside radius 240 on the reverse side
        fp.Side = "reverse"
        with self.assertRaisesRegex(SheetError, r"thickness=250.0 .*centre of curvature.*bending radius 240"):
            fp.Proxy.pattern(fp)
        self.assert_refused_as(self.doc, fp, lambda: fp.Proxy.pattern(fp), r"thickness=250.0 .*centre of curvature.*bending radius 240")
        fp.Thickness, fp.Side = T, "normal"
        self.assert_recompute_clean(self.doc, fp)

    def test_save_reopen_keeps_the_sheet(self):
        c = self._quarter_cylinder()
        (face,) = _cyl_face_name(c)
        fp = flat_pattern.make_flat_pattern(c, face, 4, doc=self.doc, name="FPkeep", thickness=T, k_factor=K, side="reverse")
        area, name = fp.AreaFlat, fp.Name
        doc2 = _reopen(self.doc)
        fp2 = doc2.getObject(name)
        self.assertEqual(fp2.Side, "reverse")
        self.assertAlmostEqual(fp2.KFactor, K, delta=0)
        self.assertAlmostEqual(fp2.AreaFlat, area, delta=1e-9 * area)
        self.assertEqual(fp2.getEditorMode("ThicknessUsed"), ["ReadOnly"])


if __name__ == "__main__":
    unittest.main()
