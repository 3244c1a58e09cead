r"""Exact developable loft between two rails (spec section 5.7).

For rails ``a(t)``, ``b(s)``, t, s ∈ [0, 1], the segment ``a(t)–b(s)`` is a ruling of a
developable through both rails iff the tangent plane is the same at its two ends:

    F(t, s) = det(a'(t), b'(s), b(s) - a(t)) = 0.

The loft is one branch of the zero set of F in the unit square, an increasing curve ``s = σ(t)``
(rulings must not cross). It is traced by predictor–corrector continuation in the path parameter
``λ = (t + s) / 2``: on the branch ``t + s = 2λ`` and ``F = 0`` give

    dt/dλ = 2 F_s / (F_s - F_t),   ds/dλ = -2 F_t / (F_s - F_t),

(both >= 0 on an increasing branch; ``F_t = det(a'', b', g)``, ``F_s = det(a', b'', g)``,
``g = b - a``) and every point is corrected by Newton's method on ``G(t) = F(t, 2λ - t)`` to
round-off, so θ of spec section 5 is round-off on every ruling. Where the branch meets a side of
the square the loft is completed by fans, cones with apex at a rail end: the branch starting on
``s = 0`` at ``t0 > 0`` adds the fan with apex ``b(0)`` over ``a([0, t0])``, starting on ``t = 0``
at ``s0 > 0`` the fan with apex ``a(0)`` over ``b([0, s0])``, and likewise at the upper-right
sides with apex ``a(1)`` or ``b(1)``. The whole loft is then the path from the corner (0, 0) to
(1, 1) in the (t, s) square, parametrized by ``λ ∈ [0, 1]``: fans run along the sides, the main
part along the branch. So both rails are covered over their whole length, the fans share the
tangent plane of the main part along the common ruling (G1), and the loft is one ruled surface
``X(λ, v) = (1-v) a(t(λ)) + v b(s(λ))`` that unrolls as one panel.

Rails running opposite ways (the developable pairs a(t) with a decreasing s) are handled by
tracing with rail b reversed (``orientation="auto"`` tries both).

This package imports numpy and scipy only; matplotlib is imported inside :func:`plot_loft_sign`.

Modules: :mod:`.rails` (rail adapters), :mod:`.equation` (``F`` and its continuation),
:mod:`.tracing` (the branch and the corner-to-corner path), :mod:`.surface` (segments, report,
:class:`DevelopableLoft`), :mod:`.build` (:func:`developable_loft`), :mod:`.plot`
(:func:`plot_loft_sign`). The optimization problem over the rails' shape parameters and its
exact gradients live in :mod:`ght_cad.optimize.problems.loft`; ``ght_cad.developables.loft.LoftProblem``,
``LOFT_OBJECTIVES``, ``LoftGradientFallback`` and ``loft_measures_and_gradients`` are deprecated
aliases of those (loaded from there on use with a :class:`DeprecationWarning`, so that importing
the loft never imports the optimize layer; not in ``__all__``).
"""

from __future__ import annotations

from ...core._lazy import lazy_getattr
from .build import developable_loft
from .equation import CORNER_RADIUS, CORNER_TOL, MIN_FAN, loft_function
from .plot import plot_loft_sign
from .rails import CallableRail, Rail, as_rail
from .surface import DevelopableLoft, LoftReport, LoftSegment

__all__ = [
    "Rail",
    "CallableRail",
    "as_rail",
    "developable_loft",
    "DevelopableLoft",
    "LoftSegment",
    "LoftReport",
    "loft_function",
    "plot_loft_sign",
]

#: Names that moved to :mod:`ght_cad.optimize.problems.loft` (a higher layer): deprecated aliases.
_MOVED = {
    "LoftProblem": "ght_cad.optimize.problems.loft",
    "LOFT_OBJECTIVES": "ght_cad.optimize.problems.loft",
    "LoftGradientFallback": "ght_cad.optimize.problems.loft",
    "loft_measures_and_gradients": "ght_cad.optimize.problems.loft",
}

__getattr__ = lazy_getattr(__name__, _MOVED, globals(), deprecated=True)
