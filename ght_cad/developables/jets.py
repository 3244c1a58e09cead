"""Jets (a value and its derivatives) of products, powers and unit vectors, curve derivatives and
small argument checks shared by the developables.

Moved from :mod:`ght_cad.developables.envelope` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from math import comb
from typing import Any, Callable

import numpy as np

from ..core._validate import as_parameter_array, check_unit_interval
from ..curves.basis import _check_order, evaluate_derivatives
from ..curves.curve import GHTCurve
from ..core.errors import GHTError


_Jet = list  # list of arrays: value and derivatives 0..K
_JET_CACHE_SIZE = 8  # dual-curve jets kept per EnvelopeDevelopable
_JET_CACHE_MAX = 4096  # largest parameter array whose jet is kept
_ZERO = np.array([0.0])
_ONE = np.array([1.0])


# ----------------------------------------------------------------------------------------------
# jets: values + derivatives propagated by Leibniz' rule
# ----------------------------------------------------------------------------------------------
def _jprod(f: Callable[[np.ndarray, np.ndarray], np.ndarray], A: _Jet, B: _Jet) -> _Jet:
    """``(f(A, B))^(r) = Σ_s C(r, s) f(A^(s), B^(r-s))`` for a bilinear ``f``."""
    K = min(len(A), len(B)) - 1
    return [sum(comb(r, s) * f(A[s], B[r - s]) for s in range(r + 1)) for r in range(K + 1)]


def _mul(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return x * y


def _dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.sum(x * y, axis=-1, keepdims=True)


def _cross(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    return np.cross(x, y)


def _jpow(N: _Jet, p: float) -> _Jet:
    """Jet of ``N^p`` (Faà di Bruno up to order 3)."""
    n0 = N[0]
    out = [n0**p]
    if len(N) > 1:
        out.append(p * n0 ** (p - 1) * N[1])
    if len(N) > 2:
        out.append(p * (p - 1) * n0 ** (p - 2) * N[1] ** 2 + p * n0 ** (p - 1) * N[2])
    if len(N) > 3:
        out.append(
            p * (p - 1) * (p - 2) * n0 ** (p - 3) * N[1] ** 3
            + 3 * p * (p - 1) * n0 ** (p - 2) * N[1] * N[2]
            + p * n0 ** (p - 1) * N[3]
        )
    return out


def _junit(F: _Jet) -> _Jet:
    """Jet of ``F / |F|``."""
    return _jprod(_mul, F, _jpow(_jprod(_dot, F, F), -0.5))


def _jcartesian(X: _Jet) -> _Jet:
    """Jet of ``(X1, X2, X3) / X0`` from a homogeneous jet."""
    w = [x[:, :1] for x in X]
    Y = [x[:, 1:] for x in X]
    with np.errstate(divide="ignore", invalid="ignore"):
        return _jprod(_mul, Y, _jpow(w, -1.0))


def _check_derivative(derivative: Any, max_order: int = 2) -> int:
    """Derivative order in ``0..max_order`` (surfaces here give analytic orders 0..2)."""
    return _check_order(derivative, max_order)


def curve_derivatives(curve: GHTCurve, t: Any, max_order: int) -> list[np.ndarray]:
    r"""``[C(t), C'(t), ..., C^(max_order)(t)]`` analytically, also beyond order 3.

    ``C^(r) = Σ_i b^{(r)}_{i,m} P_i`` with ``b^{(r)}_{i,m} = Σ_s C(r,s) Σ_k B^{(r-s)}_{i-k,n} f_k^{(s)}``;
    seed derivatives of order > 3 come from the GHT seed formulas (sin/cos and polynomials), which
    hold for every order. All orders share one seed evaluation and one Bernstein matrix per order
    (:func:`ght_cad.curves.basis.evaluate_derivatives`).

    Args:
        curve: a GHT curve (GHT/GBT/Bernstein seed, possibly reversed, for orders > 3).
        t: parameters in [0, 1].
        max_order: highest order (0..6).

    Raises:
        GHTError: a custom seed and ``max_order > 3``; t outside [0, 1].
    """
    tt, _ = as_parameter_array(t)
    check_unit_interval("t", tt, slack=1e-9)
    seed = curve.seed
    if max_order > seed.max_derivative:
        raise GHTError(
            f"derivative order {int(seed.max_derivative) + 1} of the seed {seed!r} is needed here but custom "
            f"seeds only guarantee orders 0..{int(seed.max_derivative)}; use the GHT/GBT/Bernstein seeds"
        )
    return evaluate_derivatives(tt, curve.control_points, seed, max_order)


def _fmt(v: Any) -> str:
    return np.array2string(np.asarray(v, dtype=float), precision=6, separator=", ")


def _check_range(t_range: Any) -> tuple[float, float]:
    try:
        t0, t1 = (float(x) for x in t_range)
    except (TypeError, ValueError):
        raise GHTError(f"t_range={t_range!r} must be a pair (t0, t1) with 0 <= t0 < t1 <= 1") from None
    if not (math.isfinite(t0) and math.isfinite(t1) and 0.0 <= t0 < t1 <= 1.0):
        raise GHTError(f"t_range=({t0:g}, {t1:g}) is not allowed; it must satisfy 0 <= t0 < t1 <= 1")
    return t0, t1


def _sign_change_roots(f: Callable[[np.ndarray], np.ndarray], u: np.ndarray, vals: np.ndarray) -> list[float]:
    """Parameters where the sampled scalar ``vals = f(u)`` changes sign, refined by bisection."""
    from scipy.optimize import brentq

    roots = []
    s = np.sign(vals)
    for i in np.nonzero(s[:-1] * s[1:] < 0)[0]:
        try:
            roots.append(float(brentq(lambda x: float(f(np.array([x]))[0]), u[i], u[i + 1], xtol=1e-14)))
        except ValueError:
            roots.append(float(0.5 * (u[i] + u[i + 1])))
    roots.extend(float(x) for x in u[vals == 0.0])
    return sorted(roots)
