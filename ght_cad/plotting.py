"""Moved to :mod:`ght_cad.curves.plotting` (issue 27); this path stays importable."""
import sys

from .curves import plotting as _module

sys.modules[__name__] = _module
