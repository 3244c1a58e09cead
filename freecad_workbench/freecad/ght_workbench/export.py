"""Export commands: STEP of selected features (named products via FreeCAD's XCAF exporter), DXF/SVG of flat patterns (atomic writes).

DXF is the core's file (``FlatPattern.export_dxf``, the same as ``ght-cad unroll --dxf``): in
FreeCAD's Python, which has no ezdxf, an AutoCAD R12 ASCII file with closed outline polylines,
DASHED bend lines, labels and edge marks, which every CAM/laser program reads. SVG is plain
``<path>`` markup in millimetres; its curved edges are discretized with chordal deviation
``deflection``.
"""

from __future__ import annotations

import os
from typing import Any, Iterable, Sequence

import FreeCAD as App
import Part

from . import _ensure_core  # noqa: F401
from ._base import BaseCommand, failed, failed_input, register_command
from ght_cad.core.errors import GHTError
from ght_cad.core.io import atomic_path, write_text_atomic
from ght_cad.core.outdir import lock_target

__all__ = [
    "export_step",
    "read_step",
    "stale_reason",
    "flat_pattern_polylines",
    "write_svg",
    "export_flat_pattern_dxf",
    "export_flat_pattern_svg",
]


def stale_reason(obj: Any) -> str | None:
    """Why the shape of ``obj`` may not match its inputs, or None if it is current.

    FreeCAD keeps the old shape of a feature whose recompute failed (:func:`._base.failed`), and
    does not recompute the features that depend on a failed one (they keep their old shape and
    look fine); a feature with pending changes (state ``Touched``) has not been rebuilt yet either.

    Args:
        obj: a document object; its ``State`` and those of its ``OutListRecursive`` are read.

    Returns:
        A sentence for an error message (the failed object and its status string), or None.
    """
    if failed(obj):
        return f"its last recompute failed ({obj.getStatusString()}), so its shape is stale"
    dep = failed_input(obj)
    if dep is not None:
        return f"its input {dep.Label} failed to recompute ({dep.getStatusString()}), so its shape is stale"
    if "Touched" in getattr(obj, "State", []) or any("Touched" in getattr(d, "State", []) for d in getattr(obj, "OutListRecursive", [])):
        return "it has changes not yet recomputed; recompute the document first"
    return None


def _shapes(objects: Iterable[Any]) -> list:
    out = []
    for o in objects:
        why = stale_reason(o)
        if why:
            raise GHTError(f"{o.Label}: {why}; fix it or leave it out of the export")
        shp = getattr(o, "Shape", None)
        if shp is None or shp.isNull():
            raise GHTError(f"{getattr(o, 'Label', o)} has no shape to export")
        out.append(shp)
    return out


def _step_writer() -> Any:
    """FreeCAD's XCAF STEP exporter: ``ImportGui.export`` in the GUI (it also writes the view
    colours), ``Import.export`` headless (names only)."""
    if App.GuiUp:
        try:
            import ImportGui

            return ImportGui.export
        except ImportError:  # pragma: no cover - GUI builds without ImportGui
            pass
    import Import

    return Import.export


def export_step(objects: Sequence[Any], path: str | os.PathLike, *, check: bool = True) -> str:
    """Write ``objects`` to a STEP file (AP214 schema as FreeCAD 0.20 writes it, millimetres)
    atomically, one named product each.

    FreeCAD's XCAF exporter writes every object as a STEP ``PRODUCT`` named by its ``Label``
    (several objects: under a root product named after the document); under the GUI the view
    colours are written too (``COLOUR_RGB``). The file is first written to a temporary
    ``.step`` name beside ``path`` and renamed over it only when complete.

    Args:
        objects: FreeCAD objects with a non-null ``Shape``.
        path: target file (``.step``/``.stp``; the content is STEP whatever the suffix).
        check: refuse shapes for which ``shape.isValid()`` is False.

    Raises:
        GHTError: nothing to export, an object without shape, a stale shape (:func:`stale_reason`:
            its or an input's last recompute failed, or changes are pending), or an invalid shape
            (when ``check``).
        FolderBusy: another process is writing ``path`` (its lock, :func:`ght_cad.core.outdir.lock_target`).
        OSError: the write failed; the target file is then untouched and no partial file is left.

    Returns:
        ``str(path)``.
    """
    objects = list(objects)
    shapes = _shapes(objects)
    if not shapes:
        raise GHTError("nothing to export: no objects given")
    if check:
        for o, s in zip(objects, shapes):
            if not s.isValid():
                raise GHTError(f"{o.Label} is not a valid shape (shape.isValid() is False); not exported to {path}")
    writer = _step_writer()
    units = Part.exportUnits().get("write.step.unit", "MM")
    Part.exportUnits("MM")  # FreeCAD's lengths are mm: write them as they are, whatever the user preference
    try:
        # another process (a second FreeCAD, a ght-cad run) writing this very file: refused, naming it
        lock = lock_target(path)
        try:
            # the exporter picks the format from the suffix: the temporary name must end in .step
            with atomic_path(path, suffix=".step") as tmp:
                step_tmp = tmp.with_name(tmp.name[: -len(".part")])
                try:
                    writer(objects, str(step_tmp))
                    if step_tmp.exists():
                        os.replace(step_tmp, tmp)
                finally:
                    if step_tmp.exists():
                        step_tmp.unlink()
        finally:
            lock.release()
    finally:
        Part.exportUnits(units)
    return str(path)


def read_step(path: str | os.PathLike) -> "Part.Shape":
    """Read a STEP file back into one ``Part.Shape``."""
    shape = Part.Shape()
    shape.read(str(path))
    return shape


def _edge_points(edge: "Part.Edge", deflection: float) -> list[tuple[float, float]]:
    if isinstance(edge.Curve, Part.Line) or edge.Curve.TypeId == "Part::GeomLine":
        pts = [edge.Vertexes[0].Point, edge.Vertexes[-1].Point]
        if edge.Orientation == "Reversed":
            pts = pts[::-1]
    else:
        pts = edge.discretize(Deflection=deflection)
    return [(float(p.x), float(p.y)) for p in pts]


def _current_flat_shape(obj: Any) -> "Part.Shape":
    """The flat pattern feature's shape, refused if stale (:func:`stale_reason`) or never computed."""
    why = stale_reason(obj)
    if why:
        raise GHTError(f"{obj.Label}: {why}; allowed: a flat pattern that recomputes without error")
    if not obj.Shape.Faces:
        raise GHTError(f"{obj.Label}: the flat pattern has no planar face to export; recompute it first")
    return obj.Shape


def flat_pattern_polylines(obj: Any, deflection: float = 1e-3) -> tuple[list[list[tuple[float, float]]], list[list[tuple[float, float]]]]:
    """(outline polylines, bend-line polylines) of a flat pattern feature in its XY plane.

    The outline is every edge of the planar face(s) of ``obj.Shape``; bend lines are the loose
    edges of the compound (not bounding a face).

    Raises:
        GHTError: the shape is stale (:func:`stale_reason`: its or an input's last recompute failed,
            or changes are pending) or it has no planar face (never computed).
    """
    shape = _current_flat_shape(obj)
    outline = [_edge_points(e, deflection) for f in shape.Faces for w in f.Wires for e in w.OrderedEdges]
    face_edges = [e for f in shape.Faces for e in f.Edges]
    bends = [_edge_points(e, deflection) for e in shape.Edges if not any(e.isSame(fe) for fe in face_edges)]
    return outline, bends


def write_svg(path: str | os.PathLike, layers: dict[str, list[list[tuple[float, float]]]], margin: float = 5.0) -> str:
    """SVG in millimetres (y up in the model, flipped for SVG); one ``<g id=layer>`` per layer."""
    pts = [p for polys in layers.values() for pl in polys for p in pl]
    if not pts:
        raise GHTError("nothing to export: the flat pattern has no edges")
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    x0, x1, y0, y1 = min(xs) - margin, max(xs) + margin, min(ys) - margin, max(ys) + margin
    w, h = x1 - x0, y1 - y0
    style = {"OUTLINE": 'stroke="black" stroke-width="0.25"', "BEND": 'stroke="red" stroke-width="0.2" stroke-dasharray="2,1"'}
    body = []
    for name, polys in layers.items():
        body.append(f'<g id="{name}" fill="none" {style.get(name, style["OUTLINE"])}>')
        for pl in polys:
            d = " ".join(("M" if i == 0 else "L") + f"{x - x0:.6f},{y1 - y:.6f}" for i, (x, y) in enumerate(pl))
            body.append(f'<path d="{d}"/>')
        body.append("</g>")
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.6f}mm" height="{h:.6f}mm" viewBox="0 0 {w:.6f} {h:.6f}">\n'
        + "\n".join(body)
        + "\n</svg>\n"
    )
    write_text_atomic(path, text)
    return str(path)


def export_flat_pattern_dxf(obj: Any, path: str | os.PathLike, deflection: float = 1e-3) -> str:
    """DXF of a flat pattern feature, written by the core (:meth:`ght_cad.pattern.flat_pattern.FlatPattern.export_dxf`).

    The same file as ``ght-cad unroll --dxf``: layers OUTLINE (every loop one closed polyline),
    BEND (bend lines, linetype DASHED), LABELS and MARKS, ``$INSUNITS`` millimetres; R12 ASCII in
    FreeCAD's Python (no ezdxf). The outline is the feature's flat face up to a translation (the
    core pattern's own frame). ``deflection`` is kept for compatibility and not used (the core
    samples the exact flat boundary).

    Raises:
        GHTError: the feature is stale (see :func:`stale_reason`) or has never been computed.
    """
    _current_flat_shape(obj)
    with lock_target(path):
        obj.Proxy.pattern(obj).export_dxf(path)
    return str(path)


def export_flat_pattern_svg(obj: Any, path: str | os.PathLike, deflection: float = 1e-3) -> str:
    """SVG of a flat pattern feature: group OUTLINE (black) and BEND (red dashed)."""
    outline, bends = flat_pattern_polylines(obj, deflection)
    with lock_target(path):
        return write_svg(path, {"OUTLINE": outline, "BEND": bends})


def _ask_path(title: str, filt: str, default: str) -> str | None:
    from PySide2 import QtWidgets

    import FreeCADGui as Gui

    path, _ = QtWidgets.QFileDialog.getSaveFileName(Gui.getMainWindow(), title, default, filt)
    return path or None


def _default_path(doc: Any, ext: str) -> str:
    base = os.path.splitext(doc.FileName)[0] if doc.FileName else os.path.join(os.path.expanduser("~"), doc.Name)
    return base + ext


def _flat_patterns(objs: Iterable[Any]) -> list:
    return [o for o in objs if getattr(getattr(o, "Proxy", None), "Type", "") == "GHT::FlatPattern"]


class CommandExportSTEP(BaseCommand):
    name = "GHT_ExportSTEP"
    icon_name = "GHT_ExportSTEP"
    menu_text = "Export STEP"
    tooltip = "Export the selected features to a STEP file (one product per feature, named by its label; colours in the GUI)"
    #: set by tests/macros to skip the file dialog
    target: str | None = None

    def IsActive(self) -> bool:
        import FreeCADGui as Gui

        return App.ActiveDocument is not None and bool(Gui.Selection.getSelection())

    def Activated(self) -> None:
        import FreeCADGui as Gui

        objs = [o for o in Gui.Selection.getSelection() if hasattr(o, "Shape")]
        path = self.target or _ask_path("Export STEP", "STEP (*.step *.stp)", _default_path(App.ActiveDocument, ".step"))
        if path:
            export_step(objs, path)
            App.Console.PrintMessage(f"GHT: wrote {path}\n")


class _CommandExportFlat(BaseCommand):
    ext = ".dxf"
    target: str | None = None

    def IsActive(self) -> bool:
        import FreeCADGui as Gui

        return App.ActiveDocument is not None and bool(_flat_patterns(Gui.Selection.getSelection()))

    def Activated(self) -> None:
        import FreeCADGui as Gui

        pats = _flat_patterns(Gui.Selection.getSelection())
        for i, obj in enumerate(pats):
            path = self.target or _ask_path(self.menu_text, f"{self.ext[1:].upper()} (*{self.ext})", _default_path(App.ActiveDocument, f"_{obj.Name}{self.ext}"))
            if not path:
                return
            if self.target and len(pats) > 1:
                path = f"{os.path.splitext(path)[0]}_{i}{self.ext}"
            (export_flat_pattern_dxf if self.ext == ".dxf" else export_flat_pattern_svg)(obj, path)
            App.Console.PrintMessage(f"GHT: wrote {path}\n")


class CommandExportDXF(_CommandExportFlat):
    name = "GHT_ExportDXF"
    icon_name = "GHT_ExportDXF"
    menu_text = "Export flat pattern DXF"
    tooltip = "Export the selected flat patterns to DXF (R12: layer OUTLINE = closed cut contour, BEND = dashed bend lines, LABELS, MARKS)"
    ext = ".dxf"


class CommandExportSVG(_CommandExportFlat):
    name = "GHT_ExportSVG"
    icon_name = "GHT_ExportSVG"
    menu_text = "Export flat pattern SVG"
    tooltip = "Export the selected flat patterns to SVG in millimetres (outline black, bend lines red dashed)"
    ext = ".svg"


register_command(CommandExportSTEP())
register_command(CommandExportDXF())
register_command(CommandExportSVG())
