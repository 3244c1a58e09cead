"""Moved to :mod:`ght_cad.unrolling.face_unroll` (issue 27); this path stays importable."""
import sys

from .unrolling import face_unroll as _module

sys.modules[__name__] = _module
