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
import json
import math
import os
import signal
import sys
import traceback
from pathlib import Path
from typing import Any, Callable, Sequence

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_FAILURE", "EXIT_USAGE", "EXIT_INTERRUPTED"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130

PROG = "ght-cad"


class UsageError(Exception):
    """Bad command-line input detected by a command (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line on stderr and exit code 2.

    When the command line being parsed contains ``--json`` (set by :func:`main`), the error is
    also printed to stdout as one JSON object ``{"ok": false, "error": ..., "exit_code": 2}``.
    """

    json_errors = False

    def error(self, message: str) -> None:  # type: ignore[override]
        msg = " ".join(f"{message} (see '{self.prog} --help')".split())
        if _Parser.json_errors:
            sys.stdout.write(dumps({"ok": False, "error": f"{self.prog}: {msg}", "exit_code": EXIT_USAGE}) + "\n")
            sys.stdout.flush()
        self.exit(EXIT_USAGE, f"{self.prog}: error: {msg}\n")


def _wants_json(argv: Sequence[str]) -> bool:
    """True if ``argv`` asks for ``--json`` (argparse also accepts the prefixes ``--j``, ``--js``, ...)."""
    return any(a.startswith("--j") and "--json".startswith(a) for a in argv)


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------
def _json_default(o: Any) -> Any:
    try:
        import numpy as np

        if isinstance(o, np.ndarray):
            return o.tolist()
        if isinstance(o, np.generic):
            return o.item()
    except ImportError:  # pragma: no cover
        pass
    if isinstance(o, Path):
        return str(o)
    if hasattr(o, "as_dict"):
        return o.as_dict()
    return str(o)


def _clean(o: Any) -> Any:
    """Replace NaN/inf by None so the output is strict JSON."""
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {str(k): _clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_clean(v) for v in o]
    return o


def dumps(obj: Any) -> str:
    """Strict JSON text (numpy values converted, NaN/inf as null)."""
    return json.dumps(_clean(json.loads(json.dumps(obj, default=_json_default))), indent=2, allow_nan=False)


def _parse_floats(text: str, what: str) -> list[float]:
    try:
        vals = [float(x) for x in text.replace(",", " ").split()]
    except ValueError:
        raise UsageError(f"{what}={text!r} is not a list of numbers; write e.g. '0,0.5,-1'") from None
    return vals


def _parse_points(text: str, what: str = "--points") -> list[list[float]]:
    """Points from JSON (``[[0,0],[1,2]]``) or ``'x,y[,z] x,y[,z] ...'`` (space or ';' separated)."""
    s = text.strip()
    if s.startswith("["):
        try:
            pts = json.loads(s)
        except json.JSONDecodeError as exc:
            raise UsageError(f"{what} is not valid JSON: {exc}") from None
        if not isinstance(pts, list) or not all(isinstance(p, list) for p in pts):
            raise UsageError(f"{what} must be a JSON list of coordinate lists, e.g. [[0,0],[1,2],[3,0]]")
    else:
        groups = [g for g in s.replace(";", " ").split() if g]
        pts = []
        for g in groups:
            try:
                pts.append([float(x) for x in g.split(",")])
            except ValueError:
                raise UsageError(f"{what}: {g!r} is not a point; write points as 'x,y[,z]' separated by spaces") from None
    _check_same_dimension(pts, what)
    return pts


def _check_same_dimension(pts: list[list[float]], what: str) -> None:
    """Raise :class:`UsageError` naming the first point whose dimension differs from point 1's."""
    if not pts:
        return
    dim = len(pts[0])
    for i, pt in enumerate(pts[1:], start=2):
        if len(pt) != dim:
            raise UsageError(
                f"{what}: point {i} ({_fmt_point(pt)}) has dimension {len(pt)} but point 1 "
                f"({_fmt_point(pts[0])}) has dimension {dim}; all points need the same dimension"
            )


def _fmt_point(pt: list[Any]) -> str:
    return ",".join(f"{x:g}" if isinstance(x, (int, float)) else repr(x) for x in pt)


def _out_path(text: str) -> str:
    """``--out``'s value: an empty path is refused (it would silently mean the current folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"{text!r} is an empty path; allowed: a folder or file path "
                                         "(use '.' for the current folder)")
    return text


def _check_suffix(option: str, value: str | os.PathLike | None, allowed: Sequence[str]) -> None:
    """Raise :class:`UsageError` unless ``value`` (if given) ends in one of ``allowed`` (case-insensitive)."""
    if value is None:
        return
    suf = Path(value).suffix
    if suf.lower() not in allowed:
        raise UsageError(
            f"{option} {str(value)!r}: unknown suffix {suf!r}; allowed: {', '.join(allowed)}"
        )


def _progress(total: int | None, label: str) -> Any:
    from .progress import Progress

    return Progress(total, label)


def _emit(args: argparse.Namespace, result: dict[str, Any], text: Callable[[dict[str, Any]], str]) -> None:
    if getattr(args, "json", False):
        args._json_out = dumps({"ok": True, **result})  # printed by main() once stdout is restored
    else:
        print(text(result))


def _outputs_text(result: dict[str, Any]) -> str:
    lines = []
    for k, v in (result.get("outputs") or {}).items():
        lines.append(f"  {k}: {v}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------
# commands
# ---------------------------------------------------------------------------------------------
def cmd_plot_basis(args: argparse.Namespace) -> int:
    """``ght-cad plot-basis``: PNG of ``b_{i,m}(t; μ,ν,γ)`` (or a derivative), one panel per triple."""
    from .plotting import SIZES, plot_basis

    _check_suffix("--out", args.out, _PNG)
    params = []
    for p in args.params or ["0,0,-1", "0,0,0", "0,0,1", "-0.8,0.8,0"]:
        vals = _parse_floats(p, "--params")
        if len(vals) != 3:
            raise UsageError(f"--params {p!r} must be three numbers mu,nu,gamma each in [-1, 1]")
        params.append(tuple(vals))
    path = plot_basis(args.out, args.degree, params, derivative=args.derivative)
    result = {
        "command": "plot-basis",
        "degree": args.degree,
        "derivative": args.derivative,
        "params": [list(p) for p in params],
        "outputs": {"png": str(path)},
        "pixels": list(SIZES["basis"]),
    }
    _emit(args, result, lambda r: f"wrote {path}")
    return EXIT_OK


def cmd_curve(args: argparse.Namespace) -> int:
    """``ght-cad curve``: properties of ``P(t) = Σ b_{i,m}(t) P_i``; optional STEP edge and plots."""
    import numpy as np

    from .curve import GHTCurve

    if args.points is None:
        raise UsageError("--points is required, e.g. --points '0,0 1,2 3,2 4,0'")
    _check_suffix("--step", args.step, _STEP)
    _check_suffix("--plot", args.plot, _PNG)
    _check_suffix("--curvature-plot", args.curvature_plot, _PNG)
    from .curve import curvature_from_derivatives

    curve = GHTCurve(_parse_points(args.points), args.mu, args.nu, args.gamma)
    t = np.linspace(0.0, 1.0, 513)
    pts = curve.control_points
    point = float(np.max(np.ptp(pts, axis=0))) <= 1e-12 * float(np.max(np.abs(pts)))  # all points coincide
    with np.errstate(all="ignore"):
        kappa = curvature_from_derivatives(curve.derivative(t, 1), curve.derivative(t, 2))  # NaN where P' = 0
    finite = np.zeros(0) if point else kappa[np.isfinite(kappa)]
    result: dict[str, Any] = {
        "command": "curve",
        "degree": curve.degree,
        "dim": curve.dim,
        "mu": curve.mu,
        "nu": curve.nu,
        "gamma": curve.gamma,
        "arc_length": curve.arc_length(),
        "curvature_max": float(finite.max()) if finite.size else None,  # None: a point, no curvature
        "start_tangent": curve.derivative(0.0, 1).tolist(),
        "end_tangent": curve.derivative(1.0, 1).tolist(),
        "outputs": {},
    }
    if args.step and curve.dim not in (2, 3):
        raise UsageError(f"--step needs a 2-D or 3-D curve; this curve has dim={curve.dim}")
    if args.step and point:
        raise UsageError(f"--step: the control points all coincide ({_fmt_point(pts[0].tolist())}): the curve is a "
                         "point, not an edge; allowed: control points that are not all equal")

    def write_step_edge(path: Path) -> None:
        from .bspline import curve_to_bspline
        from .cad.occ import make_edge, write_step

        data = curve_to_bspline(curve)
        write_step(make_edge(data), path)
        result["bspline"] = {"degree": data.degree, "poles": int(data.poles.shape[0]), "max_deviation": data.max_deviation}

    def write_curve_png(path: Path) -> None:
        from .plotting import plot_curve

        plot_curve(curve, path)

    def write_curvature_png(path: Path) -> None:
        from .plotting import plot_curvature

        plot_curvature(curve, path)

    result["outputs"] = _write_staged([("step", args.step, write_step_edge), ("curve_png", args.plot, write_curve_png),
                                       ("curvature_png", args.curvature_plot, write_curvature_png)])

    def text(r: dict[str, Any]) -> str:
        s = (
            f"GHT-Bézier curve: degree {r['degree']}, dim {r['dim']}, mu={r['mu']:g}, nu={r['nu']:g}, "
            f"gamma={r['gamma']:g}\n  arc length {r['arc_length']:.10g}, max curvature "
            + ("n/a (a point)" if r["curvature_max"] is None else f"{r['curvature_max']:.6g}")
        )
        out = _outputs_text(r)
        return s + ("\n" + out if out else "")

    _emit(args, result, text)
    return EXIT_OK


def _write_staged(outputs: Sequence[tuple[str, str | None, Callable[[Path], Any]]]) -> dict[str, str]:
    """Write the requested outputs all or nothing; returns ``{kind: path}`` in the given order.

    Each ``(kind, target, writer)`` with a target calls ``writer(temporary path)``; the files are
    staged beside their targets (:class:`ght_cad.outdir.StagedFiles`: locked targets, staging
    folders a later run can tell from a live one's) and moved into place only when every writer
    succeeded (a failure leaves no new file and every existing target as it was).
    """
    from .outdir import StagedFiles

    wanted = [(kind, Path(target), writer) for kind, target, writer in outputs if target]
    if not wanted:
        return {}
    with StagedFiles([t for _, t, _ in wanted]) as stage:
        for _, target, writer in wanted:
            writer(stage.path(target))
        stage.commit()
    return {kind: str(target) for kind, target, _ in wanted}


def _load(args: argparse.Namespace) -> Any:
    from .design import load_design

    return load_design(args.design)


def cmd_demo(args: argparse.Namespace) -> int:
    """``ght-cad demo``: :func:`ght_cad.demo.run_demo` into ``--out``."""
    from .demo import run_demo

    report = run_demo(args.out, progress=not args.no_progress, quick=args.quick, chord_tol=_chord_tol(args),
                      **_wait_args(args))
    _emit(args, {"command": "demo", **report}, _report_text)
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    """``ght-cad run``: validate a design file, then :func:`ght_cad.design.run_design`."""
    from .design import load_design, run_design

    design = load_design(args.design)
    out = args.out if args.out is not None else Path(args.design).with_suffix("").name + "-out"
    report = run_design(design, out, progress=not args.no_progress, chord_tol=_chord_tol(args), **_wait_args(args))
    _emit(args, {"command": "run", **report}, _report_text)
    return EXIT_OK


def _chord_tol(args: argparse.Namespace) -> float | None:
    """``--chord-tol`` (None: the design's ``[outputs] chord_tol``, else 1e-3 mm in the pattern's unit); refused
    unless > 0 and finite. The option takes precedence over the design file's key."""
    tol = getattr(args, "chord_tol", None)
    if tol is not None and not (tol > 0 and math.isfinite(tol)):
        raise UsageError(f"--chord-tol={tol!r} is not allowed; allowed: a positive length in the pattern's units "
                         "(default 1e-3 mm)")
    return tol


def _wait_args(args: argparse.Namespace) -> dict[str, Any]:
    """``wait``/``timeout`` for :func:`ght_cad.design.run_design` from ``--wait``/``--wait-timeout``."""
    timeout = getattr(args, "wait_timeout", None)
    if timeout is not None and not (math.isfinite(timeout) and timeout >= 0):
        raise UsageError(f"--wait-timeout {timeout:g} is not allowed; allowed: a number of seconds >= 0")
    return {"wait": bool(getattr(args, "wait", False) or timeout is not None), "timeout": timeout}


def add_wait_options(sp: argparse.ArgumentParser) -> None:
    """``--wait`` and ``--wait-timeout`` of the commands that write an output folder (run, demo, batch)."""
    sp.add_argument("--wait", action="store_true",
                    help="if another ght-cad process writes the output folder, wait until it has finished "
                    "(default: refuse with exit code 2, naming the folder and the other process)")
    sp.add_argument("--wait-timeout", type=float, metavar="SECONDS",
                    help="wait at most this long for the output folder (implies --wait); then exit code 2")


def _report_text(r: dict[str, Any]) -> str:
    lines = [f"{r.get('name', 'design')}: results in {r.get('out_dir')}"]
    dev = r.get("developability")
    if dev:
        lines.append(
            f"  developability: DD={dev['dd']:.12f}  theta_max={dev['theta_max']:.3e} deg  R={dev['R']:.3e}"
        )
    pat = r.get("flat_pattern")
    if pat and pat.get("errors"):
        errs = ", ".join(f"{k}={v:.2e}" for k, v in pat["errors"].items() if isinstance(v, (int, float)))
        lines.append(f"  flat pattern errors: {errs}")
    opt = r.get("optimization")
    if opt:
        lines.append(
            f"  optimization ({opt.get('method')}, {opt.get('objective')}): best {opt.get('best_value'):.6g} "
            f"at {opt.get('best_parameters')}"
        )
    if r.get("elapsed_s") is not None:
        lines.append(f"  elapsed {r['elapsed_s']:.1f} s")
    files = r.get("files") or []
    if files:
        lines.append("  files: " + ", ".join(files))
    return "\n".join(lines)


def cmd_surface(args: argparse.Namespace) -> int:
    """``ght-cad surface``: developability degree (θ_max, θ_rms, DD, R) of a design's surface."""
    from .design import build_surface, surface_summary, surface_view

    _check_suffix("--step", args.step, _STEP)
    _check_suffix("--plot", args.plot, _PNG)
    design = _load(args)
    built = build_surface(design)
    result = {"command": "surface", "name": design.name, **surface_summary(built), "outputs": {}}

    def write_step_face(path: Path) -> None:
        from .design import export_step

        export_step(built, path)

    def write_surface_png(path: Path) -> None:
        from .plotting import plot_surface

        plot_surface(surface_view(built), path, title=design.name)

    result["outputs"] = _write_staged([("step", args.step, write_step_face), ("surface_png", args.plot, write_surface_png)])

    def text(r: dict[str, Any]) -> str:
        d = r["developability"]
        s = f"{r['name']}: DD={d['dd']:.12f}, theta_max={d['theta_max']:.3e} deg, theta_rms={d['theta_rms']:.3e} deg, R={d['R']:.3e}"
        out = _outputs_text(r)
        return s + ("\n" + out if out else "")

    _emit(args, result, text)
    return EXIT_OK


def cmd_optimize(args: argparse.Namespace) -> int:
    """``ght-cad optimize``: :func:`ght_cad.design.optimize_design` with command-line overrides."""
    from .design import optimize_design

    _check_suffix("--plot", args.plot, _PNG)
    design = _load(args)
    overrides = {k: getattr(args, k) for k in ("method", "objective", "iterations", "population", "seed")}
    result_opt = optimize_design(design, overrides={k: v for k, v in overrides.items() if v is not None},
                                 progress=not args.no_progress)
    result = {"command": "optimize", "name": design.name, **result_opt.summary(), "outputs": {}}
    if args.plot:
        from .plotting import plot_convergence

        result["outputs"]["convergence_png"] = str(
            plot_convergence({result["method"]: result_opt.history}, args.plot, title=f"{design.name}: {result['objective']}")
        )

    def text(r: dict[str, Any]) -> str:
        s = (
            f"{r['name']}: {r['method']} on {r['objective']}: best {r['best_value']:.8g} at "
            + ", ".join(f"{k}={v:.6g}" for k, v in r["best_parameters"].items())
        )
        sh = r.get("sheet")
        if sh:  # [sheet]: what the sheet rule did (docs/design-files.md)
            s += (f"\n  sheet T={sh['thickness']:g}, |K*T|={sh['k_t']:.6g}: {sh['candidates_refused']} of "
                  f"{sh['candidates_checked']} candidates refused; smallest bending radius {sh['min_bending_radius']:.6g} "
                  f"(start: {'feasible' if sh['initial_feasible'] else 'refused' if sh['initial_feasible'] is False else 'no surface'})")
        out = _outputs_text(r)
        return s + ("\n" + out if out else "")

    _emit(args, result, text)
    return EXIT_OK


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
    from .design import build_surfaces, unroll_surfaces

    design = _load(args)
    if not design.surfaces:
        from .design import build_surface

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
    from .design import plot_pattern

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
        from .unfold_step import unfold_step

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
    from .design import unroll_step

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
    """Report and files of ``ght-cad unroll`` on sheet solids (:func:`ght_cad.unfold_step.unfold_step`)."""
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
        from .design import plot_pattern

        plot_pattern(pattern, path, title=name)

    def plate(path: Path) -> None:
        from .cad.occ import write_step
        from .cad.unfold_solid import blank_plates

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
    from .design import pattern_errors

    return pattern_errors(pattern)


def cmd_batch(args: argparse.Namespace) -> int:
    """``ght-cad batch``: :func:`ght_cad.batch.run_batch`; exit 0 all ok, 2 any bad input, 1 any failed."""
    from .batch import run_batch

    if args.jobs is not None and args.scheduler:
        raise UsageError("--jobs and --scheduler exclude each other: --jobs runs local processes, "
                         "--scheduler a Dask cluster's workers")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: allowed: an integer >= 1")
    res = run_batch(args.designs, args.out, jobs=args.jobs, scheduler=args.scheduler, progress=not args.no_progress,
                    chord_tol=_chord_tol(args))
    summary = res.as_dict()
    for r in summary["rows"]:
        if r["status"] != "ok":
            sys.stderr.write(f"{PROG}: {r['status']}: {r['name']}: {r['error']}\n")
    if getattr(args, "json", False):
        args._json_out = dumps({"ok": res.exit_code == EXIT_OK, "command": "batch", **summary})
    else:
        print(f"{summary['designs']} design(s) in {summary['out_dir']}: {summary['succeeded']} ok, "
              f"{summary['bad_input']} bad input, {summary['failed']} failed ({summary['executor']}, "
              f"{summary['elapsed_s']:.1f} s); summary: batch.json, batch.md")
    return res.exit_code


_EXPORT_SUFFIXES = (".step", ".stp", ".dxf", ".svg", ".json", ".png")
_STEP = (".step", ".stp")
_PNG = (".png",)


def cmd_export(args: argparse.Namespace) -> int:
    """``ght-cad export``: write the design's result to files chosen by suffix."""
    from .design import export_files

    for f in args.files:
        if Path(f).suffix.lower() not in _EXPORT_SUFFIXES:
            raise UsageError(
                f"cannot export to {f!r}: unknown suffix {Path(f).suffix!r}; allowed: {', '.join(_EXPORT_SUFFIXES)}"
            )
    design = _load(args)
    written = export_files(design, args.files, chord_tol=_chord_tol(args))
    result = {"command": "export", "name": design.name, "outputs": written}
    _emit(args, result, lambda r: "\n".join(f"wrote {v}" for v in r["outputs"].values()))
    return EXIT_OK


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
        from . import __version__

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
        from .errors import GHTError
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
        from .cad import KERNEL_HINT, is_missing_kernel

        if is_missing_kernel(exc):  # a core-only environment (e.g. FreeCAD's Python): not a bug
            return _fail(args, EXIT_USAGE, f"ght-cad {args.command}: this command {KERNEL_HINT} (No module named {exc.name!r})")
        if os.environ.get("GHT_CAD_DEBUG"):
            traceback.print_exc()
        return _fail(args, EXIT_FAILURE, f"internal failure: {type(exc).__name__}: {exc} (set GHT_CAD_DEBUG=1 for a traceback)")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
