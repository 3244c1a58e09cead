"""Benchmark: the cost of the sheet rule of ``optimize_design`` (a ``[sheet]`` with T > 0: every
candidate surface checked by :func:`ght_cad.app.design.check_sheet`, the run's check, 513 rulings).

Printed, all measured in the same run:

1. **Cost per candidate**: for random candidates of the box (seed 0) of each design, the time of
   the plain candidate (surface built and measured: the design objective) and of the sheet check
   of the same surface; ratio check / candidate.
2. **Fewer rulings for candidates?** The smallest bending radius ``min |ρ_0|`` and the check time
   at 33, 65, 129, 257 rulings against the 513 of the run (the grids are nested: a coarse grid is
   a subset of the fine one, so its radius is never smaller): the largest relative overestimate
   over the candidates and the time ratio against 513.
3. **Whole optimizations** with and without the sheet (``--runs``): value, nfev, time, candidates
   refused, the result's ``min |ρ_0| / |K T|``.

Run: ``python bench/bench_sheet_optimize.py [--candidates N] [--runs] [--transition]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

BRACKET_SHEET = '\n[sheet]\nthickness = 6.0\nk_factor = 0.5\n'


def _designs(transition: bool) -> list[tuple[str, object]]:
    from test_sheet_optimize import QUARTER, TRANSITION, bracket

    from ght_cad.app.design import parse_design_text

    out = [
        ("bracket rails 60x40 (T=6)", parse_design_text(bracket(BRACKET_SHEET), "bracket.toml")),
        ("quarter planes (T=180, K=1)", parse_design_text(
            QUARTER.format(method="hybrid", pop=20, it=40) + '\n[sheet]\nthickness = 180.0\nk_factor = 1.0\n', "quarter.toml")),
    ]
    duct = (ROOT / "examples" / "design_duct_two_strips_optimized.toml").read_text()
    # units "m": a 4 mm sheet; the strips' smallest radius is 0.31-0.36 m at the start
    out.append(("duct composite, m (T=0.004)", parse_design_text(duct + '\n[sheet]\nthickness = 0.004\nk_factor = 0.42\n',
                                                               "duct.toml")))
    if transition:
        out.append(("transition rails 600x400, fans (T=2, reverse)", parse_design_text(
            TRANSITION.replace('k_factor = 0.42', 'k_factor = 0.42\nside = "reverse"'), "transition.toml")))
    return out


def _candidates(design, n: int):
    """(shape, surface, plain time) of n random candidates that build."""
    from ght_cad.app.design.build import _initial_shape, build_curves
    from ght_cad.app.design.optimize import _objective_fn
    from ght_cad.core.errors import GHTError

    curves, _ = build_curves(design)
    base = _initial_shape(design, curves)
    names = list(design.optimize.parameters)
    f = _objective_fn(design, curves, design.optimize)
    seen = []

    def grab(surface, shape):
        seen.append(surface)

    g = _objective_fn(design, curves, design.optimize, grab)
    rng = np.random.default_rng(0)
    out = []
    tries = 0
    while len(out) < n and tries < 20 * n:
        tries += 1
        sh = dict(base)
        sh.update(dict(zip(names, rng.uniform(-1.0, 1.0, len(names)))))
        t = time.perf_counter()
        try:
            with np.errstate(all="ignore"):
                f(sh)
        except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
            continue
        dt = time.perf_counter() - t
        seen.clear()
        g(sh)
        out.append((sh, seen[-1], dt))
    return out


def cost_per_candidate(designs, n: int) -> None:
    from ght_cad.app.design import SHEET_MARGIN, check_sheet
    from ght_cad.sheetmetal.sheet import Sheet, SheetError

    print(f"\n1. cost per candidate ({n} random candidates per design; median ms)")
    print(f"{'design':48s} {'candidate':>10s} {'check':>8s} {'ratio':>6s} {'refused':>8s}")
    for name, d in designs:
        cands = _candidates(d, n)
        sh = d.sheet.to_sheet()
        strict = Sheet(sh.thickness * (1 + SHEET_MARGIN), sh.k_factor, sh.side)
        tc, refused = [], 0
        for _, surf, _ in cands:
            t = time.perf_counter()
            try:
                check_sheet(d, surf, sheet=strict)
            except SheetError:
                refused += 1
            tc.append(time.perf_counter() - t)
        tp = statistics.median(c[2] for c in cands)
        print(f"{name:48s} {1e3 * tp:10.1f} {1e3 * statistics.median(tc):8.1f} {statistics.median(tc) / tp:6.2f} "
              f"{refused:4d}/{len(cands)}")


def sample_study(designs, n: int) -> None:
    import math

    from ght_cad.app.design import sheet_parts
    from ght_cad.sheetmetal.sheet import Sheet, check_offset

    print(f"\n2. rulings checked per candidate ({n} candidates per design): largest relative overestimate of "
          "min |rho_0| against 513 rulings, and check time / time at 513")
    grid = (33, 65, 129, 257, 513)
    print(f"{'design':48s} " + " ".join(f"{k:>15d}" for k in grid[:-1]))
    for name, d in designs:
        cands = _candidates(d, n)
        over = {k: 0.0 for k in grid}
        times = {k: [] for k in grid}
        flat = Sheet(d.sheet.thickness * 1e-9, d.sheet.k_factor, d.sheet.side)  # tiny: always passes, radius measured
        for _, surf, _ in cands:
            r = {}
            for k in grid:
                t = time.perf_counter()
                try:
                    r[k] = min(check_offset(p, flat, samples=k) for p in sheet_parts(surf))
                except Exception:  # an apex on the concave side: no radius to compare
                    r[k] = math.nan
                times[k].append(time.perf_counter() - t)
            for k in grid:
                if math.isfinite(r[k]) and math.isfinite(r[513]) and r[513] > 0:
                    over[k] = max(over[k], r[k] / r[513] - 1.0)
        base = statistics.median(times[513])
        print(f"{name:48s} " + " ".join(f"{over[k]:7.1%} t{statistics.median(times[k]) / base:5.2f}" for k in grid[:-1]))


def runs(designs) -> None:
    from ght_cad.app.design import optimize_design

    print("\n3. whole optimizations, with and without the sheet")
    print(f"{'design':48s} {'method':>7s} {'sheet':>5s} {'best':>12s} {'nfev':>5s} {'time s':>7s} {'refused':>9s} {'r/|KT|':>9s}")
    for name, d in designs:
        for ov in ({"method": "hybrid", "population": 20, "iterations": 40}, {"method": "pso", "population": 10, "iterations": 15}):
            for with_sheet in (False, True):
                dd = d if with_sheet else replace(d, sheet=None)
                t = time.perf_counter()
                o = optimize_design(dd, ov, progress=False)
                dt = time.perf_counter() - t
                s = o.sheet or {}
                print(f"{name:48s} {ov['method']:>7s} {'yes' if with_sheet else 'no':>5s} {o.best_value:12.6g} {o.nfev:5d} "
                      f"{dt:7.2f} {str(s.get('candidates_refused', '-')) + '/' + str(s.get('candidates_checked', '-')):>9s} "
                      f"{s.get('min_radius_over_k_t', float('nan')):9.6g}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--candidates", type=int, default=30)
    ap.add_argument("--runs", action="store_true", help="also whole optimizations (minutes)")
    ap.add_argument("--transition", action="store_true", help="also the 600 x 400 transition with fans (slow)")
    args = ap.parse_args()
    designs = _designs(args.transition)
    cost_per_candidate(designs, args.candidates)
    sample_study(designs, args.candidates)
    if args.runs:
        runs(designs)


if __name__ == "__main__":
    main()
