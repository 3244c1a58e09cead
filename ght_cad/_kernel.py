"""Moved to :mod:`ght_cad.core._kernel` (issue 27); this path stays importable."""
import sys

from .core import _kernel as _module

sys.modules[__name__] = _module
