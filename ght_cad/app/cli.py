"""The ``ght-cad`` command line.

Subcommands::

    ght-cad demo --out DIR              the whole pipeline on the embedded default design
    ght-cad run DESIGN.toml --out DIR   the same from a design file (docs/design-files.md)
    ght-cad curve ...                   one GHT-Bézier curve: properties, STEP edge, plots
    ght-cad surface DESIGN.toml ...     developable surface of a design: measures, STEP face, view
    ght-cad optimize DESIGN.toml ...    shape-parameter optimization of a design's surface
    ght-cad unroll DESIGN.toml|FILE.step  flat pattern of a design's surface or a STEP file's faces
    ght-cad export DESIGN.toml FILE...  write a design's result to STEP/DXF/SVG/JSON/PNG by suffix
    ght-cad plot-basis ...              PNG of the GHT-Bernstein basis for chosen shape parameters
    ght-cad batch DESIGN... --out DIR   many designs (and [sweep] variants) in parallel or on Dask

Exit codes (stable, scripts may rely on them):

    0  success
    1  internal failure (a bug or a failing CAD kernel); the message says what failed
    2  bad input or usage: unknown option, unreadable or invalid design file, a value out of
       range (one line on stderr naming the file, the key and the allowed values), or a command
       that needs a CAD kernel where none is installed (the line names the extra to install)
    130 interrupted (Ctrl-C)

With ``--json`` the result (or ``{"ok": false, "error": ..., "exit_code": ...}``, also for usage
errors found by the argument parser) is printed to stdout as one JSON object and nothing else:
while the command runs, file descriptor 1 is redirected to stderr so that console output of the
CAD kernel (OCCT prints parse errors from C++) cannot corrupt it. Human-readable text goes to
stdout otherwise. A progress bar is drawn
on stderr only when stderr is a terminal. Heavy modules (numpy, scipy, matplotlib, OCP) are
imported inside the commands so that ``ght-cad --help`` is fast.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
import traceback
from typing import Any, Sequence

# The subcommands' handlers and helpers live in ght_cad.app.commands (issue 27); every name stays
# importable from here (and the parser reads the handlers from this module's namespace).
from .commands.batch import cmd_batch  # noqa: F401
from .commands.common import (_check_same_dimension, _check_suffix, _chord_tol, _clean, _emit, _fmt_point,
                              _json_default, _out_path, _outputs_text, _parse_floats, _parse_points, _Parser, _PNG,
                              _progress, _report_text, _STEP, _wait_args, _wants_json, _write_staged, add_wait_options,
                              dumps, EXIT_FAILURE, EXIT_INTERRUPTED, EXIT_OK, EXIT_USAGE, PROG, UsageError)  # noqa: F401
from .commands.curves import (cmd_curve, cmd_plot_basis)  # noqa: F401
from .commands.design import (_load, cmd_demo, cmd_optimize, cmd_run, cmd_surface)  # noqa: F401
from .commands.export import (_EXPORT_SUFFIXES, cmd_export)  # noqa: F401
from .commands.unroll import (_emit_blanks, _errors_dict, _sheet_result, _sheet_text, _unroll_step, _write_pattern,
                              cmd_unroll)  # noqa: F401

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_FAILURE", "EXIT_USAGE", "EXIT_INTERRUPTED"]


# ---------------------------------------------------------------------------------------------
# parser
# ---------------------------------------------------------------------------------------------
_EPILOG = (
    "exit codes: 0 success, 1 internal failure, 2 bad input or usage (one line on stderr), "
    "130 interrupted. With --json, stdout is exactly one JSON object, errors included "
    '({"ok": false, "exit_code": N, "error": ...}). Design files: see docs/design-files.md.'
)


def build_parser() -> argparse.ArgumentParser:
    """The argparse parser of ``ght-cad`` (one sub-parser per command)."""
    p = _Parser(
        prog=PROG,
        description="GHT-Bézier curves and developable surfaces: from control points or planes to "
        "B-rep (STEP) and flat patterns (DXF/SVG).",
        epilog=_EPILOG,
    )
    p.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    def common(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--json", action="store_true", help="print the result as one JSON object on stdout")

    def chord_tol_arg(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--chord-tol", type=float, metavar="TOL",
                        help="DXF/SVG outlines: largest distance between a curved edge and the arcs written for "
                             "it, in the pattern's units (default: the design file's [outputs] chord_tol, else "
                             "1e-3 mm; this option takes precedence; straight and circular edges are exact)")

    def design_arg(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("design", metavar="DESIGN.toml", help="design file (schema: docs/design-files.md)")

    sp = sub.add_parser(
        "demo",
        help="run the whole pipeline on the embedded default design",
        description="Run the whole pipeline on the embedded default design (a developable hull plate "
        "from control planes): GHT curves and planes -> developable surface -> shape-parameter "
        "optimization -> B-rep -> STEP, DXF and SVG flat patterns, PNG figures, JSON and Markdown report.",
        epilog=_EPILOG,
    )
    sp.add_argument("--out", required=True, metavar="DIR", type=_out_path, help="output folder (created; files are replaced atomically)")
    sp.add_argument("--quick", action="store_true", help="fewer optimizer iterations (for smoke tests)")
    sp.add_argument("--no-progress", action="store_true", help="no progress bar even on a terminal")
    chord_tol_arg(sp)
    add_wait_options(sp)
    common(sp)
    sp.set_defaults(func=cmd_demo)

    sp = sub.add_parser(
        "run",
        help="run the whole pipeline on a design file",
        description="Run the whole pipeline on DESIGN.toml. The file is validated first; an invalid "
        "file gives one line on stderr naming the file, the key and the allowed values (exit 2). "
        "Results are computed into a temporary folder beside --out and moved in only when "
        "everything succeeded, so a failure leaves --out untouched. --out holds one design: files "
        "an earlier run wrote and this one does not are removed, files you put there are kept. "
        "A second run on an --out in use is refused (exit 2) unless --wait is given.",
        epilog=_EPILOG,
    )
    design_arg(sp)
    sp.add_argument("--out", metavar="DIR", type=_out_path,
                    help="output folder (default: <DESIGN file name without .toml>-out in the current folder)")
    sp.add_argument("--no-progress", action="store_true", help="no progress bar even on a terminal")
    add_wait_options(sp)
    chord_tol_arg(sp)
    common(sp)
    sp.set_defaults(func=cmd_run)

    sp = sub.add_parser(
        "curve",
        help="one GHT-Bézier curve: properties, STEP edge, plots",
        description="Evaluate a GHT-Bézier curve P(t) = sum b_i,m(t; mu,nu,gamma) P_i: degree, arc "
        "length, curvature, end tangents; optionally a STEP edge (certified B-spline) and PNG plots.",
        epilog=_EPILOG,
    )
    sp.add_argument("--points", metavar="PTS", help="control points: 'x,y[,z] x,y[,z] ...' or JSON [[x,y],...] (>= 3 points)")
    sp.add_argument("--mu", type=float, default=0.0, help="shape parameter mu in [-1, 1] (default 0)")
    sp.add_argument("--nu", type=float, default=0.0, help="shape parameter nu in [-1, 1] (default 0)")
    sp.add_argument("--gamma", type=float, default=0.0, help="shape parameter gamma in [-1, 1] (default 0)")
    sp.add_argument("--step", metavar="FILE", help="write the curve as a STEP edge")
    sp.add_argument("--plot", metavar="PNG", help="plot of the curve with its control polygon (800x700 px)")
    sp.add_argument("--curvature-plot", metavar="PNG", help="plot of the curvature along the curve (900x500 px)")
    common(sp)
    sp.set_defaults(func=cmd_curve)

    sp = sub.add_parser(
        "surface",
        help="developable surface of a design: developability degree, STEP face, view",
        description="Build the surface of DESIGN.toml with its given shape parameters and report its "
        "developability degree (theta_max, theta_rms, DD, R; spec section 5).",
        epilog=_EPILOG,
    )
    design_arg(sp)
    sp.add_argument("--step", metavar="FILE", help="write the surface as a STEP face (a shell for a composite)")
    sp.add_argument("--plot", metavar="PNG", help="rendered view of the surface (900x700 px)")
    common(sp)
    sp.set_defaults(func=cmd_surface)

    sp = sub.add_parser(
        "optimize",
        help="optimize the shape parameters of a design's surface",
        description="Minimize the design's objective (AL, En, CVEn of the dual curve, or R, the "
        "developability objective of a curve-pair strip) over the shape parameters with the hybrid "
        "method (default), PSO, GWO or I-GWO. For a composite surface the measure is summed over the strips and every joint keeps "
        "its G1/G2/G3 order. Options override the design's [optimize] block.",
        epilog=_EPILOG,
    )
    design_arg(sp)
    sp.add_argument("--method", choices=("hybrid", "pso", "gwo", "igwo"),
                    help="optimizer (default hybrid: Sobol starts + L-BFGS-B finishes)")
    sp.add_argument("--objective", metavar="NAME", help="AL, En, CVEn or R")
    sp.add_argument("--iterations", type=int, metavar="N", help="iterations (>= 1)")
    sp.add_argument("--population", type=int, metavar="N", help="population size (>= 4)")
    sp.add_argument("--seed", type=int, metavar="S", help="random seed")
    sp.add_argument("--plot", metavar="PNG", help="convergence plot (800x500 px)")
    sp.add_argument("--no-progress", action="store_true", help="no progress bar even on a terminal")
    common(sp)
    sp.set_defaults(func=cmd_optimize)

    sp = sub.add_parser(
        "unroll",
        help="flat pattern (DXF, SVG, PNG) of a design's surface or of a STEP file's faces",
        description="Unroll a developable surface into the plane (spec section 6) and report the "
        "relative length and area errors of the pattern. FILE is a design file (.toml) or a STEP "
        "file (.step/.stp, detected by suffix) made by any CAD tool: every developable face "
        "(cylinder, cone, plane, extrusion, ruled B-spline) becomes one labelled panel F<n> "
        "(n = face number), with matching edge marks on edges shared by two faces; a sheet solid (bent "
        "part) gives ONE blank: its skin unfolded across the bends at the neutral radius R + K T, with bend "
        "lines and a bend table (--face or --best-effort unroll single faces instead). A face that is "
        "not developable within --tol-deg is refused (exit 2, naming the face and its theta_max "
        "and DD) unless --best-effort is given.",
        epilog=_EPILOG,
    )
    sp.add_argument("design", metavar="FILE", help="design file (.toml, docs/design-files.md) or STEP file (.step/.stp)")
    sp.add_argument("--dxf", metavar="FILE", help="write the pattern as DXF (layers OUTLINE, BEND, LABELS, MARKS)")
    sp.add_argument("--svg", metavar="FILE", help="write the pattern as SVG")
    sp.add_argument("--png", metavar="FILE", help="plot of the pattern (900x700 px)")
    sp.add_argument("--face", type=int, action="append", metavar="N",
                    help="STEP only: unroll face N (1-based, file order; repeatable; default all faces)")
    sp.add_argument("--best-effort", action="store_true",
                    help="STEP only: flatten non-developable faces anyway and report their distortion")
    sp.add_argument("--units", choices=("mm", "cm", "m", "in", "ft"),
                    help="STEP only: unit of the pattern (default: the file's length unit, else mm)")
    sp.add_argument("--tol-deg", type=float, metavar="DEG",
                    help="STEP only: largest accepted theta_max in degrees (default 0.01)")
    sp.add_argument("--rulings", type=int, metavar="N", help="STEP only: bend lines per face (default 16)")
    sp.add_argument("--thickness", type=float, metavar="T",
                    help="STEP only: sheet thickness; the pattern is the neutral surface at K*T from each face "
                         "(spec 6.1); a STEP plate solid gives its own thickness")
    sp.add_argument("--k-factor", type=float, metavar="K",
                    help="STEP only: ANSI K-factor in [0, 1] (default 0.5); given without --thickness on a "
                         "plate solid: unroll its inside face with the thickness between its faces")
    sp.add_argument("--din-k-factor", type=float, metavar="k", help="STEP only: DIN k-factor k = 2K in [0, 2]")
    sp.add_argument("--side", choices=("normal", "reverse"),
                    help="STEP only: material along the face normal (normal, default) or against it (reverse)")
    sp.add_argument("--forming-png", metavar="FILE",
                    help="roll-bending chart of a sheet pattern (neutral radius along the plate)")
    sp.add_argument("--k-factor-table", metavar="ansi|din|FILE",
                    help="STEP sheet solids: K per bend by R/T from a table (ansi, din or a file of 'R/T K' lines)")
    sp.add_argument("--base-face", type=int, metavar="N",
                    help="STEP sheet solids: the face (1-based, file order) that keeps its place in the blank "
                         "(default: the largest planar face)")
    sp.add_argument("--bend-lines", choices=("tangent", "centre"),
                    help="STEP sheet solids: draw both tangent lines of every bend (default) or its centre line")
    sp.add_argument("--allow-split", action="store_true",
                    help="STEP sheet solids: keep pieces that would overlap in the flat apart as separate panels")
    sp.add_argument("--plate-step", metavar="FILE",
                    help="STEP sheet solids: write every blank as a flat plate (outline extruded by T) for CAM")
    sp.add_argument("--jobs", type=int, metavar="N",
                    help="STEP only: unroll the faces in N local processes (default 1; panels identical to serial)")
    sp.add_argument("--scheduler", metavar="ADDRESS",
                    help="STEP only: unroll the faces on a dask.distributed cluster, e.g. tcp://127.0.0.1:8786")
    chord_tol_arg(sp)
    common(sp)
    sp.set_defaults(func=cmd_unroll)

    sp = sub.add_parser(
        "export",
        help="write a design's result to files chosen by suffix",
        description="Build the design (with its given shape parameters) and write each FILE by its "
        "suffix: .step/.stp (surface face, or a shell for a composite, and curves), .dxf/.svg (flat pattern), .json (report), "
        ".png (rendered surface).",
        epilog=_EPILOG,
    )
    design_arg(sp)
    sp.add_argument("files", nargs="+", metavar="FILE", help="output files (.step .stp .dxf .svg .json .png)")
    chord_tol_arg(sp)
    common(sp)
    sp.set_defaults(func=cmd_export)

    sp = sub.add_parser(
        "batch",
        help="run many designs (and [sweep] variants) in parallel processes or on a Dask cluster",
        description="Run every DESIGN.toml through the pipeline of 'ght-cad run' into DIR/<name>/ (the "
        "same files, written atomically), and write DIR/batch.json and DIR/batch.md with one row per "
        "design: status, error, flat area, theta_max, pattern error, optimization result, time and "
        "where it ran. A design with a [sweep] table expands into named variants (table and PNG in "
        "the summary). A bad design is reported and the others go on. Exit 0 if all succeeded, 2 if "
        "any design was bad input, 1 for internal failures.",
        epilog=_EPILOG,
    )
    sp.add_argument("designs", nargs="+", metavar="DESIGN.toml", help="design files (docs/design-files.md)")
    sp.add_argument("--out", required=True, metavar="DIR", type=_out_path, help="batch folder (created)")
    sp.add_argument("--jobs", type=int, metavar="N", help="local worker processes (default: the machine's cores)")
    sp.add_argument("--scheduler", metavar="ADDRESS",
                    help="dask.distributed scheduler, e.g. tcp://127.0.0.1:8786 (needs pip install 'ght_cad[dask]'; "
                    "start workers with --nthreads 1)")
    sp.add_argument("--no-progress", action="store_true", help="no progress bar even on a terminal")
    chord_tol_arg(sp)
    common(sp)
    sp.set_defaults(func=cmd_batch)

    sp = sub.add_parser(
        "plot-basis",
        help="PNG of the GHT-Bernstein basis for chosen shape parameters",
        description="Plot b_i,m(t; mu,nu,gamma) (or a derivative), one panel per --params triple, "
        "with the classical Bernstein basis dashed for comparison. 1200x800 px.",
        epilog=_EPILOG,
    )
    sp.add_argument("--degree", type=int, default=3, help="degree m, 2..200 (default 3)")
    sp.add_argument(
        "--params", action="append", metavar="MU,NU,GAMMA",
        help="shape parameters of one panel, each in [-1, 1] (repeatable; default four panels)",
    )
    sp.add_argument("--derivative", type=int, default=0, choices=(0, 1, 2, 3), help="derivative order")
    sp.add_argument("--out", required=True, metavar="PNG", type=_out_path, help="PNG file to write")
    common(sp)
    sp.set_defaults(func=cmd_plot_basis)

    from .approximate_cli import add_parser as _add_approximate  # issue 24: logic in its own module

    _add_approximate(sub, common, _EPILOG)
    return p


def _version() -> str:
    try:
        from .. import __version__

        return __version__
    except Exception:  # pragma: no cover
        return "unknown"


def _fail(args: argparse.Namespace | None, code: int, message: str) -> int:
    msg = " ".join(str(message).split())  # one line
    sys.stderr.write(f"{PROG}: error: {msg}\n")
    if args is not None and getattr(args, "json", False):
        args._json_out = dumps({"ok": False, "error": msg, "exit_code": code})
    return code


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``ght-cad``; returns the exit code (0 ok, 1 failure, 2 bad input, 130 Ctrl-C).

    With ``--json``, file descriptor 1 points to stderr while the command runs (C++ console
    output of the CAD kernel goes there) and the one JSON object is printed to the restored
    stdout at the end, for success and failure alike.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    _Parser.json_errors = _wants_json(argv)
    try:
        args = parser.parse_args(argv)
    finally:
        _Parser.json_errors = False
    if not getattr(args, "command", None):
        parser.print_help(sys.stderr)
        return EXIT_USAGE
    previous = _watch_sigint()
    try:
        if not getattr(args, "json", False):
            return _dispatch(args)
        saved = _redirect_stdout_to_stderr()
        try:
            code = _dispatch(args)
        finally:
            _restore_stdout(saved)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    out = getattr(args, "_json_out", None)
    if out is None:  # a command that returned without a result: still one JSON object
        out = dumps({"ok": code == EXIT_OK, "exit_code": code})
    sys.stdout.write(out + "\n")
    sys.stdout.flush()
    return code


def _redirect_stdout_to_stderr() -> int | None:
    """Point fd 1 at fd 2; returns a duplicate of the old fd 1 (None if fd 1 or 2 is unusable)."""
    for stream in (sys.stdout, sys.__stdout__):  # what was printed before goes to the real stdout
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):  # pragma: no cover - closed stdout
            pass
    try:
        saved = os.dup(1)
    except OSError:  # pragma: no cover - fd 1 closed
        return None
    try:
        os.dup2(2, 1)
    except OSError:  # pragma: no cover - fd 2 closed
        os.close(saved)
        return None
    return saved


def _restore_stdout(saved: int | None) -> None:
    """Undo :func:`_redirect_stdout_to_stderr` (flushing what Python buffered for the redirected fd 1)."""
    if saved is None:
        return
    for stream in (sys.stdout, sys.__stdout__):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):  # pragma: no cover
            pass
    os.dup2(saved, 1)
    os.close(saved)


#: Set by the SIGINT handler of :func:`_watch_sigint`: a Ctrl-C arrived during this run.
_SIGINT_SEEN = [False]


def _watch_sigint() -> Any:
    """Remember that Ctrl-C arrived, then raise KeyboardInterrupt as Python's default handler does.

    A Ctrl-C that lands while a C++ extension (OCP) is being imported can surface later as an
    unrelated ImportError of the half-initialized module; with this flag :func:`_dispatch` still
    reports "interrupted" with exit code 130. Installed only over Python's default handler
    (a shell that starts the command with SIGINT ignored keeps it ignored). Returns the handler
    to restore afterwards (None if nothing was installed).
    """
    _SIGINT_SEEN[0] = False
    try:
        previous = signal.getsignal(signal.SIGINT)
        if previous is not signal.default_int_handler:
            return None

        def handler(signum: int, frame: Any) -> None:
            _SIGINT_SEEN[0] = True
            signal.default_int_handler(signum, frame)

        signal.signal(signal.SIGINT, handler)
        return previous
    except ValueError:  # pragma: no cover - not the main thread (embedded use)
        return None


def _dispatch(args: argparse.Namespace) -> int:
    """Run ``args.func`` and map exceptions to exit codes (one line on stderr each)."""
    try:
        from ..core.errors import GHTError
    except Exception:  # pragma: no cover
        GHTError = ValueError  # type: ignore[assignment,misc]
    try:
        return int(args.func(args) or 0)
    except KeyboardInterrupt:
        return _fail(args, EXIT_INTERRUPTED, "interrupted")
    except UsageError as exc:
        return _fail(args, EXIT_USAGE, str(exc))
    except GHTError as exc:
        return _fail(args, EXIT_USAGE, str(exc))
    except (FileNotFoundError, IsADirectoryError, NotADirectoryError, FileExistsError, PermissionError) as exc:
        # a path the user gave cannot be read or written: bad input (the message names the path)
        reason = exc.strerror or str(exc)
        return _fail(args, EXIT_USAGE, reason if exc.filename is None else f"{reason}: {exc.filename}")
    except Exception as exc:  # noqa: BLE001 - exit code 1 for every internal failure
        if _SIGINT_SEEN[0]:  # e.g. an ImportError of a module Ctrl-C cut off half-way
            return _fail(args, EXIT_INTERRUPTED, "interrupted")
        from ..cad import KERNEL_HINT, is_missing_kernel

        if is_missing_kernel(exc):  # a core-only environment (e.g. FreeCAD's Python): not a bug
            return _fail(args, EXIT_USAGE, f"ght-cad {args.command}: this command {KERNEL_HINT} (No module named {exc.name!r})")
        if os.environ.get("GHT_CAD_DEBUG"):
            traceback.print_exc()
        return _fail(args, EXIT_FAILURE, f"internal failure: {type(exc).__name__}: {exc} (set GHT_CAD_DEBUG=1 for a traceback)")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
