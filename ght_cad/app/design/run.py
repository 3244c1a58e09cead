r"""The pipeline behind ``ght-cad run``/``demo``: :func:`run_design`.

curves → surface → optimization → measures → B-rep + STEP → flat pattern → figures → report,
computed into a staging folder beside the output folder and moved in only when every step
succeeded, so a failure leaves the output folder untouched. The folder handling (lock, staging
folders a later run can tell from a live one's, the manifest of one design per folder) is
:class:`ght_cad.core.outdir.OutputFolder`.
"""

from __future__ import annotations

import contextlib
import os
import time
from pathlib import Path
from typing import Any, Iterator

import numpy as np

from ...core.errors import GHTError
from .build import (GHT_DEFINITION, _developability_dict, _is_approximation, _is_composite, build_curves, build_surface, build_surfaces,
                    check_sheet, surface_summary, surface_view, surfaces_summary)
from .optimize import optimize_design
from .outputs import (_jsonable, brep_shapes, curve_edges, pattern_report, plate_solids, plot_pattern, shared_edge_count,
                      unroll_surfaces)
from .report import report_markdown
from .outputs import design_plates, resolve_design_sheets
from .schema import FIGURE_NAMES, FILE_NAMES, SHAPE_NAMES, Design


def _versions() -> dict[str, str]:
    import platform

    from ... import __version__

    out = {"ght_cad": __version__, "python": platform.python_version(), "numpy": np.__version__}
    try:
        import scipy

        out["scipy"] = scipy.__version__
    except ImportError:  # pragma: no cover
        pass
    return out


def _curve_max_curvature(c: Any) -> float | None:
    """Largest curvature over 513 parameters where it is defined (``P' != 0``); None for a point."""
    from ...curves.curve import curvature_from_derivatives

    t = np.linspace(0, 1, 513)
    kappa = curvature_from_derivatives(c.derivative(t, 1), c.derivative(t, 2))
    fin = kappa[np.isfinite(kappa)]
    return float(fin.max()) if fin.size else None


def _table_entry(sheet: Any) -> dict[str, Any]:
    """``[sheet] k_factor_table``: the table's name, its rows and the ``R/T`` K was read at."""
    tab = sheet.k_factor_table
    if tab is None:
        return {}
    return {"k_factor_table": {"name": tab.name, "ratios": list(tab.ratios), "k_factors": list(tab.k_factors),
                               "source": tab.source}, "k_factor_ratio": sheet.k_factor_ratio}


def _curves_report(curves: dict[str, Any]) -> list[dict[str, Any]]:
    """Per curve: degree, dimension, shape parameters, control points, arc length, max curvature."""
    return [
        {
            "name": k,
            "degree": c.degree,
            "dim": c.dim,
            "mu": c.mu,
            "nu": c.nu,
            "gamma": c.gamma,
            "control_points": c.control_points.tolist(),
            "arc_length": c.arc_length(),
            "curvature_max": _curve_max_curvature(c),
        }
        for k, c in curves.items()
    ]


def _shell_plate_report(design: Design, builts: list[Any], plates: list[Any], sheets: list[Any],
                        rails: list[Any]) -> dict[str, Any]:
    """``report["plate"]`` of a ``[[surfaces]]`` design with a ``[sheet]``: the totals, per surface
    its sheet, which way its material goes, its plates' volumes against the closed form
    ``T A + σ (T²/2) ∫ 2H dA``, and per shared rail how the plates meet
    (:func:`ght_cad.app.design.shell_sheet.rail_joints`)."""
    from .shell_sheet import rail_joints

    rows = []
    for b, sh in zip(builts, sheets):
        mine = [p for p in plates if p.name == b.design.name or str(p.name).startswith(f"{b.design.name}.")]
        closed = [p.closed_form_volume for p in mine]
        rows.append({**sh.as_dict(), "solids": [p.name for p in mine],
                     "volume": float(sum(p.volume for p in mine)) if mine else 0.0,
                     "volume_closed_form": None if None in closed else float(sum(closed))})
    closed_all = [r["volume_closed_form"] for r in rows]
    return {"valid": True, "solids": len(plates), "volume": float(sum(r["volume"] for r in rows)),
            "volume_closed_form": None if None in closed_all else float(sum(closed_all)),
            **design.sheet.to_sheet().as_dict(), "side_reference": design.sheet.side_reference,
            "surfaces": rows, "joints": rail_joints(builts, sheets, rails)}


@contextlib.contextmanager
def _naming(design: Design) -> Iterator[None]:
    """A refusal from a later stage (unrolling, the B-rep, ...) that names neither the design file
    nor a key gets both: the file and the key of the surface(s) (one line for the command line)."""
    try:
        yield
    except GHTError as exc:
        msg = " ".join(str(exc).split())
        if msg.startswith(f"{design.source}:"):
            raise
        key = design.surface.key if design.surface is not None else "surfaces" if design.surfaces else "curves"
        text = f"{design.source}: key '{key}': {msg}"
        try:
            named = type(exc)(text)
        except TypeError:  # a subclass with another constructor
            named = GHTError(text)
        raise named from None


def run_design(design: Design, out_dir: str | os.PathLike, *, progress: bool = True, wait: bool = False,
               timeout: float | None = None, chord_tol: float | None = None) -> dict[str, Any]:
    """Run the whole pipeline of a design and write its outputs into ``out_dir``.

    Steps: GHT curves (+ joins, measured) → surface (developable from control planes, or a ruled
    strip between two curves) → shape-parameter optimization (if ``[optimize]``) → developability
    degree → B-rep face → STEP (face + curve edges) → flat pattern (DXF, SVG) → PNG figures
    (basis, curve, curvature, surface, flat_pattern, convergence) → ``report.json`` and
    ``report.md``. File names: ``model.step``, ``flat_pattern.dxf``, ``flat_pattern.svg``,
    ``report.json``, ``report.md``, ``<figure>.png``.

    The output folder holds one design (:class:`ght_cad.core.outdir.OutputFolder`): it is locked for
    the whole run (a second run on it waits with ``wait`` or is refused), everything is computed
    into a staging folder beside ``out_dir`` and moved in only when every step has succeeded (a
    new ``out_dir`` appears by one rename); then the files the previous run listed in its
    manifest and this run did not write again are removed, files a person put there are kept.
    ``report["files"]`` lists every file this run wrote (the manifest). On any
    error the staging folder is removed and ``out_dir`` is untouched.

    Args:
        design: a validated :class:`Design`.
        out_dir: output folder.
        progress: progress bar on stderr when it is a terminal (and a line when it has to wait).
        wait: wait while another process writes ``out_dir`` instead of refusing.
        timeout: with ``wait``, give up after this many seconds (None: no limit).
        chord_tol: DXF/SVG outline chord tolerance in the design's units; it takes precedence
            over the file's ``[outputs] chord_tol`` (None: that key, else 1e-3 mm,
            :attr:`ght_cad.pattern.flat_pattern.FlatPattern.chord_tol`).

    Returns:
        The report dictionary (the content of ``report.json``).

    Raises:
        FolderBusy: ``out_dir`` is in use by another live process (message: folder and pid).
        GHTError: degenerate geometry, non-developable surface, ...; nothing is written.
    """
    import sys

    from ...core.outdir import OutputFolder
    from ...core.progress import progress_enabled

    t_start = time.perf_counter()
    if not os.fspath(out_dir).strip():  # Path("") would be the current folder
        raise GHTError(f"output folder path {os.fspath(out_dir)!r} is empty; allowed: a folder path")
    out = Path(out_dir)
    want_files = set(design.outputs.files)
    chord_tol = design.outputs.chord_tol if chord_tol is None else chord_tol  # --chord-tol over the file
    from ...cad import KERNEL_HINT, kernel_available

    # without a kernel (core-only: FreeCAD's Python) everything but the B-rep and STEP is computed
    use_kernel = kernel_available()
    if "step" in want_files and not use_kernel:
        raise GHTError(f"{design.source}: outputs.files asks for 'step', which {KERNEL_HINT}; "
                       "or leave 'step' out of outputs.files")
    want_figs = set(design.outputs.figures)
    steps = ["curves", "surface", "optimize", "measure", "B-rep + STEP", "flat pattern", "figures", "report"]
    show = bool(progress) and progress_enabled()
    report: dict[str, Any] = {
        "name": design.name,
        "source": design.source,
        "units": design.units,
        "ght_definition": GHT_DEFINITION,
        "design": design.to_dict(),
    }

    def step(name: str) -> None:
        if show:
            i = steps.index(name) + 1
            sys.stderr.write(f"[{i}/{len(steps)}] {design.name}: {name} ({time.perf_counter() - t_start:.1f} s)\n")
            sys.stderr.flush()

    def waiting(busy: Any) -> None:  # one line on stderr when the run has to wait for another
        who = f"pid {busy.pid}" + (f" ({busy.owner})" if busy.owner else "") if busy.pid is not None else "another process"
        sys.stderr.write(f"ght-cad: waiting for {who}, which writes {busy.path}\n")
        sys.stderr.flush()

    with OutputFolder(out, wait=wait, timeout=timeout, on_wait=waiting) as stage, _naming(design):
        # 1. curves
        step("curves")
        curves, joins = build_curves(design)
        report["curves"] = _curves_report(curves)
        report["joins"] = joins

        built = None
        builts: list[Any] = []
        opt = None
        if len(design.surfaces) > 1:
            # 2. surfaces ([[surfaces]]: each built as if it were the only one)
            step("surface")
            builts = build_surfaces(design, curves)
            shell = None
            if design.sheet is not None:
                # [sheet]: every surface's own sheet (the material on one side of the shell), checked on
                # every surface before anything else is computed (a refusal names the surface)
                shell_sheets, shell_rails, builts = resolve_design_sheets(builts)
                shell = (shell_sheets, shell_rails)
            report["developability_initial"] = surfaces_summary(builts)["developability"]
            step("measure")
            report.update(surfaces_summary(builts))
        elif design.surface is not None:
            # 2. surface
            step("surface")
            try:
                built = build_surface(design, curves=curves)
                report["developability_initial"] = _developability_dict(built.surface)
            except GHTError as exc:
                if design.optimize is None:
                    raise
                # the file's values are one rejected candidate; the optimization may find admissible ones
                report["developability_initial"] = None
                report["initial_surface_error"] = " ".join(str(exc).split())
            if design.optimize is None and built is not None:
                # [sheet]: the plate's check (the one the B-rep and the flat pattern apply) before anything
                # else is computed; with [optimize] every candidate is checked and so is the result
                check_sheet(built.design, built.surface)  # its K read from k_factor_table at its R/T, if any
            # 3. optimization
            if design.optimize is not None:
                step("optimize")
                opt = optimize_design(design, progress=progress, curves=curves)
                if design.surface.type in ("curves", "rails"):
                    # the strip's boundary curves (and the curves joined to them) take the optimized
                    # shape parameters: STEP curve edges, figures and the report show those
                    curves, joins = build_curves(design, opt.shape)
                    report["curves"] = _curves_report(curves)
                    report["joins"] = joins
                built = build_surface(design, opt.shape, curves=curves)
                if design.sheet is not None and design.sheet.k_factor_table is not None:
                    # candidates were checked with the table's largest K; the result with its own (R/T)
                    check_sheet(built.design, built.surface)
                report["optimization"] = opt.summary()
            # 4. measures
            step("measure")
            report.update(surface_summary(built))
            builts = [built]
        if builts:
            # 5. B-rep
            step("B-rep + STEP")
            if not use_kernel:
                report["brep"] = {"skipped": f"the B-rep {KERNEL_HINT}"}
            else:
                face = brep_shapes(builts)
                from ...cad.occ import is_valid

                valid = is_valid(face)
                nfaces = len(face.faces()) if hasattr(face, "faces") else 1
                report["brep"] = {"valid": bool(valid), "area": float(face.area), "faces": nfaces}
                if len(builts) > 1 or _is_composite(built.surface) or nfaces > 1:
                    report["brep"]["shape"] = "shell"
                    report["brep"]["shared_edges"] = shared_edge_count(face)
                if built is not None and _is_composite(built.surface):
                    from ...cad.developable_faces import joint_normal_deviation

                    report["brep"]["joint_normal_deviation_deg"] = [float(x) for x in joint_normal_deviation(face)]
                if not valid:
                    raise GHTError(f"{design.source}: the B-rep of the surface is not valid (BRepCheck)")
                edges = curve_edges(curves)
                report["brep"]["curve_edges"] = len(edges)
                plates = plate_solids(built) if built is not None else []  # [sheet]: the plate as solid(s), faces inside/outside/edgeN
                if built is None and design.sheet is not None:
                    # [[surfaces]] with [sheet]: one named plate per surface (per strip), faces <name>.inside, ...
                    plates = design_plates(builts)[0]
                    report["plate"] = _shell_plate_report(design, builts, plates, *shell)
                elif plates:
                    closed = [p.closed_form_volume for p in plates]
                    report["plate"] = {"valid": True, "solids": len(plates), "volume": float(sum(p.volume for p in plates)),
                                       # V = T A + σ (T²/2) ∫ 2H dA of the exact plates (ght_cad.sheetmetal.plate.plate_volume)
                                       "volume_closed_form": None if None in closed else float(sum(closed)),
                                       **built.design.sheet.to_sheet().as_dict(), **_table_entry(built.design.sheet)}
                if "step" in want_files:
                    if plates:
                        from ...cad.sheet_solid import write_plate_step

                        write_plate_step(plates, stage.path(FILE_NAMES["step"]), units=design.units, extra=edges,
                                         product=design.name)
                    else:
                        from ...cad.occ import write_step

                        write_step([face] + edges, stage.path(FILE_NAMES["step"]), units=design.units, product=design.name)
            # 6. flat pattern
            step("flat pattern")
            pattern = unroll_surfaces(builts)
            report["flat_pattern"] = pattern_report(pattern)
            if built is not None and _is_approximation(built.surface):  # every panel's flat area and label
                from .approximate import approximation_report

                report["surface"]["approximation"] = approximation_report(built.surface.result, pattern,
                                                                          name=design.name, method=built.surface.method,
                                                                          info=False)
            if "dxf" in want_files:
                pattern.export_dxf(stage.path(FILE_NAMES["dxf"]), chord_tol=chord_tol)
            if "svg" in want_files:
                pattern.export_svg(stage.path(FILE_NAMES["svg"]), chord_tol=chord_tol)
        else:
            pattern = None
            if "step" in want_files and curves:
                from ...cad.occ import write_step

                write_step(curve_edges(curves), stage.path(FILE_NAMES["step"]), units=design.units, product=design.name)

        # 7. figures
        step("figures")
        from ...curves import plotting as P

        if "basis" in want_figs:
            if built is not None and design.surface is not None and design.surface.type == "composite":
                deg = max(sg.dual_curve.degree for sg in built.surface.segments)
                params = [(0.0, 0.0, -1.0), (0.0, 0.0, 1.0)] + [(g.mu, g.nu, g.gamma) for g in design.surface.segments or []]
                params += [tuple(built.shape[f"{g.name}.{k}"] for k in SHAPE_NAMES) for g in design.surface.segments or []]
            elif built is not None and design.surface is not None and design.surface.type == "planes":
                deg = built.surface.dual_curve.degree
                sh = built.shape
                params = [(0.0, 0.0, -1.0), (0.0, 0.0, 1.0), (design.surface.mu, design.surface.nu, design.surface.gamma),
                          (sh["mu"], sh["nu"], sh["gamma"])]
            elif curves:
                c0 = next(iter(curves.values()))
                deg = c0.degree
                params = [(0.0, 0.0, -1.0), (0.0, 0.0, 1.0), (c0.mu, c0.nu, c0.gamma)]
            else:  # pragma: no cover - validation guarantees curves or a surface
                deg, params = 3, [(0.0, 0.0, 0.0)]
            uniq = []
            for p in params:
                if p not in uniq:
                    uniq.append(p)
            # the basis figure stops at MAX_PLOT_DEGREE (a plot of more functions is unreadable)
            P.plot_basis(stage.path(FIGURE_NAMES["basis"]), min(max(deg, 2), P.MAX_PLOT_DEGREE), uniq)
        if "curve" in want_figs and curves:
            P.plot_curve(list(curves.values()), stage.path(FIGURE_NAMES["curve"]))
        if "curvature" in want_figs and curves:
            P.plot_curvature(list(curves.values()), stage.path(FIGURE_NAMES["curvature"]))
        if "surface" in want_figs and builts:
            P.plot_surface(surface_view(builts), stage.path(FIGURE_NAMES["surface"]), title=f"{design.name}: surface")
        if "flat_pattern" in want_figs and pattern is not None:
            plot_pattern(pattern, stage.path(FIGURE_NAMES["flat_pattern"]), title=design.name)
            if pattern.sheet is not None:  # roll-bending chart of the sheet's bend lines
                pattern.plot_roll_chart(stage.path("forming.png"), title=f"{design.name}: roll bending")
        if "deviation" in want_figs and built is not None and _is_approximation(built.surface):
            from .approximate import plot_deviation  # the map ght-cad approximate draws

            plot_deviation(built.surface.result, stage.path(FIGURE_NAMES["deviation"]))
        if "convergence" in want_figs and opt is not None:
            P.plot_convergence({f"{opt.method} ({opt.objective})": opt.history},
                               stage.path(FIGURE_NAMES["convergence"]), title=f"{design.name}: optimizer convergence")

        # 8. report
        step("report")
        files = stage.files()
        if "json" in want_files:
            files.append(FILE_NAMES["json"])
        if "md" in want_files:
            files.append(FILE_NAMES["md"])
        report["files"] = sorted(files)
        report["out_dir"] = str(out)
        report["versions"] = _versions()
        report["elapsed_s"] = time.perf_counter() - t_start
        report = _jsonable(report)
        from ...core.io import write_text_atomic
        import json

        if "json" in want_files:
            write_text_atomic(stage.path(FILE_NAMES["json"]), json.dumps(report, indent=2) + "\n")
        if "md" in want_files:
            write_text_atomic(stage.path(FILE_NAMES["md"]), report_markdown(report))
        stage.commit()
    return report
