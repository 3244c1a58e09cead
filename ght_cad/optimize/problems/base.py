"""The problems' common ground: shape-parameter names, the GHT basis for a whole population of
parameter sets (:func:`population_basis`, :class:`CurveParameterJets`) and the :class:`Problem` base class
(named free parameters over a base parameter vector; spec sections 5, 7, 8)."""

from __future__ import annotations

from typing import Any, Mapping, Sequence

import numpy as np

from ...curves.basis import _compact_differences, basis_from_jets, bernstein, parameter_jets
from ...core.errors import GHTError
from ...curves.seeds import ght_seed_derivatives, ght_seed_jet, ght_seed_parameter_derivatives


SHAPE_NAMES = ("mu", "nu", "gamma")
FAIRNESS_MEASURES = ("AL", "En", "CVEn")


# --------------------------------------------------------------------------------------------
# vectorized GHT basis for many parameter sets
# --------------------------------------------------------------------------------------------
def ght_seed_jets(t: np.ndarray, mu: np.ndarray, nu: np.ndarray, gamma: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
    r"""GHT seed derivatives ``f0^(r)(t), f2^(r)(t)`` for P parameter sets at once.

    ``f0 = (1-w)(1-s)(1-μs) + w(1-t)²``, ``f2 = (1-w)(1-c)(1-νc) + w t²``, ``w = (1+γ)/2``,
    ``s = sin(πt/2)``, ``c = cos(πt/2)`` (spec section 1), differentiated analytically by
    :func:`ght_cad.curves.seeds.ght_seed_jet` (the same formula as :class:`ght_cad.curves.seeds.GHTSeed`).

    Args:
        t: nodes, shape (N,).
        mu, nu, gamma: shape parameters, shape (P,).
        order: derivative order 0..3.

    Returns:
        ``(f0, f2)`` each of shape (P, N).
    """
    return ght_seed_jet(np.asarray(t, dtype=float), *_columns(mu, nu, gamma), order)


def _columns(mu: Any, nu: Any, gamma: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shape parameters (P,) as columns (P, 1) that broadcast against nodes (N,)."""
    return tuple(np.asarray(x, dtype=float)[:, None] for x in (mu, nu, gamma))  # type: ignore[return-value]


def population_basis(
    t: np.ndarray, degree: int, mu: np.ndarray, nu: np.ndarray, gamma: np.ndarray, derivative: int = 0
) -> np.ndarray:
    r"""GHT basis ``b^{(r)}_{i,m}(t)`` for P parameter sets at once, shape (P, N, m+1).

    ``b^{(r)}_{i,m} = Σ_{s=0..r} C(r,s) Σ_{k=0..2} B^{(r-s)}_{i-k,n} f_k^{(s)}``, ``n = m-2``
    (spec section 2), equal to :func:`ght_cad.basis` row by row.
    """
    return PopulationBasis(t, degree)(mu, nu, gamma, (derivative,))[derivative]


class PopulationBasis:
    """Cached :func:`population_basis` on fixed nodes: Bernstein matrices are computed once,
    seed jets once per call and order.

    Args:
        t: nodes (N,).
        degree: basis degree m >= 2.
    """

    def __init__(self, t: Any, degree: int) -> None:
        self.t = np.asarray(t, dtype=float)
        self.degree = int(degree)
        n = self.degree - 2
        self._bern = [bernstein(self.t, n, q) for q in range(4)]

    def __call__(self, mu: Any, nu: Any, gamma: Any, orders: Sequence[int]) -> dict[int, np.ndarray]:
        """``{r: b^{(r)}}`` for the requested orders, each (P, N, m+1).

        One sin/cos pass for all orders (:func:`ght_cad.curves.seeds.ght_seed_derivatives`), combined
        with the cached Bernstein matrices by :func:`ght_cad.curves.basis.basis_from_jets`.
        """
        top = max(orders)
        jets = []
        for s, (f0, f2) in enumerate(ght_seed_derivatives(self.t, *_columns(mu, nu, gamma), top)):
            jets.append((f0[:, :, None], ((1.0 if s == 0 else 0.0) - f0 - f2)[:, :, None], f2[:, :, None]))
        return {r: basis_from_jets(self._bern, jets, r) for r in orders}

    def parameter_derivatives(self, mu: Any, nu: Any, gamma: Any, orders: Sequence[int]) -> dict[int, np.ndarray]:
        r"""``{r: ∂b^{(r)}/∂(μ, ν, γ)}`` for the requested orders, each (3, P, N, m+1) (spec 8.1).

        ``∂b^{(r)}_{i,m}/∂θ = Σ_s C(r,s) Σ_k B^{(r-s)}_{i-k,n} ∂f_k^{(s)}/∂θ`` with the closed-form
        seed derivatives (:func:`ght_cad.curves.basis.parameter_jets`).
        """
        pj = parameter_jets(self.t, *_columns(mu, nu, gamma), max(orders))
        return {r: np.stack([basis_from_jets(self._bern, jets, r) for jets in pj]) for r in orders}


class CurveParameterJets:
    r"""``∂X^(r)/∂(μ, ν, γ)`` of a GHT curve with a fixed control polygon, for P parameter sets.

    Compact form ``X = Q1 + f0 (Q0 - Q1) + f2 (Q2 - Q1)`` (``Q_k`` the degree-(m-2) Bézier curves
    on ``P_k..P_{k+m-2}``, fixed at the nodes), so by Leibniz' rule

    ``∂X^(r)/∂θ = Σ_s C(r,s) (∂f0^(s)/∂θ (Q0-Q1)^(r-s) + ∂f2^(s)/∂θ (Q2-Q1)^(r-s))``

    with the closed-form seed derivatives (:func:`ght_cad.curves.seeds.ght_seed_parameter_derivatives`;
    ``∂f0/∂ν = ∂f2/∂μ = 0``). Only broadcasting products per call: the Bézier parts are computed once.

    Args:
        t: nodes (N,).
        control_points: (m+1, dim), m >= 2.
        max_order: highest t-derivative order needed.
    """

    def __init__(self, t: Any, control_points: Any, max_order: int) -> None:
        self.t = np.asarray(t, dtype=float)
        P = np.asarray(control_points, dtype=float)
        self.K = int(max_order)
        n = P.shape[0] - 3
        zero = np.zeros((self.t.size, P.shape[1]))
        # Q[q] = ((Q0 - Q1)^(q), (Q2 - Q1)^(q)) at the nodes, each (N, dim)
        self.Q = [(zero, zero) if Dq is None else tuple(bernstein(self.t, n - q) @ Dq[k] for k in (0, 1))
                  for q, Dq in enumerate(_compact_differences(P, self.K))]

    def __call__(self, mu: Any, nu: Any, gamma: Any, orders: Sequence[int]) -> dict[int, np.ndarray]:
        """``{r: ∂X^(r)/∂(μ, ν, γ)}``, each (3, P, N, dim)."""
        from math import comb

        d = ght_seed_parameter_derivatives(self.t, *_columns(mu, nu, gamma), max(orders))
        out = {}
        for r in orders:
            acc = None
            for s_ in range(r + 1):
                d0mu, d0ga, d2nu, d2ga = (x[..., None] for x in d[s_])
                E0, E2 = self.Q[r - s_]
                c = comb(r, s_)
                term = np.stack([d0mu * E0, d2nu * E2, d0ga * E0 + d2ga * E2])
                if c != 1:
                    term *= c
                acc = term if acc is None else acc + term
            out[r] = acc
        return out


# --------------------------------------------------------------------------------------------
# base class: named free parameters over a base parameter vector
# --------------------------------------------------------------------------------------------
class Problem:
    """A vectorized objective over a chosen subset of named shape parameters.

    Subclasses define ``all_names`` / base values and implement :meth:`evaluate_full` on a
    full parameter matrix (pop, len(all_names)).

    Attributes:
        names: the free parameters (columns of X), e.g. ``("a.mu", "b.gamma")``.
        lb, ub: bounds of the free parameters (inside [-1, 1]).
        x0: base values of the free parameters (the unoptimized design).
        label: short name used in tables and plots.
    """

    label = "problem"

    def __init__(
        self,
        all_names: Sequence[str],
        base: Sequence[float],
        free: Sequence[str] | None,
        bounds: Mapping[str, tuple[float, float]] | None,
    ) -> None:
        self.all_names = tuple(all_names)
        self.base = np.asarray(base, dtype=float)
        if free is None:
            free = self.all_names
        if isinstance(free, str):
            free = (free,)
        free = tuple(free)
        if not free:
            raise GHTError(f"free is empty; choose at least one of {', '.join(self.all_names)}")
        for name in free:
            if name not in self.all_names:
                raise GHTError(f"free parameter {name!r} is unknown; allowed names: {', '.join(self.all_names)}")
        if len(set(free)) != len(free):
            raise GHTError(f"free={free!r} repeats a parameter name")
        self.names = free
        self._idx = np.array([self.all_names.index(n) for n in free], dtype=int)
        self._all_free = free == self.all_names
        lb = -np.ones(len(free))
        ub = np.ones(len(free))
        for name, (lo, hi) in (bounds or {}).items():
            if name not in free:
                raise GHTError(f"bounds given for {name!r}, which is not a free parameter ({', '.join(free)})")
            lo, hi = float(lo), float(hi)
            if not (-1.0 <= lo < hi <= 1.0):
                raise GHTError(
                    f"bounds for {name!r} = ({lo:g}, {hi:g}) are not allowed; need -1 <= low < high <= 1 "
                    "(shape parameters live in [-1, 1])"
                )
            j = free.index(name)
            lb[j], ub[j] = lo, hi
        self.lb, self.ub = lb, ub
        self.x0 = np.clip(self.base[self._idx], lb, ub)

    # -- parameters ------------------------------------------------------------------------
    @property
    def dim(self) -> int:
        """Number of free parameters."""
        return len(self.names)

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """``(lb, ub)`` of the free parameters."""
        return self.lb.copy(), self.ub.copy()

    def full(self, X: Any) -> np.ndarray:
        """Full parameter matrix (pop, len(all_names)) with the free columns from ``X``."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        if X.shape[1] != self.dim:
            raise GHTError(f"X has {X.shape[1]} columns; this problem has {self.dim} free parameters {self.names}")
        if self._all_free:  # every parameter free, in order: the rows themselves
            return X.copy()
        F = np.repeat(self.base[None, :], X.shape[0], axis=0)
        F[:, self._idx] = X
        return F

    def parameters(self, x: Any) -> dict[str, float]:
        """All named parameters for one free-parameter vector ``x``."""
        F = self.full(np.asarray(x, dtype=float).reshape(1, -1))[0]
        bad = [(n, v) for n, v in zip(self.all_names, F) if not -1.0 <= v <= 1.0]
        if bad:
            raise GHTError(f"parameter {bad[0][0]}={bad[0][1]:g} is outside [-1, 1]")
        return dict(zip(self.all_names, (float(v) for v in F)))

    # -- objective -------------------------------------------------------------------------
    def evaluate_full(self, F: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def __call__(self, X: Any) -> np.ndarray:
        """Objective values for a population ``X`` (pop, dim) of free parameters -> (pop,)."""
        return self.evaluate_full(self.full(X))

    def value(self, x: Any) -> float:
        """Objective at one free-parameter vector."""
        return float(self(np.asarray(x, dtype=float).reshape(1, -1))[0])

    #: True for problems with exact gradients (:meth:`value_and_grad`).
    has_gradient = True

    def value_and_grad_full(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # pragma: no cover - abstract
        """Values (pop,) and exact gradients (pop, len(all_names)) on full parameter rows."""
        raise NotImplementedError

    def value_and_grad(self, X: Any) -> tuple[np.ndarray, np.ndarray]:
        """Objective values (pop,) and exact gradients (pop, dim) for a population of free parameters.

        The values equal ``self(X)`` bit for bit; the gradient is the chain rule through the
        basis (spec 8.1: the seed is bilinear in (μ, w) and (ν, w)) and is 0 where the value is
        ``+inf``.
        """
        f, G = self.value_and_grad_full(self.full(X))
        G = G[:, self._idx]
        G[~np.isfinite(f)] = 0.0
        return f, G

    def gradient(self, X: Any) -> np.ndarray:
        """Exact gradients (pop, dim) of the objective (:meth:`value_and_grad`)."""
        return self.value_and_grad(X)[1]

    # -- result objects --------------------------------------------------------------------
    def build(self, x: Any) -> Any:  # pragma: no cover - abstract
        """The geometric object (curve or surface) for free parameters ``x``."""
        raise NotImplementedError

    def report(self, x: Any) -> dict[str, float]:
        """Measures of the design at ``x`` (for before/after tables)."""
        return {"objective": self.value(x)}


def _split(all_params: np.ndarray, start: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return all_params[:, start], all_params[:, start + 1], all_params[:, start + 2]

