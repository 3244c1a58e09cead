r"""Vase/nozzle example: a G2/G3-joined GHT profile revolved into a hollow solid of revolution.

The outer wall profile ``r(z)`` is an open chain of three GHT-Bézier segments (belly, waist,
flared lip) with a G3 and a G2 joint (a nozzle-like shell, open at both ends); the inner wall is the same chain shifted inwards by the
wall thickness (exact: GHT curves are affinely invariant), so the wall thickness measured
horizontally is constant. Profile = outer chain, top line, reversed inner chain, bottom line;
it lies in the XZ plane and is revolved 360° about Z. Both chains become certified B-spline
edges (:func:`ght_cad.cad.curves.ght_wire`); the solid is written to STEP.

Run: ``python examples/vase_revolve.py OUT_DIR`` (writes ``OUT_DIR/vase_revolve.step``).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

from ght_cad import GHTCurve
from ght_cad.curves.composite import CompositeCurve

WALL = 0.4


def radius(z: np.ndarray) -> np.ndarray:
    """Design intent of the outer wall: belly, waist and a flared lip (radius as a function of z)."""
    return 2.3 + 2.4 * np.exp(-(((z - 3.2) / 2.4) ** 2)) + 0.9 * np.exp((z - 13.0) / 1.5)


def profile() -> CompositeCurve:
    """Outer wall in the XZ plane as three GHT segments (belly, waist, lip) with G3 and G2 joints.

    Each segment's control points are the least-squares fit of ``t ↦ (radius(z), 0, z)``,
    ``z = z0 + t (z1 - z0)``, at 200 parameters (so its end jets follow the design curve); the G3
    and G2 joints use the segments' natural G parameters
    (:func:`ght_cad.curves.continuity.measure_continuity`), so the join solver only nudges the dependent
    control points.
    """
    from ght_cad import basis
    from ght_cad.curves.continuity import measure_continuity

    spans = [(0.0, 4.9, 6, (0.2, 0.1, -0.3)), (4.9, 9.0, 6, (0.0, 0.3, 0.2)), (9.0, 13.0, 6, (0.3, 0.0, 0.5))]
    segs = []
    for z0, z1, degree, shape in spans:
        t = np.linspace(0.0, 1.0, 200)
        z = z0 + t * (z1 - z0)
        target = np.column_stack([radius(z), np.zeros_like(z), z])
        points, *_ = np.linalg.lstsq(basis(t, degree, *shape), target, rcond=None)
        segs.append(GHTCurve(points, *shape))
    g = [measure_continuity(segs[0], segs[1]), measure_continuity(segs[1], segs[2])]
    return CompositeCurve(segs, ["G3", "G2"], k=[r.k for r in g], beta2=[r.beta2 for r in g],
                          beta3=[g[0].beta3, 0.0])


def _pappus_volume(outer: CompositeCurve, inner: CompositeCurve) -> float:
    """V = π |∮ x² dz| over the closed profile (the two horizontal lines contribute nothing)."""
    from ght_cad.curves.curve import gauss_legendre

    t, w = gauss_legendre(64)

    def integral(cc: CompositeCurve) -> float:
        return sum(
            float(np.sum(w * s.evaluate(t)[:, 0] ** 2 * s.derivative(t, 1)[:, 2])) for s in cc.segments
        )

    return float(np.pi * abs(integral(outer) - integral(inner)))


def main(out_dir: str | Path) -> dict[str, Any]:
    """Revolve the profile and export ``vase_revolve.step`` into ``out_dir``.

    Returns:
        ``{"step", "volume", "exact_volume", "relative_volume_error",
        "relative_volume_error_bound", "max_deviation", "joints", "joint_g_orders", "valid"}``;
        exact volume by Pappus–Guldin on the exact GHT curves; the bound follows from the
        certified deviations δ_i: ``Σ 2π (x_max,i + δ_i)(L_i δ_i + π δ_i²)``.
    """
    from build123d import Axis, Edge, Face, Wire, revolve

    from ght_cad.cad.curves import exact_edges, ght_wire
    from ght_cad.cad.occ import is_valid, write_step
    from ght_cad.cad.occ import volume as solid_volume

    outer = profile()
    shift = np.array([-WALL, 0.0, 0.0])
    inner = CompositeCurve([s.translated(shift) for s in outer.segments], outer.continuity,
                           k=[g[0] for g in outer.g_parameters], beta2=[g[1] for g in outer.g_parameters],
                           beta3=[g[2] for g in outer.g_parameters])
    inner_back = [s.reversed() for s in reversed(inner.segments)]
    w_out = ght_wire(outer)
    w_in = ght_wire(inner_back)
    top = Edge.make_line(tuple(outer.segments[-1].evaluate(1.0)), tuple(inner_back[0].evaluate(0.0)))
    bottom = Edge.make_line(tuple(inner_back[-1].evaluate(1.0)), tuple(outer.segments[0].evaluate(0.0)))
    wire = Wire(list(w_out.edges()) + [top] + list(w_in.edges()) + [bottom])
    with exact_edges():
        solid = revolve(Face(wire), Axis.Z, 360)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    step = write_step(solid, out / "vase_revolve.step")
    exact = _pappus_volume(outer, inner)
    devs = [d.max_deviation for d in w_out.ght_bspline + w_in.ght_bspline]
    # Pappus: moving the profile boundary (length L, distance <= x_max + δ from the axis) by at
    # most δ changes the volume by at most 2π (x_max + δ) (L δ + π δ²)
    segs = outer.segments + inner_back
    bound = sum(
        2 * np.pi * (float(np.abs(s.control_points[:, 0]).max()) + d) * (s.length * d + np.pi * d * d)
        for s, d in zip(segs, devs)
    )
    volume = solid_volume(solid)
    return {
        "step": step,
        "volume": volume,
        "exact_volume": exact,
        "relative_volume_error": abs(volume - exact) / exact,
        "relative_volume_error_bound": bound / exact,
        "max_deviation": max(devs),
        "joints": [str(r) for r in outer.joint_reports()],
        "joint_g_orders": [r.g_order for r in outer.joint_reports()],
        "valid": is_valid(solid),
    }


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python examples/vase_revolve.py OUT_DIR")
    for key, value in main(sys.argv[1]).items():
        print(f"{key}: {value}")
