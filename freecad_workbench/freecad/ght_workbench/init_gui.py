"""GUI start-up: registers the GHT workbench (FreeCAD imports ``freecad.<name>.init_gui``)."""

from __future__ import annotations

import importlib

import FreeCAD as App
import FreeCADGui as Gui

from . import icon

# feature modules (each registers its command(s) on import), in toolbar order
FEATURE_MODULES = (
    "ght_curve",
    "composite_curve",
    "developable",
    "spine_developable",
    "developable_loft",
    "developable_approximation",
    "plate",
    "flat_pattern",
    "optimization",
    "export",
)
# modules whose commands are registered with FreeCADGui directly (not in _base.COMMANDS, which the
# GUI check enumerates); their commands join the toolbars below when registered
EXTRA_MODULES = ("joined_developable",)
TOOLBARS = {
    "GHT curves": ["GHT_Curve", "GHT_CompositeCurve"],
    "GHT surfaces": ["GHT_Developable", "GHT_SpineDevelopable", "GHT_JoinedDevelopable", "GHT_DevelopableLoft", "GHT_DevelopableApproximation", "GHT_Plate", "GHT_FlatPattern"],
    "GHT optimization": ["GHT_Optimization", "GHT_RunOptimization"],
    "GHT export": ["GHT_ExportSTEP", "GHT_ExportDXF", "GHT_ExportSVG"],
}


def load_commands() -> list[str]:
    """Import every feature module; returns the names of the registered commands."""
    from ._base import COMMANDS

    for mod in FEATURE_MODULES:
        try:
            importlib.import_module(f"{__package__}.{mod}")
        except Exception as exc:  # a missing core module must not break the whole workbench
            App.Console.PrintWarning(f"GHT workbench: {mod} not loaded: {type(exc).__name__}: {exc}\n")
    for mod in EXTRA_MODULES:
        try:
            importlib.import_module(f"{__package__}.{mod}")
        except Exception as exc:
            App.Console.PrintWarning(f"GHT workbench: {mod} not loaded: {type(exc).__name__}: {exc}\n")
    return list(COMMANDS)


class GHTWorkbench(Gui.Workbench):
    """GHT-Bézier curves, developable surfaces, flat patterns and shape-parameter optimization."""

    MenuText = "GHT"
    ToolTip = "GHT-Bézier curves and developable surfaces (ght_cad)"
    Icon = icon("GHT_Workbench")

    def GetClassName(self) -> str:
        return "Gui::PythonWorkbench"

    def Initialize(self) -> None:
        available = set(load_commands()) | set(Gui.listCommands())
        for bar, cmds in TOOLBARS.items():
            present = [c for c in cmds if c in available]
            if present:
                self.appendToolbar(bar, present)
                self.appendMenu(["&GHT", bar.replace("GHT ", "").capitalize()], present)

    def Activated(self) -> None:
        pass

    def Deactivated(self) -> None:
        pass


Gui.addWorkbench(GHTWorkbench())
