r"""GHT-Bézier curves (spec section 3).

``P(t) = Σ_{i=0..m} b_{i,m}(t; μ, ν, γ) P_i`` for control points of any dimension (2-D, 3-D, 4-D
plane coordinates, ...). Compact form: ``P(t) = f0 Q0(t) + f1 Q1(t) + f2 Q2(t)`` where ``Q_k`` is
the classical Bézier curve of degree ``n = m-2`` on ``P_k .. P_{k+n}``.
"""

from __future__ import annotations

from functools import cached_property
from math import comb
from typing import Any, Iterable

import numpy as np

from ..core._validate import affine_parts, as_parameter_array, check_points, check_unit_interval
from .basis import MAX_DIRECT_DEGREE, _check_order, bernstein, bernstein_log, seed_basis
from ..core._quadrature import gauss_legendre  # noqa: F401  (public here: ght_cad.curves.curve.gauss_legendre)
from ..core._quadrature import leggauss as _leggauss
from ..core.errors import DegenerateGeometryError, GHTError
from .seeds import Seed, make_seed

__all__ = ["GHTCurve", "gauss_legendre", "integrate"]

_CHUNK = 1 << 15
#: evaluations of at most this many parameters are remembered per curve (:meth:`GHTCurve._memo`)
_MEMO_POINTS = 512
#: a curve's memo is emptied when its arrays exceed this many bytes
_MEMO_BYTES = 8 << 20


def integrate(
    f: Any,
    a: float = 0.0,
    b: float = 1.0,
    *,
    nodes: int = 16,
    rtol: float = 1e-13,
    max_panels: int = 4096,
) -> float:
    r"""Composite Gauss–Legendre quadrature ``∫_a^b f(t) dt`` with panel doubling.

    ``f`` takes a 1-D array and returns a 1-D array. Panels double until two successive results
    agree to ``rtol`` (relative) or ``max_panels`` is reached.
    """
    x, w = _leggauss(nodes)
    prev = None
    panels = 4
    while True:
        edges = np.linspace(a, b, panels + 1)
        h = 0.5 * np.diff(edges)
        t = (edges[:-1, None] + h[:, None] * (x[None, :] + 1.0)).ravel()
        val = float(np.sum(np.asarray(f(t)).reshape(panels, nodes) * (h[:, None] * w[None, :])))
        if prev is not None and abs(val - prev) <= rtol * max(abs(val), 1e-300):
            return val
        if panels >= max_panels:
            return val
        prev = val
        panels *= 2


def curvature_from_derivatives(d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    r"""Curvature ``κ = |X'' - (X'·X''/|X'|²) X'| / |X'|²`` (``= |X' × X''| / |X'|³``) from the
    first and second derivatives (arrays (..., dim)); inf/NaN where ``X' = 0``.

    The normal part of ``X''`` keeps a straight line's curvature at round-off level (~1e-16
    ``|X''|/|X'|²``); the Gram form ``sqrt(|X'|²|X''|² - (X'·X'')²)`` loses half the digits there.
    """
    d1 = np.asarray(d1, dtype=float)
    d2 = np.asarray(d2, dtype=float)
    a = np.sum(d1 * d1, axis=-1)
    c = np.sum(d1 * d2, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        normal = d2 - (c / a)[..., None] * d1
        return np.linalg.norm(normal, axis=-1) / a


class GHTCurve:
    r"""A GHT-Bézier curve ``P(t) = Σ b_{i,m}(t; μ,ν,γ) P_i``, t ∈ [0, 1].

    Args:
        control_points: array-like of shape (degree+1, dim), degree >= 2, any dim >= 1.
        mu, nu, gamma: shape parameters in [-1, 1] (γ = 1: classical Bézier, γ = -1: GBT); None
            (the default) is the seed family's default (0 for GHT).
        seed: seed family name or a :class:`~ght_cad.curves.seeds.Seed` instance (then mu, nu, gamma
            come from the seed). A parameter the seed does not use (``gamma`` with ``"gbt"``,
            ``mu`` with ``"bernstein"``) is refused, not ignored (:func:`~ght_cad.curves.seeds.make_seed`).

    Raises:
        GHTError: fewer than 3 control points, wrong array shape, NaN/inf coordinates, or a
            shape parameter outside [-1, 1].

    Example:
        >>> quarter = GHTCurve([(1, 0), (1, 1), (0, 1)], gamma=-1)   # exact quarter circle
        >>> bool(abs(np.linalg.norm(quarter.evaluate(0.3)) - 1) < 1e-15)
        True
    """

    def __init__(
        self,
        control_points: Any,
        mu: float | None = None,
        nu: float | None = None,
        gamma: float | None = None,
        *,
        seed: str | Seed = "ght",
    ) -> None:
        pts = check_points("control_points", control_points, min_count=3)
        if pts.shape[0] < 3:
            raise GHTError(f"control_points has {pts.shape[0]} points: degree {pts.shape[0]-1} < 2")
        self._points = pts
        self._points.setflags(write=False)
        self._seed = make_seed(seed, mu, nu, gamma)

    def __getstate__(self) -> dict[str, Any]:
        """Pickled without the evaluation memo (:meth:`_memo`)."""
        state = dict(self.__dict__)
        state.pop("_memo_cache", None)
        return state

    def _memo(self, key: tuple[Any, ...], tt: np.ndarray, compute: Any) -> Any:
        """``compute()`` (an array or a list of arrays at the parameters ``tt``), remembered by
        ``key`` (the kind, the order and ``tt``'s bytes): the loft tracer, the sheet's ruling normals
        and the flat pattern ask a rail for the same parameters again and again (measured on the
        skiff design: 10,587 evaluations, 2,095 distinct; the run's CPU time 6.4 s -> 3.5 s). The
        curve is immutable (control points read-only, the seed fixed), so a remembered value is the
        one a new evaluation would give, bit for bit; callers get copies. At most
        :data:`_MEMO_POINTS` parameters per call and :data:`_MEMO_BYTES` per curve."""
        if tt.size > _MEMO_POINTS:
            return compute()
        cache = self.__dict__.get("_memo_cache")
        if cache is None:
            cache = self.__dict__["_memo_cache"] = {"bytes": 0, "values": {}}
        key = key + (tt.shape, tt.tobytes())
        hit = cache["values"].get(key)
        if hit is None:
            hit = compute()
            size = sum(a.nbytes for a in hit) if isinstance(hit, list) else hit.nbytes
            if cache["bytes"] + size > _MEMO_BYTES:
                cache["values"].clear()
                cache["bytes"] = 0
            cache["values"][key] = hit
            cache["bytes"] += size
        return [a.copy() for a in hit] if isinstance(hit, list) else hit.copy()

    # -- basic attributes ----------------------------------------------------------------
    @property
    def control_points(self) -> np.ndarray:
        """Control points ``P_0..P_m`` as a read-only (m+1, dim) array."""
        return self._points

    @property
    def degree(self) -> int:
        """Degree m (number of control points minus one)."""
        return self._points.shape[0] - 1

    @property
    def dim(self) -> int:
        """Dimension of the control points."""
        return self._points.shape[1]

    @property
    def seed(self) -> Seed:
        """The degree-2 seed that defines the basis."""
        return self._seed

    @property
    def mu(self) -> float:
        """Shape parameter μ ∈ [-1, 1], in the seed's f0 (shapes the start of the curve)."""
        return self._seed.mu

    @property
    def nu(self) -> float:
        """Shape parameter ν ∈ [-1, 1], in the seed's f2 (shapes the end of the curve)."""
        return self._seed.nu

    @property
    def gamma(self) -> float:
        """Shape parameter γ ∈ [-1, 1] (γ = 1 classical Bézier, γ = -1 GBT)."""
        return self._seed.gamma

    @property
    def shape_parameters(self) -> tuple[float, float, float]:
        """``(mu, nu, gamma)``."""
        return (self.mu, self.nu, self.gamma)

    def __repr__(self) -> str:
        return (
            f"GHTCurve(degree={self.degree}, dim={self.dim}, mu={self.mu:g}, nu={self.nu:g}, "
            f"gamma={self.gamma:g}, seed={self._seed.name!r})"
        )

    # -- evaluation ----------------------------------------------------------------------
    def basis(self, t: Any, derivative: int = 0) -> np.ndarray:
        """Basis matrix ``b^{(r)}_{i,m}(t)`` of this curve, shape (len(t), m+1)."""
        tt, _ = as_parameter_array(t)
        return seed_basis(tt, self.degree, self._seed, _check_order(derivative))

    def _eval(self, t: Any, order: int) -> np.ndarray:
        tt, scalar = as_parameter_array(t)
        out = self._memo(("eval", order), tt, lambda: self._eval_at(tt, order))
        return out[0] if scalar else out

    def _eval_at(self, tt: np.ndarray, order: int) -> np.ndarray:
        """``P^(order)`` at the 1-D parameters ``tt`` (checked in [0, 1] here)."""
        check_unit_interval("t", tt, slack=1e-9)
        if order == 0:
            return self._evaluate_points(tt)
        P = self._points
        if tt.size <= _CHUNK:
            return seed_basis(tt, self.degree, self._seed, order) @ P
        out = np.empty((tt.size, self.dim))
        for lo in range(0, tt.size, _CHUNK):
            sl = slice(lo, lo + _CHUNK)
            out[sl] = seed_basis(tt[sl], self.degree, self._seed, order) @ P
        return out

    @cached_property
    def _compact_weights(self) -> np.ndarray:
        """Stacked, binomial-scaled control points of the compact form (3(n+1), dim)."""
        n = self.degree - 2
        if n > MAX_DIRECT_DEGREE:  # the log-space Bernstein values carry C(n, j) themselves
            return np.vstack([self._points[k : k + n + 1] for k in range(3)])
        binom = np.array([comb(n, j) for j in range(n + 1)], dtype=float)[:, None]
        return np.vstack([self._points[k : k + n + 1] * binom for k in range(3)])

    def _evaluate_points(self, t: np.ndarray, chunk: int = 8192) -> np.ndarray:
        r"""Fast evaluation by the compact form ``P = f0 Q0 + f1 Q1 + f2 Q2``.

        Per chunk: one seed evaluation (one sin/cos pass), the degree-n Bernstein powers
        ``C(n,j) t^j (1-t)^{n-j}``, and one matrix product of the (K, 3(n+1)) products
        ``f_k B_{j,n}`` with the stacked control points.
        """
        n = self.degree - 2
        W = self._compact_weights
        out = np.empty((t.size, self.dim))
        K = min(chunk, max(t.size, 1))
        T = np.empty((K, n + 1))
        U = np.empty((K, n + 1))
        F = np.empty((K, 3, n + 1))
        for lo in range(0, t.size, K):
            tt = t[lo : lo + K]
            k = tt.size
            if k < K:
                T, U, F = T[:k], U[:k], F[:k]
            f = self._seed.jet(tt, 0)
            if n > MAX_DIRECT_DEGREE:
                T[...] = bernstein_log(tt, n)
            else:
                T[:, 0] = 1.0
                U[:, n] = 1.0
            if n and n <= MAX_DIRECT_DEGREE:
                u = 1.0 - tt
                for j in range(1, n + 1):
                    np.multiply(T[:, j - 1], tt, out=T[:, j])
                    np.multiply(U[:, n - j + 1], u, out=U[:, n - j])
                T *= U
            for j in range(3):
                np.multiply(f[:, j : j + 1], T, out=F[:, j])
            np.matmul(F.reshape(k, -1), W, out=out[lo : lo + k])
        return out

    def evaluate(self, t: Any) -> np.ndarray:
        """Points ``P(t) = Σ b_{i,m}(t) P_i``; shape (len(t), dim), or (dim,) for scalar t."""
        return self._eval(t, 0)

    __call__ = evaluate

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        """Analytic derivative ``P^(r)(t) = Σ b^{(r)}_{i,m}(t) P_i`` for r = 0..3."""
        return self._eval(t, _check_order(order))

    def derivatives(self, t: Any, max_order: int = 3) -> list[np.ndarray]:
        """``[P(t), P'(t), ..., P^(max_order)(t)]`` in one pass (one seed evaluation for all orders)."""
        from .basis import evaluate_derivatives

        K = _check_order(max_order)
        tt, scalar = as_parameter_array(t)

        def compute() -> list[np.ndarray]:
            check_unit_interval("t", tt, slack=1e-9)
            return evaluate_derivatives(tt, self._points, self._seed, K)

        out = self._memo(("jet", K), tt, compute)
        return [o[0] for o in out] if scalar else out

    # -- differential geometry -----------------------------------------------------------
    def speed(self, t: Any) -> np.ndarray:
        """``|P'(t)|``."""
        return np.linalg.norm(self.derivative(t, 1), axis=-1)

    def curvature(self, t: Any) -> np.ndarray:
        r"""Curvature ``κ = |P' × P''| / |P'|^3`` in any dimension.

        Computed as ``κ = |P'' - (P'·P''/|P'|²) P'| / |P'|²`` (the part of ``P''`` normal to the
        tangent; equal to the formula above because ``|P' × P''| = |P'| · |P''_⊥|``). Unlike the
        Gram determinant ``sqrt(|P'|²|P''|² - (P'·P'')²)``, whose cancellation leaves about
        ``sqrt(1e-16)`` = 1e-8 of ``|P''|/|P'|²`` on a straight line, this is at round-off level
        (``~1e-16 |P''|/|P'|²``): a straight line's curvature is 0 up to 1e-16.

        Raises:
            DegenerateGeometryError: ``P'(t) = 0`` at a requested ``t`` (coincident control points
                at that end, or all of them: the curvature is undefined there, never NaN).
        """
        with np.errstate(all="ignore"):
            kappa = curvature_from_derivatives(self.derivative(t, 1), self.derivative(t, 2))
        bad = ~np.isfinite(np.atleast_1d(kappa))
        if bad.any():
            tt = np.atleast_1d(np.asarray(t, dtype=float))
            at = float(tt[int(np.argmax(bad))]) if tt.size == bad.size else float(tt.ravel()[0])
            raise DegenerateGeometryError(
                f"the curvature is undefined at t={at:.6g}: the tangent P'(t) vanishes there (coincident control "
                "points); allowed: parameters where P'(t) != 0")
        return kappa

    def signed_curvature(self, t: Any) -> np.ndarray:
        """Signed curvature ``(x'y'' - y'x'') / |P'|^3`` of a planar (2-D) curve."""
        if self.dim != 2:
            raise GHTError(f"signed curvature needs a 2-D curve; this curve has dim={self.dim}")
        d1 = self.derivative(t, 1)
        d2 = self.derivative(t, 2)
        num = d1[..., 0] * d2[..., 1] - d1[..., 1] * d2[..., 0]
        return num / np.sum(d1 * d1, axis=-1) ** 1.5

    def torsion(self, t: Any) -> np.ndarray:
        r"""Torsion ``τ = det(P', P'', P''') / |P' × P''|^2`` of a 3-D curve."""
        if self.dim != 3:
            raise GHTError(f"torsion needs a 3-D curve; this curve has dim={self.dim}")
        d1, d2, d3 = (self.derivative(t, r) for r in (1, 2, 3))
        cr = np.cross(d1, d2)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.sum(cr * d3, axis=-1) / np.sum(cr * cr, axis=-1)

    def frenet(self, t: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Frenet frame ``T = P'/|P'|``, ``B = P'×P''/|P'×P''|``, ``N = B × T`` (3-D curves)."""
        if self.dim != 3:
            raise GHTError(f"the Frenet frame needs a 3-D curve; this curve has dim={self.dim}")
        d1 = self.derivative(t, 1)
        d2 = self.derivative(t, 2)
        T = d1 / np.linalg.norm(d1, axis=-1, keepdims=True)
        cr = np.cross(d1, d2)
        B = cr / np.linalg.norm(cr, axis=-1, keepdims=True)
        return T, np.cross(B, T), B

    def arc_length(self, t0: float = 0.0, t1: float = 1.0, *, rtol: float = 1e-13) -> float:
        r"""Arc length ``∫_{t0}^{t1} |P'(t)| dt`` by composite Gauss–Legendre quadrature."""
        return integrate(lambda t: self.speed(t), float(t0), float(t1), rtol=rtol)

    length = property(lambda self: self.arc_length(), doc="Arc length over [0, 1].")

    # -- end-point properties (spec section 3) -------------------------------------------
    def end_derivative(self, end: int, order: int) -> np.ndarray:
        r"""``P^(r)(0)`` (end=0) or ``P^(r)(1)`` (end=1) from the spec's end-jet formula.

        ``P^(r)(0) = Σ_{s=0..r} C(r,s) Σ_k a_s^k n(n-1)…(n-r+s+1) Δ^{r-s} P_k`` with the seed's
        end jets ``a_s^k = f_k^(s)(0)``; at t = 1 the same with ``e_s^k`` and backward
        differences ending at ``P_{k+n}``. Independent of :meth:`derivative` (used to test it).
        """
        r = _check_order(order)
        if end not in (0, 1):
            raise GHTError(f"end={end!r} is not allowed; use 0 (start) or 1 (end)")
        a, e = self._seed.end_jets()
        jets = a if end == 0 else e
        n = self.degree - 2
        P = self._points
        out = np.zeros(self.dim)
        for s in range(r + 1):
            j = r - s
            if j > n:
                continue
            ff = float(np.prod(np.arange(n - j + 1, n + 1))) if j else 1.0
            for k in range(3):
                if end == 0:
                    seg = P[k : k + j + 1]
                    diff = sum((-1) ** (j - l) * comb(j, l) * seg[l] for l in range(j + 1))
                else:
                    seg = P[k + n - j : k + n + 1]
                    diff = sum((-1) ** (j - l) * comb(j, l) * seg[l] for l in range(j + 1))
                out = out + comb(r, s) * jets[s, k] * ff * diff
        return out

    def newest_point_coefficient(self, order: int, end: int = 0) -> float:
        """Coefficient ``c_r`` of the newest point (``P_r`` at t=0, ``P_{m-r}`` at t=1) in ``P^(r)``.

        At t = 0 this is ``b^{(r)}_{r,m}(0)``: ``c_1 = n + a_1^1``, ``c_2 = n(n-1) + 2n a_1^1 + a_2^2``,
        ``c_3 = n(n-1)(n-2) + 3n(n-1) a_1^1 + 3n a_2^2`` (spec section 3).
        """
        r = _check_order(order)
        if r > self.degree:
            return 0.0  # no point P_r exists: the order cannot be imposed by moving a point
        if end == 0:
            return float(seed_basis(np.array([0.0]), self.degree, self._seed, r)[0, r])
        return float(seed_basis(np.array([1.0]), self.degree, self._seed, r)[0, self.degree - r])

    # -- derived curves ------------------------------------------------------------------
    def reversed(self) -> "GHTCurve":
        """The same point set traversed backwards: ``P~(t) = P(1-t)`` (symmetry of the basis).

        Control points reverse and the seed is mirrored (for GHT: μ and ν swap).
        """
        return GHTCurve(self._points[::-1], seed=self._seed.reversed())

    def with_shape(self, mu: float | None = None, nu: float | None = None, gamma: float | None = None) -> "GHTCurve":
        """A copy with some shape parameters replaced (control points unchanged).

        GBT(μ, ν) is GHT(μ, ν, -1) and Bernstein is GHT at γ = 1, so curves of those families (and
        reversed GHT-family seeds) continue in the GHT family, where every parameter is free. A
        user-registered family keeps its own seed class.
        """
        from .seeds import GHTSeed, ReversedSeed, _REGISTRY

        base = self._seed.base if isinstance(self._seed, ReversedSeed) else self._seed
        family = "ght" if isinstance(base, GHTSeed) or base.name not in _REGISTRY else base.name
        if isinstance(self._seed, ReversedSeed) and not isinstance(base, GHTSeed):
            raise GHTError(
                f"cannot change the shape parameters of a reversed {base.name!r} seed; "
                "rebuild the curve from its family instead"
            )
        return GHTCurve(
            self._points,
            self.mu if mu is None else mu,
            self.nu if nu is None else nu,
            self.gamma if gamma is None else gamma,
            seed=family,
        )

    def with_control_points(self, control_points: Any) -> "GHTCurve":
        """A copy with new control points and the same seed."""
        return GHTCurve(control_points, seed=self._seed)

    def transformed(self, matrix: Any, offset: Any = None) -> "GHTCurve":
        """Affine image ``A P(t) + b`` (exact: the basis is a partition of unity).

        Args:
            matrix: (dim, dim) linear part, or a (dim+1, dim+1) homogeneous matrix.
            offset: translation b (dim,), only with a (dim, dim) matrix.
        """
        A, b = affine_parts(matrix, offset, self.dim)
        return self.with_control_points(self._points @ A.T + b)

    def translated(self, offset: Iterable[float]) -> "GHTCurve":
        """Translated copy ``P(t) + b``."""
        return self.transformed(np.eye(self.dim), offset)

    def bounding_box(self, samples: int = 512) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounds of the curve (sampled, clipped by the control-polygon hull)."""
        pts = self.evaluate(np.linspace(0.0, 1.0, samples))
        return pts.min(axis=0), pts.max(axis=0)

    # -- (de)serialization ----------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """Plain-data form: ``{"control_points", "mu", "nu", "gamma", "seed"}``."""
        return {
            "control_points": self._points.tolist(),
            "mu": self.mu,
            "nu": self.nu,
            "gamma": self.gamma,
            "seed": self._seed.name,
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "GHTCurve":
        """Inverse of :meth:`to_dict`."""
        return cls(
            data["control_points"],
            data.get("mu", 0.0),
            data.get("nu", 0.0),
            data.get("gamma", 0.0),
            seed=data.get("seed", "ght"),
        )
