"""Bad property values inside FreeCAD (headless), as a user types them into the property editor.

Every case: set the value, recompute; the feature must be in FreeCAD's error state (``Invalid``)
with exactly the expected status message naming the property and what is allowed, never silently
build a shape from a replaced value; the console shows that message as one line and FreeCAD's
"Recompute failed!" line, no Python traceback (:mod:`.refusal`). Then the good value is restored
and the feature recomputes to the very same geometry, printing nothing.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_audit``
"""

from __future__ import annotations

import math
import os
import tempfile
import unittest

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, composite_curve, developable, ght_curve, joined_developable, optimization
from freecad.ght_workbench.tests.refusal import RefusalAssertions

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_audit_")
PTS = [(0, 0, 0), (10, 20, 0), (30, 20, 5), (40, 0, 0)]


_bad = _base.failed


class BadValueCase(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("audit")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def assert_refused(self, obj, prop, value, message, measure=lambda s: (s.Length, s.Area)):
        """Setting ``prop`` to ``value`` puts ``obj`` in error with exactly ``message`` (one console
        line, no traceback); restoring the old value recomputes the same geometry."""
        good = getattr(obj, prop)
        before = measure(obj.Shape) if hasattr(obj, "Shape") else None
        setattr(obj, prop, value)
        self.assert_recompute_refused(self.doc, obj, message)
        setattr(obj, prop, good)
        self.assert_recompute_clean(self.doc, obj)
        if before is not None:
            after = measure(obj.Shape)
            for a, b in zip(after, before):
                self.assertLessEqual(abs(a - b), 1e-12 * max(1.0, abs(b)))


class CurveBadValuesTest(BadValueCase):
    def test_tolerance_must_be_positive(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        for v in (-1.0, 0.0, float("nan"), float("inf")):
            with self.subTest(v):
                self.assert_refused(c, "Tolerance", v, f"GHTCurve.Tolerance={v!r} is not allowed; it must be a finite number > 0")

    def test_coincident_control_points(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        self.assert_refused(c, "ControlPoints", [App.Vector(1, 2, 3)] * 3, "GHTCurve.ControlPoints: all 3 points coincide at "
                            "(1.0, 2.0, 3.0); the curve would be a single point (at least two control points must differ)")

    def test_nan_shape_parameter_and_too_few_points(self):
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        self.assert_refused(c, "Mu", float("nan"), "mu=nan is not finite; allowed range is [-1, 1]")
        self.assert_refused(c, "ControlPoints", [App.Vector(0, 0, 0), App.Vector(1, 0, 0)], "control_points has 2 points; at least 3 are required")

    def test_source_vertex_out_of_range(self):
        poly = self.doc.addObject("Part::Feature", "Poly")
        poly.Shape = Part.makePolygon([App.Vector(*p) for p in PTS])
        c = ght_curve.make_ght_curve(source=[(poly, ["Vertex1", "Vertex2", "Vertex3", "Vertex4"])], doc=self.doc)
        self.assert_refused(c, "Source", [(poly, ["Vertex1", "Vertex2", "Vertex9"])],
                            "Source: Poly has no Vertex9 (it has 4 vertices); link existing vertices, a sketch or a shape")


class CompositeBadValuesTest(BadValueCase):
    def setUp(self):
        super().setUp()
        self.a = ght_curve.make_ght_curve([(0, 0, 0), (10, 15, 0), (25, 15, 0), (30, 0, 0)], doc=self.doc, name="SegA")
        self.b = ght_curve.make_ght_curve([(30, 0, 0), (35, -10, 0), (50, -10, 0), (60, 0, 0)], doc=self.doc, name="SegB")
        self.c = ght_curve.make_ght_curve([(60, 0, 0), (66, 6, 0), (70, 9, 4), (80, 10, 0)], doc=self.doc, name="SegC")
        self.cc = composite_curve.make_composite_curve([self.a, self.b, self.c], ["G1", "G2"], k=[1.0, 2.0], doc=self.doc)
        self.assertFalse(_bad(self.cc))

    def test_one_value_per_joint(self):
        per_joint = "give exactly one per joint (segments - 1)"
        self.assert_refused(self.cc, "Continuity", ["G1"], f"CompositeCurve.Continuity has 1 value for 2 joints; {per_joint}")
        self.assert_refused(self.cc, "Continuity", ["G1", "G2", "C1"], f"CompositeCurve.Continuity has 3 values for 2 joints; {per_joint}")
        self.assert_refused(self.cc, "K", [1.0], f"CompositeCurve.K has 1 value for 2 joints; {per_joint} or none for k = 1")
        self.assert_refused(self.cc, "K", [1.0, 2.0, 3.0], f"CompositeCurve.K has 3 values for 2 joints; {per_joint} or none for k = 1")
        self.assert_refused(self.cc, "K", [1.0, float("nan")], "k=nan is not finite; it must be a finite real number")

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
        self.assert_refused(self.cc, "Segments", [self.a, box], "CompositeCurve.Segments[1] = Box is not a GHT curve; link GHT curve features only")

    def test_tolerance(self):
        self.assert_refused(self.cc, "Tolerance", -1e-6, "CompositeCurve.Tolerance=-1e-06 is not allowed; it must be a finite number > 0")


class SurfaceBadValuesTest(BadValueCase):
    def test_developable_tolerance(self):
        d = developable.make_developable(gamma=-1.0, doc=self.doc)
        for v in (-1.0, float("nan")):
            with self.subTest(v):
                self.assert_refused(d, "Tolerance", v, f"Developable.Tolerance={v!r} is not allowed; it must be a finite number >= 0 "
                                    "(0: 1e-7 of the surface size)")
        d.Tolerance = 0.0  # 0 = automatic, documented
        self.doc.recompute()
        self.assertFalse(_bad(d))

    def test_joined_joint_tolerance(self):
        d = developable.make_developable(gamma=-1.0, doc=self.doc)
        j = joined_developable.make_joined_developable(d, "G2", doc=self.doc)
        self.assert_refused(j, "JointTolerance", -1.0, "JoinedDevelopable.JointTolerance=-1.0 is not allowed; it must be a finite number >= 0 (0: 1e-9)")


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
        self.assert_recompute_refused(self.doc, d, "PlaneWeights has 3 values for 2 planes")
        d.PlaneWeights = []
        self.assert_recompute_refused(self.doc, d, "planes has 2 planes; at least 3 are required")
        # every control plane deleted: no silent fall-back, the message names both inputs
        self.doc.removeObject("P0")
        self.doc.removeObject("P2")
        self.assert_recompute_refused(self.doc, d, "no planes: Planes links nothing (deleted?) and PlaneCoordinates is empty; link planes "
                                      "or give 4 numbers (u0, u1, u2, u3) per plane")
        self.assertLessEqual(abs(d.Shape.Area - area), 1e-12 * area)  # the old shape stays, marked Invalid


class PlaneWeightsTest(BadValueCase):
    def test_weights_named_and_not_silently_ignored(self):
        d, _ = LinkedPlanesTest._linked(self)
        self.assert_refused(d, "PlaneWeights", [1.0, float("nan"), 1.0], "Developable.PlaneWeights[1]=nan is not allowed; weights must be finite and non-zero")
        self.assert_refused(d, "PlaneWeights", [1.0, 0.0, 1.0], "Developable.PlaneWeights[1]=0.0 is not allowed; weights must be finite and non-zero")
        # weights only scale linked planes: with plane coordinates they would be ignored, so refuse
        c = developable.make_developable(gamma=-1.0, doc=self.doc, name="Coords")
        self.assert_refused(c, "PlaneWeights", [1.0, 2.0, 1.0], "Coords.PlaneWeights scales linked Planes only; with PlaneCoordinates scale the "
                            "4 numbers of a plane instead and clear PlaneWeights")


class SpineBadValuesTest(BadValueCase):
    def test_curve_link_and_ruling_range(self):
        from freecad.ght_workbench import spine_developable

        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        s = spine_developable.make_spine_developable(c, doc=self.doc)
        self.assertFalse(_bad(s), s.getStatusString())
        box = self.doc.addObject("Part::Box", "Box")
        self.doc.recompute()
        self.assert_refused(s, "Curve", box, "SpineDevelopable.Curve = Box is not a GHT curve; link a GHT curve feature")
        self.assert_refused(s, "V1", 2.0, "SpineDevelopable: V0=2 mm and V1=2 mm are not allowed; they must be finite with V0 smaller than V1")
        self.assert_refused(s, "Tolerance", -1.0, "SpineDevelopable.Tolerance=-1.0 is not allowed; it must be a finite number >= 0 (0: 1e-7 of the surface size)")


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
        self.assert_refused(o, "MaxIterations", -1, "Optimization.MaxIterations=-1 is not allowed; use an integer >= 0")
        self.assert_refused(o, "PopulationSize", 2, "Optimization.PopulationSize=2 is not allowed; use an integer >= 4")
        self.assert_refused(o, "WeightEn", float("nan"), "objective weight En=nan is not allowed; weights must be finite and >= 0")
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
        message = "GHTCurve.Tolerance=-1.0 is not allowed; it must be a finite number > 0"
        self.assert_recompute_refused(self.doc, c, message)
        path = os.path.join(OUT, "audit_error.FCStd")
        self.doc.saveAs(path)
        App.closeDocument(self.doc.Name)
        self.doc = App.openDocument(path)
        c2 = self.doc.getObject(name)
        c2.touch()
        self.assert_recompute_refused(self.doc, c2, message)
        c2.Tolerance = 1e-6
        self.assert_recompute_clean(self.doc, c2)
        self.assertAlmostEqual(c2.Shape.Length, good, delta=1e-12 * good)


class ErrorReportingTest(BadValueCase):
    """How a failed recompute is reported: refused input without traceback, bugs with one."""

    def test_dependants_never_build_on_a_failed_input(self):
        """FreeCAD skips the dependants of a failed feature in a document recompute; recomputing a
        dependant alone (``obj.recompute()``) is refused too, naming the failed input."""
        from freecad.ght_workbench import spine_developable

        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        s = spine_developable.make_spine_developable(c, doc=self.doc)
        area = s.Shape.Area
        c.Tolerance = -1.0
        message = "GHTCurve.Tolerance=-1.0 is not allowed; it must be a finite number > 0"
        self.assert_recompute_refused(self.doc, c, message)
        self.assertFalse(_bad(s))  # skipped by FreeCAD: not recomputed, its old shape kept
        self.assertIs(_base.failed_input(s), c)
        s.touch()
        self.assert_recompute_refused(self.doc, s, f"its input GHTCurve failed to recompute ({message}); fix that first", recompute=s.recompute)
        self.assertEqual(s.Shape.Area, area)
        c.Tolerance = 1e-6
        self.assert_recompute_clean(self.doc, c, s)
        self.assertIsNone(_base.failed_input(s))

    def test_a_bug_keeps_its_traceback(self):
        """An exception that is not a refused input (a bug) is not hidden: FreeCAD prints its
        traceback after the line naming the feature, and the feature is in error."""
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        proxy = c.Proxy

        def broken(obj):
            return 1 / 0

        proxy.compute = broken
        try:
            c.touch()
            _, text = self.console_output(self.doc.recompute)
        finally:
            del proxy.compute
        self.assertTrue(_bad(c))
        self.assertEqual(c.getStatusString(), "division by zero")
        self.assertIn("GHTCurve: ZeroDivisionError: division by zero", text)
        self.assertIn("Traceback (most recent call last)", text)
        c.touch()
        self.assert_recompute_clean(self.doc, c)

    def test_plain_raise_fallback_gives_the_same_state(self):
        """Where the quiet raise is unavailable (``QUIET_ERRORS`` off; a tracer; Python >= 3.12)
        FreeCAD prints the traceback, and the state and status string are the same."""
        c = ght_curve.make_ght_curve(PTS, doc=self.doc)
        c.Tolerance = -1.0
        _base.QUIET_ERRORS = False
        try:
            _, text = self.console_output(self.doc.recompute)
        finally:
            _base.QUIET_ERRORS = True
        self.assertTrue(_bad(c))
        self.assertEqual(c.getStatusString(), "GHTCurve.Tolerance=-1.0 is not allowed; it must be a finite number > 0")
        self.assertIn("Traceback (most recent call last)", text)
        c.touch()
        self.assert_recompute_refused(self.doc, c, "GHTCurve.Tolerance=-1.0 is not allowed; it must be a finite number > 0")

    @staticmethod
    def console_output(fn):
        from freecad.ght_workbench.tests.refusal import console_output

        return console_output(fn)


if __name__ == "__main__":
    unittest.main()
