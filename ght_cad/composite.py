"""Moved to :mod:`ght_cad.curves.composite` (issue 27); this path stays importable."""
import sys

from .curves import composite as _module

sys.modules[__name__] = _module
