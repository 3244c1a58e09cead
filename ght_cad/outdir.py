"""Moved to :mod:`ght_cad.core.outdir` (issue 27); this path stays importable."""
import sys

from .core import outdir as _module

sys.modules[__name__] = _module
