"""The GHT Plate feature inside FreeCAD (headless): exact solid plates of developable features.

Checks, with the tolerances stated where they are asserted:

* plates of a developable from planes (the exact quarter cylinder r = 10, H = 20), of a
  developable loft with fans (the dory's chine and sheer, GHT curve rails) and of a spine
  developable are valid ``Part.Solid`` s of six faces;
* ``Volume`` (FreeCAD's ``Shape.Volume`` on the copy split at the knots) within 1e-8 of the
  closed form (``VolumeError``): the faces deviate by at most ``3e-7 T`` from the exact plate,
  which moves the volume by about that much relative in the worst case, and measured is 1e-11 to
  1e-9; the closed form of the cylinder equals the annulus ``(π/4) ((r ± T)² - r²) H`` to 1e-12;
* the inside face lies on the design surface and the outside face at distance T: at matched
  parameters ``|F_in(u, v) - X(u, v)|`` and ``| |F_out(u, v) - X(u, v)| - T |`` <= 1e-6 x size
  (the fit's certified deviation is far below), and ``distToShape`` of outside points to the
  inside face is T to 1e-6 x size;
* recompute after changing Thickness and Side;
* the Flat pattern of the plate (Thickness 0, ThicknessFromSolid) finds the inside face, the
  thickness (1e-9 relative) and side, uses the plate's KFactor, and its neutral pattern equals
  the core's ``unroll(surface, sheet=...)`` to 1e-9 (area and boundary lengths, relative);
* refused input (too thick, thickness 0, no or a wrong Source, a bad K-factor, the concave side of
  a fan's apex) puts the plate in FreeCAD's error state with exactly the one-line message, no
  traceback;
* save/reopen (FCStd) keeps it working; STEP export (``$GHT_FC_OUT/fc_plate_loft.step``, read back
  with OCP by the pytest driver, ``fc_plate.json`` with the expected volume).

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_plate``
"""

from __future__ import annotations

import json
import math
import os
import tempfile
import time
import unittest

import numpy as np

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, developable, developable_loft, export, flat_pattern, ght_curve, plate, spine_developable
from freecad.ght_workbench.tests.fc_features import _recompute, _reopen
from freecad.ght_workbench.tests.refusal import RefusalAssertions, console_output

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_plate_")
# the dory's chine and sheer (examples/design_hull_plate.toml), as in fc_loft
CHINE = [(0, -700, 300), (1500, -1050, 200), (3000, -1150, 250), (4500, -950, 450)]
# the bow of examples/design_bow_plate.toml: both rails end at (4200, 0, 1500)
BOW_SHEER = [(0, -900, 1200), (1500, -1000, 1250), (3000, -700, 1350), (4200, 0, 1500)]
BOW_CHINE = [(0, -700, 300), (1500, -800, 350), (3000, -500, 700), (4200, 0, 1500)]
SHEER = [(0, -900, 1200), (1500, -1250, 1150), (3000, -1300, 1180), (4500, -1100, 1300)]
VOLUME_RTOL = 1e-8


def _size(surface) -> float:
    g = surface.grid(33, 3).reshape(-1, 3)
    return float(np.linalg.norm(g.max(axis=0) - g.min(axis=0)))


class PlateTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("plate")

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    # -- helpers -----------------------------------------------------------------------------
    def assert_plate(self, pl, what: str, names: tuple = plate.FACE_NAMES) -> None:
        """Valid solid of the named faces (six; a pointed end has no end wall); Volume vs closed
        form; inside on X, outside at T."""
        from ght_cad.sheetmetal.sheet import ruling_normal

        self.assertFalse(_base.failed(pl), f"{what}: {pl.getStatusString()}")
        sh = pl.Shape
        self.assertEqual(sh.ShapeType, "Solid", what)
        self.assertTrue(sh.isValid(), what)
        self.assertEqual(len(sh.Faces), len(names), what)
        self.assertEqual(sorted(pl.FaceNames), sorted(names), what)
        self.assertGreater(sh.Volume, 0.0, what)
        self.assertAlmostEqual(sh.Volume, pl.ShapeVolume, delta=1e-12 * abs(sh.Volume))
        self.assertLess(abs(pl.VolumeError), VOLUME_RTOL, f"{what}: Volume {pl.Volume!r} closed form {pl.ClosedFormVolume!r}")
        self.assertAlmostEqual(pl.VolumeError, pl.Volume / pl.ClosedFormVolume - 1.0, delta=1e-15)
        surf = pl.Proxy.design_surface(pl)
        T = float(pl.Thickness.Value)
        sigma = 1.0 if pl.Side == "normal" else -1.0
        size = _size(surf)
        faces = dict(zip(pl.FaceNames, sh.Faces))
        inside, outside = faces["inside"], faces["outside"]
        self.assertTrue(pl.Proxy.inside_face(pl).isSame(inside))
        u = np.linspace(0.0, 1.0, 23)
        worst_in = worst_out = worst_dist = 0.0
        for v in (0.0, 0.3, 0.5, 1.0):
            X = surf.evaluate(u, np.full_like(u, v))
            n = ruling_normal(surf, u, 0)[0]
            fin = np.array([tuple(inside.Surface.value(float(a), v)) for a in u])
            fout = np.array([tuple(outside.Surface.value(float(a), v)) for a in u])
            worst_in = max(worst_in, float(np.linalg.norm(fin - X, axis=1).max()))
            worst_out = max(worst_out, float(np.linalg.norm(fout - (X + sigma * T * n), axis=1).max()))
            if 0.0 < v < 1.0:  # interior points: the distance to the inside face is T
                for p in fout[2:-2:4]:
                    d = Part.Vertex(App.Vector(*p)).distToShape(inside)[0]
                    worst_dist = max(worst_dist, abs(d - T))
        self.assertLess(worst_in, 1e-6 * size, what)
        self.assertLess(worst_out, 1e-6 * size, what)
        self.assertLess(worst_dist, 1e-6 * size, what)
        print(f"{what}: T={T:g} {pl.Side}: Volume={pl.Volume:.12g} closed form={pl.ClosedFormVolume:.12g} "
              f"VolumeError={pl.VolumeError:.3g}, Shape.Volume error={pl.ShapeVolume / pl.ClosedFormVolume - 1:.3g}; "
              f"inside {worst_in / size:.2g}, outside {worst_out / size:.2g}, distance {worst_dist / size:.2g} of the size; "
              f"MaxDeviation {pl.MaxDeviation:.3g}")

    def cylinder(self):
        return developable.make_developable(gamma=-1.0, doc=self.doc, name="Cyl")

    def loft(self):
        a = ght_curve.make_ght_curve(CHINE, doc=self.doc, name="Chine")
        b = ght_curve.make_ght_curve(SHEER, doc=self.doc, name="Sheer")
        lf = developable_loft.make_developable_loft(a, b, doc=self.doc)
        self.assertEqual(list(lf.Segments), ["fan_b", "main", "fan_b"])
        return lf

    # -- tests ---------------------------------------------------------------------------------
    def test_plate_of_developable_from_planes(self):
        dev = self.cylinder()
        r, H, T = 10.0, 20.0, 1.0
        t0 = time.perf_counter()
        pl = plate.make_plate(dev, T, 0.5, "normal", doc=self.doc)
        dt = time.perf_counter() - t0
        self.assert_plate(pl, "quarter cylinder")
        annulus = {s: 0.25 * math.pi * abs((r + s * T) ** 2 - r * r) * H for s in (1.0, -1.0)}
        # "normal" lies outward or inward; the other side is the other annulus
        s0 = min(annulus, key=lambda s: abs(annulus[s] - pl.ClosedFormVolume))
        self.assertAlmostEqual(pl.ClosedFormVolume, annulus[s0], delta=1e-12 * annulus[s0])
        pl.Side = "reverse"
        self.assertEqual(_recompute(self.doc), [])
        self.assert_plate(pl, "quarter cylinder")
        self.assertAlmostEqual(pl.ClosedFormVolume, annulus[-s0], delta=1e-12 * annulus[-s0])
        pl.Thickness = 2.5
        self.assertEqual(_recompute(self.doc), [])
        self.assert_plate(pl, "quarter cylinder")
        exact = 0.25 * math.pi * abs((r - s0 * 2.5) ** 2 - r * r) * H
        self.assertAlmostEqual(pl.ClosedFormVolume, exact, delta=1e-12 * exact)
        self.assertLess(abs(pl.Volume / exact - 1.0), VOLUME_RTOL)
        print(f"quarter cylinder plate: built in {dt * 1e3:.0f} ms (feature + recompute)")
        # plate_partner on our plate: the design face (radius 10) is the larger one when the material
        # lies inward, so the geometric rule (inside = the smaller face) takes the offset face; the
        # plate's own inside face as hint gives the design face (what the Flat pattern passes)
        inward = pl.Side if pl.ClosedFormVolume < 0.25 * math.pi * ((r + 2.5) ** 2 - r * r) * H - 1e-6 else None
        faces = dict(zip(pl.FaceNames, pl.Shape.Faces))
        if inward is not None:
            plain = flat_pattern.plate_partner(pl.Shape, faces["inside"])
            self.assertTrue(plain[0].isSame(faces["outside"]))
        hinted = flat_pattern.plate_partner(pl.Shape, faces["outside"], inside=faces["inside"])
        self.assertTrue(hinted[0].isSame(faces["inside"]))
        # measured between the fitted faces (each within 3e-7 T of the exact one): 1e-6 relative;
        # the Flat pattern then uses the plate's exact Thickness
        self.assertAlmostEqual(hinted[1], 2.5, delta=1e-6 * 2.5)
        self.assertEqual(hinted[2], "reverse")  # a solid's face points away from the material
        # the source changes (γ): the plate follows
        dev.Gamma = -0.5
        self.assertEqual(_recompute(self.doc), [])
        self.assert_plate(pl, "quarter cylinder at gamma -0.5")
        # the source is moved by its Placement: the plate moves with it (same volume)
        box0, volume = pl.Shape.BoundBox, pl.Volume
        dev.Placement = App.Placement(App.Vector(100, 0, 0), App.Rotation(App.Vector(0, 0, 1), 30))
        self.assertEqual(_recompute(self.doc), [])
        self.assertTrue(pl.Shape.isValid())
        self.assertAlmostEqual(pl.Volume, volume, delta=1e-9 * volume)
        self.assertAlmostEqual(pl.Shape.Volume, pl.ShapeVolume, delta=1e-9 * volume)
        moved = dev.Shape.Faces[0]
        inside = pl.Proxy.inside_face(pl)
        far = max(Part.Vertex(moved.valueAt(*p)).distToShape(inside)[0] for p in ((0.1, 0.2), (0.5, 0.5), (0.9, 0.7)))
        self.assertLess(far, 1e-6 * box0.DiagonalLength)
        self.assertGreater(pl.Shape.BoundBox.XMin, box0.XMin + 50)
        # a joined developable as Source (its core surface lives in Previous's frame)
        from freecad.ght_workbench import joined_developable

        dev.Placement, dev.Gamma = App.Placement(), -1.0
        # G2 on to the plane x = -10 (smallest bending radius 8.08; the default free planes bend
        # to 0.016 near u = 0.9, where the plate fit gives up: see the report)
        jd = joined_developable.make_joined_developable(dev, "G2", [(-10.0, -1.0, 0.0, 0.0)], doc=self.doc)
        self.assertFalse(_base.failed(jd), jd.getStatusString())
        for side in ("normal", "reverse"):
            pj = plate.make_plate(jd, 0.5, 0.5, side, doc=self.doc, name=f"PlateJoined_{side}")
            self.assert_plate(pj, "joined developable")

    def test_plate_of_loft_with_fans_and_its_flat_pattern(self):
        from ght_cad import unroll
        from ght_cad.sheetmetal.sheet import Sheet

        lf = self.loft()
        T, K = 4.0, 0.42
        t0 = time.perf_counter()
        pl = plate.make_plate(lf, T, K, "normal", doc=self.doc)
        dt = time.perf_counter() - t0
        self.assert_plate(pl, "hull loft with fans")
        # OCCT's default rule on the unsplit C0 faces (documented, not asserted beyond "it is off")
        shape_err = pl.ShapeVolume / pl.ClosedFormVolume - 1.0
        print(f"hull loft plate: built in {dt * 1e3:.0f} ms; Shape.Volume off by {shape_err:.3g} (default rule across C0 knots)")
        surf = lf.Proxy.surface(lf)
        ref = unroll(surf, sheet=Sheet(T, K, "normal"), rulings=4, samples=65)
        ref_edges = sorted(e["flat"] for e in ref.sheet["edges"])
        # the whole plate as Source, then its inside and its outside face: the same neutral pattern
        cases = [("", "whole"), (pl.InsideFace, "inside"), (f"Face{pl.FaceNames.index('outside') + 1}", "outside")]
        for sub, what in cases:
            fp = flat_pattern.make_flat_pattern(pl, sub, 4, doc=self.doc, name=f"FP_{what}")
            # returned up to date and laid beside its source (make_flat_pattern's Placement)
            self.assertNotIn("Touched", fp.State, what)
            self.assertGreater(fp.Shape.BoundBox.XMin, pl.Shape.BoundBox.XMax, what)
            self.assertEqual(_recompute(self.doc), [])
            self.assertEqual(fp.ThicknessUsed, T)  # the plate's own (plate_partner's measure agrees to 1e-6)
            self.assertEqual(len(fp.Shape.Faces), 1, what)  # one panel, fans included
            self.assertLess(abs(fp.AreaFlat / ref.area - 1.0), 1e-9, what)
            pat = fp.Proxy.pattern(fp)
            # the side is relative to the unrolled face's normal (a solid's faces point outwards, so
            # the material lies "reverse" of the inside face); the neutral surface is the same: the
            # area check above (K = 0.42, the other side's area differs by about 2e-3) says so
            self.assertAlmostEqual(pat.sheet["thickness"], T, delta=1e-9 * T)
            got = sorted(e["flat"] for e in pat.sheet["edges"])
            self.assertEqual(len(got), len(ref_edges))
            err = max(abs(g / e - 1.0) for g, e in zip(got, ref_edges) if e > 0)
            self.assertLess(err, 1e-9, what)
            print(f"flat pattern of the plate ({what}): area {fp.AreaFlat / ref.area - 1:.2g}, edges {err:.2g} relative to the core's")
        # the material on the concave side of a fan's apex is refused (the core's message); the flat
        # patterns on the plate wait (they print nothing: exactly the plate's line is shown). The
        # outside face's pattern, checked above, takes the same path as the inside face's and is
        # removed first, so the recompute below does not unroll it again
        self.doc.removeObject("FP_outside")
        pl.Side = "reverse"
        self.assert_refused_as(self.doc, pl, lambda: pl.Proxy.compute(pl),
                               r"^thickness=4.0 \(side='reverse'\) is not allowed on DevelopableLoft: the ruling at u=0 ends in an apex")
        # back to the good side with another KFactor: the plate and its patterns recompute clean, and
        # the plate's KFactor is the one the patterns use (of the whole plate and of its inside face)
        pl.Side, pl.KFactor = "normal", 0.3
        fps = [self.doc.getObject(f"FP_{what}") for what in ("whole", "inside")]
        self.assert_recompute_clean(self.doc, pl, *fps)
        self.assertEqual(_recompute(self.doc), [])
        ref3 = unroll(surf, sheet=Sheet(T, 0.3, "normal"), rulings=4, samples=65)
        for fp in fps:
            self.assertLess(abs(fp.AreaFlat / ref3.area - 1.0), 1e-9, fp.Label)
        self.assertGreater(abs(ref3.area / ref.area - 1.0), 1e-6)  # K matters: the check above can fail
        # STEP of the plate (read back with OCP by the pytest driver)
        step = os.path.join(OUT, "fc_plate_loft.step")
        export.export_step([pl], step)
        back = export.read_step(step)
        self.assertEqual(len(back.Solids), 1)
        self.assertTrue(back.Solids[0].isValid())
        self.assertLess(abs(back.Solids[0].Volume / pl.ShapeVolume - 1.0), 1e-9)
        with open(os.path.join(OUT, "fc_plate.json"), "w") as fh:
            json.dump({"closed_form": pl.ClosedFormVolume, "volume": pl.Volume, "shape_volume": pl.ShapeVolume, "T": T}, fh)

    def test_plate_of_pointed_loft(self):
        """A bow where the chine meets the sheer (examples/design_bow_plate.toml): the zero-length
        end ruling has no end wall, so the plate has five faces, one of them per rail wall meeting
        along P .. P + T n."""
        a = ght_curve.make_ght_curve(BOW_CHINE, doc=self.doc, name="BowChine")
        b = ght_curve.make_ght_curve(BOW_SHEER, doc=self.doc, name="BowSheer")
        lf = developable_loft.make_developable_loft(a, b, doc=self.doc, name="BowLoft")
        self.assertEqual(_recompute(self.doc), [])
        pl = plate.make_plate(lf, 4.0, 0.44, "normal", doc=self.doc, name="BowPlate")
        self.assert_plate(pl, "pointed bow loft", ("inside", "outside", "wall_a", "wall_b", "end0"))

    def test_plate_of_spine_developable(self):
        c = ght_curve.make_ght_curve([(0, 0, 0), (10, 0, 5), (20, 10, 5), (25, 20, 0)], doc=self.doc, name="Spine curve")
        sp = spine_developable.make_spine_developable(c, "Spine", 2.0, 10.0, doc=self.doc)
        self.assertFalse(_base.failed(sp), sp.getStatusString())
        pl = plate.make_plate(sp, 0.2, 0.5, "normal", doc=self.doc)
        if _base.failed(pl):  # the material on the concave side: the other side must work
            pl.Side = "reverse"
            self.assertEqual(_recompute(self.doc), [])
        self.assert_plate(pl, "spine developable")
        v0 = pl.ClosedFormVolume
        pl.Thickness = 0.1
        self.assertEqual(_recompute(self.doc), [])
        self.assert_plate(pl, "spine developable")
        self.assertLess(abs(pl.ClosedFormVolume / v0 - 0.5), 0.01)  # V = T A + O(T²): about half
        c.Mu = 0.5  # the curve changes: plate follows
        self.assertEqual(_recompute(self.doc), [])
        self.assert_plate(pl, "spine developable, curve mu 0.5")
        # geodesic strip with the curve in the middle
        sp.Kind, sp.V0, sp.V1 = "Geodesic", -3.0, 3.0
        self.assertEqual(_recompute(self.doc), [])
        self.assert_plate(pl, "geodesic developable")

    def test_refusals(self):
        from ght_cad.sheetmetal.sheet import Sheet, check_offset

        dev = self.cylinder()
        pl = plate.make_plate(dev, 1.0, 0.5, "normal", doc=self.doc)
        self.assertFalse(_base.failed(pl))
        volume = pl.Volume
        surf = dev.Proxy.surface(dev)
        # too thick: the material reaches the axis of the cylinder (r = 10) on one side
        concave = next(s for s in ("normal", "reverse") if _raises(lambda s=s: check_offset(surf, Sheet(12.0, 0.5, s), "Cyl")))
        pl.Thickness, pl.Side = 12.0, concave
        msg = self.assert_refused_as(self.doc, pl, lambda: pl.Proxy.compute(pl), r"thickness=12.0 .*centre of curvature of the ruling at u=.*bending radius 10\b")
        self.assertTrue(msg.startswith(f"thickness=12.0 (side='{concave}') is not allowed on Cyl: the material reaches the centre of curvature"), msg)
        # K*T beyond the radius on the convex side (the check the flat pattern needs)
        pl.Side = "normal" if concave == "reverse" else "reverse"
        pl.Thickness, pl.KFactor = 30.0, 0.5
        self.assert_refused_as(self.doc, pl, lambda: pl.Proxy.compute(pl), r"neutral offset \|K\*T\|=15 reaches the bending radius 10 of the ruling")
        pl.Thickness, pl.KFactor = 0.0, 0.5
        self.assertEqual(self.assert_refused_as(self.doc, pl, lambda: pl.Proxy.compute(pl), "Thickness"),
                         "Plate.Thickness=0.0 mm is not allowed; a plate needs a thickness > 0")
        pl.Thickness, pl.KFactor = 1.0, 1.5
        self.assertEqual(self.assert_refused_as(self.doc, pl, lambda: pl.Proxy.compute(pl), "KFactor"),
                         "Plate.KFactor=1.5 is not allowed; the ANSI K-factor lies in [0, 1] (DIN k = 2K)")
        pl.KFactor = 0.5
        box = self.doc.addObject("Part::Box", "Box")
        pl.Source = box
        self.assertEqual(self.assert_refused_as(self.doc, pl, lambda: pl.Proxy.compute(pl), "not a developable feature"),
                         "Plate.Source = Box is not a developable feature of this workbench; allowed: Developable from planes, "
                         "Joined developable, Developable loft, Spine/geodesic developable")
        pl.Source = None
        self.assertEqual(self.assert_refused_as(self.doc, pl, lambda: pl.Proxy.compute(pl), "no Source"),
                         "Plate: no Source linked; link a developable feature (from planes, joined, loft, spine/geodesic)")
        # a failed plate is not exported
        with self.assertRaisesRegex(Exception, "last recompute failed"):
            export.export_step([pl], os.path.join(OUT, "never.step"))
        # back to good input: the same solid again
        pl.Source, pl.Side = dev, "normal"
        self.assert_recompute_clean(self.doc, pl)
        self.assertAlmostEqual(pl.Volume, volume, delta=1e-12 * volume)
        # a failed Source: the plate refuses to build on it
        dev.BoundaryCoordinates = [1.0, 2.0, 3.0]
        dev.BoundaryPlanes = []
        _, text = console_output(self.doc.recompute)
        self.assertTrue(_base.failed(dev), text)
        self.assert_no_traceback(text)
        self.assertTrue(_base.failed_input(pl) is dev)

    def test_save_reopen(self):
        lf = self.loft()
        pl = plate.make_plate(lf, 4.0, 0.42, "normal", doc=self.doc)
        fp = flat_pattern.make_flat_pattern(pl, "", 4, doc=self.doc)
        name, fp_name, volume, area = pl.Name, fp.Name, pl.Volume, fp.AreaFlat
        doc2 = _reopen(self.doc)
        pl2, fp2 = doc2.getObject(name), doc2.getObject(fp_name)
        self.assertEqual(pl2.Proxy.Type, "GHT::Plate")
        self.assertEqual(pl2.getEditorMode("Volume"), ["ReadOnly"])
        self.assert_plate(pl2, "reopened hull plate")
        self.assertAlmostEqual(pl2.Volume, volume, delta=1e-12 * volume)
        self.assertAlmostEqual(fp2.AreaFlat, area, delta=1e-12 * area)
        pl2.Thickness = 3.0
        self.assertEqual(_recompute(doc2), [])
        self.assert_plate(pl2, "reopened hull plate, T 3")
        self.assertEqual(fp2.ThicknessUsed, 3.0)

    def test_no_cad_kernel_import(self):
        import sys

        self.assertFalse([m for m in sys.modules if m.split(".")[0] in ("OCP", "build123d", "cadquery")])


def _raises(fn) -> bool:
    try:
        fn()
    except Exception:  # noqa: BLE001
        return True
    return False


if __name__ == "__main__":
    unittest.main()
