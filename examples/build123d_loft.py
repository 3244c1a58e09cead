r"""build123d: a round-to-oval duct transition as the exact developable loft between two edges.

The inlet is a circle of radius 100 (z = 0), the outlet an ellipse 160 × 60 at z = 250, shifted by
40 in x. The duct is made of two mirror-image halves (a seam on each side, as sheet-metal
transitions are); one half is lofted between two plain build123d edges: the half circle and the
half ellipse. The rulings pair points
where the two tangents are parallel (the tangent-plane condition ``det(a', b', b - a) = 0`` of spec
5.7 for rails in parallel planes), so the transition is developable and unrolls into ONE flat
panel with no stretch: the sheet-metal blank, written as DXF/SVG/PNG with bend lines along the
rulings. Algebra mode gives the surface (one B-spline face); builder mode thickens it into a 2 mm
sheet solid. (A loft of the full closed rails is one face closed by a seam; OCCT's thickening of
such a seam face gives a wrong volume, so sheets are made from the halves.)

Checks (returned by :func:`main`): θ of the core loft and of the STEP face, the flat area against
the STEP face area, the rails covered by the face's edges.

Run: ``python examples/build123d_loft.py OUT_DIR``.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

R_IN, A_OUT, B_OUT, H, SHIFT, T = 100.0, 160.0, 60.0, 250.0, 40.0, 2.0


def main(out_dir: str | Path) -> dict[str, Any]:
    """Build the transition, its sheet solid and its flat pattern; return measured numbers."""
    from build123d import BuildPart, Edge, Face, Plane, Shape, thicken

    import ght_cad
    from ght_cad.cad.developable_faces import face_developability, shell_faces
    from ght_cad.cad.loft import developable_loft
    from ght_cad.cad.occ import is_valid, read_step, write_step

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    inlet = Edge.make_circle(R_IN, start_angle=0, end_angle=180)
    outlet = Edge.make_ellipse(A_OUT, B_OUT, Plane.XY.offset(H).shift_origin((SHIFT, 0, H)), start_angle=0, end_angle=180)

    # algebra mode: the surface itself
    duct = developable_loft(inlet, outlet)
    loft = duct.ght_loft
    write_step(duct, out / "duct_loft.step")

    # builder mode: the loft's faces join BuildPart's pending faces; thicken makes the sheet
    with BuildPart() as sheet:
        developable_loft(inlet, outlet)
        thicken(amount=T)
    write_step(sheet.part, out / "duct_loft_sheet.step")

    # the flat pattern: one panel, bend lines along the rulings
    pattern = ght_cad.unroll(loft, rulings=24)
    pattern.export_dxf(out / "duct_loft_pattern.dxf")
    pattern.export_svg(out / "duct_loft_pattern.svg")
    pattern.plot_png(out / "duct_loft_pattern.png", title="round-to-oval transition: flat pattern")

    back = Shape.cast(read_step(out / "duct_loft.step"))
    step_area = sum(p.area_3d for p in ght_cad.unroll(back).panels)
    lo, hi = pattern.panels[0].bbox()
    res = {
        "segments": [sg.kind for sg in loft.segments],
        "valid": is_valid(duct) and is_valid(back),
        "sheet_valid": bool(sheet.part.is_valid),
        "theta_core_deg": float(loft.report.theta_max_deg),
        "theta_step_deg": max(face_developability(Face(f)).theta_max for f in shell_faces(back)),
        "flat_area": float(pattern.area),
        "area_rel_error": abs(pattern.area - step_area) / step_area,
        "max_deviation": float(duct.ght_max_deviation),
        "panels": len(pattern.panels),
        "blank_size": [float(x) for x in (hi - lo)],
        "sheet_volume": float(sheet.part.volume),
        "step": str(out / "duct_loft.step"),
        "dxf": str(out / "duct_loft_pattern.dxf"),
        "svg": str(out / "duct_loft_pattern.svg"),
        "png": str(out / "duct_loft_pattern.png"),
    }
    return res


if __name__ == "__main__":
    result = main(sys.argv[1] if len(sys.argv) > 1 else "out_build123d_loft")
    for k, v in result.items():
        print(f"{k}: {v}")
