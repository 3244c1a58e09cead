"""``ght-cad unroll``: a design's surfaces, or the faces and sheet solids of a STEP file, to flat patterns.

Moved from :mod:`ght_cad.app.cli` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from .common import _check_suffix, _chord_tol, _emit, _outputs_text, _PNG, _write_staged, EXIT_OK, UsageError
from .design import _load


def cmd_unroll(args: argparse.Namespace) -> int:
    """``ght-cad unroll``: flat pattern of a design's surface, or of the faces of a STEP file."""
    _check_suffix("--dxf", args.dxf, (".dxf",))
    _check_suffix("--svg", args.svg, (".svg",))
    _check_suffix("--png", args.png, _PNG)
    _check_suffix("--forming-png", args.forming_png, _PNG)
    _check_suffix("--plate-step", args.plate_step, (".step", ".stp"))
    if Path(args.design).suffix.lower() in (".step", ".stp"):
        return _unroll_step(args)
    for opt, val in (("--face", args.face), ("--best-effort", args.best_effort or None), ("--units", args.units),
                     ("--tol-deg", args.tol_deg), ("--rulings", args.rulings), ("--thickness", args.thickness),
                     ("--k-factor", args.k_factor), ("--din-k-factor", args.din_k_factor), ("--side", args.side),
                     ("--jobs", args.jobs), ("--scheduler", args.scheduler), ("--k-factor-table", args.k_factor_table),
                     ("--base-face", args.base_face), ("--bend-lines", args.bend_lines),
                     ("--allow-split", args.allow_split or None), ("--plate-step", args.plate_step)):
        if val is not None:
            raise UsageError(f"{opt} applies to STEP input only ({args.design} is a design file: give the sheet "
                             "in its [sheet] table); allowed for design files: --dxf, --svg, --png, --forming-png, --json")
    from ..design import build_surfaces, unroll_surfaces

    design = _load(args)
    if not design.surfaces:
        from ..design import build_surface

        build_surface(design)  # the error naming the missing [surface]
    pattern = unroll_surfaces(build_surfaces(design))
    result: dict[str, Any] = {"command": "unroll", "name": design.name, "errors": _errors_dict(pattern), "outputs": {}}
    _sheet_result(result, pattern)
    result["outputs"] = _write_pattern(args, pattern, design.name)

    def text(r: dict[str, Any]) -> str:
        s = f"{r['name']}: flat pattern errors " + ", ".join(
            f"{k}={v:.2e}" for k, v in r["errors"].items() if isinstance(v, (int, float))
        )
        out = _outputs_text(r)
        return s + _sheet_text(r, pattern) + ("\n" + out if out else "")

    _emit(args, result, text)
    return EXIT_OK


def _write_pattern(args: argparse.Namespace, pattern: Any, title: str) -> dict[str, str]:
    """Write ``--dxf``/``--svg``/``--png`` all or nothing; returns ``{kind: path}``.

    The files are staged beside their targets and moved into place only when every one was
    written, so a failure leaves neither a partial file nor a partial set.
    """
    from ..design import plot_pattern

    if args.forming_png and pattern.sheet is None:
        raise UsageError(f"--forming-png needs a sheet thickness (no thickness was given for {title}); "
                         "allowed: with --thickness, --k-factor on a plate solid, or a design's [sheet] table")
    tol = _chord_tol(args)
    return _write_staged([("dxf", args.dxf, lambda path: pattern.export_dxf(path, chord_tol=tol)),
                          ("svg", args.svg, lambda path: pattern.export_svg(path, chord_tol=tol)),
                          ("png", args.png, lambda path: plot_pattern(pattern, path, title=title)),
                          ("forming_png", args.forming_png, lambda path: pattern.plot_roll_chart(path, title=title))])


def _sheet_result(result: dict[str, Any], pattern: Any) -> None:
    """Sheet data of every panel (thickness, K, side, edge lengths inside/neutral/outside, forming
    rows) into the JSON result (no chart samples)."""
    sheets = []
    for p in pattern.panels:
        sh = p.info.get("sheet")
        if sh:
            sheets.append({"panel": p.label, **{k: v for k, v in sh.items() if k != "chart"}})
    if sheets:
        result["sheet"] = sheets


def _sheet_text(r: dict[str, Any], pattern: Any) -> str:
    if not r.get("sheet"):
        return ""
    lines = []
    for sh in r["sheet"]:
        lines.append(f"  {sh['panel']} edges (inside / neutral / outside length):")
        for e in sh["edges"]:
            lines.append(f"    {e['edge']}: {e['inside']:.9g} / {e['neutral']:.9g} / {e['outside']:.9g}")
    return "\n" + "\n".join(lines) + "\n" + pattern.forming_table()


def _unroll_step(args: argparse.Namespace) -> int:
    """``ght-cad unroll FILE.step``: one panel per (selected) face; refuses non-developable faces."""
    tol = 0.01 if args.tol_deg is None else args.tol_deg
    blank_opts = [o for o, v in (("--k-factor-table", args.k_factor_table), ("--base-face", args.base_face),
                                 ("--bend-lines", args.bend_lines), ("--allow-split", args.allow_split or None),
                                 ("--plate-step", args.plate_step)) if v is not None]
    if not args.face and not args.best_effort and args.jobs is None and not args.scheduler:
        from ..unfold_step import unfold_step

        blanks = unfold_step(args.design, units=args.units, thickness=args.thickness, k_factor=args.k_factor,
                             din_k_factor=args.din_k_factor, k_factor_table=args.k_factor_table,
                             base_face=args.base_face, bend_lines=args.bend_lines or "tangent",
                             allow_split=args.allow_split, tol_deg=tol,
                             rulings=args.rulings if args.rulings is not None else 8, force=bool(blank_opts))
        if blanks is not None:
            return _emit_blanks(args, blanks)
    elif blank_opts:
        raise UsageError(f"{', '.join(blank_opts)} apply to sheet solids (one blank per solid), not with --face, "
                         "--best-effort, --jobs or --scheduler")
    from ..design import unroll_step

    if args.jobs is not None and args.scheduler:
        raise UsageError("--jobs and --scheduler exclude each other: --jobs runs local processes, "
                         "--scheduler a Dask cluster's workers")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: allowed: an integer >= 1")
    res = unroll_step(args.design, faces=args.face, best_effort=args.best_effort, units=args.units,
                      tol_deg=tol, rulings=args.rulings if args.rulings is not None else 16,
                      thickness=args.thickness, k_factor=args.k_factor, din_k_factor=args.din_k_factor, side=args.side,
                      jobs=1 if args.jobs is None else args.jobs, scheduler=args.scheduler)
    pattern = res.pattern
    name = Path(args.design).name
    result: dict[str, Any] = {
        "command": "unroll",
        "name": name,
        "source": str(args.design),
        "units": res.units,
        "file_units": res.file_units,
        "face_count": res.face_count,
        "panels": len(pattern.panels),
        "area": float(pattern.area),
        "errors": _errors_dict(pattern),
        "faces": res.faces,
        "outputs": {},
    }
    if res.plate is not None:
        result["plate"] = res.plate
    if res.plates is not None:
        result["plates"] = res.plates
    _sheet_result(result, pattern)
    result["outputs"] = _write_pattern(args, pattern, name)

    def text(r: dict[str, Any]) -> str:
        lines = [f"{r['name']}: {r['panels']} panel(s) of {r['face_count']} face(s), units {r['units']}, "
                 f"flat area {r['area']:.9g}"]
        for f in r["faces"]:
            d = f.get("developability")
            dev = f", theta_max={d['theta_max']:.3e} deg" if d else ""
            lines.append(f"  F{f['face']}: {f['surface_type']} ({f['method']}){dev}, max rel. error "
                         f"{max(f['errors'].get(k, 0.0) for k in ('boundary_length', 'ruling_length', 'area')):.2e}")
        if r.get("plate"):
            pl = r["plate"]
            lines.append(f"  plate solid: inside face F{pl['inside_face']}, outside face F{pl['outside_face']}, "
                         f"thickness {pl['thickness']:.9g} (found by {pl['found_by']})")
        for pl in r.get("plates") or []:
            lines.append(f"  plate solid {pl['name'] or ''}: inside face F{pl['inside_face']}, outside face "
                         f"F{pl['outside_face']}, thickness {pl['thickness']:.9g}, side {pl['side']} (found by {pl['found_by']})")
        out = _outputs_text(r)
        return "\n".join(lines) + _sheet_text(r, pattern) + ("\n" + out if out else "")

    _emit(args, result, text)
    return EXIT_OK


def _emit_blanks(args: argparse.Namespace, res: Any) -> int:
    """Report and files of ``ght-cad unroll`` on sheet solids (:func:`ght_cad.app.unfold_step.unfold_step`)."""
    if args.side is not None:
        raise UsageError("--side does not apply to a sheet solid (its material side is the solid's own)")
    unf = res.unfolded
    pattern = unf.pattern
    name = Path(args.design).name
    result: dict[str, Any] = {"command": "unroll", "name": name, "source": str(args.design), "units": res.units,
                              "file_units": res.file_units, "face_count": res.face_count,
                              "panels": len(pattern.panels), "area": float(pattern.area),
                              "errors": _errors_dict(pattern), **{k: v for k, v in unf.as_dict().items() if k == "blanks"},
                              "outputs": {}}
    if args.forming_png:
        raise UsageError("--forming-png charts a single plate's roll bending; a sheet solid's blank has a bend table "
                         "instead (in the report)")

    def png(path: Path) -> None:
        from ..design import plot_pattern

        plot_pattern(pattern, path, title=name)

    def plate(path: Path) -> None:
        from ...cad.occ import write_step
        from ...cad.unfold_solid import blank_plates

        write_step(blank_plates(unf), path, units=res.units)

    result["outputs"] = _write_staged([("dxf", args.dxf, pattern.export_dxf), ("svg", args.svg, pattern.export_svg),
                                       ("png", args.png, png), ("plate_step", args.plate_step, plate)])

    def text(r: dict[str, Any]) -> str:
        lines = [f"{r['name']}: {len(r['blanks'])} blank(s) in {r['panels']} panel(s) from {r['face_count']} face(s), "
                 f"units {r['units']}, flat area {r['area']:.9g}"]
        for b in r["blanks"]:
            lines.append(f"  {b['name']}: thickness {b['thickness']:.9g}, base face F{b['base_face']}, skin faces "
                         f"{' '.join(f'F{n}' for n in b['faces'])}, area {b['area']:.9g}"
                         + (f", cut edges {' '.join(b['cut_edges'])}" if b["cut_edges"] else ""))
        lines.append(unf.bend_table())
        out = _outputs_text(r)
        return "\n".join(lines) + ("\n" + out if out else "")

    _emit(args, result, text)
    return EXIT_OK


def _errors_dict(pattern: Any) -> dict[str, Any]:
    from ..design import pattern_errors

    return pattern_errors(pattern)
