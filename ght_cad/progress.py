"""Moved to :mod:`ght_cad.core.progress` (issue 27); this path stays importable."""
import sys

from .core import progress as _module

sys.modules[__name__] = _module
