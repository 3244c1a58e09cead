"""Moved to :mod:`ght_cad.unrolling.unroll` (issue 27); this path stays importable."""
import sys

from .unrolling import unroll as _module

sys.modules[__name__] = _module
