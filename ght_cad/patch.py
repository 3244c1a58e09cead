"""Moved to :mod:`ght_cad.surfaces.patch` (issue 27); this path stays importable."""
import sys

from .surfaces import patch as _module

sys.modules[__name__] = _module
