"""Core papercuts of issue 25: numbers from numpy arrays of any dtype."""

from __future__ import annotations

import numpy as np
import pytest

import ght_cad
from ght_cad.developables.loft import developable_loft

PLANES = [(-400, 1, 0, 0.5), (-400, 1, 1, 0.5), (-400, 0, 1, 0.5)]
CUTS = [(0, 0, 0, 1), (-400, 0, 0, 1)]


@pytest.mark.slow
@pytest.mark.parametrize("dtype", [np.int32, np.int64, np.float32], ids=lambda d: np.dtype(d).name)
def test_core_constructors_take_numpy_numbers(dtype):
    """Points, planes and options given as numpy arrays/scalars of any dtype give what the same
    Python numbers give (integer planes scaled by 2 so that they are integers)."""
    c = ght_cad.GHTCurve(np.array([(0, 0), (4, 3), (8, 0)], dtype=dtype), mu=dtype(1), gamma=dtype(-1))
    ref = ght_cad.GHTCurve([(0.0, 0.0), (4.0, 3.0), (8.0, 0.0)], mu=1.0, gamma=-1.0)
    assert c.arc_length() == pytest.approx(ref.arc_length(), rel=1e-15)
    cone = ght_cad.developable_from_planes(np.array(PLANES, dtype=float) * 2, np.array(CUTS).astype(dtype),
                                           gamma=dtype(-1))
    pattern = ght_cad.unroll(cone, tol_deg=dtype(1), rulings=np.int64(4), thickness=dtype(4), k_factor=np.float32(0.5))
    assert pattern.errors["max"] < 1e-13
    chine = ght_cad.GHTCurve([(0, -700, 300), (1500, -1050, 200), (3000, -1150, 250), (4500, -950, 450)])
    sheer = ght_cad.GHTCurve([(0, -900, 1200), (1500, -1250, 1150), (3000, -1300, 1180), (4500, -1100, 1300)])
    loft = developable_loft(chine, sheer, max_step=np.float32(0.05), step_tol=np.float64(1e-6), samples=np.int32(33))
    assert loft.report.theta_max_deg < 1e-9


def test_no_dead_cadquery_plugin_entry_point_and_readme_says_how_to_activate():
    """cadquery 2.8 loads no plugins from entry points: the plugin is activated by importing
    ght_cad.cad.cq_plugin, and the metadata must not pretend otherwise."""
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    meta = tomllib.loads((root / "pyproject.toml").read_text())
    assert "cadquery.plugins" not in meta["project"].get("entry-points", {})
    readme = (root / "README.md").read_text()
    assert "import ght_cad.cad.cq_plugin" in readme
    assert "no entry point" in readme or "loads no plugins" in readme


@pytest.mark.slow
def test_unroll_is_one_coherent_module_that_can_be_called():
    """``ght_cad.unroll`` is the submodule and callable as the stable function of spec section 9;
    every documented spelling works in a fresh interpreter (import order matters)."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    code = r"""
import inspect, types
import ght_cad.unrolling.unroll
import ght_cad.unrolling.unroll as m
from ght_cad.unrolling.unroll import unroll_composite, ruled_area
from ght_cad import unroll as u
import ght_cad
assert isinstance(ght_cad.unroll, types.ModuleType), type(ght_cad.unroll)
assert m is ght_cad.unroll is u, (m, u)
assert m.unroll_composite is unroll_composite and m.ruled_area is ruled_area
assert list(inspect.signature(ght_cad.unroll).parameters)[0] == "surface_or_face"
cone = ght_cad.developable_from_planes([(-400, 1, 0, 0.5), (-400, 1, 1, 0.5), (-400, 0, 1, 0.5)],
                                       [(0, 0, 0, 1), (-400, 0, 0, 1)], gamma=-1)
a, b, c = ght_cad.unroll(cone), u(cone), ght_cad.unroll.unroll(cone)
assert a.area == b.area == c.area, (a.area, b.area, c.area)
print("ok")
"""
    for first in ("import ght_cad", "import ght_cad.unroll", "from ght_cad.unroll import unroll"):
        out = subprocess.run([sys.executable, "-c", first + "\n" + code], capture_output=True, text=True, cwd=root)
        assert out.returncode == 0 and out.stdout.strip() == "ok", (first, out.stderr[-2000:])


README_CONE = """
name = "readme-cone"
units = "mm"

[surface]
type = "planes"
planes = [[-400, 1, 0, 0.5], [-400, 1, 1, 0.5], [-400, 0, 1, 0.5]]
boundary_planes = [[0, 0, 0, 1], [-400, 0, 0, 1]]
gamma = -1.0
"""


def test_design_files_and_api_share_one_normalize_default():
    """The README's cone planes copied into a design file give the README's surface: the exact
    quarter cone frustum (area in closed form), not the +3.3 % non-conical one of unit normals."""
    from ght_cad.app.design import build_surface, parse_design_text, surface_area

    api = ght_cad.developable_from_planes(PLANES, CUTS, gamma=-1)
    design = parse_design_text(README_CONE, "readme-cone.toml")
    assert design.surface.normalize is False
    built = build_surface(design).surface
    # quarter frustum of the cone x^2 + y^2 = ((800 - z) / 2)^2: radii 400 and 200, height 400
    r1, r2, h = 400.0, 200.0, 400.0
    exact = 0.25 * np.pi * (r1 + r2) * np.hypot(r1 - r2, h)
    assert surface_area(built) == pytest.approx(exact, rel=1e-12)
    assert surface_area(api) == pytest.approx(exact, rel=1e-12)
    from pathlib import Path

    example = (Path(__file__).resolve().parents[1] / "examples" / "design_duct_two_strips.toml").read_text()
    assert "\nnormalize = false" in example
    comp = parse_design_text(example.replace("\nnormalize = false", "\n"), "two-strips-without-normalize.toml")
    assert comp.surface.normalize is False


def test_minimize_takes_scalar_objectives_and_scipy_bounds():
    """scipy users pass f(x) -> float and a list of (low, high) pairs or scipy.optimize.Bounds;
    ght_cad.optimize.minimize accepts those as well as population objectives and (lb, ub)."""
    from scipy.optimize import Bounds, rosen

    from ght_cad.core.errors import GHTError
    from ght_cad.optimize import minimize

    target = np.array([0.3, -0.2, 0.5])

    def scalar(x):                      # one point (dim,) -> float, as for scipy.optimize.minimize
        return float(np.sum((np.asarray(x) - target) ** 2))

    def population(X):
        return np.sum((X - target) ** 2, axis=1)

    pairs = [(-1.0, 1.0)] * 3
    for fun in (scalar, population):
        for bounds in (pairs, Bounds([-1.0] * 3, [1.0] * 3), (np.full(3, -1.0), np.full(3, 1.0)), np.array(pairs)):
            for method in ("hybrid", "pso"):
                r = minimize(fun, bounds, method, seed=0, **({"max_iter": 60} if method == "pso" else {}))
                assert np.allclose(r.x, target, atol=1e-3 if method == "pso" else 1e-6), (fun.__name__, bounds, method, r.x)
    r = minimize(rosen, [(-2, 2), (-2, 2)], seed=0)                    # scipy's own scalar objective
    assert np.allclose(r.x, [1.0, 1.0], atol=1e-4)
    r = minimize(scalar, [(-1, 1)] * 3, vectorized=False, seed=0)     # the kind can be given
    assert r.fun < 1e-12
    # two pairs that also read as (lb, ub) and give another box: refused, not guessed
    with pytest.raises(GHTError, match="ambiguous"):
        minimize(scalar, [(0.0, 1.0), (2.0, 3.0)])
    # one reading valid: taken
    assert minimize(lambda x: float(np.sum(x**2)), [(0.5, 1.0), (0.5, 1.0)], seed=0).fun == pytest.approx(0.5, abs=1e-9)


def test_shipped_plane_designs_state_normalize_explicitly():
    """The default changed (true -> false): every shipped design built from control planes writes
    its choice, so its output is what it was (default design and composite examples: as before)."""
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    files = sorted((root / "examples").glob("*.toml")) + [root / "ght_cad" / "data" / "default_design.toml"]
    seen = 0
    for f in files:
        data = tomllib.loads(f.read_text())
        for surf in [data.get("surface", {})] + list(data.get("surfaces", [])):
            if surf and surf.get("type", "planes") in ("planes", "composite") and ("planes" in surf or "segments" in surf):
                assert "normalize" in surf, f"{f.name}: a planes/composite surface without an explicit normalize"
                seen += 1
    assert seen >= 4
    assert tomllib.loads(files[-1].read_text())["surface"]["normalize"] is True
