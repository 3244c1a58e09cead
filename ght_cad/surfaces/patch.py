r"""Tensor-product GHT-Bézier surface patches (spec section 3.1) and their certified B-splines.

``S(u, v) = Σ_{i=0..m} Σ_{j=0..n} b_{i,m}(u; μ_u, ν_u, γ_u) b_{j,n}(v; μ_v, ν_v, γ_v) P_ij``

over an (m+1) × (n+1) net of control points. Every curve property carries over in each direction:
corners are interpolated, the boundary curves are the GHT-Bézier curves of the boundary rows and
columns of the net, the patch lies in the convex hull of the net, it is affinely invariant.

B-spline conversion (:meth:`GHTSurface.to_bspline`) fits the *basis vectors*
``b(u) = (b_{0,m}(u), ..., b_{m,m}(u))`` and ``b(v)`` with :func:`ght_cad.surfaces.bspline.fit_function`
(``b_i(u) ≈ Σ_k N_k(u) A_ki``, ``b_j(v) ≈ Σ_l N_l(v) B_lj``) and contracts them with the net:
``Q_kl = Σ_ij A_ki B_lj P_ij``. The deviation is bounded (see :meth:`GHTSurface.to_bspline`) and
verified by sampling.
"""

from __future__ import annotations

from math import floor, log2
from typing import Any, Sequence

import numpy as np

from ..core._cache import readonly_cache
from ..core._validate import affine_parts, as_parameter_array, check_unit_interval
from ..curves.basis import _check_order, seed_basis
from .bspline import BSplineSurfaceData, fit_function
from ..curves.curve import GHTCurve
from ..core.errors import GHTError
from ..curves.seeds import Seed, make_seed

__all__ = ["GHTSurface", "join_patches", "measure_patch_continuity", "basis_bspline", "patches_to_bspline"]

_SIDES = ("u0", "u1", "v0", "v1")


@readonly_cache(maxsize=256)
def _basis_fit(degree: int, seed: Seed, tol: float, p: int) -> tuple[np.ndarray, np.ndarray, float]:
    r = min(3, p - 1)
    ends = np.array([0.0, 1.0])
    jets = [seed_basis(ends, degree, seed, k) for k in range(r + 1)]
    end_derivatives = ([j[0] for j in jets], [j[1] for j in jets])
    fit = fit_function(lambda t: seed_basis(np.asarray(t, float), degree, seed, 0), tol=tol, degree=p,
                       end_derivatives=end_derivatives)
    return fit.poles, fit.knots, float(fit.max_deviation)


def basis_bspline(degree: int, seed: Seed, tol: float, bspline_degree: int = 5) -> tuple[np.ndarray, np.ndarray, float]:
    r"""B-spline form of the whole GHT basis vector: ``b_{i,m}(t) ≈ Σ_k N_{k,p}(t) A_ki``.

    One common knot vector for all ``m+1`` functions (a d = m+1 fit), end jets of order
    ``0..min(3, p-1)`` exact, ``max_t |b(t) - Σ_k N_k(t) A_k|_2 <= tol``. Results are cached.

    Args:
        degree: GHT degree m >= 2.
        seed: the seed (shape parameters) of the basis.
        tol: maximum deviation (Euclidean norm over the m+1 functions).
        bspline_degree: B-spline degree p.

    Returns:
        ``(A, knots, deviation)`` with A of shape (K, m+1) (read-only) and the full knot vector.
    """
    return _basis_fit(int(degree), seed, float(tol), int(bspline_degree))


def _net(control_points: Any) -> np.ndarray:
    try:
        P = np.array(control_points, dtype=float)
    except (TypeError, ValueError):
        raise GHTError("control_points must be a numeric array of shape (m+1, n+1, dim)") from None
    if P.ndim != 3 or P.shape[0] < 3 or P.shape[1] < 3 or P.shape[2] < 1:
        raise GHTError(
            f"control_points has shape {P.shape}; a patch needs (m+1, n+1, dim) with m, n >= 2"
        )
    if not np.all(np.isfinite(P)):
        raise GHTError("control_points contain NaN or inf")
    P.setflags(write=False)
    return P


def _direction_seed(seed: str, direction: str, mu: Any, nu: Any, gamma: Any) -> Seed:
    """``make_seed`` for one direction; a bad shape parameter's message names ``mu_u``, ``gamma_v``, ..."""
    from ..core._validate import check_shape_parameter

    if isinstance(seed, str) and seed.lower() in ("ght", "gbt", "bernstein"):  # built-in seeds: [-1, 1]
        for name, value in (("mu", mu), ("nu", nu), ("gamma", gamma)):
            check_shape_parameter(f"{name}_{direction}", value)
    return make_seed(seed, mu, nu, gamma)


class GHTSurface:
    r"""Tensor-product GHT-Bézier patch ``S(u,v) = Σ_i Σ_j b_{i,m}(u) b_{j,n}(v) P_ij`` on [0,1]².

    Args:
        control_points: net of shape (m+1, n+1, dim), m, n >= 2 (dim 3 for CAD faces).
        mu_u, nu_u, gamma_u: shape parameters of the u basis (degree m), each in [-1, 1].
        mu_v, nu_v, gamma_v: shape parameters of the v basis (degree n), each in [-1, 1].
        seed: seed family name (``"ght"``, ``"gbt"``, ``"bernstein"``, ...) for both directions.

    Raises:
        GHTError: wrong net shape, NaN/inf, shape parameters outside [-1, 1].

    Example:
        >>> import numpy as np
        >>> net = np.zeros((3, 3, 3)); net[..., 0], net[..., 1] = np.meshgrid([0, 1, 2], [0, 1, 2], indexing="ij")
        >>> GHTSurface(net).evaluate(0.5, 0.5).round(12).tolist()
        [1.0, 1.0, 0.0]
    """

    def __init__(
        self,
        control_points: Any,
        mu_u: float = 0.0,
        nu_u: float = 0.0,
        gamma_u: float = 0.0,
        mu_v: float = 0.0,
        nu_v: float = 0.0,
        gamma_v: float = 0.0,
        *,
        seed: str = "ght",
    ) -> None:
        self._P = _net(control_points)
        self._seed_name = seed
        self._seed_u = _direction_seed(seed, "u", mu_u, nu_u, gamma_u)
        self._seed_v = _direction_seed(seed, "v", mu_v, nu_v, gamma_v)

    # -- attributes --------------------------------------------------------------------------
    @property
    def control_points(self) -> np.ndarray:
        """The (m+1, n+1, dim) net, read-only."""
        return self._P

    @property
    def degree_u(self) -> int:
        return self._P.shape[0] - 1

    @property
    def degree_v(self) -> int:
        return self._P.shape[1] - 1

    @property
    def dim(self) -> int:
        return self._P.shape[2]

    @property
    def seed_u(self) -> Seed:
        return self._seed_u

    @property
    def seed_v(self) -> Seed:
        return self._seed_v

    @property
    def shape_parameters(self) -> tuple[float, float, float, float, float, float]:
        """``(mu_u, nu_u, gamma_u, mu_v, nu_v, gamma_v)``."""
        su, sv = self._seed_u, self._seed_v
        return (su.mu, su.nu, su.gamma, sv.mu, sv.nu, sv.gamma)

    def __repr__(self) -> str:
        return (
            f"GHTSurface(degree_u={self.degree_u}, degree_v={self.degree_v}, dim={self.dim}, "
            f"shape_parameters={tuple(round(x, 6) for x in self.shape_parameters)})"
        )

    def with_control_points(self, control_points: Any) -> "GHTSurface":
        """A copy with a new net (same degrees not required) and the same shape parameters."""
        return GHTSurface(control_points, *self.shape_parameters, seed=self._seed_name)

    def transposed(self) -> "GHTSurface":
        """The same surface with u and v swapped: ``S~(u, v) = S(v, u)``."""
        su, sv = self._seed_u, self._seed_v
        return GHTSurface(np.swapaxes(self._P, 0, 1), sv.mu, sv.nu, sv.gamma, su.mu, su.nu, su.gamma,
                          seed=self._seed_name)

    def transformed(self, matrix: Any, offset: Any = None) -> "GHTSurface":
        """Affine image ``A S(u,v) + b`` (exact: both bases are partitions of unity).

        Args:
            matrix: (dim, dim) linear part, or a (dim+1, dim+1) homogeneous matrix.
            offset: translation b (dim,), only with a (dim, dim) matrix.
        """
        A, b = affine_parts(matrix, offset, self.dim)
        return self.with_control_points(self._P @ A.T + b)

    def translated(self, offset: Any) -> "GHTSurface":
        """Translated copy ``S(u, v) + b``."""
        return self.transformed(np.eye(self.dim), offset)

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form: ``{"control_points", "mu_u", "nu_u", "gamma_u", "mu_v", "nu_v",
        "gamma_v", "seed"}``."""
        keys = ("mu_u", "nu_u", "gamma_u", "mu_v", "nu_v", "gamma_v")
        out: dict[str, Any] = {"control_points": self._P.tolist()}
        out.update(dict(zip(keys, self.shape_parameters)))
        out["seed"] = self._seed_name
        return out

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "GHTSurface":
        """Inverse of :meth:`to_dict`."""
        keys = ("mu_u", "nu_u", "gamma_u", "mu_v", "nu_v", "gamma_v")
        return cls(data["control_points"], *(data.get(k, 0.0) for k in keys), seed=data.get("seed", "ght"))

    # -- evaluation --------------------------------------------------------------------------
    def _bases(self, u: Any, v: Any, du: int, dv: int) -> tuple[np.ndarray, np.ndarray, tuple]:
        uu, su = as_parameter_array(u, "u")
        vv, sv = as_parameter_array(v, "v")
        check_unit_interval("u", uu, slack=1e-9)
        check_unit_interval("v", vv, slack=1e-9)
        if uu.size != vv.size and uu.size != 1 and vv.size != 1:
            raise GHTError(f"u and v have {uu.size} and {vv.size} values; they must match or one must be scalar")
        uu, vv = np.broadcast_arrays(uu, vv)
        Bu = seed_basis(np.ascontiguousarray(uu), self.degree_u, self._seed_u, _check_order(du))
        Bv = seed_basis(np.ascontiguousarray(vv), self.degree_v, self._seed_v, _check_order(dv))
        return Bu, Bv, (su and sv)

    def derivative(self, u: Any, v: Any, du: int = 0, dv: int = 0) -> np.ndarray:
        r"""Partial derivative ``∂^{du+dv} S / ∂u^{du} ∂v^{dv} = Σ_ij b^{(du)}_i(u) b^{(dv)}_j(v) P_ij``.

        Args:
            u, v: parameters in [0, 1] (scalars or equal-length 1-D arrays; a scalar broadcasts).
            du, dv: derivative orders 0..3 (analytic).

        Returns:
            Shape (N, dim), or (dim,) when both u and v are scalars.
        """
        Bu, Bv, scalar = self._bases(u, v, du, dv)
        out = np.einsum("ki,kj,ijd->kd", Bu, Bv, self._P)
        return out[0] if scalar else out

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        """Points ``S(u, v)`` at matched parameter pairs; see :meth:`derivative`."""
        return self.derivative(u, v, 0, 0)

    __call__ = evaluate

    def evaluate_grid(self, u: Any, v: Any, du: int = 0, dv: int = 0) -> np.ndarray:
        """``S^{(du,dv)}`` on the grid ``u × v``: shape (len(u), len(v), dim)."""
        uu, _ = as_parameter_array(u, "u")
        vv, _ = as_parameter_array(v, "v")
        check_unit_interval("u", uu, slack=1e-9)
        check_unit_interval("v", vv, slack=1e-9)
        Bu = seed_basis(uu, self.degree_u, self._seed_u, _check_order(du))
        Bv = seed_basis(vv, self.degree_v, self._seed_v, _check_order(dv))
        return np.einsum("ai,bj,ijd->abd", Bu, Bv, self._P)

    def normal(self, u: Any, v: Any) -> np.ndarray:
        r"""Unit normal ``n = S_u × S_v / |S_u × S_v|`` (3-D patches; NaN where S_u ∥ S_v)."""
        if self.dim != 3:
            raise GHTError(f"normals need a 3-D patch; this patch has dim={self.dim}")
        cr = np.cross(self.derivative(u, v, 1, 0), self.derivative(u, v, 0, 1))
        with np.errstate(divide="ignore", invalid="ignore"):
            return cr / np.linalg.norm(cr, axis=-1, keepdims=True)

    def boundary(self, side: str) -> GHTCurve:
        """Boundary curve as a :class:`GHTCurve`: ``"u0"`` is ``v ↦ S(0, v)`` = GHT curve of row
        ``P_0j`` with the v parameters; ``"u1"`` ``S(1, v)``; ``"v0"`` ``u ↦ S(u, 0)`` = GHT curve of
        column ``P_i0`` with the u parameters; ``"v1"`` ``S(u, 1)``.
        """
        if side not in _SIDES:
            raise GHTError(f"side={side!r} is not allowed; use one of {_SIDES}")
        if side[0] == "u":
            row = self._P[0 if side == "u0" else -1, :]
            return GHTCurve(row, seed=self._seed_v)
        col = self._P[:, 0 if side == "v0" else -1]
        return GHTCurve(col, seed=self._seed_u)

    def boundaries(self) -> dict[str, GHTCurve]:
        """All four boundary curves keyed ``"u0", "u1", "v0", "v1"``."""
        return {s: self.boundary(s) for s in _SIDES}

    def iso_curve(self, direction: str, value: float) -> GHTCurve:
        r"""Isoparametric curve as an exact GHT curve.

        ``direction="u"``: ``u ↦ S(u, v0)`` with control points ``Σ_j b_j(v0) P_ij`` (u parameters);
        ``direction="v"``: ``v ↦ S(u0, v)`` with control points ``Σ_i b_i(u0) P_ij``.
        """
        x = float(value)
        if not 0.0 <= x <= 1.0:
            raise GHTError(f"value={value!r} is outside [0, 1]")
        if direction == "u":
            w = seed_basis(np.array([x]), self.degree_v, self._seed_v, 0)[0]
            return GHTCurve(np.einsum("j,ijd->id", w, self._P), seed=self._seed_u)
        if direction == "v":
            w = seed_basis(np.array([x]), self.degree_u, self._seed_u, 0)[0]
            return GHTCurve(np.einsum("i,ijd->jd", w, self._P), seed=self._seed_v)
        raise GHTError(f"direction={direction!r} is not allowed; use 'u' or 'v'")

    def bounding_box(self, samples: int = 65) -> tuple[np.ndarray, np.ndarray]:
        """Sampled axis-aligned bounds (a ``samples × samples`` grid)."""
        t = np.linspace(0.0, 1.0, samples)
        pts = self.evaluate_grid(t, t).reshape(-1, self.dim)
        return pts.min(axis=0), pts.max(axis=0)

    # -- conversion --------------------------------------------------------------------------
    def _auto_tolerances(self, tol: float | None) -> tuple[float, float, float, float]:
        """(tol, R, tol_u, tol_v): the requested tolerance, the net radius and the 1-D tolerances."""
        P = self._P
        if tol is None:
            lo, hi = self.bounding_box()
            diag = float(np.linalg.norm(hi - lo))
            rounding = 64.0 * np.finfo(float).eps * max(float(np.abs(P).max()), 1e-300)
            tol = max(1e-7 * diag, rounding)
        try:
            tol = float(tol)
        except (TypeError, ValueError):
            raise GHTError(f"tol={tol!r} is not a number; it must be a positive float") from None
        if not np.isfinite(tol) or tol <= 0:
            raise GHTError(f"tol={tol!r} is not allowed; it must be a positive finite number")
        c = P.reshape(-1, self.dim).mean(axis=0)
        R = max(float(np.linalg.norm(P - c, axis=-1).max()), 1e-300)
        tau = min(0.45 * tol / R, 0.1)  # then R (2τ + τ²) <= 0.945 tol

        def quantize(x: float) -> float:
            return 2.0 ** floor(log2(x))

        return tol, R, quantize(tau / np.sqrt(self.degree_u + 1)), quantize(tau / np.sqrt(self.degree_v + 1))

    def to_bspline(self, tol: float | None = None, degree: int = 5, *, basis_tol: float | None = None) -> BSplineSurfaceData:
        r"""Certified B-spline surface ``S~(u,v) = Σ_kl N_k(u) N_l(v) Q_kl`` with ``|S - S~| <= tol``.

        ``Q_kl = Σ_ij A_ki B_lj P_ij`` where ``A``, ``B`` are the B-spline forms of the u and v basis
        vectors (:func:`basis_bspline`). With the 1-D deviations ``δ_u = max |b(u) - a(u)|_2``,
        ``δ_v`` likewise, ``E_u = sqrt(m+1) δ_u``, ``E_v = sqrt(n+1) δ_v`` (ℓ1 bounds), the
        partition of unity (kept by the fit, which is linear and reproduces constants) and
        ``R = max_ij |P_ij - c|`` about the net's centroid c:

        ``|S - S~| = |Σ_ij (b_i b_j - a_i c_j) (P_ij - c)| <= R (E_u + (1 + E_u) E_v)``.

        The 1-D tolerances are chosen so that this bound is ``<= tol`` (rounded down to a power of
        two so that patches of similar size share knot vectors, which keeps the exact cross-boundary
        derivatives of a patch join identical in both B-splines). The result is also checked on a
        101 × 101 grid plus 2000 random points.

        Args:
            tol: maximum deviation; default ``1e-7 ×`` the bounding-box diagonal of the patch.
            degree: B-spline degree in u and v.
            basis_tol: optional upper bound for both 1-D basis tolerances (used by
                :func:`patches_to_bspline` to give joined patches identical boundary fits).

        Returns:
            :class:`BSplineSurfaceData` (``max_deviation`` = the bound; ``info`` holds
            ``sampled_deviation``, ``bound``, the 1-D tolerances and pole counts).

        Raises:
            GHTError: bad tol; ConversionError: unreachable tolerance.
        """
        P = self._P
        m, n = self.degree_u, self.degree_v
        tol, R, tol_u, tol_v = self._auto_tolerances(tol)
        if basis_tol is not None:
            if not (np.isfinite(basis_tol) and basis_tol > 0):
                raise GHTError(f"basis_tol={basis_tol!r} is not allowed; it must be a positive finite number")
            tol_u, tol_v = min(tol_u, float(basis_tol)), min(tol_v, float(basis_tol))
        c = P.reshape(-1, self.dim).mean(axis=0)
        A, ku, dev_u = basis_bspline(m, self._seed_u, tol_u, degree)
        B, kv, dev_v = basis_bspline(n, self._seed_v, tol_v, degree)
        Q = np.einsum("ki,lj,ijd->kld", A, B, P - c) + c
        Eu, Ev = np.sqrt(m + 1) * dev_u, np.sqrt(n + 1) * dev_v
        bound = R * (Eu + (1.0 + Eu) * Ev)
        out = BSplineSurfaceData(Q, np.array(ku), np.array(kv), int(degree), int(degree), max_deviation=bound)
        rng = np.random.default_rng(0)
        g = np.linspace(0.0, 1.0, 101)
        uu, vv = np.meshgrid(g, g, indexing="ij")
        us = np.concatenate([uu.ravel(), rng.uniform(0, 1, 2000)])
        vs = np.concatenate([vv.ravel(), rng.uniform(0, 1, 2000)])
        sampled = float(np.linalg.norm(out.evaluate(us, vs) - self.evaluate(us, vs), axis=1).max())
        if sampled > tol:  # cannot happen if the bound holds; never hand out an uncertified face
            raise GHTError(f"internal error: sampled deviation {sampled:.3g} exceeds tol={tol:g}")
        out.info.update(
            tol=tol, bound=bound, sampled_deviation=sampled, samples_checked=us.size,
            basis_tol=(tol_u, tol_v), basis_deviation=(dev_u, dev_v), poles=Q.shape[:2],
        )
        return out

    def to_face(self, tol: float | None = None, degree: int = 5) -> Any:
        """build123d ``Face`` on :meth:`to_bspline` (imports the CAD adapter lazily)."""
        from ..core._kernel import adapter

        if self.dim != 3:
            raise GHTError(f"a CAD face needs a 3-D patch; this patch has dim={self.dim}")
        return adapter("make_face")(self.to_bspline(tol, degree))


def patches_to_bspline(
    patches: Sequence[GHTSurface], tol: float | None = None, degree: int = 5
) -> list[BSplineSurfaceData]:
    r"""Convert joined patches with one common 1-D basis tolerance (see :meth:`GHTSurface.to_bspline`).

    The smallest 1-D tolerance any patch needs is used for all, so two patches that share a
    boundary basis (as :func:`join_patches` requires) get the *same* B-spline basis along it: the
    common boundary curves coincide and the cross-boundary derivative conditions
    (``∂_u S_B = k ∂_u S_A`` etc.) hold in the B-splines to rounding, not just to ``tol``.

    Args:
        patches: the patches.
        tol: per-patch maximum deviation (default: each patch's 1e-7 × box diagonal).
        degree: B-spline degree.

    Returns:
        One :class:`BSplineSurfaceData` per patch, each within its tolerance.
    """
    pats = list(patches)
    if not pats:
        raise GHTError("patches is empty")
    common = min(min(p._auto_tolerances(tol)[2:]) for p in pats)
    return [p.to_bspline(tol, degree, basis_tol=common) for p in pats]


def _row_curves(patch: GHTSurface) -> list[GHTCurve]:
    """The u-direction curves of the net columns: ``u ↦ Σ_i b_i(u) P_ij`` for each j."""
    return [GHTCurve(patch.control_points[:, j], seed=patch.seed_u) for j in range(patch.degree_v + 1)]


def join_patches(
    patch_a: GHTSurface,
    continuity: Any,
    patch_b: GHTSurface,
    *,
    direction: str = "u",
    k: float = 1.0,
    beta2: float = 0.0,
    beta3: float = 0.0,
) -> GHTSurface:
    r"""Patch B re-solved so that it joins patch A across their common boundary.

    ``direction="u"``: A's side u = 1 meets B's side u = 0. With equal v bases (same degree n and
    v shape parameters, required), ``S_B^{(r,0)}(0, v) = Σ_j b_j(v) R^{(r)}_j(0)``, so the surface
    condition holds for every v iff it holds for each column curve ``u ↦ Σ_i b_i(u) P_ij``:
    each column of B is solved with :func:`ght_cad.curves.continuity.join` (``R_0j = P_mj``; C1:
    ``∂_u S_B = ∂_u S_A``; G1: ``∂_u S_B = k ∂_u S_A``, k > 0, which gives a common tangent plane;
    C2/G2/C3/G3 likewise). ``direction="v"`` does the same with u and v swapped.

    Args:
        patch_a, patch_b: the two patches (B's first rows across the boundary are replaced).
        continuity: ``"C0".."C3"``, ``"G0".."G3"``.
        direction: ``"u"`` or ``"v"``.
        k, beta2, beta3: G parameters (as in :func:`ght_cad.curves.continuity.join`).

    Returns:
        The new patch B.

    Raises:
        GHTError: different dimensions, different bases along the boundary, bad direction;
        SingularJoinError: as :func:`ght_cad.curves.continuity.join`.
    """
    from ..curves.continuity import join

    if direction not in ("u", "v"):
        raise GHTError(f"direction={direction!r} is not allowed; use 'u' or 'v'")
    if direction == "v":
        return join_patches(patch_a.transposed(), continuity, patch_b.transposed(), direction="u",
                            k=k, beta2=beta2, beta3=beta3).transposed()
    if patch_a.dim != patch_b.dim:
        raise GHTError(f"patches have dimensions {patch_a.dim} and {patch_b.dim}")
    if patch_a.degree_v != patch_b.degree_v or patch_a.seed_v != patch_b.seed_v:
        raise GHTError(
            "patches joined across u need the same basis along the common boundary: "
            f"v degrees {patch_a.degree_v}/{patch_b.degree_v}, v seeds {patch_a.seed_v!r}/{patch_b.seed_v!r}"
        )
    kwargs: dict[str, float] = {}
    if str(continuity).upper().startswith("G"):
        kwargs = {"k": k, "beta2": beta2, "beta3": beta3}
    cols = [
        join(ca, continuity, cb, **kwargs).control_points
        for ca, cb in zip(_row_curves(patch_a), _row_curves(patch_b))
    ]
    return patch_b.with_control_points(np.stack(cols, axis=1))


def measure_patch_continuity(
    patch_a: GHTSurface, patch_b: GHTSurface, *, direction: str = "u", samples: int = 17, tol: float = 1e-9
) -> tuple[int, int]:
    r"""Continuity ``(c_order, g_order)`` achieved across a patch boundary, measured from the surfaces.

    At ``samples`` values v_s the iso-curves ``u ↦ S_A(u, v_s)`` and ``u ↦ S_B(u, v_s)`` (exact
    GHT curves, :meth:`GHTSurface.iso_curve`) are measured with
    :func:`ght_cad.curves.continuity.measure_continuity` (relative tolerance ``tol``); the minimum over
    the samples is returned. ``direction="v"`` swaps u and v.
    """
    from ..curves.continuity import measure_continuity

    if direction not in ("u", "v"):
        raise GHTError(f"direction={direction!r} is not allowed; use 'u' or 'v'")
    if direction == "v":
        patch_a, patch_b = patch_a.transposed(), patch_b.transposed()
    c_order, g_order = 3, 3
    for v in np.linspace(0.0, 1.0, int(samples)):
        rep = measure_continuity(patch_a.iso_curve("u", v), patch_b.iso_curve("u", v), tol=tol)
        c_order, g_order = min(c_order, rep.c_order), min(g_order, rep.g_order)
    return c_order, g_order
