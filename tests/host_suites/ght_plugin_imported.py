"""pytest plugin for host test suites (tests/test_host_suites.py): ght_cad's build123d and cadquery
adapters imported before any test runs (``-p ght_plugin_imported``)."""

import ght_cad.cad.cq_plugin  # noqa: F401  (registers the Workplane methods)
import ght_cad.cad.curves  # noqa: F401
import ght_cad.cad.loft  # noqa: F401
