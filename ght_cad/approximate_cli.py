r"""``ght-cad approximate``: developable panels for a STEP face that is not developable (issue 24).

Application layer: reads the face from a STEP file, runs :func:`ght_cad.approximate`, and writes
one output folder (locked, staged and committed by :class:`ght_cad.outdir.OutputFolder`):

* ``panels.step``: the panels as B-spline faces of degree 1 across the rulings, sewn into one
  shell (:func:`ght_cad.cad.approximate.panels_shell`);
* ``flat.dxf`` / ``flat.svg``: every panel's flat pattern on one sheet, seams marked
  (:func:`ght_cad.unroll.unroll_composite`: matching marks ``E<k>`` on the two panels of a seam);
* ``deviation.png``: the signed deviation of the panels from the target over its parameters;
* ``report.json`` / ``report.md``: per panel max deviation out/in, θ_max, 3-D and flat area; the
  panel count, the largest deviation and the files.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path
from typing import Any, Callable

import numpy as np

from .errors import GHTError

__all__ = ["add_parser", "cmd_approximate", "write_outputs", "plot_deviation", "report_markdown"]


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
    sp.add_argument("--direction", choices=("auto", "u", "v"), default="auto",
                    help="parameter the rulings run along (default auto: least normal curvature)")
    sp.add_argument("--face", type=int, default=1, metavar="N", help="face number, 1-based in file order (default 1)")
    common(sp)
    sp.set_defaults(func=cmd_approximate)


def plot_deviation(result: Any, path: str | os.PathLike, *, title: str | None = None) -> Path:
    """PNG (900 × 700 px) of the signed deviation (panel minus target along the target normal)
    over the target's (u, v), seams drawn as lines."""
    from .plotting import _figure, _save

    fig = _figure("surface")
    ax = fig.add_subplot(1, 1, 1)
    m = result.deviation_map
    uv, d = m["uv"], m["d"]
    lim = max(float(np.max(np.abs(d))), 1e-300)
    sc = ax.scatter(uv[:, 0], uv[:, 1], c=d, s=6, cmap="coolwarm", vmin=-lim, vmax=lim)
    fig.colorbar(sc, ax=ax, label="deviation (panel - target, along the normal)")
    u0, u1, v0, v1 = result.info.get("bounds", (uv[:, 0].min(), uv[:, 0].max(), uv[:, 1].min(), uv[:, 1].max()))
    for s in result.seams:
        if result.direction == "v":
            y = v0 + s["y"] * (v1 - v0)
            ax.plot([u0, u1], [y, y], "k-", lw=0.6)
        else:
            x = u0 + s["y"] * (u1 - u0)
            ax.plot([x, x], [v0, v1], "k-", lw=0.6)
    ax.set_xlabel("u")
    ax.set_ylabel("v")
    ax.set_title(title or f"{len(result.panels)} panels, max deviation {result.max_deviation:.4g} (tol {result.tol:g})")
    return _save(fig, path)


def report_markdown(report: dict[str, Any]) -> str:
    """The report as a Markdown table."""
    lines = [f"# Developable approximation: {report.get('name', 'target')}", "",
             f"- panels: {report['panels']} (rulings along {report['direction']})",
             f"- tolerance: {report['tol']:g}; largest deviation: {report['max_deviation']:.6g}",
             f"- total area: {report['total_area']:.6g}", "",
             "| panel | max out | max in | theta_max (deg) | area | flat area |",
             "|---|---|---|---|---|---|"]
    for p in report["panel_report"]:
        lines.append(f"| P{p['index']} | {p['max_out']:.4g} | {p['max_in']:.4g} | {p['theta_max_deg']:.2e} | "
                     f"{p['area']:.8g} | {p.get('flat_area', float('nan')):.8g} |")
    files = report.get("files")
    if files:
        lines += ["", "Files: " + ", ".join(files)]
    return "\n".join(lines) + "\n"


def _json_default(o: Any) -> Any:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(type(o).__name__)


def write_outputs(result: Any, folder: Any, *, name: str = "target", units: str = "mm") -> dict[str, Any]:
    """Write panels.step, flat.dxf, flat.svg, deviation.png, report.json and report.md into the
    open :class:`ght_cad.outdir.OutputFolder` ``folder``; returns the report dict."""
    from .cad.approximate import panels_shell
    from .cad.occ import write_step
    from .io import atomic_write

    shell = panels_shell(result)
    write_step(shell, folder.path("panels.step"), units=units)
    pattern = result.flat_pattern(units=units)
    pattern.export_dxf(folder.path("flat.dxf"))
    pattern.export_svg(folder.path("flat.svg"))
    plot_deviation(result, folder.path("deviation.png"), title=None)
    report = result.as_dict()
    report["name"] = name
    for p, fp in zip(report["panel_report"], pattern.panels):
        p["flat_area"] = float(fp.area_flat)
        p["label"] = fp.label
    names = ["panels.step", "flat.dxf", "flat.svg", "deviation.png", "report.json", "report.md"]
    report["files"] = names
    report["tool"] = "ght-cad"
    with atomic_write(folder.path("report.json")) as fh:
        fh.write(json.dumps(report, indent=2, default=_json_default))
    with atomic_write(folder.path("report.md")) as fh:
        fh.write(report_markdown(report))
    return report


def cmd_approximate(args: argparse.Namespace) -> int:
    """``ght-cad approximate TARGET.step --tol T --out DIR``."""
    from .cad.approximate import approximate_face
    from .cad.occ import read_step
    from .outdir import OutputFolder

    path = Path(args.target)
    if path.suffix.lower() not in (".step", ".stp"):
        raise GHTError(f"{path}: TARGET must be a STEP file (.step/.stp)")
    if not path.is_file():
        raise FileNotFoundError(2, "No such file", str(path))
    if not (isinstance(args.tol, float) and np.isfinite(args.tol) and args.tol > 0):
        raise GHTError(f"{path}: --tol={args.tol!r} is not allowed; it must be a length > 0")
    shape = read_step(path)
    try:
        result = approximate_face(shape, args.tol, face=args.face - 1, max_panels=args.max_panels,
                                  direction=args.direction)
    except GHTError as exc:
        raise GHTError(f"{path}: {exc}") from None
    with OutputFolder(args.out) as folder:
        report = write_outputs(result, folder, name=path.stem)
        folder.commit()
    summary = {"command": "approximate", "target": str(path), "panels": report["panels"], "tol": report["tol"],
               "max_deviation": report["max_deviation"], "out": str(args.out), "files": report["files"]}
    if getattr(args, "json", False):
        from .commands.common import dumps

        args._json_out = dumps({"ok": True, **summary})
    else:
        print(f"{path.name}: {report['panels']} developable panels, max deviation {report['max_deviation']:.4g} "
              f"(tol {report['tol']:g}) -> {args.out}")
    return 0
