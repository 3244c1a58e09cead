r"""cadquery: a slotted flange profile with GHT-Bézier ends, extruded with the ght_cad plugin.

``import ght_cad.cad.cq_plugin`` adds ``Workplane.ghtBezier`` (one certified B-spline edge per
GHT-Bézier curve, in workplane coordinates). The profile is a stadium (slot) of length ``L`` and
width ``2 R``: two straight sides and two half circles, each half circle made of two exact
quarter circles (degree 2, γ = -1, μ = ν = 0). A second, free-form GHT-Bézier edge with
μ = 0.5, ν = -0.3, γ = 0.2 shapes a tab on the top side. The profile is extruded by ``T`` with
``clean=False`` (keeps the certified edges) and exported to STEP.

Checks (returned by :func:`main`): the slot's volume against ``T (2 R L + π R²)`` plus the tab area
computed independently from the GHT curve (Green's theorem on its exact parametrization).

Run: ``python examples/cadquery_script.py OUT_DIR`` (writes ``OUT_DIR/cq_flange.step``).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path
from typing import Any

L, R, T = 60.0, 12.0, 4.0
TAB = [(-10.0, 12.0), (-6.0, 26.0), (6.0, 26.0), (10.0, 12.0)]  # tab on the top side y = R
TAB_SHAPE = {"mu": 0.5, "nu": -0.3, "gamma": 0.2}


def tab_area() -> float:
    r"""Area between the tab curve and the line y = R: ``∫ (y - R) x'(t) dt`` (reversed sign), exact quadrature."""
    from ght_cad import GHTCurve
    from ght_cad.curves.curve import integrate

    c = GHTCurve(TAB, **TAB_SHAPE)
    return abs(integrate(lambda t: (c.evaluate(t)[:, 1] - R) * c.derivative(t, 1)[:, 0]))


def main(out_dir: str | Path) -> dict[str, Any]:
    """Build the flange with cadquery + the ght_cad plugin, write STEP, return checks."""
    import cadquery as cq

    import ght_cad.cad.cq_plugin  # noqa: F401  (registers Workplane.ghtBezier / ghtCurve)
    from ght_cad.cad.occ import is_valid, write_step

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    a = L / 2
    q = dict(gamma=-1.0, includeCurrent=True)
    # the tab runs from x = +10 to x = -10 (right to left): reverse its control points
    tab_pts = TAB[::-1]
    shape_rev = {"mu": TAB_SHAPE["nu"], "nu": TAB_SHAPE["mu"], "gamma": TAB_SHAPE["gamma"]}  # reversal swaps μ, ν
    wp = (
        cq.Workplane("XY")
        .moveTo(-a, -R)
        .lineTo(a, -R)
        .ghtBezier([(a + R, -R), (a + R, 0)], **q)  # exact quarter circles (γ = -1)
        .ghtBezier([(a + R, R), (a, R)], **q)
        .lineTo(tab_pts[0][0], R)
        .ghtBezier(tab_pts[1:], includeCurrent=True, **shape_rev)
        .lineTo(-a, R)
        .ghtBezier([(-a - R, R), (-a - R, 0)], **q)
        .ghtBezier([(-a - R, -R), (-a, -R)], **q)
        .close()
        .extrude(T, clean=False)
    )
    solid = wp.val()
    step = write_step(solid.wrapped, out / "cq_flange.step")
    exact = T * (2 * R * L + math.pi * R**2 + tab_area())
    vol = solid.Volume()
    return {
        "step": step,
        "valid": is_valid(solid.wrapped),
        "volume": vol,
        "volume_exact": exact,
        "volume_rel_error": abs(vol / exact - 1.0),
    }


if __name__ == "__main__":
    result = main(sys.argv[1] if len(sys.argv) > 1 else "example-out")
    for key, value in result.items():
        print(f"{key}: {value}")
