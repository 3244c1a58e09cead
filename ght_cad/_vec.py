"""Moved to :mod:`ght_cad.core._vec` (issue 27); this path stays importable."""
import sys

from .core import _vec as _module

sys.modules[__name__] = _module
