"""Moved to :mod:`ght_cad.sheetmetal.sheet` (issue 27); this path stays importable."""
import sys

from .sheetmetal import sheet as _module

sys.modules[__name__] = _module
