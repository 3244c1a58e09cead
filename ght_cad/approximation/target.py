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
    (order 2) at 1-D arrays of parameters, each (n, 3) — the :class:`ght_cad.unrolling.face_unroll.SurfaceAdapter`
    convention.

    Args:
        jet: the evaluator.
        bounds: ``(u0, u1, v0, v1)``.
        name: label for messages and reports.
        trim: for a CAD face, how much of its surface's (u, v) box it covers:
            ``{"covered": A_face / A_box, "holes": inner wires}`` (``A_box`` the area of the same
            surface over the face's (u, v) box); None when the target is its whole box
            (:func:`check_trim`).
    """

    def __init__(self, jet: _JET, bounds: Sequence[float], name: str = "target", *,
                 trim: dict[str, float] | None = None) -> None:
        b = tuple(float(x) for x in bounds)
        if len(b) != 4 or not all(math.isfinite(x) for x in b) or not (b[1] > b[0] and b[3] > b[2]):
            raise GHTError(f"target bounds {bounds!r} are not allowed; give (u0, u1, v0, v1) with u1 > u0, v1 > v0")
        self._jet = jet
        self.bounds = b
        self.name = name
        self.trim = dict(trim) if trim is not None else None

    def jet(self, u: np.ndarray, v: np.ndarray, order: int = 2) -> list[np.ndarray]:
        """``[S, S_u, S_v(, S_uu, S_vv, S_uv)]`` at the points, each (n, 3)."""
        u = np.asarray(u, dtype=float).ravel()
        v = np.asarray(v, dtype=float).ravel()
        out = self._jet(u, v, order)
        return [np.asarray(x, dtype=float).reshape(-1, 3) for x in out[: 3 if order <= 1 else 6]]

    def __repr__(self) -> str:
        return f"SurfaceTarget({self.name!r}, bounds={self.bounds})"


#: a face covering less than ``1 - TRIM_TOL`` of its surface's (u, v) box is a trimmed face
TRIM_TOL = 1e-6


class TrimmedTargetError(GHTError):
    """A trimmed face (holes, or a boundary inside its surface's (u, v) box) given to
    :func:`ght_cad.approximate` without ``untrimmed=True``; ``covered`` and ``holes`` as in
    :attr:`SurfaceTarget.trim`, ``name`` the target's."""

    def __init__(self, name: str, covered: float, holes: int) -> None:
        self.name, self.covered, self.holes = name, float(covered), int(holes)
        super().__init__(f"the target {name!r} is {trim_words(covered, holes)}; {TRIM_ALLOWED}, or untrimmed=True to "
                         "cover the underlying surface over its whole (u, v) box knowingly")


#: what :class:`TrimmedTargetError` allows (the front ends name their own switch after it)
TRIM_ALLOWED = ("the panels would cover the whole (u, v) box, where the face has no material; allowed: a face "
                "whose trim is its (u, v) box")


def trim_words(covered: float, holes: int) -> str:
    """``"a trimmed face: it covers 0.8727 of its surface's (u, v) box, 1 hole"``."""
    return (f"a trimmed face: it covers {covered:.4g} of its surface's (u, v) box, {holes} hole"
            f"{'' if holes == 1 else 's'}")


def is_trimmed(trim: dict[str, float] | None) -> bool:
    """True when ``trim`` (:attr:`SurfaceTarget.trim`) has holes or covers less than ``1 - TRIM_TOL``."""
    return trim is not None and (int(trim.get("holes", 0)) > 0 or float(trim["covered"]) < 1.0 - TRIM_TOL)


def check_trim(target: SurfaceTarget, untrimmed: bool = False) -> dict[str, float] | None:
    r"""The target's trim record for the report, refusing a trimmed face.

    A CAD face covers the fraction ``c = A_face / A_box`` of its surface's (u, v) box (``A_box``:
    the surface over the face's (u, v) bounds) and has ``h`` inner wires; it is trimmed when
    ``c < 1 - TRIM_TOL`` or ``h > 0``. :func:`ght_cad.approximate` covers the whole box.

    Returns:
        ``{"covered": c, "holes": h, "untrimmed": untrimmed}`` for a CAD face, None otherwise.

    Raises:
        TrimmedTargetError: a trimmed face and not ``untrimmed`` (the message names c and h).
        GHTError: ``untrimmed`` not a bool.
    """
    if not isinstance(untrimmed, (bool, np.bool_)):
        raise GHTError(f"untrimmed={untrimmed!r} is not allowed; it must be True or False")
    trim = getattr(target, "trim", None)
    if trim is None:
        return None
    if is_trimmed(trim) and not untrimmed:
        raise TrimmedTargetError(target.name, trim["covered"], trim.get("holes", 0))
    return {"covered": float(trim["covered"]), "holes": int(trim.get("holes", 0)), "untrimmed": bool(untrimmed)}


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
    :class:`ght_cad.developables.loft.DevelopableLoft`), an object with ``jet(u, v, order)`` and ``bounds``, or a
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
