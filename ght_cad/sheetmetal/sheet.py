r"""Sheet thickness, K-factor and the neutral surface of a developable plate (spec section 6.1).

A plate of thickness ``T`` is modelled on its design surface ``S`` (a developable ruled surface or
a CAD face): ``S`` is the **inside face** of the sheet (the face the K-factor is measured from)
and the material fills ``S + t n``, ``t`` between 0 and ``σ T``, where ``n`` is the unit surface
normal and ``σ = +1`` for ``side="normal"`` (material along the normal) or ``σ = -1`` for
``side="reverse"`` (against it). For a developable ``n`` is constant along every ruling, so each
offset ``S + t n`` is developable with the same rulings. The flat pattern is the development of
the **neutral surface** ``S + δ n``, ``δ = σ K T`` (ANSI K-factor ``K ∈ [0, 1]``; DIN's ``k = 2K``).

Ruled form: with ``X(u, v) = a(u) + v g(u)``, ``g = b - a``, the unit normal along the ruling is

    n(u) = m / |m|,  m = ((a' + b') / 2) × g        (the normal at mid-ruling, X_u × X_v at v = ½)

and the offset is the ruled surface ``a_δ = a + δ n``, ``b_δ = b + δ n`` (same ruling ``g``).
``n'`` lies in the tangent plane across the ruling: ``n' = ω e``, ``e = n × d``, ``d = g / |g|``,
``ω = n' · e``. The across-ruling speed of the offset is ``X_u · e + t ω`` (``X_u = a' + v g'``),
so the signed bending radius of the offset at distance ``t`` is

    ρ_t(u, v) = ρ_0(u, v) + t,   ρ_0 = (X_u · e) / ω,

(``|ρ|`` the radius of curvature across the ruling, ``ρ_0 → ∞`` where the plate is flat). The
offset is regular while ``|δ| < |ρ_0|`` (``|δ| < 1/κ``, κ the largest normal curvature across the
rulings; spec 6.1) and the material does not reach a centre of curvature (``ρ_0 (ρ_0 + σ T) > 0``);
otherwise :func:`check_offset` refuses, naming the ruling and its radius.

Forming data: the bend lines of a pattern are rulings ``u_i``; each carries the neutral radius
``|ρ_0 + δ|`` at both ends of the ruling and the angle the plate turns over its share of the plate
(``[m_{i-1}, m_i]``, ``m`` the midpoints between bend lines):

    angle_i = ∫_{m_{i-1}}^{m_i} σ sgn(X_u·e) ω du      (positive: the reference face is inside)

numpy only (no CAD kernel).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np

from ..core._quadrature import leggauss
from ..core.errors import GHTError
from ..unrolling.faces.directions import ruling_direction
from ..unrolling.faces.loops import fd_derivative
from ..unrolling.faces.ruled_face import FaceRuledSurface
from ..pattern.forming import FormingRow, _fmt_r, forming_table_text, plot_roll_chart  # noqa: F401 - moved there (issue 27)
from ..pattern.model import _inside, romberg_length
from ..surfaces.ruled import SINGULAR_NORMAL_TOL, RuledSurface
from ..unrolling.ruled_development import _smooth_pieces, unroll_ruled_surface

__all__ = [
    "SIDES",
    "Sheet",
    "SheetError",
    "make_sheet",
    "ruling_normal",
    "bending_radius",
    "check_offset",
    "OffsetRuledSurface",
    "OffsetSurfaceAdapter",
    "FormingRow",
    "forming_rows",
    "plot_roll_chart",
    "forming_table_text",
]

#: the side the material lies on, relative to the design surface's unit normal
SIDES = ("normal", "reverse")


class SheetError(GHTError):
    """A bad sheet value (thickness, K-factor, side) or a thickness the surface cannot carry.

    A refusal of :func:`check_offset` also says which rule refused, for callers that weigh
    refusals (the optimizer of ``ght_cad.app.design`` keeps the best refused candidate):

    Attributes:
        constraint: ``"radius"`` (``|K T| >= |ρ_0|``), ``"centre"`` (the material reaches a centre
            of curvature, ``ρ_0 (ρ_0 + σ T) <= 0``), ``"apex"`` (material on the concave side of an
            apex) or None (a bad value, not a refusal of the geometry).
        radius: the bending radius ``|ρ_0|`` of the refused ruling (0 at an apex), or None.
        limit: the bound it was held against (``|K T|`` for "radius", ``T`` for "centre", 0 for
            "apex"), or None.
    """

    constraint: str | None = None
    radius: float | None = None
    limit: float | None = None


def _refusal(message: str, constraint: str, radius: float, limit: float) -> SheetError:
    """A :class:`SheetError` of :func:`check_offset` carrying the rule that refused."""
    err = SheetError(message)
    err.constraint, err.radius, err.limit = constraint, float(radius), float(limit)
    return err


def _finite_number(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SheetError(f"{name}={value!r} is not a number; it must be a finite real number")
    x = float(value)
    if not math.isfinite(x):
        raise SheetError(f"{name}={x!r} is not allowed; it must be a finite real number")
    return x


@dataclass(frozen=True)
class Sheet:
    r"""Thickness, K-factor and material side of a plate (spec 6.1).

    Attributes:
        thickness: ``T >= 0`` in model units (0: a zero-thickness surface, today's patterns).
        k_factor: ANSI K-factor ``K ∈ [0, 1]``: the neutral surface lies ``K T`` from the inside
            (design) face. DIN's ``k = 2K`` is accepted by :func:`make_sheet` (``din_k_factor``).
        side: ``"normal"`` (material along the design surface's unit normal) or ``"reverse"``
            (against it).

    Raises:
        SheetError: negative/NaN/infinite thickness, K outside [0, 1], an unknown side.
    """

    thickness: float
    k_factor: float = 0.5
    side: str = "normal"

    def __post_init__(self) -> None:
        t = _finite_number("thickness", self.thickness)
        if t < 0:
            raise SheetError(f"thickness={t!r} is not allowed; the sheet thickness must be a finite length >= 0")
        k = _finite_number("k_factor", self.k_factor)
        if not 0.0 <= k <= 1.0:
            raise SheetError(
                f"k_factor={k!r} is not allowed; the ANSI K-factor lies in [0, 1] (DIN k = 2K lies in [0, 2]: "
                "give it as din_k_factor)"
            )
        if self.side not in SIDES:
            raise SheetError(
                f"side={self.side!r} is not allowed; allowed: 'normal' (material along the surface normal) or "
                "'reverse' (material against it)"
            )
        object.__setattr__(self, "thickness", t)
        object.__setattr__(self, "k_factor", k)

    @property
    def sign(self) -> float:
        """``σ = +1`` for side "normal", ``-1`` for "reverse"."""
        return 1.0 if self.side == "normal" else -1.0

    @property
    def neutral_offset(self) -> float:
        """``δ = σ K T``: signed distance of the neutral surface from the design surface along n."""
        return self.sign * self.k_factor * self.thickness

    @property
    def outside_offset(self) -> float:
        """``σ T``: signed distance of the outside face along n."""
        return self.sign * self.thickness

    @property
    def din_k_factor(self) -> float:
        """DIN 6935 ``k = 2K``."""
        return 2.0 * self.k_factor

    @property
    def is_zero(self) -> bool:
        """True for ``T = 0`` (the pattern is the design surface's own development)."""
        return self.thickness == 0.0

    def flipped(self) -> "Sheet":
        """The same sheet with the material on the other side."""
        return Sheet(self.thickness, self.k_factor, "reverse" if self.side == "normal" else "normal")

    def as_dict(self) -> dict[str, Any]:
        """Plain dict for reports (thickness, k_factor, din_k_factor, side, neutral_offset)."""
        return {
            "thickness": self.thickness,
            "k_factor": self.k_factor,
            "din_k_factor": self.din_k_factor,
            "side": self.side,
            "neutral_offset": self.neutral_offset,
        }


def make_sheet(
    thickness: Any = None,
    k_factor: Any = None,
    *,
    din_k_factor: Any = None,
    side: str = "normal",
    flip: bool = False,
) -> Sheet | None:
    """A :class:`Sheet` from user values, or None when no thickness is given.

    Args:
        thickness: sheet thickness T (None: no sheet).
        k_factor: ANSI K-factor in [0, 1] (default 0.5 when neither K nor DIN k is given).
        din_k_factor: DIN k-factor ``k = 2K`` in [0, 2] (instead of ``k_factor``).
        side: "normal" or "reverse" (see :class:`Sheet`).
        flip: put the material on the other side.

    Raises:
        SheetError: both k_factor and din_k_factor, DIN k outside [0, 2], or a bad Sheet value.
    """
    if thickness is None:
        if k_factor is not None or din_k_factor is not None:
            raise SheetError("a K-factor was given without a thickness; give thickness=T (a length >= 0) too")
        return None
    if k_factor is not None and din_k_factor is not None:
        raise SheetError(
            f"k_factor={k_factor!r} and din_k_factor={din_k_factor!r} are both given; give one of them (DIN k = 2K)"
        )
    if din_k_factor is not None:
        k = _finite_number("din_k_factor", din_k_factor)
        if not 0.0 <= k <= 2.0:
            raise SheetError(f"din_k_factor={k!r} is not allowed; the DIN k-factor (k = 2K) lies in [0, 2]")
        K = k / 2.0
    else:
        K = 0.5 if k_factor is None else k_factor
    sh = Sheet(thickness, K, side)
    return sh.flipped() if flip else sh


# -- ruled-surface geometry --------------------------------------------------------------------
def _fd_first(fun: Callable[[np.ndarray], np.ndarray], u: np.ndarray, breaks: Sequence[float] = ()) -> np.ndarray:
    return fd_derivative(fun, u, breaks, h=1e-4)


#: a ruling at u = 0 or 1 shorter than this times ``|(a' + b')/2|`` is a pointed end (the rails meet)
POINTED_END_TOL = 1e-9


def _pointed_ends(uu: np.ndarray, g: np.ndarray, c1: np.ndarray) -> np.ndarray:
    """Mask of the rulings that are a pointed strip end: u = 0 or 1 and ``|g| <= 1e-9 |c'|``."""
    gl = np.linalg.norm(g, axis=1)
    return ((uu == 0.0) | (uu == 1.0)) & (gl <= POINTED_END_TOL * np.linalg.norm(c1, axis=1))


def ruling_normal(surface: RuledSurface, u: Any, order: int = 1) -> list[np.ndarray]:
    r"""Unit normal along the rulings and its u-derivatives: ``[n, n', (n'')]``.

    ``n = m/|m|``, ``m = ((a' + b')/2) × g``; ``n' = (m' - n (n·m')) / |m|`` with
    ``m' = ((a'' + b'')/2) × g + ((a' + b')/2) × g'``; ``n''`` (order 2) by 5-point differences of
    ``n'`` (the surfaces give analytic derivatives up to order 2 only).

    **Pointed ends.** At a strip end ``u0 ∈ {0, 1}`` whose ruling has zero length (the two
    boundaries meet: a bow where chine and sheer meet; ``|g| <= 1e-9 |c'|``, ``c' = (a' + b')/2``)
    ``m = 0``, and n is the limit of the neighbouring rulings' normals: with
    ``g(u) = g'(u0) (u - u0) + ½ g''(u0) (u - u0)² + ...``, ``M = m / (u - u0)`` is smooth,
    ``M(u0) = c' × g'``, ``M'(u0) = c'' × g' + ½ c' × g''``, so

        n(u0) = s M/|M|,   n'(u0) = (s M' - n (n·s M')) / |M|,

    ``s = +1`` at u0 = 0 and ``-1`` at u0 = 1 (u approaches from inside the strip). ``n''`` there
    is the one-sided difference of n' (:func:`ght_cad.unrolling.face_unroll.fd_derivative`).

    Raises:
        SheetError: a ruling where the normal is undefined (``m = 0`` on a ruling of positive
            length, an interior zero ruling, or a pointed end where the boundaries meet
            tangentially, ``c' × g' = 0``).
    """
    uu = np.atleast_1d(np.asarray(u, dtype=float))
    a1, b1 = surface.a(uu, 1), surface.b(uu, 1)
    g = surface.ruling(uu)
    c1 = 0.5 * (a1 + b1)
    m = np.cross(c1, g)
    ml = np.linalg.norm(m, axis=1)
    scale = np.linalg.norm(c1, axis=1) * np.linalg.norm(g, axis=1)
    # a pointed end counts as such even where rounding leaves a tiny ruling (its direction is noise)
    point = _pointed_ends(uu, g, c1)
    bad = ~(ml > 1e-12 * np.maximum(scale, 1e-300)) | point
    if bad.any():
        g1p = surface.ruling(uu[point], 1) if point.any() else np.zeros((0, 3))
        Mp = np.cross(c1[point], g1p)
        Ml = np.linalg.norm(Mp, axis=1)
        # the boundaries meet at an angle: |c' x g'| against |c'|² (g' = b' - a' is rounding noise
        # where they meet tangentially with the same speed)
        ok = Ml > POINTED_END_TOL * np.linalg.norm(c1[point], axis=1) ** 2
        other = bad & ~point
        if other.any() or not ok.all():
            if other.any():
                i = int(np.argmin(np.where(other, ml / np.maximum(scale, 1e-300), np.inf)))
                why = "a sheet offset needs a regular surface"
            else:
                i = int(np.nonzero(point)[0][int(np.argmin(ok))])
                why = ("the strip ends in a point where its two boundaries meet tangentially (c' x g' = 0), "
                       "so the tangent plane there is undefined; allowed: boundaries meeting at an angle")
            raise SheetError(f"the surface normal is undefined at the ruling u={uu[i]:.6g}; {why}")
        sgn = np.where(uu[point] == 0.0, 1.0, -1.0)
        m = m.copy()
        ml = ml.copy()
        m[point] = sgn[:, None] * Mp
        ml[point] = Ml
    n = m / ml[:, None]
    out = [n]
    if order >= 1:
        c2 = 0.5 * (surface.a(uu, 2) + surface.b(uu, 2))
        g1 = surface.ruling(uu, 1)
        m1 = np.cross(c2, g) + np.cross(c1, g1)
        if point.any():  # M' = c'' × g' + ½ c' × g'' (signed like M)
            g2 = surface.ruling(uu[point], 2)
            sgn = np.where(uu[point] == 0.0, 1.0, -1.0)
            m1[point] = sgn[:, None] * (np.cross(c2[point], g1[point]) + 0.5 * np.cross(c1[point], g2))
        n1 = (m1 - n * np.einsum("ij,ij->i", n, m1)[:, None]) / ml[:, None]
        out.append(n1)
    if order >= 2:
        bp = getattr(surface, "breakpoints", ())
        out.append(_fd_first(lambda t: ruling_normal(surface, t, 1)[1], uu, bp))
    return out


def _unit_ruling(surface: RuledSurface, u: np.ndarray) -> np.ndarray:
    """``d = g/|g|``; at a pointed end (:func:`ruling_normal`) the limit ``s g'/|g'|``."""
    g = surface.ruling(u)
    gl = np.linalg.norm(g, axis=1)
    ends = (u == 0.0) | (u == 1.0)
    if not ends.any():
        return g / gl[:, None]
    point = _pointed_ends(u, g, 0.5 * (surface.a(u, 1) + surface.b(u, 1)))
    if point.any():
        g = g.copy()
        g[point] = np.where(u[point] == 0.0, 1.0, -1.0)[:, None] * surface.ruling(u[point], 1)
        gl = np.linalg.norm(g, axis=1)
    return g / gl[:, None]


def _across(surface: RuledSurface, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(X_u · e, ω = n' · e)`` at (u, v) (u, v same shape), ``e = n × d``."""
    n, n1 = ruling_normal(surface, u, 1)
    d = _unit_ruling(surface, u)
    e = np.cross(n, d)
    xu = surface.a(u, 1) + v[:, None] * surface.ruling(u, 1)
    return np.einsum("ij,ij->i", xu, e), np.einsum("ij,ij->i", n1, e)


def bending_radius(surface: RuledSurface, u: Any, v: Any) -> np.ndarray:
    r"""Signed bending radius across the ruling, ``ρ_0 = (X_u·e)/ω`` (``+inf`` where flat).

    The offset ``S + t n`` has the radius ``ρ_0 + t`` there (module doc); ``|ρ_0|`` is the radius
    of curvature across the ruling at ``X(u, v)``.
    """
    uu = np.atleast_1d(np.asarray(u, dtype=float))
    vv = np.broadcast_to(np.asarray(v, dtype=float), uu.shape).astype(float)
    s, w = _across(surface, uu, vv)
    scale = np.abs(s).max() if s.size else 1.0
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(np.abs(w) > 1e-13 * max(scale, 1e-300), s / np.where(w == 0, 1.0, w), np.inf)


class _Memo:
    """A ruled surface whose ``a``, ``b`` and ``ruling`` keep their results for repeated identical
    calls (same parameter array, same derivative): :func:`check_offset` asks for the same jets
    several times (the normal, the across-ruling speed, the apex test), and each answer is the
    surface's own, so the check computes bit for bit what it computes without the memo. Results are
    read-only copies. ``ruling`` is ``b - a`` from the kept values unless the surface overrides it."""

    def __init__(self, surface: RuledSurface) -> None:
        self._surface = surface
        self._kept: dict[tuple[Any, ...], np.ndarray] = {}
        self._own_ruling = type(surface).ruling is not RuledSurface.ruling

    def _get(self, name: str, fn: Callable[[Any, int], np.ndarray], u: Any, derivative: int) -> np.ndarray:
        uu = np.asarray(u)
        if uu.dtype != np.float64:
            return fn(u, derivative)
        key = (name, int(derivative), uu.shape, uu.tobytes())
        hit = self._kept.get(key)
        if hit is None:
            hit = np.array(fn(u, derivative), dtype=float)
            hit.setflags(write=False)
            self._kept[key] = hit
        return hit

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._get("a", self._surface.a, u, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._get("b", self._surface.b, u, derivative)

    def ruling(self, u: Any, derivative: int = 0) -> np.ndarray:
        if self._own_ruling:
            return self._get("g", self._surface.ruling, u, derivative)
        return self.b(u, derivative) - self.a(u, derivative)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._surface, name)


def check_offset(surface: RuledSurface, sheet: Sheet, label: str = "surface", *, sign: float = 1.0, samples: int = 513) -> float:
    r"""Refuse a sheet the surface cannot carry (spec 6.1): ``|δ| ≥ |ρ_0|`` or material through a
    centre of curvature (``ρ_0 (ρ_0 + σ T) ≤ 0``), at ``samples`` rulings, both ruling ends. An
    apex end (a stationary boundary, ``|a'| ≤ 1e-10 |g|``: the point of a cone or of a loft's fan,
    ``ρ_0 = 0``) is regular when the material lies on the convex side (the offset turns the apex into
    an arc of radius ``|t|``) and refused on the concave side.

    Args:
        surface: the design surface.
        sheet: the sheet (its normal is ``sign`` × the ruled surface's normal).
        label: name for the message.
        sign: +1 when the sheet's normal is :func:`ruling_normal`, -1 when opposite (a face whose
            parameters run the other way).
        samples: rulings checked, ``u = linspace(0, 1, samples)`` (both ends of each); the run's
            checks (plate solid, unroll) use the default 513.

    Returns:
        The smallest bending radius ``min |ρ_0|`` (``inf`` for a flat surface).

    Raises:
        SheetError: naming the ruling (u and the ruling end), its radius and the allowed bound; its
            ``constraint``, ``radius`` and ``limit`` say which rule refused (:class:`SheetError`).
    """
    surface = _Memo(surface)  # type: ignore[assignment]  # the same jets are asked for several times
    u = np.linspace(0.0, 1.0, samples)
    uu = np.concatenate([u, u])
    vv = np.concatenate([np.zeros_like(u), np.ones_like(u)])
    rho = sign * bending_radius(surface, uu, vv)  # radius relative to the sheet's normal
    # apex ends (a stationary boundary: the point of a cone / loft fan, ρ_0 = 0 there): the offset is
    # regular on the convex side (the apex becomes an arc of radius |t|), singular on the concave one
    g = np.linalg.norm(surface.ruling(u), axis=1)
    tang = np.concatenate([np.linalg.norm(surface.a(u, 1), axis=1), np.linalg.norm(surface.b(u, 1), axis=1)])
    apex = tang <= SINGULAR_NORMAL_TOL * np.concatenate([g, g])
    delta, out = sheet.neutral_offset, sheet.outside_offset
    if apex.any():
        mid = sign * bending_radius(surface, uu[apex], np.full(int(apex.sum()), 0.5))
        bad = np.isfinite(mid) & ((mid * delta < 0) | (mid * out < 0))
        if bad.any():
            j = int(np.nonzero(apex)[0][np.argmax(bad)])
            raise _refusal(
                f"thickness={sheet.thickness!r} (side={sheet.side!r}) is not allowed on {label}: the ruling at "
                f"u={uu[j]:.6g} ends in an apex ({'b' if vv[j] else 'a'} end, bending radius 0) and the material lies "
                "on its concave side; allowed: the material on the convex side of an apex (flip the side)",
                "apex", 0.0, 0.0,
            )
        rho = np.where(apex, np.inf, rho)
    finite = np.isfinite(rho)
    if not finite.any():
        return math.inf
    i = int(np.argmin(np.where(finite, np.abs(rho), np.inf)))
    rmin = float(abs(rho[i]))
    where = f"the ruling at u={uu[i]:.6g} ({'b' if vv[i] else 'a'} end)"
    if abs(delta) >= rmin:
        raise _refusal(
            f"thickness={sheet.thickness!r} with k_factor={sheet.k_factor!r} is not allowed on {label}: the neutral "
            f"offset |K*T|={abs(delta):.6g} reaches the bending radius {rmin:.6g} of {where}; allowed |K*T| < "
            f"{rmin:.6g} (the smallest radius of curvature across the rulings)",
            "radius", rmin, abs(delta),
        )
    cross = finite & (rho * (rho + out) <= 0)
    if cross.any():
        j = int(np.argmin(np.where(cross, np.abs(rho), np.inf)))
        raise _refusal(
            f"thickness={sheet.thickness!r} (side={sheet.side!r}) is not allowed on {label}: the material reaches the "
            f"centre of curvature of the ruling at u={uu[j]:.6g} ({'b' if vv[j] else 'a'} end), bending radius "
            f"{abs(rho[j]):.6g}; allowed a thickness below {abs(rho[j]):.6g} on that side (or side flipped)",
            "centre", abs(float(rho[j])), sheet.thickness,
        )
    return rmin


class OffsetRuledSurface(RuledSurface):
    r"""The offset ``a_δ = a + δ n``, ``b_δ = b + δ n`` of a ruled surface (same rulings ``g``).

    ``a_δ' = a' + δ n'``; ``a_δ'' = a'' + δ n''`` (``n''`` by differences, :func:`ruling_normal`).
    ``breakpoints`` are the base surface's.
    """

    def __init__(self, base: RuledSurface, delta: float) -> None:
        self.base = base
        self.delta = float(delta)
        self.breakpoints = tuple(getattr(base, "breakpoints", ()))

    def _off(self, which: str, u: Any, derivative: int) -> np.ndarray:
        uu = np.atleast_1d(np.asarray(u, dtype=float))
        f = self.base.a if which == "a" else self.base.b
        if derivative > 2:
            raise GHTError(f"derivative={derivative!r} is not allowed for an offset surface; allowed 0, 1, 2")
        return f(uu, derivative) + self.delta * ruling_normal(self.base, uu, derivative)[derivative]

    def a(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._off("a", u, derivative)

    def b(self, u: Any, derivative: int = 0) -> np.ndarray:
        return self._off("b", u, derivative)

    def ruling(self, u: Any, derivative: int = 0) -> np.ndarray:
        """The base surface's ruling (``b_δ - a_δ = g`` exactly)."""
        return self.base.ruling(u, derivative)


# -- faces (kernel-free adapters of ght_cad.unrolling.face_unroll) -----------------------------------------
class OffsetSurfaceAdapter:
    r"""``S + δ n`` of a face's surface (``n = o N/|N|``, ``N = S_u × S_v``, ``o = -1`` for a face
    whose orientation is reversed), as a :class:`ght_cad.unrolling.face_unroll.SurfaceAdapter`.

    ``n_u = (N_u - n (n·N_u)) / |N|`` with ``N_u = S_uu × S_v + S_u × S_uv`` (likewise ``n_v``);
    the second derivatives of the offset (only used for ruled-surface second derivatives) by
    central differences of the first. A cylinder of radius R keeps its kind with radius
    ``R + δ_r`` and a cone (reference radius R, semi-angle α) radius ``R + δ_r cos α`` (same α),
    ``δ_r`` the offset towards the outside of the axis, so the closed-form maps stay exact.

    Where ``N`` vanishes (``|N| <= 1e-9 |S_u| |S_v|``: a collapsed boundary row, the apex of a
    cone-like fan, where ``S_u = 0``) ``n, n_u, n_v`` are taken ``1e-6`` of the half box inward
    across the collapsed direction (v when ``|S_u| < |S_v|``, else u), on the same ruling of a
    developable: its normal is constant along the ruling, so that is the limit (the offset of an
    apex is then the arc ``P + δ n(u)``, not NaN).
    """

    def __init__(self, base: Any, delta: float, orientation: float = 1.0, bounds: Sequence[float] | None = None) -> None:
        self.base = base
        self.delta = float(delta)
        self.o = 1.0 if orientation >= 0 else -1.0
        self.kind = base.kind
        self.ruled_hint = base.ruled_hint
        self.semi_angle = base.semi_angle
        self.radius = base.radius
        b = bounds if bounds is not None else (0.0, 1.0, 0.0, 1.0)
        self._box = tuple(float(x) for x in b)
        self._h = (1e-5 * (b[1] - b[0]), 1e-5 * (b[3] - b[2]))
        if self.kind in ("cylinder", "cone"):
            u = np.array([0.5 * (b[0] + b[1])])
            v = np.array([0.5 * (b[2] + b[3])])
            d = base.d2(u, v)
            outward = -d[3][0]  # S_uu points to the axis for a cylinder and a cone
            n = self._normal(d, u, v)[0][0]
            dr = self.delta * (1.0 if float(n @ outward) > 0 else -1.0)
            self.radius = base.radius + (dr if self.kind == "cylinder" else dr * math.cos(base.semi_angle))

    @staticmethod
    def _frame(d: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(n, n_u, n_v, degenerate) from ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` (orientation not applied)."""
        N = np.cross(d[1], d[2])
        Nl = np.linalg.norm(N, axis=1)[:, None]
        bad = Nl[:, 0] <= 1e-9 * np.linalg.norm(d[1], axis=1) * np.linalg.norm(d[2], axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            n = N / Nl
            Nu = np.cross(d[3], d[2]) + np.cross(d[1], d[5])
            Nv = np.cross(d[5], d[2]) + np.cross(d[1], d[4])
            nu = (Nu - n * np.einsum("ij,ij->i", n, Nu)[:, None]) / Nl
            nv = (Nv - n * np.einsum("ij,ij->i", n, Nv)[:, None]) / Nl
        return n, nu, nv, bad

    def _normal(self, d: list[np.ndarray], u: Any, v: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(n, n_u, n_v) at the points ``(u, v)`` whose base derivatives are ``d`` (class doc:
        collapsed rows take the frame 1e-6 of the half box inward)."""
        n, nu, nv, bad = self._frame(d)
        if bad.any():
            uu = np.broadcast_to(np.asarray(u, dtype=float), bad.shape)[bad]
            vv = np.broadcast_to(np.asarray(v, dtype=float), bad.shape)[bad]
            u0, u1, v0, v1 = self._box
            uc, vc = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
            across_v = np.linalg.norm(d[1][bad], axis=1) < np.linalg.norm(d[2][bad], axis=1)
            uu = np.where(across_v, uu, uu + 1e-6 * (uc - uu))
            vv = np.where(across_v, vv + 1e-6 * (vc - vv), vv)
            n2, nu2, nv2, _ = self._frame(self.base.d2(uu, vv))
            n, nu, nv = n.copy(), nu.copy(), nv.copy()
            n[bad], nu[bad], nv[bad] = n2, nu2, nv2
        return self.o * n, self.o * nu, self.o * nv

    def normal(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The sheet's unit normal ``n`` at the points."""
        return self._normal(self.base.d2(u, v), u, v)[0]

    def value(self, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        d = self.base.d2(u, v)
        return d[0] + self.delta * self._normal(d, u, v)[0]

    def d1(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        d = self.base.d2(u, v)
        _, nu, nv = self._normal(d, u, v)
        return [d[1] + self.delta * nu, d[2] + self.delta * nv]

    def d2(self, u: np.ndarray, v: np.ndarray) -> list[np.ndarray]:
        d = self.base.d2(u, v)
        n, nu, nv = self._normal(d, u, v)
        hu, hv = self._h
        pu, mu_ = self.d1(u + hu, v), self.d1(u - hu, v)
        pv, mv = self.d1(u, v + hv), self.d1(u, v - hv)
        suu = (pu[0] - mu_[0]) / (2 * hu)
        svv = (pv[1] - mv[1]) / (2 * hv)
        suv = 0.5 * ((pv[0] - mv[0]) / (2 * hv) + (pu[1] - mu_[1]) / (2 * hu))
        return [d[0] + self.delta * n, d[1] + self.delta * nu, d[2] + self.delta * nv, suu, svv, suv]

    def breaks(self, direction: str) -> np.ndarray:
        return self.base.breaks(direction)


# -- forming data -----------------------------------------------------------------------------
def _midline_speed(surface: RuledSurface, delta: float, u: np.ndarray) -> np.ndarray:
    n1 = ruling_normal(surface, u, 1)[1]
    return np.linalg.norm(0.5 * (surface.a(u, 1) + surface.b(u, 1)) + delta * n1, axis=1)


def _signed_turning(surface: RuledSurface, sheet: Sheet, sign: float, u: np.ndarray) -> np.ndarray:
    """``σ sgn(X_u·e) ω`` at mid-ruling relative to the sheet's normal (``sign`` × ruled normal)."""
    s, w = _across(surface, u, np.full_like(u, 0.5))
    # flipping n flips e = n × d and n', so ω = n'·e stays and X_u·e flips: hence the factor sign
    return sheet.sign * sign * np.sign(s) * w


def forming_rows(
    surface: RuledSurface,
    sheet: Sheet,
    lines: Sequence[float],
    *,
    sign: float = 1.0,
    const_tol: float = 1e-9,
) -> tuple[list[FormingRow], dict[str, list[float]]]:
    r"""Roll-forming data of the bend lines ``lines`` (ruling parameters) and the chart samples.

    Each row: neutral radius ``|ρ_0 + δ|`` at both ruling ends, the angle turned over
    ``[m_{i-1}, m_i]`` (Gauss–Legendre, 24 nodes per bend line), the mid-line position
    ``∫_0^u |(a_δ' + b_δ')/2| du``; every rule is split at the surface's ``breakpoints`` (a
    loft's joint rulings, where the integrands jump), 24 nodes on each part. A plate whose radii do not vary along it (relative
    ``const_tol``: a cylinder or a cone) gives one row (``line = 0``) for the whole plate.

    Returns:
        ``(rows, chart)``, chart = ``{"position", "radius_a", "radius_b"}`` on 257 rulings.
    """
    delta = sheet.neutral_offset
    gx, gw = leggauss(24)
    # the surface's breakpoints (a loft's joint rulings): the integrands (mid-line speed, turning
    # rate) jump there, so every rule is split at them (one rule across a joint was off by 5e-5 in
    # position and 0.06° in angle on the hull plate with fans); without breakpoints the same rules
    breaks = sorted(float(b) for b in getattr(surface, "breakpoints", ()) if 0.0 < b < 1.0)

    def integral(f: Callable[[np.ndarray], np.ndarray], lo: float, hi: float) -> float:
        if hi <= lo:
            return 0.0
        inner = [b for b in breaks if lo < b < hi]
        if inner:
            cuts = [lo, *inner, hi]
            return sum(integral(f, x0, x1) for x0, x1 in zip(cuts[:-1], cuts[1:]))
        t = 0.5 * (lo + hi) + 0.5 * (hi - lo) * gx
        return float(0.5 * (hi - lo) * np.sum(gw * f(t)))

    uc = np.linspace(0.0, 1.0, 257)
    ra = np.abs(sign * bending_radius(surface, uc, np.zeros_like(uc)) + delta)
    rb = np.abs(sign * bending_radius(surface, uc, np.ones_like(uc)) + delta)
    # mid-line positions: 24-point Gauss–Legendre on every chart interval, one vectorized call
    h = 0.5 * np.diff(uc)
    tn = ((0.5 * (uc[1:] + uc[:-1]))[:, None] + h[:, None] * gx[None, :]).ravel()
    steps = (_midline_speed(surface, delta, tn).reshape(h.size, gx.size) @ gw) * h
    for b in breaks:  # a chart interval holding a joint: split there
        j = min(int(np.searchsorted(uc, b, side="right")) - 1, h.size - 1)
        if uc[j] < b < uc[j + 1]:
            steps[j] = integral(lambda t: _midline_speed(surface, delta, t), float(uc[j]), float(uc[j + 1]))
    pos = np.concatenate([[0.0], np.cumsum(steps)])
    chart = {"position": pos.tolist(), "radius_a": ra.tolist(), "radius_b": rb.tolist()}
    turn = lambda t: np.degrees(_signed_turning(surface, sheet, sign, t))  # noqa: E731

    def const(r: np.ndarray) -> bool:
        if not np.all(np.isfinite(r)):
            return bool(np.all(~np.isfinite(r)))
        return bool(np.ptp(r) <= const_tol * max(float(np.max(r)), 1e-300))

    if const(ra) and const(rb):
        total = integral(turn, 0.0, 1.0)
        return [FormingRow(0, 0.5, float(ra[128]), float(rb[128]), total, float(pos[-1]) / 2)], chart
    u = np.asarray(sorted(float(x) for x in lines), dtype=float)
    if u.size == 0:
        return [], chart
    mids = np.concatenate([[0.0], 0.5 * (u[1:] + u[:-1]), [1.0]])
    rows = []
    r0a = np.abs(sign * bending_radius(surface, u, np.zeros_like(u)) + delta)
    r0b = np.abs(sign * bending_radius(surface, u, np.ones_like(u)) + delta)
    for i, ui in enumerate(u):
        ang = integral(turn, float(mids[i]), float(mids[i + 1]))
        p = integral(lambda t: _midline_speed(surface, delta, t), 0.0, float(ui))
        rows.append(FormingRow(i + 1, float(ui), float(r0a[i]), float(r0b[i]), ang, p))
    return rows, chart


@dataclass
class EdgeLengths:
    """Inside (design surface), neutral and outside 3-D lengths of one boundary edge."""

    name: str
    inside: float
    neutral: float
    outside: float
    flat: float = float("nan")

    def as_dict(self) -> dict[str, Any]:
        return {"edge": self.name, "inside": self.inside, "neutral": self.neutral, "outside": self.outside, "flat": self.flat}


def offset_length(points: Callable[[np.ndarray], np.ndarray], normals: Callable[[np.ndarray], np.ndarray], t: float) -> float:
    r"""Length of the offset curve ``c(s) + t n(s)``, s ∈ [0, 1], by Romberg-extrapolated chord sums
    (513 samples, O(h⁶), :func:`ght_cad.pattern.model.romberg_length`)."""
    s = np.linspace(0.0, 1.0, 513)
    p = np.asarray(points(s), dtype=float)
    if t:
        p = p + t * np.asarray(normals(s), dtype=float)
    return romberg_length(p)


def sheet_info(sheet: Sheet, edges: list[EdgeLengths], rows: list[FormingRow], chart: dict[str, list[float]], rmin: float) -> dict[str, Any]:
    """The ``panel.info["sheet"]`` entry: the sheet, edge lengths, forming rows and chart samples."""
    d = sheet.as_dict()
    d.update(
        {
            "min_bending_radius": rmin,
            "edges": [e.as_dict() for e in edges],
            "forming": [r.as_dict() for r in rows],
            "chart": chart,
        }
    )
    return d


__all__ += ["EdgeLengths", "offset_length", "sheet_info"]


# -- unrolling hooks (called by ght_cad.unroll and ght_cad.unrolling.face_unroll for T > 0) --------------
def _label_height(panel: Any) -> float:
    lo, hi = panel.bbox()
    return 0.012 * float(np.max(hi - lo))


def _add_forming_texts(panel: Any, rows: list[FormingRow], flat_line: Callable[[float], tuple[np.ndarray, np.ndarray]]) -> None:
    """Forming labels (layer FORMING): along each bend line, at its middle or, where that point is
    off the trimmed outline (a hole, a cut), at the first of 1/4, 3/4, 1/10, 9/10 of it inside; a
    bend line with no point inside gets no label (its row stays in the table)."""
    h = _label_height(panel)
    loops = panel.loop_polylines()
    for r in rows:
        p, q = flat_line(r.u)
        cand = np.array([p + f * (q - p) for f in (0.5, 0.25, 0.75, 0.1, 0.9)])
        ins = _inside(cand, loops)
        if not ins.any():
            continue
        mid = cand[int(np.argmax(ins))]
        ang = math.degrees(math.atan2(q[1] - p[1], q[0] - p[0]))
        if ang > 90:
            ang -= 180
        elif ang < -90:
            ang += 180
        r.xy = (float(mid[0]), float(mid[1]))
        panel.forming_texts.append((float(mid[0]), float(mid[1]), r.label(), h, ang))


def unroll_ruled_sheet(surface: RuledSurface, sheet: Sheet, *, label: str = "P1", **kwargs: Any) -> Any:
    r"""Flat pattern of the neutral offset ``S + δ n`` of a ruled surface (module doc).

    Checks the offset (:func:`check_offset`), unrolls :class:`OffsetRuledSurface` by
    :func:`ght_cad.unrolling.ruled_development.unroll_ruled_surface`, and puts into ``panel.info["sheet"]`` the sheet, the
    inside/neutral/outside lengths of the four boundary edges (``Σ_k ∫_{u_k}^{u_{k+1}} |a' + t n'| du``
    by adaptive Gauss–Legendre on every smooth piece between the surface's ``breakpoints``,
    ``t = 0, δ, σT``; rulings keep their length), the forming rows of the bend
    lines and the chart samples; forming labels go to ``panel.forming_texts``.

    Raises:
        SheetError: the thickness is beyond a bending radius (:func:`check_offset`).
    """
    from ..curves.curve import integrate

    rmin = check_offset(surface, sheet, f"surface {label!r}")
    off = OffsetRuledSurface(surface, sheet.neutral_offset)
    pat = unroll_ruled_surface(off, label=label, breakpoints=off.breakpoints, **kwargs)
    panel = pat.panels[0]

    def edge_len(which: str, t: float) -> float:
        # piecewise between the breakpoints (a loft's joint rulings, where |a' + t n'| jumps: one
        # adaptive rule across them was off by 3e-6 relative on the hull plate with fans)
        f = surface.a if which == "a" else surface.b
        return sum(integrate(lambda x: np.linalg.norm(f(x, 1) + t * ruling_normal(surface, x, 1)[1], axis=1), lo, hi,
                             rtol=1e-14) for lo, hi in _smooth_pieces(surface))

    g0, g1 = (float(x) for x in surface.ruling_lengths(np.array([0.0, 1.0])))
    edges = []
    for e in panel.loops[0]:
        if e.name in ("a", "b"):
            inside, outside = edge_len(e.name, 0.0), edge_len(e.name, sheet.outside_offset)
        else:
            inside = outside = g1 if e.name == "ruling u=1" else g0
        edges.append(EdgeLengths(e.name, inside, float(e.length_3d), outside, float(e.length_flat)))
    rulings = kwargs.get("rulings", 16)
    lines = (np.arange(1, rulings + 1) / (rulings + 1)) if rulings else np.zeros(0)
    rows, chart = forming_rows(surface, sheet, lines)

    def flat_line(u: float) -> tuple[np.ndarray, np.ndarray]:
        y = panel.map(np.array([u, u]), np.array([0.0, 1.0]))
        return y[0], y[1]

    _add_forming_texts(panel, rows, flat_line)
    panel.info["sheet"] = sheet_info(sheet, edges, rows, chart, rmin)
    return pat


class FaceSheet:
    r"""The sheet hook of :func:`ght_cad.unrolling.face_unroll.unroll_face_data` for one face.

    The neutral surface is :class:`OffsetSurfaceAdapter` (``δ = σ K T`` along the face normal,
    orientation included); curvature checks and forming data use the base face's ruled surface
    (:class:`ght_cad.unrolling.face_unroll.FaceRuledSurface` along its ruling direction).

    Raises:
        SheetError: a thickness beyond a bending radius (:func:`check_offset`).
    """

    def __init__(self, face: Any, sheet: Sheet, label: str) -> None:
        self.sheet = sheet
        self.base = face.surface
        self.bounds = tuple(face.bounds)
        orient = -1.0 if getattr(face, "reversed", False) else 1.0
        self.neutral = OffsetSurfaceAdapter(self.base, sheet.neutral_offset, orient, self.bounds)
        self.outside = OffsetSurfaceAdapter(self.base, sheet.outside_offset, orient, self.bounds)
        self.unit = OffsetSurfaceAdapter(self.base, 1.0, orient, self.bounds)
        self.label = label
        if self.base.kind == "plane":
            self.ruled_dir: str | None = None
        elif self.base.kind in ("cylinder", "cone", "extrusion"):
            self.ruled_dir = "v"
        else:
            self.ruled_dir = ruling_direction(self.base, self.bounds)[0]
        self.rs = None
        self.sign = 1.0
        self.rmin = math.inf
        if self.ruled_dir is not None:
            self.rs = FaceRuledSurface(self.base, self.ruled_dir, self.bounds)
            n_rs = ruling_normal(self.rs, np.array([0.5]), 0)[0][0]
            u0, u1, v0, v1 = self.bounds
            n_f = self.unit.normal(np.array([0.5 * (u0 + u1)]), np.array([0.5 * (v0 + v1)]))[0]
            self.sign = 1.0 if float(n_rs @ n_f) >= 0 else -1.0
            self.rmin = check_offset(self.rs, sheet, f"face {label!r}", sign=self.sign)

    def edge_xyz(self, uv: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]) -> Callable[[np.ndarray], np.ndarray]:
        """t -> points of the edge on the neutral surface."""
        return lambda t: self.neutral.value(*(np.asarray(x, dtype=float) for x in uv(t)))

    def finish(self, panel: Any, dmap: Any, rulings: int, wires: Sequence[Sequence[Any]]) -> None:
        """Edge lengths (inside = the face's own edges, neutral = measured, outside = Romberg of
        ``S + σT n`` on the pcurve), forming rows and labels into the panel (before placement)."""
        edges = []
        for loop, wire in zip(panel.loops, wires):
            for e, ed in zip(loop, wire):
                def pts(t: np.ndarray, uvf: Callable = ed.uv) -> np.ndarray:
                    return self.outside.value(*(np.asarray(x, dtype=float) for x in uvf(t)))

                outside = offset_length(pts, lambda t: 0.0, 0.0) if ed.length_3d > 0 else 0.0
                edges.append(EdgeLengths(e.name, float(ed.length_3d), float(e.length_3d), outside, float(e.length_flat)))
        rows: list[FormingRow] = []
        chart: dict[str, list[float]] = {"position": [], "radius_a": [], "radius_b": []}
        if self.rs is not None:
            lines = (np.arange(1, rulings + 1) / (rulings + 1)) if rulings else np.zeros(0)
            rows, chart = forming_rows(self.rs, self.sheet, lines, sign=self.sign)

            def flat_line(t: float) -> tuple[np.ndarray, np.ndarray]:
                uu, vv = self.rs.uv(np.array([t, t]), np.array([0.0, 1.0]))
                y = dmap.map(uu, vv)
                return y[0], y[1]

            _add_forming_texts(panel, rows, flat_line)
        panel.info["sheet"] = sheet_info(self.sheet, edges, rows, chart, self.rmin)


__all__ += ["unroll_ruled_sheet", "FaceSheet"]
