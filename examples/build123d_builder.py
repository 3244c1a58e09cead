r"""build123d builder mode: a sheet-metal blank with exactly round corners from GHT-Bézier arcs.

A rectangular plate ``W × H`` whose four corners are quarter circles of radius ``R``, each one
GHT-Bézier curve of degree 2 with γ = -1, μ = ν = 0 on the control points ``c + R e1``,
``c + R (e1 + e2)``, ``c + R e2`` (spec section 1: the seed is then ``(1-s, s+c-1, 1-c)`` and the
curve is the exact quarter circle, no rational weights). The outline is built in ``BuildLine``
from build123d ``Line`` objects and :class:`ght_cad.cad.curves.GHTBezierLine`, turned into a face
and extruded to the sheet thickness inside :func:`ght_cad.cad.curves.exact_edges` (keeps the
certified B-spline edges through build123d's clean-up). A circular hole of radius ``R/2`` made of
four GHT arcs is cut in the middle.

Checks (returned by :func:`main`): the solid's volume against the closed form
``T (W H - (4 - π) R² - π R²/4)`` and the length of each corner edge against ``π R / 2``.

Run: ``python examples/build123d_builder.py OUT_DIR`` (writes ``OUT_DIR/builder_plate.step``).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

W, H, R, T = 120.0, 80.0, 15.0, 3.0


def quarter_arc(center: tuple[float, float], start_dir: tuple[float, float], end_dir: tuple[float, float], r: float):
    """Control points of the exact quarter circle (γ = -1) from ``center + r·start_dir`` to ``center + r·end_dir``."""
    cx, cy = center
    (ax, ay), (bx, by) = start_dir, end_dir
    return [(cx + r * ax, cy + r * ay), (cx + r * (ax + bx), cy + r * (ay + by)), (cx + r * bx, cy + r * by)]


def main(out_dir: str | Path) -> dict[str, Any]:
    """Build the plate in builder mode, write STEP, return measured vs closed-form numbers."""
    from build123d import BuildLine, BuildPart, BuildSketch, Line, Mode, extrude, make_face

    from ght_cad.cad.curves import GHTBezierLine, exact_edges
    from ght_cad.cad.occ import is_valid, write_step

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    w, h = W / 2, H / 2
    corners = [  # (centre, start direction, end direction), counter-clockwise
        ((w - R, -h + R), (0, -1), (1, 0)),
        ((w - R, h - R), (1, 0), (0, 1)),
        ((-w + R, h - R), (0, 1), (-1, 0)),
        ((-w + R, -h + R), (-1, 0), (0, -1)),
    ]
    arcs = []
    with exact_edges():
        with BuildPart() as part:
            with BuildSketch():
                with BuildLine():
                    for k, (c, a, b) in enumerate(corners):
                        pts = quarter_arc(c, a, b, R)
                        arcs.append(GHTBezierLine(*pts, gamma=-1.0))
                        nxt = corners[(k + 1) % 4]
                        Line(pts[-1], quarter_arc(*nxt, R)[0])
                make_face()
                with BuildLine():  # hole: four exact quarter circles of radius R/2 around the origin
                    dirs = [(1, 0), (0, 1), (-1, 0), (0, -1)]
                    for k in range(4):
                        GHTBezierLine(*quarter_arc((0, 0), dirs[k], dirs[(k + 1) % 4], R / 2), gamma=-1.0)
                make_face(mode=Mode.SUBTRACT)
            extrude(amount=T)
    solid = part.part
    step = write_step(solid, out / "builder_plate.step")
    exact_volume = T * (W * H - (4 - math.pi) * R**2 - math.pi * (R / 2) ** 2)
    return {
        "step": step,
        "valid": is_valid(solid),
        "volume": solid.volume,
        "volume_exact": exact_volume,
        "volume_rel_error": abs(solid.volume / exact_volume - 1.0),
        "corner_length_rel_error": max(abs(a.length / (math.pi * R / 2) - 1.0) for a in arcs),
    }


if __name__ == "__main__":
    result = main(sys.argv[1] if len(sys.argv) > 1 else "example-out")
    for key, value in result.items():
        print(f"{key}: {value}")
