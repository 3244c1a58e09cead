"""DXF/SVG export time: outlines as lines and arcs (issue 25) vs the former polyline writer, same run.

For the README cone (rails develop to exact arcs) and the hopper transition (rails develop to
curves: three-point arcs within the 1e-3 mm chord tolerance), alternating blocks of:

* ``old``: the former writer, one closed LWPOLYLINE through the outline samples (1,024 points),
  the rest of the document (bend lines, labels, marks) as now;
* ``new``: :meth:`FlatPattern.export_dxf` with the arc fit recomputed on every call (the
  per-panel cache cleared), i.e. what a fresh pattern pays;
* ``unroll``: the unroll itself (what precedes an export on the user's path), for scale.

Printed: median times (ms), the ratio new/old, the segments written and the area error of the
written geometry against the pattern's exact flat area. Timings on this 2-core VM drift by ±30 %
within a minute: read the ratios, not the milliseconds.

Run: ``.venv/bin/python bench/bench_dxf_export.py [--rounds N]``.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

import ght_cad
from ght_cad.app.design import build_surfaces, load_design, unroll_surfaces
from ght_cad.pattern.outline_arcs import bulge_polygon_area

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def readme_cone():
    cone = ght_cad.developable_from_planes([(-400, 1, 0, 0.5), (-400, 1, 1, 0.5), (-400, 0, 1, 0.5)],
                                           [(0, 0, 0, 1), (-400, 0, 0, 1)], gamma=-1)
    return lambda: ght_cad.unroll(cone)


def hopper():
    builts = build_surfaces(load_design(EXAMPLES / "design_hopper_transition.toml"))
    return lambda: unroll_surfaces(builts)


def old_export(pattern, path: Path) -> None:
    """The former writer's outline: one closed LWPOLYLINE through the samples (then the same rest)."""
    import ezdxf

    doc = ezdxf.new("R2010", setup=True)
    doc.layers.add("OUTLINE", color=7)
    doc.layers.add("BEND", color=1, linetype="DASHED")
    msp = doc.modelspace()
    for lp in pattern.outlines:
        msp.add_lwpolyline(lp.tolist(), close=True, dxfattribs={"layer": "OUTLINE"})
    for p, q in pattern.bend_lines:
        msp.add_line(tuple(p), tuple(q), dxfattribs={"layer": "BEND", "linetype": "DASHED"})
    for x, y, s, h in pattern.labels:
        msp.add_text(s, height=h, dxfattribs={"layer": "LABELS", "insert": (x, y)})
    doc.saveas(path)


def new_export(pattern, path: Path) -> None:
    for p in pattern.panels:
        p._arcs.clear()  # what a fresh pattern pays
    pattern.export_dxf(path)


def timed(fn, *args) -> float:
    t = time.perf_counter()
    fn(*args)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "p.dxf"
        for name, make in (("README cone", readme_cone()), ("hopper", hopper())):
            pattern = make()
            times: dict[str, list[float]] = {"old": [], "new": [], "unroll": []}
            for _ in range(args.rounds):  # alternating blocks
                times["unroll"].append(timed(make))
                times["old"].append(min(timed(old_export, pattern, path) for _ in range(3)))
                times["new"].append(min(timed(new_export, pattern, path) for _ in range(3)))
            med = {k: 1e3 * statistics.median(v) for k, v in times.items()}
            loops = pattern.outline_arcs()
            segs = sum(b.size for _, b in loops)
            area = sum(abs(bulge_polygon_area(p, b)) for p, b in loops)
            old_area = sum(abs(0.5 * float(np.dot(lp[:, 0], np.roll(lp[:, 1], -1)) - np.dot(lp[:, 1], np.roll(lp[:, 0], -1))))
                           for lp in pattern.outlines)
            exact = pattern.area
            print(f"{name}: unroll {med['unroll']:.1f} ms; DXF old {med['old']:.1f} ms, new {med['new']:.1f} ms, "
                  f"ratio new/old {med['new'] / med['old']:.2f}; (new - old) / unroll "
                  f"{(med['new'] - med['old']) / med['unroll']:+.3f}")
            print(f"  segments: new {segs}, old {sum(len(lp) for lp in pattern.outlines)}; area error vs exact: "
                  f"new {(area - exact) / exact:+.1e}, old {(old_area - exact) / exact:+.1e}")


if __name__ == "__main__":
    main()
