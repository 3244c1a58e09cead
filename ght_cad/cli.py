"""Moved to :mod:`ght_cad.app.cli` (issue 27); this path stays importable."""
import sys

from .app import cli as _module

if __name__ == "__main__":  # python -m ght_cad.cli
    sys.exit(_module.main())
sys.modules[__name__] = _module
