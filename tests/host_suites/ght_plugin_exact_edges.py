"""pytest plugin for host test suites (tests/test_host_suites.py): every test runs inside
``ght_cad.cad.curves.exact_edges()`` (``-p ght_plugin_exact_edges``)."""

import importlib.util

import pytest

from ght_cad.cad.curves import exact_edges

if importlib.util.find_spec("cadquery") is not None:  # a [cadquery] + build123d environment
    import ght_cad.cad.cq_plugin  # noqa: F401


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    with exact_edges():
        yield
