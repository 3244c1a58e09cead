"""The FreeCAD adapter reads B-spline surfaces and curves into the core evaluator (:mod:`ght_cad.surfaces.nurbs`).

Inside Debian's FreeCAD (headless):

* a rational B-spline generalized cylinder (interior knot, weights equal across the rulings) with
  a hole cut by a boolean, the bench's polynomial tangent-developable B-spline, and a rational
  Bézier quarter cylinder are read into :class:`ght_cad.surfaces.nurbs.NurbsSurface` (``path == "nurbs"``),
  their line/B-spline pcurves and 3-D curves into numpy (``_Edge.paths``); ``jet`` and
  ``density_grid`` match FreeCAD's own ``value``/``getDN`` to 1e-12 of the size; the flat
  outlines equal the old point-by-point path's to 1e-9 of the size (that path differentiates
  pcurves by finite differences), the Bézier quarter cylinder is the closed-form R·π/2 × h
  rectangle;
* fallback: a periodic B-spline surface stays on FreeCAD's evaluation (``path == "freecad"``) and
  still unrolls to its 3-D area; a surface whose reading disagrees with FreeCAD (a pole moved by
  1e-9 of the size) is refused by the agreement check and unrolls through FreeCAD;
* the faces are written as BREP files with the fast path's outlines (``nurbs.json``) to
  ``$GHT_FC_OUT``: the pytest driver (tests/test_freecad_nurbs.py) unrolls them with the OCP
  adapter and compares the outlines to 1e-12 of the size;
* planes, cylinders and cones are evaluated by the core's closed forms (``path == "analytic"``),
  checked against FreeCAD's value/getDN and the point-by-point path.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_nurbs``
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import unittest

import numpy as np

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, face_reader, flat_pattern
from ght_cad.unrolling.face_unroll import unroll_face_data

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_")
RESULTS_JSON = os.path.join(OUT, "nurbs.json")
OPTS = dict(rulings=8, samples=65)


def _bspline_surface(poles, uknots, umults, vknots, vmults, udeg, vdeg, weights=None, uperiodic=False):
    s = Part.BSplineSurface()
    rows = [[App.Vector(*p) for p in row] for row in poles]
    if weights is None:
        s.buildFromPolesMultsKnots(rows, umults, vmults, uknots, vknots, uperiodic, False, udeg, vdeg)
    else:
        s.buildFromPolesMultsKnots(rows, umults, vmults, uknots, vknots, uperiodic, False, udeg, vdeg, [list(map(float, w)) for w in weights])
    return s


def _rational_cylinder_face(hole: bool) -> "Part.Face":
    """Rational cubic B-spline cross-section (interior knot 0.4) extruded along d (weights equal
    across the rulings: a generalized cylinder, developable), optionally drilled through."""
    A = np.array([[0, 0, 0], [20, 5, 3], [35, 30, -4], [60, 35, 6], [80, 20, 0]], float)
    d = np.array([2.0, -3.0, 40.0])
    w = np.array([1.0, 1.3, 0.7, 1.1, 1.0])
    s = _bspline_surface(np.stack([A, A + d], axis=1), [0.0, 0.4, 1.0], [4, 1, 4], [0.0, 1.0], [2, 2], 3, 1,
                         weights=np.stack([w, w], axis=1))
    face = s.toShape()
    if hole:
        mid = s.value(0.5, 0.5)
        n = s.normal(0.5, 0.5)
        drill = Part.makeCylinder(6.0, 200.0, mid - n * 100.0, n)
        face = face.cut(drill).Faces[0]
    return face


def _tangent_developable_face() -> "Part.Face":
    """The bench's tangent-developable cubic B-spline (bench/flatmesh_compare.py:default_faces)."""
    M = np.array([[1, 0, 0, 0], [1, 1 / 3, 0, 0], [1, 2 / 3, 1 / 3, 0], [1, 1, 1, 1]])
    c = 10.0 * np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    cp = np.vstack([np.array([[1, 0, 0], [0, 2, 0], [0, 0, 3]], float) * 10.0, np.zeros(3)])
    A, B = M @ (c + 0.3 * cp / 10.0), M @ (c + 1.0 * cp / 10.0)
    return _bspline_surface(np.stack([A, B], axis=1), [0.0, 1.0], [4, 4], [0.0, 1.0], [2, 2], 3, 1).toShape()


def _bezier_quarter_cylinder(R: float, h: float) -> "Part.Face":
    """Rational quadratic Bézier (weights 1, √2/2, 1) quarter circle of radius R extruded by h."""
    s = Part.BezierSurface()
    s.increase(2, 1)
    arc = [(R, 0, 0), (R, R, 0), (0, R, 0)]
    for i, p in enumerate(arc):
        for j in range(2):
            s.setPole(i + 1, j + 1, App.Vector(p[0], p[1], h * j), (1.0, math.sqrt(0.5), 1.0)[i])
    return s.toShape()


def _outline(pat) -> list:
    return [[(np.asarray(e.flat) + p.offset).tolist() for e in loop] for p in pat.panels for loop in p.loops]


def _size(pat) -> float:
    pts = np.concatenate([np.asarray(e.flat) for p in pat.panels for loop in p.loops for e in loop])
    return float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))


def _outline_distance(a, b) -> float:
    """Largest distance between matching edges of two outlines (each edge of ``a`` to the closest
    edge of ``b``, either direction)."""
    eb = [np.asarray(e) for loop in b for e in loop]
    worst = 0.0
    for loop in a:
        for e in loop:
            e = np.asarray(e)
            worst = max(worst, min(min(float(np.abs(e - f).max()), float(np.abs(e - f[::-1]).max())) for f in eb if f.shape == e.shape))
    return worst


def _record(name: str, face, pat) -> None:
    face.exportBrep(os.path.join(OUT, f"{name}.brep"))
    data = json.load(open(RESULTS_JSON)) if os.path.exists(RESULTS_JSON) else {}
    data[name] = {"outline": _outline(pat), "area": pat.area, "size": _size(pat)}
    json.dump(data, open(RESULTS_JSON, "w"))


def _edges(face, surf):
    return [flat_pattern._Edge(face, e, surf) for w in face.Wires for e in w.OrderedEdges]


class NurbsAdapterTest(unittest.TestCase):
    def _check_surface_against_freecad(self, face) -> None:
        """jet (orders 0..2) and density_grid of the core evaluator vs FreeCAD's value/getDN."""
        surf = flat_pattern.FreeCADSurface(face)
        self.assertEqual(surf.path, "nurbs")
        old = flat_pattern.FreeCADSurface(face, fast=False)
        self.assertEqual(old.path, "freecad")
        u0, u1, v0, v1 = face.ParameterRange
        rng = np.random.default_rng(1)
        u, v = rng.uniform(u0, u1, 25), rng.uniform(v0, v1, 25)
        ours, theirs = surf.jet(u, v, 2), old.d2(u, v)
        self.assertEqual(len(ours), 6)
        for k, (a, b) in enumerate(zip(ours, theirs)):
            scale = max(1.0, float(np.abs(b).max()))
            self.assertLessEqual(float(np.abs(a - b).max()), 1e-12 * scale, f"jet component {k}")
        for order in (0, 1):
            for a, b in zip(surf.jet(u, v, order), theirs):
                self.assertLessEqual(float(np.abs(a - b).max()), 1e-12 * max(1.0, float(np.abs(b).max())))
        gs, gv = np.sort(u[:7]), np.sort(v[:5])
        dens, ref = surf.density_grid(gs, gv), old.density_grid(gs, gv)
        self.assertEqual(dens.shape, (7, 5))
        self.assertLessEqual(float(np.abs(dens - ref).max()), 1e-12 * float(ref.max()))

    def _fast_and_old(self, name: str, face, expect_pcurves: set, expect_3d: set):
        surf = flat_pattern.FreeCADSurface(face)
        edges = _edges(face, surf)
        for e in edges:
            e.xyz(np.array([0.0, 1.0]))
        pcurves = {e.paths["pcurve"] for e in edges}
        curves3d = {e.paths["curve3d"] for e in edges}
        self.assertTrue(expect_pcurves <= pcurves, pcurves)
        self.assertTrue(expect_3d <= curves3d, curves3d)
        new = unroll_face_data(flat_pattern.face_data(face), **OPTS)
        old = unroll_face_data(flat_pattern.face_data(face, fast=False), **OPTS)
        size = _size(new)
        self.assertLessEqual(_outline_distance(_outline(new), _outline(old)), 1e-9 * size)
        self.assertAlmostEqual(new.area / old.area, 1.0, delta=1e-9)
        # the exact pcurve derivatives of the fast path against finite differences of its own points
        for e in edges:
            if e.paths["pcurve"] != "freecad":
                t = np.linspace(0.05, 0.95, 7)
                h = 1e-6
                fd = (np.stack(e.uv(t + h), axis=1) - np.stack(e.uv(t - h), axis=1)) / (2 * h)
                self.assertLessEqual(float(np.abs(e.duv(t) - fd).max()), 1e-6 * max(1.0, float(np.abs(fd).max())))
        _record(name, face, new)
        return new

    def test_rational_bspline_cylinder_reads_into_core(self):
        face = _rational_cylinder_face(hole=False)
        self._check_surface_against_freecad(face)
        pat = self._fast_and_old("rational_cylinder", face, {"line"}, {"bspline"})
        self.assertAlmostEqual(pat.area / pat.panels[0].area_3d, 1.0, delta=1e-12)
        self.assertLess(pat.errors["max"], 1e-9)

    def test_drilled_rational_bspline_cylinder(self):
        face = _rational_cylinder_face(hole=True)
        self.assertEqual(len(face.Wires), 2)
        self._check_surface_against_freecad(face)
        pat = self._fast_and_old("drilled_rational_cylinder", face, {"line", "bspline"}, {"bspline"})  # the hole: periodic B-splines
        self.assertEqual(len(pat.panels[0].loops), 2)

    def test_tangent_developable_bspline(self):
        face = _tangent_developable_face()
        self._check_surface_against_freecad(face)
        self._fast_and_old("tangent_dev_bspline", face, {"line"}, {"bspline"})

    def test_rational_bezier_quarter_cylinder_is_rectangle(self):
        R, h = 30.0, 50.0
        face = _bezier_quarter_cylinder(R, h)
        self.assertEqual(type(face.Surface).__name__, "BezierSurface")
        self._check_surface_against_freecad(face)
        pat = self._fast_and_old("bezier_quarter_cylinder", face, {"line"}, set())
        self.assertAlmostEqual(pat.area / (R * math.pi / 2 * h), 1.0, delta=1e-12)

    def test_plane_cylinder_cone_evaluated_in_numpy(self):
        """Planes, cylinders and cones (placed off the origin, tilted axes, a drilled half cylinder)
        are evaluated by the core's closed forms (path "analytic"): the jet to order 2 and the
        density grid match FreeCAD's value/getDN to 1e-12 of the size, and the flat outlines and
        areas the point-by-point path's (fast=False) to 1e-12."""
        axis = App.Vector(0.3, 0.4, 0.8)
        cyl = Part.makeCylinder(20, 50, App.Vector(100, 200, 300), axis, 180)
        drill = Part.makeCylinder(5, 200, App.Vector(100, 200, 300) + axis * 25 - App.Vector(-0.8, 0, 0.3) * 100,
                                  App.Vector(-0.8, 0, 0.3))
        faces = {
            "drilled half cylinder": next(f for f in cyl.cut(drill).Faces
                                          if type(f.Surface).__name__ == "Cylinder" and abs(f.Surface.Radius - 20) < 1e-9),
            "cone": next(f for f in Part.makeCone(10, 4, 20, App.Vector(1, 2, 3), App.Vector(0, 0.6, 0.8), 270).Faces
                         if type(f.Surface).__name__ == "Cone"),
            "plane": Part.makePlane(5, 7, App.Vector(1, 2, 3), App.Vector(0.2, 0.3, 0.9)).Faces[0],
        }
        rng = np.random.default_rng(2)
        for name, face in faces.items():
            surf, old = flat_pattern.FreeCADSurface(face), flat_pattern.FreeCADSurface(face, fast=False)
            self.assertEqual((surf.path, old.path), ("analytic", "freecad"), name)
            u0, u1, v0, v1 = face.ParameterRange
            u, v = rng.uniform(u0, u1, 25), rng.uniform(v0, v1, 25)
            for k, (a, b) in enumerate(zip(surf.jet(u, v, 2), old.d2(u, v))):
                scale = max(1.0, float(np.abs(b).max()), surf.radius)
                self.assertLessEqual(float(np.abs(a - b).max()), 1e-12 * scale, f"{name}: jet component {k}")
            gs, gv = np.sort(u[:7]), np.sort(v[:5])
            ref = old.density_grid(gs, gv)
            self.assertLessEqual(float(np.abs(surf.density_grid(gs, gv) - ref).max()), 1e-12 * float(ref.max()), name)
            new_pat = unroll_face_data(flat_pattern.face_data(face), **OPTS)
            old_pat = unroll_face_data(flat_pattern.face_data(face, fast=False), **OPTS)
            self.assertLessEqual(_outline_distance(_outline(new_pat), _outline(old_pat)), 1e-12 * _size(new_pat), name)
            self.assertAlmostEqual(new_pat.area / old_pat.area, 1.0, delta=1e-12, msg=name)
            # the flat area against the face's own 3-D area (developable: equal; FreeCAD's face.Area,
            # OCCT's default-precision integration, is 1.4e-5 off on the drilled face)
            self.assertAlmostEqual(new_pat.area / new_pat.panels[0].area_3d, 1.0, delta=1e-12, msg=name)

    def test_periodic_bspline_surface_stays_on_freecad(self):
        """A periodic (closed) B-spline surface is not read (path "freecad") and still unrolls."""
        n, R, h = 8, 25.0, 40.0
        ring = [(R * math.cos(2 * math.pi * k / n), R * math.sin(2 * math.pi * k / n), 0.0) for k in range(n)]
        poles = [[p, (p[0], p[1], h)] for p in ring]
        s = _bspline_surface(poles, [float(k) for k in range(n + 1)], [1] * (n + 1), [0.0, 1.0], [2, 2], 3, 1, uperiodic=True)
        self.assertTrue(s.isUPeriodic())
        self.assertIsNone(flat_pattern.read_surface(s))
        face = s.toShape()
        surf = flat_pattern.FreeCADSurface(face)
        self.assertEqual(surf.path, "freecad")
        pat = unroll_face_data(flat_pattern.face_data(face), **OPTS)
        self.assertAlmostEqual(pat.area / pat.panels[0].area_3d, 1.0, delta=1e-6)
        self.assertAlmostEqual(pat.panels[0].area_3d / face.Area, 1.0, delta=1e-6)

    def test_disagreeing_reading_falls_back_to_freecad(self):
        """A reading that differs from FreeCAD's own evaluation (a pole moved by 1e-9 of the
        size) fails the agreement check: the surface is evaluated by FreeCAD, the pattern is the
        same as the fast path's."""
        face = _rational_cylinder_face(hole=False)
        good = unroll_face_data(flat_pattern.face_data(face), **OPTS)
        orig = face_reader.read_surface  # where FreeCADSurface looks it up (issue 27 move)

        def bad(s):
            ns = orig(s)
            ns.cw[2, 1, :3] += 1e-9 * 100.0 * ns.cw[2, 1, 3]
            return type(ns)(ns.U, ns.V, ns.pu, ns.pv, ns.cw)

        face_reader.read_surface = bad
        try:
            surf = flat_pattern.FreeCADSurface(face)
            self.assertEqual(surf.path, "freecad")
            pat = unroll_face_data(flat_pattern.face_data(face), **OPTS)
        finally:
            face_reader.read_surface = orig
        self.assertEqual(flat_pattern.FreeCADSurface(face).path, "nurbs")
        self.assertLessEqual(_outline_distance(_outline(pat), _outline(good)), 1e-9 * _size(good))

    def test_flat_pattern_feature_uses_the_core_evaluator(self):
        doc = App.newDocument("fc_nurbs")
        try:
            obj = doc.addObject("Part::Feature", "Cyl")
            obj.Shape = _rational_cylinder_face(hole=True)
            doc.recompute()
            fp = flat_pattern.make_flat_pattern(obj, "Face1", doc=doc)
            self.assertFalse(_base.failed(fp), fp.State)
            direct = unroll_face_data(flat_pattern.face_data(obj.Shape.Faces[0]), **OPTS)
            self.assertAlmostEqual(fp.AreaFlat / direct.area, 1.0, delta=1e-12)
            self.assertAlmostEqual(fp.Shape.Faces[0].Area / direct.area, 1.0, delta=1e-6)
        finally:
            App.closeDocument(doc.Name)

    def test_face_reader_names_resolve_from_flat_pattern(self):
        """The face reader moved from flat_pattern to face_reader (issue 27, the cycle flat_pattern <->
        sheet_skin): every moved name is still an attribute of flat_pattern, the same object."""
        from freecad.ght_workbench import sheet_skin

        for name in ("face_data", "FreeCADSurface", "read_surface", "read_curve", "_Edge", "_CurveEval", "_placement",
                     "_vec", "_KINDS"):
            self.assertIs(getattr(flat_pattern, name), getattr(face_reader, name), name)
        self.assertIs(sheet_skin.face_data, face_reader.face_data)
        self.assertEqual(face_reader.face_data.__module__, face_reader.__name__)


if __name__ == "__main__":
    unittest.main()
