"""Moved to :mod:`ght_cad.curves.basis` (issue 27); this path stays importable."""
import sys

from .curves import basis as _module

sys.modules[__name__] = _module
