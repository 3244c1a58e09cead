"""The core imports fast, without any CAD kernel or plotting stack, and runs on Debian's numpy."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_core_import_does_not_load_cad_or_plotting() -> None:
    code = (
        "import sys, json, ght_cad, ght_cad.curves.basis, ght_cad.curves.curve, ght_cad.surfaces.ruled, ght_cad.surfaces.bspline; "
        "print(json.dumps(sorted({m.split('.')[0] for m in sys.modules})))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    loaded = set(json.loads(out.stdout))
    assert not loaded & {"build123d", "cadquery", "OCP", "matplotlib", "ezdxf", "FreeCAD"}


def test_core_runs_on_debian_python_numpy() -> None:
    """FreeCAD's Debian Python (numpy 1.24, scipy 1.10) computes the same numbers."""
    py = shutil.which("python3", path="/usr/bin")
    if py is None:
        pytest.skip("no Debian /usr/bin/python3")
    probe = subprocess.run([py, "-c", "import numpy, scipy"], capture_output=True)
    if probe.returncode != 0:
        pytest.skip("Debian python3 has no numpy/scipy (python3-numpy not installed)")
    code = (
        "import json, numpy as np, ght_cad; "
        "c = ght_cad.GHTCurve([[0,0,0],[1,2,0],[3,1,1],[4,3,2],[5,0,1]], 0.3, -0.6, 0.2); "
        "t = np.linspace(0, 1, 7); "
        "print(json.dumps([c.evaluate(t).tolist(), c.derivative(t, 3).tolist(), c.arc_length(), np.__version__]))"
    )
    out = subprocess.run([py, "-c", code], capture_output=True, text=True, cwd=ROOT, env={"PYTHONPATH": str(ROOT)})
    assert out.returncode == 0, out.stderr
    pts, d3, length, npver = json.loads(out.stdout)
    from ght_cad import GHTCurve

    c = GHTCurve([[0, 0, 0], [1, 2, 0], [3, 1, 1], [4, 3, 2], [5, 0, 1]], 0.3, -0.6, 0.2)
    t = np.linspace(0, 1, 7)
    np.testing.assert_allclose(pts, c.evaluate(t), rtol=0, atol=1e-13)
    np.testing.assert_allclose(d3, c.derivative(t, 3), rtol=1e-12, atol=1e-11)
    assert length == pytest.approx(c.arc_length(), rel=1e-13)
