"""Benchmark: ``method = "hybrid"`` with exact shape-parameter gradients vs finite differences,
in the same run, on

* the composite duct (``examples/design_duct_two_strips_optimized.toml``, two strips joined G2,
  6 parameters, objective Σ CVEn): :func:`ght_cad.app.design.optimize_design` with
  ``exact_gradients=True`` (:func:`ght_cad.app.design.composite_value_and_grad`) and ``False``;
  I-GWO (the file's own method) for reference;
* the hull plate rails loft (``examples/design_hull_plate.toml``, fan share over the rails' 6
  shape parameters): the same, with :meth:`ght_cad.optimize.problems.loft.LoftProblem.gradient_of`.

Printed per run: objective evaluations ``nfev`` (finite-difference points included; exact
gradients counted separately as ``njev``), the measured cost of one exact gradient in objective
evaluations (``grad/eval``: wall time of value+gradient over value alone, median of 5 at the start
point), the cost in evaluations ``nfev + njev * (grad/eval - 1)`` (the value of a gradient call
is already counted in ``nfev``), the best value and wall time, and the
FD/exact ratios of cost and time.

Run: ``python bench/bench_design_gradients.py [--population P]``
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def _grad_cost(design, overrides) -> float:
    """Wall time of one value+gradient over one value at the start point (median of 5)."""
    from ght_cad.app.design.build import _initial_shape, build_curves
    from ght_cad.app.design.optimize import _objective_fn, _value_and_grad_fn
    from ght_cad.app.design.schema import OptimizeSpec

    curves, _ = build_curves(design)
    spec = OptimizeSpec(**{**design.optimize.__dict__, **overrides})
    base = _initial_shape(design, curves)
    names = list(spec.parameters)
    f = _objective_fn(design, curves, spec)

    def shape_of(x):
        sh = dict(base)
        sh.update(dict(zip(names, (float(v) for v in x))))
        return sh

    vg = _value_and_grad_fn(design, curves, spec, names, shape_of)
    x = np.array([base[k] for k in names])
    tf, tg = [], []
    for _ in range(5):
        t = time.perf_counter()
        f(shape_of(x))
        tf.append(time.perf_counter() - t)
        t = time.perf_counter()
        vg(x[None, :])
        tg.append(time.perf_counter() - t)
    return statistics.median(tg) / statistics.median(tf)


def run(path: Path, population: int, reference: str | None) -> None:
    from ght_cad.app.design import load_design, optimize_design

    d = load_design(path)
    ov = {"method": "hybrid", "population": population}
    cost = _grad_cost(d, ov)
    print(f"\n{path.name}: one exact gradient costs {cost:.2f} objective evaluations (value + gradient / value)")
    rows = {}
    for label, kw, o in (("hybrid exact", True, ov), ("hybrid FD", False, ov)) + (
            ((f"{reference} (file)", True, {"method": reference}),) if reference else ()):
        t = time.perf_counter()
        r = optimize_design(d, o, progress=False, exact_gradients=kw)
        wall = time.perf_counter() - t
        c = r.nfev + r.njev * (cost - 1.0)  # a gradient call's value is already in nfev
        rows[label] = (c, wall)
        print(f"  {label:14s} nfev {r.nfev:5d}  njev {r.njev:4d}  cost {c:7.1f} evals  best {r.best_value:.12g}  "
              f"time {wall:6.2f} s")
    (ce, te), (cf, tf) = rows["hybrid exact"], rows["hybrid FD"]
    print(f"  FD / exact: cost {cf / ce:.2f}x, wall time {tf / te:.2f}x")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--population", type=int, default=16)
    ap.add_argument("--no-reference", action="store_true", help="skip the file's own method")
    a = ap.parse_args()
    import os

    print(f"load average {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    run(ROOT / "examples" / "design_duct_two_strips_optimized.toml", a.population, None if a.no_reference else "igwo")
    run(ROOT / "examples" / "design_hull_plate.toml", min(a.population, 8), None if a.no_reference else "pso")


if __name__ == "__main__":
    main()
