"""Joined developable feature inside FreeCAD (headless): G1/G2/G3 joins of enveloping developables.

Checks: the measured ``JointOrder`` equals the requested continuity (and not more), the Part face
normals of both strips agree along the shared edge of the sewn shell (< 1e-6 deg), the shell's
shared edge is one edge, recompute follows the previous strip, save/reopen, STEP round trip and
the flat pattern of the joined strip.

Run: ``PYTHONPATH=<repo>/freecad_workbench:<repo> freecadcmd -t freecad.ght_workbench.tests.fc_joined``
"""

from __future__ import annotations

import math
import os
import tempfile
import unittest

import numpy as np

import FreeCAD as App
import Part

from freecad.ght_workbench import _base, developable, export, flat_pattern, joined_developable
from freecad.ght_workbench.tests.refusal import RefusalAssertions

OUT = os.environ.get("GHT_FC_OUT") or tempfile.mkdtemp(prefix="ght_fc_joined_")
NORMAL_TOL_DEG = 1e-6


def _shared_edge_normal_angle(shell: "Part.Shape", n: int = 11) -> tuple[float, float]:
    """(max angle (deg) between the two faces' normals, max point distance) along the one shared edge.

    The shared edge is found topologically (an edge of both faces); each sample point on it is
    projected into both faces' surfaces (``Surface.parameter``) and ``Face.normalAt`` compared.
    """
    f1, f2 = shell.Faces[-2], shell.Faces[-1]
    shared = [e for e in f2.Edges if any(e.isSame(g) for g in f1.Edges)]
    if len(shared) != 1:
        raise AssertionError(f"{len(shared)} shared edges between the last two faces (need exactly 1)")
    edge = shared[0]
    worst, gap = 0.0, 0.0
    for p in edge.discretize(n):
        normals = []
        for f in (f1, f2):
            u, v = f.Surface.parameter(p)
            gap = max(gap, f.valueAt(u, v).distanceToPoint(p))
            normals.append(f.normalAt(u, v))
        a, b = normals
        # atan2(|a x b|, a·b): accurate for tiny angles too (acos is not)
        worst = max(worst, math.degrees(math.atan2(a.cross(b).Length, a.dot(b))))
    return worst, gap


_bad = _base.failed  # the object's last recompute failed (FreeCAD state Invalid)


def _samples(face: "Part.Face", n: int = 9) -> np.ndarray:
    """Points of the face on an n x n grid of its parameter range."""
    u0, u1, v0, v1 = face.ParameterRange
    return np.array([[p.x, p.y, p.z] for p in (face.valueAt(u, v) for u in np.linspace(u0, u1, n) for v in np.linspace(v0, v1, n))])


def _poles(face: "Part.Face") -> np.ndarray:
    return np.array([[[p.x, p.y, p.z] for p in row] for row in face.Surface.getPoles()])


class JoinedDevelopableTest(RefusalAssertions, unittest.TestCase):
    def setUp(self):
        self.doc = App.newDocument("joined")
        # exact quarter cylinder r = 10, H = 20 (γ = -1): ends at the plane y = 10
        self.first = developable.make_developable(gamma=-1.0, doc=self.doc)

    def tearDown(self):
        for name in list(App.listDocuments()):
            App.closeDocument(name)

    def test_g1_g2_g3_measured_order_and_normals(self):
        for r, cont in enumerate(("G1", "G2", "G3"), 1):
            with self.subTest(cont):
                j = joined_developable.make_joined_developable(self.first, cont, fuse=True, doc=self.doc)
                self.assertFalse(_bad(j), j.State)
                self.assertEqual(j.JointOrder, r)
                # exactly r: the next contact condition fails clearly (not a lucky higher order)
                if r < 3:
                    self.assertGreater(j.JointResiduals[r + 1], 1e-6)
                self.assertLess(max(j.JointResiduals[: r + 1]), 1e-9)
                self.assertEqual(j.Degree, r + len(joined_developable.DEFAULT_FREE_PLANES))
                self.assertLess(float(j.ThetaMax), 1e-9)
                shape = j.Shape
                self.assertTrue(shape.isValid())
                self.assertEqual(shape.ShapeType, "Shell")
                self.assertEqual(len(shape.Faces), 2)
                self.assertEqual(len(shape.Edges), 7)  # 4 + 4 edges, the joint ruling shared
                angle, gap = _shared_edge_normal_angle(shape)
                self.assertLess(angle, NORMAL_TOL_DEG, f"{cont}: normals differ by {angle:.3g} deg")
                self.assertLess(gap, 1e-7)
                print(f"{cont}: JointOrder={j.JointOrder} residuals={list(j.JointResiduals)} normal angle={angle:.3g} deg")
                # without Fuse: the single new face; its start ruling is the first strip's end ruling
                j.Fuse = False
                self.doc.recompute()
                self.assertEqual(len(j.Shape.Faces), 1)
                P, Q = _poles(j.Shape.Faces[0]), _poles(self.first.Shape.Faces[0])
                self.assertLess(float(np.max(np.abs(P[0] - Q[-1]))), 1e-9)

    def test_cone_joints_generic_normals(self):
        """Conical strips (all planes through the apex (0, 0, -20)), γ = -0.5, tilted normals."""

        def plane(phi_deg: float, w: float = 1.0) -> list:
            n = np.array([math.cos(math.radians(phi_deg)), math.sin(math.radians(phi_deg)), -0.3])
            return list(w * np.array([20.0 * n[2], *n]))  # u0 = -n·apex

        first = developable.make_developable([plane(0), plane(45, 1.2), plane(90)], mu=0.1, gamma=-0.5, doc=self.doc)
        for r, cont in enumerate(("G1", "G2", "G3"), 1):
            with self.subTest(cont):
                j = joined_developable.make_joined_developable(first, cont, [plane(150), plane(180)], nu=0.2, fuse=True, doc=self.doc)
                self.assertFalse(_bad(j), j.State)
                self.assertEqual(j.JointOrder, r)
                self.assertTrue(j.Shape.isValid())
                self.assertEqual(len(j.Shape.Edges), 7)
                angle, gap = _shared_edge_normal_angle(j.Shape)
                self.assertLess(angle, NORMAL_TOL_DEG, f"{cont}: normals differ by {angle:.3g} deg")
                self.assertLess(gap, 1e-7)
                # the joint normal is tilted (not a trivially exact axis direction)
                f = j.Shape.Faces[-1]
                u0, _, v0, _ = f.ParameterRange
                self.assertGreater(abs(f.normalAt(u0, v0).z), 0.1)
                print(f"cone {cont}: JointOrder={j.JointOrder} normal angle={angle:.3g} deg gap={gap:.3g}")

    def test_previous_change_recomputes_and_keeps_order(self):
        j = joined_developable.make_joined_developable(self.first, "G3", fuse=True, doc=self.doc)
        before = _samples(j.Shape.Faces[-1])
        self.first.Mu = 0.5
        self.first.Nu = -0.3
        self.doc.recompute()
        self.assertFalse(_bad(j), j.State)
        self.assertEqual(j.JointOrder, 3)
        after = _samples(j.Shape.Faces[-1])
        self.assertGreater(float(np.max(np.abs(after - before))), 1e-2)
        self.assertTrue(j.Shape.isValid())
        angle, _ = _shared_edge_normal_angle(j.Shape)
        self.assertLess(angle, NORMAL_TOL_DEG)
        # a chain: a joined developable after a joined developable; the shell holds all three strips
        j2 = joined_developable.make_joined_developable(j, "G1", [(-30.0, -1.0, -1.0, 0.0), (-12.0, 0.0, -1.0, 0.0)], fuse=True, doc=self.doc)
        self.assertEqual(j2.JointOrder, 1)
        self.assertEqual(len(j2.Shape.Faces), 3)
        self.assertEqual(len(j2.Shape.Edges), 10)
        self.assertTrue(j2.Shape.isValid())
        angle2, _ = _shared_edge_normal_angle(j2.Shape)
        self.assertLess(angle2, NORMAL_TOL_DEG)
        # own shape parameters and G parameters change the new strip but not the measured order
        j.Mu, j.Beta2 = 0.4, 0.3
        self.doc.recompute()
        self.assertEqual((j.JointOrder, j2.JointOrder), (3, 1))
        self.assertGreater(float(np.max(np.abs(_samples(j.Shape.Faces[-1]) - after))), 1e-2)
        self.assertEqual(j.Mu, 0.4)
        j.Mu = 3.0  # App::PropertyFloatConstraint clamps to [-1, 1]
        self.assertEqual(j.Mu, 1.0)

    def test_parameter_box(self):
        """24 seeded samples of the box |μ|, |ν| <= 0.5 (both strips), γ ∈ [-1, 1], k ∈ [0.75, 1.25],
        |β2|, |β3| <= 0.2, G1/G2/G3 in turn: measured order = requested, normals agree, valid shell."""
        rng = np.random.default_rng(20261122)
        j = joined_developable.make_joined_developable(self.first, "G1", fuse=True, doc=self.doc)
        worst = 0.0
        for i in range(24):
            fm, fn, m, nu = rng.uniform(-0.5, 0.5, 4)
            g, k = rng.uniform(-1.0, 1.0), rng.uniform(0.75, 1.25)
            b2, b3 = rng.uniform(-0.2, 0.2, 2)
            r = 1 + i % 3
            self.first.Mu, self.first.Nu = float(fm), float(fn)
            j.Continuity = f"G{r}"
            j.Mu, j.Nu, j.Gamma, j.K, j.Beta2, j.Beta3 = float(m), float(nu), float(g), float(k), float(b2), float(b3)
            self.doc.recompute()
            case = f"sample {i}: mu0={fm:.3f} nu0={fn:.3f} mu={m:.3f} nu={nu:.3f} gamma={g:.3f} k={k:.3f} b2={b2:.3f} b3={b3:.3f} G{r}"
            self.assertFalse(_bad(j), case)
            self.assertEqual(j.JointOrder, r, case)
            self.assertTrue(j.Shape.isValid(), case)
            self.assertEqual(len(j.Shape.Edges), 7, case)
            angle, gap = _shared_edge_normal_angle(j.Shape, 5)
            self.assertLess(angle, NORMAL_TOL_DEG, case)
            self.assertLess(gap, 1e-7, case)
            worst = max(worst, angle)
        print(f"parameter box: 24 samples, worst joint normal angle {worst:.3g} deg")

    def test_follows_moved_previous(self):
        j = joined_developable.make_joined_developable(self.first, "G2", fuse=True, doc=self.doc)
        before = _samples(j.Shape.Faces[-1])
        pl = App.Placement(App.Vector(5, -3, 2), App.Rotation(App.Vector(1, 1, 0), 30))
        self.first.Placement = pl
        self.doc.recompute()
        self.assertFalse(_bad(j), j.State)
        self.assertTrue(j.Shape.isValid())
        self.assertEqual(len(j.Shape.Edges), 7)  # still sewn: the moved strips share their ruling
        moved = np.array([list(pl.multVec(App.Vector(*p))) for p in before])
        self.assertLess(float(np.max(np.abs(_samples(j.Shape.Faces[-1]) - moved))), 1e-9)
        angle, _ = _shared_edge_normal_angle(j.Shape)
        self.assertLess(angle, NORMAL_TOL_DEG)
        # a second joined strip follows the chain of placements
        j2 = joined_developable.make_joined_developable(j, "G1", [(-30.0, -1.0, -1.0, 0.0), (-12.0, 0.0, -1.0, 0.0)], fuse=True, doc=self.doc)
        self.assertEqual(len(j2.Shape.Edges), 10)
        self.assertTrue(j2.Shape.isValid())

    def test_save_reopen_step_and_flat_pattern(self):
        self.first.Mu = 0.2
        j = joined_developable.make_joined_developable(self.first, "G2", fuse=True, doc=self.doc)
        area, name, order = j.Shape.Area, j.Name, j.JointOrder
        path = os.path.join(OUT, "joined.FCStd")
        self.doc.saveAs(path)
        App.closeDocument(self.doc.Name)
        doc2 = App.openDocument(path)
        for o in doc2.Objects:
            o.touch()
        doc2.recompute()
        self.assertEqual([o.Name for o in doc2.Objects if _bad(o)], [])
        j2 = doc2.getObject(name)
        self.assertEqual(j2.JointOrder, order)
        self.assertAlmostEqual(j2.Shape.Area, area, delta=1e-9 * area)
        self.assertEqual(j2.Continuity, "G2")
        j2.Gamma = 2.0  # the [-1, 1] constraint survives the reload
        self.assertEqual(j2.Gamma, 1.0)
        j2.Gamma = -1.0
        doc2.recompute()
        self.assertEqual(j2.JointOrder, 2)
        # STEP round trip keeps the shell topology (shared edge) and the area
        step = os.path.join(OUT, "joined.step")
        export.export_step([j2], step)
        back = export.read_step(step)
        self.assertEqual(len(back.Faces), 2)
        self.assertEqual(len(back.Edges), 7)
        self.assertAlmostEqual(back.Area, j2.Shape.Area, delta=1e-6 * area)
        self.assertTrue(back.isValid())
        # flat pattern of the joined strip: vertical rulings of length 20 -> a rectangle L x 20
        fp = flat_pattern.make_flat_pattern(j2, doc=doc2)
        self.assertFalse(_bad(fp), fp.State)
        self.assertTrue(fp.Shape.isValid())
        face = j2.Shape.Faces[-1]
        bottom = [e for e in face.Edges if abs(e.BoundBox.ZMax) < 1e-9 and e.Length > 1e-6][0]
        self.assertAlmostEqual(fp.AreaFlat, 20.0 * bottom.Length, delta=1e-6 * fp.AreaFlat)
        self.assertAlmostEqual(fp.AreaFlat, fp.Area3D, delta=1e-9 * fp.AreaFlat)
        # OCC's Shape.Area integrates B-spline faces with a fixed Gauss rule (~5e-5 relative here)
        self.assertAlmostEqual(fp.AreaFlat, face.Area, delta=2e-4 * face.Area)
        self.assertLess(fp.MaxRelativeError, 1e-6)
        print(f"flat pattern of the joined strip: AreaFlat={fp.AreaFlat:.9f} face area={face.Area:.9f} MaxRelativeError={fp.MaxRelativeError:.3g}")

    def test_normal_check_detects_a_kink(self):
        """The shared-edge normal check is not vacuous: two planar faces with a 10° kink."""
        a = Part.Face(Part.makePolygon([App.Vector(0, 0, 0), App.Vector(0, 0, 5), App.Vector(-4, 0, 5), App.Vector(-4, 0, 0), App.Vector(0, 0, 0)]))
        c, s_ = math.cos(math.radians(10)), math.sin(math.radians(10))
        b = Part.Face(Part.makePolygon([App.Vector(0, 0, 0), App.Vector(4 * c, 4 * s_, 0), App.Vector(4 * c, 4 * s_, 5), App.Vector(0, 0, 5), App.Vector(0, 0, 0)]))
        shell = Part.makeCompound([a, b])
        shell.sewShape(1e-7)
        angle, gap = _shared_edge_normal_angle(shell)
        self.assertAlmostEqual(min(angle, 180.0 - angle), 10.0, delta=1e-9)
        self.assertLess(gap, 1e-12)

    def test_no_cad_kernel_import(self):
        import sys

        self.assertFalse([m for m in sys.modules if m.split(".")[0] in ("OCP", "build123d", "cadquery")])

    def test_bad_input(self):
        with self.assertRaisesRegex(ValueError, "G0"):
            joined_developable.make_joined_developable(self.first, "G0", doc=self.doc)
        from ght_cad.core.errors import ShapeParameterError

        with self.assertRaisesRegex(ShapeParameterError, "nu"):
            joined_developable.make_joined_developable(self.first, "G1", nu=1.5, doc=self.doc)
        j = joined_developable.make_joined_developable(self.first, "G1", doc=self.doc)
        j.PlaneCoordinates = [1.0, 2.0, 3.0]
        self.assert_recompute_refused(self.doc, j, "PlaneCoordinates has 3 numbers; give 4 per free control plane (at least one plane)")
        # own boundary planes: the joint ruling segments differ, so Fuse cannot sew one shell
        j.PlaneCoordinates = [float(x) for x in np.ravel(joined_developable.DEFAULT_FREE_PLANES)]
        j.BoundaryCoordinates = [-2.0, 0.0, 0.0, 1.0, -15.0, 0.0, 0.0, 1.0]
        j.Fuse = True
        self.assert_recompute_refused(
            self.doc, j, "sewing with Previous did not give one shell in which the new face shares its start ruling edge; the strips do "
            "not share their joint ruling segment (own BoundaryCoordinates?) — set Fuse to False")
        j.Fuse = False  # the single face is fine and the (dual-curve) joint order is unchanged
        self.assert_recompute_clean(self.doc, j)
        self.assertEqual(j.JointOrder, 1)
        self.assertAlmostEqual(j.Shape.BoundBox.ZLength, 13.0, delta=1e-9)
        # a non-enveloping previous feature is refused with its name in the message
        plain = self.doc.addObject("Part::Feature", "Plain")
        plain.Shape = Part.makePlane(1, 1)
        j.PlaneCoordinates = [float(x) for x in np.ravel(joined_developable.DEFAULT_FREE_PLANES)]
        j.Previous = plain
        message = ("Previous=Plain is a Part::Feature; a developable join needs an enveloping developable (GHT 'Developable from "
                   "planes' or another 'Joined developable')")
        with self.assertRaises(ValueError) as ctx:
            j.Proxy.surface(j)
        self.assertEqual(str(ctx.exception), message)
        self.assert_recompute_refused(self.doc, j, message)


def gui_check() -> dict:
    """Inside the FreeCAD GUI (``GHT_JOINED_GUI=1 xvfb-run freecad fc_joined.py``): the workbench
    shows the command in its toolbar, the command joins a strip to the selected developable and
    opens its task panel. Returns the findings (also written to ``$GHT_FC_OUT/joined_gui.json``)."""
    import FreeCADGui as Gui

    res: dict = {}
    Gui.activateWorkbench("GHTWorkbench")
    res["registered"] = "GHT_JoinedDevelopable" in Gui.listCommands()
    items = Gui.activeWorkbench().getToolbarItems() if hasattr(Gui.activeWorkbench(), "getToolbarItems") else {}
    res["toolbar"] = [bar for bar, cmds in items.items() if "GHT_JoinedDevelopable" in cmds]
    pixmap = joined_developable.COMMAND.GetResources()["Pixmap"]
    res["pixmap"] = os.path.isfile(pixmap) and pixmap.endswith("GHT_JoinedDevelopable.svg")
    doc = App.newDocument("JoinedGui")
    dev = developable.make_developable(gamma=-1.0, doc=doc)
    before = {o.Name for o in doc.Objects}
    Gui.Selection.clearSelection()
    Gui.Selection.addSelection(dev)
    Gui.runCommand("GHT_JoinedDevelopable", 0)
    doc.recompute()
    new = [o for o in doc.Objects if o.Name not in before]
    res["created"] = [o.Proxy.Type for o in new if hasattr(o, "Proxy")]
    if new:
        j = new[0]
        res["joint_order"] = j.JointOrder
        res["faces"] = len(j.Shape.Faces)
        res["valid"] = j.Shape.isValid()
        res["panel_open"] = bool(Gui.Control.activeDialog())
        res["icon"] = os.path.isfile(j.ViewObject.Proxy.getIcon())
        if Gui.Control.activeDialog():
            Gui.Control.closeDialog()
    return res


def _gui_main() -> None:  # pragma: no cover - runs in the GUI process only
    import json
    import traceback

    try:
        res = gui_check()
    except Exception:
        res = {"error": traceback.format_exc()}
    with open(os.path.join(OUT, "joined_gui.json"), "w") as fh:
        json.dump(res, fh, indent=1, default=str)
    os._exit(0)


if App.GuiUp and os.environ.get("GHT_JOINED_GUI") == "1":
    from PySide2 import QtCore

    QtCore.QTimer.singleShot(200, _gui_main)
elif __name__ == "__main__":
    unittest.main()
