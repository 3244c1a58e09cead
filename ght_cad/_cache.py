"""Moved to :mod:`ght_cad.core._cache` (issue 27); this path stays importable."""
import sys

from .core import _cache as _module

sys.modules[__name__] = _module
