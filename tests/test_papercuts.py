"""Core papercuts of issue 25: numbers from numpy arrays of any dtype."""

from __future__ import annotations

import numpy as np
import pytest

import ght_cad
from ght_cad.loft import developable_loft

PLANES = [(-400, 1, 0, 0.5), (-400, 1, 1, 0.5), (-400, 0, 1, 0.5)]
CUTS = [(0, 0, 0, 1), (-400, 0, 0, 1)]


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


def test_unroll_is_one_coherent_module_that_can_be_called():
    """``ght_cad.unroll`` is the submodule and callable as the stable function of spec section 9;
    every documented spelling works in a fresh interpreter (import order matters)."""
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    code = r"""
import inspect, types
import ght_cad.unroll
import ght_cad.unroll as m
from ght_cad.unroll import unroll_composite, ruled_area
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
