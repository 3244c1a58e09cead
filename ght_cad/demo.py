"""Moved to :mod:`ght_cad.app.demo` (issue 27); this path stays importable."""
import sys

from .app import demo as _module

sys.modules[__name__] = _module
