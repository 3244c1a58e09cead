r"""The approximation's result: panels (:class:`Panel`, :class:`ConeStrip` where a seam is one point)
and :class:`ApproximationResult` (report, shell, unrolling). Moved from
``ght_cad/approximation.py`` (issue 27); every name is importable from :mod:`ght_cad.approximation`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from ..core.io import strict_json as _strict
from ..surfaces.ruled import RuledSurface


# ----------------------------------------------------------------------------------------------
# panels
# ----------------------------------------------------------------------------------------------
class ConeStrip(RuledSurface):
    r"""The cone between a curve ``a(u)`` and an apex ``b(u) = P`` (a strip with a one-point seam):
    developable (every ruling passes through P)."""

    def __init__(self, curve: Callable[[np.ndarray, int], np.ndarray], apex: np.ndarray) -> None:
        self._c = curve
        self._p = np.asarray(apex, dtype=float).reshape(3)

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
        return self._c(uu, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
        return np.tile(self._p, (uu.size, 1)) if derivative == 0 else np.zeros((uu.size, 3))

    def area(self) -> float:
        """3-D area (:func:`ght_cad.unroll.ruled_area`)."""
        from ..unrolling.unroll import ruled_area

        return float(ruled_area(self, rtol=1e-13))

    def parameters(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        uu = np.atleast_1d(np.asarray(u, dtype=float)).ravel()
        return uu, uu


@dataclass
class Panel:
    """One developable panel of an approximation.

    Attributes:
        surface: the panel as exported: :class:`BSplineRuled` (B-spline face data of degree 1 across,
            fitted to 1e-7 of the size to ``exact``).
        y0, y1: the seams' positions across the strips (0..1 over the target's parameter range;
            :func:`ght_cad.approximation.strip_uv` gives their (u, v)).
        max_out, max_in: largest deviation of the panel outside / inside the target (along the
            target's normal, both ways: panel -> target and target -> panel), lengths >= 0.
        max_deviation: ``max(max_out, max_in)``.
        theta_max_deg: the developability measure θ_max of the panel (degrees).
        area: 3-D area.
        exact: the exact developable (a :class:`ght_cad.developables.loft.DevelopableLoft` or :class:`ConeStrip`).
        method: ``"loft"`` (seams centred by the offsets of step 2) or ``"dual"`` (seams = the
            trimmed boundary of the strip's dual fit, :mod:`ght_cad.approximation.dual`).
        choice: how the method was chosen: the sampled deviations of both candidates
            (``deviation_loft``, ``deviation_dual``), the dual fit's μ, ν, γ and its deviation at
            ``μ = ν = γ = 0`` and after optimization (``dual_start``, ``dual_optimized``).
    """

    surface: Any
    y0: float
    y1: float
    max_out: float = math.nan
    max_in: float = math.nan
    max_deviation: float = math.nan
    theta_max_deg: float = math.nan
    area: float = math.nan
    exact: Any = None
    method: str = "loft"
    choice: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {k: float(getattr(self, k)) for k in ("y0", "y1", "max_out", "max_in", "max_deviation", "theta_max_deg", "area")}
        d["method"] = self.method
        d.update(self.choice)
        return d


@dataclass
class ApproximationResult:
    """What :func:`approximate` returns.

    Attributes:
        panels: the panels in seam order.
        tol: the tolerance asked for.
        direction: the strip direction: the parameter the rulings run along (``"u"``, ``"v"``) or
            ``"diagonal"``/``"antidiagonal"`` (seams along the isolines of ``u_n ± v_n``; ``y0``,
            ``y1`` of the panels and ``seams[i]["y"]`` are then ``(u_n ± v_n) / 2``, shifted to [0, 1]
            for ``-``: :func:`ght_cad.approximation.strip_uv` maps them to (u, v)).
        size: bounding-box diagonal of the target.
        max_deviation: largest panel deviation (both ways).
        deviation_map: ``{"xyz": (n, 3), "uv": (n, 2), "d": (n,)}`` target samples with the signed
            distance of the panels from them (panel minus target along the target normal).
        seams: the seams' positions across (0..1) and offsets (``delta`` Chebyshev coefficients).
        info: estimates, march history, time.
    """

    panels: list[Panel]
    tol: float
    direction: str
    size: float
    max_deviation: float
    deviation_map: dict[str, np.ndarray]
    seams: list[dict[str, Any]]
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def surfaces(self) -> list[Any]:
        """The panels' developable surfaces."""
        return [p.surface for p in self.panels]

    def as_dict(self) -> dict[str, Any]:
        """Plain report, strict JSON (``json.dumps(..., allow_nan=False)``): a number that is not
        finite (an infinite direction estimate, a dual fit that failed) is written as None (null)."""
        return _strict({
            "panels": len(self.panels),
            "tol": self.tol,
            "direction": self.direction,
            "size": self.size,
            "max_deviation": self.max_deviation,
            "total_area": float(sum(p.area for p in self.panels)),
            "panel_report": [dict(p.as_dict(), index=i + 1) for i, p in enumerate(self.panels)],
            "seams": self.seams,
            "info": self.info,
        })

    def flat_pattern(self, **kwargs: Any) -> Any:
        """All panels unrolled on one sheet with seam marks (:func:`ght_cad.unroll.unroll_composite`
        of the exact developables, whose fans and apexes it handles; labels P1..PN in seam order)."""
        from ..unrolling.unroll import unroll_composite

        return unroll_composite([p.exact if p.exact is not None else p.surface for p in self.panels], **kwargs)
