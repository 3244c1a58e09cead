"""Moved to :mod:`ght_cad.unrolling.ruled_development` (issue 27); this path stays importable."""
import sys

from .unrolling import ruled_development as _module

sys.modules[__name__] = _module
