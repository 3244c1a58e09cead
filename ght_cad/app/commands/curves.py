"""``ght-cad plot-basis`` and ``ght-cad curve``.

Moved from :mod:`ght_cad.app.cli` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from .common import (_check_suffix, _emit, _fmt_point, _outputs_text, _parse_floats, _parse_points, _PNG, _STEP,
                     _write_staged, EXIT_OK, UsageError)


# ---------------------------------------------------------------------------------------------
# commands
# ---------------------------------------------------------------------------------------------
def cmd_plot_basis(args: argparse.Namespace) -> int:
    """``ght-cad plot-basis``: PNG of ``b_{i,m}(t; μ,ν,γ)`` (or a derivative), one panel per triple."""
    from ...curves.plotting import SIZES, plot_basis

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

    from ...curves.curve import GHTCurve

    if args.points is None:
        raise UsageError("--points is required, e.g. --points '0,0 1,2 3,2 4,0'")
    _check_suffix("--step", args.step, _STEP)
    _check_suffix("--plot", args.plot, _PNG)
    _check_suffix("--curvature-plot", args.curvature_plot, _PNG)
    from ...curves.curve import curvature_from_derivatives

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
        from ...surfaces.bspline import curve_to_bspline
        from ...cad.occ import make_edge, write_step

        data = curve_to_bspline(curve)
        write_step(make_edge(data), path)
        result["bspline"] = {"degree": data.degree, "poles": int(data.poles.shape[0]), "max_deviation": data.max_deviation}

    def write_curve_png(path: Path) -> None:
        from ...curves.plotting import plot_curve

        plot_curve(curve, path)

    def write_curvature_png(path: Path) -> None:
        from ...curves.plotting import plot_curvature

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
