"""Benchmark: GHT-Bézier evaluation against scipy's BPoly, and core import time.

Evaluates a degree-7 3-D curve at 10^6 parameters with ght_cad and with scipy's ``BPoly`` (classical
Bernstein, same degree, same size) in the same run, and prints the ratio (target: >= 5x faster).
Then measures ``import ght_cad`` in fresh interpreters (target: < 0.3 s without the CAD stack),
against ``import numpy`` measured the same way.

Run: ``python bench/bench_basis.py [--size N] [--repeat R]``
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time

import numpy as np


def _best(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def bench_evaluation(size: int, repeat: int) -> dict[str, float]:
    from scipy.interpolate import BPoly

    from ght_cad import GHTCurve

    rng = np.random.default_rng(0)
    pts = rng.normal(size=(8, 3))
    t = rng.random(size)
    curve = GHTCurve(pts, 0.3, -0.2, 0.1)
    bpoly = BPoly(pts[:, None, :], [0.0, 1.0])
    # same results for the classical case (gamma = 1), to show the comparison is like for like
    classical = GHTCurve(pts, 0.0, 0.0, 1.0)
    err = float(np.abs(classical.evaluate(t[:10000]) - bpoly(t[:10000])).max())
    t_ght = _best(lambda: curve.evaluate(t), repeat)
    t_bp = _best(lambda: bpoly(t), repeat)
    return {"ght_s": t_ght, "bpoly_s": t_bp, "ratio": t_bp / t_ght, "classical_max_diff": err}


def bench_import(repeat: int) -> dict[str, float]:
    def run(stmt: str) -> float:
        code = f"import time; t=time.perf_counter(); {stmt}; print(time.perf_counter()-t)"
        vals = [float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout) for _ in range(repeat)]
        return statistics.median(vals)

    numpy_s = run("import numpy")
    core_s = run("import ght_cad")
    return {"import_ght_cad_s": core_s, "import_numpy_s": numpy_s, "ratio_to_numpy": core_s / numpy_s}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--size", type=int, default=10**6)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    ev = bench_evaluation(args.size, args.repeat)
    print(f"degree-7 3-D curve at {args.size:,} parameters (best of {args.repeat})")
    print(f"  ght_cad GHTCurve.evaluate : {ev['ght_s']*1e3:8.1f} ms")
    print(f"  scipy BPoly (Bernstein)   : {ev['bpoly_s']*1e3:8.1f} ms")
    print(f"  ratio BPoly / ght_cad     : {ev['ratio']:8.2f}x   (target >= 5x)")
    print(f"  gamma=1 vs BPoly max diff : {ev['classical_max_diff']:.2e}")
    im = bench_import(args.repeat)
    print(f"import ght_cad (median of {args.repeat} fresh interpreters): {im['import_ght_cad_s']*1e3:.1f} ms "
          f"(target < 300 ms); import numpy alone: {im['import_numpy_s']*1e3:.1f} ms; ratio {im['ratio_to_numpy']:.2f}")


if __name__ == "__main__":
    main()
