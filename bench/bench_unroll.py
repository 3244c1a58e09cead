"""Unroll timing and accuracy: quadrature along rulings vs a triangle-strip baseline (same run).

1. Time to unroll a 1,000-ruling panel (the enveloping developable of the FreeCAD numbers test and
   a quarter cone frustum), including the distortion report, and to write its DXF.
2. Error against ruling count N for both methods. The baseline lays the quads between N rulings
   out as triangle pairs with exact 3-D edge lengths (the classical strip development, O(h²)).
   Errors are relative to exact 3-D values: ``pos`` = distance of the flat corner B(1) from its
   closed-form place (cone: annular sector) / pattern size; ``area`` and ``b-len`` = area and
   length of the b boundary of the cut outline vs the 3-D area and arc length of b.

Run: ``/tmp/venv/bin/python bench/bench_unroll.py``.
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ght_cad import GHTCurve, developable_from_planes
from ght_cad.curves.curve import integrate
from ght_cad.surfaces.ruled import CurvePairRuledSurface
from ght_cad.unrolling.unroll import ruled_area, unroll


def quarter(r: float, z: float) -> GHTCurve:
    return GHTCurve([(r, 0, z), (r, r, z), (0, r, z)], gamma=-1)


def triangle_strip(surface, n_rulings: int) -> tuple[np.ndarray, np.ndarray]:
    """Classical strip development: flat A_i, B_i from exact 3-D triangle edge lengths."""
    u = np.linspace(0.0, 1.0, n_rulings)
    a, b = surface.a(u), surface.b(u)
    A = np.zeros((n_rulings, 2))
    B = np.zeros((n_rulings, 2))
    B[0] = [0.0, np.linalg.norm(b[0] - a[0])]

    def third(P, Q, dp, dq, side_ref):
        # point X with |X-P| = dp, |X-Q| = dq on the side opposite to side_ref
        d = np.linalg.norm(Q - P)
        x = (dp**2 - dq**2 + d**2) / (2 * d)
        y = math.sqrt(max(dp**2 - x**2, 0.0))
        e = (Q - P) / d
        n = np.array([-e[1], e[0]])
        c1, c2 = P + x * e + y * n, P + x * e - y * n
        return c1 if np.dot(c1 - P, n) * np.dot(side_ref - P, n) < 0 else c2

    for i in range(n_rulings - 1):
        # triangle (a_i, b_i, a_{i+1}) then (a_{i+1}, b_i, b_{i+1})
        A[i + 1] = third(A[i], B[i], np.linalg.norm(a[i + 1] - a[i]), np.linalg.norm(a[i + 1] - b[i]),
                         A[i - 1] if i else B[i] + (B[i] - A[i]) @ np.array([[0, 1], [-1, 0]]))
        B[i + 1] = third(A[i + 1], B[i], np.linalg.norm(b[i + 1] - a[i + 1]), np.linalg.norm(b[i + 1] - b[i]), A[i])
    return A, B


def _shoelace(P: np.ndarray) -> float:
    return 0.5 * abs(float(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1])))


def strip_errors(surface, A: np.ndarray, B: np.ndarray, exact_corner) -> dict[str, float]:
    area3 = ruled_area(surface)
    lb = integrate(lambda t: np.linalg.norm(surface.b(t, 1), axis=1), 0, 1, rtol=1e-14)
    poly = np.vstack([A, B[::-1]])
    size = float(np.max(np.ptp(poly, axis=0)))
    out = {
        "area": abs(_shoelace(poly) - area3) / area3,
        "b-len": abs(float(np.sum(np.linalg.norm(np.diff(B, axis=0), axis=1))) - lb) / lb,
    }
    if exact_corner is not None:
        out["pos"] = abs(np.linalg.norm(B[-1] - A[0]) - exact_corner) / size
    return out


def main() -> int:
    cone = CurvePairRuledSurface(quarter(1.0, 0.0), quarter(2.0, 1.5))
    slant = math.hypot(1.0, 1.5)
    rho1, rho2 = slant * 1.0, slant * 2.0
    ang = 0.5 * math.pi * 2.0 / rho2
    # exact |B(1) - A(0)| in the annular sector (law of cosines)
    cone_corner = math.sqrt(rho1**2 + rho2**2 - 2 * rho1 * rho2 * math.cos(ang))
    planes = [(-10.0, 1.0, 0.0, 0.2), (-10.0, 1.0, 1.0, 0.1), (-10.0, 0.0, 1.0, 0.2)]
    boundary = [(0.0, 0.0, 0.0, 1.0), (-20.0, 0.0, 0.0, 1.0)]
    env = developable_from_planes(planes, boundary, 0.1, -0.2, -0.6)
    cases = {"cone frustum": (cone, cone_corner), "envelope developable": (env, None)}

    print("1) 1,000-ruling panel (best of 3; includes the distortion report)")
    unroll(cone, rulings=10)  # warm-up: imports
    for name, (surf, _) in cases.items():
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            pat = unroll(surf, rulings=1000)
            best = min(best, time.perf_counter() - t0)
        t0 = time.perf_counter()
        A, B = triangle_strip(surf, 1000)
        t_strip = time.perf_counter() - t0
        with tempfile.TemporaryDirectory() as d:
            t0 = time.perf_counter()
            pat.export_dxf(Path(d) / "p.dxf")
            t_dxf = time.perf_counter() - t0
        print(f"   {name:22s} unroll {best:.3f} s ({pat.panels[0].info['panels']} panels, {len(pat.bend_lines)} bend "
              f"lines), DXF {t_dxf:.3f} s; triangle strip baseline {t_strip:.3f} s (time ratio {best / t_strip:.2f}); "
              f"max rel error {pat.errors['max']:.1e}")

    print("\n2) error against ruling count N (relative)")
    hdr = f"   {'surface':22s} {'N':>5s} | {'quad area':>10s} {'quad b-len':>10s} {'quad pos':>10s} | " \
          f"{'strip area':>10s} {'strip b-len':>10s} {'strip pos':>10s} | {'ratio':>8s}"
    print(hdr)
    for name, (surf, corner) in cases.items():
        for N in (10, 30, 100, 300, 1000):
            pat = unroll(surf, rulings=N)
            panel = pat.panels[0]
            q = pat.report.as_dict()
            bl = next(r for n, r in zip(pat.report.boundary_names, pat.report.boundary_length) if n.endswith(":b"))
            qpos = float("nan")
            if corner is not None:
                Y = panel.development
                qpos = abs(np.linalg.norm(Y.map([1.0], [1.0])[0] - Y.map([0.0], [0.0])[0]) - corner) / float(
                    np.max(np.ptp(pat.outlines[0], axis=0)))
            s = strip_errors(surf, *triangle_strip(surf, N), corner)
            qmax = max(q["area"]["max"], bl, 0.0 if math.isnan(qpos) else qpos, 1e-16)
            smax = max(s.values())
            print(f"   {name:22s} {N:5d} | {q['area']['max']:10.2e} {bl:10.2e} {qpos:10.2e} | {s['area']:10.2e} "
                  f"{s['b-len']:10.2e} {s.get('pos', float('nan')):10.2e} | {smax / qmax:8.1e}")
    print("   ratio = worst strip error / worst quadrature error (quadrature floored at 1e-16)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
