"""Named STEP export inside FreeCAD (headless): every feature becomes a STEP PRODUCT named by its
Label (non-ASCII and quotes too), the geometry equals the old anonymous-compound export, the file
is in millimetres whatever the user's unit preference, and a failed export leaves an existing
file byte-identical and no temporary file behind.

Writes ``export_named.step`` and ``export_named.json`` (the labels) into ``$GHT_FC_OUT`` for the
pytest side, which reads the file independently with OCP's XCAF reader.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_export``
"""

from __future__ import annotations

import json
import os
import re
import tempfile
import unittest

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, composite_curve, developable, export, flat_pattern, ght_curve, joined_developable
from freecad.ght_workbench.tests.refusal import RefusalAssertions

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_export_")
REL = 1e-9


def step_products(path: str) -> list[str]:
    """Names of the PRODUCT entities of a STEP file, in file order (ISO 10303-21 '' unescaped)."""
    text = open(path, encoding="utf-8").read()
    return [m.group(1).replace("''", "'") for m in re.finditer(r"=\s*PRODUCT\s*\(\s*'((?:[^']|'')*)'", text)]


def _measures(shape: "Part.Shape") -> tuple:
    return (len(shape.Faces), len(shape.Edges), shape.Area, shape.Length, sum(s.Volume for s in shape.Solids))


class NamedStepExportTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("ExportDoc")
        d = self.doc
        self.curve = ght_curve.make_ght_curve([(0, 0, 0), (10, 20, 0), (30, 20, 5), (40, 0, 0)], mu=0.3, doc=d, name="Curve")
        a = ght_curve.make_ght_curve([(0, 0, 0), (10, 15, 0), (25, 15, 0), (30, 0, 0)], doc=d, name="SegA")
        b = ght_curve.make_ght_curve([(30, 0, 0), (35, -10, 0), (50, -10, 0), (60, 0, 0)], gamma=-0.5, doc=d, name="SegB")
        self.composite = composite_curve.make_composite_curve([a, b], "G1", doc=d)
        self.dev = developable.make_developable(gamma=-1.0, doc=d)
        self.joined = joined_developable.make_joined_developable(self.dev, "G2", fuse=True, doc=d)
        self.flat = flat_pattern.make_flat_pattern(self.dev, bend_lines=4, doc=d)
        self.box = d.addObject("Part::Box", "Box")  # a solid, so volumes are compared too
        self.box.Placement.Base = App.Vector(100, 0, 0)
        # a moved and turned feature: XCAF writes its placement as the product's location
        self.curve.Placement = App.Placement(App.Vector(3, -40, 12), App.Rotation(App.Vector(1, 1, 0), 35))
        self.dev.Label = "Platte Ä"
        self.flat.Label = "Zuschnitt \"1\" 'A'"
        self.joined.Label = "Naht Ø-Blech"
        d.recompute()
        self.objects = [self.curve, self.composite, self.dev, self.joined, self.flat, self.box]
        bad = [o.Name for o in self.objects if _base.failed(o)]
        self.assertEqual(bad, [])

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def test_names_round_trip_and_geometry_equals_the_compound_export(self):
        path = os.path.join(OUT, "export_named.step")
        export.export_step(self.objects, path)
        labels = [o.Label for o in self.objects]
        names = step_products(path)
        # several objects: a root product named after the document, one product per object
        self.assertEqual(names[0], self.doc.Label)
        self.assertEqual(sorted(names[1:]), sorted(labels))
        with open(os.path.join(OUT, "export_named.json"), "w", encoding="utf-8") as fh:
            json.dump({"root": self.doc.Label, "labels": labels}, fh, ensure_ascii=False)
        # geometry equal to the old anonymous export (Part.makeCompound(...).exportStep)
        old = os.path.join(OUT, "export_compound.step")
        Part.makeCompound([o.Shape for o in self.objects]).exportStep(old)
        new_s, old_s = export.read_step(path), export.read_step(old)
        new_m, old_m = _measures(new_s), _measures(old_s)
        # the same place too: bounding boxes and per-edge/face centres of mass, in file order
        nb, ob = new_s.BoundBox, old_s.BoundBox
        for k in ("XMin", "XMax", "YMin", "YMax", "ZMin", "ZMax"):
            self.assertAlmostEqual(getattr(nb, k), getattr(ob, k), delta=1e-9 * 200, msg=k)
        for got, ref in ((new_s.Faces, old_s.Faces), (new_s.Edges, old_s.Edges)):
            gc = sorted((round(x.CenterOfMass.x, 6), round(x.CenterOfMass.y, 6), round(x.CenterOfMass.z, 6)) for x in got)
            rc = sorted((round(x.CenterOfMass.x, 6), round(x.CenterOfMass.y, 6), round(x.CenterOfMass.z, 6)) for x in ref)
            self.assertEqual(gc, rc)
        self.assertEqual(new_m[:2], old_m[:2])
        for got, ref in zip(new_m[2:], old_m[2:]):
            self.assertLessEqual(abs(got - ref), REL * max(1.0, abs(ref)), (new_m, old_m))
        self.assertGreater(new_m[4], 0.0)  # the box's volume is in there
        self.assertIn("SI_UNIT(.MILLI.,.METRE.)", open(path, encoding="utf-8").read())

    def test_each_feature_alone(self):
        for obj in self.objects:
            with self.subTest(obj.Label):
                path = os.path.join(OUT, f"export_{obj.Name}.step")
                export.export_step([obj], path)
                self.assertEqual(step_products(path), [obj.Label])  # one object: it is the root
                back = export.read_step(path)
                ref = obj.Shape
                self.assertEqual((len(back.Faces), len(back.Edges)), (len(ref.Faces), len(ref.Edges)))
                self.assertLessEqual(abs(back.Area - ref.Area), REL * max(1.0, ref.Area))
                self.assertLessEqual(abs(back.Length - ref.Length), REL * max(1.0, ref.Length))
        # the flat pattern keeps its planar face and loose bend-line edges
        back = export.read_step(os.path.join(OUT, f"export_{self.flat.Name}.step"))
        self.assertEqual(len(back.Faces), 1)
        self.assertEqual(len(back.Edges), len(self.flat.Shape.Edges))
        # the joined developable stays one shell with the shared edge
        back = export.read_step(os.path.join(OUT, f"export_{self.joined.Name}.step"))
        self.assertEqual(len(back.Shells), 1)
        self.assertEqual(len(back.Faces), 2)

    def test_millimetres_whatever_the_unit_preference(self):
        before = Part.exportUnits()["write.step.unit"]
        try:
            Part.exportUnits("INCH")
            path = os.path.join(OUT, "export_units.step")
            export.export_step([self.box], path)
            self.assertEqual(Part.exportUnits()["write.step.unit"], "INCH")  # the preference is restored
        finally:
            Part.exportUnits(before)
        text = open(path, encoding="utf-8").read()
        self.assertIn("SI_UNIT(.MILLI.,.METRE.)", text)
        self.assertNotIn("INCH", text.upper())
        self.assertAlmostEqual(export.read_step(path).Volume, 1000.0, delta=1e-9 * 1000)

    def test_failures_leave_the_existing_file_untouched(self):
        folder = tempfile.mkdtemp(prefix="fail_", dir=OUT)  # fresh: the listing must hold only our files
        path = os.path.join(folder, "part.step")
        export.export_step([self.box], path)
        original = open(path, "rb").read()

        def listing():
            return sorted(os.listdir(folder))

        # 1. the writer fails half-way (a partial temporary file exists)
        def broken(objs, name):
            with open(name, "w") as fh:
                fh.write("ISO-10303-21;\nHEADER;\n")
            raise RuntimeError("disk full (simulated)")

        saved = export._step_writer
        try:
            export._step_writer = lambda: broken
            with self.assertRaisesRegex(RuntimeError, "simulated"):
                export.export_step([self.curve], path)
            self.assertEqual(open(path, "rb").read(), original)
            self.assertEqual(listing(), ["part.step"])
            # 2. the writer silently writes nothing
            export._step_writer = lambda: (lambda objs, name: None)
            with self.assertRaisesRegex(OSError, re.escape(path)):
                export.export_step([self.curve], path)
            self.assertEqual(open(path, "rb").read(), original)
            self.assertEqual(listing(), ["part.step"])
        finally:
            export._step_writer = saved
        # 3. an object without shape: refused by name before anything is written
        empty = self.doc.addObject("Part::Feature", "Empty")
        empty.Label = "Leer Ü"
        with self.assertRaisesRegex(Exception, "Leer Ü has no shape to export"):
            export.export_step([self.box, empty], path)
        # 4. a feature whose last recompute failed keeps its old shape: refused, not exported stale
        self.curve.Tolerance = -1.0
        message = "Curve.Tolerance=-1.0 is not allowed; it must be a finite number > 0"
        self.assert_recompute_refused(self.doc, self.curve, message)
        with self.assertRaises(Exception) as ctx:
            export.export_step([self.box, self.curve], path)
        self.assertEqual(str(ctx.exception), f"Curve: its last recompute failed ({message}), so its shape is stale; fix it or leave "
                                             "it out of the export")
        self.curve.Tolerance = 1e-6
        self.assert_recompute_clean(self.doc, self.curve)
        # 5. nothing selected
        with self.assertRaisesRegex(Exception, "nothing to export"):
            export.export_step([], path)
        self.assertEqual(open(path, "rb").read(), original)
        self.assertEqual(listing(), ["part.step"])
        # a .stp target works too (the temporary name ends in .step)
        stp = os.path.join(folder, "part.stp")
        export.export_step([self.box], stp)
        self.assertEqual(step_products(stp), ["Box"])
        self.assertEqual(listing(), ["part.step", "part.stp"])

    def test_a_file_another_process_writes_is_refused(self):
        """Two writers of one file: the second export is refused naming the file and the holder's
        pid (the lock of :mod:`ght_cad.core.outdir`, which a ``ght-cad`` process takes too), the file
        stays as it was; once the lock is gone the export works and leaves no lock file."""
        import subprocess
        import sys

        from ght_cad.core.outdir import FolderBusy, lock_path_for

        folder = tempfile.mkdtemp(prefix="busy_", dir=OUT)
        paths = {ext: os.path.join(folder, "part" + ext) for ext in (".step", ".dxf", ".svg")}
        export.export_step([self.box], paths[".step"])
        original = open(paths[".step"], "rb").read()
        code = ("import sys, time\nfrom ght_cad.core.outdir import lock_target\n"
                "locks = [lock_target(p) for p in sys.argv[1:]]\nprint('held', flush=True)\ntime.sleep(60)\n")
        env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
        # FreeCAD's own Python interpreter (sys.executable is freecadcmd there)
        exe = sys.executable if os.path.basename(sys.executable).startswith("python") else "/usr/bin/python3"
        holder = subprocess.Popen([exe, "-c", code, *paths.values()], stdout=subprocess.PIPE, env=env, text=True)
        try:
            self.assertEqual(holder.stdout.readline().strip(), "held")
            calls = ((export.export_step, [self.box], ".step"), (export.export_flat_pattern_dxf, self.flat, ".dxf"),
                     (export.export_flat_pattern_svg, self.flat, ".svg"))
            for fn, arg, ext in calls:
                with self.subTest(ext):
                    with self.assertRaises(FolderBusy) as cm:
                        fn(arg, paths[ext])
                    self.assertIn(paths[ext], str(cm.exception))
                    self.assertIn(f"pid {holder.pid}", str(cm.exception))
        finally:
            holder.kill()
            holder.wait()
        self.assertEqual(open(paths[".step"], "rb").read(), original)
        self.assertEqual(sorted(os.listdir(folder)), sorted(["part.step"] + [os.path.basename(str(lock_path_for(p))) for p in paths.values()]))
        for fn, arg, ext in calls:  # the killed holder's locks are gone with it
            fn(arg, paths[ext])
        self.assertEqual(sorted(os.listdir(folder)), ["part.dxf", "part.step", "part.svg"])

    def test_stale_inputs_are_refused(self):
        """A shape that does not match its inputs is never written: pending changes (Touched), or an
        input whose recompute failed (FreeCAD then skips the dependants, which keep their old shape)."""
        from freecad.ght_workbench import export as ex

        step = os.path.join(OUT, "stale.step")
        dxf = os.path.join(OUT, "stale.dxf")
        ex.export_step([self.flat], step)
        ex.export_flat_pattern_dxf(self.flat, dxf)
        originals = [open(f, "rb").read() for f in (step, dxf)]
        self.dev.Gamma = 0.5  # changed, not yet recomputed
        with self.assertRaisesRegex(Exception, "Platte Ä: it has changes not yet recomputed"):
            ex.export_step([self.dev], step)
        self.dev.Tolerance = -1.0
        message = "Platte Ä.Tolerance=-1.0 is not allowed; it must be a finite number >= 0 (0: 1e-7 of the surface size)"
        self.assert_recompute_refused(self.doc, self.dev, message)
        self.assertFalse(_base.failed(self.flat))  # skipped: the flat pattern keeps the pattern of γ = -1
        self.assertIs(_base.failed_input(self.flat), self.dev)
        stale = f"its input Platte Ä failed to recompute ({message}), so its shape is stale"
        for fn, path in ((ex.export_step, step), (ex.export_flat_pattern_dxf, dxf), (ex.export_flat_pattern_svg, dxf)):
            with self.subTest(fn.__name__):
                with self.assertRaisesRegex(Exception, re.escape(stale)):
                    fn([self.flat] if fn is ex.export_step else self.flat, path)
        self.assertEqual([open(f, "rb").read() for f in (step, dxf)], originals)
        self.dev.Tolerance = 0.0
        self.doc.recompute()
        ex.export_step([self.flat], step)  # fixed: exported again, the new pattern
        self.assertNotEqual(open(step, "rb").read(), originals[0])


if __name__ == "__main__":
    unittest.main()
