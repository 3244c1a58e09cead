r"""Targets of the approximation: :class:`SurfaceTarget` (positions and derivatives of ``S(u, v)``)
and :func:`as_target` (GHT patches, ruled surfaces, NURBS, CAD faces). Moved from
``ght_cad/approximation.py`` (issue 27); every name is importable from :mod:`ght_cad.approximation`.
"""

from __future__ import annotations

import math
from typing import Any, Callable, Sequence

import numpy as np

from ..core.errors import GHTError
from ..surfaces.ruled import RuledSurface


_JET = Callable[[np.ndarray, np.ndarray, int], list]


# ----------------------------------------------------------------------------------------------
# targets
# ----------------------------------------------------------------------------------------------
class SurfaceTarget:
    r"""A target surface as the approximation sees it: ``jet(u, v, order)`` and its parameter box.

    ``jet(u, v, order)`` returns ``[S, S_u, S_v]`` (order 1) or ``[S, S_u, S_v, S_uu, S_vv, S_uv]``
    (order 2) at 1-D arrays of parameters, each (n, 3) — the :class:`ght_cad.face_unroll.SurfaceAdapter`
    convention.

    Args:
        jet: the evaluator.
        bounds: ``(u0, u1, v0, v1)``.
        name: label for messages and reports.
    """

    def __init__(self, jet: _JET, bounds: Sequence[float], name: str = "target") -> None:
        b = tuple(float(x) for x in bounds)
        if len(b) != 4 or not all(math.isfinite(x) for x in b) or not (b[1] > b[0] and b[3] > b[2]):
            raise GHTError(f"target bounds {bounds!r} are not allowed; give (u0, u1, v0, v1) with u1 > u0, v1 > v0")
        self._jet = jet
        self.bounds = b
        self.name = name

    def jet(self, u: np.ndarray, v: np.ndarray, order: int = 2) -> list[np.ndarray]:
        """``[S, S_u, S_v(, S_uu, S_vv, S_uv)]`` at the points, each (n, 3)."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        out = self._jet(u, v, order)
        return [np.asarray(x, dtype=float).reshape(-1, 3) for x in out[: 3 if order <= 1 else 6]]

    def __repr__(self) -> str:
        return f"SurfaceTarget({self.name!r}, bounds={self.bounds})"


def _ght_jet(surf: Any) -> _JET:
    def jet(u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        d = [(0, 0), (1, 0), (0, 1)] + ([(2, 0), (0, 2), (1, 1)] if order >= 2 else [])
        return [np.asarray(surf.derivative(u, v, du, dv), dtype=float)[:, :3] for du, dv in d]
    return jet


def _ruled_jet(surf: RuledSurface) -> _JET:
    r"""``S(u, v) = a(u) + v (b(u) - a(u))``: ``S_u = a' + v g'``, ``S_v = g``, ``S_uu = a'' + v g''``,
    ``S_vv = 0``, ``S_uv = g'``."""
    def jet(u: np.ndarray, v: np.ndarray, order: int) -> list[np.ndarray]:
        vv = v[:, None]
        a = [np.asarray(surf.a(u, k), dtype=float).reshape(-1, 3) for k in range(3 if order >= 2 else 2)]
        b = [np.asarray(surf.b(u, k), dtype=float).reshape(-1, 3) for k in range(3 if order >= 2 else 2)]
        g = [bk - ak for ak, bk in zip(a, b)]
        out = [a[0] + vv * g[0], a[1] + vv * g[1], g[0]]
        if order >= 2:
            out += [a[2] + vv * g[2], np.zeros_like(g[0]), g[1]]
        return out
    return jet


def as_target(target: Any) -> SurfaceTarget:
    """A :class:`SurfaceTarget` from a GHTSurface, a NurbsSurface, a RuledSurface (e.g. a
    :class:`ght_cad.loft.DevelopableLoft`), an object with ``jet(u, v, order)`` and ``bounds``, or a
    build123d/cadquery/OCP face (through :func:`ght_cad.cad.approximate.face_target`).

    Raises:
        GHTError: anything else.
    """
    from ..surfaces.nurbs import NurbsSurface
    from ..surfaces.patch import GHTSurface

    if isinstance(target, SurfaceTarget):
        return target
    if isinstance(target, NurbsSurface):
        return SurfaceTarget(lambda u, v, k: target.eval(u, v, min(k, 2)), target.bounds, "NurbsSurface")
    if isinstance(target, GHTSurface):
        if target.dim < 3:
            raise GHTError(f"the GHTSurface target has dimension {target.dim}; a 3-D surface is needed")
        return SurfaceTarget(_ght_jet(target), (0.0, 1.0, 0.0, 1.0), "GHTSurface")
    if isinstance(target, RuledSurface):
        return SurfaceTarget(_ruled_jet(target), (0.0, 1.0, 0.0, 1.0), type(target).__name__)
    if hasattr(target, "jet") and hasattr(target, "bounds"):
        b = target.bounds() if callable(target.bounds) else target.bounds
        return SurfaceTarget(lambda u, v, k: target.jet(u, v, k), b, type(target).__name__)
    if hasattr(target, "wrapped") or type(target).__module__.startswith("OCP"):
        from ..core._kernel import adapter  # the kernel adapter, through the core's dispatch

        return adapter("face_target")(target)
    raise GHTError(
        f"target of type {type(target).__name__} is not allowed; give a GHTSurface, NurbsSurface, RuledSurface, "
        "a SurfaceTarget (jet + bounds) or a build123d/cadquery/OCP face"
    )
