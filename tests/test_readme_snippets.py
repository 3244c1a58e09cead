"""Every python block of the README runs on its own (a fresh interpreter per block, in an empty
folder): no block may lean on names from an earlier one. Blocks that need FreeCAD are skipped."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCKS = re.findall(r"^```python\n(.*?)^```", (ROOT / "README.md").read_text(), flags=re.S | re.M)


def test_the_readme_has_python_blocks():
    assert len(BLOCKS) >= 4


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs_standalone(index, tmp_path):
    code = BLOCKS[index]
    if re.search(r"^\s*(import FreeCAD|from FreeCAD|import Part\b|import FreeCADGui)", code, flags=re.M):
        pytest.skip("needs FreeCAD")
    for module in re.findall(r"^\s*(?:import|from) (build123d|cadquery)\b", code, flags=re.M):
        pytest.importorskip(module)
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, f"README python block {index} failed:\n{code}\n{run.stderr[-3000:]}"
