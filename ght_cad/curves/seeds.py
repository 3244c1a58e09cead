r"""Degree-2 seeds of the GHT family (spec section 1).

A *seed* is a triple ``f0, f1, f2`` on [0, 1] with ``f0 + f1 + f2 = 1``, all ``>= 0``,
``f0(0) = f2(1) = 1``, ``f2(0) = f0(1) = 0`` and ``f2'(0) = f0'(1) = 0``. The degree-m basis is
built from the seed (section 2), so the seed is the only pluggable piece. Three seeds ship:

=========  ==========================================  ==========================================
seed       f0(t)                                       f2(t)
=========  ==========================================  ==========================================
Bernstein  (1-t)^2                                     t^2
GBT        (1-s)(1-μ s)                                (1-c)(1-ν c)
GHT        (1-w)(1-s)(1-μ s) + w (1-t)^2               (1-w)(1-c)(1-ν c) + w t^2
=========  ==========================================  ==========================================

with ``s = sin(πt/2)``, ``c = cos(πt/2)``, ``w = (1+γ)/2`` and always ``f1 = 1 - f0 - f2``.
The GHT row is this project's definition (see the spec's provenance note): γ = -1 gives GBT(μ, ν),
γ = 1 gives the Bernstein seed. All derivatives up to order 3 are analytic.

Users register further seeds with :func:`register_seed`; a seed class implements
:meth:`Seed.f0_f2` (values and derivatives of f0 and f2) and inherits everything else.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, Callable

import numpy as np

from ..core._validate import check_shape_parameter
from ..core.errors import GHTError

__all__ = [
    "Seed",
    "BernsteinSeed",
    "GBTSeed",
    "GHTSeed",
    "ReversedSeed",
    "register_seed",
    "make_seed",
    "seed_names",
    "MAX_DERIVATIVE",
    "ght_seed_jet",
    "ght_seed_derivatives",
    "ght_seed_parameter_derivatives",
]

#: Highest derivative order every seed provides analytically.
MAX_DERIVATIVE = 3

_HALF_PI = 0.5 * math.pi


class Seed(ABC):
    """A degree-2 seed ``(f0, f1, f2)`` with analytic derivatives up to order 3.

    Subclasses implement :meth:`f0_f2`; ``f1 = 1 - f0 - f2`` (so ``f1^(r) = -(f0^(r) + f2^(r))``
    for r >= 1) and all jets follow.

    Attributes:
        name: registry name of the seed family.
        mu, nu, gamma: shape parameters (``0.0`` for seeds that do not use them).
    """

    name: str = "seed"

    def __init__(self, mu: float = 0.0, nu: float = 0.0, gamma: float = 0.0) -> None:
        self.mu = check_shape_parameter("mu", mu)
        self.nu = check_shape_parameter("nu", nu)
        self.gamma = check_shape_parameter("gamma", gamma)

    # -- the one method a seed must provide -------------------------------------------------
    @abstractmethod
    def f0_f2(self, t: np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """Return ``(f0^(order)(t), f2^(order)(t))`` for a 1-D array ``t``, order 0..3."""

    # -- derived -----------------------------------------------------------------------------
    #: Highest derivative order :meth:`f0_f2` provides (custom seeds: 3; the GHT family: any).
    max_derivative: float = MAX_DERIVATIVE

    def jet(self, t: np.ndarray | float, order: int = 0) -> np.ndarray:
        """Values of ``(f0, f1, f2)^(order)`` at ``t`` as an array of shape (len(t), 3).

        ``f1 = 1 - f0 - f2``, hence ``f1^(r) = -(f0^(r) + f2^(r))`` for ``r >= 1``.
        """
        if not 0 <= int(order) <= MAX_DERIVATIVE:
            raise GHTError(f"derivative order {order} is not available; seeds provide orders 0..{MAX_DERIVATIVE}")
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        return _pack(*self.f0_f2(tt, int(order)), int(order), tt.size)

    def f0_f2_jets(self, t: np.ndarray | float, max_order: int) -> list[tuple[np.ndarray, np.ndarray]]:
        """``[f0_f2(t, 0), ..., f0_f2(t, max_order)]`` for a 1-D ``t``; subclasses share work between orders.

        Orders above 3 exist only for seeds whose :attr:`max_derivative` allows them (the GHT
        family, whose sin/cos and polynomial formulas hold for every order).

        Raises:
            GHTError: ``max_order`` outside ``0..max_derivative``.
        """
        K = _check_jet_order(self, max_order)
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        return [self.f0_f2(tt, r) for r in range(K + 1)]

    def jets(self, t: np.ndarray | float, max_order: int) -> list[np.ndarray]:
        """``[jet(t, 0), ..., jet(t, max_order)]``, each (len(t), 3), from :meth:`f0_f2_jets`.

        Raises:
            GHTError: ``max_order`` outside ``0..max_derivative``.
        """
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        return [_pack(f0, f2, r, tt.size) for r, (f0, f2) in enumerate(self.f0_f2_jets(tt, max_order))]

    def end_jets(self) -> tuple[np.ndarray, np.ndarray]:
        """End jets ``a[r, k] = f_k^(r)(0)`` and ``e[r, k] = f_k^(r)(1)`` for r = 0..3.

        Computed from the seed's own analytic derivatives (never finite differences).
        """
        a = np.empty((MAX_DERIVATIVE + 1, 3))
        e = np.empty((MAX_DERIVATIVE + 1, 3))
        ends = np.array([0.0, 1.0])
        for r in range(MAX_DERIVATIVE + 1):
            j = self.jet(ends, r)
            a[r], e[r] = j[0], j[1]
        return a, e

    def reversed(self) -> "Seed":
        """The seed of the reversed curve: ``f0~(t) = f2(1-t)``, ``f2~(t) = f0(1-t)``."""
        return ReversedSeed(self)

    def params(self) -> dict[str, float]:
        """Shape parameters as a dict (for reports and serialization)."""
        return {"mu": self.mu, "nu": self.nu, "gamma": self.gamma}

    def key(self) -> tuple:
        """Hashable identity: family name and parameters."""
        return (self.name, self.mu, self.nu, self.gamma)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Seed) and self.key() == other.key()

    def __hash__(self) -> int:
        return hash(self.key())

    def __repr__(self) -> str:
        return f"{type(self).__name__}(mu={self.mu:g}, nu={self.nu:g}, gamma={self.gamma:g})"


def _pack(f0: np.ndarray, f2: np.ndarray, order: int, size: int) -> np.ndarray:
    """``(f0, f1, f2)^(order)`` as a (size, 3) array, ``f1^(r) = δ_r0 - f0^(r) - f2^(r)``."""
    out = np.empty((size, 3))
    out[:, 0] = f0
    out[:, 2] = f2
    out[:, 1] = (1.0 if order == 0 else 0.0) - f0 - f2
    return out


def _check_jet_order(seed: "Seed", max_order: Any) -> int:
    try:
        K = int(max_order)
    except (TypeError, ValueError):
        raise GHTError(f"max_order={max_order!r} is not an integer") from None
    if K != max_order or not 0 <= K <= seed.max_derivative:
        top = seed.max_derivative
        allowed = "0, 1, 2, ..." if math.isinf(top) else f"0..{int(top)}"
        raise GHTError(f"derivative order {max_order!r} of the seed {seed!r} is not available; it provides orders {allowed}")
    return K


def _trig_values(t: np.ndarray, orders: range) -> tuple[np.ndarray | None, ...]:
    """``sin(πt/2), cos(πt/2)`` and those of ``sin(πt)`` (odd orders) and ``cos(πt)`` (even orders
    >= 2) that ``orders`` need, shared by all orders. ``cos(πt)`` is evaluated directly (not as
    ``cos² - sin²`` of the half angle) so that it is exactly ±1 at the ends, where the derivative
    terms must cancel exactly (e.g. f0''(1) = 0 at μ = 1)."""
    a = _HALF_PI * t
    pt = math.pi * t if orders.stop > 1 else None
    odd = any(r % 2 for r in orders)
    even = any(r and not r % 2 for r in orders)
    return np.sin(a), np.cos(a), np.sin(pt) if odd else None, np.cos(pt) if even else None


# r-th derivative of sin(x), cos(x) as (sign, use_cos) for r mod 4
_SIN_D = ((1.0, False), (1.0, True), (-1.0, False), (-1.0, True))
_COS_D = ((1.0, True), (-1.0, False), (-1.0, True), (1.0, False))


def _ght_from_trig(t: np.ndarray, mu: Any, nu: Any, gamma: Any, order: int, trig: tuple[Any, ...]) -> tuple[np.ndarray, np.ndarray]:
    """The GHT seed formula at one derivative order from precomputed :func:`_trig_values`."""
    w = 0.5 * (1.0 + gamma)
    sa, ca = trig[0], trig[1]
    if order == 0:
        # (1-x)(1-λx) = 1 - (1+λ)x + λx^2
        g0 = 1.0 - (1.0 + mu) * sa + mu * (sa * sa)
        g2 = 1.0 - (1.0 + nu) * ca + nu * (ca * ca)
        return (1.0 - w) * g0 + w * (1.0 - t) ** 2, (1.0 - w) * g2 + w * (t * t)
    # f0^(r) = (1-w)(-(1+μ) s^(r) + μ (s²)^(r)) + w p0^(r), f2^(r) likewise with c, ν; with
    # s^(r) = (π/2)^r sin^(r)(πt/2), c^(r) = (π/2)^r cos^(r)(πt/2), (s²)^(r) = -(c²)^(r) = -π^r cos^(r)(πt)/2
    v = 1.0 - w
    hr, pr = _HALF_PI**order, math.pi**order
    sg_s, cos_s = _SIN_D[order % 4]
    sg_c, cos_c = _COS_D[order % 4]
    x_s = ca if cos_s else sa
    x_c = ca if cos_c else sa
    x_d = trig[3] if cos_c else trig[2]
    half_d = 0.5 * pr * sg_c  # (c²)^(r) = half_d * x_d
    f0 = (-(v * (1.0 + mu)) * (hr * sg_s)) * x_s - (v * mu * half_d) * x_d
    f2 = (-(v * (1.0 + nu)) * (hr * sg_c)) * x_c + (v * nu * half_d) * x_d
    # polynomial part w p^(r): p0 = (1-t)², p2 = t²
    if order == 1:
        wt = (2.0 * w) * t
        f0 = f0 + (wt - 2.0 * w)
        f2 = f2 + wt
    elif order == 2:
        f0 = f0 + 2.0 * w
        f2 = f2 + 2.0 * w
    return f0, f2


def ght_seed_jet(t: np.ndarray, mu: Any, nu: Any, gamma: Any, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
    r"""GHT seed derivatives ``(f0^(r)(t), f2^(r)(t))``, broadcasting ``mu, nu, gamma`` against ``t``.

    ``f0 = (1-w)(1-s)(1-μs) + w(1-t)²``, ``f2 = (1-w)(1-c)(1-νc) + w t²``, ``w = (1+γ)/2``,
    ``s = sin(πt/2)``, ``c = cos(πt/2)``; for ``r >= 1`` with ``s^(r) = (π/2)^r sin(πt/2 + rπ/2)``,
    ``c^(r) = (π/2)^r cos(πt/2 + rπ/2)`` and ``(s²)^(r) = -(c²)^(r) = -π^r cos(πt + rπ/2) / 2``.
    The formulas hold for every order r >= 0. This is the one implementation of the GHT seed:
    :meth:`GHTSeed.f0_f2` and the population-vectorized optimizer problems call it.

    Args:
        t: parameters, 1-D array (N,).
        mu, nu, gamma: shape parameters, scalars or arrays broadcasting against ``t`` (e.g. shape
            (P, 1) for P parameter sets: the result is then (P, N)).
        order: derivative order r >= 0.

    Returns:
        ``(f0^(r), f2^(r))``, each of the broadcast shape of ``t`` and the parameters.
    """
    t = np.asarray(t, dtype=float)
    order = int(order)
    return _ght_from_trig(t, mu, nu, gamma, order, _trig_values(t, range(order, order + 1)))


def ght_seed_derivatives(t: np.ndarray, mu: Any, nu: Any, gamma: Any, max_order: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``[ght_seed_jet(t, mu, nu, gamma, r) for r = 0..max_order]`` sharing one sin/cos pass.

    Args:
        t: parameters, 1-D array (N,).
        mu, nu, gamma: shape parameters, scalars or arrays broadcasting against ``t``.
        max_order: highest derivative order K >= 0.

    Returns:
        K+1 pairs ``(f0^(r), f2^(r))``: exactly the arrays of :func:`ght_seed_jet` (same
        formulas, same operations).
    """
    t = np.asarray(t, dtype=float)
    K = int(max_order)
    trig = _trig_values(t, range(K + 1))
    return [_ght_from_trig(t, mu, nu, gamma, r, trig) for r in range(K + 1)]


def ght_seed_parameter_derivatives(
    t: np.ndarray, mu: Any, nu: Any, gamma: Any, max_order: int
) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    r"""Exact derivatives of the GHT seed jets with respect to the shape parameters (spec 8.1).

    ``f0`` is bilinear in ``(μ, w)`` and ``f2`` in ``(ν, w)``, ``w = (1+γ)/2``, so for every
    t-derivative order r:

    * ``∂f0^(r)/∂μ = (1-w) (-s^(r) + (s²)^(r))``  (from ``(1-s)(1-μs) = 1 - (1+μ)s + μs²``),
    * ``∂f2^(r)/∂ν = (1-w) (-c^(r) + (c²)^(r))``,
    * ``∂f0^(r)/∂γ = (p0^(r) - g0^(r)) / 2``, ``∂f2^(r)/∂γ = (p2^(r) - g2^(r)) / 2`` with
      ``g0 = (1-s)(1-μs)``, ``g2 = (1-c)(1-νc)`` (the GBT seed), ``p0 = (1-t)²``, ``p2 = t²``,

    and ``∂f0/∂ν = ∂f2/∂μ = 0``; ``f1 = 1 - f0 - f2`` gives ``∂f1 = -∂f0 - ∂f2``. The sin/cos
    derivatives are those of :func:`ght_seed_jet` (one shared pass).

    Args:
        t: parameters, 1-D array (N,).
        mu, nu, gamma: shape parameters, scalars or arrays broadcasting against ``t``.
        max_order: highest t-derivative order K >= 0.

    Returns:
        K+1 tuples ``(∂f0^(r)/∂μ, ∂f0^(r)/∂γ, ∂f2^(r)/∂ν, ∂f2^(r)/∂γ)``, each of the broadcast
        shape of ``t`` and the parameters.
    """
    t = np.asarray(t, dtype=float)
    K = int(max_order)
    trig = _trig_values(t, range(K + 1))
    sa, ca = trig[0], trig[1]
    v = 1.0 - 0.5 * (1.0 + np.asarray(gamma, dtype=float))
    zero = np.zeros(np.broadcast_shapes(t.shape, np.shape(mu), np.shape(nu), np.shape(gamma)))
    out = []
    for r in range(K + 1):
        g0, g2 = _ght_from_trig(t, mu, nu, -1.0, r, trig)  # w = 0: the GBT part
        if r == 0:
            dmu = sa * sa - sa
            dnu = ca * ca - ca
            p0, p2 = (1.0 - t) ** 2, t * t
        else:
            hr, pr = _HALF_PI**r, math.pi**r
            sg_s, cos_s = _SIN_D[r % 4]
            sg_c, cos_c = _COS_D[r % 4]
            x_s = ca if cos_s else sa
            x_c = ca if cos_c else sa
            x_d = trig[3] if cos_c else trig[2]
            half_d = 0.5 * pr * sg_c  # (c²)^(r) = -(s²)^(r) = half_d * x_d
            dmu = -(hr * sg_s) * x_s - half_d * x_d
            dnu = -(hr * sg_c) * x_c + half_d * x_d
            p0 = {1: 2.0 * t - 2.0, 2: np.full_like(t, 2.0)}.get(r, np.zeros_like(t))
            p2 = {1: 2.0 * t, 2: np.full_like(t, 2.0)}.get(r, np.zeros_like(t))
        out.append((zero + v * dmu, zero + 0.5 * (p0 - g0), zero + v * dnu, zero + 0.5 * (p2 - g2)))
    return out


class GHTSeed(Seed):
    r"""The generalized hybrid trigonometric seed (this project's GHT definition).

    ``f0 = (1-w)(1-s)(1-μs) + w(1-t)^2``, ``f2 = (1-w)(1-c)(1-νc) + w t^2``, ``w = (1+γ)/2``,
    ``s = sin(πt/2)``, ``c = cos(πt/2)``.
    """

    name = "ght"

    @property
    def w(self) -> float:
        """Blend weight ``w = (1+γ)/2`` between the GBT (w=0) and Bernstein (w=1) seeds."""
        return 0.5 * (1.0 + self.gamma)

    max_derivative = math.inf

    def f0_f2(self, t: np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        return ght_seed_jet(t, self.mu, self.nu, self.gamma, order)

    def f0_f2_jets(self, t: np.ndarray | float, max_order: int) -> list[tuple[np.ndarray, np.ndarray]]:
        """All orders ``0..max_order`` (any order) from one sin/cos pass (:func:`ght_seed_derivatives`)."""
        K = _check_jet_order(self, max_order)
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        return ght_seed_derivatives(tt, self.mu, self.nu, self.gamma, K)

    def reversed(self) -> "Seed":
        """Symmetry ``f2(t; μ,ν,γ) = f0(1-t; ν,μ,γ)``: the reversed seed swaps μ and ν."""
        return type(self)(mu=self.nu, nu=self.mu, gamma=self.gamma)


class GBTSeed(GHTSeed):
    """The generalized blended trigonometric seed ``f0 = (1-s)(1-μs)``, ``f2 = (1-c)(1-νc)``.

    Identical to :class:`GHTSeed` at γ = -1; ``gamma`` is accepted only as -1 (or omitted).
    """

    name = "gbt"

    def __init__(self, mu: float = 0.0, nu: float = 0.0, gamma: float = -1.0) -> None:
        super().__init__(mu, nu, -1.0)
        if float(gamma) != -1.0:
            raise GHTError(f"gamma={gamma!r} is not used by the GBT seed (it is GHT at gamma = -1)")

    def __repr__(self) -> str:
        return f"GBTSeed(mu={self.mu:g}, nu={self.nu:g})"


class BernsteinSeed(GHTSeed):
    """The classical quadratic Bernstein seed ``((1-t)^2, 2t(1-t), t^2)`` (GHT at γ = 1)."""

    name = "bernstein"

    def __init__(self, mu: float = 0.0, nu: float = 0.0, gamma: float = 1.0) -> None:
        check_shape_parameter("mu", mu)
        check_shape_parameter("nu", nu)
        super().__init__(0.0, 0.0, 1.0)

    def f0_f2(self, t: np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        if order == 0:
            return (1.0 - t) ** 2, t * t
        if order == 1:
            return -2.0 * (1.0 - t), 2.0 * t
        if order == 2:
            return np.full_like(t, 2.0), np.full_like(t, 2.0)
        return np.zeros_like(t), np.zeros_like(t)

    f0_f2_jets = Seed.f0_f2_jets  # its own polynomial f0_f2 (every order), not the GHT formula at gamma = 1

    def reversed(self) -> "Seed":
        return BernsteinSeed()

    def __repr__(self) -> str:
        return "BernsteinSeed()"


class ReversedSeed(Seed):
    """Generic reversal of any seed: ``f0~(t) = f2(1-t)``, ``f2~(t) = f0(1-t)``."""

    def __init__(self, base: Seed) -> None:
        self.base = base
        self.mu, self.nu, self.gamma = base.nu, base.mu, base.gamma
        self.name = f"reversed-{base.name}"

    @property
    def max_derivative(self) -> float:  # type: ignore[override]
        """Orders available: those of the base seed."""
        return self.base.max_derivative

    def f0_f2(self, t: np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        f0, f2 = self.base.f0_f2(1.0 - t, order)
        sign = -1.0 if order % 2 else 1.0
        return sign * f2, sign * f0

    def reversed(self) -> Seed:
        return self.base

    def key(self) -> tuple:
        return ("reversed",) + self.base.key()


_REGISTRY: dict[str, Callable[..., Seed]] = {}


def register_seed(name: str, factory: Callable[..., Seed]) -> None:
    """Register a seed family under ``name``.

    Args:
        name: registry key (case-insensitive), e.g. ``"my-variant"``.
        factory: callable ``factory(mu=, nu=, gamma=) -> Seed``, typically a :class:`Seed` subclass.
    """
    if not callable(factory):
        raise GHTError(f"seed factory for {name!r} must be callable, got {factory!r}")
    _REGISTRY[name.lower()] = factory


def seed_names() -> list[str]:
    """Names of all registered seed families."""
    return sorted(_REGISTRY)


#: the values a built-in family fixes (a parameter it does not use may be given only as this value)
_FIXED = {"gbt": {"gamma": -1.0}, "bernstein": {"mu": 0.0, "nu": 0.0, "gamma": 1.0}}


def make_seed(seed: str | Seed = "ght", mu: float | None = None, nu: float | None = None,
              gamma: float | None = None) -> Seed:
    """Return a :class:`Seed`: ``seed`` itself if it is one, else the registered family's instance.

    A parameter left as None takes the family's default (0 for the GHT family, the fixed value
    for GBT's γ = -1 and Bernstein's μ = ν = 0, γ = 1). A parameter the seed does not use is
    refused rather than ignored: ``make_seed("gbt", gamma=0.5)`` (GBT is GHT at γ = -1),
    ``make_seed("bernstein", mu=0.3)``, or a value given beside a :class:`Seed` instance that
    differs from the instance's own.

    Raises:
        GHTError: unknown family name, a parameter the seed does not use, or (from the family)
            a shape parameter outside [-1, 1].
    """
    given = {k: v for k, v in (("mu", mu), ("nu", nu), ("gamma", gamma)) if v is not None}
    if isinstance(seed, Seed):
        for k, v in given.items():
            own = getattr(seed, k, None)
            if own is None or not _same(v, own):
                raise GHTError(f"{k}={v!r} is given beside the seed object {seed!r}, which has {k}={own!r}; "
                               f"allowed: the seed's own value, or a seed name (e.g. seed='ght') with {k}")
        return seed
    key = str(seed).lower()
    if key not in _REGISTRY:
        raise GHTError(f"seed={seed!r} is not registered; known seeds: {', '.join(seed_names())}")
    fixed = _FIXED.get(key)
    if fixed is None:  # the GHT family or a registered one: every parameter is passed on
        return _REGISTRY[key](**{"mu": 0.0, "nu": 0.0, "gamma": 0.0, **given})
    for k, v in given.items():
        if k in fixed and not _same(v, fixed[k]):
            raise GHTError(f"{k}={v!r} is not used by the {key!r} seed (it is the GHT seed at "
                           + ", ".join(f"{n}={x:g}" for n, x in fixed.items())
                           + f"); allowed: leave {k} out, or seed='ght' to use {k}")
    return _REGISTRY[key](**{k: v for k, v in given.items() if k not in fixed})


def _same(a: Any, b: Any) -> bool:
    try:
        return float(a) == float(b)
    except (TypeError, ValueError):
        return False


register_seed("ght", GHTSeed)
register_seed("gbt", GBTSeed)
register_seed("bernstein", BernsteinSeed)
