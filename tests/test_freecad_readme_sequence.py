"""The FreeCAD workbench README's scripting sequence runs as written in freecadcmd (no recompute
between the make_* calls and the exports)."""

from __future__ import annotations

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def test_readme_scripting_sequence_in_freecadcmd(tmp_path):
    run_fc_unittest("freecad.ght_workbench.tests.fc_readme_sequence", tmp_path, min_tests=1, timeout=300)
    assert (tmp_path / "readme.dxf").stat().st_size > 1000
