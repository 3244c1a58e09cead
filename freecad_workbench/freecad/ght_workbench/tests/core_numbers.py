"""Reference numbers of the ght_cad core, computed identically in FreeCAD's Python (numpy 1.24)
and in the project's environment (numpy 2); the pytest side compares the two to ~1e-12.

Imports ght_cad only (no FreeCAD), so pytest can load this file directly.
"""

from __future__ import annotations

from typing import Any, Callable

import numpy as np

#: tolerance of the B-spline fit in :func:`_bspline`. An adaptive fit places its knots from
#: measured errors |f - C| ~ tol, which carry rounding noise of ~1e-14 absolute, so knots and
#: values of fits made with different numpy/scipy builds agree to the fit tolerance, not to 1e-12:
#: keys in FIT_KEYS are compared with FIT_KEYS[key] (absolute), every other key to 1e-12 relative.
BSPLINE_TOL = 1e-6
FIT_KEYS = {"bspline/knots": 1e-3, "bspline/at_t": 2 * BSPLINE_TOL, "bspline/max_deviation": BSPLINE_TOL}

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
    from ght_cad.surfaces.bspline import curve_to_bspline

    c = GHTCurve(POINTS, 0.3, -0.2, 0.1)
    d = curve_to_bspline(c, tol=BSPLINE_TOL)
    out["bspline/knots"] = d.knots
    out["bspline/at_t"] = d.evaluate(T)
    out["bspline/max_deviation"] = float(d.max_deviation)


def _join(out: dict[str, Any]) -> None:
    from ght_cad import GHTCurve
    from ght_cad.curves.continuity import join

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
    pat = unroll(developable_from_planes(planes, boundary, 0.0, 0.0, -1.0), rulings=5, samples=33)
    out["unroll/cylinder/area"] = float(pat.area)
    out["unroll/cylinder/outline0"] = pat.outlines[0]
    out["unroll/cylinder/bend_lines"] = pat.bend_lines
    planes2 = [(-10.0, 1.0, 0.0, 0.2), (-10.0, 1.0, 1.0, 0.1), (-10.0, 0.0, 1.0, 0.2)]
    pat2 = unroll(developable_from_planes(planes2, boundary, 0.1, -0.2, -0.6), rulings=5, samples=33)
    out["unroll/general/area"] = float(pat2.area)
    out["unroll/general/outline0"] = pat2.outlines[0]


def _problems(out: dict[str, Any]) -> None:
    from ght_cad import GHTCurve
    from ght_cad.optimize.problems import CurveFairnessProblem, DualCurveFairnessProblem, StripProblem

    X = np.array([[0.1, -0.4, 0.3], [-0.9, 0.8, -1.0], [0.5, 0.5, 0.9]])
    c = GHTCurve(POINTS, 0.0, 0.0, 0.0)
    p = CurveFairnessProblem(c, objective={"AL": 1.0, "En": 0.01, "CVEn": 1e-4})
    out["problems/curve_fairness/measures"] = p.measures(X)
    planes = [(-10.0, 1.0, 0.0, 0.2), (-10.0, 1.0, 1.0, 0.1), (-10.0, 0.0, 1.0, 0.2)]
    q = DualCurveFairnessProblem(planes, objective="En")
    out["problems/dual_fairness/values"] = q(X)
    a = GHTCurve([(0, 0, 0), (10, 2, 0), (20, 0, 0)])
    b = GHTCurve([(0, 0, 10), (8, 6, 10), (20, 3, 10)])
    s = StripProblem(a, b)
    out["problems/strip/values"] = s(np.hstack([X, X[::-1]]))


SECTIONS: dict[str, Callable[[dict[str, Any]], None]] = {
    "basis": _basis,
    "curve": _curve,
    "bspline": _bspline,
    "join": _join,
    "developable": _developable,
    "unroll": _unroll,
    "problems": _problems,
}


def compute() -> dict[str, Any]:
    """All reference numbers as ``{key: list | float}`` (JSON-ready)."""
    out: dict[str, Any] = {}
    for fn in SECTIONS.values():
        fn(out)
    return {k: (np.asarray(v, dtype=float).tolist() if not isinstance(v, float) else v) for k, v in out.items()}
