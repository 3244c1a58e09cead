r"""``ght-cad approximate``: developable panels for a STEP face that is not developable (issue 24).

Application layer: reads the face from a STEP file, runs :func:`ght_cad.approximate`, and writes
one output folder (locked, staged and committed by :class:`ght_cad.core.outdir.OutputFolder`):

* ``panels.step``: the panels as B-spline faces of degree 1 across the rulings, sewn into one
  shell (:func:`ght_cad.cad.approximate.panels_shell`);
* ``flat.dxf`` / ``flat.svg``: every panel's flat pattern on one sheet, seams marked
  (:func:`ght_cad.unroll.unroll_composite`: matching marks ``E<k>`` on the two panels of a seam);
* ``deviation.png``: the signed deviation of the panels from the target over its parameters;
* ``report.json`` / ``report.md``: per panel max deviation out/in, θ_max, 3-D and flat area and the
  method it got (loft or dual); the method asked for (``--method``), the panel count, the largest
  deviation and the files.

Progress: the core's steps (direction chosen, each march, the dual fits, each attempt's deviation)
are printed to stderr as they happen, as ``ght-cad run`` prints its steps: only when stderr is a
terminal (or ``GHT_CAD_PROGRESS=1``; :func:`ght_cad.core.progress.progress_enabled`) and not with
``--no-progress``.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .design.approximate import (approximation_report, panel_pattern, panel_plates, panel_sheets,  # noqa: F401
                                 plot_deviation, report_markdown)
from ..approximation.target import TRIM_ALLOWED, TrimmedTargetError, trim_words
from ..core.errors import GHTError
from .design.schema.constants import APPROX_DIRECTIONS, APPROX_METHODS

__all__ = ["add_parser", "cmd_approximate", "write_outputs", "plot_deviation", "report_markdown", "approximation_report",
           "panel_pattern", "panel_plates"]


def add_parser(sub: Any, common: Callable[[argparse.ArgumentParser], None], epilog: str = "") -> None:
    """Register the ``approximate`` sub-command on the ``ght-cad`` sub-parsers ``sub``."""
    sp = sub.add_parser(
        "approximate",
        help="cover a double-curved STEP face with developable panels within a tolerance",
        description="Cover a face that is not developable (a spherical cap, a hull side) with exactly "
        "developable panels: strips between isolines of the face, each the developable loft between its "
        "two seam curves, seams moved off the face so the deviation is split both ways and shared exactly "
        "by neighbouring panels. Writes panels.step (one sewn shell), flat.dxf/flat.svg (all flat patterns "
        "with seam marks), deviation.png and report.json/report.md into --out. Exit 2 when --tol cannot be "
        "met with --max-panels panels (the message names the best deviation reached).",
        epilog=epilog,
    )
    sp.add_argument("target", metavar="TARGET.step", help="STEP file holding the face to approximate")
    sp.add_argument("--tol", type=float, required=True, metavar="T", help="largest deviation, both ways (model units)")
    sp.add_argument("--out", required=True, metavar="DIR", help="output folder")
    sp.add_argument("--max-panels", type=int, default=64, metavar="N", help="largest panel count accepted (default 64)")
    sp.add_argument("--direction", choices=APPROX_DIRECTIONS, default="auto",
                    help="parameter the rulings run along, or diagonal/antidiagonal: seams along the isolines of "
                         "u+v / u-v of the normalized parameter box (default auto: fewest strips estimated)")
    sp.add_argument("--method", choices=APPROX_METHODS, default="auto",
                    help="how each strip is fitted: auto (default: per strip the closer of the rails loft and the "
                         "dual fit of the target's tangent planes), loft (rails lofts only) or dual (the dual fit "
                         "wherever it is usable)")
    sp.add_argument("--untrimmed", action="store_true",
                    help="a trimmed face (holes, or an outline inside its surface's (u, v) box) is refused unless "
                         "given this: cover the underlying surface over the face's whole (u, v) box knowingly "
                         "(report.json records the covered fraction under info.trim)")
    sp.add_argument("--no-progress", action="store_true", help="no progress lines on stderr even on a terminal")
    sp.add_argument("--face", type=int, default=1, metavar="N", help="face number, 1-based in file order (default 1)")
    sp.add_argument("--thickness", type=float, metavar="T",
                    help="sheet thickness: panels.step holds one plate solid per panel and the flat patterns are "
                         "the neutral surfaces at K*T from the panels (spec 6.1), as a design's [sheet]")
    sp.add_argument("--k-factor", type=float, metavar="K", help="ANSI K-factor in [0, 1] (default 0.5; with --thickness)")
    sp.add_argument("--din-k-factor", type=float, metavar="k", help="DIN k-factor k = 2K in [0, 2] (with --thickness)")
    sp.add_argument("--side", choices=("normal", "reverse"),
                    help="material along the panels' normal (normal, default) or against it (reverse)")
    common(sp)
    sp.set_defaults(func=cmd_approximate)


def _json_default(o: Any) -> Any:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(type(o).__name__)


def write_outputs(result: Any, folder: Any, *, name: str = "target", units: str = "mm",
                  sheet: Any = None, target: Any = None, method: str = "auto") -> dict[str, Any]:
    """Write panels.step, flat.dxf, flat.svg, deviation.png, report.json and report.md into the
    open :class:`ght_cad.core.outdir.OutputFolder` ``folder``; returns the report dict. With a sheet of
    T > 0 the STEP file holds one plate solid per panel and the flat patterns are the neutral
    surfaces (:func:`panel_plates`, :func:`panel_pattern`), ``side`` measured on the normal of the
    ``target`` (:func:`panel_sheets`; needed with a sheet); ``method``: the one asked for, recorded
    in the report."""
    from ..cad.approximate import panels_shell
    from ..cad.occ import write_step
    from ..core.io import atomic_write, strict_json

    sheets = panel_sheets(result, target, sheet)
    if sheets is not None:
        from ..cad.sheet_solid import write_plate_step

        plates = panel_plates(result, sheets, name)
        write_plate_step(plates, folder.path("panels.step"), units=units, product=name)
    else:
        write_step(panels_shell(result), folder.path("panels.step"), units=units)
    pattern = panel_pattern(result, sheets, units=units)
    pattern.export_dxf(folder.path("flat.dxf"))
    pattern.export_svg(folder.path("flat.svg"))
    plot_deviation(result, folder.path("deviation.png"), title=None)
    report = approximation_report(result, pattern, name=name, method=method)
    if sheet is not None:
        report["sheet"] = sheet.as_dict()
        if not sheet.is_zero:
            report["plate"] = {"solids": len(plates), "volume": float(sum(p.volume for p in plates))}
    names = ["panels.step", "flat.dxf", "flat.svg", "deviation.png", "report.json", "report.md"]
    report["files"] = names
    report["tool"] = "ght-cad"
    with atomic_write(folder.path("report.json")) as fh:
        fh.write(json.dumps(strict_json(report), indent=2, default=_json_default, allow_nan=False))
    with atomic_write(folder.path("report.md")) as fh:
        fh.write(report_markdown(report))
    return report


def _progress_lines(args: argparse.Namespace) -> Callable[[str], None] | None:
    """The core's ``progress`` callback: each line to stderr with the elapsed time, ``ght-cad run``'s
    convention (a terminal or ``GHT_CAD_PROGRESS=1``, not ``--no-progress``); None otherwise."""
    from ..core.progress import progress_enabled

    if getattr(args, "no_progress", False) or not progress_enabled():
        return None
    t0 = time.perf_counter()

    def say(line: str) -> None:
        sys.stderr.write(f"approximate: {line.strip()} ({time.perf_counter() - t0:.1f} s)\n")
        sys.stderr.flush()

    return say


def cmd_approximate(args: argparse.Namespace) -> int:
    """``ght-cad approximate TARGET.step --tol T --out DIR``."""
    from ..cad.approximate import step_target
    from ..core.outdir import OutputFolder
    from ..approximation import approximate
    from ..sheetmetal.sheet import make_sheet

    path = Path(args.target)
    if path.suffix.lower() not in (".step", ".stp"):
        raise GHTError(f"{path}: TARGET must be a STEP file (.step/.stp)")
    if not path.is_file():
        raise FileNotFoundError(2, "No such file", str(path))
    if not (isinstance(args.tol, float) and np.isfinite(args.tol) and args.tol > 0):
        raise GHTError(f"{path}: --tol={args.tol!r} is not allowed; it must be a length > 0")
    try:
        sheet = make_sheet(args.thickness, args.k_factor, din_k_factor=args.din_k_factor, side=args.side or "normal")
        target = step_target(path, args.face - 1)
        result = approximate(target, args.tol, max_panels=args.max_panels, direction=args.direction,
                             method=args.method, progress=_progress_lines(args), untrimmed=args.untrimmed)
    except TrimmedTargetError as exc:
        raise GHTError(f"{path}: face {args.face} is {trim_words(exc.covered, exc.holes)}; {TRIM_ALLOWED}, or "
                       "--untrimmed to cover the underlying surface over its whole (u, v) box knowingly") from None
    except GHTError as exc:
        raise GHTError(f"{path}: {' '.join(str(exc).split())}") from None
    with OutputFolder(args.out) as folder:
        report = write_outputs(result, folder, name=path.stem, sheet=sheet, target=target, method=args.method)
        folder.commit()
    summary = {"command": "approximate", "target": str(path), "method": args.method, "panels": report["panels"],
               "tol": report["tol"],
               "max_deviation": report["max_deviation"], "out": str(args.out), "files": report["files"]}
    if getattr(args, "json", False):
        from .commands.common import dumps

        args._json_out = dumps({"ok": True, **summary})
    else:
        print(f"{path.name}: {report['panels']} developable panels, max deviation {report['max_deviation']:.4g} "
              f"(tol {report['tol']:g}) -> {args.out}")
    return 0
