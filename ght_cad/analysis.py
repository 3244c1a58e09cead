"""Moved to :mod:`ght_cad.curves.analysis` (issue 27); this path stays importable."""
import sys

from .curves import analysis as _module

sys.modules[__name__] = _module
