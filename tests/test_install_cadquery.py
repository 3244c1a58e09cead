"""The [cadquery] world: cadquery 2.8 on OCP 7.9 without build123d (``.venv-cadquery``).

In its own file (not in tests/test_install.py beside the other build123d world) so that
``pytest -n auto --dist loadfile`` builds and tests the two worlds on two workers at once: each
is two minutes of pip installs and a sub-suite in its venv.
"""

from __future__ import annotations

import pytest

from test_install import CADQUERY_TESTS, TEST_TOOLS, _pytest_in, _venv, _versions


@pytest.mark.slow
@pytest.mark.timeout(3600)
def test_cadquery_extra_works_on_ocp_7_9_without_build123d() -> None:
    """``.venv-cadquery``: ``pip install -e '.[cadquery]'`` gives cadquery 2.8 on OCP 7.9 (cadquery-ocp
    alone: no build123d, no second OCP distribution); the plugin's tests, tests/test_cq_world.py, the
    cadquery example and the cadquery halves of other modules pass there, none of them skipped."""
    python = _venv(".venv-cadquery", "cadquery", more=TEST_TOOLS)
    there = _versions(python)
    assert there["cadquery"].startswith("2.8") and there["cadquery-ocp"].startswith("7.9"), there
    assert "build123d" not in there and "cadquery-ocp-novtk" not in there, there
    tail = _pytest_in(python, CADQUERY_TESTS, marks="")
    assert " passed" in tail
    # none of the cadquery tests may skip there (they all skip in the main world): only what needs
    # build123d may, and the host suite when GHT_CAD_HOST_SUITES=off asks
    skipped = [line for line in tail.splitlines() if line.startswith("SKIPPED")]
    allowed = ("could not import 'build123d'", "GHT_CAD_HOST_SUITES=off")
    assert all(any(a in line for a in allowed) for line in skipped), skipped
