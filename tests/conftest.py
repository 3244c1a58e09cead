"""Shared pytest configuration."""

from __future__ import annotations

import os
import shutil

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

settings.register_profile(
    "ght", max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True
)
settings.load_profile("ght")


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def freecadcmd_or_skip() -> str:
    """Path of Debian's freecadcmd; in CI (CI=true) a missing FreeCAD is a failure, not a skip."""
    exe = shutil.which("freecadcmd")
    if exe is None:
        if os.environ.get("CI") == "true":
            pytest.fail("freecadcmd is not installed but CI=true: .ci/run must install freecad-python3")
        pytest.skip("freecadcmd (Debian's FreeCAD) is not installed")
    return exe


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """A FreeCAD test (a separate ``freecadcmd`` process, seconds to start) is also ``slow``, so the
    fast loop ``pytest -m "not slow"`` leaves it out without a second marker in every module."""
    for item in items:
        if item.get_closest_marker("freecad") is not None and item.get_closest_marker("slow") is None:
            item.add_marker(pytest.mark.slow)
