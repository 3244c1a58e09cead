"""Moved to :mod:`ght_cad.core._lazy` (issue 27); this path stays importable."""
import sys

from .core import _lazy as _module

sys.modules[__name__] = _module
