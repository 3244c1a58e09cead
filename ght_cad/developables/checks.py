"""Argument and regularity checks of the tangent and rectifying developables.

Moved from :mod:`ght_cad.developables.envelope` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..curves.curve import GHTCurve
from ..core.errors import EdgeOfRegressionError, GHTError
from ..surfaces.ruled import regression_v, RuledSurface
from .jets import _fmt


# ----------------------------------------------------------------------------------------------
# generic check of a ruled strip against its striction/regression points
# ----------------------------------------------------------------------------------------------
def _check_strip_regular(surf: RuledSurface, samples: int = 513, what: str = "strip") -> None:
    r"""Raise EdgeOfRegressionError when the singular point of a developable strip is inside it.

    On a developable the tangent plane is singular where ``X_u = a' + v g'`` is parallel to ``g``:
    ``v* = -((a' × g)·(g' × g)) / |g' × g|²``. Where ``|g' × g|`` vanishes (cylinder-like) there is
    no singular point.
    """
    u = np.linspace(0.0, 1.0, samples)
    a1 = surf.a(u, 1)
    g = surf.ruling(u)
    g1 = surf.ruling(u, 1)
    vs = regression_v(a1, g, g1)
    inside = np.isfinite(vs) & (vs >= 0.0) & (vs <= 1.0)
    if inside.any():
        i = int(np.argmax(inside))
        raise EdgeOfRegressionError(
            f"the {what} contains its edge of regression at u={u[i]:.6g}, v={vs[i]:.6g} "
            f"(point {_fmt(surf.evaluate(u[i], vs[i]))}); the surface is singular there"
        )


def _check_3d_curve(curve: Any, name: str) -> GHTCurve:
    if not isinstance(curve, GHTCurve):
        raise GHTError(f"{name} must be a GHTCurve, got {type(curve).__name__}")
    if curve.dim != 3:
        raise GHTError(f"{name} has dimension {curve.dim}; a space curve of dimension 3 is required")
    return curve


def _check_v_range(v0: Any, v1: Any) -> tuple[float, float]:
    try:
        a, b = float(v0), float(v1)
    except (TypeError, ValueError):
        raise GHTError(f"v0={v0!r}, v1={v1!r} must be real numbers") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise GHTError(f"v0={a}, v1={b} must be finite")
    if not a < b:
        raise GHTError(f"v0={a:g} must be smaller than v1={b:g}")
    return a, b
