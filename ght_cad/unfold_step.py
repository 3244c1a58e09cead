"""Moved to :mod:`ght_cad.app.unfold_step` (issue 27); this path stays importable."""
import sys

from .app import unfold_step as _module

sys.modules[__name__] = _module
