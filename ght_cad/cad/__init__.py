"""Thin adapters from ght_cad's plain data to CAD kernels (build123d/OCP and cadquery).

Importing :mod:`ght_cad` never imports this package; importing this package itself imports no
kernel (its modules import OCP). :func:`kernel_available` tells whether one can be imported.
"""

from __future__ import annotations

#: The top-level modules of the CAD kernels the adapters use (a ``ModuleNotFoundError`` of one of
#: these means "no kernel installed", not a bug)
KERNEL_MODULES = ("OCP", "build123d", "cadquery")

#: What to tell a user whose environment lacks the kernel the B-rep needs (pyproject.toml's extras;
#: the CLI's B-rep and STEP go through build123d, the [cadquery] extra brings the Workplane plugin)
KERNEL_HINT = ("needs build123d and its CAD kernel (OCP), which are not installed; install them with "
               "pip install 'ght_cad[build123d]'")


def kernel_available() -> bool:
    """Whether OCP and build123d (the design runs' B-rep) can be found, without importing them."""
    import importlib.util

    try:
        return all(importlib.util.find_spec(m) is not None for m in ("OCP", "build123d"))
    except (ImportError, ValueError):
        return False


def is_missing_kernel(exc: BaseException) -> bool:
    """Whether ``exc`` is the ``ModuleNotFoundError`` of a kernel module (OCP, build123d, cadquery)."""
    name = getattr(exc, "name", None) or ""
    return isinstance(exc, ModuleNotFoundError) and name.split(".")[0] in KERNEL_MODULES
