"""Benchmark: developable approximation (issue 24) -- panel count and time against tolerance.

Targets (as B-spline faces, read through the OCP adapter):

* ``cap``: spherical cap, radius 1,000 mm, polar angle 0..60 deg (OCCT's exact rational sphere);
* ``hull``: one side of a ship-like hull, 6 m long (tests/test_approximate.py::hull_point);
* ``bump`` (``--targets bump``): a bent strip whose cross curvature doubles at mid-length
  (tests/test_approximate_dual.py::bump_target), where the dual fit wins.

For each tolerance and method (``--methods``: ``loft`` = rails lofts between the centred seams only,
``dual`` = the dual fit of the tangent planes wherever usable, ``auto`` = per strip the closer of
the two, spec 10.1): ``ght_cad.approximate`` (panels, largest deviation by its own two-way measure,
wall time, the chosen mix ``dual/loft`` panels; a second line: the time of the seam march(es) in it) beside the naive baseline of the issue: equally spaced isolines of the target (same
direction) as rails on the target, a developable between each pair (the rulings of
``det(a', b', b - a) = 0``, the equation ``developable_loft`` traces, solved per ruling), deviation
measured one way (panel points projected onto the target); the baseline count is the smallest N
whose every strip is within tol (found by doubling and bisection). A figure of panels vs tolerance
is written to docs/img/approximate_panels.png (``--png`` to change).

Run: ``python bench/bench_approximate.py [--tols 2,1,0.5,0.25] [--targets cap,hull] [--methods loft,dual,auto] [--png FILE]``
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))


def targets() -> dict[str, object]:
    from test_approximate import bspline_face, cap_face, hull_point
    from test_approximate_dual import bump_target

    from ght_cad.cad.approximate import face_target

    return {"cap": face_target(cap_face()), "hull": face_target(bspline_face(hull_point, 14, 10)),
            "bump": bump_target(1.0)}


def baseline_count(target: object, direction: str, tol: float, start: int) -> int:
    """Smallest N of equally spaced on-target isoline strips whose deviation is <= tol."""
    from ght_cad.approximation import _Seam, _strip_range, make_frame

    fr = make_frame(target, direction)

    def ok(n: int) -> bool:
        ys = np.linspace(0.0, 1.0, n + 1)
        seams = [_Seam(fr, y) for y in ys]
        for a, b in zip(seams[:-1], seams[1:]):
            lo, hi = _strip_range(fr, a, b)
            if max(-lo, hi) > tol:
                return False
        return True

    lo, hi = max(start - 1, 0), max(start, 1)
    while not ok(hi):
        lo, hi = hi, hi * 2
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if ok(mid):
            hi = mid
        else:
            lo = mid
    return hi


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tols", default="2,1,0.5,0.25")
    ap.add_argument("--targets", default="cap,hull")
    ap.add_argument("--methods", default="loft,dual,auto")
    ap.add_argument("--png", default=os.path.join(os.path.dirname(__file__), "..", "docs", "img", "approximate_panels.png"))
    args = ap.parse_args()
    from ght_cad.approximation import approximate
    from ght_cad.core.errors import GHTError

    tols = [float(x) for x in args.tols.split(",")]
    tg = targets()
    rows = []
    methods = args.methods.split(",")
    print(f"{'target':6} {'tol':>6} {'method':>6} {'panels':>6} {'mix d/l':>7} {'max dev':>9} {'time s':>7} {'baseline':>8} {'ratio':>6}")
    for name in args.targets.split(","):
        for tol in tols:
            nb = None
            for method in methods:
                t0 = time.perf_counter()
                stamps: list[tuple[float, str]] = [(t0, "")]
                try:
                    res = approximate(tg[name], tol, max_panels=200, method=method,
                                      progress=lambda m: stamps.append((time.perf_counter(), m)))
                except GHTError as exc:  # a method that cannot meet tol: say so, keep going
                    print(f"{name:6} {tol:6.3g} {method:>6}  failed: {str(exc)[:80]}", flush=True)
                    continue
                dt = time.perf_counter() - t0
                if nb is None:
                    nb = baseline_count(tg[name], res.direction, tol, len(res.panels))
                nd = sum(p.method == "dual" for p in res.panels)
                rows.append((name, tol, len(res.panels), res.max_deviation, dt, nb, method))
                print(f"{name:6} {tol:6.3g} {method:>6} {len(res.panels):6d} {nd:3d}/{len(res.panels) - nd:<3d} "
                      f"{res.max_deviation:9.4g} {dt:7.1f} {nb:8d} {nb / len(res.panels):6.2f}", flush=True)
                # the seam march's share of the time: from the message before each "march f=..." to it
                marches = [b[0] - a[0] for a, b in zip(stamps[:-1], stamps[1:]) if b[1].startswith("march")]
                print(f"{'':6} {'':6} {'':6}   march {sum(marches):.1f} s of {dt:.1f} s ({len(marches)} marches)", flush=True)
    if args.png:
        from ght_cad.curves.plotting import _figure, _save

        fig = _figure("convergence")
        ax = fig.add_subplot(1, 1, 1)
        for name in args.targets.split(","):
            for method in methods:
                r = [x for x in rows if x[0] == name and x[6] == method]
                if r:
                    ax.plot([x[1] for x in r], [x[2] for x in r], "o-", label=f"{name}: approximate ({method})")
            r = [x for x in rows if x[0] == name and x[6] == methods[0]]
            ax.plot([x[1] for x in r], [x[5] for x in r], "s--", label=f"{name}: equal isolines (baseline)")
        ax.set_xscale("log")
        ax.set_xlabel("tolerance (mm)")
        ax.set_ylabel("developable panels")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
        ax.set_title("Panels needed against tolerance")
        _save(fig, args.png)
        print(f"figure: {args.png}")


if __name__ == "__main__":
    main()
