r"""Glyph/logo example: an "O"-like glyph whose outline and counter are G3/G2-joined GHT segments.

The outer outline is a closed chain of four degree-7 GHT-Bézier segments with G3 and G2 joints
(alternating, G parameters k, β2, β3 chosen per joint), the counter (hole) a closed chain of four
degree-5 segments with G2 joints. Both become certified B-spline wires
(:func:`ght_cad.cad.curves.ght_wire`, deviation <= 1e-7 × size, end derivatives exact so the
G2/G3 joints survive in the B-rep), the face is extruded in build123d's builder mode inside
:func:`~ght_cad.cad.curves.exact_edges` (so no edge is re-approximated) and written to STEP.

Run: ``python examples/glyph_logo.py OUT_DIR`` (writes ``OUT_DIR/glyph_logo.step``).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

from ght_cad import GHTCurve
from ght_cad.curves.composite import CompositeCurve

HEIGHT = 4.0


def _superellipse(a: float, b: float, e: float, tilt: float, center: tuple[float, float]):
    """Point on a rotated superellipse |x/a|^e + |y/b|^e = 1 at polar-like angle θ."""

    def point(theta: float) -> tuple[float, float]:
        c, s = np.cos(theta), np.sin(theta)
        x = a * np.sign(c) * abs(c) ** (2.0 / e)
        y = b * np.sign(s) * abs(s) ** (2.0 / e)
        ct, st = np.cos(tilt), np.sin(tilt)
        return (center[0] + ct * x - st * y, center[1] + st * x + ct * y)

    return point


def _chain(point, degree: int, continuity: list[str]) -> CompositeCurve:
    """Four segments sampled from ``point`` over quarter turns, then joined by the solver.

    The G parameters of each G joint are the "natural" ones of the unjoined segments (the
    least-squares k, β2, β3 that :func:`ght_cad.curves.continuity.measure_continuity` reports), so the
    solver moves the dependent control points as little as possible.
    """
    from ght_cad.curves.continuity import measure_continuity

    segs = []
    for q in range(4):
        th = np.linspace(q * np.pi / 2, (q + 1) * np.pi / 2, degree + 1)
        segs.append(GHTCurve([point(x) for x in th], 0.3, 0.3, -0.2))
    ks, b2s, b3s = [], [], []
    for j, c in enumerate(continuity):
        rep = measure_continuity(segs[j], segs[(j + 1) % 4])
        geometric = c.upper().startswith("G")
        ks.append(rep.k if geometric else 1.0)
        b2s.append(rep.beta2 if geometric else 0.0)
        b3s.append(rep.beta3 if geometric else 0.0)
    return CompositeCurve(segs, continuity, closed=True, k=ks, beta2=b2s, beta3=b3s)


def glyph_outlines() -> tuple[CompositeCurve, CompositeCurve]:
    """(outer outline with G3/G2 joints, counter with G2 joints) as closed composite curves."""
    outer = _chain(_superellipse(10.0, 12.0, 3.0, 0.0, (0.0, 0.0)), 7, ["G3", "G2", "G3", "G2"])
    inner = _chain(_superellipse(5.0, 7.5, 2.4, 0.35, (0.4, 0.3)), 5, ["G2"] * 4)
    return outer, inner


def _green_area(cc: CompositeCurve) -> float:
    from ght_cad.curves.curve import gauss_legendre

    t, w = gauss_legendre(64)
    total = 0.0
    for s in cc.segments:
        p, d = s.evaluate(t), s.derivative(t, 1)
        total += 0.5 * float(np.sum(w * (p[:, 0] * d[:, 1] - p[:, 1] * d[:, 0])))
    return abs(total)


def main(out_dir: str | Path) -> dict[str, Any]:
    """Build the glyph solid and export ``glyph_logo.step`` into ``out_dir``.

    Returns:
        ``{"step", "volume", "exact_volume", "relative_volume_error",
        "relative_volume_error_bound", "max_deviation", "joints", "joint_g_orders", "valid"}``:
        the solid's volume against ``H × (A_outer - A_counter)`` from Green's theorem on the exact
        GHT curves, with the bound ``H Σ (L_i δ_i + π δ_i²)`` implied by the certified
        deviations δ_i of the segments (lengths L_i), the largest deviation and the measured
        joint continuity of both chains.
    """
    from build123d import BuildLine, BuildPart, BuildSketch, Mode, extrude, make_face

    from ght_cad.cad.curves import GHTCompositeLine, exact_edges
    from ght_cad.cad.occ import is_valid, write_step
    from ght_cad.cad.occ import volume as solid_volume

    outer, inner = glyph_outlines()
    with exact_edges():
        with BuildPart() as part:
            with BuildSketch():
                with BuildLine():
                    outline = GHTCompositeLine(outer)
                make_face()
                with BuildLine():
                    counter = GHTCompositeLine(inner)
                make_face(mode=Mode.SUBTRACT)
            extrude(amount=HEIGHT)
    solid = part.part
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    step = write_step(solid, out / "glyph_logo.step")
    exact = HEIGHT * (_green_area(outer) - _green_area(inner))
    datas = outline.ght_bspline + counter.ght_bspline
    devs = [d.max_deviation for d in datas]
    # moving a boundary of length L by at most δ changes the area by at most L δ + π δ² (Steiner)
    segs = outer.segments + inner.segments
    bound = HEIGHT * sum(s.length * d + np.pi * d * d for s, d in zip(segs, devs))
    volume = solid_volume(solid)
    return {
        "step": step,
        "volume": volume,
        "exact_volume": exact,
        "relative_volume_error": abs(volume - exact) / exact,
        "relative_volume_error_bound": bound / exact,
        "max_deviation": max(devs),
        "joints": [str(r) for r in outer.joint_reports()] + [str(r) for r in inner.joint_reports()],
        "joint_g_orders": [r.g_order for r in outer.joint_reports() + inner.joint_reports()],
        "valid": is_valid(solid),
    }


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python examples/glyph_logo.py OUT_DIR")
    for key, value in main(sys.argv[1]).items():
        print(f"{key}: {value}")
