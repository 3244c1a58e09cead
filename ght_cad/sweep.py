"""Moved to :mod:`ght_cad.app.sweep` (issue 27); this path stays importable."""
import sys

from .app import sweep as _module

sys.modules[__name__] = _module
