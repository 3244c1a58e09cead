"""Moved to :mod:`ght_cad.surfaces.bspline` (issue 27); this path stays importable."""
import sys

from .surfaces import bspline as _module

sys.modules[__name__] = _module
