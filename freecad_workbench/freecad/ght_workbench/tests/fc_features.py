"""Feature tests inside FreeCAD (headless): create, recompute, change a shape parameter, check
the shape changed as expected and is valid; save, close, reopen, recompute; STEP round trip.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_features``
"""

from __future__ import annotations

import math
import os
import tempfile
import unittest

import numpy as np

import FreeCAD as App
import Part

from freecad.ght_workbench import composite_curve, export, ght_curve

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_")
QUARTER = [(1.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 1.0, 0.0)]


def _sample(edge_or_wire, n: int = 41) -> np.ndarray:
    return np.array([[p.x, p.y, p.z] for p in edge_or_wire.discretize(n)])


def _reopen(doc):
    """Save ``doc``, close it, open the file again and recompute everything."""
    path = os.path.join(OUT, doc.Name + ".FCStd")
    doc.saveAs(path)
    App.closeDocument(doc.Name)
    App.setActiveDocument("")
    doc2 = App.openDocument(path)
    for o in doc2.Objects:
        o.touch()
    doc2.recompute()
    return doc2


class GHTCurveTest(unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("ght_curve")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def test_quarter_circle_and_gamma_change(self):
        obj = ght_curve.make_ght_curve(QUARTER, gamma=-1.0, doc=self.doc)
        self.assertTrue(obj.Shape.isValid())
        self.assertEqual(obj.Degree, 2)
        # γ = -1, μ = ν = 0: exact quarter unit circle (spec section 1); B-spline within Tolerance
        r = np.linalg.norm(_sample(obj.Shape, 101)[:, :2], axis=1)
        self.assertLess(np.max(np.abs(r - 1.0)), 10 * obj.Tolerance)
        self.assertAlmostEqual(obj.Shape.Length, math.pi / 2, delta=1e-6)
        self.assertAlmostEqual(obj.CurveLength, math.pi / 2, delta=1e-12)
        # γ = 1: classical quadratic Bézier, midpoint (P0 + 2 P1 + P2)/4 = (0.75, 0.75)
        obj.Gamma = 1.0
        self.doc.recompute()
        self.assertTrue(obj.Shape.isValid())
        mid = obj.Shape.Curve.value(0.5)
        self.assertAlmostEqual(mid.x, 0.75, delta=1e-6)
        self.assertAlmostEqual(mid.y, 0.75, delta=1e-6)

    def test_mu_moves_the_curve_and_is_constrained(self):
        obj = ght_curve.make_ght_curve([(0, 0, 0), (10, 20, 0), (30, 20, 5), (40, 0, 0)], doc=self.doc)
        before = _sample(obj.Shape)
        obj.Mu = 0.8
        self.doc.recompute()
        after = _sample(obj.Shape)
        self.assertTrue(obj.Shape.isValid())
        self.assertGreater(np.max(np.abs(after - before)), 1e-2)
        # end points are interpolated whatever μ is
        np.testing.assert_allclose(after[[0, -1]], [[0, 0, 0], [40, 0, 0]], atol=1e-9)
        # the core curve and the FreeCAD edge agree to the tolerance at matched parameters
        curve = ght_curve.core_curve(obj)
        t = np.linspace(0, 1, 33)
        fc = np.array([[p.x, p.y, p.z] for p in (obj.Shape.Curve.value(x) for x in t)])
        self.assertLess(np.max(np.linalg.norm(fc - curve.evaluate(t), axis=1)), 10 * obj.Tolerance)
        obj.Mu = 5.0  # App::PropertyFloatConstraint clamps to [-1, 1]
        self.assertEqual(obj.Mu, 1.0)

    def test_from_vertices_and_sketch(self):
        pts = [App.Vector(0, 0, 0), App.Vector(5, 8, 0), App.Vector(12, 8, 0), App.Vector(16, 0, 0)]
        wire = self.doc.addObject("Part::Feature", "Poly")
        wire.Shape = Part.makePolygon(pts)
        obj = ght_curve.make_ght_curve(source=[(wire, ["Vertex1", "Vertex2", "Vertex3", "Vertex4"])], doc=self.doc)
        self.assertEqual(obj.Degree, 3)
        self.assertTrue(obj.Shape.isValid())
        # moving a source vertex moves the curve
        wire.Shape = Part.makePolygon([pts[0], App.Vector(5, 12, 0), pts[2], pts[3]])
        self.doc.recompute()
        self.assertAlmostEqual(obj.ControlPoints[1].y, 12.0)
        sk = self.doc.addObject("Sketcher::SketchObject", "Sketch")
        for p in pts:
            sk.addGeometry(Part.Point(p))
        self.doc.recompute()
        obj2 = ght_curve.make_ght_curve(source=[(sk, [])], gamma=-1, doc=self.doc)
        self.assertEqual(obj2.Degree, 3)
        self.assertTrue(obj2.Shape.isValid())
        self.assertLess(obj2.Shape.Vertexes[-1].Point.distanceToPoint(pts[-1]), 1e-9)

    def test_save_reopen_step(self):
        obj = ght_curve.make_ght_curve([(0, 0, 0), (10, 20, 0), (30, 20, 5), (40, 0, 0)], mu=0.3, nu=-0.4, gamma=0.2, doc=self.doc)
        length, name = obj.Shape.Length, obj.Name
        doc2 = _reopen(self.doc)
        obj2 = doc2.getObject(name)
        self.assertEqual(obj2.Proxy.Type, "GHT::Curve")
        self.assertAlmostEqual(obj2.Shape.Length, length, delta=1e-9)
        self.assertEqual((obj2.Mu, obj2.Nu, obj2.Gamma), (0.3, -0.4, 0.2))
        obj2.Mu = 7.0  # the [-1, 1] constraint survives the reload
        self.assertEqual(obj2.Mu, 1.0)
        doc2.recompute()
        self.assertTrue(obj2.Shape.isValid())
        self.assertNotAlmostEqual(obj2.Shape.Length, length, delta=1e-6)
        path = os.path.join(OUT, "curve.step")
        export.export_step([obj2], path)
        back = export.read_step(path)
        self.assertEqual(len(back.Edges), 1)
        self.assertAlmostEqual(back.Length, obj2.Shape.Length, delta=1e-6)


class CompositeCurveTest(unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("composite")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def _segments(self):
        a = ght_curve.make_ght_curve([(0, 0, 0), (10, 15, 0), (25, 15, 0), (30, 0, 0)], doc=self.doc, name="SegA")
        b = ght_curve.make_ght_curve([(31, 1, 0), (35, -10, 0), (50, -10, 0), (60, 0, 0)], gamma=-0.5, doc=self.doc, name="SegB")
        c = ght_curve.make_ght_curve([(60, 0, 0), (66, 6, 0), (70, 9, 4), (80, 10, 0)], mu=0.5, doc=self.doc, name="SegC")
        return a, b, c

    def _tangents(self, wire):
        e = wire.OrderedEdges
        return [(e[i].tangentAt(e[i].LastParameter), e[i + 1].tangentAt(e[i + 1].FirstParameter)) for i in range(len(e) - 1)]

    def test_continuity_per_joint(self):
        a, b, c = self._segments()
        comp = composite_curve.make_composite_curve([a, b, c], ["G1", "C2"], k=[2.0, 1.0], doc=self.doc)
        self.assertTrue(comp.Shape.isValid())
        self.assertEqual(len(comp.Shape.Edges), 3)
        orders = [s.split("/") for s in comp.JointOrders]
        self.assertGreaterEqual(int(orders[0][1][1]), 1)  # G1 measured at joint 0
        self.assertGreaterEqual(int(orders[1][0][1]), 2)  # C2 measured at joint 1
        for t0, t1 in self._tangents(comp.Shape):  # unit tangents agree across both joints
            self.assertLess((t0 - t1).Length, 1e-7)
        # a shape parameter of the middle segment changes the wire but keeps the joints smooth
        before = _sample(comp.Shape, 61)
        b.Mu = -0.9
        self.doc.recompute()
        self.assertTrue(comp.Shape.isValid())
        self.assertGreater(np.max(np.abs(_sample(comp.Shape, 61) - before)), 1e-2)
        for t0, t1 in self._tangents(comp.Shape):
            self.assertLess((t0 - t1).Length, 1e-7)
        # switching joint 0 to C0 leaves a corner (the original SegB starts with a kink)
        comp.Continuity = ["C0", "C2"]
        self.doc.recompute()
        t0, t1 = self._tangents(comp.Shape)[0]
        self.assertGreater((t0 - t1).Length, 1e-2)
        self.assertTrue(comp.JointOrders[0].startswith("C0"))

    def test_save_reopen_step(self):
        a, b, c = self._segments()
        comp = composite_curve.make_composite_curve([a, b, c], "G2", doc=self.doc)
        length, name = comp.Shape.Length, comp.Name
        doc2 = _reopen(self.doc)
        comp2 = doc2.getObject(name)
        self.assertAlmostEqual(comp2.Shape.Length, length, delta=1e-9)
        self.assertEqual(list(comp2.Continuity), ["G2", "G2"])
        self.assertEqual([s.Name for s in comp2.Segments], ["SegA", "SegB", "SegC"])
        path = os.path.join(OUT, "composite.step")
        export.export_step([comp2], path)
        back = export.read_step(path)
        self.assertEqual(len(back.Edges), 3)
        self.assertAlmostEqual(back.Length, length, delta=1e-6)


if __name__ == "__main__":
    unittest.main()
