"""Thin adapters from ght_cad's plain data to CAD kernels (build123d/OCP and cadquery).

Importing :mod:`ght_cad` never imports this package; importing this package itself imports no
kernel (its modules import OCP). :func:`kernel_available` tells whether one can be imported.
Importing it registers its adapters (:data:`ADAPTERS`, loaded on first call) with the core's
kernel dispatch :mod:`ght_cad.core._kernel`, which is how the kernel-free core reaches them.
"""

from __future__ import annotations

import importlib
from typing import Any, Callable

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


# -- the core's kernel dispatch (ght_cad.core._kernel) ---------------------------------------------------

#: operation of :data:`ght_cad.core._kernel.OPERATIONS` -> (module of this package, function)
ADAPTERS = {
    "make_face": ("occ", "make_face"),
    "make_edge": ("occ", "make_edge"),
    "write_step": ("occ", "write_step"),
    "developable_face": ("developable_faces", "developable_face"),
    "composite_shell": ("developable_faces", "composite_shell"),
    "face_target": ("approximate", "face_target"),
    "shape_faces": ("unroll_faces", "shape_faces"),
    "unroll_face": ("unroll_faces", "unroll_face"),
    "flat_faces": ("unroll_faces", "flat_faces"),
}


def _on_first_call(module: str, name: str) -> Callable[..., Any]:
    """``ght_cad.cad.<module>.<name>``, imported (and with it the kernel) when first called."""

    def call(*args: Any, **kwargs: Any) -> Any:
        return getattr(importlib.import_module(f"{__name__}.{module}"), name)(*args, **kwargs)

    call.__name__ = call.__qualname__ = name
    call.__doc__ = f"Calls :func:`ght_cad.cad.{module}.{name}` (imports it, and the kernel, on first call)."
    return call


def _register_adapters() -> None:
    """Fill the core's kernel registry with this package's adapters (imports no kernel)."""
    from ..core import _kernel

    for operation, (module, name) in ADAPTERS.items():
        _kernel.register_adapter(operation, _on_first_call(module, name))


_register_adapters()
