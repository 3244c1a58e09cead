"""The cadquery Workplane plugin on its own: the ``[cadquery]`` extra (cadquery 2.8, OCP 7.9)
without build123d. Runs wherever cadquery is installed: in the suite's second environment
(``tests/test_install.py``, ``.venv-ocp79``) and, with build123d blocked in a subprocess, in any
environment that has both."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

cq = pytest.importorskip("cadquery")

from cad_checks import green_area as _green_area  # noqa: E402

import ght_cad.cad.cq_plugin  # noqa: E402,F401  (registers Workplane.ghtBezier / ghtCurve / developableLoft)
from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.cq_plugin import developable_loft_cq  # noqa: E402
from ght_cad.cad.occ import read_step, read_step_products, write_step  # noqa: E402
from ght_cad.core.errors import GHTError, NotDevelopableError  # noqa: E402

BLOCKER = Path(__file__).resolve().parent / "no_kernel"
ROOT = Path(__file__).resolve().parent.parent
PTS = [(1, 1.5), (2.5, 1.0), (3, 0)]
CHINE = GHTCurve([[0, -700, 300], [1500, -1050, 200], [3000, -1150, 250], [4500, -950, 450]])
SHEER = GHTCurve([[0, -900, 1200], [1500, -1250, 1150], [3000, -1300, 1180], [4500, -1100, 1300]])


def test_ght_bezier_profile_extrudes_to_the_exact_volume(tmp_path: Path) -> None:
    solid = cq.Workplane("XY").moveTo(0, 0).ghtBezier(PTS, mu=0.3, includeCurrent=True).close().extrude(2.0, clean=False).val()
    assert solid.isValid()
    exact = 2.0 * _green_area([GHTCurve([(0, 0)] + PTS, 0.3), GHTCurve([(3, 0), (1.5, 0), (0, 0)])])
    assert solid.Volume() == pytest.approx(exact, rel=1e-6)  # the edge's certified tolerance is 1e-7 of its size
    write_step(solid, tmp_path / "tab.step")
    back = read_step(tmp_path / "tab.step")
    assert cq.Shape.cast(back).Volume() == pytest.approx(solid.Volume(), rel=1e-9)
    assert read_step_products(tmp_path / "tab.step") == ["tab"]


def test_ght_curve_maps_local_coordinates_exactly() -> None:
    curve = GHTCurve([(0, 0)] + PTS, 0.3)
    e = cq.Workplane("XZ").ghtCurve(curve).val()  # XZ: local y -> world Z
    for t in (0.0, 0.3, 0.5, 1.0):
        p = curve.evaluate(np.array([t]))[0]
        assert np.allclose(e.positionAt(t, mode="parameter").toTuple(), [p[0], 0.0, p[1]], atol=1e-7 * 3.5)
    with pytest.raises(GHTError, match=r"curve has dimension 4; .*2-D or 3-D"):
        cq.Workplane("XY").ghtCurve(GHTCurve(np.zeros((3, 4)) + np.arange(3)[:, None]))


def test_developable_loft_on_the_workplane() -> None:
    ea = cq.Workplane("XY").ghtCurve(CHINE).val()
    eb = cq.Workplane("XY").ghtCurve(SHEER).val()
    shell = cq.Workplane("XY").add(ea).add(eb).developableLoft().val()
    assert isinstance(shell, cq.Shell) and shell.isValid() and len(shell.Faces()) == 3
    assert shell.ght_loft.area() == pytest.approx(shell.Area(), rel=1e-6)  # B-rep fit within 1e-7 of the size
    # the exact cone between two circles: lateral area π (r1 + r2) s
    face = developable_loft_cq(cq.Edge.makeCircle(5.0), cq.Edge.makeCircle(2.0, cq.Vector(0, 0, 6)))
    assert isinstance(face, cq.Face) and face.isValid()
    assert face.Area() == pytest.approx(math.pi * 7.0 * math.hypot(3.0, 6.0), rel=1e-6)
    with pytest.raises(GHTError, match="exactly two edges"):
        cq.Workplane().add(ea).developableLoft()
    with pytest.raises(NotDevelopableError):
        developable_loft_cq(cq.Edge.makeLine(cq.Vector(0, 0, 0), cq.Vector(10, 0, 0)),
                            cq.Edge.makeLine(cq.Vector(0, 5, 3), cq.Vector(0, 8, 10)))


@pytest.mark.slow
def test_the_plugin_needs_no_build123d(tmp_path: Path) -> None:
    """With build123d made unimportable (the [cadquery] extra installs none), the plugin's curves,
    loft and STEP export work and build123d is never imported."""
    code = f"""
import json, math, sys
import cadquery as cq
import ght_cad.cad.cq_plugin
from ght_cad import GHTCurve
from ght_cad.cad.occ import write_step, read_step_products
solid = cq.Workplane("XY").moveTo(0, 0).ghtBezier({PTS!r}, mu=0.3, includeCurrent=True).close().extrude(2.0, clean=False).val()
face = cq.Workplane().developableLoft(cq.Edge.makeCircle(5.0), cq.Edge.makeCircle(2.0, cq.Vector(0, 0, 6))).val()
write_step([solid, face], {str(tmp_path / 'both.step')!r})
print(json.dumps({{"volume": solid.Volume(), "area": face.Area(), "valid": solid.isValid() and face.isValid(),
                  "products": read_step_products({str(tmp_path / 'both.step')!r}),
                  "build123d": "build123d" in sys.modules}}))
"""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(BLOCKER), str(ROOT)]), GHT_BLOCK_MODULES="build123d")
    res = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert out["valid"] and not out["build123d"] and set(out["products"]) == {"both"}
    exact = 2.0 * _green_area([GHTCurve([(0, 0)] + PTS, 0.3), GHTCurve([(3, 0), (1.5, 0), (0, 0)])])
    assert out["volume"] == pytest.approx(exact, rel=1e-6)
    assert out["area"] == pytest.approx(math.pi * 7.0 * math.hypot(3.0, 6.0), rel=1e-6)
