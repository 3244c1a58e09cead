"""``ght-cad demo``, ``run``, ``surface`` and ``optimize``: the design-file commands.

Moved from :mod:`ght_cad.app.cli` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from .common import (_check_suffix, _chord_tol, _emit, _outputs_text, _PNG, _report_text, _STEP, _wait_args,
                     _write_staged, EXIT_OK)


def _load(args: argparse.Namespace) -> Any:
    from ..design import load_design

    return load_design(args.design)


def cmd_demo(args: argparse.Namespace) -> int:
    """``ght-cad demo``: :func:`ght_cad.app.demo.run_demo` into ``--out``."""
    from ..demo import run_demo

    report = run_demo(args.out, progress=not args.no_progress, quick=args.quick, chord_tol=_chord_tol(args),
                      **_wait_args(args))
    _emit(args, {"command": "demo", **report}, _report_text)
    return EXIT_OK


def cmd_run(args: argparse.Namespace) -> int:
    """``ght-cad run``: validate a design file, then :func:`ght_cad.app.design.run_design`."""
    from ..design import load_design, run_design

    design = load_design(args.design)
    out = args.out if args.out is not None else Path(args.design).with_suffix("").name + "-out"
    report = run_design(design, out, progress=not args.no_progress, chord_tol=_chord_tol(args), **_wait_args(args))
    _emit(args, {"command": "run", **report}, _report_text)
    return EXIT_OK


def cmd_surface(args: argparse.Namespace) -> int:
    """``ght-cad surface``: developability degree (θ_max, θ_rms, DD, R) of a design's surface."""
    from ..design import build_surface, surface_summary, surface_view

    _check_suffix("--step", args.step, _STEP)
    _check_suffix("--plot", args.plot, _PNG)
    design = _load(args)
    built = build_surface(design)
    result = {"command": "surface", "name": design.name, **surface_summary(built), "outputs": {}}

    def write_step_face(path: Path) -> None:
        from ..design import export_step

        export_step(built, path)

    def write_surface_png(path: Path) -> None:
        from ...curves.plotting import plot_surface

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
    """``ght-cad optimize``: :func:`ght_cad.app.design.optimize_design` with command-line overrides."""
    from ..design import optimize_design

    _check_suffix("--plot", args.plot, _PNG)
    design = _load(args)
    overrides = {k: getattr(args, k) for k in ("method", "objective", "iterations", "population", "seed")}
    result_opt = optimize_design(design, overrides={k: v for k, v in overrides.items() if v is not None},
                                 progress=not args.no_progress)
    result = {"command": "optimize", "name": design.name, **result_opt.summary(), "outputs": {}}
    if args.plot:
        from ...curves.plotting import plot_convergence

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
