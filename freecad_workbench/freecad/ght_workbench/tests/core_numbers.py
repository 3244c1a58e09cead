"""Reference numbers of the ght_cad core, computed identically in FreeCAD's Python (numpy 1.24)
and in the project's environment (numpy 2); the pytest side compares the two to ~1e-12.

Imports ght_cad only (no FreeCAD), so pytest can load this file directly. Parts of the core that
are not present yet are skipped (the key is absent in both runs).
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

PARAMS = [(0.0, 0.0, 0.0), (0.7, -0.3, -1.0), (-1.0, 1.0, 0.4), (0.25, 0.5, 1.0)]
T = np.linspace(0.0, 1.0, 11)
POINTS = [(0.0, 0.0, 0.0), (10.0, 20.0, 0.0), (30.0, 20.0, 5.0), (40.0, 0.0, 0.0), (55.0, -5.0, 2.0)]


def _basis(out: dict[str, Any]) -> None:
    from ght_cad import basis

    for m in (2, 3, 6):
        for k, (mu, nu, gamma) in enumerate(PARAMS):
            for r in (0, 1, 2, 3):
                out[f"basis/m{m}/p{k}/d{r}"] = basis(T, m, mu, nu, gamma, derivative=r)


def _curve(out: dict[str, Any]) -> None:
    from ght_cad import GHTCurve

    for k, (mu, nu, gamma) in enumerate(PARAMS):
        c = GHTCurve(POINTS, mu, nu, gamma)
        for r in range(4):
            out[f"curve/p{k}/d{r}"] = c.derivative(T, r)
        out[f"curve/p{k}/length"] = c.arc_length()
        out[f"curve/p{k}/curvature"] = c.curvature(T)
        out[f"curve/p{k}/torsion"] = c.torsion(T)


def _bspline(out: dict[str, Any]) -> None:
    from ght_cad import GHTCurve
    from ght_cad.bspline import curve_to_bspline

    c = GHTCurve(POINTS, 0.3, -0.2, 0.1)
    d = curve_to_bspline(c, tol=1e-6)
    out["bspline/knots"] = d.knots
    out["bspline/poles"] = d.poles
    out["bspline/at_t"] = d.evaluate(T)


def _join(out: dict[str, Any]) -> None:
    from ght_cad import GHTCurve
    from ght_cad.continuity import join

    a = GHTCurve(POINTS[:4], 0.2, 0.4, -0.5)
    b = join(a, "G2", [(0, 0, 0), (0, 0, 0), (0, 0, 0), (60, 10, 0), (70, 0, 3)], mu=-0.6, k=1.5, beta2=0.3)
    out["join/G2/points"] = b.control_points


def _developable(out: dict[str, Any]) -> None:
    from ght_cad import developable_from_planes

    planes = [(-10.0, 1.0, 0.0, 0.2), (-10.0, 1.0, 1.0, 0.1), (-10.0, 0.0, 1.0, 0.2)]
    boundary = [(0.0, 0.0, 0.0, 1.0), (-20.0, 0.0, 0.0, 1.0)]
    s = developable_from_planes(planes, boundary, 0.1, -0.2, -0.6)
    out["developable/a"] = s.a(T)
    out["developable/b"] = s.b(T)
    dev = s.developability()
    out["developable/R"] = dev.R
    out["developable/dd"] = dev.dd


def _unroll(out: dict[str, Any]) -> None:
    from ght_cad import developable_from_planes, unroll

    planes = [(-10.0, 1.0, 0.0, 0.0), (-10.0, 1.0, 1.0, 0.0), (-10.0, 0.0, 1.0, 0.0)]
    boundary = [(0.0, 0.0, 0.0, 1.0), (-20.0, 0.0, 0.0, 1.0)]
    pat = unroll(developable_from_planes(planes, boundary, 0.0, 0.0, -1.0))
    out["unroll/area"] = float(pat.area) if hasattr(pat, "area") else float("nan")
    outline = pat.outline() if callable(getattr(pat, "outline", None)) else getattr(pat, "outline", None)
    if outline is not None:
        out["unroll/outline0"] = np.asarray(outline[0] if isinstance(outline, (list, tuple)) else outline, dtype=float)


SECTIONS: dict[str, Callable[[dict[str, Any]], None]] = {
    "basis": _basis,
    "curve": _curve,
    "bspline": _bspline,
    "join": _join,
    "developable": _developable,
    "unroll": _unroll,
}


def compute() -> dict[str, Any]:
    """All reference numbers as ``{key: list | float}`` (JSON-ready); missing core parts skipped."""
    out: dict[str, Any] = {}
    for name, fn in SECTIONS.items():
        part: dict[str, Any] = {}
        try:
            fn(part)
        except ImportError:
            continue
        except AttributeError:
            continue
        out.update(part)
    return {k: (np.asarray(v, dtype=float).tolist() if not isinstance(v, float) else v) for k, v in out.items()}
