"""Moved to :mod:`ght_cad.core._quadrature` (issue 27); this path stays importable."""
import sys

from .core import _quadrature as _module

sys.modules[__name__] = _module
