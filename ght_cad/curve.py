"""Moved to :mod:`ght_cad.curves.curve` (issue 27); this path stays importable."""
import sys

from .curves import curve as _module

sys.modules[__name__] = _module
