"""Moved to :mod:`ght_cad.surfaces.ruled` (issue 27); this path stays importable."""
import sys

from .surfaces import ruled as _module

sys.modules[__name__] = _module
