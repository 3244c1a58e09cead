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
from typing import Callable

import numpy as np

from ._validate import check_shape_parameter
from .errors import GHTError

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
    def jet(self, t: np.ndarray | float, order: int = 0) -> np.ndarray:
        """Values of ``(f0, f1, f2)^(order)`` at ``t`` as an array of shape (len(t), 3).

        ``f1 = 1 - f0 - f2``, hence ``f1^(r) = -(f0^(r) + f2^(r))`` for ``r >= 1``.
        """
        if not 0 <= int(order) <= MAX_DERIVATIVE:
            raise GHTError(f"derivative order {order} is not available; seeds provide orders 0..{MAX_DERIVATIVE}")
        tt = np.atleast_1d(np.asarray(t, dtype=float))
        f0, f2 = self.f0_f2(tt, int(order))
        out = np.empty((tt.size, 3))
        out[:, 0] = f0
        out[:, 2] = f2
        out[:, 1] = (1.0 if order == 0 else 0.0) - f0 - f2
        return out

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


def _trig_parts(t: np.ndarray, order: int, *, ccw: bool) -> tuple[np.ndarray, np.ndarray]:
    """Derivative of order ``order`` of ``(x, x^2)`` where x = sin(πt/2) (ccw) or cos(πt/2).

    Uses ``sin^2(πt/2) = (1 - cos πt)/2`` and ``cos^2(πt/2) = (1 + cos πt)/2``.
    """
    h = _HALF_PI
    a = h * t
    if order == 0:
        x = np.sin(a) if ccw else np.cos(a)
        return x, x * x
    # r-th derivative of sin(h t) is h^r sin(h t + r π/2); of cos likewise with cos.
    x = h**order * (np.sin(a + order * h) if ccw else np.cos(a + order * h))
    # r-th derivative of cos(πt) is π^r cos(πt + r π/2)
    dcos = math.pi**order * np.cos(math.pi * t + order * h)
    x2 = -0.5 * dcos if ccw else 0.5 * dcos
    return x, x2


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

    def f0_f2(self, t: np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        w = self.w
        mu, nu = self.mu, self.nu
        s, s2 = _trig_parts(t, order, ccw=True)
        c, c2 = _trig_parts(t, order, ccw=False)
        # (1-x)(1-λx) = 1 - (1+λ)x + λx^2
        const = 1.0 if order == 0 else 0.0
        g0 = const - (1.0 + mu) * s + mu * s2
        g2 = const - (1.0 + nu) * c + nu * c2
        if order == 0:
            p0, p2 = (1.0 - t) ** 2, t * t
        elif order == 1:
            p0, p2 = -2.0 * (1.0 - t), 2.0 * t
        elif order == 2:
            p0 = p2 = np.full_like(t, 2.0)
        else:
            p0 = p2 = np.zeros_like(t)
        return (1.0 - w) * g0 + w * p0, (1.0 - w) * g2 + w * p2

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


def make_seed(seed: str | Seed = "ght", mu: float = 0.0, nu: float = 0.0, gamma: float = 0.0) -> Seed:
    """Return a :class:`Seed`: ``seed`` itself if it is one, else the registered family's instance."""
    if isinstance(seed, Seed):
        return seed
    key = str(seed).lower()
    if key not in _REGISTRY:
        raise GHTError(f"seed={seed!r} is not registered; known seeds: {', '.join(seed_names())}")
    if key == "gbt":
        return _REGISTRY[key](mu=mu, nu=nu)
    if key == "bernstein":
        return _REGISTRY[key](mu=mu, nu=nu)
    return _REGISTRY[key](mu=mu, nu=nu, gamma=gamma)


register_seed("ght", GHTSeed)
register_seed("gbt", GBTSeed)
register_seed("bernstein", BernsteinSeed)
