r"""Benchmark: certified GHT → B-spline conversion against OCCT's ``GeomAPI_PointsToBSpline``.

For random 3-D GHT-Bézier curves of degrees 2..10 (random shape parameters in [-1, 1]) the
target is the default tolerance ``tol = 1e-7 ×`` bounding-box diagonal.

* ours: :func:`ght_cad.surfaces.bspline.curve_to_bspline` at the default degree 5 and at degree 8 (OCCT's
  DegMax below), end jets exact; deviation measured at matched parameters
  ``max_t |P(t) - C(t)|`` on 20 000 random + 4001 uniform fresh t.
* OCCT, two modes, each on N uniform samples ``P(t_k)`` (t_k = k/(N-1)) with DegMin 3, DegMax 8,
  C2, ``Tol3D = f × tol``; N doubles from 16 and f runs through 1, 0.3, 0.1 until the verified
  deviation is <= tol (first N that succeeds, the configuration with the fewest poles at it):

  - ``matched``: the parameters t_k are passed to OCCT, so its B-spline is parametrized by t and
    the deviation is measured exactly like ours (matched parameters, same fresh t).
  - ``matched5``: as ``matched`` with DegMax 5 (same maximum degree as our default).
  - ``chord``: OCCT's default (chord-length) parametrization; deviation = max distance of 20 000
    points of the OCCT curve to the exact curve by dense projection (nearest of 20 001 samples,
    refined by 4 Newton steps on ``|P(t) - q|²``): a weaker metric, favourable to OCCT.

Times are the minimum of 3 runs of one conversion; OCCT's time includes evaluating its N samples
(ours includes all of its own evaluations). The search over N and f is not timed (favourable to
OCCT). Printed ratios are OCCT / ours (ours at degree 5 and at degree 8): poles ratio > 1 means we
need fewer poles, time ratio > 1 means we are faster.

Run: ``python bench/bench_bspline.py [--curves-per-degree K]``.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from ght_cad import GHTCurve
from ght_cad.surfaces.bspline import BSplineCurveData, curve_to_bspline


def _timed(fn, repeat: int = 3):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _occt_fit(curve: GHTCurve, n: int, tol3d: float, matched: bool, deg_max: int = 8) -> BSplineCurveData | None:
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.GeomAPI import GeomAPI_PointsToBSpline
    from OCP.gp import gp_Pnt
    from ght_cad.cad._ocp import TColgp_Array1OfPnt, TColStd_Array1OfReal

    t = np.linspace(0.0, 1.0, n)
    pts = curve.evaluate(t)
    arr = TColgp_Array1OfPnt(1, n)
    for i, p in enumerate(pts, 1):
        arr.SetValue(i, gp_Pnt(*map(float, p)))
    if matched:
        par = TColStd_Array1OfReal(1, n)
        for i, x in enumerate(t, 1):
            par.SetValue(i, float(x))
        api = GeomAPI_PointsToBSpline(arr, par, 3, deg_max, GeomAbs_C2, tol3d)
    else:
        api = GeomAPI_PointsToBSpline(arr, 3, deg_max, GeomAbs_C2, tol3d)
    if not api.IsDone():
        return None
    c = api.Curve()
    poles = np.array([c.Pole(i).Coord() for i in range(1, c.NbPoles() + 1)])
    knots = np.array([c.KnotSequence().Value(i) for i in range(1, c.KnotSequence().Length() + 1)])
    return BSplineCurveData(poles, knots, c.Degree())


def _matched_deviation(curve: GHTCurve, bs: BSplineCurveData, t: np.ndarray) -> float:
    return float(np.linalg.norm(curve.evaluate(t) - bs.evaluate(t), axis=1).max())


def _projected_deviation(curve: GHTCurve, bs: BSplineCurveData, dense: int = 20001) -> float:
    """max over 20 000 points q of the B-spline of min_t |P(t) - q| (nearest sample + Newton)."""
    from scipy.spatial import cKDTree

    s = np.linspace(bs.knots[0], bs.knots[-1], 20000)
    q = bs.evaluate(s)
    td = np.linspace(0.0, 1.0, dense)
    _, idx = cKDTree(curve.evaluate(td)).query(q)
    t = td[idx]
    for _ in range(4):
        p, d1, d2 = curve.evaluate(t), curve.derivative(t, 1), curve.derivative(t, 2)
        r = p - q
        g = np.sum(r * d1, axis=1)
        h = np.sum(d1 * d1, axis=1) + np.sum(r * d2, axis=1)
        t = np.clip(t - g / np.where(h > 0, h, 1.0), 0.0, 1.0)
    return float(np.linalg.norm(curve.evaluate(t) - q, axis=1).max())


def _occt_search(curve: GHTCurve, tol: float, matched: bool, t_check: np.ndarray, deg_max: int = 8):
    n = 16
    while n <= 4096:
        found = []
        for f in (1.0, 0.3, 0.1):
            bs = _occt_fit(curve, n, f * tol, matched, deg_max)
            if bs is None:
                continue
            dev = _matched_deviation(curve, bs, t_check) if matched else _projected_deviation(curve, bs)
            if dev <= tol:
                found.append((bs.poles.shape[0], f, dev))
        if found:
            poles, f, dev = min(found)
            secs, _ = _timed(lambda: _occt_fit(curve, n, f * tol, matched, deg_max))
            return {"poles": poles, "time": secs, "n": n, "f": f, "dev": dev}
        n *= 2
    return None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--curves-per-degree", type=int, default=2)
    ap.add_argument("--seed", type=int, default=2024)
    args = ap.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    t_check = np.concatenate([rng.uniform(0, 1, 20000), np.linspace(0, 1, 4001)])
    rows = []
    print(f"{'deg':>3} {'ours5 poles':>11} {'ms':>6} {'dev/tol':>7} {'ours8 poles':>11} {'ms':>6} | "
          f"{'matched poles':>13} {'N':>5} {'ms':>6} | {'chord poles':>11} {'N':>5} {'ms':>7} | "
          f"{'matched5 poles':>14} {'N':>5} {'ms':>6}")
    for degree in range(2, 11):
        for _ in range(args.curves_per_degree):
            curve = GHTCurve(rng.normal(size=(degree + 1, 3)) * 10, *rng.uniform(-1, 1, 3))
            lo, hi = curve.bounding_box()
            tol = 1e-7 * float(np.linalg.norm(hi - lo))
            ours = {}
            for p in (5, 8):
                secs, bs = _timed(lambda: curve_to_bspline(curve, tol, degree=p))
                dev = _matched_deviation(curve, bs, t_check)
                if dev > tol:
                    raise AssertionError(f"ours (degree {p}) exceeded tol: {dev:.3g} > {tol:.3g}")
                ours[p] = {"poles": bs.poles.shape[0], "time": secs, "dev": dev, "fits": bs.info["fits"],
                           "samples": bs.info["samples_checked"]}
            occ_m = _occt_search(curve, tol, True, t_check)
            occ_c = _occt_search(curve, tol, False, t_check)
            occ_5 = _occt_search(curve, tol, True, t_check, deg_max=5)
            rows.append((ours, occ_m, occ_c, occ_5))

            def cell(o, w=13):
                return f"{o['poles']:>{w}} {o['n']:>5} {1e3 * o['time']:>6.2f}" if o else f"{'failed':>{w}} {'':>5} {'':>6}"

            o5, o8 = ours[5], ours[8]
            print(f"{degree:>3} {o5['poles']:>11} {1e3 * o5['time']:>6.2f} {o5['dev'] / tol:>7.3f} "
                  f"{o8['poles']:>11} {1e3 * o8['time']:>6.2f} | {cell(occ_m)} | {cell(occ_c, 11)} | "
                  f"{cell(occ_5, 14)}")
    for p in (5, 8):
        ms = np.array([r[0][p]["time"] for r in rows]) * 1e3
        print(f"ours degree {p}: {ms.mean():.2f} ms per curve (median {np.median(ms):.2f}), "
              f"{np.mean([r[0][p]['poles'] for r in rows]):.2f} poles, "
              f"{np.mean([r[0][p]['fits'] for r in rows]):.2f} least-squares fits, "
              f"{np.mean([r[0][p]['samples'] for r in rows]):.0f} evaluations of P per curve")
    for label, k in (("matched parameters", 1), ("chord length + projection", 2), ("matched, DegMax 5", 3)):
        ok = [r for r in rows if r[k] is not None]
        if not ok:
            print(f"OCCT ({label}): never reached the tolerance")
            continue
        for p in (5, 8):
            pr = np.array([r[k]["poles"] / r[0][p]["poles"] for r in ok])
            tr = np.array([r[k]["time"] / r[0][p]["time"] for r in ok])
            print(
                f"OCCT ({label}) / ours degree {p}, {len(ok)} curves ({len(rows) - len(ok)} OCCT failures): "
                f"poles ratio {np.exp(np.log(pr).mean()):.2f} (geo-mean; min {pr.min():.2f}, max {pr.max():.2f}), "
                f"time ratio {np.exp(np.log(tr).mean()):.2f} (min {tr.min():.2f}, max {tr.max():.2f})"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
