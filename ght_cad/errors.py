"""Moved to :mod:`ght_cad.core.errors` (issue 27); this path stays importable."""
import sys

from .core import errors as _module

sys.modules[__name__] = _module
