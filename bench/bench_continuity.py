"""Benchmark: join / composite re-solve against a dense linear-solve baseline, same run.

The baseline imposes the same conditions R^(r)(0) = T_r the generic way: it evaluates the
(r+1) x (r+1) matrix of basis derivatives at 0 with ``GHTCurve.basis`` and calls
``numpy.linalg.solve``. ``join`` builds the end rows in closed form from the seed's (cached) end
jets and solves the triangular system one point at a time; the ratio mostly measures the
closed-form end rows. Ratios > 1 mean join is faster; ``max |diff|`` is the point difference.
Also: re-solving a 200-segment composite after ``set_shape`` versus building it from scratch.

Run: ``python bench/bench_continuity.py``
"""

from __future__ import annotations

import time

import numpy as np

from ght_cad import GHTCurve
from ght_cad.curves.composite import CompositeCurve
from ght_cad.curves.continuity import join, join_targets


def _baseline(a: GHTCurve, cont: str, b: GHTCurve, **g) -> GHTCurve:
    r = int(cont[1])
    T = np.array(join_targets(a, cont, **g))
    M = np.vstack([b.basis(np.array([0.0]), j)[0, : r + 1] for j in range(r + 1)])
    pts = np.array(b.control_points)
    pts[: r + 1] = np.linalg.solve(M, T)
    return GHTCurve(pts, seed=b.seed)


def _time(fn, repeat: int = 5, number: int = 200) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(number):
            fn()
        best = min(best, (time.perf_counter() - t0) / number)
    return best


def main() -> None:
    rng = np.random.default_rng(0)
    print(f"{'case':24s} {'join [us]':>10s} {'dense [us]':>11s} {'ratio':>7s} {'max |diff|':>11s}")
    for m, cont in [(3, "C1"), (5, "G2"), (8, "G3"), (8, "C3")]:
        a = GHTCurve(rng.normal(size=(m + 1, 3)), 0.2, -0.3, -0.5)
        b = GHTCurve(rng.normal(size=(m + 1, 3)), -0.4, 0.6, 0.1)
        g = {"k": 1.3, "beta2": 0.2, "beta3": -0.1} if cont[0] == "G" else {}
        t_join = _time(lambda: join(a, cont, b, **g))
        t_base = _time(lambda: _baseline(a, cont, b, **g))
        diff = np.abs(join(a, cont, b, **g).control_points - _baseline(a, cont, b, **g).control_points).max()
        print(f"{f'degree {m} {cont}':24s} {t_join * 1e6:10.1f} {t_base * 1e6:11.1f} {t_base / t_join:7.2f} {diff:11.2e}")
    segs = [GHTCurve(rng.normal(size=(7, 2)) + 3 * i, 0.1, 0.2, -0.3) for i in range(200)]
    t_build = _time(lambda: CompositeCurve(segs, "G2", k=1.1, beta2=0.1), repeat=3, number=3)
    cc = CompositeCurve(segs, "G2", k=1.1, beta2=0.1)
    t_edit = _time(lambda: cc.set_shape(100, mu=float(rng.uniform(-1, 1))), repeat=3, number=3)
    print(f"200-segment G2 chain: build {t_build * 1e3:.1f} ms, set_shape re-solve {t_edit * 1e3:.1f} ms, "
          f"ratio build/edit {t_build / t_edit:.2f}")


if __name__ == "__main__":
    main()
