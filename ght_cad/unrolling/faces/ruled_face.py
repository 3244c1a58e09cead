"""A face whose isolines in one direction are straight, as a :class:`ght_cad.surfaces.ruled.RuledSurface`.

Moved from :mod:`ght_cad.unrolling.face_unroll` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ...core._vec import unique_inverse
from ...core.errors import GHTError
from ...surfaces.ruled import RuledSurface
from .adapter import Bounds, surface_jet, SurfaceAdapter
from .loops import _flat1


class FaceRuledSurface(RuledSurface):
    r"""The ruled surface of a face whose ``ruled``-isolines are straight lines.

    With ``ruled == "v"`` (rulings along v): ``a(t) = S(u0 + t Δu, v0)``, ``b(t) = S(u0 + t Δu, v1)``,
    ``a^(r)(t) = Δu^r ∂_u^r S``; with ``ruled == "u"`` the roles of u and v swap. ``breakpoints``
    are the surface's C∞-interval ends (B-spline knots) in t.

    Raises:
        GHTError: ``ruled`` is not "u" or "v".
    """

    def __init__(self, surface: SurfaceAdapter, ruled: str, bounds: Bounds) -> None:
        if ruled not in ("u", "v"):
            raise GHTError(f"ruled={ruled!r} is not allowed; use 'u' or 'v'")
        self.ev = surface
        self.ruled = ruled
        self.bounds = bounds
        u0, u1, v0, v1 = bounds
        if ruled == "v":
            self.t0, self.t1, self.s0, self.s1 = u0, u1, v0, v1
        else:
            self.t0, self.t1, self.s0, self.s1 = v0, v1, u0, u1
        ks = np.asarray(surface.breaks("u" if ruled == "v" else "v"), dtype=float)
        self.breakpoints = tuple(((ks - self.t0) / (self.t1 - self.t0)).tolist())
        self._jets: dict[bytes, tuple[int, list[np.ndarray]]] = {}

    def _jet(self, t: np.ndarray, order: int) -> list[np.ndarray]:
        """Jets of the surface at both boundaries ``(t, s0)`` and ``(t, s1)`` stacked (2n points), one
        surface evaluation per parameter array (kept for the last 16 arrays: the quadrature and the
        developability ask for a, a', b, b' at the same parameters; :meth:`prefetch` evaluates
        several arrays at once)."""
        key = t.tobytes()
        hit = self._jets.get(key)
        if hit is not None and hit[0] >= order:
            return hit[1]
        u, v = self._ends_uv(t)
        jet = surface_jet(self.ev, u, v, order)
        self._keep(key, order, jet)
        return jet

    def _ends_uv(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Face parameters of both boundaries at ``t``: ``uv(t, 0)`` then ``uv(t, 1)`` (2n points)."""
        ss = np.zeros(2 * t.size)
        ss[t.size:] = 1.0
        return self.uv(np.concatenate([t, t]), ss)

    def _keep(self, key: bytes, order: int, jet: list[np.ndarray]) -> None:
        """Remember the boundary jet of one parameter array (the last 16 arrays are kept)."""
        if key not in self._jets and len(self._jets) >= 16:
            self._jets.pop(next(iter(self._jets)))
        self._jets[key] = (order, jet)

    def prefetch(self, arrays: Sequence[np.ndarray], order: int,
                 extra: tuple[np.ndarray, np.ndarray] | None = None) -> list[np.ndarray] | None:
        """The boundary jets (:meth:`_jet`) of several parameter arrays in one surface evaluation,
        each kept as :meth:`_jet` keeps one (the per-evaluation overhead of a surface, ~25 µs for a
        B-spline, paid once: the developability's, the quadrature's first and the ruling ends'
        parameters are known before any of them is asked for); ``extra``: (u, v) points whose
        jet is evaluated in the same call and returned (the metric grid's partials).

        The points of each array are ``uv(t, 0)`` then ``uv(t, 1)``, the same numbers as
        :meth:`_jet` makes, so each array's jet is a contiguous slice of the result."""
        todo = []
        for t in arrays:
            t = _flat1(t)
            hit = self._jets.get(t.tobytes())
            if t.size and not (hit is not None and hit[0] >= order):
                todo.append(t)
        us, vs = [], []
        for t in todo:
            u, v = self._ends_uv(t)
            us.append(u)
            vs.append(v)
        if extra is not None:
            us.append(np.asarray(extra[0], dtype=float).ravel())
            vs.append(np.asarray(extra[1], dtype=float).ravel())
        if not us:
            return None
        jet = surface_jet(self.ev, np.concatenate(us), np.concatenate(vs), order)
        i = 0
        for t in todo:
            m = 2 * t.size
            self._keep(t.tobytes(), order, [d[i:i + m] for d in jet])
            i += m
        return [d[i:] for d in jet] if extra is not None else None

    def uv(self, t: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Face parameters of ruled parameters (t, s) ∈ [0, 1]²."""
        tp = self.t0 + t * (self.t1 - self.t0)
        sp = self.s0 + s * (self.s1 - self.s0)
        return (tp, sp) if self.ruled == "v" else (sp, tp)

    def ts(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Ruled parameters (t, s) of face parameters (u, v)."""
        tp, sp = (u, v) if self.ruled == "v" else (v, u)
        return (tp - self.t0) / (self.t1 - self.t0), (sp - self.s0) / (self.s1 - self.s0)

    def value_and_ends(self, t: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """``S(u, v)`` at points on the rulings at ``t``, evaluated together with the ruling ends
        ``a(t)``, ``b(t)`` (kept for :meth:`a`, :meth:`b`) in one surface evaluation."""
        t = _flat1(t)
        key = t.tobytes()
        if key in self._jets:
            return self.ev.value(u, v)
        # the ends at the distinct t only (points along one ruling share them: a ruling edge's
        # samples, the metric stencil's v steps, the bend lines' two ends)
        tu, inv = unique_inverse(t)
        m = tu.size
        ue, ve = self.uv(np.concatenate([tu, tu]), np.concatenate([np.zeros(m), np.ones(m)]))
        n = np.size(u)
        p = self.ev.value(np.concatenate([np.asarray(u).ravel(), ue]), np.concatenate([np.asarray(v).ravel(), ve]))
        inv = inv.ravel()
        self._keep(key, 0, [np.concatenate([p[n:n + m][inv], p[n + m:][inv]])])
        return p[:n]

    def _edge(self, t: Any, s: float, derivative: int) -> np.ndarray:
        t = _flat1(t)
        if derivative > 2:
            raise GHTError(f"derivative={derivative} is not available for faces; allowed 0, 1, 2")
        d = self._jet(t, derivative)
        part = slice(0, t.size) if s == 0.0 else slice(t.size, 2 * t.size)
        if derivative == 0:
            return d[0][part].copy()
        k = (1 if self.ruled == "v" else 2) if derivative == 1 else (3 if self.ruled == "v" else 4)
        return d[k][part] * (self.t1 - self.t0) ** derivative

    def edge_jets(self, u: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(a', g, g')`` (:meth:`RuledSurface.edge_jets`) from one kept jet (:meth:`_jet`, order 1):
        the same numbers as :meth:`a` and :meth:`ruling` give."""
        t = _flat1(u)
        d = self._jet(t, 1)
        n = t.size
        k = 1 if self.ruled == "v" else 2
        s = self.t1 - self.t0
        a1, b1 = d[k][:n] * s, d[k][n:] * s
        return a1, d[0][n:] - d[0][:n], b1 - a1

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._edge(u, 0.0, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._edge(u, 1.0, derivative)
