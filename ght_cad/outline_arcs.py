"""Moved to :mod:`ght_cad.pattern.outline_arcs` (issue 27); this path stays importable."""
import sys

from .pattern import outline_arcs as _module

sys.modules[__name__] = _module
