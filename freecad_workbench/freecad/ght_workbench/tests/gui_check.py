"""GUI check, run by the FreeCAD GUI binary under a virtual display (Xvfb):

    xvfb-run -a freecad gui_check.py        (with GHT_FC_OUT=<dir>)

The workbench must be installed in the user's Mod folder (the pytest side links it there). Once
the event loop runs, the script activates the workbench, checks every command is registered, runs
each one on a prepared document (selection set as a user would), exercises a task panel's live
preview, opens every feature's task panel by the double-click path (``ViewProvider.doubleClicked``
-> ``setEdit``), also of features whose links are unset, exports STEP/DXF/SVG, saves a screenshot
and writes ``gui_result.json``, then exits.

Errors are watched during the whole scripted session, not only the steps' return values:

* FreeCAD's **Report view** widget is read back after every step: every line its highlighter
  paints in the error colour (``Console.PrintError``, Python's stderr, the tracebacks FreeCAD
  prints when a Python callback such as ``setEdit`` raises) and every line that starts a Python
  traceback is collected;
* ``sys.excepthook`` (exceptions raised in Qt slots: a slider or button callback) and
  ``sys.stderr`` are hooked;
* the **Python console** widget is read for tracebacks.

A step may declare the error lines it provokes on purpose (``allow=`` regular expressions of the
whole line, e.g. the one-line recompute error of a feature given a negative tolerance); every other
line lands in ``RESULT["unexpected_errors"]``, and the pytest side fails on any. A refused input
is reported by the workbench as one line ``"<Label>: <message>"`` plus FreeCAD's "Recompute failed!"
line, never with a Python traceback: ``RESULT["traceback_lines"]`` holds every line of the whole
Report view that looks like part of a traceback (the pytest side wants none), and each step's
``"tracebacks"`` those of the step.
"""

import json
import os
import re
import sys
import time
import traceback

import FreeCAD as App
import FreeCADGui as Gui

try:
    from PySide2 import QtCore, QtWidgets
except ImportError:  # pragma: no cover
    from PySide import QtCore  # type: ignore
    from PySide import QtGui as QtWidgets  # type: ignore

OUT = os.environ.get("GHT_FC_OUT", "/tmp")
RESULT = {"steps": [], "errors": [], "unexpected_errors": [], "report_errors": []}
TRACEBACK_RE = re.compile(r"Traceback \(most recent call last\)|^\s*File \".*\", line \d+|\b\w*(Error|Exception)\b: ")


class ErrorWatch:
    """Collects error lines from the Report view, sys.excepthook, sys.stderr and the Python console."""

    def __init__(self):
        mw = Gui.getMainWindow()
        self.report = mw.findChild(QtWidgets.QTextEdit, "Report view")
        self.console = mw.findChild(QtWidgets.QPlainTextEdit, "Python console")
        if self.report is None:
            raise RuntimeError("FreeCAD's Report view widget was not found: the check cannot see errors")
        packed = App.ParamGet("User parameter:BaseApp/Preferences/OutputWindow").GetUnsigned("colorError", 0xFF000000)
        self.error_colour = "#{:02x}{:02x}{:02x}".format((packed >> 24) & 255, (packed >> 16) & 255, (packed >> 8) & 255)
        self.hooked = []  # (source, text)
        self._excepthook = sys.excepthook
        sys.excepthook = self._hook
        self._stderr = sys.stderr
        sys.stderr = _Tee(self._stderr, self.hooked)
        self.start = self.mark()

    def _hook(self, etype, value, tb):
        self.hooked.append(("excepthook", "".join(traceback.format_exception(etype, value, tb))))
        self._excepthook(etype, value, tb)

    def mark(self):
        QtWidgets.QApplication.processEvents()
        return (self.report.document().blockCount() - 1, self.console.document().blockCount() - 1 if self.console else 0,
                len(self.hooked))

    def _blocks(self, doc, first):
        b = doc.findBlockByNumber(max(first, 0))
        while b.isValid():
            yield b
            b = b.next()

    def since(self, mark):
        """Error lines that appeared after ``mark`` (a :meth:`mark` value), in order."""
        QtWidgets.QApplication.processEvents()
        lines = []
        for b in self._blocks(self.report.document(), mark[0]):
            text = b.text()
            if not text.strip():
                continue
            colours = {r.format.foreground().color().name() for r in b.layout().formats()}
            if self.error_colour in colours or TRACEBACK_RE.search(text):
                lines.append("report view: " + text)
        if self.console is not None:
            for b in self._blocks(self.console.document(), mark[1]):
                if TRACEBACK_RE.search(b.text()):
                    lines.append("python console: " + b.text())
        for source, text in self.hooked[mark[2]:]:
            lines.extend(f"{source}: {l}" for l in text.splitlines() if l.strip())
        return lines

    def report_text(self):
        return self.report.toPlainText()


class _Tee:
    """sys.stderr replacement that also records what is written (FreeCAD's stream stays in use)."""

    def __init__(self, stream, sink):
        self.stream, self.sink = stream, sink

    def write(self, text):
        if text.strip():
            self.sink.append(("stderr", text))
        return self.stream.write(text)

    def flush(self):
        return self.stream.flush()

    def __getattr__(self, name):
        return getattr(self.stream, name)


WATCH = None


def _entries(lines):
    """Group error lines into entries: a Python traceback (from its "Traceback" line through the
    indented frame lines to the exception line) is one entry, with that last line as its message;
    every other line is an entry of its own. Returns ``[(message, [lines])]``."""
    out, block = [], None
    for line in lines:
        body = line.split(": ", 1)[1] if ": " in line else line
        body = re.sub(r"^\d\d:\d\d:\d\d\s+", "", body)  # the Report view's time stamp
        if "Traceback (most recent call last)" in body:
            block = [line]
            continue
        if block is not None:
            block.append(line)
            if body[:1].isspace():
                continue
            out.append((body, block))
            block = None
            continue
        out.append((body, [line]))
    if block is not None:
        out.append((block[-1], block))
    return out


def step(name, fn, allow=()):
    """Run one step; record its value, its error lines, and those not matched by ``allow``.

    ``allow`` holds regular expressions (anchored: the whole message) of the error lines the step
    provokes on purpose; a traceback is allowed only if its exception line matches one (no
    pattern below matches the ``<class '...'>: `` prefix of such a line, so a recompute error
    reported with a traceback fails the check), and FreeCAD's "Recompute failed!" line only in a
    step with an allowed error.
    """
    mark = WATCH.mark()
    t0 = time.perf_counter()
    try:
        value = fn()
        entry = {"name": name, "ok": True, "value": value}
    except Exception:
        entry = {"name": name, "ok": False, "error": traceback.format_exc()}
    finally:
        if Gui.Control.activeDialog():
            Gui.Control.closeDialog()
    entry["seconds"] = round(time.perf_counter() - t0, 3)  # where the GUI check spends its time
    lines = WATCH.since(mark)
    entry["report_errors"] = lines
    entry["tracebacks"] = [l for l in lines if TRACEBACK_RE.search(l.split(": ", 1)[-1])]
    patterns = list(allow) + ([r"^Recompute failed! Please check report view\.$"] if allow else [])
    unexpected = [l for msg, block in _entries(lines) if not any(re.fullmatch(a, msg) for a in patterns) for l in block]
    entry["unexpected_errors"] = unexpected
    RESULT["unexpected_errors"].extend(f"{name}: {l}" for l in unexpected)
    RESULT["report_errors"].extend(f"{name}: {l}" for l in lines)
    RESULT["steps"].append(entry)
    return entry


def wait(ms):
    """Run the event loop for ``ms`` milliseconds (timers fire, widgets repaint)."""
    timer = QtCore.QElapsedTimer()
    timer.start()
    while timer.elapsed() < ms:
        QtWidgets.QApplication.processEvents(QtCore.QEventLoop.AllEvents, 50)


def new_objects(doc, before):
    return [o for o in doc.Objects if o.Name not in before]


def run_command(doc, name, select=()):
    before = {o.Name for o in doc.Objects}
    Gui.Selection.clearSelection()
    for obj in select:
        Gui.Selection.addSelection(obj)
    Gui.runCommand(name, 0)
    App.ActiveDocument.recompute()
    created = new_objects(doc, before)
    shapes_ok = all(o.Shape.isValid() for o in created if hasattr(o, "Shape") and not o.Shape.isNull())
    return created, shapes_ok


def main():
    global WATCH
    WATCH = ErrorWatch()
    from freecad.ght_workbench import _base

    RESULT["workbenches"] = "GHTWorkbench" in Gui.listWorkbenches()
    Gui.activateWorkbench("GHTWorkbench")
    RESULT["active_workbench"] = type(Gui.activeWorkbench()).__name__
    registered = set(Gui.listCommands())
    RESULT["commands"] = {name: name in registered for name in _base.COMMANDS}
    RESULT["toolbars"] = list(Gui.activeWorkbench().listToolbars())
    doc = App.newDocument("GuiCheck")
    ctx = {}

    def curve():
        created, ok = run_command(doc, "GHT_Curve")
        obj = [o for o in created if o.Proxy.Type == "GHT::Curve"][0]
        ctx["curve"] = obj
        panel = _base.ShapeParameterPanel.last
        dialog_open = bool(Gui.Control.activeDialog())
        length0 = obj.Shape.Length
        panel.spins["Mu"].setValue(0.75)  # live preview: the feature recomputes at once
        live_length = obj.Shape.Length
        panel.sliders["Gamma"].setValue(-1000)
        live_gamma = obj.Gamma
        # a bad value elsewhere: the live preview shows the feature's error in the panel
        obj.Tolerance = -1.0
        panel.spins["Nu"].setValue(0.25)
        error_shown = panel.status.text()
        obj.Tolerance = 1e-6
        panel.spins["Nu"].setValue(0.0)
        error_cleared = panel.status.text() == ""
        panel.reject()  # Cancel restores the values the feature had
        return {
            "created": len(created), "valid": ok, "dialog_open": dialog_open,
            "live_changed": abs(live_length - length0) > 1e-6, "slider_gamma": live_gamma,
            "restored": [obj.Mu, obj.Gamma], "length_restored": abs(obj.Shape.Length - length0) < 1e-9,
            "error_shown": error_shown, "error_cleared": error_cleared,
        }

    def composite():
        created, ok = run_command(doc, "GHT_CompositeCurve")
        comp = [o for o in created if o.Proxy.Type == "GHT::CompositeCurve"][0]
        return {"created": len(created), "valid": ok, "joints": list(comp.JointOrders)}

    # the one line the refused tolerance gives (the Label is the command's default name)
    step("GHT_Curve", curve, allow=[r"GHTCurve\d*\.Tolerance=-1\.0 is not allowed; it must be a finite number > 0"])

    def curve_from_vertices():
        import Part

        poly = doc.addObject("Part::Feature", "Polygon")
        poly.Shape = Part.makePolygon([App.Vector(0, -30, 0), App.Vector(8, -20, 6), App.Vector(20, -24, 6), App.Vector(28, -30, 0)])
        doc.recompute()
        before = {o.Name for o in doc.Objects}
        Gui.Selection.clearSelection()
        for i in range(1, 5):  # selection order = control point order
            Gui.Selection.addSelection(poly, f"Vertex{i}")
        Gui.runCommand("GHT_Curve", 0)
        doc.recompute()
        obj = new_objects(doc, before)[0]
        return {"degree": obj.Degree, "source": [s for _, subs in obj.Source for s in subs], "valid": obj.Shape.isValid(), "created": 1}

    step("GHT_Curve from vertices", curve_from_vertices)
    step("GHT_CompositeCurve", composite)

    def generic(name, select_key=None, kind=None, store=None):
        def run():
            sel = [ctx[select_key]] if select_key else []
            created, ok = run_command(doc, name, sel)
            if store:
                ctx[store] = [o for o in created if getattr(o, "Proxy", None) and o.Proxy.Type == kind][0]
            return {"created": len(created), "valid": ok}
        return run

    if "GHT_Developable" in _base.COMMANDS:
        step("GHT_Developable", generic("GHT_Developable", None, "GHT::Developable", "developable"))
    if "GHT_SpineDevelopable" in _base.COMMANDS:
        step("GHT_SpineDevelopable", generic("GHT_SpineDevelopable", "curve", "GHT::SpineDevelopable", "spine"))
    if "GHT_DevelopableLoft" in _base.COMMANDS:
        def loft():
            # two sketch edges selected as a user would, in their own document (the main check's
            # object count stays), then double-click: the panel shows the report; unset: a message
            import Part

            ldoc = App.newDocument("LoftCheck")
            sketches = []
            for name, r, z in (("RimA", 5.0, 0.0), ("RimB", 2.0, 6.0)):
                sk = ldoc.addObject("Sketcher::SketchObject", name)
                sk.Placement = App.Placement(App.Vector(0, 0, z), App.Rotation())
                sk.addGeometry(Part.Circle(App.Vector(0, 0, 0), App.Vector(0, 0, 1), r), False)
                sketches.append(sk)
            ldoc.recompute()
            try:
                Gui.Selection.clearSelection()
                for sk in sketches:  # the edges themselves, as a click in the 3-D view selects them
                    Gui.Selection.addSelection(sk, "Edge1")
                before = {o.Name for o in ldoc.Objects}
                Gui.runCommand("GHT_DevelopableLoft", 0)
                ldoc.recompute()
                created = new_objects(ldoc, before)
                ok = all(o.Shape.isValid() for o in created)
                lf = [o for o in created if o.Proxy.Type == "GHT::DevelopableLoft"][0]
                Gui.ActiveDocument.setEdit(lf.Name, 0)
                from freecad.ght_workbench.developable_loft import LoftPanel

                report = LoftPanel.last.message if Gui.Control.activeDialog() else ""
                Gui.Control.closeDialog()
                Gui.ActiveDocument.resetEdit()
                lf.RailB = None  # unset link: a message, not a traceback (the recompute is not run)
                Gui.ActiveDocument.setEdit(lf.Name, 0)
                unset = LoftPanel.last.message if Gui.Control.activeDialog() else ""
                return {"created": len(created), "valid": ok, "segments": list(lf.Segments), "faces": len(lf.Shape.Faces),
                        "report": report, "unset": unset, "icon": os.path.isfile(lf.ViewObject.Proxy.getIcon())}
            finally:
                if Gui.Control.activeDialog():
                    Gui.Control.closeDialog()
                App.closeDocument(ldoc.Name)
                App.setActiveDocument(doc.Name)
        step("GHT_DevelopableLoft", loft)
    if "GHT_DevelopableApproximation" in _base.COMMANDS:
        def approximation():
            # a face selected as a user would (the lateral face of a Part cone: one panel, seconds),
            # in its own document; the feature and its flat pattern child, then a double-click
            adoc = App.newDocument("ApproxCheck")
            cone = adoc.addObject("Part::Cone", "Cone")
            cone.Radius1, cone.Radius2, cone.Height = 50.0, 20.0, 80.0
            adoc.recompute()
            try:
                Gui.Selection.clearSelection()
                Gui.Selection.addSelection(cone, "Face1")
                before = {o.Name for o in adoc.Objects}
                Gui.runCommand("GHT_DevelopableApproximation", 0)
                adoc.recompute()
                created = new_objects(adoc, before)
                kinds = sorted(o.Proxy.Type for o in created)
                ap = [o for o in created if o.Proxy.Type == "GHT::DevelopableApproximation"][0]
                _base.ViewProviderBase.last_panel = None
                handled = ap.ViewObject.Proxy.doubleClicked(ap.ViewObject)  # what a double-click in the tree does
                QtWidgets.QApplication.processEvents()
                panel = _base.ViewProviderBase.last_panel
                info = {"handled": bool(handled), "dialog": bool(Gui.Control.activeDialog()),
                        "message": getattr(panel, "message", None)}
                if Gui.Control.activeDialog():
                    Gui.Control.closeDialog()
                Gui.ActiveDocument.resetEdit()
                return {"created": len(created), "kinds": kinds, "valid": all(o.Shape.isValid() for o in created), "panels": ap.PanelCount,
                        "touched": [o.Name for o in created if "Touched" in o.State], "failed": [o.Name for o in created if _base.failed(o)],
                        "children": [c.Proxy.Type for c in ap.ViewObject.Proxy.claimChildren()],
                        "icon": os.path.isfile(ap.ViewObject.Proxy.getIcon()), "panel": info}
            finally:
                if Gui.Control.activeDialog():
                    Gui.Control.closeDialog()
                App.closeDocument(adoc.Name)
                App.setActiveDocument(doc.Name)
        step("GHT_DevelopableApproximation", approximation)
    if "GHT_FlatPattern" in _base.COMMANDS and "developable" in ctx:
        step("GHT_FlatPattern", generic("GHT_FlatPattern", "developable", "GHT::FlatPattern", "flat"))
    if "GHT_Plate" in _base.COMMANDS and "developable" in ctx:
        def plate_step():
            out = generic("GHT_Plate", "developable", "GHT::Plate", "plate")()
            pl = ctx["plate"]
            out.update({"shape_type": pl.Shape.ShapeType, "faces": len(pl.Shape.Faces), "volume": pl.Volume,
                        "closed_form": pl.ClosedFormVolume, "volume_error": pl.VolumeError, "failed": _base.failed(pl)})
            return out
        step("GHT_Plate", plate_step)
    if "GHT_Optimization" in _base.COMMANDS and "developable" in ctx:
        step("GHT_Optimization", generic("GHT_Optimization", "developable", "GHT::Optimization", "optimization"))
    if "GHT_RunOptimization" in _base.COMMANDS and "optimization" in ctx:
        def run_opt():
            opt = ctx["optimization"]
            Gui.Selection.clearSelection()
            Gui.Selection.addSelection(opt)
            Gui.runCommand("GHT_RunOptimization", 0)
            return {"best": opt.BestValue, "initial": opt.InitialValue, "status": opt.Status}
        step("GHT_RunOptimization", run_opt)

        def cancel_opt():
            from PySide2 import QtWidgets

            opt = ctx["optimization"]
            target = opt.Targets[0]
            before = (target.Mu, target.Nu, target.Gamma)
            pressed = []

            tries = []

            def press_cancel():  # what a user's click on the dialog's Cancel button does
                for dlg in Gui.getMainWindow().findChildren(QtWidgets.QProgressDialog):
                    if dlg.isVisible():
                        dlg.cancel()
                        pressed.append(dlg.labelText())
                        return
                tries.append(1)
                if len(tries) < 10000:  # the dialog is not up yet: look again on the next event
                    QtCore.QTimer.singleShot(0, press_cancel)

            QtCore.QTimer.singleShot(0, press_cancel)
            opt.MaxIterations = 400
            Gui.Selection.clearSelection()
            Gui.Selection.addSelection(opt)
            Gui.runCommand("GHT_RunOptimization", 0)
            return {"pressed": pressed, "status": opt.Status, "unchanged": before == (target.Mu, target.Nu, target.Gamma)}

        step("cancel optimization", cancel_opt)

    from freecad.ght_workbench import export

    def exp_step():
        export.CommandExportSTEP.target = os.path.join(OUT, "gui_export.step")
        ctx["curve"].Label = "Kurve Ä"
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(ctx["curve"])
        # a user who switched off "export hidden objects": a selected hidden feature is exported anyway
        pref = App.ParamGet("User parameter:BaseApp/Preferences/Mod/Import")
        pref.SetBool("ExportHiddenObject", False)
        ctx["curve"].ViewObject.Visibility = False
        try:
            Gui.runCommand("GHT_ExportSTEP", 0)
        finally:
            ctx["curve"].ViewObject.Visibility = True
        hidden_pref_kept = pref.GetBool("ExportHiddenObject", True) is False
        pref.RemBool("ExportHiddenObject")
        # FreeCAD reads the names back (STEP import with "compound merge" off; its default on
        # Debian merges everything into one compound named after the file)
        import ImportGui

        step_pref = App.ParamGet("User parameter:BaseApp/Preferences/Mod/Import/hSTEP")
        merge = step_pref.GetBool("ReadShapeCompoundMode", True)
        step_pref.SetBool("ReadShapeCompoundMode", False)
        back = App.newDocument("StepBack")
        try:
            ImportGui.insert(export.CommandExportSTEP.target, back.Name)
            reimported = [o.Label for o in back.Objects]
        finally:
            step_pref.SetBool("ReadShapeCompoundMode", merge)
            App.closeDocument(back.Name)
            App.setActiveDocument(doc.Name)
        text = open(export.CommandExportSTEP.target, encoding="utf-8").read()
        import re

        # ImportGui.export writes the view colour (COLOUR_RGB) and the Label as the product name
        colours = [tuple(float(x) for x in m) for m in re.findall(r"COLOUR_RGB\s*\(\s*'[^']*'\s*,\s*([-\d.Ee+]+)\s*,\s*([-\d.Ee+]+)\s*,\s*([-\d.Ee+]+)", text)]
        line = tuple(ctx["curve"].ViewObject.LineColor[:3])
        return {
            "exists": os.path.getsize(export.CommandExportSTEP.target) > 0,
            "products": re.findall(r"=\s*PRODUCT\s*\(\s*'((?:[^']|'')*)'", text),
            "label": ctx["curve"].Label,
            "colours": colours,
            "line_colour": line,
            "hidden_pref_kept": hidden_pref_kept,
            "reimported": reimported,
            "line_colour_written": any(max(abs(a - b) for a, b in zip(c, line)) < 1e-3 for c in colours),
        }

    step("GHT_ExportSTEP", exp_step)
    for name, ext in (("GHT_ExportDXF", ".dxf"), ("GHT_ExportSVG", ".svg")):
        if "flat" in ctx:
            def exp_flat(name=name, ext=ext):
                cls = type(_base.COMMANDS[name])
                cls.target = os.path.join(OUT, "gui_flat" + ext)
                Gui.Selection.clearSelection()
                Gui.Selection.addSelection(ctx["flat"])
                Gui.runCommand(name, 0)
                return {"exists": os.path.getsize(cls.target) > 0}
            step(name, exp_flat)

    def open_by_double_click(obj, shot=None):
        """What a double-click in the tree does: ViewProvider.doubleClicked -> setEdit -> a panel
        (with ``shot``: the main window with the panel open is saved there)."""
        _base.ViewProviderBase.last_panel = None
        vobj = obj.ViewObject
        handled = vobj.Proxy.doubleClicked(vobj)
        QtWidgets.QApplication.processEvents()
        panel = _base.ViewProviderBase.last_panel
        info = {"handled": bool(handled), "dialog": bool(Gui.Control.activeDialog()),
                "panel": type(panel).__name__ if panel is not None else None,
                "title": panel.form.windowTitle() if panel is not None else None,
                "message": getattr(panel, "message", None)}
        if shot:
            mw = Gui.getMainWindow()
            mw.resize(1280, 860)
            QtWidgets.QApplication.processEvents()
            info["shot"] = shot if mw.grab().save(shot) else None
        if panel is not None and Gui.Control.activeDialog():
            panel.reject()  # Cancel: the values the feature had
        if Gui.Control.activeDialog():
            Gui.Control.closeDialog()
        Gui.ActiveDocument.resetEdit()
        QtWidgets.QApplication.processEvents()
        return info

    def double_click_every_feature():
        feats = [o for o in doc.Objects if hasattr(getattr(o, "Proxy", None), "Type") and o.ViewObject is not None]
        return {o.Proxy.Type: open_by_double_click(o) for o in feats}

    step("double-click every feature", double_click_every_feature)

    # features whose links are unset (the linked object was never set, or removed): their
    # recompute fails with a clear message, and a double-click shows that message in a panel
    UNSET = {  # the status string each feature reports once its link is unset
        "GHT::SpineDevelopable": "OrphanSpine: no Curve linked",
        "GHT::CompositeCurve": "a composite curve needs >= 2 segments; OrphanComposite has 0",
        "GHT::JoinedDevelopable": "Previous is not set; link a developable (from planes) or a joined developable",
        "GHT::FlatPattern": "OrphanFlat: no Source linked",
        "GHT::Plate": "OrphanPlate: no Source linked; link a developable feature (from planes, joined, loft, spine/geodesic)",
    }
    # ... and the one Report view line each prints: "<Label>: <status>" (the Label not repeated)
    UNSET_LINES = [
        "OrphanSpine: no Curve linked",
        "OrphanComposite: a composite curve needs >= 2 segments; OrphanComposite has 0",
        "OrphanJoined: Previous is not set; link a developable (from planes) or a joined developable",
        "OrphanFlat: no Source linked",
        "OrphanPlate: no Source linked; link a developable feature (from planes, joined, loft, spine/geodesic)",
    ]

    def tree_items(labels, marked_over=None):
        """Per label: how many strongly red pixels the tree item's 16x16 icon has (FreeCAD paints
        its error mark over the icon of a failed object in red). The tree refreshes the items'
        status on a timer: with ``marked_over`` (an earlier result) the icons are read again every
        0.1 s, for up to 10 s, until each has 10 red pixels more than there."""
        timer = QtCore.QElapsedTimer()
        timer.start()
        while True:
            wait(100)
            out = _tree_items(labels)
            if marked_over is None or timer.elapsed() > 10000:
                return out
            if all(out.get(l, {}).get("red_pixels", 0) >= marked_over.get(l, {}).get("red_pixels", 0) + 10 for l in marked_over):
                return out

    def _tree_items(labels):
        from PySide2 import QtGui

        out = {}
        for tree in Gui.getMainWindow().findChildren(QtWidgets.QTreeWidget):
            it = QtWidgets.QTreeWidgetItemIterator(tree)
            while it.value():
                item = it.value()
                if item.text(0) in labels:
                    img = item.icon(0).pixmap(16, 16).toImage()
                    red = 0
                    for x in range(img.width()):
                        for y in range(img.height()):
                            c = QtGui.QColor.fromRgba(img.pixel(x, y))
                            red += c.alpha() > 128 and c.red() > 180 and c.green() < 90 and c.blue() < 90
                    out[item.text(0)] = {"red_pixels": red}
                it += 1
        return out

    def show_tree(label):
        """Give the Model tree most of the Combo View's height and scroll ``label`` into view."""
        for tree in Gui.getMainWindow().findChildren(QtWidgets.QTreeWidget):
            parent = tree.parent()
            while parent is not None and not isinstance(parent, QtWidgets.QSplitter):
                parent = parent.parent()
            if parent is not None:
                parent.setSizes([900, 80])
            for item in tree.findItems(label, QtCore.Qt.MatchExactly | QtCore.Qt.MatchRecursive):
                tree.scrollToItem(item, QtWidgets.QAbstractItemView.PositionAtBottom)

    def make_orphans():
        from freecad.ght_workbench import composite_curve, developable, flat_pattern, ght_curve, joined_developable, optimization, spine_developable

        c1 = ght_curve.make_ght_curve([(0, 60, 0), (10, 70, 5), (20, 70, 5), (30, 60, 0)], doc=doc, name="OrphanInput1")
        c2 = ght_curve.make_ght_curve([(30, 60, 0), (40, 50, 0), (50, 55, 0), (60, 60, 0)], doc=doc, name="OrphanInput2")
        orphans = [
            spine_developable.make_spine_developable(c1, doc=doc, name="OrphanSpine"),
            composite_curve.make_composite_curve([c1, c2], "G1", doc=doc, name="OrphanComposite"),
            joined_developable.make_joined_developable(ctx["developable"], "G2", doc=doc, name="OrphanJoined"),
            flat_pattern.make_flat_pattern(ctx["developable"], doc=doc, name="OrphanFlat"),
            optimization.make_optimization([c1], doc=doc, name="OrphanOptimization"),
        ]
        if "GHT_Plate" in _base.COMMANDS:
            from freecad.ght_workbench import plate

            orphans.append(plate.make_plate(ctx["developable"], doc=doc, name="OrphanPlate"))
        ok_before = {o.Proxy.Type: not _base.failed(o) for o in orphans}
        labels = [o.Label for o in orphans]
        mw = Gui.getMainWindow()
        for tabs in mw.findChildren(QtWidgets.QTabWidget):  # the Model tree in front
            for k in range(tabs.count()):
                if tabs.tabText(k) == "Model":
                    tabs.setCurrentIndex(k)
        icons_before = tree_items(labels)
        for o in orphans:
            for prop, empty in (("Curve", None), ("Segments", []), ("Previous", None), ("Source", None), ("Targets", [])):
                if prop in o.PropertiesList:
                    setattr(o, prop, empty)
        doc.recompute()
        ctx["orphans"] = orphans
        # what a user sees: the Model tree (error marks) and the Report view
        Gui.Selection.clearSelection()
        failed_labels = [o.Label for o in orphans if _base.failed(o)]
        icons_after = tree_items(labels, marked_over={l: icons_before.get(l, {}) for l in failed_labels})
        mw = Gui.getMainWindow()
        mw.resize(1280, 860)
        show_tree(labels[-1])
        wait(200)
        shot = os.path.join(OUT, "ght_workbench_failed.png")
        return {"valid_before": ok_before,
                "failed": {o.Proxy.Type: _base.failed(o) for o in orphans},
                "states": {o.Proxy.Type: list(o.State) for o in orphans},
                "status": {o.Proxy.Type: o.getStatusString() for o in orphans},
                "labels": {o.Proxy.Type: o.Label for o in orphans},
                "icons_before": icons_before, "icons_after": icons_after,
                "shot": shot if mw.grab().save(shot) else None}

    step("features with unset links: recompute", make_orphans, allow=[re.escape(m) for m in UNSET_LINES])

    def double_click_orphans():
        shots = {"GHT::SpineDevelopable": os.path.join(OUT, "ght_workbench_unset_link.png")}
        out = {o.Proxy.Type: open_by_double_click(o, shots.get(o.Proxy.Type)) for o in ctx["orphans"]}
        for o in ctx["orphans"]:
            doc.removeObject(o.Name)
        for n in ("OrphanInput2", "OrphanInput1"):
            doc.removeObject(n)
        doc.recompute()
        return out

    # the panels' Cancel recomputes the document: the orphans' recompute errors come again
    step("features with unset links: double-click", double_click_orphans, allow=[re.escape(m) for m in UNSET_LINES])

    def screenshot():
        Gui.Selection.clearSelection()
        view = Gui.ActiveDocument.ActiveView
        view.viewIsometric()
        view.fitAll()
        path = os.path.join(OUT, "ght_workbench.png")
        view.saveImage(path, 1024, 768, "White")
        # the whole main window too: menus, the GHT toolbar and the tree, as a user sees them
        from PySide2 import QtWidgets
        mw = Gui.getMainWindow()
        mw.resize(1280, 860)
        QtWidgets.QApplication.processEvents()
        window = os.path.join(OUT, "ght_workbench_window.png")
        grabbed = bool(mw.grab().save(window))
        return {"path": path, "size": os.path.getsize(path), "window": window if grabbed else None}

    step("screenshot", screenshot)

    def reopen():
        path = os.path.join(OUT, "gui_check.FCStd")
        names = {o.Name: o.Proxy.Type for o in doc.Objects if hasattr(o, "Proxy")}
        doc.saveAs(path)
        App.closeDocument(doc.Name)
        doc2 = App.openDocument(path)
        for o in doc2.Objects:
            o.touch()
        doc2.recompute()
        objs = [doc2.getObject(n) for n in names]
        bad = [o.Name for o in objs if "Invalid" in o.State or "Error" in o.State]
        icons = all(os.path.isfile(o.ViewObject.Proxy.getIcon()) for o in objs)
        dev = [o for o in objs if o.Proxy.Type == "GHT::Developable"][0]
        Gui.ActiveDocument.setEdit(dev.Name, 0)  # double-click: task panel again
        panel_open = bool(Gui.Control.activeDialog())
        return {"objects": len(objs), "bad": bad, "icons": icons, "panel_open": panel_open,
                "children": [c.Name for c in dev.ViewObject.Proxy.claimChildren()]}

    step("reopen", reopen)

    if "GHT_FlatPattern" in _base.COMMANDS:
        def whole_solid():
            # issue 23: a Part L-bracket (R 3, T 2, flanges 40/25, width 50) selected as a whole object:
            # the Flat pattern command unfolds the solid into one face, the bend table in its properties
            from freecad.ght_workbench.tests.fc_blank import bracket_shape

            bdoc = App.newDocument("blank")
            src = bdoc.addObject("Part::Feature", "Bracket")
            src.Shape = bracket_shape()
            bdoc.recompute()
            created, ok = run_command(bdoc, "GHT_FlatPattern", [src])
            flat = [o for o in created if getattr(o, "Proxy", None) and o.Proxy.Type == "GHT::FlatPattern"][0]
            flat.KFactor = 0.42
            bdoc.recompute()
            return {"created": len(created), "valid": ok and flat.Shape.isValid(), "whole_solid": bool(flat.WholeSolid),
                    "faces": len(flat.Shape.Faces),
                    "area": flat.Shape.Faces[0].Area if flat.Shape.Faces else 0.0, "bend_table": list(flat.BendTable),
                    "failed": _base.failed(flat)}

        step("GHT_FlatPattern whole solid", whole_solid)


def finish():
    try:
        main()
    except Exception:
        RESULT["errors"].append(traceback.format_exc())
    try:
        # error lines outside every step (workbench activation, between steps)
        in_steps = [l for s in RESULT["steps"] for l in s.get("report_errors", [])]
        for line in WATCH.since(WATCH.start):
            if line in in_steps:
                in_steps.remove(line)
            else:
                RESULT["unexpected_errors"].append("outside the steps: " + line)
        RESULT["report_view"] = WATCH.report_text()
        RESULT["traceback_lines"] = [l for l in RESULT["report_view"].splitlines() if TRACEBACK_RE.search(l)]
    except Exception:
        RESULT["errors"].append(traceback.format_exc())
    with open(os.path.join(OUT, "gui_result.json"), "w") as fh:
        json.dump(RESULT, fh, indent=1, default=str)
    os._exit(0)


QtCore.QTimer.singleShot(200, finish)
