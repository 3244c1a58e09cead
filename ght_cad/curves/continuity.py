r"""Joining two GHT-Bézier segments with C0–C3 / G0–G3 continuity (spec section 4).

Segment A (control points ``P_0..P_m``, its own μ, ν, γ) ends where segment B (``R_0..R_n``, its
own μ, ν, γ) starts. The conditions at the joint are

=====  ==========================================================================
C0=G0  ``R(0) = P(1)``
C1     ``R'(0) = P'(1)``
C2     also ``R''(0) = P''(1)``
C3     also ``R'''(0) = P'''(1)``
G1     ``R'(0) = k P'(1)``, ``k > 0``
G2     also ``R''(0) = k² P''(1) + β2 P'(1)``
G3     also ``R'''(0) = k³ P'''(1) + 3 k β2 P''(1) + β3 P'(1)``
=====  ==========================================================================

The G conditions are the chain rule for ``R(t) = P(φ(t))`` with ``φ(0) = 1``, ``φ'(0) = k``,
``φ''(0) = β2``, ``φ'''(0) = β3``. Every derivative is linear in the control points,
``R^(r)(0) = Σ_i b^{(r)}_{i}(0) R_i``, and ``b^{(r)}_i(0) = 0`` for ``i > r``, so the conditions
solve one point at a time: ``R_r = (target_r - Σ_{i<r} b^{(r)}_i(0) R_i) / c_r`` with the
newest-point coefficient ``c_r = b^{(r)}_r(0)`` (:meth:`GHTCurve.newest_point_coefficient`).
The remaining points of B are kept. Works for any degrees, shape parameters and dimension (2-D,
3-D and 4-D plane coordinates, spec section 5.6).

:func:`measure_continuity` measures the order a joint achieves from the two curves alone
(their end derivatives), independently of :func:`join`.
"""

from __future__ import annotations

import enum
import math
from math import comb
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .curve import GHTCurve
from ..core.errors import GHTError, SingularJoinError
from ..core._cache import readonly_cache
from .seeds import MAX_DERIVATIVE, BernsteinSeed, GBTSeed, GHTSeed, make_seed, seed_names

__all__ = [
    "Continuity",
    "JointReport",
    "join",
    "join_targets",
    "measure_continuity",
    "reverse_g_parameters",
]

#: ``|c_r|`` at or below this (relative to the 1-norm of the basis-derivative row) is singular.
_SINGULAR_REL = 1e-12
#: relative size of A's end tangent |P'(1)| (against the sum of the terms) below which G1..G3 joins are refused
_TANGENT_REL = 1e-9


class Continuity(str, enum.Enum):
    """Continuity at a joint: parametric ``C0..C3`` or geometric ``G0..G3``.

    Members compare equal to their names (``Continuity.G2 == "G2"``). Parse user input with
    :meth:`parse` (case-insensitive); ``Continuity("g2")`` works too.

    Attributes:
        order: derivative order r (0..3).
        geometric: True for G orders.
    """

    C0 = "C0"
    C1 = "C1"
    C2 = "C2"
    C3 = "C3"
    G0 = "G0"
    G1 = "G1"
    G2 = "G2"
    G3 = "G3"

    @property
    def order(self) -> int:
        """Derivative order r of the condition (0..3)."""
        return int(self.value[1])

    @property
    def geometric(self) -> bool:
        """True for G0..G3 (geometric continuity with parameters k, β2, β3)."""
        return self.value[0] == "G"

    def __str__(self) -> str:
        return self.value

    @classmethod
    def parse(cls, value: Any) -> "Continuity":
        """Return the member for ``value`` (a member or a string such as ``"g2"``, ``" C1 "``).

        Raises:
            GHTError: ``value`` is not one of C0..C3, G0..G3.
        """
        if isinstance(value, cls):
            return value
        if isinstance(value, str):
            key = value.strip().upper()
            if key in cls.__members__:
                return cls.__members__[key]
        raise GHTError(
            f"continuity={value!r} is not allowed; use one of "
            + ", ".join(m.value for m in cls)
            + " (case-insensitive)"
        )

    @classmethod
    def _missing_(cls, value: object) -> "Continuity":
        return cls.parse(value)


def _check_g_parameters(k: Any, beta2: Any, beta3: Any) -> tuple[float, float, float]:
    vals = []
    for name, v in (("k", k), ("beta2", beta2), ("beta3", beta3)):
        try:
            f = float(v)
        except (TypeError, ValueError):
            raise GHTError(f"{name}={v!r} is not a number; it must be a finite real number") from None
        if not math.isfinite(f):
            raise GHTError(f"{name}={f} is not finite; it must be a finite real number")
        vals.append(f)
    if vals[0] <= 0.0:
        raise SingularJoinError(
            f"k={vals[0]:g} is not allowed: geometric continuity needs k > 0 "
            "(k <= 0 reverses or collapses the tangent at the joint)"
        )
    return vals[0], vals[1], vals[2]


def _seed_for(curve: GHTCurve, mu: Any, nu: Any, gamma: Any):
    """Seed of ``curve`` with some shape parameters replaced (same seed family)."""
    if mu is None and nu is None and gamma is None:
        return curve.seed
    name = curve.seed.name
    if name in ("gbt", "bernstein"):
        name = "ght"  # both are members of the GHT family (γ = -1 and γ = 1)
    if name not in seed_names():
        raise GHTError(
            f"segment_b uses the unregistered seed {name!r}; its shape parameters cannot be "
            "replaced by mu/nu/gamma: build segment_b with the wanted parameters instead"
        )
    return make_seed(
        name,
        curve.mu if mu is None else mu,
        curve.nu if nu is None else nu,
        curve.gamma if gamma is None else gamma,
    )


def _as_segment_b(segment_b: Any, mu: Any, nu: Any, gamma: Any) -> GHTCurve:
    if isinstance(segment_b, GHTCurve):
        return GHTCurve(segment_b.control_points, seed=_seed_for(segment_b, mu, nu, gamma))
    return GHTCurve(
        segment_b,
        0.0 if mu is None else mu,
        0.0 if nu is None else nu,
        0.0 if gamma is None else gamma,
    )


def _end_rows(curve: GHTCurve, end: int, max_order: int) -> list[np.ndarray]:
    """Rows ``b^{(r)}_{i}(end)`` of the basis, r = 0..max_order, by full basis evaluation.

    Used by :func:`measure_continuity` (the independent path).
    """
    t = np.array([float(end)])
    return [curve.basis(t, r)[0] for r in range(max_order + 1)]


_BUILTIN_SEEDS = (GHTSeed, GBTSeed, BernsteinSeed)


def _seed_end_jets(seed) -> tuple[np.ndarray, np.ndarray]:
    """``seed.end_jets()``, cached for the built-in seed classes (keyed by class and μ, ν, γ; read-only)."""
    if type(seed) not in _BUILTIN_SEEDS:
        return seed.end_jets()
    return _builtin_end_jets(type(seed), seed.mu, seed.nu, seed.gamma)


@readonly_cache(maxsize=4096)
def _builtin_end_jets(cls: type, mu: float, nu: float, gamma: float) -> tuple[np.ndarray, np.ndarray]:
    """``cls(mu, nu, gamma).end_jets()`` for a built-in seed class (:func:`ght_cad.core._cache.readonly_cache`)."""
    return cls(mu, nu, gamma).end_jets()


def _end_rows_fast(curve: GHTCurve, end: int, max_order: int) -> list[np.ndarray]:
    r"""Rows ``b^{(r)}_{i,m}(end)`` from the seed's end jets (used by :func:`join`).

    ``b^{(r)}_{i,m} = Σ_s C(r,s) Σ_k B^{(r-s)}_{i-k,n} f_k^{(s)}`` (n = m-2) with the Bernstein end
    values ``B^{(j)}_{l,n}(0) = n!/(n-j)! (-1)^{j-l} C(j,l)`` and
    ``B^{(j)}_{l,n}(1) = n!/(n-j)! (-1)^{n-l} C(j, l-n+j)``.
    """
    a, e = _seed_end_jets(curve.seed)
    jets = a if end == 0 else e
    m = curve.degree
    n = m - 2
    rows = []
    for r in range(max_order + 1):
        row = np.zeros(m + 1)
        for s_ in range(r + 1):
            j = r - s_
            if j > n:
                continue
            ff = float(np.prod(np.arange(n - j + 1, n + 1))) if j else 1.0
            Bj = np.zeros(n + 1)
            if end == 0:
                for l_ in range(j + 1):
                    Bj[l_] = ff * (-1) ** (j - l_) * comb(j, l_)
            else:
                for l_ in range(n - j, n + 1):
                    Bj[l_] = ff * (-1) ** (n - l_) * comb(j, l_ - n + j)
            c = comb(r, s_)
            for k in range(3):
                row[k : k + n + 1] += c * jets[s_, k] * Bj
        rows.append(row)
    return rows


def join_targets(
    segment_a: GHTCurve,
    continuity: Any,
    *,
    k: float = 1.0,
    beta2: float = 0.0,
    beta3: float = 0.0,
) -> list[np.ndarray]:
    r"""Targets ``T_r`` for ``R^(r)(0)``, r = 0..order, from segment A's end derivatives.

    C: ``T_r = P^(r)(1)``, ``T_0 = P(1) = P_m`` (exactly). G: ``T_0 = P_m``, ``T_1 = k P'``, ``T_2 = k² P'' + β2 P'``,
    ``T_3 = k³ P''' + 3kβ2 P'' + β3 P'`` (all at t = 1).

    Args:
        segment_a: the segment whose end is joined.
        continuity: C0..C3 or G0..G3.
        k, beta2, beta3: G parameters (k > 0); must keep their defaults for C orders.

    Returns:
        List of ``order + 1`` arrays of shape (dim,).

    Raises:
        GHTError: bad continuity, non-finite G parameters, G parameters given for a C order.
        SingularJoinError: k <= 0.
    """
    cont = Continuity.parse(continuity)
    if not isinstance(segment_a, GHTCurve):
        raise GHTError(f"segment_a must be a GHTCurve, got {type(segment_a).__name__}")
    k, beta2, beta3 = _check_g_parameters(k, beta2, beta3)
    if not cont.geometric and (k != 1.0 or beta2 != 0.0 or beta3 != 0.0):
        raise GHTError(
            f"k={k:g}, beta2={beta2:g}, beta3={beta3:g} given with parametric continuity "
            f"{cont.value}; k, beta2, beta3 apply to G1..G3 only (use k=1, beta2=beta3=0)"
        )
    r = cont.order
    P = segment_a.control_points
    d = [row @ P for row in _end_rows_fast(segment_a, 1, r)]
    d[0] = np.array(P[-1], dtype=float)  # P(1) = P_m exactly (b_{i,m}(1) = δ_im, spec section 2)
    if not cont.geometric:
        return d
    out = [d[0]]
    with np.errstate(over="ignore", invalid="ignore"):  # huge k: inf targets, refused by join()
        if r >= 1:
            out.append(k * d[1])
        if r >= 2:
            out.append(k * k * d[2] + beta2 * d[1])
        if r >= 3:
            out.append(k * k * k * d[3] + 3.0 * k * beta2 * d[2] + beta3 * d[1])
    return out


def join(
    segment_a: GHTCurve,
    continuity: Any,
    segment_b: Any,
    *,
    mu: float | None = None,
    nu: float | None = None,
    gamma: float | None = None,
    k: float = 1.0,
    beta2: float = 0.0,
    beta3: float = 0.0,
) -> GHTCurve:
    r"""Segment B with its first ``r+1`` control points solved for continuity ``r`` with A.

    For r = 0..order: ``R_r = (T_r - Σ_{i<r} b^{(r)}_i(0) R_i) / c_r`` with ``c_r = b^{(r)}_r(0)``
    (B's newest-point coefficient) and ``T_r`` from :func:`join_targets`:
    ``R(0) = P(1)``; C: ``R^(r)(0) = P^(r)(1)``; G1: ``R'(0) = k P'(1)``;
    G2: ``R''(0) = k² P''(1) + β2 P'(1)``; G3: ``R'''(0) = k³ P''' + 3kβ2 P'' + β3 P'``.
    Points ``R_{r+1}..R_n`` of B are kept unchanged.

    Args:
        segment_a: segment A (any degree >= 2, any shape parameters and dimension).
        continuity: ``Continuity`` or string ``"C0".."C3"``, ``"G0".."G3"`` (case-insensitive).
        segment_b: a :class:`GHTCurve`, or array-like control points (count, dim) of B.
        mu, nu, gamma: B's shape parameters; ``None`` keeps those of ``segment_b`` (or 0.0 when
            ``segment_b`` is an array).
        k: G tangent-length ratio ``k > 0`` (G1..G3 only).
        beta2, beta3: G2/G3 parameters (G orders only).

    Returns:
        A new :class:`GHTCurve` B (same seed family as given) satisfying the condition exactly up
        to rounding.

    Raises:
        SingularJoinError: ``k <= 0``; B's degree is below the order (it has fewer than r+1
            points to solve); a newest-point coefficient ``c_r`` is zero (e.g. degree 2 with
            γ = -1, μ = -1 has ``c_1 = 0``); G1..G3 when A's end tangent vanishes
            (``|P'(1)| <= 1e-9 Σ_i |a'_i(1)| |P_i|``, e.g. degree 2 with ν = γ = -1).
        GHTError: segments of different dimension, bad continuity, bad shape parameters,
            G parameters with a C order.

    Example:
        >>> a = GHTCurve([(0, 0), (1, 1), (2, 0)], gamma=-1)
        >>> b = join(a, "G2", [(0, 0), (0, 0), (0, 0), (3, -1), (4, 0)], k=2.0)
        >>> measure_continuity(a, b).g_order
        2
    """
    cont = Continuity.parse(continuity)
    if not isinstance(segment_a, GHTCurve):
        raise GHTError(f"segment_a must be a GHTCurve, got {type(segment_a).__name__}")
    b = _as_segment_b(segment_b, mu, nu, gamma)
    if b.dim != segment_a.dim:
        raise GHTError(
            f"segment_b has dimension {b.dim} but segment_a has dimension {segment_a.dim}; "
            "joined segments must have the same dimension"
        )
    r_max = cont.order
    if b.degree < r_max:
        raise SingularJoinError(
            f"cannot impose {cont.value}: it fixes R_0..R_{r_max} ({r_max + 1} control points) but "
            f"segment B has degree {b.degree} ({b.degree + 1} points); {cont.value} needs degree >= {r_max}"
        )
    targets = join_targets(segment_a, cont, k=k, beta2=beta2, beta3=beta3)
    if cont.geometric and r_max >= 1:
        # G1..G3 need A's unit tangent at t = 1; with P'(1) = 0 (e.g. degree 2, nu = gamma = -1,
        # or P_{m-1} = P_m) the condition R'(0) = k P'(1) would only build a cusp R_1 = R_0
        P = segment_a.control_points
        row1 = _end_rows_fast(segment_a, 1, 1)[1]
        scale = max(float(np.abs(row1) @ np.linalg.norm(P, axis=1)), float(np.ptp(P, axis=0).max()), 1e-300)
        d1 = float(np.linalg.norm(row1 @ P))
        if not d1 > _TANGENT_REL * scale:
            raise SingularJoinError(
                f"cannot impose {cont.value}: the end tangent P'(1) of segment A vanishes (|P'(1)| = {d1:.3g}, "
                f"relative {d1 / scale:.3g} <= {_TANGENT_REL:g}) for segment A of degree {segment_a.degree} with "
                f"mu={segment_a.mu:g}, nu={segment_a.nu:g}, gamma={segment_a.gamma:g}; a geometric joint needs a "
                "unit tangent: change A's shape parameters (degree 2 with nu = gamma = -1 has P'(1) = 0) or "
                "separate P_(m-1) from P_m, or join with C0/C1"
            )
    rows = _end_rows_fast(b, 0, r_max)
    pts = np.array(b.control_points, dtype=float)
    pts[0] = targets[0]  # R(0) = R_0 exactly (b_{i,n}(0) = δ_i0, c_0 = 1)
    for r in range(1, r_max + 1):
        row = rows[r]
        c = float(row[r])
        if not abs(c) > _SINGULAR_REL * max(1.0, float(np.abs(row).sum())):
            raise SingularJoinError(
                f"cannot impose {cont.value}: the newest-point coefficient c_{r} = b^({r})_{{{r},{b.degree}}}(0) "
                f"of R_{r} in R^({r})(0) is {c:.3g} (zero) for segment B of degree {b.degree} with "
                f"mu={b.mu:g}, nu={b.nu:g}, gamma={b.gamma:g}; order {r} cannot be imposed by moving "
                f"R_{r}: change B's degree or shape parameters"
            )
        known = row[:r] @ pts[:r]
        with np.errstate(over="ignore", invalid="ignore"):
            pts[r] = (targets[r] - known) / c
    from ..core._validate import MAX_COORDINATE

    if not np.all(np.abs(pts) <= MAX_COORDINATE):  # NaN/inf included
        raise SingularJoinError(
            f"cannot impose {cont.value} with k={k:g}, beta2={beta2:g}, beta3={beta3:g}: segment B's solved "
            f"control points R_1..R_{r_max} reach {float(np.nanmax(np.abs(pts))):g} (beyond ±{MAX_COORDINATE:g}); "
            "allowed: G parameters of moderate size (k near the ratio of the two segments' end speeds)"
        )
    return GHTCurve(pts, seed=b.seed)


def reverse_g_parameters(k: float, beta2: float, beta3: float) -> tuple[float, float, float]:
    r"""G parameters of the same joint seen with both segments reversed.

    If ``R(t) = P(φ(t))`` with ``φ' = k, φ'' = β2, φ''' = β3`` at the joint, then for the reversed
    curves ``P~(t) = P(1-t)``, ``R~(t) = R(1-t)``: ``P~(t) = R~(χ(t))`` with
    ``χ' = 1/k``, ``χ'' = β2/k³``, ``χ''' = (3β2² - kβ3)/k⁵`` (inverse-function derivatives).
    So joining ``R~`` (as A) to ``P~`` (as B) with these parameters is the same joint.

    Args:
        k, beta2, beta3: the forward joint's G parameters (k > 0).

    Returns:
        ``(k~, β2~, β3~)``.

    Raises:
        SingularJoinError: k <= 0.
    """
    k, beta2, beta3 = _check_g_parameters(k, beta2, beta3)
    return 1.0 / k, beta2 / k**3, (3.0 * beta2 * beta2 - k * beta3) / k**5


@dataclass(frozen=True)
class JointReport:
    """Continuity a joint achieves, measured by :func:`measure_continuity`.

    Attributes:
        c_order: highest r (0..3) with C0..Cr all holding; -1 if not even C0.
        g_order: highest r (0..3) with G0..Gr holding; -1 if not even G0. Never below c_order.
        c_residuals: relative residuals of the C conditions, r = 0..3.
        g_residuals: relative residuals of the G conditions with the fitted k, β2, β3.
        k, beta2, beta3: least-squares estimates (NaN when A's end tangent vanishes).
        tol: the relative tolerance used.
        notes: human-readable remarks (vanishing or reversed end tangents).
    """

    c_order: int
    g_order: int
    c_residuals: tuple[float, ...]
    g_residuals: tuple[float, ...]
    k: float
    beta2: float
    beta3: float
    tol: float
    notes: tuple[str, ...] = field(default=())

    def satisfies(self, continuity: Any) -> bool:
        """True if the joint achieves ``continuity`` (e.g. ``"G2"``)."""
        c = Continuity.parse(continuity)
        return (self.g_order if c.geometric else self.c_order) >= c.order

    def __str__(self) -> str:
        c = f"C{self.c_order}" if self.c_order >= 0 else "discontinuous"
        g = f"G{self.g_order}" if self.g_order >= 0 else "discontinuous"
        return f"joint {c}/{g} (k={self.k:.6g}, beta2={self.beta2:.6g}, beta3={self.beta3:.6g}, tol={self.tol:g})"


def measure_continuity(a: GHTCurve, b: GHTCurve, *, tol: float = 1e-9) -> JointReport:
    r"""Measure the continuity order of the joint ``A(1) → B(0)`` from the two curves alone.

    Uses only the analytic end derivatives ``d_r = A^(r)(1)``, ``e_r = B^(r)(0)`` (r = 0..3).
    Tolerance definition: a condition ``e_r = T_r`` holds when its relative residual
    ``ρ_r = |e_r - T_r| / S_r <= tol``, with the scale

    ``S_r = max(L, Σ_i |b^{(r)}_i(0)| |R_i|, Σ_j w_j Σ_i |a^{(j)}_i(1)| |P_i|)``

    where L is the bounding-box diagonal of both control polygons, ``a^{(j)}_i``/``b^{(r)}_i`` the
    basis-derivative rows of A at 1 and B at 0, and ``w_j`` the absolute coefficients with which
    ``d_j`` enters ``T_r`` (C: ``T_r = d_r``; G: ``T_1 = k d_1``, ``T_2 = k² d_2 + β2 d_1``,
    ``T_3 = k³ d_3 + 3kβ2 d_2 + β3 d_1``). ``S_r`` bounds the magnitude of the terms summed, so
    ``ρ_r`` is the residual relative to the size at which rounding happens.
    G parameters are least-squares fits, one order at a time: ``k = <e_1, d_1>/|d_1|²``,
    ``β2 = <e_2 - k² d_2, d_1>/|d_1|²``, ``β3 = <e_3 - k³ d_3 - 3kβ2 d_2, d_1>/|d_1|²``; G1 and
    higher also need ``k > 0`` and non-vanishing tangents (``|d_1|, |e_1| > tol S_1``). Since
    ``Cr`` is ``Gr`` with ``k = 1, β = 0``, ``g_order >= c_order`` always.

    Args:
        a: segment A (its end t = 1 is the joint).
        b: segment B (its start t = 0 is the joint).
        tol: relative tolerance (> 0).

    Returns:
        :class:`JointReport`.

    Raises:
        GHTError: not GHTCurves, different dimensions, bad tol.
    """
    if not isinstance(a, GHTCurve) or not isinstance(b, GHTCurve):
        raise GHTError(
            f"measure_continuity needs two GHTCurve objects, got {type(a).__name__} and {type(b).__name__}"
        )
    if a.dim != b.dim:
        raise GHTError(f"curves have dimensions {a.dim} and {b.dim}; a joint needs equal dimensions")
    try:
        tol = float(tol)
    except (TypeError, ValueError):
        raise GHTError(f"tol={tol!r} is not a number; it must be a positive real number") from None
    if not (math.isfinite(tol) and tol > 0):
        raise GHTError(f"tol={tol!r} is not allowed; it must be a positive finite number")
    R_ = MAX_DERIVATIVE
    P, Q = a.control_points, b.control_points
    allpts = np.vstack([P, Q])
    L = float(np.linalg.norm(allpts.max(axis=0) - allpts.min(axis=0)))
    if L == 0.0:
        L = 1.0
    nP, nQ = np.linalg.norm(P, axis=1), np.linalg.norm(Q, axis=1)
    rows_a, rows_b = _end_rows(a, 1, R_), _end_rows(b, 0, R_)
    d = [row @ P for row in rows_a]
    e = [row @ Q for row in rows_b]
    ma = [float(np.abs(row) @ nP) for row in rows_a]
    mb = [float(np.abs(row) @ nQ) for row in rows_b]

    def rel(vec: np.ndarray, scale: float) -> float:
        return float(np.linalg.norm(vec)) / max(L, scale)

    c_res = tuple(rel(e[r] - d[r], max(ma[r], mb[r])) for r in range(R_ + 1))
    c_order = -1
    for r in range(R_ + 1):
        if c_res[r] <= tol:
            c_order = r
        else:
            break

    notes: list[str] = []
    den = float(d[1] @ d[1])
    S1 = max(L, ma[1], mb[1])
    degenerate = not (math.sqrt(den) > tol * S1 and float(np.linalg.norm(e[1])) > tol * S1)
    if math.sqrt(den) > 0.0:
        k = float(e[1] @ d[1]) / den
        u2 = e[2] - k * k * d[2]
        beta2 = float(u2 @ d[1]) / den
        u3 = e[3] - k**3 * d[3] - 3.0 * k * beta2 * d[2]
        beta3 = float(u3 @ d[1]) / den
        g1 = rel(e[1] - k * d[1], max(mb[1], abs(k) * ma[1]))
        g2 = rel(u2 - beta2 * d[1], max(mb[2], k * k * ma[2], abs(beta2) * ma[1]))
        g3 = rel(
            u3 - beta3 * d[1],
            max(mb[3], abs(k) ** 3 * ma[3], 3.0 * abs(k * beta2) * ma[2], abs(beta3) * ma[1]),
        )
    else:
        k = beta2 = beta3 = float("nan")
        g1 = g2 = g3 = float("inf")
    g_res = (c_res[0], g1, g2, g3)
    if degenerate:  # the G parameters of a vanishing tangent are fits of rounding noise: undefined
        k = beta2 = beta3 = float("nan")
        notes.append("an end tangent vanishes: G1 and higher are undefined (g_order capped at c_order)")
    elif not k > 0:
        notes.append(f"tangents are antiparallel or orthogonal (k={k:.3g} <= 0): not G1")
    g_order = -1
    if g_res[0] <= tol:
        g_order = 0
        if not degenerate and k > 0:
            for r in (1, 2, 3):
                if g_res[r] <= tol:
                    g_order = r
                else:
                    break
    g_order = max(g_order, c_order)
    return JointReport(c_order, g_order, c_res, g_res, k, beta2, beta3, tol, tuple(notes))
