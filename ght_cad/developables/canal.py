"""Canal surfaces (the envelope of a one-parameter family of spheres) and their report.

Moved from :mod:`ght_cad.developables.envelope` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core._validate import as_parameter_array
from ..curves.curve import GHTCurve
from ..core.errors import DegenerateGeometryError, GHTError
from .checks import _check_3d_curve


# ----------------------------------------------------------------------------------------------
# 5.5 canal surfaces
# ----------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CanalReport:
    """Developability report of a canal surface (sampled Gaussian curvature).

    Attributes:
        k_max: ``max |K| ρ²`` over the samples (scale-free; ρ = mean sphere radius).
        k_rms: root mean square of ``K ρ²``.
        developable: True only for a cone or cylinder of revolution whose sampled ``|K| ρ²``
            stays below ``tol``.
        kind: ``"cylinder of revolution"``, ``"cone of revolution"`` or ``"not developable"``.
        tol: tolerance used on ``k_max``.
    """

    k_max: float
    k_rms: float
    developable: bool
    kind: str
    tol: float

    def __str__(self) -> str:
        return f"canal surface: {self.kind} (max |K| rho^2 = {self.k_max:.3e}, rms {self.k_rms:.3e})"


class CanalSurface:
    r"""Envelope of the spheres with centre ``C(t)`` and radius ``r(t)`` (spec 5.5).

    ``X(t, φ) = C - r ṙ/|C'|² C' + r sqrt(1 - ṙ²/|C'|²) (cos φ e1 + sin φ e2)`` where ``e1, e2``
    is an orthonormal frame normal to ``C'`` (``e1 = ref × T / |..|``, a fixed reference axis),
    ``φ = φ0 + v (φ1 - φ0)``. Not a ruled surface in general: it is developable only when it is a
    cone or a cylinder of revolution, which :meth:`developability` reports (it never calls another
    canal surface developable).

    Args:
        center: 3-D GHT curve ``C(t)``.
        radius: 1-D GHT curve ``r(t)`` (positive), or a positive number (pipe surface).
        phi_range: angle range in radians, default the full circle.

    Raises:
        DegenerateGeometryError: ``r <= 0``, ``|r'| >= |C'|`` (no real envelope), ``C' = 0``.
    """

    def __init__(self, center: GHTCurve, radius: Any, *, phi_range: tuple[float, float] = (0.0, 2 * math.pi), samples: int = 257) -> None:
        self.center = _check_3d_curve(center, "center")
        if isinstance(radius, GHTCurve):
            if radius.dim != 1:
                raise GHTError(f"radius must be a 1-D GHT curve; got dimension {radius.dim}")
            self.radius = radius
        else:
            try:
                r = float(radius)
            except (TypeError, ValueError):
                raise GHTError(f"radius={radius!r} must be a 1-D GHTCurve or a positive number") from None
            self.radius = GHTCurve([[r]] * 3)
        try:
            self.phi_range = (float(phi_range[0]), float(phi_range[1]))
        except (TypeError, ValueError, IndexError):
            raise GHTError(f"phi_range={phi_range!r} must be a pair of angles (phi0, phi1) in radians") from None
        if not (all(math.isfinite(x) for x in self.phi_range) and self.phi_range[0] != self.phi_range[1]):
            raise GHTError(
                f"phi_range={self.phi_range!r} is not allowed; it must be two finite, different angles (radians)"
            )
        u = np.linspace(0.0, 1.0, samples)
        rv = self.radius.evaluate(u)[:, 0]
        if not np.all(rv > 0):
            i = int(np.argmin(rv))
            raise DegenerateGeometryError(f"radius r(t)={rv[i]:.6g} at t={u[i]:.6g}; sphere radii must be > 0")
        c1 = self.center.derivative(u, 1)
        sp = np.linalg.norm(c1, axis=1)
        r1 = self.radius.derivative(u, 1)[:, 0]
        if not np.all(np.abs(r1) < sp):
            i = int(np.argmax(np.abs(r1) - sp))
            raise DegenerateGeometryError(
                f"at t={u[i]:.6g} |r'|={abs(r1[i]):.6g} >= |C'|={sp[i]:.6g}: the spheres are nested and "
                "have no real envelope; the radius must change slower than the centre moves"
            )
        T = c1 / sp[:, None]
        axes = np.eye(3)
        self._ref = axes[int(np.argmin(np.abs(T @ axes.T).max(axis=0)))]
        if not np.all(np.linalg.norm(np.cross(self._ref, T), axis=1) > 1e-6):
            raise DegenerateGeometryError("the centre curve turns through every coordinate axis; no fixed frame reference found")

    def evaluate(self, u: Any, v: Any) -> np.ndarray:
        """Points ``X(t, φ(v))``; u, v broadcast to a common 1-D shape."""
        uu, us = as_parameter_array(u, "u")
        vv, vs = as_parameter_array(v, "v")
        uu, vv = np.broadcast_arrays(uu, vv)
        out = self._point(uu, vv)
        return out[0] if (us and vs) else out

    def _point(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        C = self.center.evaluate(u)
        c1 = self.center.derivative(u, 1)
        r = self.radius.evaluate(u)[:, 0]
        r1 = self.radius.derivative(u, 1)[:, 0]
        s2 = np.sum(c1 * c1, axis=1)
        T = c1 / np.sqrt(s2)[:, None]
        e1 = np.cross(self._ref, T)
        e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
        e2 = np.cross(T, e1)
        phi = self.phi_range[0] + v * (self.phi_range[1] - self.phi_range[0])
        rho = r * np.sqrt(1.0 - r1**2 / s2)
        return C - (r * r1 / s2)[:, None] * c1 + rho[:, None] * (np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2)

    def gaussian_curvature(self, u: Any, v: Any, h: float = 1e-3) -> np.ndarray:
        r"""Gaussian curvature ``K = (LN - M²)/(EG - F²)`` from 4th-order central differences."""
        uu, _ = as_parameter_array(u, "u")
        vv, _ = as_parameter_array(v, "v")
        uu, vv = np.broadcast_arrays(uu, vv)
        # keep the stencil inside [0, 1] in u (v is periodic-safe: the formula extends smoothly)
        uc = np.clip(uu, 2 * h, 1 - 2 * h)

        def X(du: float, dv: float) -> np.ndarray:
            return self._point(uc + du * h, vv + dv * h)

        w = {-2: 1 / 12, -1: -2 / 3, 1: 2 / 3, 2: -1 / 12}
        w2 = {-2: -1 / 12, -1: 4 / 3, 0: -5 / 2, 1: 4 / 3, 2: -1 / 12}
        Xu = sum(c * X(k, 0) for k, c in w.items()) / h
        Xv = sum(c * X(0, k) for k, c in w.items()) / h
        Xuu = sum(c * X(k, 0) for k, c in w2.items()) / h**2
        Xvv = sum(c * X(0, k) for k, c in w2.items()) / h**2
        Xuv = sum(ci * cj * X(i, j) for i, ci in w.items() for j, cj in w.items()) / h**2
        n = np.cross(Xu, Xv)
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        E, F, G = (np.sum(a * b, axis=1) for a, b in ((Xu, Xu), (Xu, Xv), (Xv, Xv)))
        L, M, N = (np.sum(a * n, axis=1) for a in (Xuu, Xuv, Xvv))
        return (L * N - M * M) / (E * G - F * F)

    def kind(self, tol: float = 1e-9, samples: int = 129) -> str:
        """``"cylinder of revolution"``, ``"cone of revolution"`` or ``"not developable"``.

        Geometric test on ``samples`` parameters: the centres ``C(t)`` lie on one line (distance
        ``<= tol L``, L the centre curve's extent) and the radius is an affine function of the
        position ``s = (C - C(0))·d`` along it, ``r = α + β s`` (residual ``<= tol max(L, r)``); then
        the spheres envelope a cone of revolution (``β ≠ 0``) or a cylinder (``β = 0``). Works for
        any parametrizations of the two curves.
        """
        t = np.linspace(0.0, 1.0, samples)
        C = self.center.evaluate(t)
        R = self.radius.evaluate(t)[:, 0]
        ext = C.max(axis=0) - C.min(axis=0)
        L = float(np.linalg.norm(ext))
        if L == 0.0:
            return "not developable"
        i = int(np.argmax(np.linalg.norm(C - C[0], axis=1)))
        d = (C[i] - C[0]) / np.linalg.norm(C[i] - C[0])
        off = C - C[0]
        sp = off @ d
        if np.max(np.linalg.norm(off - np.outer(sp, d), axis=1)) > tol * L:
            return "not developable"
        scale = max(L, float(np.abs(R).max()))
        A = np.column_stack([np.ones_like(sp), sp])
        coef, *_ = np.linalg.lstsq(A, R, rcond=None)
        if np.max(np.abs(A @ coef - R)) > tol * scale:
            return "not developable"
        return "cylinder of revolution" if abs(coef[1]) * L <= tol * scale else "cone of revolution"

    def developability(self, nu: int = 41, nv: int = 24, tol: float = 1e-6) -> CanalReport:
        """Sampled scale-free Gaussian curvature ``K ρ²`` and the structural kind (see :meth:`kind`)."""
        u = np.linspace(0.02, 0.98, nu)
        v = np.linspace(0.0, 1.0, nv, endpoint=False)
        U, V = (x.ravel() for x in np.meshgrid(u, v, indexing="ij"))
        K = self.gaussian_curvature(U, V)
        rho = float(np.mean(self.radius.evaluate(u)[:, 0]))
        Ks = K * rho**2
        kmax = float(np.max(np.abs(Ks)))
        krms = float(np.sqrt(np.mean(Ks**2)))
        kind = self.kind()
        dev = kind != "not developable" and kmax <= tol
        return CanalReport(kmax, krms, dev, kind if dev else "not developable", tol)
