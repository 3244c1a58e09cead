"""Moved to :mod:`ght_cad.pattern.flat_pattern` (issue 27); this path stays importable."""
import sys

from .pattern import flat_pattern as _module

sys.modules[__name__] = _module
