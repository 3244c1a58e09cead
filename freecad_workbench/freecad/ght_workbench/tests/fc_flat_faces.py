"""Flat patterns of FreeCAD's own faces inside FreeCAD (headless): Part::Cylinder / Part::Cone
lateral faces, a slanted cut, a drilled cone, an extrusion of a B-spline with a cut-out, a
Part::RuledSurface, a re-imported STEP face, a refused sphere; save/reopen keeps the pattern.

Every case states its exact expectation (closed forms, scipy quadratures). Faces are also written
as BREP files with the pattern's numbers (``flat_faces.json``) to ``$GHT_FC_OUT``: the pytest
driver (tests/test_freecad_flat_faces.py) unrolls them with the OCP adapter and compares.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_flat_faces``
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import unittest

import numpy as np
from scipy.integrate import quad

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, export, flat_pattern
from freecad.ght_workbench.tests.fc_features import _reopen  # save, close, reopen, recompute (into $GHT_FC_OUT)
from freecad.ght_workbench.tests.refusal import RefusalAssertions
from ght_cad.core.errors import DegenerateGeometryError, GHTError, NotDevelopableError
from ght_cad.unrolling.face_unroll import unroll_face_data

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_")
RTOL = 1e-9
RESULTS_JSON = os.path.join(OUT, "flat_faces.json")


def _face_name(obj, kind: str) -> str:
    names = [f"Face{i + 1}" for i, f in enumerate(obj.Shape.Faces) if type(f.Surface).__name__ == kind]
    if len(names) != 1:
        raise AssertionError(f"{obj.Label}: expected one {kind} face, found {names}")
    return names[0]


def _pattern(fp):
    return fp.Proxy.pattern(fp)


def _loop_lengths(pat) -> list[float]:
    return sorted(sum(e.length_flat for e in loop) for loop in pat.panels[0].loops)


def _record(name: str, face, pat, fp=None) -> None:
    """BREP of the face (and of the flat pattern's planar face) and the pattern's numbers, for the
    OCP cross-check in pytest."""
    face.exportBrep(os.path.join(OUT, f"{name}.brep"))
    if fp is not None:
        fp.Shape.Faces[0].exportBrep(os.path.join(OUT, f"{name}_flat.brep"))
    data = json.load(open(RESULTS_JSON)) if os.path.exists(RESULTS_JSON) else {}
    data[name] = {
        "area": pat.area,
        "area_3d": pat.panels[0].area_3d,
        "loop_lengths": _loop_lengths(pat),
        "edge_lengths_3d": sorted(float(e.length_3d) for loop in pat.panels[0].loops for e in loop),
        "face_area": face.Area,
    }
    with open(RESULTS_JSON, "w") as fh:
        json.dump(data, fh, indent=1)


class FlatFacesTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("flat_faces")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def _cylinder(self, r, h, name="Cyl"):
        c = self.doc.addObject("Part::Cylinder", name)
        c.Radius, c.Height = r, h
        return c

    def _extrusion(self, base, length, name):
        """A Part::Extrusion of ``base`` along +z by ``length`` (a sheet, not a solid), recomputed."""
        ext = self.doc.addObject("Part::Extrusion", name)
        ext.Base = base
        ext.DirMode = "Custom"
        ext.Dir = App.Vector(0, 0, 1)
        ext.LengthFwd = length
        ext.Solid = False
        self.doc.recompute()
        return ext

    def test_cylinder_lateral_face_is_rectangle_and_survives_reopen(self):
        cyl = self._cylinder(10.0, 20.0)
        self.doc.recompute()
        fp = flat_pattern.make_flat_pattern(cyl, _face_name(cyl, "Cylinder"), bend_lines=5, doc=self.doc)
        self.assertTrue(fp.Shape.isValid())
        exact = 400.0 * math.pi
        self.assertAlmostEqual(fp.AreaFlat, exact, delta=RTOL * exact)
        self.assertAlmostEqual(fp.Area3D, exact, delta=RTOL * exact)
        self.assertLess(fp.MaxRelativeError, 1e-12)
        pat = _pattern(fp)
        np.testing.assert_allclose(np.ptp(pat.outlines[0], axis=0), [20.0 * math.pi, 20.0], rtol=RTOL)
        lengths = sorted(e.length_flat for e in pat.panels[0].loops[0])
        np.testing.assert_allclose(lengths, [20.0, 20.0, 20.0 * math.pi, 20.0 * math.pi], rtol=RTOL)
        self.assertEqual(len(pat.bend_lines), 5)
        flat_face = fp.Shape.Faces[0]
        self.assertAlmostEqual(flat_face.Area, exact, delta=1e-9 * exact)
        bb = flat_face.BoundBox
        self.assertAlmostEqual(bb.XLength, 20.0 * math.pi, delta=1e-9 * 20 * math.pi)
        self.assertAlmostEqual(bb.YLength, 20.0, delta=1e-9 * 20)
        self.assertAlmostEqual(bb.ZLength, 0.0, delta=1e-12)
        self.assertEqual(len(fp.Shape.Edges), 4 + 5)  # rectangle + bend lines
        _record("cylinder", cyl.Shape.getElement(_face_name(cyl, "Cylinder")), pat, fp)
        # save, close, reopen, recompute: the pattern is still there with the same numbers
        fp_name, cyl_name = fp.Name, cyl.Name
        doc2 = _reopen(self.doc)
        fp2 = doc2.getObject(fp_name)
        self.assertTrue(fp2.Shape.isValid())
        self.assertAlmostEqual(fp2.AreaFlat, exact, delta=RTOL * exact)
        self.assertAlmostEqual(fp2.Shape.Faces[0].Area, exact, delta=1e-9 * exact)
        self.assertEqual(fp2.Source[0].Name, cyl_name)
        # and follows a change of the source after reopening
        doc2.getObject(cyl_name).Height = 30.0
        doc2.recompute()
        self.assertAlmostEqual(fp2.AreaFlat, 600.0 * math.pi, delta=RTOL * 600.0 * math.pi)

    def test_slanted_cut_top_edge_is_sine_of_ellipse_length(self):
        """Cylinder r=10 cut by a plane tilted β=20° through z=20: the top edge develops to
        y = 20 ± a cos(x/R), a = R tan β, of length the ellipse perimeter; area 2π R 20."""
        R, beta = 10.0, math.radians(20.0)
        cyl = self._cylinder(R, 40.0)
        box = self.doc.addObject("Part::Box", "Cutter")
        box.Length = box.Width = box.Height = 100.0
        box.Placement = App.Placement(App.Vector(0, 0, 20), App.Rotation(App.Vector(0, 1, 0), 20.0)).multiply(
            App.Placement(App.Vector(-50, -50, 0), App.Rotation())
        )
        cut = self.doc.addObject("Part::Cut", "Slanted")
        cut.Base, cut.Tool = cyl, box
        self.doc.recompute()
        name = _face_name(cut, "Cylinder")
        fp = flat_pattern.make_flat_pattern(cut, name, doc=self.doc)
        self.assertTrue(fp.Shape.isValid())
        pat = _pattern(fp)
        exact = 2 * math.pi * R * 20.0
        self.assertAlmostEqual(pat.area, exact, delta=RTOL * exact)
        self.assertAlmostEqual(fp.Area3D, exact, delta=RTOL * exact)
        a = R * math.tan(beta)
        ellipse = quad(lambda u: math.sqrt(R * R + a * a * math.sin(u) ** 2), 0, 2 * math.pi, epsabs=0, epsrel=1e-13, limit=200)[0]
        # the top (the cut; OCCT may split it in several edges): neither vertical nor horizontal
        top = [e for e in pat.panels[0].loops[0] if min(np.ptp(e.flat, axis=0)) > 1e-6]
        self.assertGreaterEqual(len(top), 1)
        self.assertAlmostEqual(sum(e.length_flat for e in top), ellipse, delta=RTOL * ellipse)
        self.assertAlmostEqual(sum(e.length_3d for e in top), ellipse, delta=RTOL * ellipse)
        # heights above the bottom circle's image (a horizontal segment; the cut's cylinder may
        # run its v axis downwards, then the pattern is upside down)
        bottom = [e for e in pat.panels[0].loops[0] if np.ptp(e.flat[:, 1]) < 1e-9 and np.ptp(e.flat[:, 0]) > 1.0]
        self.assertEqual(len(bottom), 1)
        flat = np.concatenate([e.flat for e in top])
        x, y = flat[:, 0], np.abs(flat[:, 1] - bottom[0].flat[0, 1])
        # shape of the curve: up to OCCT's pcurve of the cut (an approximation within the edge
        # tolerance, 1e-7; measured 1.5e-8)
        tol = max(e.Tolerance for e in cut.Shape.getElement(name).Edges)
        self.assertLessEqual(tol, 2e-7)
        self.assertAlmostEqual(float(np.ptp(y)), 2 * a, delta=tol)
        # y = 20 + A cos(x/R) + B sin(x/R) (the seam's position fixes the phase): fit A, B
        M = np.stack([np.cos(x / R), np.sin(x / R)], axis=1)
        coef = np.linalg.lstsq(M, y - 20.0, rcond=None)[0]
        self.assertAlmostEqual(float(np.hypot(*coef)), a, delta=tol)
        self.assertLess(float(np.abs(M @ coef + 20.0 - y).max()), tol)
        self.assertLess(pat.errors["max"], 1e-9)
        _record("slanted", cut.Shape.getElement(name), pat, fp)

    def test_cone_frustum_is_annular_sector(self):
        cone = self.doc.addObject("Part::Cone", "Cone")
        cone.Radius1, cone.Radius2, cone.Height = 20.0, 10.0, 30.0
        self.doc.recompute()
        fp = flat_pattern.make_flat_pattern(cone, _face_name(cone, "Cone"), doc=self.doc)
        self.assertTrue(fp.Shape.isValid())
        pat = _pattern(fp)
        slant = math.hypot(10.0, 30.0)
        rho_small, rho_big = slant * 10.0 / 10.0, slant * 20.0 / 10.0
        angle = 2 * math.pi * 20.0 / rho_big
        panel = pat.panels[0]
        pts = np.concatenate([e.flat for e in panel.loops[0]]) + panel.offset
        d = np.linalg.norm(pts - panel.offset, axis=1)  # the apex develops to the origin, moved by offset
        self.assertAlmostEqual(float(d.min()), rho_small, delta=RTOL * rho_small)
        self.assertAlmostEqual(float(d.max()), rho_big, delta=RTOL * rho_big)
        ang = np.unwrap(np.arctan2(pts[:, 1] - panel.offset[1], pts[:, 0] - panel.offset[0]))
        self.assertAlmostEqual(float(np.ptp(ang)), angle, delta=RTOL * angle)
        exact = math.pi * (20.0 + 10.0) * slant
        self.assertAlmostEqual(pat.area, exact, delta=RTOL * exact)
        self.assertAlmostEqual(0.5 * angle * (rho_big**2 - rho_small**2), exact, delta=1e-12 * exact)
        self.assertLess(pat.errors["max"], 1e-12)

    def _drilled_cone(self, axis: str):
        cone = self.doc.addObject("Part::Cone", "Cone")
        cone.Radius1, cone.Radius2, cone.Height = 20.0, 10.0, 30.0
        drill = self._cylinder(3.0, 40.0, "Drill")
        rot = App.Rotation(App.Vector(1, 0, 0), -90.0) if axis == "y" else App.Rotation(App.Vector(0, 1, 0), 90.0)
        drill.Placement = App.Placement(App.Vector(0, 0, 15), rot)
        cut = self.doc.addObject("Part::Cut", "Drilled")
        cut.Base, cut.Tool = cone, drill
        self.doc.recompute()
        name = _face_name(cut, "Cone")
        return cut, name, cut.Shape.getElement(name)

    @staticmethod
    def _drilled_cone_area() -> float:
        """Frustum area π (r1 + r2) slant minus the hole's area on the cone,
        ∫ 2 asin(w) r(z) √(1 + 1/9) dz, w = √(9 - (z-15)²) / r(z), r(z) = 20 - z/3 (z = 15 + 3 sin φ)."""

        def hole_strip(phi: float) -> float:
            z = 15.0 + 3.0 * math.sin(phi)
            r = 20.0 - z / 3.0
            return 2.0 * math.asin(3.0 * math.cos(phi) / r) * r * math.sqrt(10.0 / 9.0) * 3.0 * math.cos(phi)

        hole = quad(hole_strip, -math.pi / 2, math.pi / 2, epsabs=0, epsrel=1e-13, limit=200)[0]
        return math.pi * 30.0 * math.hypot(10.0, 30.0) - hole

    def test_drilled_cone_keeps_hole(self):
        """Frustum r 20 -> 10, h 30, drilled radially (r=3 along +y at z=15): two loops, area =
        frustum area minus the hole's area on the cone (:meth:`_drilled_cone_area`)."""
        cut, name, face = self._drilled_cone("y")
        self.assertEqual(len(face.Wires), 2)
        fp = flat_pattern.make_flat_pattern(cut, name, doc=self.doc)
        self.assertTrue(fp.Shape.isValid())
        self.assertEqual(len(fp.Shape.Faces[0].Wires), 2)  # the hole is kept in the planar face
        pat = _pattern(fp)
        self.assertEqual(len(pat.outlines), 2)
        exact = self._drilled_cone_area()
        self.assertAlmostEqual(pat.area, exact, delta=1e-9 * exact)
        self.assertAlmostEqual(fp.Area3D, exact, delta=1e-9 * exact)
        self.assertAlmostEqual(face.Area, exact, delta=1e-6 * exact)  # FreeCAD's own, independent
        # FreeCAD's Area (BRepGProp without eps) of the planar face is only ~2e-6 accurate with
        # fitted B-spline boundaries: pytest re-measures the exported face with OCP at eps 1e-12
        self.assertAlmostEqual(fp.Shape.Faces[0].Area, exact, delta=1e-5 * exact)
        self.assertLess(pat.errors["max"], 1e-9)
        _record("drilled_cone", face, pat, fp)
        # a STEP round trip keeps the face (and the pattern)
        path = os.path.join(OUT, "drilled_cone.step")
        face.exportStep(path)
        part = self.doc.addObject("Part::Feature", "Imported")
        part.Shape = Part.read(path)
        self.doc.recompute()
        fp2 = flat_pattern.make_flat_pattern(part, _face_name(part, "Cone"), doc=self.doc)
        self.assertAlmostEqual(fp2.AreaFlat, exact, delta=1e-9 * exact)

    def test_hole_across_the_seam(self):
        """Drilled along +x, through the cone's seam (u = 0): the hole is part of the outer wire
        (split by the seam); same area."""
        cut, name, face = self._drilled_cone("x")
        self.assertEqual(len(face.Wires), 1)
        fp = flat_pattern.make_flat_pattern(cut, name, doc=self.doc)
        self.assertTrue(fp.Shape.isValid())
        exact = self._drilled_cone_area()
        pat = _pattern(fp)
        self.assertAlmostEqual(pat.area, exact, delta=1e-9 * exact)
        self.assertAlmostEqual(fp.Area3D, exact, delta=1e-9 * exact)
        self.assertLess(pat.errors["max"], 1e-9)
        _record("seam_hole_cone", face, pat, fp)

    def test_cylinder_drilled_radially_twice(self):
        """Part.makeCylinder(20, 60) cut by two radial drills r=3 (along x at z=20, along y at z=40):
        four holes, one across the seam. FreeCAD's Face.OuterWire names a hole as the outer wire
        here (before the fix: negative area, IndexError in compute). Area 2π R H minus four holes,
        each ∫ 2 R asin(√(r² - z²) / R) dz over z ∈ [-r, r]. Scaled by 1e5 too: the seam matching
        tolerance was 1e-6 of the largest parameter range, 6 (radians!) in u there, so the outer
        loop was shifted by a period and the holes lay outside the flat outline (planar face
        without holes, 1.1 % too large)."""
        for sc in (1.0, 1e5):
            R, H, r = 20.0 * sc, 60.0 * sc, 3.0 * sc
            shape = Part.makeCylinder(R, H)
            shape = shape.cut(Part.makeCylinder(r, H, App.Vector(-1.5 * R, 0, H / 3), App.Vector(1, 0, 0)))
            shape = shape.cut(Part.makeCylinder(r, H, App.Vector(0, -1.5 * R, 2 * H / 3), App.Vector(0, 1, 0)))
            obj = self.doc.addObject("Part::Feature", "Drilled")
            obj.Shape = shape
            self.doc.recompute()
            name = next(f"Face{i + 1}" for i, f in enumerate(obj.Shape.Faces) if type(f.Surface).__name__ == "Cylinder" and f.Surface.Radius == R)
            face = obj.Shape.getElement(name)
            self.assertEqual(len(face.Wires), 4)  # the seam hole belongs to the outer wire
            hole = quad(lambda z: 2 * R * math.asin(math.sqrt(r * r - z * z) / R), -r, r, epsabs=0, epsrel=1e-13, limit=200)[0]
            exact = 2 * math.pi * R * H - 4 * hole
            fp = flat_pattern.make_flat_pattern(obj, name, doc=self.doc)
            self.assertFalse(_base.failed(fp), fp.getStatusString())
            self.assertTrue(fp.Shape.isValid())
            self.assertEqual(len(fp.Shape.Faces[0].Wires), 4, sc)
            pat = _pattern(fp)
            self.assertAlmostEqual(pat.area, exact, delta=1e-9 * exact)
            self.assertAlmostEqual(fp.Area3D, exact, delta=1e-9 * exact)
            outline = pat.outlines[0]
            np.testing.assert_allclose(np.ptp(outline, axis=0), [2 * math.pi * R, H], rtol=RTOL)
            for hole_loop in pat.outlines[1:]:  # the holes lie inside the outline's box
                self.assertTrue(np.all(hole_loop.min(axis=0) > outline.min(axis=0)), sc)
                self.assertTrue(np.all(hole_loop.max(axis=0) < outline.max(axis=0)), sc)
            # the planar face FreeCAD built has the holes cut out (OCCT's Area is ~1e-5 here)
            self.assertAlmostEqual(fp.Shape.Faces[0].Area, exact, delta=1e-4 * exact)
            self.assertLess(pat.errors["max"], 1e-9)
            if sc == 1.0:
                _record("drilled_cylinder", face, pat, fp)

    def test_bspline_extrusion_with_cut_out(self):
        pts = [App.Vector(0, 0, 0), App.Vector(10, 5, 0), App.Vector(20, -3, 0), App.Vector(30, 0, 0)]
        sp = Part.BSplineCurve()
        sp.interpolate(pts)
        L = sp.length(sp.FirstParameter, sp.LastParameter, 1e-13)
        base = self.doc.addObject("Part::Feature", "Profile")
        base.Shape = sp.toShape()
        ext = self._extrusion(base, 25.0, "Extrusion")
        self.assertEqual(type(ext.Shape.Faces[0].Surface).__name__, "SurfaceOfExtrusion")
        fp = flat_pattern.make_flat_pattern(ext, "Face1", doc=self.doc)
        pat = _pattern(fp)
        np.testing.assert_allclose(np.ptp(pat.outlines[0], axis=0), [L, 25.0], rtol=RTOL)
        self.assertAlmostEqual(pat.area, 25.0 * L, delta=RTOL * 25.0 * L)
        self.assertAlmostEqual(fp.Area3D, 25.0 * L, delta=RTOL * 25.0 * L)
        # a round cut-out through the sheet
        tool = self._cylinder(4.0, 60.0, "Punch")
        tool.Placement = App.Placement(App.Vector(15, -30, 12), App.Rotation(App.Vector(1, 0, 0), -90.0))
        cut = self.doc.addObject("Part::Cut", "CutOut")
        cut.Base, cut.Tool = ext, tool
        self.doc.recompute()
        face = cut.Shape.Faces[0]
        self.assertEqual(len(cut.Shape.Faces), 1)
        self.assertEqual(len(face.Wires), 2)
        fp2 = flat_pattern.make_flat_pattern(cut, "Face1", doc=self.doc)
        self.assertTrue(fp2.Shape.isValid())
        pat2 = _pattern(fp2)
        self.assertEqual(len(pat2.outlines), 2)
        self.assertLess(pat2.errors["boundary_length"], 1e-9)
        self.assertLess(pat2.errors["area"], 1e-9)
        self.assertLess(pat2.area, 25.0 * L - 0.9 * math.pi * 16.0)  # at least the punch's cross-section is gone
        self.assertAlmostEqual(pat2.area, face.Area, delta=1e-6 * face.Area)
        _record("extrusion_cut", face, pat2, fp2)

    def test_closed_elliptic_extrusion(self):
        """Part::Extrusion of a Part::Ellipse (10 x 5) by 15: a closed surface of extrusion, its
        pattern a 15 × perimeter rectangle (FreeCAD's own face.Area is 3e-5 off here)."""
        el = self.doc.addObject("Part::Ellipse", "Ellipse")
        el.MajorRadius, el.MinorRadius = 10.0, 5.0
        ext = self._extrusion(el, 15.0, "Tube")
        fp = flat_pattern.make_flat_pattern(ext, "Face1", doc=self.doc)
        self.assertTrue(fp.Shape.isValid())
        pat = _pattern(fp)
        perimeter = quad(lambda u: math.hypot(10 * math.sin(u), 5 * math.cos(u)), 0, 2 * math.pi, epsabs=0, epsrel=1e-13, limit=200)[0]
        np.testing.assert_allclose(np.sort(np.ptp(pat.outlines[0], axis=0)), [15.0, perimeter], rtol=RTOL)
        self.assertAlmostEqual(pat.area, 15.0 * perimeter, delta=RTOL * 15.0 * perimeter)
        self.assertAlmostEqual(fp.Area3D, 15.0 * perimeter, delta=RTOL * 15.0 * perimeter)
        self.assertLess(pat.errors["max"], 1e-12)

    def test_ruled_surface_is_unrolled(self):
        """Part::RuledSurface between two parallel circles (an oblique cone: developable)."""
        c1 = self.doc.addObject("Part::Circle", "C1")
        c1.Radius = 10.0
        c2 = self.doc.addObject("Part::Circle", "C2")
        c2.Radius = 5.0
        c2.Placement = App.Placement(App.Vector(3, 0, 10), App.Rotation())
        ruled = self.doc.addObject("Part::RuledSurface", "Ruled")
        ruled.Curve1, ruled.Curve2 = (c1, [""]), (c2, [""])
        self.doc.recompute()
        face = ruled.Shape.Faces[0]
        fp = flat_pattern.make_flat_pattern(ruled, "Face1", doc=self.doc)
        self.assertTrue(fp.Shape.isValid())
        pat = _pattern(fp)
        self.assertLess(pat.errors["max"], 1e-9)
        self.assertAlmostEqual(pat.area, face.Area, delta=1e-7 * face.Area)

    def test_sphere_is_refused_unless_best_effort(self):
        sph = self.doc.addObject("Part::Sphere", "Sphere")
        sph.Radius = 5.0
        self.doc.recompute()
        face = sph.Shape.Faces[0]
        with self.assertRaises(NotDevelopableError) as ctx:
            unroll_face_data(flat_pattern.face_data(face), label="Sphere.Face1")
        msg = str(ctx.exception)
        self.assertIn("not ruled", msg)
        self.assertIn("(u-isolines)", msg)
        self.assertIn("best_effort", msg)
        fp = flat_pattern.make_flat_pattern(sph, "Face1", doc=self.doc)
        self.assertTrue(_base.failed(fp), fp.State)
        # the feature's status string is the core's message, one line on the console, no traceback
        with self.assertRaisesRegex(NotDevelopableError, "Sphere.Face1.*not ruled") as ctx:
            _pattern(fp)
        fp.touch()
        self.assert_recompute_refused(self.doc, fp, str(ctx.exception))
        # a full sphere cannot be flattened even with BestEffort: its meridians run between the
        # poles, the ruled surface between the two boundary isolines (points) has no area
        fp.BestEffort = True
        with self.assertRaisesRegex(DegenerateGeometryError, "run between two points") as ctx:
            _pattern(fp)
        self.assert_recompute_refused(self.doc, fp, str(ctx.exception))
        # a gore (Angle3 = 45°) is flattened with BestEffort: rulings between its two meridians
        sph.Angle3 = 45.0
        self.assert_recompute_clean(self.doc, fp)
        self.assertTrue(fp.Shape.isValid())
        exact = 2 * 25.0 * math.radians(45.0)
        self.assertAlmostEqual(fp.Area3D, exact, delta=1e-9 * exact)
        self.assertGreater(fp.AreaFlat, 0.85 * exact)
        self.assertGreater(fp.MaxRelativeError, 1e-3)
        dxf = os.path.join(OUT, "gore.dxf")
        export.export_flat_pattern_dxf(fp, dxf)
        self.assertIn("OUTLINE", open(dxf).read().split("ENTITIES", 1)[1])
        # back to a full sphere: the recompute fails and FreeCAD keeps the gore's old shape; DXF
        # and SVG export refuse it (before: the stale gore, or an empty DXF for a feature that
        # never computed) and write nothing
        sph.Angle3 = 360.0
        self.assert_recompute_refused(self.doc, fp, str(ctx.exception))
        for fn, ext in ((export.export_flat_pattern_dxf, "dxf"), (export.export_flat_pattern_svg, "svg")):
            target = os.path.join(OUT, f"stale.{ext}")
            with self.assertRaisesRegex(GHTError, "recompute failed"):
                fn(fp, target)
            self.assertFalse(os.path.exists(target))

    def test_bad_sources_are_named(self):
        """A sub-element that no longer exists (the source's topology changed), an edge instead of
        a face, a source without faces: ValueError naming the source and what is allowed (before:
        OCCError 'Index out of bound', AttributeError 'Part.Edge' object has no attribute
        'Surface', 'Circ has 0 faces; select one face')."""
        cyl = self._cylinder(10.0, 20.0)
        self.doc.recompute()
        fp = flat_pattern.make_flat_pattern(cyl, "Face1", doc=self.doc)
        cases = (
            ((cyl, ["Face9"]), "Cyl has no Face9; allowed: Face1..Face3 (did the source's topology change? select the face again)"),
            ((cyl, ["Edge1"]), "Cyl.Edge1 is not a face; allowed: a face (Face1..Face3)"),
        )
        circle = self.doc.addObject("Part::Circle", "Circ")
        self.doc.recompute()
        cases += (((circle, []), "Circ has no faces to unroll; allowed: a face or a developable feature of this workbench"),)
        for source, message in cases:
            fp.Source = source
            self.assert_recompute_refused(self.doc, fp, message)
            with self.assertRaises(GHTError) as ctx:
                _pattern(fp)
            self.assertEqual(str(ctx.exception), message)

    def test_negative_bend_lines_are_refused_by_name(self):
        """BendLines = -1 was silently treated as 0 (feature Up-to-date): now an error naming it;
        0 is allowed (no bend lines, the outline only)."""
        cyl = self._cylinder(10.0, 20.0)
        self.doc.recompute()
        fp = flat_pattern.make_flat_pattern(cyl, "Face1", doc=self.doc)
        fp.BendLines = 0
        self.assert_recompute_clean(self.doc, fp)
        self.assertEqual(len(fp.Shape.Faces), 1)
        self.assertEqual(len(fp.Shape.Edges), 4)  # the rectangle alone
        fp.BendLines = -1
        self.assert_recompute_refused(self.doc, fp, "FlatPattern: BendLines=-1 is not allowed; allowed: 0 or more bend lines")
        with self.assertRaisesRegex(GHTError, r"BendLines=-1 is not allowed; allowed: 0 or more"):
            _pattern(fp)

    def test_twisted_face_is_refused_with_theta(self):
        """A bilinear (twisted) B-spline face: ruled both ways, θ_max = 45°, DD = 0.75."""
        s = Part.BSplineSurface()
        s.buildFromPolesMultsKnots(
            [[App.Vector(0, 0, 0), App.Vector(0, 1, 1)], [App.Vector(1, 0, 0), App.Vector(1, 1, 0)]],
            [2, 2], [2, 2], [0.0, 1.0], [0.0, 1.0], False, False, 1, 1,
        )
        with self.assertRaisesRegex(NotDevelopableError, r"theta_max=45 deg.*DD=0\.75"):
            unroll_face_data(flat_pattern.face_data(s.toShape()))
