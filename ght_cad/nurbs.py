"""Moved to :mod:`ght_cad.surfaces.nurbs` (issue 27); this path stays importable."""
import sys

from .surfaces import nurbs as _module

sys.modules[__name__] = _module
