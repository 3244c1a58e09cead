"""Moved to :mod:`ght_cad.core._validate` (issue 27); this path stays importable."""
import sys

from .core import _validate as _module

sys.modules[__name__] = _module
