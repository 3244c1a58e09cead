"""pytest plugin for host test suites (tests/test_host_suites.py): ght_cad's build123d and cadquery
adapters imported before any test runs (``-p ght_plugin_imported``); each adapter where its host
is installed (the [build123d] and [cadquery] extras are separate environments)."""

import importlib.util

if importlib.util.find_spec("cadquery") is not None:
    import ght_cad.cad.cq_plugin  # noqa: F401  (registers the Workplane methods)
if importlib.util.find_spec("build123d") is not None:
    import ght_cad.cad.curves  # noqa: F401
    import ght_cad.cad.loft  # noqa: F401
