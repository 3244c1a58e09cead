"""Duct transition from control planes: half of an oblique round-to-offset transition piece.

The transition joins a round inlet (radius 1, in the plane z = 0) to an outlet in the tilted plane
z = 2.5 + 0.15 x. Its side is built from control planes tangent to an oblique cone (apex
``APEX``): the first segment from four planes covering 0°..90° of the inlet, the second solved by
a G2 join of the 4-D dual curves (spec 5.6) and three free planes up to 180°. The two segments
form one shell with a shared joint ruling; the other half is its mirror image in y = 0.
Every control plane passes through the apex, so the edge of regression is the apex, safely
outside the strip.

Run: ``python examples/duct_transition.py [OUT_DIR]``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

APEX = np.array([1.5, 0.0, 6.0])
INLET = (0.0, 0.0, 0.0, 1.0)  # z = 0
OUTLET = (-2.5, -0.15, 0.0, 1.0)  # z = 2.5 + 0.15 x


def tangent_plane(phi_deg: float) -> np.ndarray:
    """Plane through the apex tangent to the inlet circle (radius 1) at angle ``phi``."""
    from ght_cad.surfaces.planes import plane_from_points

    p = math.radians(phi_deg)
    base = np.array([math.cos(p), math.sin(p), 0.0])
    tangent = np.array([-math.sin(p), math.cos(p), 0.0])
    U = plane_from_points(base, base + tangent, APEX)
    # orient every normal outwards (away from the duct axis) so the dual curve does not flip
    return U if U[1:] @ base > 0 else -U


def build() -> Any:
    """The two-segment composite (a :class:`ght_cad.developables.envelope.CompositeDevelopable`)."""
    from ght_cad import developable_from_planes
    from ght_cad.developables.envelope import CompositeDevelopable, join_developable

    first = developable_from_planes([tangent_plane(a) for a in (0, 30, 60, 90)], [INLET, OUTLET], gamma=-1.0)
    free = [tangent_plane(a) for a in (100, 110, 120, 140, 160, 180)]  # rows 0..2 are solved
    second = join_developable(first, "G2", free, mu=0.0, nu=0.0, gamma=-1.0, k=1.0)
    return CompositeDevelopable([first, second])


def main(out_dir: str | Path = "out") -> dict[str, Any]:
    """Build the transition, export ``duct_transition.step`` (one shell of two faces) and the
    flat pattern ``duct_transition_flat.dxf``.

    Returns:
        Report dict: paths, validity, face count, θ_max of each face (OCCT normals), normal jump
        across the shared ruling, the measured joint order, flat-pattern relative errors.
    """
    from ght_cad.cad.developable_faces import face_developability, joint_normal_deviation, shell_faces
    from ght_cad.cad.occ import is_valid, write_step

    from ght_cad.unrolling.unroll import unroll_composite

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    duct = build()
    shell = duct.to_shell()
    step = write_step(shell, out / "duct_transition.step")
    joint = duct.joints()[0]
    # both strips as one flat blank: they meet G2, so the second is placed across the joint ruling
    pattern = unroll_composite(duct.segments, units="m", labels=["first", "second"], join=True, join_label="duct")
    dxf = out / "duct_transition_flat.dxf"
    pattern.export_dxf(dxf)
    return {
        "step": str(step),
        "dxf": str(dxf),
        "flat_errors": dict(pattern.errors),
        "flat_panels": len(pattern.panels),
        "flat_area": pattern.area,
        "strip_areas_3d": [p["area_3d"] for p in pattern.panels[0].info.get("parts", [])],
        "valid": is_valid(shell),
        "faces": len(shell_faces(shell)),
        "theta_max_exact_deg": max(d.theta_max for d in duct.developability()),
        "theta_max_faces_deg": [face_developability(f).theta_max for f in shell_faces(shell)],
        "joint_normal_jump_deg": joint_normal_deviation(shell),
        "joint_order": joint.order,
    }


if __name__ == "__main__":
    report = main(sys.argv[1] if len(sys.argv) > 1 else "out")
    for key, value in report.items():
        print(f"{key}: {value}")
