"""Ship-hull side plate from four control planes (enveloping developable, spec 5.2).

The designer gives four tangent planes of the plate — at the sheer (top), the side and towards the
bilge — as point + normal, and the two frame planes x = 0 and x = 12 (m) that bound it. The plate
is the envelope of the GHT dual curve of those planes: exactly developable, so it is cut from flat
steel with no stretching. The script exports the plate as one B-spline face (STEP) and its flat
pattern (DXF), and reports the developability measured on the exact surface and on the face.

Run: ``python examples/ship_hull_plate.py [OUT_DIR]``.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

#: control planes (point, normal): sheer strake to bilge, units m
CONTROL = [
    ((0.0, 5.0, 0.0), (0.0, 1.0, -0.15)),
    ((4.0, 5.3, -0.5), (0.05, 1.0, -0.4)),
    ((8.0, 5.2, -1.2), (0.1, 1.0, -0.8)),
    ((12.0, 4.6, -2.0), (0.2, 0.8, -1.2)),
]
#: frame planes bounding the plate: x = 0 (aft) and x = 12 (fore)
FRAMES = [(0.0, 1.0, 0.0, 0.0), (-12.0, 1.0, 0.0, 0.0)]
SHAPE = {"mu": 0.3, "nu": -0.2, "gamma": 0.1}


def build() -> Any:
    """The exact plate surface (an :class:`ght_cad.developables.envelope.EnvelopeDevelopable`)."""
    from ght_cad import developable_from_planes
    from ght_cad.surfaces.planes import plane_from_point_normal

    planes = [plane_from_point_normal(p, n) for p, n in CONTROL]
    return developable_from_planes(planes, FRAMES, **SHAPE)


def main(out_dir: str | Path = "out") -> dict[str, Any]:
    """Build the plate, export ``ship_hull_plate.step`` and ``ship_hull_plate_flat.dxf``.

    Returns:
        Report dict: paths, developability of the exact surface (θ_max, residual) and of the
        B-rep face (θ_max from OCCT normals), fit deviation, flat-pattern relative errors.
    """
    from ght_cad import unroll
    from ght_cad.cad.developable_faces import developable_surface_data, face_developability
    from ght_cad.cad.occ import is_valid, make_face, write_step

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    plate = build()
    exact = plate.developability()
    data = developable_surface_data(plate)
    face = make_face(data)
    step = write_step(face, out / "ship_hull_plate.step")
    fd = face_developability(face)
    pattern = unroll(plate, units="m", label="SHELL-P1")
    dxf = out / "ship_hull_plate_flat.dxf"
    pattern.export_dxf(dxf)
    ruling_mid = plate.evaluate(0.5, np.array([0.0, 1.0]))
    return {
        "step": str(step),
        "dxf": str(dxf),
        "valid": is_valid(face),
        "theta_max_exact_deg": exact.theta_max,
        "residual_exact": exact.residual_max,
        "theta_max_face_deg": fd.theta_max,
        "fit_deviation_m": data.max_deviation,
        "poles_u": int(data.poles.shape[0]),
        "flat_errors": dict(pattern.errors),
        "mid_ruling_length_m": float(np.linalg.norm(ruling_mid[1] - ruling_mid[0])),
    }


if __name__ == "__main__":
    report = main(sys.argv[1] if len(sys.argv) > 1 else "out")
    for key, value in report.items():
        print(f"{key}: {value}")
