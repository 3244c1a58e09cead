"""Moved to :mod:`ght_cad.app.batch` (issue 27); this path stays importable."""
import sys

from .app import batch as _module

sys.modules[__name__] = _module
