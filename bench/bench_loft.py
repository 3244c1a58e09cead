"""Benchmark: the exact developable loft between two rails (spec 5.7) against build123d's ruled face.

Times, in the same run, on the dory's chine and sheer (examples/design_hull_plate.toml):

* ``ght``: ``developable_loft(chine, sheer)`` (boundary zeros of F, predictor–corrector tracing
  in both orientations of rail b, fans, report with θ on 257 rulings per segment) and then 1,000
  rulings of it (``loft.a(u)``, ``loft.b(u)``, Newton on F = 0 to round-off at every ruling);
* ``build123d``: ``Face.make_surface_from_curves(edge_a, edge_b)``, the equal-parameter ruled face
  between B-spline edges of the same rails (``ght_edge``, built before timing) and 1,000 rulings of
  it (both ends from ``BRepAdaptor_Surface.Value``), which is not developable (θ_max printed).

and prints both and their ratio, then the fan share before and after optimizing the rails' shape
parameters (``LoftProblem(objective="fan_share")``, a short PSO run).

Run: ``python bench/bench_loft.py [--repeat R] [--iterations N]``
"""

from __future__ import annotations

import argparse

import numpy as np

from bench_basis import _best  # best-of-R wall time, shared by the bench scripts

CHINE = [[0, -700, 300], [1500, -1050, 200], [3000, -1150, 250], [4500, -950, 450]]
SHEER = [[0, -900, 1200], [1500, -1250, 1150], [3000, -1300, 1180], [4500, -1100, 1300]]


def bench_construction(repeat: int) -> dict[str, float]:
    from build123d import Face
    from OCP.BRepAdaptor import BRepAdaptor_Surface

    from ght_cad import GHTCurve, developable_loft
    from ght_cad.cad.curves import ght_edge
    from ght_cad.surfaces.ruled import CurvePairRuledSurface

    chine, sheer = GHTCurve(CHINE), GHTCurve(SHEER)
    u = np.linspace(0.0, 1.0, 1000)

    def ght() -> None:
        loft = developable_loft(chine, sheer)
        A, B = loft.a(u), loft.b(u)
        assert A.shape == B.shape == (1000, 3)

    ea, eb = ght_edge(chine), ght_edge(sheer)

    def baseline() -> None:
        face = Face.make_surface_from_curves(ea, eb)
        srf = BRepAdaptor_Surface(face.wrapped)
        u0, u1 = srf.FirstUParameter(), srf.LastUParameter()
        v0, v1 = srf.FirstVParameter(), srf.LastVParameter()
        pts = [(srf.Value(x, v0), srf.Value(x, v1)) for x in u0 + (u1 - u0) * u]
        assert len(pts) == 1000

    ght()
    baseline()  # warm up imports
    t_ght = _best(ght, repeat)
    t_base = _best(baseline, repeat)
    loft = developable_loft(chine, sheer)
    strip = CurvePairRuledSurface(chine, sheer).developability().theta_max
    print(f"loft: {loft.report}")
    print(f"ght_cad developable_loft + 1,000 rulings (θ_max {loft.report.theta_max_deg:.1e} deg): {t_ght * 1e3:9.1f} ms")
    print(f"build123d equal-parameter ruled face + 1,000 rulings (θ_max {strip:.2f} deg):   {t_base * 1e3:9.1f} ms")
    print(f"ratio ght / build123d: {t_ght / t_base:.1f}x")
    return {"ght_s": t_ght, "build123d_s": t_base, "ratio": t_ght / t_base}


def bench_optimization(iterations: int, pop: int, seed: int = 1) -> dict[str, float]:
    import time

    from ght_cad import GHTCurve
    from ght_cad.optimize.problems import LoftProblem
    from ght_cad.optimize import minimize

    prob = LoftProblem(GHTCurve(CHINE), GHTCurve(SHEER), objective="fan_share")
    before = prob.report(prob.x0)
    t0 = time.perf_counter()
    res = minimize(prob, prob.bounds, method="pso", pop_size=pop, max_iter=iterations, seed=seed, x0=prob.x0)
    dt = time.perf_counter() - t0
    after = prob.report(res.x)
    print(f"fan share before optimization: {before['fan_share']:.5f} (fairness {before['fairness']:.4g})")
    print(f"fan share after  optimization: {after['fan_share']:.5f} (fairness {after['fairness']:.4g}) "
          f"at {dict(zip(prob.names, (round(float(v), 4) for v in res.x)))}; PSO {pop} x {iterations} in {dt:.1f} s")
    return {"fan_share_before": before["fan_share"], "fan_share_after": after["fan_share"], "seconds": dt}


def main(repeat: int = 3, iterations: int = 8, pop: int = 10) -> dict[str, float]:
    out = bench_construction(repeat)
    out.update(bench_optimization(iterations, pop))
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--iterations", type=int, default=8)
    ap.add_argument("--pop", type=int, default=10)
    a = ap.parse_args()
    main(a.repeat, a.iterations, a.pop)
