r"""The exact plate of a developable design surface as B-spline data (spec 6.1), no CAD kernel.

A sheet of thickness ``T`` on a developable ``X(u, v) = (1-v) a(u) + v b(u)`` (unit normal
``n(u)``, constant along each ruling; :func:`ght_cad.sheetmetal.sheet.ruling_normal`) fills the region

    P = { X(u, v) + t n(u) : u, v ∈ [0, 1], t between 0 and σT }        (σ = +1 "normal", -1 "reverse")

bounded by six ruled faces, all of degree 1 in their second parameter:

* ``inside``: the design surface ``X`` (net ``[A, B]``);
* ``outside``: the offset ``X + σT n`` (net ``[A', B']``; again developable with the same
  rulings, :class:`ght_cad.sheetmetal.sheet.OffsetRuledSurface`);
* ``wall_a``, ``wall_b``: the walls over the boundary curves, ``c(u) + t n(u)`` for ``c = a, b``
  (nets ``[A, A']``, ``[B, B']``); over a fan whose apex ``P`` is on that boundary the wall is the
  cone patch between the point ``P`` (a collapsed pole row) and the arc ``P + σT n(u)``;
* ``end0``, ``end1``: the end rulings swept along the normal, the planar parallelograms
  ``a(e), b(e), b(e) + σT n(e), a(e) + σT n(e)`` (e = 0, 1; a bilinear 2 x 2 net). At a
  **pointed end** (the end ruling has zero length: the boundaries meet at ``P``, a bow) the
  parallelogram collapses to the segment ``P .. P + σT n(e)`` (``n(e)`` the limit normal,
  :func:`ght_cad.sheetmetal.sheet.ruling_normal`): there is no end face, ``inside`` and ``outside`` end in a
  collapsed pole column (a degenerate edge) and the walls ``wall_a``, ``wall_b`` meet along that
  segment (their end pole columns are snapped to the same points).

The four boundary curves are fitted TOGETHER as one 12-D function
``f(u) = (a, b, a + σT n, b + σT n)`` by :func:`ght_cad.surfaces.bspline.fit_function` (one knot vector,
deviation at matched parameters, values and first derivatives exact at the ends), piece by piece
between the surface's ``breakpoints`` (:func:`ght_cad.developables.envelope.ruled_pieces`, e.g. a loft's
fans and main part) and joined with knots of multiplicity ``p`` (:func:`ght_cad.surfaces.bspline.join_bsplines`).
Every two faces that meet share their boundary curve pole for pole, so a kernel sews them exactly
(:func:`ght_cad.cad.sheet_solid.plate_solid`). A boundary that stands still on a piece (a fan's
apex) gets its exact point as every pole of that piece.

Volume (the closed form the solid is checked against): with ``e = n × d``, ``d = g/|g|``,
``ω = n'·e`` (:func:`ght_cad.sheetmetal.sheet.bending_radius`: ``ρ_0 = (X_u·e)/ω``) the area element of the
offset at ``t`` is ``dA_t = (1 + t/ρ_0) dA``, and ``(1/ρ_0) dA = sgn(X_u·e) ω |g| du dv``, so

    V = T A + σ (T²/2) ∫∫ 2H dA = T A + σ (T²/2) ∫_0^1 sgn(X_u·e) ω(u) |g(u)| du

(``2H = 1/ρ_0`` the mean curvature of a developable, signed by the normal ``n``;
:func:`plate_volume`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..surfaces.bspline import BSplineCurveData, BSplineSurfaceData, fit_function, join_bsplines
from ..core.errors import ConversionError, GHTError
from ..surfaces.ruled import RuledSurface

__all__ = ["PlateBSplineData", "plate_bspline", "plate_volume", "PLATE_FACES"]

#: the faces of a plate in the order :attr:`PlateBSplineData.faces` lists them
PLATE_FACES = ("inside", "outside", "wall_a", "wall_b", "end0", "end1")

_KNOTS_1 = np.array([0.0, 0.0, 1.0, 1.0])


@dataclass
class PlateBSplineData:
    r"""The six faces of an exact plate (module doc) as B-spline surface data.

    Attributes:
        inside, outside, wall_a, wall_b: degree ``p`` in u (the surface's own parameter λ, knots
            of multiplicity ``p`` at the breakpoints), degree 1 across.
        end0, end1: bilinear parallelograms at u = 0 and u = 1.
        breaks: the piece boundaries ``0 = λ_0 < ... < λ_P = 1``.
        apex: per piece, which boundary stands still there (``"a"``, ``"b"`` or None).
        max_deviation: certified ``max_u |f(u) - F(u)|`` of the 12-D fit (module doc).
        info: fit details (``tol``, ``spans``, per-piece infos, ``joint_gaps``, ``snap``: the
            largest pole move of a collapsed row).
    """

    inside: BSplineSurfaceData
    outside: BSplineSurfaceData
    wall_a: BSplineSurfaceData
    wall_b: BSplineSurfaceData
    end0: BSplineSurfaceData | None
    end1: BSplineSurfaceData | None
    breaks: tuple[float, ...]
    apex: tuple[str | None, ...]
    max_deviation: float
    info: dict[str, Any] = field(default_factory=dict)
    #: per end (u = 0, u = 1): True where the strip ends in a point (zero-length end ruling)
    pointed: tuple[bool, bool] = (False, False)

    @property
    def faces(self) -> list[tuple[str, BSplineSurfaceData]]:
        """``[(name, data)]`` in the order of :data:`PLATE_FACES`, without the end wall of a
        pointed end (None: it collapsed to the segment ``P .. P + σT n``)."""
        return [(name, getattr(self, name)) for name in PLATE_FACES if getattr(self, name) is not None]


def _offset_thickness(sheet: Any) -> float:
    out = getattr(sheet, "outside_offset", None)
    if out is None or not math.isfinite(float(out)) or float(out) == 0.0:
        raise GHTError(f"sheet={sheet!r} is not allowed; give a ght_cad.sheet.Sheet with a thickness > 0")
    return float(out)


def _piece_fit(piece: Any, off: float, tol: float, degree: int, size: float) -> tuple[BSplineCurveData, str | None, float]:
    """The 12-D fit of one smooth piece; its collapsed boundary row (if any) snapped to the point."""
    from .sheet import ruling_normal

    surf = piece.surface

    def f(x: np.ndarray) -> np.ndarray:
        a, b = surf.a(x), surf.b(x)
        n = ruling_normal(surf, x, 0)[0]
        return np.hstack([a, b, a + off * n, b + off * n])

    e = np.array([0.0, 1.0])
    n0, n1 = ruling_normal(surf, e, 1)
    a0, b0, a1, b1 = surf.a(e), surf.b(e), surf.a(e, 1), surf.b(e, 1)
    ends = []
    for k in (0, 1):
        jet = [np.concatenate([a0[k], b0[k], a0[k] + off * n0[k], b0[k] + off * n0[k]])]
        if min(piece.end_orders[k], 1, degree - 1) >= 1:
            jet.append(np.concatenate([a1[k], b1[k], a1[k] + off * n1[k], b1[k] + off * n1[k]]))
        ends.append(jet)
    try:
        curve = fit_function(f, tol=tol, degree=degree, end_derivatives=(ends[0], ends[1]))
    except ConversionError as exc:
        raise ConversionError(f"could not fit the plate boundary curves of {surf!r} to tol={tol:g}: {exc}") from exc
    # a boundary that stands still on the piece (a fan's apex): every pole of its row is the point
    x = np.linspace(0.0, 1.0, 33)
    apex, snap = None, 0.0
    for name, fn, cols in (("a", surf.a, slice(0, 3)), ("b", surf.b, slice(3, 6))):
        vals = fn(x)
        if float(np.ptp(vals, axis=0).max()) <= 64.0 * np.finfo(float).eps * max(size, 1e-300):
            apex = name
            snap = max(snap, float(np.abs(curve.poles[:, cols] - vals[0]).max()))
            curve.poles[:, cols] = vals[0]
    return curve, apex, snap


def plate_bspline(surface: RuledSurface, sheet: Any, *, tol: float | None = None, degree: int = 5) -> PlateBSplineData:
    r"""The six faces of the exact plate of thickness ``T`` on a developable (module doc).

    Does not check the sheet against the surface's curvature: call
    :func:`ght_cad.sheetmetal.sheet.check_offset` first (a thickness beyond a bending radius gives a
    self-intersecting offset).

    Args:
        surface: the developable design surface (a :class:`~ght_cad.surfaces.ruled.RuledSurface`, with or
            without ``breakpoints``).
        sheet: the :class:`ght_cad.sheetmetal.sheet.Sheet` (``outside_offset = σ T``; K does not change the
            solid).
        tol: deviation bound of the 12-D fit at matched parameters; default
            ``max(3e-7 T, 64 ulp × size)`` (a deviation ``d`` changes the volume by about
            ``d / T`` relative).
        degree: B-spline degree in u (2..25).

    Returns:
        :class:`PlateBSplineData`.

    Raises:
        GHTError: not a ruled surface, no sheet thickness, bad ``tol``/``degree``; a
            :class:`ght_cad.sheetmetal.sheet.SheetError` where the normal is undefined (a zero ruling).
        ConversionError: the fit did not reach ``tol``.
    """
    from ..developables.envelope import _size, ruled_pieces

    if not isinstance(surface, RuledSurface):
        raise GHTError(f"surface must be a RuledSurface, got {type(surface).__name__}")
    off = _offset_thickness(sheet)
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or not 2 <= int(degree) <= 25:
        raise GHTError(f"degree={degree!r} is not allowed; plate B-spline degrees are integers 2..25")
    degree = int(degree)
    size = _size(surface)
    if tol is None:
        tol = max(3e-7 * abs(off), 64.0 * np.finfo(float).eps * size)
    try:
        tol = float(tol)
    except (TypeError, ValueError):
        raise GHTError(f"tol={tol!r} is not a number; it must be a positive float") from None
    if not (math.isfinite(tol) and tol > 0):
        raise GHTError(f"tol={tol!r} is not allowed; it must be a positive finite number")
    pieces = ruled_pieces(surface)
    fits = [_piece_fit(pc, off, tol, degree, size) for pc in pieces]
    breaks = [pieces[0].lo] + [pc.hi for pc in pieces]
    curve = fits[0][0] if len(fits) == 1 else join_bsplines([c for c, _, _ in fits], breaks)
    if len(fits) == 1:  # the single piece's knots are already on [0, 1]
        curve.info = {"pieces": [dict(curve.info)], "joint_gaps": [], "breaks": breaks, "spans": curve.info.get("spans")}
    P = curve.poles
    # a pointed end (zero-length end ruling, the rails meet): the end poles of a and b (and of
    # their offsets) are one point; snapped to it so the faces' edges there collapse exactly
    g_end = surface.ruling_lengths(np.array([0.0, 1.0]))
    pointed = tuple(bool(x <= 64.0 * np.finfo(float).eps * size) for x in g_end)
    for k, row in ((0, 0), (1, -1)):
        if pointed[k]:
            for c0, c1 in ((0, 3), (6, 9)):
                mid = 0.5 * (P[row, c0:c0 + 3] + P[row, c1:c1 + 3])
                P[row, c0:c0 + 3] = mid
                P[row, c1:c1 + 3] = mid
    A, B, A2, B2 = P[:, 0:3], P[:, 3:6], P[:, 6:9], P[:, 9:12]
    K = curve.knots

    def ruled(first: np.ndarray, second: np.ndarray) -> BSplineSurfaceData:
        return BSplineSurfaceData(np.stack([first, second], axis=1), K, _KNOTS_1, degree, 1, max_deviation=curve.max_deviation)

    def quad(i: int) -> BSplineSurfaceData:
        net = np.array([[A[i], B[i]], [A2[i], B2[i]]])
        return BSplineSurfaceData(net, _KNOTS_1, _KNOTS_1, 1, 1, max_deviation=curve.max_deviation)

    snap = max(s for _, _, s in fits)
    dev = float(curve.max_deviation) + snap
    info = dict(curve.info)
    info.update({"tol": tol, "snap": snap, "size": size, "offset": off})
    return PlateBSplineData(ruled(A, B), ruled(A2, B2), ruled(A, A2), ruled(B, B2),
                            None if pointed[0] else quad(0), None if pointed[1] else quad(-1),
                            tuple(float(x) for x in breaks), tuple(a for _, a, _ in fits), dev, info, pointed)


def plate_volume(surface: RuledSurface, sheet: Any, *, rtol: float = 1e-13) -> float:
    r"""Closed-form volume of the plate ``{X + t n, t between 0 and σT}`` (module doc):

        V = T A + σ (T²/2) ∫_0^1 sgn(X_u·e) ω(u) |g(u)| du,

    ``A`` the surface's area (:func:`ght_cad.unroll.ruled_area`), ``ω = n'·e``, ``e = n × d``,
    ``X_u`` at mid-ruling; both integrals by adaptive Gauss–Legendre piecewise between the
    ``breakpoints``. Valid while the offset is regular (:func:`ght_cad.sheetmetal.sheet.check_offset`).

    Args:
        surface: the developable.
        sheet: the :class:`ght_cad.sheetmetal.sheet.Sheet` (thickness > 0).
        rtol: relative tolerance of the quadratures.

    Raises:
        GHTError: not a ruled surface or no thickness.
    """
    from ..curves.curve import integrate
    from .sheet import ruling_normal
    from ..unrolling.unroll import _smooth_pieces, ruled_area

    if not isinstance(surface, RuledSurface):
        raise GHTError(f"surface must be a RuledSurface, got {type(surface).__name__}")
    off = _offset_thickness(sheet)
    T = abs(off)

    def bend(u: np.ndarray) -> np.ndarray:
        n, n1 = ruling_normal(surface, u, 1)
        g = surface.ruling(u)
        L = np.linalg.norm(g, axis=1)
        e = np.cross(n, g / L[:, None])
        xu = surface.a(u, 1) + 0.5 * surface.ruling(u, 1)
        return np.sign(np.einsum("ij,ij->i", xu, e)) * np.einsum("ij,ij->i", n1, e) * L

    area = ruled_area(surface, rtol=rtol)
    turn = sum(integrate(bend, lo, hi, rtol=rtol) for lo, hi in _smooth_pieces(surface))
    return float(T * area + math.copysign(1.0, off) * 0.5 * T * T * turn)
