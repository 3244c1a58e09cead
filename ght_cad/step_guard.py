"""Moved to :mod:`ght_cad.core.step_guard` (issue 27); this path stays importable."""
import sys

from .core import step_guard as _module

sys.modules[__name__] = _module
