"""Moved to :mod:`ght_cad.core.io` (issue 27); this path stays importable."""
import sys

from .core import io as _module

sys.modules[__name__] = _module
