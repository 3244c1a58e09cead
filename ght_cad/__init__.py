"""ght_cad: GHT-Bézier curves and developable surfaces for CAD.

The core (this package) depends on numpy and scipy only; CAD kernels (build123d/OCP, cadquery,
FreeCAD) are reached through thin adapters in :mod:`ght_cad.cad` and ``freecad_workbench``, which
are never imported here.

Stable names (spec section 9): :func:`basis`, :class:`GHTCurve`, :func:`developable_from_planes`,
:func:`unroll`.
"""

from __future__ import annotations

import importlib
from typing import Any

from .core import _aliases

#: Modules moved into the layer packages (issue 27): old name (relative to ``ght_cad``) -> new module
#: path. The old path stays importable as the same module object, through the import hook of
#: :mod:`ght_cad.core._aliases` (an old package name maps its submodules too:
#: ``ght_cad.<old>.<sub>`` is ``<new>.<sub>``); as an attribute of this package it is imported on
#: first use, like the names of :data:`_LAZY`. Code in the repository imports the new paths
#: (``tests/test_layer_packages.py`` fails on an old one).
_MOVED: dict[str, str] = {
    **{n: f"ght_cad.core.{n}" for n in ("errors", "_validate", "_vec", "_quadrature", "_cache", "_lazy", "io",
                                        "progress", "step_guard", "_kernel", "outdir")},
    **{n: f"ght_cad.curves.{n}" for n in ("seeds", "basis", "curve", "continuity", "composite", "analysis", "plotting")},
    **{n: f"ght_cad.surfaces.{n}" for n in ("planes", "bspline", "nurbs", "patch", "ruled")},
    **{n: f"ght_cad.unrolling.{n}" for n in ("unroll", "ruled_development", "face_unroll", "faces")},
    **{n: f"ght_cad.sheetmetal.{n}" for n in ("sheet", "plate", "join_panels", "blank")},
    **{n: f"ght_cad.pattern.{n}" for n in ("flat_pattern", "outline_arcs")},
    **{n: f"ght_cad.app.{n}" for n in ("cli", "batch", "sweep", "demo", "unfold_step", "approximate_cli", "design",
                                       "commands")},
    "developable": "ght_cad.developables.envelope",
    "loft": "ght_cad.developables.loft",  # a package: ght_cad.loft.rails is ght_cad.developables.loft.rails
    "approximation_dual": "ght_cad.approximation.dual",
}

_aliases.install(__name__, _MOVED)
# ``ght_cad.basis`` is the function basis (spec section 9) and also the old path of the module
# ght_cad.curves.basis: that old path is put into sys.modules now, so that a later
# ``import ght_cad.basis`` finds it there and does not replace the function by the module.
_aliases.alias_now(__name__, _MOVED, "basis")

from .core._lazy import lazy_getattr
from .curves.basis import basis, bernstein
from .curves.curve import GHTCurve
from .core.errors import (
    ConversionError,
    DegenerateGeometryError,
    EdgeOfRegressionError,
    GHTError,
    NotDevelopableError,
    ShapeParameterError,
    SingularJoinError,
)
from .curves.seeds import BernsteinSeed, GBTSeed, GHTSeed, Seed, make_seed, register_seed, seed_names

# ``ght_cad.unroll`` is the module ght_cad.unrolling.unroll, made callable (its ``__call__`` is the
# stable function ``unroll`` of spec section 9), so the package attribute is the same object whichever
# way and in whichever order it is imported (numpy-only, ~30 ms).
from .unrolling import unroll

__version__ = "0.1.0"

__all__ = [
    "basis",
    "bernstein",
    "GHTCurve",
    "Seed",
    "GHTSeed",
    "GBTSeed",
    "BernsteinSeed",
    "make_seed",
    "register_seed",
    "seed_names",
    "GHTError",
    "ShapeParameterError",
    "DegenerateGeometryError",
    "EdgeOfRegressionError",
    "NotDevelopableError",
    "SingularJoinError",
    "ConversionError",
    "developable_from_planes",
    "unroll",
    "join",
    "measure_continuity",
    "Continuity",
    "CompositeCurve",
    "curve_to_bspline",
    "fit_function",
    "GHTSurface",
    "developable_loft",
    "unfold",
]

# Names provided by modules that import scipy or are heavier: loaded on first use so that
# ``import ght_cad`` stays fast (< 0.3 s) and never touches a CAD kernel.
_LAZY: dict[str, str] = {
    "developable_from_planes": "ght_cad.developables.envelope",
    "join": "ght_cad.curves.continuity",
    "measure_continuity": "ght_cad.curves.continuity",
    "Continuity": "ght_cad.curves.continuity",
    "CompositeCurve": "ght_cad.curves.composite",
    "curve_to_bspline": "ght_cad.surfaces.bspline",
    "fit_function": "ght_cad.surfaces.bspline",
    "GHTSurface": "ght_cad.surfaces.patch",
    "developable_loft": "ght_cad.developables.loft",
    "unfold": "ght_cad.cad.unfold_solid",
    "approximate": "ght_cad.approximation",
}

_lazy_name = lazy_getattr(__name__, _LAZY, globals())


def __getattr__(name: str) -> Any:
    """A name of :data:`_LAZY` or an old module path of :data:`_MOVED`, imported on first use."""
    if name in _MOVED:
        return importlib.import_module(f"{__name__}.{name}")  # through the alias hook, which sets the attribute
    return _lazy_name(name)
