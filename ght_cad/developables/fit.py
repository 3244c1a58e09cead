"""A ruled or developable surface as a certified B-spline surface: its smooth pieces and the fit.

Moved from :mod:`ght_cad.developables.envelope` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..surfaces.bspline import BSplineSurfaceData, fit_function
from ..core.errors import ConversionError, GHTError
from ..surfaces.ruled import RuledSurface


# ----------------------------------------------------------------------------------------------
# B-spline data (compatible directrix poles)
# ----------------------------------------------------------------------------------------------
def _size(surface: RuledSurface) -> float:
    """Diagonal of the bounding box of the strip, from the boundary curves at 33 parameters (a
    ruling segment lies in the box of its end points)."""
    fast = getattr(surface, "boundary_values", None)
    u = np.linspace(0.0, 1.0, 33)
    g = fast(u).reshape(-1, 3) if fast is not None else np.vstack([surface.a(u), surface.b(u)])
    return float(np.linalg.norm(g.max(axis=0) - g.min(axis=0)))


def _bspline_theta(curve: Any, samples: int = 513) -> float:
    """θ_max (degrees) of the ruled B-spline ``(A(u), B(u))`` from its own derivatives."""
    from ..surfaces.ruled import _theta

    u = np.linspace(0.0, 1.0, samples)
    F = curve.evaluate(u)
    F1 = curve.evaluate(u, 1)
    th, _ = _theta(F1[:, :3], F1[:, 3:], F[:, 3:] - F[:, :3])
    return float(np.nanmax(th))


@dataclass(frozen=True)
class RuledPiece:
    r"""One smooth piece of a ruled surface between two of its ``breakpoints``.

    Attributes:
        lo, hi: the piece's parameter interval ``[λ_lo, λ_hi]`` on the whole surface.
        surface: the piece as a :class:`~ght_cad.surfaces.ruled.RuledSurface` on ``x ∈ [0, 1]``,
            ``λ = λ_lo + x (λ_hi - λ_lo)`` (derivatives with respect to x).
        end_orders: the highest end derivative order of ``surface`` that is exact (one-sided) at
            ``x = 0`` and at ``x = 1`` (0..2).
    """

    lo: float
    hi: float
    surface: RuledSurface
    end_orders: tuple[int, int]


class _RuledInterval(RuledSurface):
    r"""``surface`` on ``[lo, hi]`` as a ruled surface on ``[0, 1]``:
    ``a_k^(r)(x) = (hi - lo)^r a^(r)(lo + x (hi - lo))`` (likewise b). At an interior breakpoint a
    surface evaluates one of its two sides only, so there only the value is a one-sided limit
    (``end_orders`` 0 at interior ends)."""

    def __init__(self, surface: RuledSurface, lo: float, hi: float) -> None:
        self._s = surface
        self._lo, self._w = float(lo), float(hi) - float(lo)

    def _lam(self, u: Any) -> np.ndarray:
        x = np.atleast_1d(np.asarray(u, dtype=float))
        return np.clip(self._lo + x * self._w, 0.0, 1.0)

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._s.a(self._lam(u), derivative) * self._w**derivative

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._s.b(self._lam(u), derivative) * self._w**derivative

    def __repr__(self) -> str:
        return f"{self._s!r}[{self._lo:.6g}, {self._lo + self._w:.6g}]"


def ruled_pieces(surface: RuledSurface) -> list[RuledPiece]:
    r"""The smooth pieces of a ruled surface between its ``breakpoints`` (where a, b are only C0 or
    C1 in u, e.g. the joint rulings of a :class:`~ght_cad.developables.loft.DevelopableLoft`'s fans).

    The pieces are, in this order of preference: the surface's own ``segments`` when they match
    the breakpoints (a loft: each segment is exact with one-sided jets, ``end_orders`` =
    ``segment.end_order``); for an :class:`~ght_cad.sheetmetal.sheet.OffsetRuledSurface` the offsets of its
    base's pieces (the same δ); otherwise the surface restricted to ``[λ_k, λ_{k+1}]``
    (``end_orders`` 2 at the surface's ends, 0 at interior breakpoints, where only the value is
    one-sided).

    Args:
        surface: any :class:`~ght_cad.surfaces.ruled.RuledSurface` (``breakpoints`` optional).

    Returns:
        One :class:`RuledPiece` per interval; a single piece ``(0, 1, surface, (2, 2))`` without
        breakpoints in (0, 1).
    """
    bp = sorted(float(b) for b in getattr(surface, "breakpoints", ()) if 0.0 < float(b) < 1.0)
    if not bp:
        return [RuledPiece(0.0, 1.0, surface, (2, 2))]
    edges = [0.0] + bp + [1.0]
    segs = list(getattr(surface, "segments", None) or [])
    if len(segs) == len(edges) - 1 and all(isinstance(sg, RuledSurface) for sg in segs):
        ranges = [tuple(getattr(sg, "lam_range", (math.nan, math.nan))) for sg in segs]
        if all(abs(r[0] - lo) <= 1e-12 and abs(r[1] - hi) <= 1e-12 for r, lo, hi in zip(ranges, edges[:-1], edges[1:])):
            out = []
            for sg, lo, hi in zip(segs, edges[:-1], edges[1:]):
                k = int(getattr(sg, "end_order", 2))
                out.append(RuledPiece(lo, hi, sg, (k, k)))
            return out
    from ..sheetmetal.sheet import OffsetRuledSurface

    if isinstance(surface, OffsetRuledSurface):
        base = ruled_pieces(surface.base)
        if [(pc.lo, pc.hi) for pc in base] == list(zip(edges[:-1], edges[1:])):
            return [RuledPiece(pc.lo, pc.hi, OffsetRuledSurface(pc.surface, surface.delta), pc.end_orders) for pc in base]
    return [RuledPiece(lo, hi, _RuledInterval(surface, lo, hi), (2 if lo == 0.0 else 0, 2 if hi == 1.0 else 0))
            for lo, hi in zip(edges[:-1], edges[1:])]


def _check_fit_args(surface: Any, tol: Any, degree: Any, end_order: Any, theta_tol_deg: Any) -> tuple[float, int, float, float]:
    """Validated ``(tol, degree, theta_tol_deg, size)`` of :func:`developable_bspline`."""
    if not isinstance(surface, RuledSurface):
        raise GHTError(f"surface must be a RuledSurface, got {type(surface).__name__}")
    if end_order not in (0, 1, 2):
        raise GHTError(f"end_order={end_order!r} is not allowed; use 0, 1 or 2")
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer, float)) or int(degree) != degree \
            or not 1 <= int(degree) <= 25:
        raise GHTError(f"degree={degree!r} is not allowed; B-spline degrees are integers 1..25")
    degree = int(degree)
    size = _size(surface)
    if tol is None:
        tol = 1e-7 * max(size, 1e-300)
    try:
        tol = float(tol)
        theta_tol_deg = float(theta_tol_deg)
    except (TypeError, ValueError):
        bad = "tol" if not isinstance(tol, float) else "theta_tol_deg"
        raise GHTError(f"{bad}={(tol if bad == 'tol' else theta_tol_deg)!r} is not a number; it must be a positive float") from None
    if not (math.isfinite(tol) and tol > 0):
        raise GHTError(f"tol={tol!r} must be a positive finite number")
    if not theta_tol_deg > 0:
        raise GHTError(f"theta_tol_deg={theta_tol_deg!r} must be > 0 (use inf to skip the check)")
    return tol, degree, theta_tol_deg, size


def _strip_fit(surface: RuledSurface, tol: float, degree: int, end_orders: tuple[int, int],
               theta_tol_deg: float) -> tuple[Any, float, float]:
    """The certified 6-D fit of one smooth strip with its θ check: ``(curve, θ_max, tol used)``."""
    fast = getattr(surface, "boundary_values", None)

    def f(u: np.ndarray) -> np.ndarray:
        return fast(u) if fast is not None else np.hstack([surface.a(u), surface.b(u)])

    tops = tuple(min(k, degree - 1) for k in end_orders)
    jet = getattr(surface, "boundary_jet", None)
    if jet is not None:
        J = jet(np.array([0.0, 1.0]), max(tops))
        ends = tuple([J[r][e] for r in range(tops[e] + 1)] for e in (0, 1))
    else:
        ends = tuple(
            [np.concatenate([surface.a(np.array([e]), r)[0], surface.b(np.array([e]), r)[0]]) for r in range(tops[i] + 1)]
            for i, e in enumerate((0.0, 1.0))
        )
    exact_theta = None
    for attempt in range(4):
        try:
            curve = fit_function(f, tol=tol, degree=degree, end_derivatives=ends)
        except ConversionError as exc:
            raise ConversionError(f"could not fit the boundary curves of {surface!r} to tol={tol:g}: {exc}") from exc
        theta = _bspline_theta(curve) if math.isfinite(theta_tol_deg) else float("nan")
        if not theta > theta_tol_deg:
            break
        if exact_theta is None:
            exact_theta = float(np.nanmax(surface.theta(np.linspace(0.0, 1.0, 513))))
            if exact_theta > 0.5 * theta_tol_deg:
                break  # the surface itself is not developable to theta_tol_deg: keep the tol fit
        if attempt == 3:
            raise ConversionError(
                f"the B-spline fit of {surface!r} has θ_max={theta:.3g}° > theta_tol_deg={theta_tol_deg:g}° "
                f"even at tol={tol:g}; the exact surface has θ_max={exact_theta:.3g}°"
            )
        tol /= 10.0
    return curve, theta, tol


def developable_bspline(
    surface: RuledSurface,
    *,
    tol: float | None = None,
    degree: int = 5,
    end_order: int = 2,
    theta_tol_deg: float = 1e-3,
) -> BSplineSurfaceData:
    r"""B-spline surface data of a ruled strip from compatible directrix poles.

    ``f(u) = (a(u), b(u)) ∈ R^6`` is fitted by :func:`ght_cad.surfaces.bspline.fit_function` with
    ``max_u |f(u) - F(u)| <= tol`` at matched parameters and exact end derivatives up to
    ``end_order``; poles ``F_i = (A_i, B_i)`` give the net ``P[i, 0] = A_i``, ``P[i, 1] = B_i`` with
    ``degree_v = 1``, ``knots_v = [0, 0, 1, 1]``, so ``S(u, v) = (1-v) A(u) + v B(u)``.

    A surface with ``breakpoints`` in (0, 1) (where f is only C0/C1, e.g. a loft's fans, whose apex
    stands still while the other rail moves) is fitted piece by piece (:func:`ruled_pieces`: each
    piece with its exact one-sided end jets, end order ``min(end_order, piece)``) and the pieces
    are joined with knots of multiplicity ``degree`` at the breakpoints
    (:func:`ght_cad.surfaces.bspline.join_bsplines`): ``S`` is then each piece's fit exactly (C0 at the
    joint rulings, the joint ruling an exact pole pair), with the surface's own parameter u = λ.
    A surface without breakpoints takes the single fit as before (bit for bit).

    The fitted surface's own developability is then checked: ``θ(u)`` from the B-spline's
    derivatives (``n_A = A' × G``, ``n_B = B' × G``, ``G = B - A``) on 513 parameters (per piece);
    while ``θ_max > theta_tol_deg`` the fit is repeated with ``tol / 10`` (at most 3 times) — the
    face is then developable to ``theta_tol_deg`` by construction, not only close to a developable.

    Args:
        surface: any :class:`~ght_cad.surfaces.ruled.RuledSurface`.
        tol: absolute deviation bound; default ``1e-7`` times the bounding-box diagonal.
        degree: B-spline degree in u (>= 3 recommended).
        end_order: highest end derivative reproduced exactly (0..2).
        theta_tol_deg: required θ_max of the B-spline surface (degrees); ``inf`` skips the check.

    Returns:
        :class:`~ght_cad.surfaces.bspline.BSplineSurfaceData` with ``max_deviation`` and ``info``
        (``info["theta_max_deg"]``: θ_max of the B-spline surface, ``info["fit_tol"]``; with
        breakpoints also ``info["pieces"]``, ``info["breaks"]``, ``info["joint_gaps"]``).

    Raises:
        ConversionError: the fit could not reach ``tol``, or θ_max stays above
            ``theta_tol_deg`` (only for a surface that is not developable itself).
    """
    tol, degree, theta_tol_deg, size = _check_fit_args(surface, tol, degree, end_order, theta_tol_deg)
    pieces = ruled_pieces(surface)
    if len(pieces) == 1:
        curve, theta, tol = _strip_fit(surface, tol, degree, (end_order, end_order), theta_tol_deg)
    else:
        from ..surfaces.bspline import join_bsplines

        fits = [_strip_fit(pc.surface, tol, degree, tuple(min(end_order, k) for k in pc.end_orders), theta_tol_deg)
                for pc in pieces]
        curve = join_bsplines([c for c, _, _ in fits], [pieces[0].lo] + [pc.hi for pc in pieces])
        ths = [t for _, t, _ in fits if not math.isnan(t)]
        theta = max(ths) if ths else float("nan")
        tol = min(t for _, _, t in fits)
    poles = np.stack([curve.poles[:, :3], curve.poles[:, 3:]], axis=1)
    info = dict(curve.info)
    info["size"] = size
    info["theta_max_deg"] = theta
    info["fit_tol"] = tol
    return BSplineSurfaceData(poles, curve.knots, np.array([0.0, 0.0, 1.0, 1.0]), curve.degree, 1,
                              max_deviation=curve.max_deviation, info=info)
