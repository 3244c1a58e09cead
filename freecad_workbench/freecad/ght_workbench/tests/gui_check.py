"""GUI check, run by the FreeCAD GUI binary under a virtual display (Xvfb):

    xvfb-run -a freecad gui_check.py        (with GHT_FC_OUT=<dir>)

The workbench must be installed in the user's Mod folder (the pytest side links it there). Once
the event loop runs, the script activates the workbench, checks every command is registered, runs
each one on a prepared document (selection set as a user would), exercises a task panel's live
preview, exports STEP/DXF/SVG, saves a screenshot and writes ``gui_result.json``, then exits.
"""

import json
import os
import traceback

import FreeCAD as App
import FreeCADGui as Gui

try:
    from PySide2 import QtCore
except ImportError:  # pragma: no cover
    from PySide import QtCore  # type: ignore

OUT = os.environ.get("GHT_FC_OUT", "/tmp")
RESULT = {"steps": [], "errors": []}


def step(name, fn):
    try:
        value = fn()
        RESULT["steps"].append({"name": name, "ok": True, "value": value})
    except Exception:
        RESULT["steps"].append({"name": name, "ok": False, "error": traceback.format_exc()})
    finally:
        if Gui.Control.activeDialog():
            Gui.Control.closeDialog()


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

    step("GHT_Curve", curve)

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
    if "GHT_FlatPattern" in _base.COMMANDS and "developable" in ctx:
        step("GHT_FlatPattern", generic("GHT_FlatPattern", "developable", "GHT::FlatPattern", "flat"))
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

    def panel_without_input():
        # double-click on a spine whose Curve link is empty: no crash, no dialog, a message instead
        from freecad.ght_workbench import spine_developable

        orphan = spine_developable.make_spine_developable(ctx["curve"], doc=doc, name="Orphan")
        orphan.Curve = None
        doc.recompute()
        try:
            opened = Gui.ActiveDocument.setEdit(orphan.Name, 0)
            dialog = bool(Gui.Control.activeDialog())
        finally:
            if Gui.Control.activeDialog():
                Gui.Control.closeDialog()
            Gui.ActiveDocument.resetEdit()
            doc.removeObject(orphan.Name)
            doc.recompute()
        return {"opened": bool(opened), "dialog": dialog}

    step("panel without input", panel_without_input)

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


def finish():
    try:
        main()
    except Exception:
        RESULT["errors"].append(traceback.format_exc())
    with open(os.path.join(OUT, "gui_result.json"), "w") as fh:
        json.dump(RESULT, fh, indent=1, default=str)
    os._exit(0)


QtCore.QTimer.singleShot(200, finish)
