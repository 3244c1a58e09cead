"""Developable loft feature inside FreeCAD (headless): two sketch edges, GHT curve rails, any edge.

Checks: the loft between the circles of two sketches is the cone (rulings through the apex within
the faces' certified deviation, flat pattern = closed-form annular sector to 1e-9); moving a rail's
sketch or changing its radius recomputes it onto the new cone; save/reopen; the flat pattern
feature of it; STEP export (read back by pytest); the Part.Edge rail adapter's derivatives; GHT
curve rails with fans and the optimization feature's Loft problem; skew lines and unset links put
the feature in error with a message naming the problem.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_loft``
"""

from __future__ import annotations

import math
import os
import tempfile
import unittest

import numpy as np

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, developable_loft, export, flat_pattern, ght_curve, optimization
from freecad.ght_workbench.tests.refusal import RefusalAssertions

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_loft_")
# the dory's chine and sheer (examples/design_hull_plate.toml)
CHINE = [(0, -700, 300), (1500, -1050, 200), (3000, -1150, 250), (4500, -950, 450)]
SHEER = [(0, -900, 1200), (1500, -1250, 1150), (3000, -1300, 1180), (4500, -1100, 1300)]


_bad = _base.failed  # the object's last recompute failed (FreeCAD state Invalid)


def _sketch(doc, name: str, radius: float, z: float):
    sk = doc.addObject("Sketcher::SketchObject", name)
    sk.Placement = App.Placement(App.Vector(0, 0, z), App.Rotation())
    sk.addGeometry(Part.Circle(App.Vector(0, 0, 0), App.Vector(0, 0, 1), radius), False)
    doc.recompute()
    return sk


def _apex_distance(shape: "Part.Shape", apex: "App.Vector", n: int = 41) -> float:
    """max distance from ``apex`` to the lines through the ruling iso-lines (degree-1 direction)
    of every face of the shape."""
    worst = 0.0
    for f in shape.Faces:
        s = f.Surface
        assert s.VDegree == 1 and s.NbVPoles == 2, (s.UDegree, s.VDegree)
        u0, u1, v0, v1 = s.bounds()
        for u in np.linspace(u0, u1, n):
            p, q = s.value(float(u), v0), s.value(float(u), v1)
            d = (q - p).normalize()
            worst = max(worst, (apex - p).cross(d).Length)
    return worst


def _frustum_area(r1: float, r2: float, h: float) -> float:
    """Lateral area π (r1 + r2) slant of a frustum = the annular sector of its flat pattern."""
    return math.pi * (r1 + r2) * math.hypot(h, r1 - r2)


class DevelopableLoftTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("loft")
        self.ska = _sketch(self.doc, "SketchA", 5.0, 0.0)
        self.skb = _sketch(self.doc, "SketchB", 2.0, 6.0)

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def loft(self):
        return developable_loft.make_developable_loft((self.ska, "Edge1"), (self.skb, "Edge1"), doc=self.doc)

    def test_cone_from_two_sketch_edges(self):
        lf = self.loft()
        self.assertFalse(_bad(lf), lf.State)
        self.assertEqual(list(lf.Segments), ["main"])
        self.assertTrue(lf.Shape.isValid())
        self.assertEqual(len(lf.Shape.Faces), 1)
        self.assertEqual(len(lf.Shape.Edges), 3)  # two circles and the seam (closed around)
        self.assertLess(float(lf.ThetaMax), 1e-8)
        self.assertLess(lf.FResidual, 1e-13)
        self.assertEqual(lf.FanShare, 0.0)
        apex = App.Vector(0, 0, 10)
        dist = _apex_distance(lf.Shape, apex)
        self.assertLess(dist, 10 * lf.MaxDeviation + 1e-12)
        exact = _frustum_area(5.0, 2.0, 6.0)
        self.assertAlmostEqual(lf.Area, exact, delta=1e-9 * exact)
        print(f"sketch cone: apex distance {dist:.3g} (MaxDeviation {lf.MaxDeviation:.3g}), area {lf.Area:.12g} exact {exact:.12g}")

    def test_recompute_after_moving_a_rail(self):
        lf = self.loft()
        area0 = lf.Area
        self.skb.Placement = App.Placement(App.Vector(0, 0, 4), App.Rotation())
        self.doc.recompute()
        self.assertFalse(_bad(lf), lf.State)
        self.assertAlmostEqual(lf.Area, _frustum_area(5.0, 2.0, 4.0), delta=1e-9 * area0)
        apex = App.Vector(0, 0, 4 * 5.0 / 3.0)  # r: 5 at z = 0, 2 at z = 4
        self.assertLess(_apex_distance(lf.Shape, apex), 10 * lf.MaxDeviation + 1e-12)
        # change the rail's geometry (radius 2 -> 3): the cone follows again
        geo = self.skb.Geometry
        geo[0].Radius = 3.0
        self.skb.Geometry = geo
        self.doc.recompute()
        self.assertFalse(_bad(lf), lf.State)
        self.assertAlmostEqual(lf.Area, _frustum_area(5.0, 3.0, 4.0), delta=1e-9 * area0)
        self.assertLess(_apex_distance(lf.Shape, App.Vector(0, 0, 10)), 10 * lf.MaxDeviation + 1e-12)
        print(f"moved rail: area {area0:.9g} -> {lf.Area:.9g}")

    def test_flat_pattern_save_reopen_and_step(self):
        lf = self.loft()
        fp = flat_pattern.make_flat_pattern(lf, doc=self.doc)
        self.assertFalse(_bad(fp), fp.State)
        self.assertTrue(fp.Shape.isValid())
        self.assertEqual(len(fp.Shape.Faces), 1)  # one panel
        exact = _frustum_area(5.0, 2.0, 6.0)
        self.assertAlmostEqual(fp.AreaFlat, exact, delta=1e-9 * exact)
        self.assertLess(fp.MaxRelativeError, 1e-8)
        self.assertAlmostEqual(fp.Shape.Faces[0].Area, exact, delta=1e-6 * exact)
        step = os.path.join(OUT, "loft.step")
        export.export_step([lf], step)
        with open(os.path.join(OUT, "loft_area.txt"), "w") as fh:
            fh.write(repr(exact))
        print(f"flat pattern: AreaFlat={fp.AreaFlat:.12g} exact={exact:.12g} MaxRelativeError={fp.MaxRelativeError:.3g}")
        name, fp_name, area = lf.Name, fp.Name, lf.Area
        path = os.path.join(OUT, "loft.FCStd")
        self.doc.saveAs(path)
        App.closeDocument(self.doc.Name)
        doc2 = App.openDocument(path)
        for o in doc2.Objects:
            o.touch()
        doc2.recompute()
        self.assertEqual([o.Name for o in doc2.Objects if _bad(o)], [])
        lf2, fp2 = doc2.getObject(name), doc2.getObject(fp_name)
        self.assertEqual(lf2.Proxy.Type, "GHT::DevelopableLoft")
        self.assertEqual(list(lf2.Segments), ["main"])
        self.assertAlmostEqual(lf2.Area, area, delta=1e-12 * area)
        self.assertAlmostEqual(fp2.AreaFlat, exact, delta=1e-9 * exact)
        self.assertEqual(lf2.RailA[0].Name, "SketchA")

    def test_part_edge_rail_derivatives(self):
        """PartEdgeRail on an ellipse edge (a = 4, b = 1.5) and its reversal: closed-form
        r^(k)(t) for k = 0..3 (1e-12 relative)."""
        e = Part.Ellipse(App.Vector(0, 0, 0), 4.0, 1.5).toShape()
        rng = np.random.default_rng(7)
        for rev in (False, True):
            rail = developable_loft.PartEdgeRail(e.reversed() if rev else e)
            w = -2 * math.pi if rev else 2 * math.pi
            for t in rng.uniform(0, 1, 12):
                ph = 2 * math.pi * (1 - t) if rev else 2 * math.pi * t
                ref = [
                    np.array([4 * math.cos(ph), 1.5 * math.sin(ph), 0]),
                    w * np.array([-4 * math.sin(ph), 1.5 * math.cos(ph), 0]),
                    w**2 * np.array([-4 * math.cos(ph), -1.5 * math.sin(ph), 0]),
                    w**3 * np.array([4 * math.sin(ph), -1.5 * math.cos(ph), 0]),
                ]
                for k in range(4):
                    got = rail.derivative(t, k)[0]
                    self.assertLess(float(np.linalg.norm(got - ref[k])), 1e-12 * 10 * np.linalg.norm(ref[k]), (rev, t, k))

    def test_ght_curve_rails_fans_and_loft_optimization(self):
        a = ght_curve.make_ght_curve(CHINE, doc=self.doc, name="Chine")
        b = ght_curve.make_ght_curve(SHEER, doc=self.doc, name="Sheer")
        lf = developable_loft.make_developable_loft(a, b, doc=self.doc)
        self.assertFalse(_bad(lf), lf.State)
        self.assertEqual(list(lf.Segments), ["fan_b", "main", "fan_b"])
        self.assertTrue(lf.Shape.isValid())
        self.assertEqual(lf.Shape.ShapeType, "Shell")
        self.assertEqual(len(lf.Shape.Faces), 3)
        self.assertLess(float(lf.ThetaMax), 1e-8)
        # the faces' rail edges lie on the exact GHT rails within MaxDeviation
        from freecad.ght_workbench.ght_curve import core_curve

        chine = core_curve(a, placed=True)
        pts = chine.evaluate(np.linspace(0, 1, 41))
        cover = max(min(Part.Vertex(App.Vector(*p)).distToShape(e)[0] for e in lf.Shape.Edges) for p in pts)
        self.assertLess(cover, 1e-6 * lf.Shape.BoundBox.DiagonalLength)
        fan0 = lf.FanShare
        opt = optimization.make_optimization([lf], "Loft", method="pso", doc=self.doc, PopulationSize=4, MaxIterations=2, Seed=3)
        self.assertFalse(_bad(opt), opt.State)
        self.assertAlmostEqual(opt.CurrentValue, fan0, delta=1e-6)
        res = optimization.run_optimization(opt, gui=False)
        self.assertLessEqual(opt.BestValue, opt.InitialValue)
        self.assertFalse(_bad(lf), lf.State)
        # the optimum was written into the rails and the loft recomputed with it
        self.assertAlmostEqual(lf.FanShare, opt.BestValue, delta=1e-6)
        print(f"loft optimization: fan share {fan0:.6g} -> {lf.FanShare:.6g} ({res.nfev} evaluations)")
        # a loft on non-GHT rails cannot be optimized: the message names the rail
        cone = self.loft()
        opt.Targets = [cone]
        self.assert_refused_as(self.doc, opt, lambda: opt.Proxy.problem(opt), "RailA is SketchA, not a GHT curve")

    def test_refusals_name_the_problem(self):
        l1 = self.doc.addObject("Part::Feature", "LineA")
        l1.Shape = Part.LineSegment(App.Vector(0, 0, 0), App.Vector(10, 0, 0)).toShape()
        l2 = self.doc.addObject("Part::Feature", "LineB")
        l2.Shape = Part.LineSegment(App.Vector(0, 5, 3), App.Vector(0, 8, 10)).toShape()
        lf = developable_loft.make_developable_loft(l1, l2, doc=self.doc)
        self.assertTrue(_bad(lf))
        # each refusal: the feature's status string is the message, one console line, no traceback
        self.assert_refused_as(self.doc, lf, lambda: lf.Proxy.surface(lf), "no developable joins the rails")
        lf.RailB = None
        self.assertEqual(self.assert_refused_as(self.doc, lf, lambda: lf.Proxy.surface(lf), "RailB is not linked"),
                         "DevelopableLoft.RailB is not linked; select two edges (of sketches, GHT curves or any Part feature)")
        lf.RailB = (self.skb, ["Edge7"])
        self.assert_refused_as(self.doc, lf, lambda: lf.Proxy.surface(lf), r"SketchB.Edge7 is not an edge of it \(Edge1..Edge1\)")
        # a good pair again: the feature recovers
        lf.RailA, lf.RailB = (self.ska, ["Edge1"]), (self.skb, ["Edge1"])
        self.assert_recompute_clean(self.doc, lf)
        with self.assertRaisesRegex(ValueError, "orientation='sideways'"):
            developable_loft.make_developable_loft(l1, l2, orientation="sideways", doc=self.doc)

    def test_no_cad_kernel_import(self):
        import sys

        self.assertFalse([m for m in sys.modules if m.split(".")[0] in ("OCP", "build123d", "cadquery")])


if __name__ == "__main__":
    unittest.main()
