"""Moved to :mod:`ght_cad.sheetmetal.join_panels` (issue 27); this path stays importable."""
import sys

from .sheetmetal import join_panels as _module

sys.modules[__name__] = _module
