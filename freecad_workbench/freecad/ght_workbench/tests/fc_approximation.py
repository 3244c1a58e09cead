"""Developable approximation feature inside FreeCAD (headless, issue 24).

Checks: a spherical cap (``Part::Sphere`` R 1000 mm, latitude 50..90°: polar angle 0..40°; the
core's own tests cover the larger 0..60° cap, 14 panels at most at 1 mm) at Tolerance 1 mm gives at
most 14 panels (6), one valid shell of B-spline faces of degree 1 across the
rulings whose seams are shared edges; the deviation measured independently by FreeCAD's
``distToShape`` (target grid points to the shell, panel grid points to the target face) is within
Tolerance (1 + 1 %: the margin covers only OCCT's extrema accuracy); its
Flat pattern child holds one face per panel with the shell's area; the document recomputes clean
(not Touched, nothing in the Report view); save/reopen keeps it working, and a new Tolerance (4 mm)
changes PanelCount. The lateral face of a cone (a PartDesign Body's face) gives one panel within
1e-6 of its size; a B-spline dome (500 mm square) imported from STEP is covered within Tolerance
(open strips).
Direction and Method are enumerations of the core's choices and reach it (a small dome with Method
loft along u, then v: every panel a loft, DirectionUsed as asked, recorded in Report), with the
``Base.ProgressIndicator`` fed by the core's progress lines and nothing in the Report view.
Refusals (bad Tolerance, MaxPanels, unset Target, a tolerance the panel count cannot meet) are one
line each naming the property. A trimmed face (the small dome with a hole: covers 0.9295 of its
surface's (u, v) box; with a curved outline: 0.8588) is refused naming ``Untrimmed`` and the
fraction; with ``Untrimmed`` it is covered over its whole box and Report records the fraction.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_approximation``
"""

from __future__ import annotations

import os
import tempfile
import time
import unittest

import numpy as np

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, developable_approximation as da, export
from freecad.ght_workbench.tests.refusal import RefusalAssertions, console_lines, console_output

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_approx_")
#: margin of the independent deviation measurement over Tolerance (OCCT extrema accuracy only)
MARGIN = 0.01


def two_way(target: "Part.Face", shell: "Part.Shape", n_target: tuple = (36, 19), n_panel: tuple = (24, 5)) -> tuple[float, float]:
    """``(max distance of target grid points to the shell, of panel grid points to the target)``
    by ``Part.Vertex(p).distToShape`` (OCCT's BRepExtrema), on grids over the faces' parameter
    ranges (the panels: ``n_panel`` = along, across the rulings)."""
    def grid(face, nu, nv):
        u0, u1, v0, v1 = face.ParameterRange
        return [face.valueAt(float(u), float(v)) for u in np.linspace(u0, u1, nu) for v in np.linspace(v0, v1, nv)]

    to_shell = max(Part.Vertex(p).distToShape(shell)[0] for p in grid(target, *n_target))
    to_target = max(Part.Vertex(p).distToShape(target)[0] for f in shell.Faces for p in grid(f, *n_panel))
    return float(to_shell), float(to_target)


def shared_edges(shell: "Part.Shape") -> int:
    """Edges of ``shell`` that bound two different faces."""
    return sum(1 for e in shell.Edges if sum(1 for f in shell.Faces if any(e.isSame(g) for g in f.Edges)) == 2)


class DevelopableApproximationTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("approx")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def cap(self):
        sph = self.doc.addObject("Part::Sphere", "Cap")
        # latitude 50..90°: polar angle 0..40° (6 panels at 1 mm; the larger cap of the core's tests
        # costs 9 and proves nothing more about the feature)
        sph.Radius, sph.Angle1, sph.Angle2 = 1000.0, 50.0, 90.0
        self.doc.recompute()
        return sph

    def assert_panels(self, obj):
        """Valid shell (or one face) of PanelCount B-spline faces, degree 1 with 2 poles across,
        neighbours joined along their seams."""
        shape = obj.Shape
        self.assertTrue(shape.isValid())
        self.assertEqual(len(shape.Faces), obj.PanelCount)
        for f in shape.Faces:
            s = f.Surface
            self.assertEqual((type(s).__name__, s.VDegree, s.NbVPoles), ("BSplineSurface", 1, 2))
        if obj.PanelCount > 1:
            self.assertEqual(shape.ShapeType, "Shell")
            self.assertEqual(shared_edges(shape), obj.PanelCount - 1)
        self.assertEqual(len(obj.PanelDeviations), obj.PanelCount)
        self.assertEqual(len(obj.PanelMethods), obj.PanelCount)
        self.assertLessEqual(set(obj.PanelMethods), {"loft", "dual"})
        self.assertAlmostEqual(max(obj.PanelDeviations), obj.MaxDeviation, delta=1e-12 * max(obj.MaxDeviation, 1.0))
        self.assertLess(max(obj.PanelThetaMax), 0.01)

    def test_spherical_cap_save_reopen_and_new_tolerance(self):
        sph = self.cap()
        face = sph.Shape.Faces[0]
        self.assertEqual(type(face.Surface).__name__, "Sphere")
        self.assertEqual(da.face_target(face).path, "nurbs (toNurbs)")  # OCCT's exact NURBS of the face
        t0 = time.perf_counter()
        obj = da.make_developable_approximation((sph, "Face1"), 1.0, flat_pattern=True, doc=self.doc)
        seconds = time.perf_counter() - t0
        self.assertFalse(_base.failed(obj), obj.getStatusString())
        self.assertNotIn("Touched", obj.State)
        self.assertLessEqual(obj.PanelCount, 14)
        self.assertEqual(obj.DirectionUsed, "v")  # rulings along the meridians, seams on latitude circles
        self.assertLessEqual(obj.MaxDeviation, 1.0)
        self.assert_panels(obj)
        out, back = two_way(face, obj.Shape)
        self.assertLessEqual(max(out, back), 1.0 * (1 + MARGIN), (out, back))
        self.assertEqual(obj.Method, "auto")
        print(f"cap tol 1: {obj.PanelCount} panels, MaxDeviation {obj.MaxDeviation:.4f}, measured target->shell {out:.4f} "
              f"shell->target {back:.4f}, {seconds:.1f} s, methods {list(obj.PanelMethods)}")
        # the flat pattern child: one face per panel, the shell's area
        flats = da.flat_patterns_of(obj)
        self.assertEqual(len(flats), 1)
        fp = flats[0]
        self.assertFalse(_base.failed(fp), fp.getStatusString())
        self.assertEqual(len(fp.Shape.Faces), obj.PanelCount)
        self.assertLess(abs(fp.AreaFlat - obj.Shape.Area), 1e-6 * obj.Shape.Area)
        self.assertLess(fp.MaxRelativeError, 1e-8)
        self.assertLess(abs(sum(obj.PanelAreas) - obj.Shape.Area), 1e-6 * obj.Shape.Area)
        export.export_flat_pattern_dxf(fp, os.path.join(OUT, "cap_flat.dxf"))
        with open(os.path.join(OUT, "cap_panels.txt"), "w") as fh:
            fh.write(f"{obj.PanelCount} {fp.AreaFlat!r}\n")
        print(f"cap flat pattern: {len(fp.Shape.Faces)} faces, AreaFlat {fp.AreaFlat:.6f}, shell area {obj.Shape.Area:.6f}")
        self.assert_recompute_clean(self.doc, obj, fp)
        self.assertNotIn("Touched", obj.State)
        # save, reopen: the feature and its flat pattern work on
        names, count = (obj.Name, fp.Name), obj.PanelCount
        path = os.path.join(OUT, "approx.FCStd")
        self.doc.saveAs(path)
        App.closeDocument(self.doc.Name)
        self.doc = App.openDocument(path)
        obj, fp = (self.doc.getObject(n) for n in names)
        self.assertEqual(obj.Proxy.Type, "GHT::DevelopableApproximation")
        self.assertEqual((obj.PanelCount, len(obj.Shape.Faces)), (count, count))
        fp.BendLines = 4  # only the flat pattern recomputes: the panels are made again from the inputs
        self.assert_recompute_clean(self.doc, obj, fp)
        self.assertEqual(len(fp.Shape.Faces), count)
        obj.Tolerance = 4.0
        obj.Method = "loft"  # the rails loft on every strip (no dual fits: faster)
        t0 = time.perf_counter()
        self.assert_recompute_clean(self.doc, obj, fp)
        seconds = time.perf_counter() - t0
        self.assertNotIn("Touched", obj.State)
        self.assertLess(obj.PanelCount, count)
        self.assertLessEqual(obj.MaxDeviation, 4.0)
        self.assertEqual(set(obj.PanelMethods), {"loft"})
        self.assert_panels(obj)
        self.assertEqual(len(fp.Shape.Faces), obj.PanelCount)
        print(f"cap reopened, tol 4: {count} -> {obj.PanelCount} panels, MaxDeviation {obj.MaxDeviation:.4f}, {seconds:.1f} s")

    def test_cone_of_a_body_gives_one_panel(self):
        body = self.doc.addObject("PartDesign::Body", "Body")
        cone = self.doc.addObject("PartDesign::AdditiveCone", "Cone")
        body.addObject(cone)
        cone.Radius1, cone.Radius2, cone.Height = 50.0, 20.0, 80.0
        self.doc.recompute()
        face = body.Shape.Faces[0]  # a face of the Body (its tip's shape), as a click selects it
        self.assertEqual(type(face.Surface).__name__, "Cone")
        self.assertEqual(da.face_target(face).path, "analytic")
        obj = da.make_developable_approximation((body, "Face1"), 0.1, flat_pattern=True, doc=self.doc)
        self.assertFalse(_base.failed(obj), obj.getStatusString())
        self.assertEqual(obj.PanelCount, 1)
        self.assert_panels(obj)
        size = face.BoundBox.DiagonalLength
        self.assertLess(obj.MaxDeviation, 1e-6 * size)
        out, back = two_way(face, obj.Shape, (36, 9), (36, 9))
        self.assertLess(max(out, back), 1e-6 * size, (out, back))
        fp = da.flat_patterns_of(obj)[0]
        self.assertLess(abs(fp.AreaFlat - face.Area), 1e-6 * face.Area)
        self.assert_recompute_clean(self.doc, obj, fp)
        print(f"cone: 1 panel, MaxDeviation {obj.MaxDeviation:.3g}, measured {max(out, back):.3g} (size {size:.1f}), "
              f"AreaFlat {fp.AreaFlat:.6f} cone face {face.Area:.6f}")

    def test_bspline_dome_imported_from_step(self):
        # a shallow dome, 500 mm square (z = (x² + y²) / 8000: 3 strips at 1 mm), as an interpolated
        # B-spline face written to STEP and read back into a Part feature, as an imported design
        # surface arrives
        pts = [[App.Vector(x, y, (x * x + y * y) / 8000) for y in np.linspace(-250.0, 250.0, 9)] for x in np.linspace(-250.0, 250.0, 9)]
        srf = Part.BSplineSurface()
        srf.interpolate(pts)
        path = os.path.join(OUT, "dome.step")
        srf.toShape().exportStep(path)
        imported = self.doc.addObject("Part::Feature", "Dome")
        imported.Shape = Part.read(path)
        self.doc.recompute()
        face = imported.Shape.Faces[0]
        self.assertEqual(da.face_target(face).path, "nurbs")
        obj = da.make_developable_approximation((imported, "Face1"), 1.0, flat_pattern=True, doc=self.doc)
        self.assertFalse(_base.failed(obj), obj.getStatusString())
        self.assertNotIn("Touched", obj.State)
        self.assert_panels(obj)
        out, back = two_way(face, obj.Shape, (25, 25), (24, 5))
        self.assertLessEqual(max(out, back), 1.0 * (1 + MARGIN), (out, back))
        fp = da.flat_patterns_of(obj)[0]
        self.assertEqual(len(fp.Shape.Faces), obj.PanelCount)
        self.assertLess(abs(fp.AreaFlat - obj.Shape.Area), 1e-6 * obj.Shape.Area)
        self.assert_recompute_clean(self.doc, obj, fp)
        print(f"dome tol 1: {obj.PanelCount} panels, MaxDeviation {obj.MaxDeviation:.4f}, measured target->shell {out:.4f} "
              f"shell->target {back:.4f}")

    def test_direction_and_method_properties_drive_the_result_with_progress(self):
        # Direction and Method offer exactly what the core accepts (ght_cad.approximation.DIRECTIONS, read
        # at run time); Method "loft" and a given Direction reach the core: every panel a loft,
        # DirectionUsed the one asked for, recorded in Report; recomputes print nothing in the
        # Report view, also with the progress indicator driven (as in the GUI)
        import ght_cad.approximation as core

        pts = [[App.Vector(x, y, (x * x + y * y) / 4000) for y in range(-200, 201, 100)] for x in range(-200, 201, 100)]
        srf = Part.BSplineSurface()
        srf.interpolate(pts)
        dome = self.doc.addObject("Part::Feature", "SmallDome")
        dome.Shape = srf.toShape()
        self.doc.recompute()
        obj = da.make_developable_approximation((dome, "Face1"), 1.0, method="loft", direction="u", doc=self.doc)
        self.assertEqual(list(obj.getEnumerationsOfProperty("Direction")), list(getattr(core, "DIRECTIONS", ("auto", "u", "v"))))
        self.assertEqual(list(obj.getEnumerationsOfProperty("Method")), ["auto", "loft", "dual"])
        self.assertFalse(_base.failed(obj), obj.getStatusString())
        self.assertEqual((obj.Method, obj.Direction, obj.DirectionUsed), ("loft", "u", "u"))
        self.assertEqual(set(obj.PanelMethods), {"loft"})
        self.assertIn("Method loft", obj.Report)
        self.assert_panels(obj)
        self.assertLessEqual(obj.MaxDeviation, 1.0)
        loft_u = obj.PanelCount
        obj.Direction = "v"
        # FreeCAD.Base.ProgressIndicator fed by the core's lines, headless too; the feature recomputed
        # alone (a document recompute runs its own sequencer, which FreeCAD 0.20 lets no nested one drive)
        da.SHOW_PROGRESS = True
        try:
            _, text = console_output(obj.recompute)
        finally:
            da.SHOW_PROGRESS = None
        self.assertFalse(_base.failed(obj), obj.getStatusString())
        self.assertEqual(obj.DirectionUsed, "v")
        self.assertIn(f"{obj.Label}: developable approximation...", text)  # the console sequencer's start line
        self.assert_no_traceback(text)
        lines = [ln for ln in console_lines(text) if not ln.startswith(f"{obj.Label}: developable approximation")]
        self.assertEqual(lines, [], text)  # nothing else: no error in the Report view
        self.assert_panels(obj)
        # headless without the indicator: the recompute prints nothing at all
        obj.Method = "auto"
        self.assert_recompute_clean(self.doc, obj)
        self.assertLessEqual(set(obj.PanelMethods), {"loft", "dual"})
        self.assertIn("Method auto", obj.Report)
        # a document saved when the core had fewer directions gets the new ones on opening, its value kept
        obj.Direction = ["auto", "u"]
        obj.Direction = "u"
        obj.Proxy.restored(obj)
        self.assertEqual(list(obj.getEnumerationsOfProperty("Direction")), da.DIRECTIONS)
        self.assertEqual(obj.Direction, "u")
        print(f"small dome tol 1: loft along u {loft_u} panels; loft along v {obj.PanelCount} panels")

    def test_trimmed_face_refused_unless_untrimmed(self):
        # the small dome with a hole (a vertical cylinder r 60 cut through it) and trimmed by a curved
        # outline (common with a side cylinder r 300): face_trim measures the covered fraction of the
        # surface's (u, v) box; the feature refuses both naming Untrimmed and the fraction; with
        # Untrimmed the surface is covered over its whole box and Report records the fraction
        pts = [[App.Vector(x, y, (x * x + y * y) / 4000) for y in range(-200, 201, 100)] for x in range(-200, 201, 100)]
        srf = Part.BSplineSurface()
        srf.interpolate(pts)
        plain = srf.toShape()
        holed = plain.cut(Part.makeCylinder(60, 400, App.Vector(0, 0, -100))).Faces[0]
        deck = plain.common(Part.makeCylinder(300, 400, App.Vector(0, -330, -100))).Faces[0]
        for face in (plain, Part.makeCone(2, 4, 10).Faces[0], self.cap().Shape.Faces[0]):
            trim = da.face_trim(face)
            self.assertEqual(trim["holes"], 0)
            self.assertAlmostEqual(trim["covered"], 1.0, delta=1e-9)
        th, td = da.face_trim(holed), da.face_trim(deck)
        self.assertEqual((th["holes"], td["holes"]), (1, 0))
        # the hole's area on the dome, by FreeCAD: the cut-away disc (plain.common(cylinder))
        disc = plain.common(Part.makeCylinder(60, 400, App.Vector(0, 0, -100))).Area
        self.assertAlmostEqual(th["covered"], 1.0 - disc / plain.Area, delta=1e-6)
        feats = []
        for label, face, holes in (("HoledDome", holed, "1 hole"), ("DeckDome", deck, "0 holes")):
            src = self.doc.addObject("Part::Feature", label)
            src.Shape = face
            self.doc.recompute()
            obj = da.make_developable_approximation((src, "Face1"), 1.0, method="loft", direction="u", doc=self.doc)
            self.assertTrue(_base.failed(obj), obj.State)
            msg = obj.getStatusString()
            covered = th["covered"] if label == "HoledDome" else td["covered"]
            self.assertRegex(msg, rf"^{obj.Label}.Target = {label}.Face1 is a trimmed face: it covers {covered:.4g} of its "
                             rf"surface's \(u, v\) box, {holes}; .*set {obj.Label}.Untrimmed = True")
            feats.append(obj)
        self.doc.removeObject(feats[1].Name)
        obj = feats[0]
        obj.Untrimmed = True
        self.assert_recompute_clean(self.doc, obj)
        self.assert_panels(obj)
        self.assertLessEqual(obj.MaxDeviation, 1.0)
        self.assertIn(f"Untrimmed: the trimmed target ({th['covered']:.4g} of its (u, v) box, 1 hole(s))", obj.Report)
        print(f"trimmed dome: hole covers {th['covered']:.4f} (1 hole), deck covers {td['covered']:.4f}; refused; "
              f"Untrimmed: {obj.PanelCount} panels, MaxDeviation {obj.MaxDeviation:.4f}")

    def test_refusals_name_the_property(self):
        cone = self.doc.addObject("Part::Cone", "Cone")
        self.doc.recompute()
        obj = da.make_developable_approximation((cone, "Face1"), 0.01, doc=self.doc)
        self.assertFalse(_base.failed(obj), obj.getStatusString())
        obj.Tolerance = -1.0
        self.assert_recompute_refused(self.doc, obj, f"{obj.Label}.Tolerance=-1.0 is not allowed; it must be a finite number > 0")
        obj.Tolerance = 0.01
        obj.MaxPanels = 0
        self.assert_recompute_refused(self.doc, obj, f"{obj.Label}.MaxPanels=0 is not allowed; it must be an integer >= 1")
        obj.MaxPanels = 64
        obj.Target = (cone, ["Face9"])
        self.assert_recompute_refused(self.doc, obj, f"{obj.Label}.Target = Cone.Face9 is not a face of it (Face1..Face3); select the face again")
        obj.Target = None
        self.assert_recompute_refused(self.doc, obj, f"{obj.Label}.Target is not linked; select one face (of a Part feature, a Body or an imported STEP)")
        obj.Target = (cone, ["Face1"])
        self.assert_recompute_clean(self.doc, obj)
        self.assertEqual(obj.PanelCount, 1)
        # a cap that one panel cannot cover within 1 mm: the core's message with the best deviation
        sph = self.cap()
        obj.Target = (sph, ["Face1"])
        obj.Tolerance, obj.MaxPanels = 1.0, 1
        _, text = console_output(self.doc.recompute)
        self.assertTrue(_base.failed(obj), obj.State)
        msg = obj.getStatusString()
        # the core measures the one-strip covering (a cone to the pole) once and names its deviation
        self.assertRegex(msg, r"^no approximation of the target within tol=1 with at most max_panels=1 panels; "
                              r"best deviation reached [0-9.]+(e[+-]?[0-9]+)? with 1 panels \(properties Tolerance, MaxPanels\)$")
        self.assert_no_traceback(text)
        print(f"refused: {msg}")


if __name__ == "__main__":
    unittest.main()
