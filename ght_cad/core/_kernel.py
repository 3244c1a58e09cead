"""Kernel dispatch: how the kernel-free core reaches a CAD kernel without importing one (issue 27).

The core (curves, surfaces, the loft, unrolling, approximation, the optimize pipeline) never
imports :mod:`ght_cad.cad`. Where it needs a kernel — a B-rep face of a patch or a developable,
a build123d/OCP face as the thing to unroll or approximate, the planar faces of a flat pattern,
STEP output — it asks this registry for the operation by name::

    from ._kernel import adapter
    return adapter("developable_face")(self, tol=tol, **kwargs)

:mod:`ght_cad.cad` registers its adapters (:func:`register_adapter`) when it is imported, and
:func:`load_kernel` — the only place where the core imports the kernel layer — imports it the first
time an operation is asked for. Importing :mod:`ght_cad.cad` imports no kernel (its adapters
import OCP/build123d when first called), so asking for an adapter is cheap; calling it without
build123d/OCP installed raises their ``ModuleNotFoundError`` as before. Another kernel (or a test)
can register its own function for an operation; the last registration wins.
"""

from __future__ import annotations

from typing import Any, Callable

from .errors import GHTError

__all__ = ["OPERATIONS", "INSTALL_HINT", "register_adapter", "adapter", "registered", "load_kernel"]

#: The operations the core dispatches, with what they take and give (and the adapter that
#: :mod:`ght_cad.cad` registers for each).
OPERATIONS: dict[str, str] = {
    "make_face": "BSplineSurfaceData -> build123d Face (ght_cad.cad.occ.make_face)",
    "make_edge": "BSplineCurveData -> build123d Edge (ght_cad.cad.occ.make_edge)",
    "write_step": "shape(s), path -> STEP file (ght_cad.cad.occ.write_step)",
    "developable_face": "RuledSurface -> one B-spline Face (ght_cad.cad.developable_faces.developable_face)",
    "composite_shell": "segments of a composite developable -> sewn Shell "
                       "(ght_cad.cad.developable_faces.composite_shell)",
    "face_target": "build123d/cadquery/OCP face -> SurfaceTarget (ght_cad.cad.approximate.face_target)",
    "shape_faces": "shape -> its faces (ght_cad.cad.unroll_faces.shape_faces)",
    "unroll_face": "one CAD face -> FlatPattern (ght_cad.cad.unroll_faces.unroll_face)",
    "flat_faces": "FlatPattern -> planar Faces (ght_cad.cad.unroll_faces.flat_faces)",
}

#: The extra that brings the kernel the registered adapters use (pyproject.toml).
INSTALL_HINT = "pip install 'ght_cad[build123d]'"

_ADAPTERS: dict[str, Callable[..., Any]] = {}


def _check_operation(operation: Any) -> str:
    if not isinstance(operation, str) or operation not in OPERATIONS:
        raise GHTError(f"kernel operation {operation!r} is not allowed; known operations: {sorted(OPERATIONS)}")
    return operation


def register_adapter(operation: str, function: Callable[..., Any]) -> None:
    """Make ``function`` the kernel's implementation of ``operation`` (one of :data:`OPERATIONS`).

    Raises:
        GHTError: an unknown operation, or ``function`` not callable.
    """
    _check_operation(operation)
    if not callable(function):
        raise GHTError(f"the adapter for {operation!r} must be callable, got {type(function).__name__}")
    _ADAPTERS[operation] = function


def registered() -> dict[str, Callable[..., Any]]:
    """A copy of the registry: operation -> function (empty until a kernel layer registered)."""
    return dict(_ADAPTERS)


def load_kernel() -> None:
    """Import :mod:`ght_cad.cad`, which registers its adapters: the core's one import of the kernel
    layer (allowed, as the only such entry, by tests/test_import_layers.py)."""
    from .. import cad  # noqa: F401  (imports no kernel itself; it registers its adapters on import)


def adapter(operation: str) -> Callable[..., Any]:
    """The registered function for ``operation``, loading the kernel layer on first need.

    Raises:
        GHTError: an unknown operation, or none registered even after :func:`load_kernel`
            (the message names the extra to install).
    """
    _check_operation(operation)
    if operation not in _ADAPTERS:
        load_kernel()
    try:
        return _ADAPTERS[operation]
    except KeyError:
        raise GHTError(
            f"no CAD kernel adapter is registered for {operation!r} ({OPERATIONS[operation]}); "
            f"this needs build123d and OCP: {INSTALL_HINT}"
        ) from None
