r"""The developable loft's shape-parameter problem (spec sections 5.7, 8.1): :class:`LoftProblem`
optimizes the six shape parameters of two GHT rails for the loft's measures (fan share, fairness,
distance of the edge of regression), with exact gradients through the implicit-function theorem
(:func:`loft_measures_and_gradients`). Moved here from ``ght_cad.developables.loft``, which still gives these names."""

from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from ...core._validate import is_real
from ...core._vec import cross as _cross3
from ...core._quadrature import gauss_legendre
from ...curves.curve import GHTCurve
from ...core.errors import GHTError
from ...developables.loft.build import developable_loft
from ...developables.loft.equation import MIN_FAN
from ...developables.loft.rails import _det, _jet
from ...developables.loft.surface import DevelopableLoft, LoftSegment
from ...developables.loft.tracing import _at_corner
from ...surfaces.ruled import regression_v
from .base import CurveParameterJets, Problem


# ----------------------------------------------------------------------------------------------
# objectives for optimizing GHT rails' shape parameters
# ----------------------------------------------------------------------------------------------
LOFT_OBJECTIVES = ("fan_share", "fairness", "regression")


def _regression_penalty(loft: DevelopableLoft, margin: float, nodes: int = 32) -> float:
    r"""``∫_0^1 max(0, 1 - c(λ)/margin)² dλ`` with ``c`` the distance of ``v*(λ)`` from [0, 1]
    (fans' apexes excluded: a cone's apex on its rail is not an edge of regression between the
    rails)."""
    x, w = gauss_legendre(nodes)
    tot = 0.0
    for i, sg in enumerate(loft.segments):
        lo, hi = loft._edges[i], loft._edges[i + 1]
        if sg.kind != "main":
            continue
        vs = regression_v(sg.a(x, 1), sg.ruling(x), sg.ruling(x, 1))
        c = np.where(vs < 0, -vs, np.where(vs > 1, vs - 1, 0.0))
        c = np.where(np.isfinite(vs), c, np.inf)
        tot += float(np.sum(w * (hi - lo) * np.maximum(0.0, 1.0 - c / margin) ** 2))
    return tot


class LoftProblem(Problem):
    r"""Objectives of the developable loft over the shape parameters of two GHT rails.

    Parameters ``a.mu, a.nu, a.gamma, b.mu, b.nu, b.gamma``; for each candidate the loft is built
    (:func:`developable_loft`) and the objective is the weighted sum of

    * ``fan_share``: fan area / loft area (0 = rulings end to end),
    * ``fairness``: ``∫_0^1 |d'(λ)|² dλ``, d the unit ruling direction,
    * ``regression``: ``∫ max(0, 1 - c/margin)² dλ``, c the distance of the edge of regression
      parameter ``v*`` from [0, 1] on the main part (0 when it stays ``margin`` away),

    ``+inf`` where no loft exists (infeasible candidate). Usable with
    :func:`ght_cad.optimize.minimize` (``problem(X) -> (pop,)``); it has the attributes of
    :class:`ght_cad.optimize.problems.Problem` (names, lb, ub, x0, build, report).

    Gradients (:meth:`value_and_grad`, used by ``method="hybrid"``, spec 8.1): exact where the
    loft's structure is locally fixed (same chosen branch and orientation, same fans):
    :func:`loft_measures_and_gradients`. Where it is not, the objective itself is not
    differentiable and the gradient is as follows:

    * a branch end within ``MIN_FAN`` of a corner of the (t, s) square where F does not vanish (a
      fan appears or vanishes; for GHT rails the end tangents are ``∝ P_1 - P_0``, so F at a corner
      vanishes for all shape parameters or for none and this is a coincidence of measure zero) and
      a non-finite derivative (a zero ruling where the rails meet: ``|d'|²`` is a limit there;
      ``F_s = F_t`` on the branch): forward finite differences, reason in :attr:`fallbacks`,
      evaluations in :attr:`fallback_nfev`;
    * a switch of the chosen branch or orientation between candidates (:func:`developable_loft`
      ranks them), or the regression penalty where ``v*`` touches [0, 1] (a kink): not detected;
      the gradient is that of the loft built at the point (one-sided).
    

    Args:
        rail_a, rail_b: 3-D GHTCurve objects with the 'ght' seed.
        objective: a name of :data:`LOFT_OBJECTIVES` or a mapping name -> weight.
        free, bounds: as in :class:`ght_cad.optimize.problems.Problem`.
        margin: regression margin (fraction of the ruling length).
        loft_options: passed to :func:`developable_loft`.
    """

    label = "loft"

    def __init__(
        self,
        rail_a: GHTCurve,
        rail_b: GHTCurve,
        objective: str | Mapping[str, float] = "fan_share",
        free: Sequence[str] | None = None,
        bounds: Mapping[str, tuple[float, float]] | None = None,
        *,
        margin: float = 0.25,
        loft_options: Mapping[str, Any] | None = None,
    ) -> None:
        for nm, c in (("rail_a", rail_a), ("rail_b", rail_b)):
            if not isinstance(c, GHTCurve) or c.dim != 3:
                raise GHTError(f"{nm} must be a 3-D GHTCurve to optimize its shape parameters, got {c!r}")
            if c.seed.name != "ght":
                raise GHTError(f"{nm} uses seed {c.seed.name!r}; shape-parameter problems need the 'ght' seed")
        if isinstance(objective, str):
            objective = {objective: 1.0}
        weights = dict(objective)
        for k, v in weights.items():
            if k not in LOFT_OBJECTIVES:
                raise GHTError(f"loft objective {k!r} is unknown; allowed: {', '.join(LOFT_OBJECTIVES)}")
            if not (is_real(v) and math.isfinite(v) and v >= 0):
                raise GHTError(f"weight {k}={v!r} is not allowed; weights are finite numbers >= 0")
        if not any(v > 0 for v in weights.values()):
            raise GHTError(f"objective={objective!r} has no positive weight")
        if not (is_real(margin) and math.isfinite(margin) and margin > 0):
            raise GHTError(f"margin={margin!r} is not allowed; it must be a finite number > 0")
        names = [f"{r}.{p}" for r in ("a", "b") for p in ("mu", "nu", "gamma")]
        super().__init__(names, list(rail_a.shape_parameters) + list(rail_b.shape_parameters), free, bounds)
        self.rail_a, self.rail_b = rail_a, rail_b
        self.weights = weights
        self.margin = float(margin)
        self.loft_options = dict(loft_options or {"samples": 33})
        self.label = "loft " + "+".join(weights)

    def rails(self, x: Any) -> tuple[GHTCurve, GHTCurve]:
        """The two rails for free parameters ``x``."""
        p = self.parameters(x)
        a = GHTCurve(self.rail_a.control_points, p["a.mu"], p["a.nu"], p["a.gamma"])
        b = GHTCurve(self.rail_b.control_points, p["b.mu"], p["b.nu"], p["b.gamma"])
        return a, b

    def _rails_full(self, row: np.ndarray) -> tuple[GHTCurve, GHTCurve]:
        return (GHTCurve(self.rail_a.control_points, *row[:3]), GHTCurve(self.rail_b.control_points, *row[3:]))

    def measures_of(self, loft: DevelopableLoft) -> dict[str, float]:
        """fan_share, fairness and regression of one loft."""
        return {
            "fan_share": float(loft.report.fan_share),
            "fairness": loft.fairness(),
            "regression": _regression_penalty(loft, self.margin),
        }

    def evaluate_full(self, F: np.ndarray) -> np.ndarray:
        out = np.empty(F.shape[0])
        for i, row in enumerate(F):
            try:
                if not np.all(np.abs(row) <= 1.0):
                    raise GHTError("outside the box")
                lf = developable_loft(*self._rails_full(row), **self.loft_options)
                m = self.measures_of(lf)
                out[i] = sum(w * m[k] for k, w in self.weights.items())
            except GHTError:
                out[i] = math.inf
        return np.where(np.isfinite(out), out, np.inf)

    #: exact gradients where the loft's structure is locally fixed, finite differences elsewhere
    has_gradient = True
    #: finite-difference step (box units) of the fallback
    fd_step = 1e-7

    def gradient_of(self, loft: DevelopableLoft, rail_a: GHTCurve, rail_b: GHTCurve) -> np.ndarray:
        r"""Exact gradient (6,) of the weighted objective of ``loft`` built from ``rail_a``, ``rail_b``
        with respect to ``(a.μ, a.ν, a.γ, b.μ, b.ν, b.γ)`` (:func:`loft_measures_and_gradients`).

        Raises:
            LoftGradientFallback: the loft's structure is not locally fixed (see there).
        """
        _, g = loft_measures_and_gradients(loft, rail_a, rail_b, self.margin)
        return sum(w * g[k] for k, w in self.weights.items())

    def value_and_grad_full(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        r"""Values (pop,) (those of :meth:`evaluate_full`) and gradients (pop, 6).

        Exact (:meth:`gradient_of`: implicit-function derivative of the traced branch plus the
        moving-breakpoint terms) where the loft's structure is locally fixed; for a candidate where
        it is not (:class:`LoftGradientFallback`: a branch end at a box corner where F does not
        vanish, a zero ruling, F_s = F_t) forward differences of step :attr:`fd_step` inwards
        (6 more lofts; counted in :attr:`fallback_nfev`, the reason in :attr:`fallbacks`). ``0`` where
        the value is ``+inf``.
        """
        F = np.atleast_2d(np.asarray(F, dtype=float))
        out = np.empty(F.shape[0])
        G = np.zeros(F.shape)
        for i, row in enumerate(F):
            try:
                if not np.all(np.abs(row) <= 1.0):
                    raise GHTError("outside the box")
                ca, cb = self._rails_full(row)
                lf = developable_loft(ca, cb, **self.loft_options)
                m = self.measures_of(lf)
                out[i] = sum(w * m[k] for k, w in self.weights.items())
            except GHTError:
                out[i] = math.inf
                continue
            if not math.isfinite(out[i]):
                out[i] = math.inf
                continue
            try:
                with np.errstate(all="ignore"):
                    G[i] = self.gradient_of(lf, ca, cb)
            except LoftGradientFallback as exc:
                self.fallbacks.append(str(exc))
                steps = np.where(row + self.fd_step <= 1.0, self.fd_step, -self.fd_step)
                Xs = np.repeat(row[None, :], 6, axis=0) + np.diag(steps)
                fs = self.evaluate_full(Xs)
                self.fallback_nfev += 6
                with np.errstate(invalid="ignore"):
                    G[i] = np.where(np.isfinite(fs), (fs - out[i]) / steps, 0.0)
        return out, G

    @property
    def fallbacks(self) -> list[str]:
        """Why :meth:`value_and_grad_full` used finite differences, per fallback candidate."""
        if not hasattr(self, "_fallbacks"):
            self._fallbacks: list[str] = []
        return self._fallbacks

    @property
    def fallback_nfev(self) -> int:
        """Loft evaluations spent on finite-difference fallbacks (not counted by the optimizer)."""
        return int(getattr(self, "_fallback_nfev", 0))

    @fallback_nfev.setter
    def fallback_nfev(self, v: int) -> None:
        self._fallback_nfev = int(v)

    def build(self, x: Any) -> DevelopableLoft:
        """The loft for free parameters ``x``."""
        return developable_loft(*self.rails(x), **self.loft_options)

    def report(self, x: Any) -> dict[str, float]:
        """The objective and all three measures at ``x`` (inf where no loft exists)."""
        try:
            lf = self.build(x)
        except GHTError:
            return {"objective": math.inf, **{k: math.inf for k in LOFT_OBJECTIVES}}
        m = self.measures_of(lf)
        return {"objective": sum(w * m[k] for k, w in self.weights.items()), **m}


# ----------------------------------------------------------------------------------------------
# exact shape-parameter gradients of the loft objectives (spec 8.1)
# ----------------------------------------------------------------------------------------------
class LoftGradientFallback(GHTError):
    """The loft's structure is not locally fixed at this candidate (no exact gradient): the reason."""


def _rail_parameter_jets(curve: GHTCurve, t: np.ndarray, k: int, reverse: bool) -> list[np.ndarray]:
    r"""``∂r^(q)/∂(μ, ν, γ)`` at ``t`` for q = 0..k, each (3, N, 3) (closed form,
    :class:`ght_cad.optimize.problems.CurveParameterJets`); for the reversed rail ``r~(s) = r(1-s)``,
    ``∂r~^(q)(s) = (-1)^q ∂r^(q)(1-s)``."""
    x = 1.0 - t if reverse else t
    J = CurveParameterJets(x, curve.control_points, k)(np.array([curve.mu]), np.array([curve.nu]),
                                                       np.array([curve.gamma]), tuple(range(k + 1)))
    return [((-1.0) ** q if reverse else 1.0) * J[q][:, 0] for q in range(k + 1)]


def _det6(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """:func:`_det` broadcast over a leading parameter axis: (..., N, 3) -> (..., N)."""
    return np.einsum("...i,...i->...", x, _cross3(y, z))


class _LoftJets:
    r"""Along the loft at path parameters ``lam`` of one segment: the rails' jets, the path
    ``t, s, t_λ, s_λ`` and their total derivatives with respect to the six shape parameters
    ``p = (a.μ, a.ν, a.γ, b.μ, b.ν, b.γ)`` at fixed λ.

    On the main part the path solves ``F(t, s; p) = 0``, ``t + s = 2λ``; at fixed λ
    ``∂t/∂p = -F_p / (F_t - F_s)``, ``∂s/∂p = -∂t/∂p`` (implicit function theorem), and from
    ``t_λ = 2 F_s / (F_s - F_t)``: ``∂t_λ/∂p = 2 (F_s δF_t - F_t δF_s) / (F_s - F_t)²`` with
    ``δF_t = F_tp + (F_tt - F_ts) ∂t/∂p``, ``δF_s = F_sp + (F_ts - F_ss) ∂t/∂p``, ``s_λ = 2 - t_λ``;
    ``F_p = det(a'_p, b', g) + det(a', b'_p, g) + det(a', b', b_p - a_p)``,
    ``F_tp = det(a''_p, b', g) + det(a'', b'_p, g) + det(a'', b', b_p - a_p)``,
    ``F_sp = det(a'_p, b'', g) + det(a', b''_p, g) + det(a', b'', b_p - a_p)``. On a fan (t or s
    fixed at a side, the other linear in λ) the path does not move with p.

    Attributes (each (6, N, 3) or (N, 3)): ``al`` = a_λ, ``g`` = b - a, ``gl`` = g_λ and their
    derivatives ``dal``, ``dg``, ``dgl``.
    """

    def __init__(self, lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, sg: LoftSegment, lam: np.ndarray) -> None:
        pair = lf._pair
        n = lam.size
        z, one = np.zeros(n), np.ones(n)
        tll = sll = z
        if sg.kind == "main":
            (t, tl, tll), (s, sl, sll), _ = lf._path.main(lam, 2)
        elif sg.side == "s=0":
            t, tl, s, sl = 2 * lam, 2 * one, z, z
        elif sg.side == "t=0":
            t, tl, s, sl = z, z, 2 * lam, 2 * one
        elif sg.side == "t=1":
            t, tl, s, sl = one, z, 2 * lam - 1.0, 2 * one
        else:
            t, tl, s, sl = 2 * lam - 1.0, 2 * one, one, z
        t, s = np.clip(t, 0.0, 1.0), np.clip(s, 0.0, 1.0)
        A = _jet(pair.ra, t, 2)
        B = _jet(pair.rb, s, 2)
        dA = [np.concatenate([x, np.zeros_like(x)]) for x in _rail_parameter_jets(ca, t, 2, False)]
        dB = [np.concatenate([np.zeros_like(x), x]) for x in _rail_parameter_jets(cb, s, 2, lf.reversed_b)]
        g = B[0] - A[0]
        Tp = np.zeros((6, n))
        dTl = np.zeros((6, n))
        if sg.kind == "main":
            p = pair.parts(t, s, 2)
            dg0 = dB[0] - dA[0]
            Fp = _det6(dA[1], B[1], g) + _det6(A[1], dB[1], g) + _det6(A[1], B[1], dg0)
            Ftp = _det6(dA[2], B[1], g) + _det6(A[2], dB[1], g) + _det6(A[2], B[1], dg0)
            Fsp = _det6(dA[1], B[2], g) + _det6(A[1], dB[2], g) + _det6(A[1], B[2], dg0)
            Ft, Fs = p["Ft"], p["Fs"]
            den = Fs - Ft
            Tp = Fp / den
            dFt = Ftp + (p["Ftt"] - p["Fts"]) * Tp
            dFs = Fsp + (p["Fts"] - p["Fss"]) * Tp
            dTl = 2.0 * (Fs * dFt - Ft * dFs) / den**2
        Sp, dSl = -Tp, -dTl
        dA0 = dA[0] + A[1] * Tp[..., None]
        dA1 = dA[1] + A[2] * Tp[..., None]
        dB0 = dB[0] + B[1] * Sp[..., None]
        dB1 = dB[1] + B[2] * Sp[..., None]
        self.al = A[1] * tl[:, None]
        bl = B[1] * sl[:, None]
        self.g = g
        self.gl = bl - self.al
        self.dal = dA1 * tl[:, None] + A[1] * dTl[..., None]
        dbl = dB1 * sl[:, None] + B[1] * dSl[..., None]
        self.dg = dB0 - dA0
        self.dgl = dbl - self.dal
        # second λ-derivatives (for the moving quadrature nodes of the regression penalty)
        self.all = A[2] * (tl**2)[:, None] + A[1] * tll[:, None]
        self.gll = B[2] * (sl**2)[:, None] + B[1] * sll[:, None] - self.all

    def part(self, sl: slice) -> "_LoftJets":
        """The same quantities at a subset of the nodes."""
        out = object.__new__(_LoftJets)
        for k in ("al", "g", "gl", "all", "gll"):
            setattr(out, k, getattr(self, k)[sl])
        for k in ("dal", "dg", "dgl"):
            setattr(out, k, getattr(self, k)[:, sl])
        return out

    # integrands q(λ) and their derivatives at fixed λ
    def area(self) -> tuple[np.ndarray, np.ndarray]:
        r"""``ρ = Σ_v w_v |(a_λ + v g_λ) × g|`` (16-node Gauss–Legendre in v, as :func:`ght_cad.unroll.ruled_area`)
        and ``∂ρ = Σ_v w_v c_v·∂c_v / |c_v|``."""
        tv, wv = gauss_legendre(16)
        ca_, cg_ = _cross3(self.al, self.g), _cross3(self.gl, self.g)  # c_v = ca + v cg
        dca = _cross3(self.dal, self.g) + _cross3(self.al, self.dg)
        dcg = _cross3(self.dgl, self.g) + _cross3(self.gl, self.dg)
        rho = np.zeros(self.g.shape[0])
        drho = np.zeros((6, self.g.shape[0]))
        for v, w in zip(tv, wv):
            c = ca_ + v * cg_
            nc = np.sqrt(np.sum(c * c, axis=-1))
            rho += w * nc
            drho += (w / nc) * (np.einsum("nd,pnd->pn", c, dca) + v * np.einsum("nd,pnd->pn", c, dcg))
        return rho, drho

    def fairness(self) -> tuple[np.ndarray, np.ndarray]:
        r"""``h = |d_λ|² = |g_λ|²/|g|² - (g·g_λ)²/|g|⁴`` (d = g/|g|) and its derivative."""
        A_ = np.sum(self.gl * self.gl, axis=-1)
        B_ = np.sum(self.g * self.gl, axis=-1)
        C_ = np.sum(self.g * self.g, axis=-1)
        dA_ = 2.0 * np.einsum("nd,pnd->pn", self.gl, self.dgl)
        dB_ = np.einsum("pnd,nd->pn", self.dg, self.gl) + np.einsum("nd,pnd->pn", self.g, self.dgl)
        dC_ = 2.0 * np.einsum("nd,pnd->pn", self.g, self.dg)
        h = A_ / C_ - B_**2 / C_**2
        dh = dA_ / C_ - A_ * dC_ / C_**2 - 2.0 * B_ * dB_ / C_**2 + 2.0 * B_**2 * dC_ / C_**3
        return h, dh

    def regression(self, margin: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        r"""``q = max(0, 1 - c/margin)²``, ``c = dist(v*, [0, 1])``, ``v* = -(c1·c2)/|c2|²``,
        ``c1 = a_λ × g``, ``c2 = g_λ × g`` (:func:`ght_cad.surfaces.ruled.regression_v`), its derivative at
        fixed λ (``dc/dv* = -1`` below 0, ``+1`` above 1) and ``q_λ`` (``c1_λ = a_λλ × g + a_λ × g_λ``,
        ``c2_λ = g_λλ × g``): q is only C¹ in λ, so the penalty's quadrature is differentiated
        node by node (moving nodes) rather than as the exact integral."""
        c1 = _cross3(self.al, self.g)
        c2 = _cross3(self.gl, self.g)
        dc1 = _cross3(self.dal, self.g) + _cross3(self.al, self.dg)
        dc2 = _cross3(self.dgl, self.g) + _cross3(self.gl, self.dg)
        num = np.sum(c1 * c2, axis=-1)
        den = np.sum(c2 * c2, axis=-1)
        vs = regression_v(self.al, self.g, self.gl)
        fin = np.isfinite(vs)
        with np.errstate(divide="ignore", invalid="ignore"):
            dvs = -(np.einsum("pnd,nd->pn", dc1, c2) + np.einsum("nd,pnd->pn", c1, dc2)) / den \
                + num * 2.0 * np.einsum("nd,pnd->pn", c2, dc2) / den**2
        c = np.where(vs < 0, -vs, np.where(vs > 1, vs - 1, 0.0))
        sgn = np.where(vs < 0, -1.0, np.where(vs > 1, 1.0, 0.0))
        c = np.where(fin, c, np.inf)
        m = np.maximum(0.0, 1.0 - c / margin)
        q = m**2
        slope = np.where(fin & (m > 0), -2.0 * m / margin * sgn, 0.0)
        dq = slope * np.where(fin, dvs, 0.0)
        c1l = _cross3(self.all, self.g) + _cross3(self.al, self.gl)
        c2l = _cross3(self.gll, self.g)
        with np.errstate(divide="ignore", invalid="ignore"):
            vl = -(np.sum(c1l * c2, axis=-1) + np.sum(c1 * c2l, axis=-1)) / den \
                + num * 2.0 * np.sum(c2 * c2l, axis=-1) / den**2
        ql = slope * np.where(fin, vl, 0.0)
        return q, dq, ql


def _side_shift(lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, t: float, s: float, end: str) -> np.ndarray:
    r"""``∂λ/∂p`` of a branch end (6,): on ``s = 0`` or ``s = 1`` ``F(t, s; p) = 0`` gives
    ``∂t/∂p = -F_p/F_t``, on ``t = 0`` or ``t = 1`` ``∂s/∂p = -F_p/F_s`` (``λ = (t + s)/2``); a branch
    end at a corner where ``F`` vanishes to round-off, or where the rails meet (a pointed end:
    they meet there for every shape parameter), stays there (``0``).

    Raises:
        LoftGradientFallback: an end at (within MIN_FAN of) a corner where F does not vanish (a fan
            appears or vanishes there: the objective is not differentiable).
    """
    pair = lf._pair
    tt, ss = np.array([t]), np.array([s])
    if end == "start":
        at_t, at_s = t <= MIN_FAN, s <= MIN_FAN  # on the side t = 0 / s = 0
    else:
        at_t, at_s = t >= 1.0 - MIN_FAN, s >= 1.0 - MIN_FAN  # on the side t = 1 / s = 1
    if at_t and at_s:
        if _at_corner(pair, t, s):  # the rails meet there for every shape parameter (a GHT curve
            return np.zeros(6)      # interpolates its end points): the end stays at the corner
        p = pair.parts(tt, ss, 1)
        if abs(float(p["F"][0])) <= 64 * float(p["noise"][0]) + 1e-13 * float(p["scale"][0]):
            return np.zeros(6)
        raise LoftGradientFallback(f"the branch {end}s at the corner (t, s) = ({t:.3g}, {s:.3g}) where F does not vanish "
                                   "identically: a fan appears or vanishes there")
    A = _jet(pair.ra, tt, 2)
    B = _jet(pair.rb, ss, 2)
    dA = [np.concatenate([x, np.zeros_like(x)]) for x in _rail_parameter_jets(ca, tt, 1, False)]
    dB = [np.concatenate([np.zeros_like(x), x]) for x in _rail_parameter_jets(cb, ss, 1, lf.reversed_b)]
    g = B[0] - A[0]
    Fp = (_det6(dA[1], B[1], g) + _det6(A[1], dB[1], g) + _det6(A[1], B[1], dB[0] - dA[0]))[:, 0]
    if at_s:  # s fixed on the side: t moves
        Ft = float(_det(A[2], B[1], g)[0])
        return -Fp / Ft / 2.0
    Fs = float(_det(A[1], B[2], g)[0])
    return -Fp / Fs / 2.0


def loft_measures_and_gradients(lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, margin: float = 0.25,
                                nodes: int = 32, area_nodes: int = 64) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    r"""The loft objectives of :class:`LoftProblem` and their exact gradients with respect to
    ``(a.μ, a.ν, a.γ, b.μ, b.ν, b.γ)`` where the loft's structure is locally fixed.

    Each measure is a sum over segments of ``I = ∫_{λ_lo}^{λ_hi} q(λ; p) dλ`` (area density
    ``ρ``, ruling fairness ``|d_λ|²``, regression penalty on the main part), so
    ``∂I/∂p = ∫ ∂q/∂p|_λ dλ + q(λ_hi) ∂λ_hi/∂p - q(λ_lo) ∂λ_lo/∂p``: the integrand's derivative at
    fixed λ (:class:`_LoftJets`: implicit-function derivative of the path on the main part) plus the
    boundary terms of the moving breakpoints (:func:`_side_shift`). ``fan_share = A_fan / A`` gives
    ``(∂A_fan A - A_fan ∂A) / A²``. Integrals by Gauss–Legendre: ``nodes`` per segment (as the
    measures themselves), ``area_nodes`` for the area derivative (the area is adaptive to 1e-13).

    Returns:
        ``(measures, gradients)``: ``{"fan_share", "fairness", "regression"}`` (measures as
        :meth:`LoftProblem.measures_of`) and the (6,) gradient of each.

    Raises:
        LoftGradientFallback: the structure changes at this candidate (a branch end at a corner
            where F does not vanish) or a quantity is singular (zero ruling, F_s = F_t on the
            branch, a non-finite derivative); the caller falls back to finite differences.
    """
    with np.errstate(all="ignore"):
        return _loft_measures_and_gradients(lf, ca, cb, margin, nodes, area_nodes)


def _loft_measures_and_gradients(lf: DevelopableLoft, ca: GHTCurve, cb: GHTCurve, margin: float, nodes: int,
                                 area_nodes: int) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    x, w = gauss_legendre(nodes)
    xa, wa = gauss_legendre(area_nodes)
    (t0, s0), (t1, s1) = lf._branch.start, lf._branch.end
    shift = {"start": _side_shift(lf, ca, cb, t0, s0, "start"), "end": _side_shift(lf, ca, cb, t1, s1, "end")}
    zero = np.zeros(6)
    grads = {k: np.zeros(6) for k in ("fan_area", "area", "fairness", "regression")}
    for i, sg in enumerate(lf.segments):
        lo, hi = lf._edges[i], lf._edges[i + 1]
        # the outer edges are λ = 0, 1; an inner edge is the branch start λ0 or its end λ1
        dlo = zero if i == 0 else (shift["start"] if sg.kind == "main" else shift["end"])
        dhi = zero if i == len(lf.segments) - 1 else (shift["end"] if sg.kind == "main" else shift["start"])
        L = hi - lo
        nq, na = x.size, xa.size
        jall = _LoftJets(lf, ca, cb, sg, np.concatenate([[lo, hi], lo + L * x, lo + L * xa]))
        je, jq, ja = jall.part(slice(0, 2)), jall.part(slice(2, 2 + nq)), jall.part(slice(2 + nq, 2 + nq + na))
        rho, drho = ja.area()
        rho_e, _ = je.area()
        dA = L * (drho @ wa) + rho_e[1] * dhi - rho_e[0] * dlo
        grads["area"] += dA
        if sg.kind != "main":
            grads["fan_area"] += dA
        h, dh = jq.fairness()
        h_e, _ = je.fairness()
        grads["fairness"] += L * (dh @ w) + h_e[1] * dhi - h_e[0] * dlo
        if sg.kind == "main":
            # the penalty's own quadrature differentiated with its nodes λ_j = lo + x_j L moving
            q, dq, ql = jq.regression(margin)
            dnode = dlo[:, None] + x[None, :] * (dhi - dlo)[:, None]
            grads["regression"] += (dhi - dlo) * (q @ w) + L * ((dq + ql[None, :] * dnode) @ w)
    area, fan = lf.report.area, lf.report.fan_area
    out = {
        "fan_share": (grads["fan_area"] * area - fan * grads["area"]) / area**2,
        "fairness": grads["fairness"],
        "regression": grads["regression"],
    }
    for k, v in out.items():
        if not np.all(np.isfinite(v)):
            raise LoftGradientFallback(f"the derivative of {k} is not finite here (zero ruling or F_s = F_t on the branch)")
    measures = {"fan_share": float(lf.report.fan_share), "fairness": lf.fairness(),
                "regression": _regression_penalty(lf, margin)}
    return measures, out
