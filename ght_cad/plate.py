"""Moved to :mod:`ght_cad.sheetmetal.plate` (issue 27); this path stays importable."""
import sys

from .sheetmetal import plate as _module

sys.modules[__name__] = _module
