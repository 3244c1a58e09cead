"""Problem 1: the quasi-developable strip between two GHT curves (objective ``R``, spec section 5),
with its fast exact-gradient kernel and the default strip designs."""

from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from ...core._vec import cross as _cross
from ...curves.basis import bernstein
from ...core._quadrature import gauss_legendre
from ...curves.curve import GHTCurve
from ...core.errors import GHTError
from ...surfaces.ruled import CurvePairRuledSurface
from .base import CurveParameterJets, PopulationBasis, Problem, SHAPE_NAMES, _split


class _StripKernel:
    r"""Fast evaluation of the strip's ``R`` and its exact gradient on fixed Gauss–Legendre nodes.

    **Values**: bit for bit those of the basis-matrix route (:class:`PopulationBasis` ->
    ``b^(r) @ control_points`` -> ``numpy.cross``, kept as
    :meth:`StripProblem._r_and_grad_reference`). Every elementwise operation of the seed formula
    (:func:`ght_cad.curves.seeds.ght_seed_jet`, orders 0 and 1) is done once on arrays stacked over
    (curve, f0/f2) instead of once per curve and order; everything that depends on the nodes only
    (sin/cos, their squares, ``(1-t)²``, ``t²``, Bernstein matrices) is computed once; the basis
    ``b^(r)_{i,m} = Σ_s C(r,s) Σ_k B^(r-s)_{i-k,n} f_k^(s)`` is one product with zero-padded
    Bernstein matrices (terms in the order of :func:`ght_cad.curves.basis.basis_from_jets`, the padding
    adds exact zeros) summed over the terms. Same operations in the same order per element: same
    floating-point results (checked in tests/test_optimize_problems.py).

    **Gradient** (spec 8.1): ``∂X^(r)/∂μ = v U_r``, ``∂X^(r)/∂ν = v V_r``,
    ``∂X^(r)/∂γ = W_r - (μ U_r + ν V_r)/2`` with ``v = (1-γ)/2`` and the fixed fields
    ``(U, V, W)_r = ∂X^(r)/∂(μ, ν, γ)`` at ``(μ, ν, γ) = (0, 0, -1)`` (:class:`CurveParameterJets`;
    f0 is bilinear in (μ, w), f2 in (ν, w)). With ``K_a = n_b/(|n_a||n_b|) - c n_a/|n_a|²`` and
    ``K_b = n_a/(|n_a||n_b|) - c n_b/|n_b|²`` (so ``∂c = ∂n_a·K_a + ∂n_b·K_b``) and the triple
    product ``(x×y)·z = x·(y×z)``:

    ``∂c = ∂A'·(g×K_a) + ∂A·M + ∂B'·(g×K_b) - ∂B·M``, ``M = A'×K_a + B'×K_b``, ``g = B - A``,

    so the gradient costs four cross products per node whatever the number of parameters, and
    ``∂R/∂θ = -Σ_j w_j ∂c_j`` (0 where the clip of c to [-1, 1] is active) is one small matrix
    product with the fixed fields per curve.
    """

    def __init__(self, t: np.ndarray, curves: Sequence[GHTCurve]) -> None:
        from ...curves.seeds import _HALF_PI, _trig_values

        self.t = t
        N = t.size
        sa, ca, sp, _ = _trig_values(t, range(2))  # the arrays ght_seed_derivatives(t, ..., 1) uses
        col = (2, 1, 1, N)  # (f0/f2, curve, row, node)
        self._x1 = np.stack([sa, ca]).reshape(col)                    # s, c
        self._x2 = np.stack([sa * sa, ca * ca]).reshape(col)          # s², c²
        self._poly0 = np.stack([(1.0 - t) ** 2, t * t]).reshape(col)  # (1-t)², t²
        self._xs1 = np.stack([ca, sa]).reshape(col)                   # s' ∝ cos, c' ∝ -sin
        self._xd = sp                                                 # (s²)' = -(c²)' ∝ sin(πt)
        hr = _HALF_PI ** 1
        self._hs = np.array([hr * 1.0, hr * -1.0]).reshape(2, 1, 1, 1)  # (π/2) sign of s', c'
        self._half_d = 0.5 * math.pi ** 1 * -1.0
        self._sgn = np.array([-1.0, 1.0]).reshape(2, 1, 1, 1)          # f0' = a - b, f2' = a + b
        degs = [c.degree for c in curves]
        groups = [list(range(len(curves)))] if len(set(degs)) == 1 else [[i] for i in range(len(curves))]
        self.groups = []
        for grp in groups:
            m1 = degs[grp[0]] + 1
            n1 = m1 - 2
            b0, b1 = bernstein(t, n1 - 1, 0), bernstein(t, n1 - 1, 1)
            # terms (f0, f1, f2, f0', f1', f2') per t-order: order 0 uses B f_k, order 1 B' f_k then B f_k'
            bst = np.zeros((2, 6, N, m1))
            for k in range(3):
                bst[0, k, :, k:k + n1] = b0
                bst[1, k, :, k:k + n1] = b1
                bst[1, 3 + k, :, k:k + n1] = b0
            cp = np.stack([np.asarray(curves[i].control_points, dtype=float) for i in grp])[:, None]
            cols_l = [3 * i for i in grp] + [3 * i + 1 for i in grp]  # (μ of each curve, ν of each curve)
            cols_g = [3 * i + 2 for i in grp]
            self.groups.append((grp, cols_l, cols_g, bst[:, :, None, None], cp))
        self.n_curves = len(curves)
        # fixed gradient fields (U, V, W) per curve and t-order, each (N*3, 3)
        f0, f1 = [], []
        for c in curves:
            d = CurveParameterJets(t, c.control_points, 1)(np.zeros(1), np.zeros(1), -np.ones(1), (0, 1))
            f0.append(d[0][:, 0].reshape(3, -1).T)
            f1.append(d[1][:, 0].reshape(3, -1).T)
        self._fields0 = np.concatenate(f0, axis=1)  # (N*3, 6): ∂X fields of curve A then curve B
        self._fields1 = np.stack(f1)                # (2, N*3, 3): ∂X' fields

    def jets_stacked(self, F: np.ndarray) -> list[tuple[list[int], np.ndarray]]:
        """Per group of curves of one degree: (curve indices, ``[X, X']`` of shape (2, G, P, N, 3))."""
        P = F.shape[0]
        N = self.t.size
        out = []
        for grp, cols_l, cols_g, bst, cp in self.groups:
            G = len(grp)
            lam = F[:, cols_l].T.reshape(2, G, P, 1)  # (μ, ν) x curve
            ga = F[:, cols_g].T.reshape(1, G, P, 1)
            w = 0.5 * (1.0 + ga)
            v = 1.0 - w
            lam1 = 1.0 + lam
            w2 = 2.0 * w
            # seed jets (f0, f1, f2, f0', f1', f2'), f1 = δ_r0 - f0 - f2, straight into the term array
            fs = np.empty((6, G, P, N))
            # order 0: (1-w)(1 - (1+λ)x + λx²) + w p   (f0: λ = μ, x = s, p = (1-t)²; f2: ν, c, t²)
            np.add(v * (1.0 - lam1 * self._x1 + lam * self._x2), w * self._poly0, out=fs[0:3:2])
            np.subtract(1.0, fs[0], out=fs[1])
            np.subtract(fs[1], fs[2], out=fs[1])
            # order 1: -(1-w)(1+λ) x' + (1-w) λ (x²)' + w p'   (p0' = 2wt - 2w, p2' = 2wt)
            d1 = (-(v * lam1)) * self._hs * self._xs1 + (((v * lam) * self._half_d) * self._sgn) * self._xd
            wt = w2 * self.t
            np.add(d1[0], wt[0] - w2[0], out=fs[3])
            np.add(d1[1], wt[0], out=fs[5])
            np.subtract(0.0, fs[3], out=fs[4])
            np.subtract(fs[4], fs[5], out=fs[4])
            J = np.add.reduce(bst * fs[..., None], axis=1) @ cp  # basis (2, G, P, N, m+1) @ points
            out.append((grp, J))
        return out

    def jets(self, F: np.ndarray) -> list[np.ndarray]:
        """``[X, X']`` per curve: a list of (2, P, N, 3) arrays (curve order of the constructor)."""
        out: list[Any] = [None] * self.n_curves
        for grp, J in self.jets_stacked(F):
            for j, i in enumerate(grp):
                out[i] = J[:, j]
        return out

    def value_and_grad(self, F: np.ndarray, w: np.ndarray, grad: bool) -> tuple[np.ndarray, Any]:
        """``R`` (pop,) and, with ``grad``, its gradient (pop, 6) on full rows."""
        js = self.jets_stacked(F)
        if len(js) == 1:
            J = js[0][1]
            D = J[1]  # A', B'
            g = J[0, 1] - J[0, 0]
        else:
            (_, Ja), (_, Jb) = js
            D = np.concatenate([Ja[1], Jb[1]])
            g = Jb[0, 0] - Ja[0, 0]
        n = _cross(D, g)  # n_a, n_b
        L = np.sqrt(np.add.reduce(n * n, axis=-1))  # numpy.linalg.norm(n, axis=-1)
        la, lb = L[0], L[1]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            dot = np.add.reduce(n[0] * n[1], axis=-1) / (la * lb)
            val = (1.0 - np.clip(dot, -1.0, 1.0)) @ w
            val = np.where(np.isfinite(val), val, np.inf)
            if not grad:
                return val, None
            P = F.shape[0]
            # K_a, K_b, weighted by w_j where c is not clipped (rows with a non-finite value get G = 0)
            K = n[::-1] / (la * lb)[..., None] - (dot / (L * L))[..., None] * n
            K *= np.where(np.abs(dot) < 1.0, w, 0.0)[..., None]
            X3 = np.empty((3,) + g.shape)
            X3[0] = g
            X3[1:] = D
            C = _cross(X3[:, None], K)  # (g, A', B') x (K_a, K_b)
            M = (C[1, 0] + C[2, 1]).reshape(P, -1)  # A'×K_a + B'×K_b
            S0 = M @ self._fields0  # (P, 6): Σ_j w_j M·(U, V, W) for curve A, then curve B
            S1 = C[0].reshape(2, P, -1) @ self._fields1  # (2, P, 3): Σ_j w_j (g×K_c)·(U', V', W')
            S = S1 + np.stack([S0[:, :3], -S0[:, 3:]])  # (2, P, 3) per curve
            Fc = F.reshape(P, 2, 3).transpose(1, 0, 2)  # (2, P, 3): μ, ν, γ per curve
            v = 1.0 - 0.5 * (1.0 + Fc[..., 2])
            G = np.empty((P, 2, 3))
            Gt = G.transpose(1, 0, 2)
            np.multiply(-v[..., None], S[..., :2], out=Gt[..., :2])
            np.subtract(0.5 * (Fc[..., 0] * S[..., 0] + Fc[..., 1] * S[..., 1]), S[..., 2], out=Gt[..., 2])
            G = G.reshape(P, 6)
        G[~np.isfinite(val)] = 0.0
        return val, G


# --------------------------------------------------------------------------------------------
# problem 1: quasi-developable strip between two GHT curves
# --------------------------------------------------------------------------------------------
class StripProblem(Problem):
    r"""Problem 1: make the strip between two GHT boundary curves as developable as possible.

    The ruled surface ``X(u, v) = (1-v) A(u) + v B(u)`` pairs the two curves by their common
    parameter (:class:`~ght_cad.surfaces.ruled.CurvePairRuledSurface`). Parameters ``a.mu, a.nu, a.gamma``
    (curve A) and ``b.mu, b.nu, b.gamma`` (curve B). Objective (spec section 5):

    ``R = ∫_0^1 (1 - n_a·n_b) du``, ``n_a = A'×g/|A'×g|``, ``n_b = B'×g/|B'×g|``, ``g = B - A``,

    by ``nodes``-point Gauss–Legendre quadrature (>= 64). Nodes where a normal is undefined
    (``A'×g = 0``) make the value ``+inf``.

    Args:
        curve_a, curve_b: 3-D :class:`GHTCurve` objects (their shape parameters are the base).
        free: names of the free parameters (default all six).
        bounds: optional narrower bounds per free name, inside [-1, 1].
        nodes: Gauss–Legendre nodes (>= 64).

    Raises:
        GHTError: non-GHT seeds, non-3-D curves, unknown names, bad bounds, nodes < 64.
    """

    label = "strip R"

    def __init__(
        self,
        curve_a: GHTCurve,
        curve_b: GHTCurve,
        free: Sequence[str] | None = None,
        bounds: Mapping[str, tuple[float, float]] | None = None,
        nodes: int = 64,
    ) -> None:
        for nm, c in (("curve_a", curve_a), ("curve_b", curve_b)):
            if not isinstance(c, GHTCurve) or c.dim != 3:
                raise GHTError(f"{nm} must be a 3-D GHTCurve, got {c!r}")
            if c.seed.name != "ght":
                raise GHTError(f"{nm} uses seed {c.seed.name!r}; shape-parameter problems need the 'ght' seed")
        if int(nodes) < 64:
            raise GHTError(f"nodes={nodes} is too few; R uses >= 64 Gauss–Legendre nodes")
        names = [f"a.{s}" for s in SHAPE_NAMES] + [f"b.{s}" for s in SHAPE_NAMES]
        super().__init__(names, list(curve_a.shape_parameters) + list(curve_b.shape_parameters), free, bounds)
        self.curve_a, self.curve_b = curve_a, curve_b
        self.t, self.w = gauss_legendre(int(nodes))
        self._basis = (PopulationBasis(self.t, curve_a.degree), PopulationBasis(self.t, curve_b.degree))
        self._pjets = (CurveParameterJets(self.t, curve_a.control_points, 1),
                       CurveParameterJets(self.t, curve_b.control_points, 1))
        self._kernel = _StripKernel(self.t, (curve_a, curve_b))

    def jets(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``A, A', B, B'`` at the nodes for full parameter rows F: each (pop, N, 3) (bit for bit
        ``population_basis(...) @ control_points``)."""
        Ja, Jb = self._kernel.jets(np.asarray(F, dtype=float))
        return Ja[0], Ja[1], Jb[0], Jb[1]

    def evaluate_full(self, F: np.ndarray) -> np.ndarray:
        return self._r_and_grad(F, False)[0]

    def value_and_grad_full(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r"""``R`` and its exact gradient on full rows (a.mu, a.nu, a.gamma, b.mu, b.nu, b.gamma).

        With ``g = B - A``, ``n_a = A'×g``, ``n_b = B'×g``, ``c = n_a·n_b / (|n_a||n_b|)``:
        ``∂c = (∂n_a·n_b + n_a·∂n_b)/(|n_a||n_b|) - c (n_a·∂n_a/|n_a|² + n_b·∂n_b/|n_b|²)``,
        ``∂n_a = ∂A'×g + A'×∂g``, ``∂n_b = ∂B'×g + B'×∂g``, ``∂g = ∂B - ∂A``, and
        ``∂R = -Σ_j w_j ∂c_j`` (0 where the clip to [-1, 1] is active); ``∂A, ∂A'`` from
        :class:`CurveParameterJets`.
        """
        return self._r_and_grad(F, True)

    def _r_and_grad(self, F: np.ndarray, grad: bool) -> tuple[np.ndarray, Any]:
        return self._kernel.value_and_grad(F, self.w, grad)

    def _r_and_grad_reference(self, F: np.ndarray, grad: bool) -> tuple[np.ndarray, Any]:
        """The direct implementation (one basis and one jet call per curve, a cross product per
        parameter), kept to check :class:`_StripKernel` against (tests)."""
        out = []
        for k, c, pb in ((0, self.curve_a, self._basis[0]), (3, self.curve_b, self._basis[1])):
            Bm = pb(*_split(F, k), (0, 1))
            out += [Bm[r] @ c.control_points for r in (0, 1)]
        A, A1, B, B1 = out
        g = B - A
        na = np.cross(A1, g)
        nb = np.cross(B1, g)
        la = np.linalg.norm(na, axis=-1)
        lb = np.linalg.norm(nb, axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            dot = np.sum(na * nb, axis=-1) / (la * lb)
        val = (1.0 - np.clip(dot, -1.0, 1.0)) @ self.w
        val = np.where(np.isfinite(val), val, np.inf)
        if not grad:
            return val, None
        G = np.zeros((F.shape[0], 6))
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            inv = 1.0 / (la * lb)
            ca, cb = dot / (la * la), dot / (lb * lb)
            active = (np.abs(dot) < 1.0) & np.isfinite(dot)  # (pop, N): where c is not clipped
            for k, pj in ((0, self._pjets[0]), (3, self._pjets[1])):
                dXr = pj(*_split(F, k), (0, 1))
                dX, dX1 = dXr[0], dXr[1]  # (3, pop, N, 3)
                if k == 0:  # curve A: dg = -dA
                    dna = _cross(dX1, g) - _cross(A1, dX)
                    dnb = -_cross(B1, dX)
                else:  # curve B: dg = dB
                    dna = _cross(A1, dX)
                    dnb = _cross(dX1, g) + _cross(B1, dX)
                dc = (np.sum(dna * nb, axis=-1) + np.sum(na * dnb, axis=-1)) * inv \
                    - ca * np.sum(na * dna, axis=-1) - cb * np.sum(nb * dnb, axis=-1)
                G[:, k:k + 3] = -(np.where(active, dc, 0.0) @ self.w).T
        G[~np.isfinite(val)] = 0.0
        return val, G

    def curves(self, x: Any) -> tuple[GHTCurve, GHTCurve]:
        """The two boundary curves for free parameters ``x``."""
        p = self.parameters(x)
        a = GHTCurve(self.curve_a.control_points, p["a.mu"], p["a.nu"], p["a.gamma"])
        b = GHTCurve(self.curve_b.control_points, p["b.mu"], p["b.nu"], p["b.gamma"])
        return a, b

    def build(self, x: Any) -> CurvePairRuledSurface:
        """The strip :class:`~ght_cad.surfaces.ruled.CurvePairRuledSurface` for free parameters ``x``."""
        return CurvePairRuledSurface(*self.curves(x))

    def report(self, x: Any) -> dict[str, float]:
        """``θ_max``, ``θ_rms`` (degrees), ``DD``, ``R`` of the strip (RuledSurface.developability)."""
        d = self.build(x).developability()
        return {"theta_max": d.theta_max, "theta_rms": d.theta_rms, "DD": d.dd, "R": d.R}


# --------------------------------------------------------------------------------------------
# default designs (used by tests, the bench and the demo)
# --------------------------------------------------------------------------------------------
def default_strip_problem(free: Sequence[str] | None = None, **kw: Any) -> StripProblem:
    """A strip between two cubic GHT curves, clearly non-developable at the base design.

    Both end quadrilaterals ``A_0 A_1 B_1 B_0`` and ``A_2 A_3 B_3 B_2`` are planar, so θ(0) =
    θ(1) = 0 (the end normals do not depend on the shape parameters); the twist is interior and
    the shape parameters can remove most of it (θ_max 11.3° at all-zero parameters).
    """
    A = GHTCurve([[0.2, 0.079, 0.511], [0.982, 1.1, 0.253], [2.173, -0.764, 0.063], [3.032, 0.422, 0.054]])
    B = GHTCurve([[0.335, 0.303, 1.623], [1.2, 1.43, 1.24], [2.255, -0.042, 1.08], [2.805, 0.769, 1.16]])
    return StripProblem(A, B, free=free, **kw)

def wave_strip_problem(free: Sequence[str] | None = None, **kw: Any) -> StripProblem:
    """A strip between two quartic GHT curves over a wavy cross-section (bench problem).

    Unlike :func:`default_strip_problem` (cubics, planar end quadrilaterals) the ends are twisted
    too; the minimum of R lies on the box boundary in four of the six parameters
    (``a.mu = -1, a.nu = 1, a.gamma = -1, b.nu = 1``; θ_max 10.4° -> 9.5°).
    """
    A = GHTCurve([[0.0, 0.0, 0.0], [1.0, 0.6, 0.2], [2.0, -0.5, 0.1], [3.0, 0.7, -0.2], [4.0, 0.0, 0.0]])
    B = GHTCurve([[0.1, 0.2, 1.2], [1.1, 1.0, 1.0], [2.1, -0.1, 1.4], [2.9, 1.1, 0.9], [4.1, 0.3, 1.1]])
    return StripProblem(A, B, free=free, **kw)


def cone_strip_problem(free: Sequence[str] | None = None, **kw: Any) -> StripProblem:
    """A conical strip between two quartic arcs (radius 2 at z ≈ 0, radius 1.1 at z ≈ 1.5) with
    perturbed heights and angles (bench problem).

    The minimum of R is flat and has ``a.nu = a.gamma = -1``, ``b.nu = 1`` on the box boundary
    and ``a.mu, b.mu, b.gamma`` inside: a finish must land exactly on the bounds.
    """
    ang = np.radians([0.0, 30.0, 60.0, 90.0, 120.0])
    angb = np.radians([5.0, 40.0, 65.0, 95.0, 118.0])
    A = GHTCurve(np.column_stack([2.0 * np.cos(ang), 2.0 * np.sin(ang), [0.0, 0.15, -0.1, 0.2, 0.0]]))
    B = GHTCurve(np.column_stack([1.1 * np.cos(angb), 1.1 * np.sin(angb), [1.5, 1.3, 1.7, 1.45, 1.6]]))
    return StripProblem(A, B, free=free, **kw)
