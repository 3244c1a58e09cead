r"""Outputs of a built design: B-rep (face or shell), STEP, flat pattern (DXF, SVG, PNG) and
:func:`export_files` (all or nothing, by suffix).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np

from .build import (BuiltSurface, _is_approximation, _is_composite, build_curves, build_surfaces, sheet_part_label, sheet_parts, surfaces_summary,
                    surface_view)
from .schema import Design, DesignError


def _ruled_face(surface: Any, tol: float) -> Any:
    """B-spline face of degree (p, 1) through the paired boundary curves ``a(u)``, ``b(u)``.

    ``a`` and ``b`` are fitted together as one 6-D function (one knot vector, pole i of each at
    the same parameter), so the face is ``(1-v) A(u) + v B(u)`` with ``|A - a|, |B - b| <= tol``.
    """
    from ...surfaces.bspline import BSplineSurfaceData, fit_function
    from ...cad.occ import make_face

    fit = fit_function(lambda t: np.hstack([surface.a(t), surface.b(t)]), tol=tol, degree=5)
    poles = np.stack([fit.poles[:, :3], fit.poles[:, 3:]], axis=1)
    data = BSplineSurfaceData(poles, fit.knots, np.array([0.0, 0.0, 1.0, 1.0]), fit.degree, 1,
                              max_deviation=fit.max_deviation)
    return make_face(data)


def brep_face(built: BuiltSurface, tol: float | None = None) -> Any:
    """A build123d face of the built surface (``surface.to_face()`` when it has one)."""
    s = built.surface
    if tol is None:
        g = s.grid(17, 3).reshape(-1, 3)
        tol = 1e-7 * float(np.linalg.norm(g.max(axis=0) - g.min(axis=0)))
    if hasattr(s, "to_face"):
        try:
            return s.to_face(tol=tol)
        except ImportError:
            pass
    return _ruled_face(s, tol)


def brep_shape(built: BuiltSurface, tol: float | None = None) -> Any:
    """The B-rep of the built surface: one face (:func:`brep_face`), or for a composite one shell
    of one B-spline face per strip sewn along the joint rulings
    (:func:`ght_cad.cad.developable_faces.composite_shell`)."""
    if _is_composite(built.surface):
        from ...cad.developable_faces import composite_shell

        return composite_shell(built.surface, tol=tol)
    if _is_approximation(built.surface):  # the shell ght-cad approximate writes
        from ...cad.approximate import panels_shell

        return panels_shell(built.surface.result)
    return brep_face(built, tol)


def brep_shapes(builts: Sequence[BuiltSurface], tol: float | None = None) -> Any:
    """The B-rep of a design's surfaces: :func:`brep_shape` of a single surface; for several, every
    face of every surface sewn into one shell (:func:`sew_shell`), so surfaces meeting along a rail
    share that edge."""
    if len(builts) == 1:
        return brep_shape(builts[0], tol)
    return sew_shell([brep_shape(b, tol) for b in builts])


def sew_shell(shapes: Sequence[Any], sew_tol: float | None = None) -> Any:
    """One build123d ``Shell`` of all faces of ``shapes`` sewn together (``BRepBuilderAPI_Sewing``
    with ``sew_tol``, default ``1e-6`` times the size of the whole): edges that coincide within the
    tolerance become one edge shared by both faces (split where the faces' edges end at different
    points).

    Raises:
        ConversionError: the faces do not make one shell, or the shell is not valid (BRepCheck).
    """
    from build123d import Compound, Shell
    from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from ...cad._ocp import TopoDS

    from ...cad.developable_faces import shell_faces
    from ...cad.occ import is_valid, unwrap
    from ...core.errors import ConversionError

    faces = [f for sh in shapes for f in shell_faces(sh)]
    if sew_tol is None:
        bb = Compound(list(shapes)).bounding_box()
        sew_tol = 1e-6 * float(max(bb.size.X, bb.size.Y, bb.size.Z))
    sewing = BRepBuilderAPI_Sewing(float(sew_tol))
    for f in faces:
        sewing.Add(unwrap(f))
    sewing.Perform()
    exp = TopExp_Explorer(sewing.SewedShape(), TopAbs_SHELL)
    shells = []
    while exp.More():
        shells.append(TopoDS.Shell_s(exp.Current()))
        exp.Next()
    if len(shells) != 1:
        raise ConversionError(f"sewing the {len(faces)} faces of the {len(shapes)} surfaces gave {len(shells)} shells; "
                              "expected one (surfaces must meet along a common rail)")
    shell = Shell(shells[0])
    if not is_valid(shell):
        raise ConversionError("the sewn shell of the surfaces is not a valid B-rep (BRepCheck_Analyzer)")
    return shell


def shared_edge_count(shape: Any) -> int:
    """Number of edges of a B-rep shared by two or more of its faces (``TopExp`` edge→face map)."""
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from ...cad._ocp import TopTools_IndexedDataMapOfShapeListOfShape

    from ...cad.occ import unwrap

    m = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(unwrap(shape), TopAbs_EDGE, TopAbs_FACE, m)
    return sum(1 for i in range(1, m.Extent() + 1) if m.FindFromIndex(i).Size() >= 2)


def curve_edges(curves: dict[str, Any]) -> list[Any]:
    """Certified B-spline edges (``curve_to_bspline``) of the 2-D/3-D curves."""
    from ...surfaces.bspline import curve_to_bspline
    from ...cad.occ import make_edge

    return [make_edge(curve_to_bspline(c)) for c in curves.values() if c.dim in (2, 3)]


def export_step(built: BuiltSurface | Sequence[BuiltSurface], path: str | os.PathLike, *,
                with_curves: bool = True) -> Path:
    """Write the surface face(s) (:func:`brep_shapes`: several surfaces as one sewn shell) and the
    design's curves as edges to one STEP file, atomically; with a ``[sheet]`` of thickness > 0 the
    plate solid(s) instead of the face (:func:`plate_solids`, faces named inside/outside/edgeN)."""
    from ...cad.occ import write_step

    builts = list(built) if isinstance(built, (list, tuple)) else [built]
    edges = curve_edges(builts[0].curves) if with_curves else []
    plates = plate_solids(builts[0]) if len(builts) == 1 else design_plates(builts)[0]
    if plates:
        from ...cad.sheet_solid import write_plate_step

        write_plate_step(plates, path, units=builts[0].design.units, extra=edges, product=builts[0].design.name)
        return Path(path)
    write_step([brep_shapes(builts)] + edges, path, units=builts[0].design.units, product=builts[0].design.name)
    return Path(path)


def unroll_surface(built: BuiltSurface) -> Any:
    """Flat pattern of the built surface (:func:`ght_cad.unroll`).

    A composite's strips (joined G1..G3) are one blank labelled with the design's name
    (``[unroll] panels = "joined"``, the default; :func:`ght_cad.sheetmetal.join_panels.join_panels`) or one
    panel per strip (``"per-surface"``). A ``curves`` strip is flattened with ``best_effort=True`` (it is only quasi-developable); its
    distortion is then in the pattern's errors.
    """
    from ...unrolling.unroll import unroll

    d = built.design
    sheet = d.sheet.to_sheet() if d.sheet is not None else None  # [sheet]: the neutral surface (spec 6.1)
    if _is_approximation(built.surface):  # the panels of ght-cad approximate, seams marked
        from .approximate import panel_pattern

        return panel_pattern(built.surface.result, built.surface.part_sheets(sheet), tol_deg=d.unroll.tol_deg,
                             rulings=d.unroll.rulings, samples=d.unroll.samples, units=d.units)
    if _is_composite(built.surface):
        from ...unrolling.unroll import unroll_composite

        return unroll_composite(built.surface.segments, tol_deg=d.unroll.tol_deg, rulings=d.unroll.rulings,
                                samples=d.unroll.samples, units=d.units, labels=[g.name for g in d.surface.segments or []],
                                sheet=sheet, join=d.unroll.panels == "joined", join_label=d.name[:24])
    best_effort = d.surface is not None and d.surface.type == "curves"
    return unroll(built.surface, best_effort=best_effort, tol_deg=d.unroll.tol_deg, rulings=d.unroll.rulings,
                  samples=d.unroll.samples, units=d.units, label=d.name[:24], sheet=sheet)


def plate_solids(built: BuiltSurface) -> list[Any]:
    """The ``[sheet]`` plate of the built surface: one :class:`ght_cad.cad.sheet_solid.PlateSolid`
    per strip (a composite gives one per segment); empty without a sheet or with T = 0."""
    d = built.design
    if d.sheet is None or d.sheet.thickness == 0:
        return []
    from ...cad.sheet_solid import plate_solid

    sheet = d.sheet.to_sheet()
    if _is_approximation(built.surface):  # the plates of ght-cad approximate --thickness (P1.inside, ...)
        from .approximate import panel_plates

        return panel_plates(built.surface.result, built.surface.part_sheets(sheet), d.name)
    # the parts and labels of check_sheet (the optimizer's sheet rule is the same check on the same parts)
    return [plate_solid(s, sheet, label=sheet_part_label(d, i)) for i, s in enumerate(sheet_parts(built.surface))]


def design_plates(builts: Sequence[BuiltSurface]) -> tuple[list[Any], Any]:
    """The plates of a ``[[surfaces]]`` design with a ``[sheet]``: every surface's
    :func:`plate_solids` with its own sheet (:func:`ght_cad.app.design.shell_sheet.surface_sheets`:
    the material on one side of the shell), each named after its surface (``<surface>`` or
    ``<surface>.<strip>``; faces ``<name>.inside``, ...). Returns ``(plates, (sheets, rails, builts))``
    with the resolved per-surface sheets and the shared rails (None when ``builts`` carry their
    sheets already); ``([], None)`` without a sheet or with one surface; a surface with T = 0 has
    no plate.

    Raises:
        GHTError: a surface the sheet cannot be made on (names ``surfaces[i]`` and the surface).
    """
    if len(builts) < 2 or builts[0].design.sheet is None:
        return [], None
    resolved = None if all(b.sheet_resolved for b in builts) else resolve_design_sheets(builts)
    sheeted = builts if resolved is None else resolved[2]
    plates: list[Any] = []
    for b in sheeted:
        pl = plate_solids(b)
        names = ([f"{b.design.name}.{g.name}" for g in b.design.surface.segments or []] if _is_composite(b.surface)
                 else [str(b.design.name)])
        for p, nm in zip(pl, names):
            p.name = nm
        plates += pl
    return plates, resolved


def resolve_design_sheets(builts: Sequence[BuiltSurface]) -> tuple[list[Any], list[Any], list[BuiltSurface]]:
    """Per-surface sheets of a ``[[surfaces]]`` design (:func:`ght_cad.app.design.shell_sheet.surface_sheets`),
    checked on every surface (:func:`~ght_cad.app.design.shell_sheet.check_surface_sheets`), the
    shared rails, and the built surfaces carrying their own sheet."""
    from .shell_sheet import apply_sheets, check_surface_sheets, surface_sheets

    from dataclasses import replace

    if all(b.sheet_resolved for b in builts):
        raise DesignError("the surfaces' sheets are resolved already")  # pragma: no cover - internal misuse
    # the design of all surfaces (the sub-designs carry the file's [sheet] and their own surface)
    parent = replace(builts[0].design, surface=None, surfaces=[b.design.surface for b in builts])
    sheets, rails = surface_sheets(parent, builts)
    sheeted = apply_sheets(builts, sheets)
    check_surface_sheets(parent, sheeted)
    return sheets, rails, sheeted


def unroll_surfaces(builts: Sequence[BuiltSurface]) -> Any:
    """Flat pattern of a design's surfaces: :func:`unroll_surface` of a single surface; for several,
    one labelled panel per surface (per strip for a composite: ``<surface>.<strip>``) on one sheet
    (:func:`ght_cad.unroll.unroll_composite`: panels laid side by side, matching edge marks ``E<k>``
    on the edges two panels share in 3-D, e.g. a common rail). With ``[unroll] panels = "joined"``
    (the default) surfaces and strips meeting at G1 or smoother along a whole shared edge are one
    blank (:func:`ght_cad.sheetmetal.join_panels.join_panels`); sharp chines stay separate panels with marks."""
    if len(builts) == 1:
        return unroll_surface(builts[0])
    from ...unrolling.unroll import unroll_composite

    d = builts[0].design
    if d.sheet is not None and not all(b.sheet_resolved for b in builts):
        builts = resolve_design_sheets(builts)[2]
    parts: list[Any] = []
    labels: list[str] = []
    sheets: list[Any] = []
    for b in builts:
        sh = b.design.sheet.to_sheet() if b.design.sheet is not None else None
        if _is_composite(b.surface):
            parts += list(b.surface.segments)
            labels += [f"{b.design.name}.{g.name}" for g in b.design.surface.segments or []]
            sheets += [sh] * len(b.surface.segments)
        else:
            parts.append(b.surface)
            labels.append(b.design.name)
            sheets.append(sh)
    best_effort = any(b.design.surface is not None and b.design.surface.type == "curves" for b in builts)
    join = {"join": d.unroll.panels == "joined"}  # a blank's label: its surfaces' names joined by "+"
    if all(s is None for s in sheets):  # no [sheet]: as before
        return unroll_composite(parts, best_effort=best_effort, tol_deg=d.unroll.tol_deg, rulings=d.unroll.rulings,
                                samples=d.unroll.samples, units=d.units, labels=labels, **join)
    # [sheet]: every panel its surface's neutral surface; edge marks matched on the design edges (the
    # neutral surfaces of two plates meeting at an angle part along their shared rail)
    return unroll_composite(parts, best_effort=best_effort, tol_deg=d.unroll.tol_deg, rulings=d.unroll.rulings,
                            samples=d.unroll.samples, units=d.units, labels=labels, sheet=sheets, marks_on="design", **join)


def pattern_report(pattern: Any) -> dict[str, Any]:
    """The ``flat_pattern`` entry of a report: area, errors, distortion report, outline and bend-line
    counts, bounding box, per-panel areas and the edge-mark labels (``E<n>``, panel labels excluded)."""
    import re

    panel_labels = {pn.label for pn in pattern.panels}
    out = {
        "area": float(pattern.area),
        "errors": pattern_errors(pattern),
        "report": pattern.report.as_dict(),
        "outline_points": int(sum(len(o) for o in pattern.outlines)),
        "bend_lines": int(len(pattern.bend_lines)),
        "bbox": [np.min(np.concatenate(pattern.outlines), axis=0).tolist(),
                 np.max(np.concatenate(pattern.outlines), axis=0).tolist()],
        "panels": [{"label": pn.label, "area_flat": float(pn.area_flat), "area_3d": float(pn.area_3d),
                    "max_error": float(pn.report.max_relative_error) if pn.report is not None else None}
                   for pn in pattern.panels],
        "edge_marks": sorted({t[2] for t in pattern.labels
                              if t[2] not in panel_labels and re.fullmatch(r"E\d+", t[2])}, key=lambda m: int(m[1:])),
    }
    # [sheet]: per panel the sheet, inside/neutral/outside edge lengths and forming rows (spec 6.1)
    sheets = [{"panel": pn.label, **{k: v for k, v in pn.info["sheet"].items() if k != "chart"}}
              for pn in pattern.panels if pn.info.get("sheet")]
    if sheets:
        out["sheet"] = sheets
    return out


def pattern_errors(pattern: Any) -> dict[str, float]:
    """Max relative length/area errors of a flat pattern (``FlatPattern.errors``) as floats."""
    return {k: float(v) for k, v in pattern.errors.items()}


def plot_pattern(pattern: Any, path: str | os.PathLike, title: str | None = None) -> Path:
    """Fixed-size PNG (900 x 700) of a flat pattern: outlines and bend lines."""
    from ...curves.plotting import plot_flat_pattern

    e = pattern.errors
    t = (title + ": " if title else "") + f"flat pattern, max rel. error {e['max']:.1e}"
    return plot_flat_pattern(pattern.outlines, path, rulings=list(pattern.bend_lines), title=t,
                             labels=list(pattern.labels), marks=list(pattern.marks))


def export_files(design: Design, files: Iterable[str | os.PathLike], chord_tol: float | None = None) -> dict[str, str]:
    """Build the design with its given shape parameters and write each file by its suffix.

    ``.step``/``.stp``: face + curves; ``.dxf``/``.svg``: flat pattern; ``.json``: name, units,
    surface summary, curves and (with a surface) the ``flat_pattern`` entry of :func:`pattern_report`;
    ``.png``: rendered surface (or the curves when the design has no surface).

    All or nothing (:class:`ght_cad.core.outdir.StagedFiles`): every target is locked against other
    ght-cad processes, every file is first written into a staging folder beside its target
    (which also proves the target's folder is writable) and the files are moved into place only
    when every one was written; a failure leaves every target as it was (existing files
    untouched, no new file).

    Args:
        design: a validated design (:func:`load_design`).
        files: output paths; the suffix selects the content.
        chord_tol: DXF/SVG outline chord tolerance in the design's units; it takes precedence
            over the file's ``[outputs] chord_tol`` (None: that key, else 1e-3 mm,
            :attr:`ght_cad.pattern.flat_pattern.FlatPattern.chord_tol`).

    Raises:
        DesignError: a suffix that is not allowed, a surface output without [surface].
        GHTError: a target whose folder cannot be written (the message names the target).
        FolderBusy: another process writes one of the targets.

    Returns:
        ``{kind: path}`` for each written file (``kind`` = suffix without dot, ``_<n>`` appended
        for repeats).
    """
    files = [Path(f) for f in files]
    allowed = (".step", ".stp", ".dxf", ".svg", ".json", ".png")
    for f in files:
        if f.suffix.lower() not in allowed:
            raise DesignError(f"{f}: unknown output suffix {f.suffix!r}; allowed: {', '.join(allowed)}")
    chord_tol = design.outputs.chord_tol if chord_tol is None else chord_tol  # --chord-tol over the file
    curves, _ = build_curves(design)
    builts = build_surfaces(design, curves)
    if not builts:
        for f in files:
            if f.suffix.lower() in (".dxf", ".svg"):
                raise DesignError(f"{design.source}: key 'surface': missing; {f} needs a [surface] table")
    from ...core.outdir import StagedFiles

    with StagedFiles(files) as stage:  # locked targets, staging folders with pid + lock
        out: dict[str, str] = {}
        pattern = None
        for f in files:
            pattern = _export_one(design, curves, builts, f, stage.path(f), pattern, chord_tol)
            suf = f.suffix.lower().lstrip(".")
            out[suf + (f"_{len(out)}" if suf in out else "")] = str(f)
        stage.commit()
    return out


def _export_one(design: Design, curves: dict[str, Any], builts: list[BuiltSurface], target: Path,
                tmp: Path, pattern: Any, chord_tol: float | None = None) -> Any:
    """Write the content for ``target`` (chosen by its suffix) into ``tmp``; returns the flat pattern."""
    import json

    from ...core.io import write_text_atomic

    suf = target.suffix.lower()
    if suf in (".step", ".stp"):
        if builts:
            export_step(builts, tmp)
        else:
            from ...cad.occ import write_step

            write_step(curve_edges(curves), tmp, units=design.units, product=design.name)
    elif suf in (".dxf", ".svg"):
        pattern = pattern or unroll_surfaces(builts)
        (pattern.export_dxf if suf == ".dxf" else pattern.export_svg)(tmp, chord_tol=chord_tol)
    elif suf == ".json":
        summ = {"name": design.name, "units": design.units}
        summ.update(surfaces_summary(builts) if builts else {})
        summ["curves"] = {k: c.to_dict() for k, c in curves.items()}
        if builts:
            pattern = pattern or unroll_surfaces(builts)
            summ["flat_pattern"] = pattern_report(pattern)
        write_text_atomic(tmp, json.dumps(_jsonable(summ), indent=2) + "\n")
    else:
        from ...curves.plotting import plot_curve, plot_surface

        if builts:
            plot_surface(surface_view(builts), tmp, title=design.name)
        else:
            plot_curve(list(curves.values()), tmp)
    return pattern


def _jsonable(o: Any) -> Any:
    if isinstance(o, dict):
        return {str(k): _jsonable(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_jsonable(v) for v in o]
    if isinstance(o, np.ndarray):
        return _jsonable(o.tolist())
    if isinstance(o, (np.floating, float)):
        x = float(o)
        return x if math.isfinite(x) else None
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.bool_,)):
        return bool(o)
    return o
