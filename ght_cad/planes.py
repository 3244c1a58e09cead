"""Moved to :mod:`ght_cad.surfaces.planes` (issue 27); this path stays importable."""
import sys

from .surfaces import planes as _module

sys.modules[__name__] = _module
