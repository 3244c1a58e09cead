"""Bad property values inside FreeCAD (headless), as a user types them into the property editor.

Every case: set the value, recompute; the feature must be in error (``Invalid``) with a status
message naming the property and what is allowed, never silently build a shape from a replaced
value. Then the good value is restored and the feature recomputes to the very same geometry.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_audit``
"""

from __future__ import annotations

import math
import os
import tempfile
import unittest

import FreeCAD as App
import Part

from freecad.ght_workbench import composite_curve, developable, ght_curve, joined_developable, optimization

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_audit_")
PTS = [(0, 0, 0), (10, 20, 0), (30, 20, 5), (40, 0, 0)]


def _bad(obj) -> bool:
    return "Invalid" in obj.State or "Error" in obj.State


class BadValueCase(unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("audit")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def assert_refused(self, obj, prop, value, *words, measure=lambda s: (s.Length, s.Area)):
        """Setting ``prop`` to ``value`` puts ``obj`` in error with a message holding ``words``;
        restoring the old value recomputes the same geometry."""
        good = getattr(obj, prop)
        before = measure(obj.Shape) if hasattr(obj, "Shape") else None
        setattr(obj, prop, value)
        self.doc.recompute()
        self.assertTrue(_bad(obj), f"{obj.Label}.{prop} = {value!r} was accepted (state {obj.State})")
        msg = obj.getStatusString()
        for w in words:
            self.assertIn(w, msg, f"{obj.Label}.{prop} = {value!r}: message {msg!r} lacks {w!r}")
        setattr(obj, prop, good)
        self.doc.recompute()
        self.assertFalse(_bad(obj), obj.getStatusString())
        if before is not None:
            after = measure(obj.Shape)
            for a, b in zip(after, before):
                self.assertLessEqual(abs(a - b), 1e-12 * max(1.0, abs(b)))


class CurveBadValuesTest(BadValueCase):
    def test_tolerance_must_be_positive(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        for v in (-1.0, 0.0, float("nan"), float("inf")):
            with self.subTest(v):
                self.assert_refused(c, "Tolerance", v, "Tolerance", "> 0")

    def test_coincident_control_points(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        self.assert_refused(c, "ControlPoints", [App.Vector(1, 2, 3)] * 3, "ControlPoints", "coincide")

    def test_nan_shape_parameter_and_too_few_points(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        self.assert_refused(c, "Mu", float("nan"), "mu", "[-1, 1]")
        self.assert_refused(c, "ControlPoints", [App.Vector(0, 0, 0), App.Vector(1, 0, 0)], "at least 3")

    def test_source_vertex_out_of_range(self):
        poly = self.doc.addObject("Part::Feature", "Poly")
        poly.Shape = Part.makePolygon([App.Vector(*p) for p in PTS])
        c = ght_curve.make_ght_curve(source=[(poly, ["Vertex1", "Vertex2", "Vertex3", "Vertex4"])], doc=self.doc)
        self.assert_refused(c, "Source", [(poly, ["Vertex1", "Vertex2", "Vertex9"])], "Source", "Vertex9", "4 vertices")


class CompositeBadValuesTest(BadValueCase):
    def setUp(self):
        super().setUp()
        self.a = ght_curve.make_ght_curve([(0, 0, 0), (10, 15, 0), (25, 15, 0), (30, 0, 0)], doc=self.doc, name="SegA")
        self.b = ght_curve.make_ght_curve([(30, 0, 0), (35, -10, 0), (50, -10, 0), (60, 0, 0)], doc=self.doc, name="SegB")
        self.c = ght_curve.make_ght_curve([(60, 0, 0), (66, 6, 0), (70, 9, 4), (80, 10, 0)], doc=self.doc, name="SegC")
        self.cc = composite_curve.make_composite_curve([self.a, self.b, self.c], ["G1", "G2"], k=[1.0, 2.0], doc=self.doc)
        self.assertFalse(_bad(self.cc))

    def test_one_value_per_joint(self):
        self.assert_refused(self.cc, "Continuity", ["G1"], "Continuity", "1 value", "2 joints")
        self.assert_refused(self.cc, "Continuity", ["G1", "G2", "C1"], "Continuity", "3 values", "2 joints")
        self.assert_refused(self.cc, "K", [1.0], "K", "1 value", "2 joints")
        self.assert_refused(self.cc, "K", [1.0, 2.0, 3.0], "K", "3 values", "2 joints")
        self.assert_refused(self.cc, "K", [1.0, float("nan")], "k=nan")

    def test_empty_k_means_one_everywhere(self):
        self.cc.K = [1.0, 1.0]
        self.doc.recompute()
        ref = self.cc.Shape.Length
        self.cc.K = []
        self.doc.recompute()
        self.assertFalse(_bad(self.cc), self.cc.getStatusString())
        self.assertAlmostEqual(self.cc.Shape.Length, ref, delta=1e-12 * ref)

    def test_segment_must_be_a_ght_curve(self):
        box = self.doc.addObject("Part::Box", "Box")
        self.assert_refused(self.cc, "Segments", [self.a, box], "Segments", "Box", "GHT curve")

    def test_tolerance(self):
        self.assert_refused(self.cc, "Tolerance", -1e-6, "Tolerance", "> 0")


class SurfaceBadValuesTest(BadValueCase):
    def test_developable_tolerance(self):
        d = developable.make_developable(gamma=-1.0, doc=self.doc)
        for v in (-1.0, float("nan")):
            with self.subTest(v):
                self.assert_refused(d, "Tolerance", v, "Tolerance", ">= 0")
        d.Tolerance = 0.0  # 0 = automatic, documented
        self.doc.recompute()
        self.assertFalse(_bad(d))

    def test_joined_joint_tolerance(self):
        d = developable.make_developable(gamma=-1.0, doc=self.doc)
        j = joined_developable.make_joined_developable(d, "G2", doc=self.doc)
        self.assert_refused(j, "JointTolerance", -1.0, "JointTolerance", ">= 0")


class LinkedPlanesTest(BadValueCase):
    @staticmethod
    def _linked(self):
        from freecad.ght_workbench.tests.fc_features import plane_feature, quarter_cylinder_planes

        ps = quarter_cylinder_planes(self.doc)
        ea, eb = plane_feature(self.doc, (0, 0, 1), (0, 0, 0), "Ea"), plane_feature(self.doc, (0, 0, 1), (0, 0, 20), "Eb")
        self.doc.recompute()
        d = developable.make_developable([(p, "") for p in ps], [(ea, ""), (eb, "")], gamma=-1.0, weights=[1.0, math.sqrt(2), 1.0], doc=self.doc)
        self.assertFalse(_bad(d), d.getStatusString())
        return d, ps

    def test_reopen_identical_then_deleted_planes(self):
        d, ps = self._linked(self)
        area, name = d.Shape.Area, d.Name
        self.assertAlmostEqual(area, 100 * math.pi, delta=1e-6 * area)  # exact quarter cylinder r = 10, H = 20
        path = os.path.join(OUT, "audit_linked.FCStd")
        self.doc.saveAs(path)
        App.closeDocument(self.doc.Name)
        self.doc = App.openDocument(path)
        d = self.doc.getObject(name)
        for o in self.doc.Objects:
            o.touch()
        self.doc.recompute()
        self.assertFalse(_bad(d), d.getStatusString())
        self.assertLessEqual(abs(d.Shape.Area - area), 1e-12 * area)
        self.assertEqual(list(d.PlaneWeights), [1.0, math.sqrt(2), 1.0])
        # a deleted control plane: the link drops out, the feature says how many planes are left
        self.doc.removeObject("P1")
        self.doc.recompute()
        self.assertTrue(_bad(d))
        self.assertIn("PlaneWeights has 3 values for 2 planes", d.getStatusString())
        d.PlaneWeights = []
        self.doc.recompute()
        self.assertTrue(_bad(d))
        self.assertIn("at least 3", d.getStatusString())
        # every control plane deleted: no silent fall-back, the message names both inputs
        self.doc.removeObject("P0")
        self.doc.removeObject("P2")
        self.doc.recompute()
        self.assertTrue(_bad(d))
        self.assertIn("Planes", d.getStatusString())
        self.assertIn("PlaneCoordinates", d.getStatusString())
        self.assertLessEqual(abs(d.Shape.Area - area), 1e-12 * area)  # the old shape stays, marked Invalid


class PlaneWeightsTest(BadValueCase):
    def test_weights_named_and_not_silently_ignored(self):
        d, _ = LinkedPlanesTest._linked(self)
        self.assert_refused(d, "PlaneWeights", [1.0, float("nan"), 1.0], "PlaneWeights[1]=nan", "finite and non-zero")
        self.assert_refused(d, "PlaneWeights", [1.0, 0.0, 1.0], "PlaneWeights[1]=0", "finite and non-zero")
        # weights only scale linked planes: with plane coordinates they would be ignored, so refuse
        c = developable.make_developable(gamma=-1.0, doc=self.doc, name="Coords")
        self.assert_refused(c, "PlaneWeights", [1.0, 2.0, 1.0], "PlaneWeights", "linked Planes only")


class SpineBadValuesTest(BadValueCase):
    def test_curve_link_and_ruling_range(self):
        from freecad.ght_workbench import spine_developable

        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        s = spine_developable.make_spine_developable(c, doc=self.doc)
        self.assertFalse(_bad(s), s.getStatusString())
        box = self.doc.addObject("Part::Box", "Box")
        self.doc.recompute()
        self.assert_refused(s, "Curve", box, "Curve", "Box", "GHT curve")
        self.assert_refused(s, "V1", 2.0, "V0", "V1", "smaller")
        self.assert_refused(s, "Tolerance", -1.0, "Tolerance", ">= 0")


class CurvePlacementTest(BadValueCase):
    """A GHT curve moved with its Placement (Transform / placement dialog): what is built on it follows."""

    def test_spine_follows_a_moved_curve(self):
        from freecad.ght_workbench import spine_developable

        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        s = spine_developable.make_spine_developable(c, doc=self.doc)
        area, before = s.Shape.Area, s.Shape.copy()
        pl = App.Placement(App.Vector(5, -7, 100), App.Rotation(App.Vector(0, 0, 1), 30))
        c.Placement = pl
        self.doc.recompute()
        self.assertFalse(_bad(s), s.getStatusString())
        # a rigid motion; the B-spline face is refitted within its tolerance (1e-7 of the size)
        self.assertAlmostEqual(s.Shape.Area, area, delta=1e-6 * area)
        # the spine of the moved curve is the old spine moved the same way
        # (points of the new face lie on the moved old face within the two fits' tolerances)
        expected = before.transformGeometry(pl.toMatrix())
        face = s.Shape.Faces[0]
        u0, u1, v0, v1 = face.ParameterRange
        gaps = [expected.distToShape(Part.Vertex(face.valueAt(u0 + (u1 - u0) * i / 6, v0 + (v1 - v0) * j / 4)))[0]
                for i in range(7) for j in range(5)]
        self.assertLess(max(gaps), 1e-5)
        self.assertGreater(s.Shape.BoundBox.ZMin, 90.0)

    def test_composite_follows_a_moved_segment(self):
        a = ght_curve.make_ght_curve([(0, 0, 0), (10, 15, 0), (25, 15, 0), (30, 0, 0)], doc=self.doc, name="SegA")
        b = ght_curve.make_ght_curve([(30, 0, 0), (35, -10, 0), (50, -10, 0), (60, 0, 0)], doc=self.doc, name="SegB")
        cc = composite_curve.make_composite_curve([a, b], "G1", doc=self.doc)
        b.Placement = App.Placement(App.Vector(0, 0, 50), App.Rotation())
        self.doc.recompute()
        self.assertFalse(_bad(cc), cc.getStatusString())
        # b's far end is where the user moved it (a join moves only b's first control points)
        end = cc.Shape.OrderedVertexes[-1].Point
        self.assertLess(end.distanceToPoint(b.Shape.Vertexes[-1].Point), 1e-9)
        self.assertAlmostEqual(cc.Shape.BoundBox.ZMax, b.Shape.BoundBox.ZMax, delta=1e-6)
        self.assertEqual(list(cc.JointOrders)[0].split("/")[1], "G1")


class OptimizationBadValuesTest(BadValueCase):
    def test_optimizer_settings_named_by_property(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        o = optimization.make_optimization([c], doc=self.doc)
        self.assertFalse(_bad(o))
        self.assert_refused(o, "MaxIterations", -1, "MaxIterations", ">= 0")
        self.assert_refused(o, "PopulationSize", 2, "PopulationSize", ">= 4")
        self.assert_refused(o, "WeightEn", float("nan"), "En=nan")
        mu = (c.Mu, c.Nu, c.Gamma)
        o.MaxIterations = -1
        self.doc.recompute()
        with self.assertRaisesRegex(ValueError, "MaxIterations"):
            o.Proxy.run(o)
        self.assertEqual((c.Mu, c.Nu, c.Gamma), mu)


class ReopenInErrorTest(BadValueCase):
    def test_a_feature_in_error_survives_save_and_reopen(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        good, name = c.Shape.Length, c.Name
        c.Tolerance = -1.0
        self.doc.recompute()
        self.assertTrue(_bad(c))
        path = os.path.join(OUT, "audit_error.FCStd")
        self.doc.saveAs(path)
        App.closeDocument(self.doc.Name)
        self.doc = App.openDocument(path)
        c2 = self.doc.getObject(name)
        c2.touch()
        self.doc.recompute()
        self.assertTrue(_bad(c2))
        self.assertIn("Tolerance", c2.getStatusString())
        c2.Tolerance = 1e-6
        self.doc.recompute()
        self.assertFalse(_bad(c2))
        self.assertAlmostEqual(c2.Shape.Length, good, delta=1e-12 * good)


if __name__ == "__main__":
    unittest.main()
