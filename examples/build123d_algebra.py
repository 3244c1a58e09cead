r"""build123d algebra mode: a conical duct segment from control planes, thickened to sheet metal.

The exact quarter cone of spec section 1 (control planes ``(-k h, 1, 0, k)``, ``(-k h, 1, 1, k)``,
``(-k h, 0, 1, k)``, γ = -1, μ = ν = 0, apex ``(0, 0, h)``, base radius ``k h``) is cut by the
planes z = 0 and z = h/2 (:func:`ght_cad.developable_from_planes`), turned into a certified
B-spline face (``surface.to_face()``), combined in algebra mode with build123d operations
(``thicken``, ``Pos``/``Rot`` placement, ``+``) into a four-quarter duct of sheet thickness ``T``,
and unrolled into a flat pattern (:func:`ght_cad.unroll`, DXF and SVG).

Checks (returned by :func:`main`): the face area and the pattern area against the closed form of
the frustum, ``(π/2) (r1 + r2)/2 · s`` with slant ``s``; the sheet volume against
``T × area`` (exact to first order in T); the developability degree of the face.

Run: ``python examples/build123d_algebra.py OUT_DIR``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

H, K, T = 800.0, 0.5, 2.0  # apex height, radius/height ratio (base radius K*H = 400), sheet thickness


def main(out_dir: str | Path) -> dict[str, Any]:
    """Build the duct in algebra mode, write STEP/DXF/SVG, return measured vs closed-form numbers."""
    from build123d import Compound, Rot, thicken

    import ght_cad
    from ght_cad.cad.occ import is_valid, write_step

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    kh = K * H
    planes = [(-kh, 1, 0, K), (-kh, 1, 1, K), (-kh, 0, 1, K)]
    boundary = [(0, 0, 0, 1), (-H / 2, 0, 0, 1)]  # z = 0 and z = H/2
    surface = ght_cad.developable_from_planes(planes, boundary, mu=0.0, nu=0.0, gamma=-1.0)
    quarter = surface.to_face()
    sheet = thicken(quarter, T)  # algebra mode: functions on shapes
    duct = Compound([Rot(0, 0, 90 * k) * sheet for k in range(4)])  # four quarters around the axis
    step = write_step(duct, out / "algebra_duct.step")
    pattern = ght_cad.unroll(surface)
    dxf = pattern.export_dxf(out / "algebra_duct_quarter.dxf")
    svg = pattern.export_svg(out / "algebra_duct_quarter.svg")
    r2, r1 = kh, kh / 2
    slant = math.hypot(r2 - r1, H / 2)
    area_exact = (math.pi / 2) * 0.5 * (r1 + r2) * slant
    dev = surface.developability()
    return {
        "step": step,
        "dxf": str(dxf),
        "svg": str(svg),
        "valid": is_valid(duct) and is_valid(quarter),
        "solids": len(duct.solids()),
        "face_area": quarter.area,
        "area_exact": area_exact,
        "face_area_rel_error": abs(quarter.area / area_exact - 1.0),
        "pattern_area_rel_error": abs(pattern.area / area_exact - 1.0),
        "pattern_errors": pattern.errors,
        "sheet_volume_rel_error": abs(sheet.volume / (T * area_exact) - 1.0),
        "theta_max_deg": dev.theta_max,
        "duct_bbox_z": (duct.bounding_box().min.Z, duct.bounding_box().max.Z),
    }


if __name__ == "__main__":
    result = main(sys.argv[1] if len(sys.argv) > 1 else "example-out")
    for key, value in result.items():
        print(f"{key}: {value}")
