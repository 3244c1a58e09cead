"""One blank of a whole sheet solid in FreeCAD's Flat pattern feature (issue 23, headless).

* an L-bracket made with Part (inside radius 3, T 2, flat flanges 40 and 25, width 50; a profile
  extruded): the Flat pattern of the whole solid (no face selected) is ONE planar face whose area
  is the closed-form neutral blank ``W (L1 + L2 + (R + K T) π/2)`` = 3551.5929... for K = 0.42
  to 1e-6 relative; its bend table (one 90° bend, inside radius 3, K 0.42, allowance
  ``(R + K T) π/2``) is in the feature's ``BendTable``; the console shows no traceback;
* the same with a base face selected (the vertical flange's inside face), in a PartDesign Body
  (its BaseFeature) and from a STEP file FreeCAD wrote and read back;
* a block (no sheet) and a bracket with a sharp (zero-radius) bend are refused with one line
  naming the solid / edge; save and reopen keeps the pattern.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_blank``
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import unittest

import FreeCAD as App
import Part

from freecad.ght_workbench import flat_pattern
from freecad.ght_workbench.tests.fc_features import _recompute, _reopen
from freecad.ght_workbench.tests.refusal import RefusalAssertions, console_output

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_")
R, T, L1, L2, W, K = 3.0, 2.0, 40.0, 25.0, 50.0, 0.42
#: the closed-form neutral blank: flat flanges plus the neutral arc (R + K T) π/2, times the width
BLANK = W * (L1 + L2 + (R + K * T) * math.pi / 2)
V = App.Vector


def bracket_shape(radius: float = R) -> "Part.Shape":
    """The L-bracket as a solid: the profile in the XZ plane extruded along +y by W. Horizontal
    flange z in [0, T], x in [-L1, 0]; the bend about the axis x = 0, z = R + T; vertical flange x
    in [R, R + T], z in [R + T, R + T + L2]. ``radius = 0``: a sharp corner (no bend face)."""
    c = radius + T
    ro, ri = radius + T, radius
    s = math.sqrt(0.5)
    if radius > 0:
        e = [Part.LineSegment(V(-L1, 0, 0), V(0, 0, 0)), Part.Arc(V(0, 0, 0), V(ro * s, 0, c - ro * s), V(ro, 0, c)),
             Part.LineSegment(V(ro, 0, c), V(ro, 0, c + L2)), Part.LineSegment(V(ro, 0, c + L2), V(ri, 0, c + L2)),
             Part.LineSegment(V(ri, 0, c + L2), V(ri, 0, c)), Part.Arc(V(ri, 0, c), V(ri * s, 0, c - ri * s), V(0, 0, c - ri))]
    else:  # sharp corners inside and outside
        e = [Part.LineSegment(V(-L1, 0, 0), V(T, 0, 0)), Part.LineSegment(V(T, 0, 0), V(T, 0, T + L2)),
             Part.LineSegment(V(T, 0, T + L2), V(0, 0, T + L2)), Part.LineSegment(V(0, 0, T + L2), V(0, 0, T))]
    e += [Part.LineSegment(V(0, 0, T), V(-L1, 0, T)), Part.LineSegment(V(-L1, 0, T), V(-L1, 0, 0))]
    return Part.Face(Part.Wire([x.toShape() for x in e])).extrude(V(0, W, 0))


class BlankTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("blank")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def _bracket(self, name: str = "Bracket", radius: float = R):
        obj = self.doc.addObject("Part::Feature", name)
        obj.Shape = bracket_shape(radius)
        self.doc.recompute()
        return obj

    def _check_blank(self, flat, base: int | None = None) -> dict:
        self.assertTrue(flat.WholeSolid)
        faces = [f for f in flat.Shape.Faces]
        self.assertEqual(len(faces), 1)  # one blank, one face
        self.assertTrue(faces[0].isValid())
        self.assertAlmostEqual(faces[0].Area / BLANK, 1.0, delta=1e-6)
        self.assertAlmostEqual(flat.AreaFlat / BLANK, 1.0, delta=1e-9)
        self.assertLess(flat.MaxRelativeError, 1e-9)
        self.assertAlmostEqual(flat.ThicknessUsed, T, delta=1e-9 * T)
        self.assertEqual(len(flat.BendTable), 2)  # header + one bend
        row = flat.BendTable[1].split()
        self.assertAlmostEqual(float(row[3]), 90.0, delta=1e-6)  # angle
        self.assertAlmostEqual(float(row[4]), R, delta=1e-9)  # inside radius
        self.assertAlmostEqual(float(row[5]), K, delta=1e-12)
        self.assertAlmostEqual(float(row[6]), (R + K * T) * math.pi / 2, delta=1e-8)  # bend allowance (9 digits)
        if base is not None:
            self.assertEqual(flat.BaseFaceUsed, base)
        # the bend lines: both tangent lines of the bend, (R + K T) π/2 apart
        lines = [e for e in flat.Shape.Edges if e not in faces[0].Edges and not any(e.isSame(x) for x in faces[0].Edges)]
        self.assertEqual(len(lines), 2)
        d = lines[0].distToShape(lines[1])[0]
        self.assertAlmostEqual(d, (R + K * T) * math.pi / 2, delta=1e-9)
        return {"area": faces[0].Area, "area_flat": flat.AreaFlat, "bend_table": list(flat.BendTable)}

    def test_part_bracket_whole_solid_one_face(self):
        src = self._bracket()
        flat, text = console_output(lambda: flat_pattern.make_flat_pattern(src, k_factor=K, doc=self.doc))
        self.assertEqual(_recompute(self.doc), [])
        self.assert_no_traceback(text)
        out = self._check_blank(flat)
        out["closed_form"] = BLANK
        with open(os.path.join(OUT, "fc_blank.json"), "w") as fh:
            json.dump(out, fh)
        name = flat.Name
        self.doc = _reopen(self.doc)
        self._check_blank(self.doc.getObject(name))

    def test_base_face_body_and_step(self):
        src = self._bracket()
        # the vertical flange's inside face (x = R) as base face
        k = next(i + 1 for i, f in enumerate(src.Shape.Faces)
                 if type(f.Surface).__name__ == "Plane" and abs(f.CenterOfMass.x - R) < 1e-9 and f.Area > 1000)
        flat = flat_pattern.make_flat_pattern(src, f"Face{k}", k_factor=K, doc=self.doc, whole_solid=True)
        self.assertEqual(_recompute(self.doc), [])
        self._check_blank(flat, base=k)
        body = self.doc.addObject("PartDesign::Body", "Body")
        body.BaseFeature = self._bracket("Base")
        self.doc.recompute()
        self._check_blank(flat_pattern.make_flat_pattern(body, k_factor=K, doc=self.doc))
        path = os.path.join(OUT, "fc_bracket.step")
        Part.export([src], path)
        imported = self.doc.addObject("Part::Feature", "Imported")
        imported.Shape = Part.read(path)
        self.doc.recompute()
        self._check_blank(flat_pattern.make_flat_pattern(imported, k_factor=K, doc=self.doc))
        self.assertEqual(_recompute(self.doc), [])

    def test_block_and_sharp_bend_refused(self):
        box = self.doc.addObject("Part::Box", "Box")
        self.doc.recompute()
        flat = flat_pattern.make_flat_pattern(box, k_factor=K, doc=self.doc)
        self.assertTrue(flat.WholeSolid)
        msg = flat.getStatusString()
        self.assertIn("Box:S1: no sheet", msg)
        flat.touch()
        self.assert_recompute_refused(self.doc, flat, msg)
        self.doc.removeObject(flat.Name)
        self.doc.removeObject(box.Name)
        sharp = self._bracket("Sharp", radius=0.0)
        flat = flat_pattern.make_flat_pattern(sharp, k_factor=K, doc=self.doc)
        msg = flat.getStatusString()
        self.assertRegex(msg, r"Sharp:S1: sharp edge E\d+ between skin faces F\d+ and F\d+: they meet at 90 deg")
        flat.touch()
        self.assert_recompute_refused(self.doc, flat, msg)


if __name__ == "__main__":
    unittest.main()
