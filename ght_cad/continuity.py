"""Moved to :mod:`ght_cad.curves.continuity` (issue 27); this path stays importable."""
import sys

from .curves import continuity as _module

sys.modules[__name__] = _module
