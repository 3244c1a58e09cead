"""The loft as a result (spec section 5.7): its segments (fans and main part) as ruled surfaces,
the report, and :class:`DevelopableLoft`, one ruled surface over the whole path."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ...core._validate import as_parameter_array
from ...core._quadrature import gauss_legendre
from ...core.errors import GHTError
from ...surfaces.ruled import Developability, RuledSurface, regression_v
from .equation import MIN_FAN, _EPS, _Pair
from .rails import _jet
from .tracing import _Branch, _Path


class LoftSegment(RuledSurface):
    r"""One piece of a developable loft: a fan (cone with apex at a rail end) or the main part.

    ``X(u, v) = (1-v) a(t(λ)) + v b(s(λ))``, ``λ = λ0 + u (λ1 - λ0)``, u ∈ [0, 1], with the path
    of the loft in the (t, s) square (module doc). ``kind`` is ``"fan_a"`` (apex on rail a: t
    constant), ``"fan_b"`` (apex on rail b: s constant) or ``"main"`` (the traced branch
    ``F(t, σ(t)) = 0``). ``a``, ``b`` are rail a and rail b in their given orientation.

    Attributes:
        kind, lam_range, t_range, s_range (parameters on the given rails), apex (3-D point or None).
    """

    def __init__(self, loft: "DevelopableLoft", kind: str, lam0: float, lam1: float, side: str | None = None) -> None:
        self._loft = loft
        self.kind = kind
        self.side = side  # for fans: "s=0", "t=0", "t=1", "s=1"
        self.lam_range = (float(lam0), float(lam1))

    # path parameters (internal orientation: rail b possibly reversed)
    def _ts(self, u: np.ndarray, k: int) -> tuple[list[np.ndarray], list[np.ndarray]]:
        lam0, lam1 = self.lam_range
        dl = lam1 - lam0
        lam = lam0 + u * dl
        if self.kind == "main":
            tt, ss, _ = self._loft._path.main(lam, k)
        else:
            z = np.zeros_like(lam)
            one = np.ones_like(lam)
            if self.side == "s=0":
                tt, ss = [2 * lam, 2 * one], [z, z]
            elif self.side == "t=0":
                tt, ss = [z, z], [2 * lam, 2 * one]
            elif self.side == "t=1":
                tt, ss = [one, z], [2 * lam - 1.0, 2 * one]
            else:  # s=1
                tt, ss = [2 * lam - 1.0, 2 * one], [one, z]
            tt = tt + [z] * k
            ss = ss + [z] * k
        tt = [np.clip(tt[0], 0.0, 1.0)] + [tt[r] * dl**r for r in range(1, k + 1)]
        ss = [np.clip(ss[0], 0.0, 1.0)] + [ss[r] * dl**r for r in range(1, k + 1)]
        return tt, ss

    @staticmethod
    def _compose(rail: Any, x: list[np.ndarray], r: int) -> np.ndarray:
        """``d^r/du^r rail(x(u))`` for r = 0, 1, 2 (Faà di Bruno)."""
        if r == 0:
            return rail.derivative(x[0], 0)
        if r == 1:
            return rail.derivative(x[0], 1) * x[1][:, None]
        if r == 2:
            J = _jet(rail, x[0], 2)
            return J[2] * (x[1] ** 2)[:, None] + J[1] * x[2][:, None]
        raise GHTError(f"derivative={r!r} is not allowed; loft segments give derivatives of order 0..2")

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        tt, _ = self._ts(uu, derivative)
        return self._compose(self._loft._pair.ra, tt, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        _, ss = self._ts(uu, derivative)
        return self._compose(self._loft._pair.rb, ss, derivative)

    def ruling(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``g = b - a``; near a corner where the rails meet (a pointed end) the ruling is the
        branch's own, integrated from the corner without cancellation (:meth:`_Pair.corner_branch`):
        the plain difference carries ``eps |a|``, i.e. the direction ``eps |a| / |g|``."""
        g = self.b(u, derivative) - self.a(u, derivative)
        path = self._loft._path
        if derivative or self.kind != "main" or not path.corner_ends:
            return g
        uu, _ = as_parameter_array(u, "u")
        lam0, lam1 = self.lam_range
        lam = lam0 + uu * (lam1 - lam0)
        near = path.near_corner(lam)
        if near is not None and near.any():
            g[near] = path.main(lam[near], 0)[2]["g"]
        return g

    def parameters(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        """Rail parameters ``(t, s)`` of the rulings at ``u`` (s on rail b as given)."""
        uu, _ = as_parameter_array(u, "u")
        tt, ss = self._ts(uu, 0)
        return tt[0], self._loft._given_s(ss[0])

    @property
    def t_range(self) -> tuple[float, float]:
        t, _ = self.parameters(np.array([0.0, 1.0]))
        return float(t[0]), float(t[1])

    @property
    def s_range(self) -> tuple[float, float]:
        _, s = self.parameters(np.array([0.0, 1.0]))
        return float(s[0]), float(s[1])

    @property
    def end_order(self) -> int:
        """Highest end derivative order that is exact at both ends: 2, or 1 where the rails meet
        at an end of the segment (a zero ruling: the second derivative there is a limit known to
        about 1e-3 only)."""
        g = self.ruling_lengths(np.array([0.0, 1.0]))
        return 1 if float(g.min()) <= 1e-9 * self._loft._pair.size else 2

    @property
    def apex(self) -> np.ndarray | None:
        """The cone apex (a rail end) of a fan; None for the main part."""
        if self.kind == "fan_a":
            return self.a(np.array([0.5]))[0]
        if self.kind == "fan_b":
            return self.b(np.array([0.5]))[0]
        return None

    def __repr__(self) -> str:
        t0, t1 = self.t_range
        s0, s1 = self.s_range
        return f"LoftSegment({self.kind}, t=[{t0:.6g}, {t1:.6g}], s=[{s0:.6g}, {s1:.6g}])"


# ----------------------------------------------------------------------------------------------
# report
# ----------------------------------------------------------------------------------------------
@dataclass
class LoftReport:
    r"""What the loft construction found (spec section 5.7).

    Attributes:
        reversed_b: rail b was traced reversed (the rails run opposite ways).
        branch_start, branch_end: (t, s) where the branch meets the lower-left / upper-right sides
            (s on rail b as given).
        nodes: number of traced branch nodes (predictor–corrector steps + 1).
        segments: per segment: kind, t and s ranges, apex, area.
        area: 3-D area of the loft; fan_area, fan_share = fan_area / area.
        theta_max_deg: max θ over ``samples`` rulings per segment (round-off expected).
        f_residual_max: max ``|F| / (|a'||b'||b - a|)`` at those rulings.
        theta: (λ, t, s, θ in degrees) of the sampled rulings.
        degenerate_rulings: rulings with ``|b - a|`` below 1e-9 of the size, or a rail tangent
            parallel to the ruling (sine below 1e-9): dicts with t, s, kind, value.
        regression: sampled rulings with the edge of regression between the rails,
            ``v* = -((a' × g)·(g' × g)) / |g' × g|²`` in [0, 1]: dicts with t, s, v, point.
        regression_clearance: min over the sampled rulings of the distance of ``v*`` from [0, 1]
            (0 when the edge of regression meets the loft; inf for a cylinder-like loft).
        candidates: every branch tried: start, end, orientation, fan_share or why it was refused.
    """

    reversed_b: bool
    branch_start: tuple[float, float]
    branch_end: tuple[float, float]
    nodes: int
    segments: list[dict[str, Any]]
    area: float
    fan_area: float
    fan_share: float
    theta_max_deg: float
    f_residual_max: float
    theta: np.ndarray = field(repr=False)
    degenerate_rulings: list[dict[str, Any]] = field(default_factory=list)
    regression: list[dict[str, Any]] = field(default_factory=list)
    regression_clearance: float = math.inf
    candidates: list[dict[str, Any]] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        """Plain data (floats, lists, dicts) for JSON reports."""
        d = asdict(self)
        d["theta"] = np.asarray(self.theta).tolist()
        return _plain(d)

    def __str__(self) -> str:
        kinds = ", ".join(f"{s['kind']} t=[{s['t'][0]:.4g},{s['t'][1]:.4g}] s=[{s['s'][0]:.4g},{s['s'][1]:.4g}]"
                          for s in self.segments)
        return (
            f"developable loft: {len(self.segments)} segment(s) ({kinds}); fan share {self.fan_share:.4g}; "
            f"θ_max={self.theta_max_deg:.3g}°; |F| residual {self.f_residual_max:.2g}; "
            f"{len(self.degenerate_rulings)} degenerate ruling(s); edge of regression "
            + ("between the rails" if self.regression else f"clear (margin {self.regression_clearance:.3g})")
        )


def _plain(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    return x


# ----------------------------------------------------------------------------------------------
# the loft
# ----------------------------------------------------------------------------------------------
class DevelopableLoft(RuledSurface):
    r"""The exact developable loft between two rails (spec section 5.7), fans included.

    As a whole it is one ruled surface ``X(λ, v) = (1-v) a(t(λ)) + v b(s(λ))``, λ ∈ [0, 1]
    (``λ = (t + s)/2`` along the path from corner (0, 0) to (1, 1) of the (t, s) square, module
    doc), smooth inside each segment and G1 across the joint rulings (listed in
    ``breakpoints``), so :func:`ght_cad.unroll` gives one panel with bend lines along the
    rulings. ``segments`` are the fans and the main part in order along the rails.

    Do not construct directly: use :func:`developable_loft`.

    Attributes:
        rail_a, rail_b: the rails as given.
        segments: :class:`LoftSegment` list (RuledSurface instances).
        report: :class:`LoftReport`.
        breakpoints: λ of the joint rulings (inside (0, 1)).
    """

    def __init__(self, rail_a: Any, rail_b: Any, pair: _Pair, branch: _Branch, *, samples: int = 257,
                 candidates: Sequence[dict[str, Any]] = (), area_rtol: float = 1e-13) -> None:
        self.rail_a = rail_a
        self.rail_b = rail_b
        self._pair = pair
        self._branch = branch
        self.reversed_b = branch.reversed_b
        self._path = _Path(pair, branch)
        (t0, s0), (t1, s1) = branch.start, branch.end
        segs: list[LoftSegment] = []
        lam0, lam1 = self._path.lam0, self._path.lam1
        if t0 > MIN_FAN:
            segs.append(LoftSegment(self, "fan_b", 0.0, lam0, "s=0"))
        elif s0 > MIN_FAN:
            segs.append(LoftSegment(self, "fan_a", 0.0, lam0, "t=0"))
        if lam1 - lam0 > MIN_FAN:
            segs.append(LoftSegment(self, "main", lam0, lam1))
        if t1 < 1.0 - MIN_FAN:
            segs.append(LoftSegment(self, "fan_b", lam1, 1.0, "s=1"))
        elif s1 < 1.0 - MIN_FAN:
            segs.append(LoftSegment(self, "fan_a", lam1, 1.0, "t=1"))
        self.segments: list[LoftSegment] = segs
        self._edges = np.array([segs[0].lam_range[0]] + [sg.lam_range[1] for sg in segs])
        self._edges[0], self._edges[-1] = 0.0, 1.0
        self.breakpoints = tuple(float(x) for x in self._edges[1:-1])
        self.report = self._make_report(samples, list(candidates), area_rtol)

    # -- parametrization -----------------------------------------------------------------
    def _given_s(self, s: np.ndarray) -> np.ndarray:
        return 1.0 - s if self.reversed_b else s

    def _dispatch(self, u: Any, fn: Callable[[LoftSegment, np.ndarray], np.ndarray]) -> np.ndarray:
        uu, _ = as_parameter_array(u, "u")
        idx = np.clip(np.searchsorted(self._edges, uu, side="right") - 1, 0, len(self.segments) - 1)
        out = np.empty((uu.size, 3))
        for i, sg in enumerate(self.segments):
            m = idx == i
            if m.any():
                lo, hi = self._edges[i], self._edges[i + 1]
                out[m] = fn(sg, (uu[m] - lo) / (hi - lo), hi - lo)
        return out

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Rail a along the loft: ``a(t(λ))`` and its λ-derivatives."""
        return self._dispatch(u, lambda sg, x, w: sg.a(x, derivative) / w**derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        """Rail b along the loft: ``b(s(λ))`` and its λ-derivatives."""
        return self._dispatch(u, lambda sg, x, w: sg.b(x, derivative) / w**derivative)

    def ruling(self, u: Any, derivative: int = 0) -> np.ndarray:
        """``g = b - a`` (near a pointed end the segment's cancellation-free ruling, :meth:`LoftSegment.ruling`)."""
        if not self._path.corner_ends:
            return super().ruling(u, derivative)
        return self._dispatch(u, lambda sg, x, w: sg.ruling(x, derivative) / w**derivative)

    def parameters(self, u: Any) -> tuple[np.ndarray, np.ndarray]:
        """Rail parameters ``(t, s)`` of the rulings at loft parameters ``u`` (= λ)."""
        uu, _ = as_parameter_array(u, "u")
        ts = self._dispatch(uu, lambda sg, x, w: np.column_stack([*sg.parameters(x), np.zeros(x.size)]))
        return ts[:, 0], ts[:, 1]

    def sigma(self, t: Any) -> np.ndarray:
        r"""``s = σ(t)``: the parameter on rail b (as given) of the ruling from ``a(t)``.

        On the main part ``F(t, σ(t)) = 0`` solved by Newton in s to round-off; where a(t) is
        covered by a fan with apex on rail b it is that apex's parameter (0 or 1); at an end of
        rail a that is a fan apex itself, the end of the branch.
        """
        tt, scalar = as_parameter_array(t, "t")
        if np.any((tt < 0) | (tt > 1)) or not np.all(np.isfinite(tt)):
            raise GHTError("t must be finite and in [0, 1]")
        br = self._branch
        (t0, s0), (t1, s1) = br.start, br.end
        s = np.interp(tt, br.t, br.s)
        s = np.where(tt <= t0, s0 if t0 <= MIN_FAN else 0.0, s)
        s = np.where(tt >= t1, s1 if t1 >= 1 - MIN_FAN else 1.0, s)
        inner = (tt > t0) & (tt < t1)
        if inner.any():
            ti, si = tt[inner], s[inner]
            for _ in range(8):
                p = self._pair.parts(ti, si, 1)
                with np.errstate(divide="ignore", invalid="ignore"):
                    ds = np.where(p["Fs"] != 0, p["F"] / p["Fs"], 0.0)
                si = np.clip(si - ds, 0.0, 1.0)
                if np.all(np.abs(ds) <= 4 * _EPS):
                    break
            s[inner] = si
        out = self._given_s(s)
        return out[0] if scalar else out

    # -- measures ------------------------------------------------------------------------
    def developability(self, nodes: int = 64, samples: int = 257) -> Developability:
        """Developability degree of the whole loft, per segment combined (θ_max over all rulings;
        integrals weighted by the segments' λ-lengths)."""
        parts = [sg.developability(nodes, samples) for sg in self.segments]
        w = np.diff(self._edges)
        w = w / w.sum()
        th = [p.theta_max for p in parts if math.isfinite(p.theta_max)]
        return Developability(
            theta_max=max(th) if th else math.nan,
            theta_rms=float(math.sqrt(sum(wi * p.theta_rms**2 for wi, p in zip(w, parts) if math.isfinite(p.theta_rms)))),
            dd=float(sum(wi * p.dd for wi, p in zip(w, parts) if math.isfinite(p.dd))),
            R=float(sum(wi * p.R for wi, p in zip(w, parts) if math.isfinite(p.R))),
            residual_max=max(p.residual_max for p in parts),
        )

    def area(self) -> float:
        """3-D area, sum over the segments of ``∫∫ |(a' + v g') × g| dv du``."""
        from ...unrolling.unroll import ruled_area

        return float(sum(ruled_area(sg, rtol=1e-13) for sg in self.segments))

    def ruling_field(self, u: Any) -> dict[str, np.ndarray]:
        """Unit ruling direction ``d = g/|g|`` and its λ-derivative ``d' = (g' - d (d·g'))/|g|``."""
        uu, _ = as_parameter_array(u, "u")
        g = self.ruling(uu)
        g1 = self.ruling(uu, 1)
        L = np.linalg.norm(g, axis=1)
        d = g / L[:, None]
        d1 = (g1 - d * np.einsum("ij,ij->i", d, g1)[:, None]) / L[:, None]
        return {"d": d, "d1": d1, "length": L}

    def fairness(self, nodes: int = 32) -> float:
        r"""Fairness of the ruling field ``∫_0^1 |d'(λ)|² dλ`` (Gauss–Legendre per segment)."""
        x, w = gauss_legendre(nodes)
        tot = 0.0
        for i in range(len(self.segments)):
            lo, hi = self._edges[i], self._edges[i + 1]
            uu = lo + (hi - lo) * x
            d1 = self.ruling_field(uu)["d1"]
            tot += float(np.sum(w * (hi - lo) * np.sum(d1 * d1, axis=1)))
        return tot

    def regression_parameter(self, u: Any) -> np.ndarray:
        r"""``v* = -((a' × g)·(g' × g)) / |g' × g|²``: where on the ruling ``X = a + v g`` the
        surface is singular (the edge of regression); ±inf where ``g' × g = 0`` (cylinder-like)."""
        uu, _ = as_parameter_array(u, "u")
        return regression_v(self.a(uu, 1), self.ruling(uu), self.ruling(uu, 1))

    def bspline_data(self, tol: float | None = None, degree: int = 5, theta_tol_deg: float = 1e-3) -> list[Any]:
        r"""Plain-data B-spline surfaces, one per segment (poles, knots, degrees; degree 1 across
        the rulings), from :func:`ght_cad.developables.envelope.developable_bspline`: the boundary curves are
        fitted together (compatible poles) with ``max_u |f(u) - F(u)| <= max_deviation <= tol``,
        so the faces' edges lie on the rails within ``max_deviation`` (the certified tolerance) and
        joint rulings are exact end poles."""
        from ..envelope import developable_bspline

        return [developable_bspline(sg, tol=tol, degree=degree, theta_tol_deg=theta_tol_deg, end_order=sg.end_order)
                for sg in self.segments]

    def to_dict(self, tol: float | None = None, degree: int = 5) -> dict[str, Any]:
        """Plain data: the report and per segment the B-spline data (poles, knots, degrees)."""
        segs = []
        for sg, data in zip(self.segments, self.bspline_data(tol=tol, degree=degree)):
            segs.append({
                "kind": sg.kind,
                "t_range": list(sg.t_range),
                "s_range": list(sg.s_range),
                "poles": np.asarray(data.poles).tolist(),
                "knots_u": np.asarray(data.knots_u).tolist(),
                "knots_v": np.asarray(data.knots_v).tolist(),
                "degree_u": int(data.degree_u),
                "degree_v": int(data.degree_v),
                "max_deviation": float(data.max_deviation),
            })
        return {"report": self.report.as_dict(), "segments": segs}

    def to_face(self, tol: float | None = None, **kwargs: Any) -> Any:
        """A build123d ``Shell`` of one B-spline face per segment sewn along the joint rulings
        (:func:`ght_cad.cad.developable_faces.composite_shell`; needs build123d)."""
        from ...core._kernel import adapter

        return adapter("composite_shell")(self.segments, tol=tol, **kwargs)

    def joint_folds(self) -> list[dict[str, float]]:
        r"""Joint rulings where the surface folds back (a fan lying over the main part).

        At a joint ruling the segments share the tangent plane; the loft continues across it iff
        the normals ``N = X_λ × g`` at mid-ruling (``X_λ = a' + g'/2``) on both sides point the same
        way, ``N_left · N_right > 0``. Returns the folded joints (λ, t, s of the joint).
        """
        out = []
        one, zero = np.array([1.0]), np.array([0.0])
        for i in range(len(self.segments) - 1):
            L, R = self.segments[i], self.segments[i + 1]
            nl = np.cross(0.5 * (L.a(one, 1) + L.b(one, 1)), L.ruling(one))[0]
            nr = np.cross(0.5 * (R.a(zero, 1) + R.b(zero, 1)), R.ruling(zero))[0]
            if float(np.dot(nl, nr)) < 0:
                t, s = L.parameters(one)
                out.append({"lam": L.lam_range[1], "t": float(t[0]), "s": float(s[0])})
        return out

    def __repr__(self) -> str:
        return f"DevelopableLoft({', '.join(sg.kind for sg in self.segments)}; fan share {self.report.fan_share:.3g})"

    # -- report --------------------------------------------------------------------------
    def _make_report(self, samples: int, candidates: list[dict[str, Any]], area_rtol: float) -> LoftReport:
        from ...unrolling.unroll import ruled_area
        from ...surfaces.ruled import _theta

        size = self._pair.size
        seg_info = []
        area = fan_area = 0.0
        rows = []
        degenerate: list[dict[str, Any]] = []
        regression: list[dict[str, Any]] = []
        clearance = math.inf
        fres = 0.0
        for i, sg in enumerate(self.segments):
            ar = ruled_area(sg, rtol=area_rtol)
            area += ar
            if sg.kind != "main":
                fan_area += ar
            apex = sg.apex
            seg_info.append({
                "kind": sg.kind,
                "t": list(sg.t_range),
                "s": list(sg.s_range),
                "lam": list(sg.lam_range),
                "apex": None if apex is None else apex.tolist(),
                "area": ar,
            })
            u = np.linspace(0.0, 1.0, samples)
            a0, a1 = sg.a(u), sg.a(u, 1)
            b0, b1 = sg.b(u), sg.b(u, 1)
            g = b0 - a0
            th, _ = _theta(a1, b1, g)
            lam = sg.lam_range[0] + u * (sg.lam_range[1] - sg.lam_range[0])
            t, s = sg.parameters(u)
            rows.append(np.column_stack([lam, t, s, th]))
            if sg.kind == "main":
                tt, ss, _ = self._path.main(lam, 0)
                fres = max(fres, float(np.max(np.abs(self._pair.f(tt[0], ss[0])))))
            L = np.linalg.norm(g, axis=1)
            # degenerate rulings: zero length or a rail tangent along the ruling
            sin_a = _sine(self._pair.ra.derivative(np.clip(t, 0, 1), 1), g)
            sin_b = _sine(self._pair.rb.derivative(np.clip(self._given_s(s), 0, 1), 1), g)
            for j in range(u.size):
                if L[j] <= 1e-9 * size:
                    degenerate.append({"t": float(t[j]), "s": float(s[j]), "kind": "zero length", "value": float(L[j])})
                elif sin_a[j] <= 1e-9 or sin_b[j] <= 1e-9:
                    which = "rail_a" if sin_a[j] <= sin_b[j] else "rail_b"
                    degenerate.append({"t": float(t[j]), "s": float(s[j]), "kind": f"{which} tangent along the ruling",
                                       "value": float(min(sin_a[j], sin_b[j]))})
            vs = regression_v(a1, g, b1 - a1)
            # a cone's apex on a rail (a stationary side: v* = 0 with a' = 0, v* = 1 with b' = 0) is
            # the edge of regression of a fan (or of a planar triangle), not a defect between the rails
            g1n = np.linalg.norm(b1 - a1, axis=1)
            apex = ((np.linalg.norm(a1, axis=1) <= 1e-9 * g1n) & (np.abs(vs) <= 1e-6)) | (
                (np.linalg.norm(b1, axis=1) <= 1e-9 * g1n) & (np.abs(vs - 1) <= 1e-6))
            vs = np.where(apex, np.inf, vs)
            fin = np.isfinite(vs)
            if fin.any():
                dist = np.where(vs < 0, -vs, np.where(vs > 1, vs - 1, 0.0))[fin]
                clearance = min(clearance, float(dist.min()))
                inside = np.flatnonzero(fin & (vs >= 0) & (vs <= 1))
                for j in inside:
                    regression.append({"t": float(t[j]), "s": float(s[j]), "v": float(vs[j]),
                                       "point": (a0[j] + vs[j] * g[j]).tolist()})
        theta = np.vstack(rows)
        fin = np.isfinite(theta[:, 3])
        theta_max = float(np.max(theta[fin, 3])) if fin.any() else math.nan
        start = (float(self._branch.t[0]), float(self._given_s(np.array([self._branch.s[0]]))[0]))
        end = (float(self._branch.t[-1]), float(self._given_s(np.array([self._branch.s[-1]]))[0]))
        return LoftReport(
            reversed_b=bool(self.reversed_b),
            branch_start=start,
            branch_end=end,
            nodes=int(self._branch.lam.size),
            segments=seg_info,
            area=area,
            fan_area=fan_area,
            fan_share=fan_area / area if area > 0 else math.nan,
            theta_max_deg=theta_max,
            f_residual_max=fres,
            theta=theta,
            degenerate_rulings=degenerate,
            regression=regression,
            regression_clearance=clearance,
            candidates=candidates,
        )


def _sine(x: np.ndarray, g: np.ndarray) -> np.ndarray:
    with np.errstate(divide="ignore", invalid="ignore"):
        den = np.linalg.norm(x, axis=1) * np.linalg.norm(g, axis=1)
        return np.where(den > 0, np.linalg.norm(np.cross(x, g), axis=1) / np.where(den > 0, den, 1.0), 1.0)

