"""Moved to :mod:`ght_cad.curves.seeds` (issue 27); this path stays importable."""
import sys

from .curves import seeds as _module

sys.modules[__name__] = _module
