r"""Flat patterns: outline loops, bend lines, labels, distortion report and DXF/SVG/PNG export.

A :class:`FlatPattern` holds one :class:`FlatPanel` per unrolled surface/face. Every panel is
checked against its 3-D original (spec section 6) in a :class:`DistortionReport`:

* boundary length: relative error ``|ℓ_flat - ℓ_3d| / ℓ_3d`` per boundary edge; flat lengths by
  Romberg-extrapolated chord sums (``N, 2N, 4N`` uniform samples, error O(h⁶)), 3-D lengths by
  adaptive Gauss–Legendre quadrature of ``|c'|`` where available;
* ruling length: ``| |Y(u,1) - Y(u,0)| - |g(u)| | / |g(u)|`` at 129 rulings;
* area: ``|area_flat - area_3d| / area_3d``, flat area by Romberg-extrapolated shoelace sums over
  all loops (outer minus holes), 3-D area by quadrature of ``|X_u × X_v|``;
* angle: ``|angle(Y_u, Y_v) - angle(X_u, X_v)|`` in degrees on a parameter grid (first
  fundamental form), flat partials by 5-point central differences of the development map.

Exports write atomically through :mod:`ght_cad.io`; ezdxf and matplotlib are imported inside the
exporting methods only.
"""

from __future__ import annotations

import functools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence
from xml.sax.saxutils import escape

import numpy as np

from .errors import GHTError
from ._vec import einsum as _einsum
from ._vec import stack as _stack
from .io import atomic_path, write_text_atomic

__all__ = [
    "BoundaryEdge",
    "FlatPanel",
    "FlatPattern",
    "DistortionReport",
    "measure_panel",
    "romberg_length",
    "layout_panels",
    "mark_shared_edges",
    "shared_edge_pairs",
    "INSUNITS",
    "SVG_UNITS",
    "CHORD_TOL_MM",
    "default_chord_tol",
]

#: DXF $INSUNITS codes
INSUNITS = {"unitless": 0, "in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6}

#: SVG width/height unit and scale per model unit: SVG lengths know mm, cm, in (not m, ft), so
#: ``1 m = 1000 mm`` and ``1 ft = 12 in``; the viewBox stays in model units (true-scale print).
SVG_UNITS = {
    "unitless": ("", 1.0),
    "mm": ("mm", 1.0),
    "cm": ("cm", 1.0),
    "m": ("mm", 1000.0),
    "in": ("in", 1.0),
    "ft": ("in", 12.0),
}

#: millimetres per model unit (the SVG's physical stroke width and dash lengths)
_MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "ft": 304.8}

#: SVG stroke width of every line at true scale, millimetres
SVG_STROKE_MM = 0.25

#: default chord tolerance of the DXF/SVG outlines, millimetres (converted to the pattern's unit)
CHORD_TOL_MM = 1e-3


def default_chord_tol(units: str) -> float:
    """The default outline chord tolerance in ``units``: ``CHORD_TOL_MM / (mm per unit)`` (1 µm;
    a unitless pattern: 1e-3)."""
    return CHORD_TOL_MM / _MM_PER_UNIT.get(units, 1.0)

_ROMBERG_N = 128
#: relative |R2 - R| below which the outline samples' Romberg length is accepted (BoundaryEdge.measure)
_ROMBERG_ACCEPT = 1e-10

#: 3-D arc-length fractions of the edge-mark ticks (double tick near the start)
MARK_FRACTIONS = (0.2, 0.25, 0.5, 0.75)


def _chords(p: np.ndarray) -> float:
    d = p[1:] - p[:-1]
    return float(np.sum(np.sqrt(_einsum("ij,ij->i", d, d))))


@functools.lru_cache(maxsize=8)
def _unit_samples(n: int) -> np.ndarray:
    """``linspace(0, 1, n)``, made once per n (read-only)."""
    t = np.linspace(0.0, 1.0, n)
    t.flags.writeable = False
    return t


def romberg_length(points: np.ndarray) -> float:
    r"""Length of a smooth curve from ``4N + 1`` uniform-parameter samples (N divisible by 1).

    ``ℓ_N`` is the chord sum on every 4th sample, ``ℓ_2N`` on every 2nd, ``ℓ_4N`` on all; the
    chord-sum error expands in even powers of h, so two Richardson steps
    ``R1 = (4 ℓ_2h - ℓ_h) / 3``, ``R = (16 R1_fine - R1_coarse) / 15`` leave O(h⁶).
    """
    p = np.asarray(points, dtype=float)
    if (p.shape[0] - 1) % 4:
        raise GHTError(f"romberg_length needs 4N+1 samples; got {p.shape[0]}")
    return _romberg_pair(p)[0]


def piecewise_samples(breaks: Sequence[float], m: int) -> np.ndarray | None:
    r"""Parameters ``t`` of ``m + 1`` uniform samples on every piece ``[t_k, t_{k+1}]`` of [0, 1]
    cut at ``breaks`` (those in (0, 1)), joints shared: ``P m + 1`` points for P pieces, piece k at
    indices ``k m .. (k + 1) m``. None when no break lies inside (0, 1).

    With ``m`` divisible by 4, every 2nd and every 4th sample are again uniform on each piece and
    hit every joint, so chord sums (:func:`piecewise_romberg_length`) and shoelace areas
    (:func:`measure_panel`) on ``[::4]``, ``[::2]``, ``[::1]`` extrapolate piece by piece.
    """
    bp = sorted({float(b) for b in breaks if 0.0 < float(b) < 1.0})
    if not bp:
        return None
    edges = [0.0, *bp, 1.0]
    parts = [np.linspace(lo, hi, m + 1)[:-1] for lo, hi in zip(edges[:-1], edges[1:])]
    return np.concatenate(parts + [np.array([1.0])])


def piecewise_romberg_length(points: np.ndarray, m: int) -> float:
    r"""Length of a piecewise smooth curve sampled by :func:`piecewise_samples` (``m + 1`` points a
    piece, ``m = 4N``): ``Σ_k R_k``, ``R_k`` the Romberg length (:func:`romberg_length`, O(h⁶)) of
    piece k. Between joints the chord-sum error expands in even powers of h; a chord across a joint
    where the curvature jumps would leave an O(h³) term that Romberg cannot remove."""
    p = np.asarray(points, dtype=float)
    if m % 4 or (p.shape[0] - 1) % m:
        raise GHTError(f"piecewise_romberg_length needs k*{m}+1 samples with {m} divisible by 4; got {p.shape[0]}")
    return float(sum(_romberg_pair(p[i: i + m + 1])[0] for i in range(0, p.shape[0] - 1, m)))


def _outline_serves_length(samples: int) -> bool:
    """``samples = 4N + 1`` outline points with ``N_ROMBERG / 2 <= N <= N_ROMBERG``: their Romberg
    length may serve (:meth:`BoundaryEdge.measure`)."""
    m = samples - 1
    return m % 4 == 0 and 2 * _ROMBERG_N <= m <= 4 * _ROMBERG_N


def _romberg_pairs(P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_romberg_pair` of several polylines with the same number of points at once,
    ``P`` (k, 4N + 1, d): the arrays ``(R, R2)``."""
    ls = []
    for step in (4, 2, 1):
        q = P[:, ::step]
        d = q[:, 1:] - q[:, :-1]
        ls.append(np.sqrt(_einsum("eij,eij->ei", d, d)).sum(axis=1))
    l1, l2, l4 = ls
    r1 = (4 * l2 - l1) / 3
    r2 = (4 * l4 - l2) / 3
    return (16 * r2 - r1) / 15, r2


def _romberg_pair(p: np.ndarray) -> tuple[float, float]:
    """``(R, R2)``: the Romberg length of :func:`romberg_length` and its O(h⁴) value
    ``R2 = (4 ℓ_4N - ℓ_2N) / 3`` (``|R2 - R|`` estimates R2's error)."""
    l1, l2, l4 = _chords(p[::4]), _chords(p[::2]), _chords(p)
    r1 = (4 * l2 - l1) / 3
    r2 = (4 * l4 - l2) / 3
    return (16 * r2 - r1) / 15, r2


def _dxf_ascii(text: str) -> str:
    """Text for an ASCII DXF R12 file: every non-ASCII character as the DXF escape ``\\U+XXXX``
    (outside the BMP: ``?``; control characters, which would break the group-code/value lines, as
    spaces)."""
    out = []
    for ch in text:
        code = ord(ch)
        if code < 32:
            out.append(" ")
        elif code < 128:
            out.append(ch)
        elif code <= 0xFFFF:
            out.append(f"\\U+{code:04X}")
        else:  # outside the BMP (emoji ...): \U+ has four hex digits
            out.append("?")
    return "".join(out)


def _next(loop: np.ndarray) -> np.ndarray:
    """The vertices of a closed polyline shifted by one: ``loop[i + 1]``, the last one wrapping to
    ``loop[0]`` (``np.roll(loop, -1, axis=0)`` without its axis handling)."""
    return np.concatenate([loop[1:], loop[:1]])


def _shoelace(loop: np.ndarray) -> float:
    """Signed area of a closed polyline, ``½ Σ_i (x_i y_{i+1} - x_{i+1} y_i)`` (indices mod n), with
    the coordinates taken relative to the first vertex (the terms touching it vanish; less
    cancellation than in absolute coordinates)."""
    x, y = loop[1:, 0] - loop[0, 0], loop[1:, 1] - loop[0, 1]
    return 0.5 * float(np.sum(x[:-1] * y[1:] - x[1:] * y[:-1]))


@dataclass
class BoundaryEdge:
    """One boundary edge of a panel: flat and 3-D images as functions of t ∈ [0, 1].

    Attributes:
        name: edge name ("a", "b", "ruling u=0", OCC edge index ...).
        flat_fn: t -> (n, 2) flat points.
        xyz_fn: t -> (n, 3) points on the 3-D surface.
        length_3d: exact 3-D length if known (else measured by Romberg chord sums).
        samples: number of output polyline points.
        xyz: the 3-D points at the ``samples`` outline parameters, ``xyz_fn`` evaluated on first
            access (a single panel needs none; shared-edge marks and exports ask for them).
        breaks: edge parameters ``t`` in (0, 1) where the edge is not smooth (a developable loft's
            joint rulings: the edge is G1 there but its curvature and parametric speed jump). The
            length and area measures then sample every smooth piece ``[t_k, t_{k+1}]`` on its
            own ``4 _ROMBERG_N + 1`` uniform points (:func:`piecewise_samples`), so Romberg's
            even-power error expansion holds on each piece; a chord across a break leaves an
            O(h³) term Romberg cannot remove (measured 1e-11 .. 2e-7 relative on loft edges with
            fans). The outline polyline ``flat`` stays the ``samples`` uniform points.
    """

    name: str
    flat_fn: Callable[[np.ndarray], np.ndarray]
    xyz_fn: Callable[[np.ndarray], np.ndarray]
    length_3d: float | None = None
    samples: int = 257
    flat: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    xyz: np.ndarray | None = None  # a property below: evaluated on first access
    length_flat: float = float("nan")
    dense_flat: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    _xyz: np.ndarray | None = field(default=None, init=False, repr=False, compare=False)
    breaks: tuple[float, ...] = ()

    def _pieces(self) -> np.ndarray | None:
        """The dense measuring parameters of an edge with ``breaks`` (None: no break inside)."""
        return piecewise_samples(self.breaks, 4 * _ROMBERG_N)

    def measure(self, pair: tuple[float, float] | None = None) -> None:
        """Sample the edge and measure its flat length (Romberg, :func:`romberg_length`).

        The ``samples`` outline points serve the length when they are ``4N + 1`` with
        ``N >= _ROMBERG_N / 2`` and Romberg's own estimate accepts them: the h⁴ value ``R2`` and
        the h⁶ value ``R`` agree to ``|R2 - R| <= _ROMBERG_ACCEPT · R`` (R's error is then smaller
        by about h², far below round-off for a smooth edge); otherwise (a tight circle, a short
        ``samples``) the edge is sampled at ``4 _ROMBERG_N + 1`` points as before.

        Args:
            pair: ``(R, R2)`` of :func:`_romberg_pair` for ``self.flat`` already sampled (several
                edges' pairs computed together, :func:`measure_panel`); None: sample and compute.
        """
        if pair is None:
            self.flat = np.asarray(self.flat_fn(_unit_samples(self.samples)), dtype=float)
        length = None
        t_pw = self._pieces()
        if t_pw is not None:  # breaks inside: every smooth piece measured on its own samples
            self.densify()
            if self.length_3d is None:
                self.length_3d = piecewise_romberg_length(np.asarray(self.xyz_fn(t_pw), dtype=float), 4 * _ROMBERG_N)
            return
        if _outline_serves_length(self.samples):
            length, r2 = pair if pair is not None else _romberg_pair(self.flat)
            if not (math.isfinite(length) and abs(r2 - length) <= _ROMBERG_ACCEPT * abs(length)):
                length = None
        if length is None:
            self.densify()
        else:
            self.dense_flat = self.flat
            self.length_flat = length
        if self.length_3d is None:
            t = np.linspace(0.0, 1.0, 4 * _ROMBERG_N + 1)
            dense = np.asarray(self.xyz_fn(t), dtype=float)
            self.length_3d = romberg_length(dense)
            if (4 * _ROMBERG_N) % max(self.samples - 1, 1) == 0:  # the outline's points are among them
                self._xyz = dense[::4 * _ROMBERG_N // max(self.samples - 1, 1)].copy()

    def densify(self) -> None:
        """Flat samples at ``4 _ROMBERG_N + 1`` points (``dense_flat``) and the length from them;
        with ``breaks``, ``4 _ROMBERG_N + 1`` points on every smooth piece (joints shared) and the
        sum of the pieces' Romberg lengths (:func:`piecewise_romberg_length`)."""
        t_pw = self._pieces()
        if t_pw is not None:
            self.dense_flat = np.asarray(self.flat_fn(t_pw), dtype=float)
            self.length_flat = piecewise_romberg_length(self.dense_flat, 4 * _ROMBERG_N)
            return
        t = np.linspace(0.0, 1.0, 4 * _ROMBERG_N + 1)
        self.dense_flat = np.asarray(self.flat_fn(t), dtype=float)
        self.length_flat = romberg_length(self.dense_flat)


def _get_xyz(self: BoundaryEdge) -> np.ndarray:
    if self._xyz is None:
        if self.xyz_fn is None:
            return np.zeros((0, 3))
        self._xyz = np.asarray(self.xyz_fn(np.linspace(0.0, 1.0, self.samples)), dtype=float)
    return self._xyz


def _set_xyz(self: BoundaryEdge, value: Any) -> None:
    if isinstance(value, property):  # the dataclass default (the property itself): not set
        value = None
    self._xyz = None if value is None else np.asarray(value, dtype=float)


BoundaryEdge.xyz = property(_get_xyz, _set_xyz, doc="3-D points at the outline parameters, (samples, 3) (evaluated on first access).")  # type: ignore[assignment]


@dataclass
class DistortionReport:
    """Distortion of a flat pattern against its 3-D original (see module doc for definitions).

    Attributes:
        boundary_length: relative length error of each boundary edge.
        boundary_names: the edges' names.
        ruling_length: relative length errors of sampled rulings.
        area: relative area errors (one per panel).
        angle_deg: absolute angle errors of the first fundamental form, degrees.
        stretch: relative errors ``|Y_u| / |X_u| - 1`` on the same grid.
    """

    boundary_length: np.ndarray
    boundary_names: list[str]
    ruling_length: np.ndarray
    area: np.ndarray
    angle_deg: np.ndarray
    stretch: np.ndarray
    info: dict[str, Any] = field(default_factory=dict)

    @staticmethod
    def _mr(x: np.ndarray) -> tuple[float, float]:
        x = np.abs(np.asarray(x, dtype=float))
        if x.size == 0:
            return 0.0, 0.0
        return float(x.max()), float(np.sqrt(np.mean(x**2)))

    def as_dict(self) -> dict[str, dict[str, float]]:
        """``{quantity: {"max": ..., "rms": ...}}`` (relative, angles in degrees)."""
        out = {}
        for key in ("boundary_length", "ruling_length", "area", "angle_deg", "stretch"):
            mx, rms = self._mr(getattr(self, key))
            out[key] = {"max": mx, "rms": rms}
        return out

    @property
    def max_relative_error(self) -> float:
        """Largest relative length/area error (boundary, ruling, area)."""
        d = self.as_dict()
        return max(d["boundary_length"]["max"], d["ruling_length"]["max"], d["area"]["max"])

    def summary(self) -> str:
        """Short text summary (max and RMS per quantity)."""
        d = self.as_dict()
        lines = ["distortion report (relative errors; angles in degrees)"]
        names = {
            "boundary_length": "boundary length",
            "ruling_length": "ruling length",
            "area": "area",
            "angle_deg": "angle (deg)",
            "stretch": "metric stretch",
        }
        for k, nm in names.items():
            lines.append(f"  {nm:16s} max {d[k]['max']:.3e}   rms {d[k]['rms']:.3e}")
        worst = int(np.argmax(np.abs(self.boundary_length))) if self.boundary_length.size else -1
        if worst >= 0:
            lines.append(f"  worst boundary edge: {self.boundary_names[worst]}")
        return "\n".join(lines)

    @classmethod
    def combine(cls, reports: Sequence["DistortionReport"]) -> "DistortionReport":
        return cls(
            boundary_length=np.concatenate([r.boundary_length for r in reports]),
            boundary_names=[n for r in reports for n in r.boundary_names],
            ruling_length=np.concatenate([r.ruling_length for r in reports]),
            area=np.concatenate([r.area for r in reports]),
            angle_deg=np.concatenate([r.angle_deg for r in reports]),
            stretch=np.concatenate([r.stretch for r in reports]),
        )


@dataclass
class FlatPanel:
    """One unrolled face: boundary loops (first = outer), bend lines, marks and labels.

    Attributes:
        label: panel label.
        loops: list of loops, each a list of :class:`BoundaryEdge` in order; loop 0 is the outer.
        bend_lines: (k, 2, 2) ruling segments (bend lines), already clipped to the panel.
        ruling_lengths_3d / ruling_lengths_flat: sampled ruling lengths for the report.
        area_3d: 3-D area of the face.
        metric: first-fundamental-form samples (angle_3d, angle_flat, xu_len, yu_len).
        development: the development map object (``.map(u, v)``), before ``offset``.
        offset: translation applied after the development map (composite layout).
    """

    label: str
    loops: list[list[BoundaryEdge]]
    bend_lines: np.ndarray
    ruling_lengths_3d: np.ndarray
    ruling_lengths_flat: np.ndarray
    area_3d: float
    metric: dict[str, np.ndarray]
    info: dict[str, Any] = field(default_factory=dict)
    development: Any = None
    offset: np.ndarray = field(default_factory=lambda: np.zeros(2))
    marks: list[np.ndarray] = field(default_factory=list)
    texts: list[tuple[float, float, str, float]] = field(default_factory=list)
    #: sheet forming labels (x, y, text, height, rotation in degrees): layer FORMING (ght_cad.sheet)
    forming_texts: list[tuple[float, float, str, float, float]] = field(default_factory=list)
    #: bend annotations (x, y, text, height, rotation in degrees): layer BEND (a blank's bend
    #: direction, angle and inside radius, ght_cad.blank)
    bend_texts: list[tuple[float, float, str, float, float]] = field(default_factory=list)
    report: DistortionReport | None = None
    area_flat: float = float("nan")
    _arcs: dict[float, list[tuple[np.ndarray, np.ndarray, list[str]]]] = field(
        default_factory=dict, init=False, repr=False, compare=False)

    def loop_arcs(self, chord_tol: float) -> list[tuple[np.ndarray, np.ndarray, list[str]]]:
        """Closed loops as lines and circular arcs (:mod:`ght_cad.outline_arcs`), offset applied.

        Every boundary edge becomes an :class:`~ght_cad.outline_arcs.ArcChain`: one exact line or
        arc when its development is one (within ``1e-12`` of the panel's size), else arcs through
        three points of the exact edge within ``chord_tol`` of it. Corners are the development's
        edge end points.

        Args:
            chord_tol: largest distance between the exact flat edges and the written arcs (the
                pattern's units).

        Returns:
            Per loop ``(points (n, 2), bulges (n,), kinds)``: segment ``i`` runs from
            ``points[i]`` to ``points[i + 1 mod n]`` with DXF bulge ``bulges[i]`` (``tan(θ/4)``,
            θ the signed sweep, 0 straight); ``kinds`` the edges' kinds ("line", "arc", "arcs",
            "curve", "point").
        """
        from .outline_arcs import arc_chain

        key = float(chord_tol)
        if key not in self._arcs:
            lo, hi = self.bbox()
            size = float(np.max(hi - lo))
            loops = []
            for loop in self.loops:
                pts, bul, kinds = [], [], []
                for e in loop:
                    grid = e.flat if e.flat.shape[0] == e.samples and not e.breaks else None
                    ch = arc_chain(e.flat_fn, key, size, e.breaks, grid)
                    kinds.append(ch.kind)
                    if ch.bulges.size:  # a zero-length edge adds no segment
                        pts.append(ch.points[:-1])
                        bul.append(ch.bulges)
                if bul:
                    loops.append((np.concatenate(pts), np.concatenate(bul), kinds))
            self._arcs[key] = loops
        return [(p + self.offset, b, k) for p, b, k in self._arcs[key]]

    def loop_polylines(self) -> list[np.ndarray]:
        """Closed loops as (n, 2) arrays (last point not repeated), offset applied."""
        out = []
        for loop in self.loops:
            pts = np.concatenate([e.flat[:-1] for e in loop], axis=0)
            out.append(pts + self.offset)
        return out

    def translate(self, delta: np.ndarray) -> None:
        delta = np.asarray(delta, dtype=float)
        self.offset = self.offset + delta
        if self.bend_lines.size:
            self.bend_lines = self.bend_lines + delta
        self.marks = [m + delta for m in self.marks]
        self.texts = [(float(x + delta[0]), float(y + delta[1]), s, h) for x, y, s, h in self.texts]
        self.forming_texts = [(float(x + delta[0]), float(y + delta[1]), s, h, a) for x, y, s, h, a in self.forming_texts]
        self.bend_texts = [(float(x + delta[0]), float(y + delta[1]), s, h, a) for x, y, s, h, a in self.bend_texts]

    def bbox(self, loops: list[np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Lower-left and upper-right corners of the outline (``loops``: :meth:`loop_polylines`
        when already made)."""
        pts = np.concatenate(self.loop_polylines() if loops is None else loops, axis=0)
        return points_bbox(pts)

    def map(self, u: Any, v: Any) -> np.ndarray:
        """Flat image of surface parameters (u, v) in pattern coordinates."""
        if self.development is None:
            raise GHTError(f"panel {self.label!r} has no development map")
        return self.development.map(u, v) + self.offset


def points_bbox(pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(pts.min(axis=0), pts.max(axis=0))`` of (n, d) points (the same values), column by
    column: numpy's reduction across the rows of an (n, 2) array costs 27 µs for 1,000 points, a
    column's 1-D reduction 1 µs."""
    cols = [pts[:, k] for k in range(pts.shape[1])]
    return np.array([c.min() for c in cols]), np.array([c.max() for c in cols])


def _point_in_polygon(pts: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd ray casting, vectorized over points (in chunks of ~2e6 point-edge pairs): a ray
    from each point towards +x crosses the edges whose end points lie on either side of its
    height, at ``x0 + (y - y0)(x1 - x0)/(y1 - y0)``; only those pairs are evaluated."""
    step = max(1, int(2e6 // max(len(poly), 1)))
    if len(pts) > step:
        return np.concatenate([_point_in_polygon(pts[i : i + step], poly) for i in range(0, len(pts), step)])
    nxt = _next(poly)
    y = pts[:, 1][:, None]
    i, j = np.nonzero((poly[:, 1][None, :] > y) != (nxt[:, 1][None, :] > y))
    x0, y0, x1, y1 = poly[j, 0], poly[j, 1], nxt[j, 0], nxt[j, 1]
    xi = x0 + (pts[i, 1] - y0) * (x1 - x0) / (y1 - y0)
    return (np.bincount(i[pts[i, 0] < xi], minlength=len(pts)) % 2) == 1


def _inside(pts: np.ndarray, loops: list[np.ndarray]) -> np.ndarray:
    ins = _point_in_polygon(pts, loops[0])
    for h in loops[1:]:
        ins &= ~_point_in_polygon(pts, h)
    return ins


def _sagitta(loop: np.ndarray) -> float:
    """Largest chord-to-curve deviation estimate of a closed polyline at its smooth vertices
    (turning < 10 degrees): a quarter of the vertex's distance from its neighbours' chord."""
    a, b, c = np.concatenate([loop[-1:], loop[:-1]]), loop, _next(loop)
    ac = c - a
    n = np.linalg.norm(ac, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = np.abs(ac[:, 0] * (b - a)[:, 1] - ac[:, 1] * (b - a)[:, 0]) / n
        u, v = b - a, c - b
        turn = np.arctan2(np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]), _einsum("ij,ij->i", u, v))
    smooth = (turn < math.radians(10)) & (n > 0)
    return float(np.max(dist[smooth]) / 4) if smooth.any() else 0.0


def clip_segments(segments: np.ndarray, loops: list[np.ndarray]) -> np.ndarray:
    """Clip (k, 2, 2) segments to the region inside ``loops[0]`` and outside ``loops[1:]``.

    Crossings within a few polyline sagittas of a segment end are the end meeting the polygonal
    approximation of a curved boundary, not a cut, and are ignored. Vectorized over segments x
    polygon edges; only segments with interior crossings are split one by one.
    """
    segments = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    if segments.shape[0] == 0:
        return segments
    step = max(1, int(2e6 // sum(len(lp) for lp in loops)))
    if segments.shape[0] > step:  # bound the (segments x edges) work arrays
        parts = [clip_segments(segments[i : i + step], loops) for i in range(0, segments.shape[0], step)]
        return np.concatenate(parts, axis=0)
    A = np.concatenate(loops, axis=0)
    S = np.concatenate([_next(lp) for lp in loops], axis=0) - A  # (m, 2) polygon edges
    P, Q = segments[:, 0], segments[:, 1]
    R = Q - P  # (k, 2)
    sag = max(_sagitta(lp) for lp in loops)
    dt = np.minimum(1e-3, 8.0 * sag / np.maximum(np.sqrt(_einsum("ij,ij->i", R, R)), 1e-300))[:, None]
    # P + t R = A + w S: with 2-D cross products x × y = x_0 y_1 - x_1 y_0 (as matrix products)
    Sp = _stack([S[:, 1], -S[:, 0]])  # (2, m): x @ Sp = x × S
    Rp = _stack([R[:, 1], -R[:, 0]])  # (2, k)
    den = R @ Sp  # R × S, (k, m)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (_einsum("ij,ji->i", A, Sp)[None, :] - P @ Sp) / den  # ((A - P) × S) / (R × S)
        w = ((A @ Rp).T - _einsum("ij,ji->i", P, Rp)[:, None]) / den  # ((A - P) × R) / (R × S)
    sel = (np.abs(den) > 1e-300) & (t > dt) & (t < 1 - dt) & (w >= 0) & (w <= 1)
    crossing = sel.any(axis=1)
    out: list[tuple[int, np.ndarray]] = []  # (segment index, piece): keeps the input order
    plain = np.nonzero(~crossing)[0]
    # the pieces' mid points of all segments (whole plain segments, split crossing ones) in one
    # inside test
    cuts = [np.unique(np.concatenate([[0.0, 1.0], t[i, sel[i]]])) for i in np.nonzero(crossing)[0]]
    mids = [P[plain] + 0.5 * R[plain]]
    mids += [P[i] + (0.5 * (ts[:-1] + ts[1:]))[:, None] * R[i] for i, ts in zip(np.nonzero(crossing)[0], cuts)]
    keep_all = _inside(np.concatenate(mids, axis=0), loops)
    keep, start = keep_all[:plain.size], plain.size
    out.extend((int(i), segments[i]) for i in plain[keep])
    for i, ts in zip(np.nonzero(crossing)[0], cuts):
        keep = keep_all[start:start + ts.size - 1]
        start += ts.size - 1
        for j in np.nonzero(keep)[0]:
            if ts[j + 1] - ts[j] > 1e-9:
                out.append((int(i), np.array([P[i] + ts[j] * R[i], P[i] + ts[j + 1] * R[i]])))
    out.sort(key=lambda item: item[0])
    return np.asarray([seg for _, seg in out], dtype=float).reshape(-1, 2, 2)


def measure_panel(panel: FlatPanel) -> DistortionReport:
    """Sample the panel's edges, measure flat vs 3-D quantities, set ``panel.report``; add label."""
    names, rel = [], []
    # the outline samples of all edges, their Romberg lengths together per sample count
    pairs: dict[int, tuple[float, float]] = {}
    groups: dict[int, list[BoundaryEdge]] = {}
    for e in (e for loop in panel.loops for e in loop):
        e.flat = np.asarray(e.flat_fn(_unit_samples(e.samples)), dtype=float)
        if _outline_serves_length(e.samples) and not e.breaks:
            groups.setdefault(e.samples, []).append(e)
    for es in groups.values():
        R, R2 = _romberg_pairs(_stack([e.flat for e in es]))
        pairs.update({id(e): (float(a), float(b)) for e, a, b in zip(es, R, R2)})
    for li, loop in enumerate(panel.loops):
        for e in loop:
            e.measure(pair=pairs.get(id(e), (math.nan, math.nan)))
            names.append(f"{panel.label}:{'outer' if li == 0 else f'hole{li}'}:{e.name}")
            L3 = float(e.length_3d)
            rel.append(abs(e.length_flat - L3) / L3 if L3 > 0 else abs(e.length_flat))
    # Romberg on the shoelace area: every edge at N, 2N, 4N segments (an edge's N is its own: the
    # shoelace error still expands in even powers of the common refinement factor); when the
    # O(h⁴) and O(h⁶) values disagree by more than _ROMBERG_ACCEPT, every edge is densified
    for attempt in range(2):
        areas = []
        for step in (4, 2, 1):
            tot = 0.0
            for li, loop in enumerate(panel.loops):
                pts = np.concatenate([e.dense_flat[::step][:-1] for e in loop], axis=0)
                a = abs(_shoelace(pts))
                tot += a if li == 0 else -a
            areas.append(tot)
        r1 = (4 * areas[1] - areas[0]) / 3
        r2 = (4 * areas[2] - areas[1]) / 3
        panel.area_flat = (16 * r2 - r1) / 15
        coarse = [e for loop in panel.loops for e in loop if e.dense_flat.shape[0] < 4 * _ROMBERG_N + 1]
        if attempt or not coarse or abs(r2 - panel.area_flat) <= _ROMBERG_ACCEPT * abs(panel.area_flat):
            break
        for e in coarse:
            e.densify()
    area_rel = abs(panel.area_flat - panel.area_3d) / panel.area_3d
    g3, gf = panel.ruling_lengths_3d, panel.ruling_lengths_flat
    # relative to the ruling's length; a ruling shorter than 1e-6 of the longest (1 µm on a metre:
    # a pointed end read back from a B-spline face, 2e-13 on 500 mm, whose two measurements differ
    # by rounding, 1e-13) relative to that floor; a zero-length ruling by its absolute error
    gmax = float(g3.max()) if g3.size else 0.0
    ruling_rel = np.abs(gf - g3) / np.where(g3 > 0, np.maximum(g3, 1e-6 * gmax), 1.0)
    m = panel.metric
    ang = np.degrees(np.abs(m["angle_flat"] - m["angle_3d"])) if m else np.zeros(0)
    stretch = (m["yu_len"] / m["xu_len"] - 1.0) if m else np.zeros(0)
    panel.report = DistortionReport(
        boundary_length=np.asarray(rel),
        boundary_names=names,
        ruling_length=ruling_rel,
        area=np.array([area_rel]),
        angle_deg=ang,
        stretch=stretch,
        info={"area_flat": panel.area_flat, "area_3d": panel.area_3d},
    )
    # clip bend lines to the outline (trimmed faces, holes)
    loops = panel.loop_polylines()
    if panel.bend_lines.size:
        panel.bend_lines = clip_segments(panel.bend_lines, loops)
    lo, hi = panel.bbox(loops)
    c = _centroid(loops[0])
    ext = hi - lo
    # horizontal text is about 0.7 h wide per character: keep it within a third of the panel's width
    h = min(0.05 * float(max(ext)), 0.35 * float(ext[0]) / (0.7 * max(len(panel.label), 1)), 0.2 * float(ext[1]))
    panel.texts.append((float(c[0]), float(c[1]), panel.label, float(h)))
    return panel.report


def _centroid(poly: np.ndarray) -> np.ndarray:
    """Area centroid of a closed polyline (the label's place), the mean of its vertices when the
    area vanishes or the centroid lies outside (a crescent)."""
    x, y = poly[:, 0], poly[:, 1]
    nxt = _next(poly)
    x1, y1 = nxt[:, 0], nxt[:, 1]
    cr = x * y1 - x1 * y
    a = 0.5 * cr.sum()
    if abs(a) < 1e-300:
        return np.array([x.sum(), y.sum()]) / x.size
    c = np.array([(x + x1) @ cr, (y + y1) @ cr]) / (6 * a)
    if not _inside(c[None, :], [poly])[0]:
        return np.array([x.sum(), y.sum()]) / x.size
    return c


def layout_panels(panels: Sequence[FlatPanel], gap: float | None = None) -> None:
    """Place panels in rows (shelves) along +x, ``gap`` between bounding boxes (in place).

    Up to four panels stay in one row; with more, a row is closed when it would exceed
    ``max(widest panel, 1.5 sqrt(Σ bbox areas))``, so the sheet stays roughly square.
    """
    sizes = [p.bbox() for p in panels]
    big = max(float(np.max(hi - lo)) for lo, hi in sizes)
    g = 0.05 * big if gap is None else float(gap)
    if not (math.isfinite(g) and g >= 0):
        raise GHTError(f"gap={gap!r} is not allowed; it must be a finite length >= 0")
    dims = [hi - lo for lo, hi in sizes]
    row_width = max(max(float(d[0]) for d in dims), 1.5 * math.sqrt(sum(float(d[0] * d[1]) for d in dims)))
    if len(panels) <= 4:
        row_width = math.inf
    x = 0.0
    y = 0.0
    row_h = 0.0
    for p, (lo, hi) in zip(panels, sizes):
        w, h = float(hi[0] - lo[0]), float(hi[1] - lo[1])
        if x > 0 and x + w > row_width:
            y -= row_h + g
            x, row_h = 0.0, 0.0
        p.translate(np.array([x - lo[0], y - hi[1]]))
        x += w + g
        row_h = max(row_h, h)


def _polyline_param(poly: np.ndarray, pts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Distance of pts to polyline and fractional sample index of the nearest point."""
    a, b = poly[:-1], poly[1:]
    ab = b - a
    den = np.maximum(_einsum("ij,ij->i", ab, ab), 1e-300)
    t = np.clip(_einsum("kij,ij->ki", pts[:, None, :] - a[None], ab) / den, 0, 1)
    proj = a[None] + t[..., None] * ab[None]
    dist = np.linalg.norm(pts[:, None, :] - proj, axis=2)
    j = np.argmin(dist, axis=1)
    return dist[np.arange(len(pts)), j], j + t[np.arange(len(pts)), j]


def _interp_polyline(poly: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Point and unit tangent at fractional sample index s."""
    i = np.clip(np.floor(s).astype(int), 0, len(poly) - 2)
    f = s - i
    p = poly[i] + f[:, None] * (poly[i + 1] - poly[i])
    t = poly[i + 1] - poly[i]
    return p, t / np.linalg.norm(t, axis=1, keepdims=True)


def _sagitta3(poly: np.ndarray) -> float:
    """Chord-to-curve deviation estimate of an open 3-D polyline: a quarter of the largest
    distance of a vertex from its neighbours' chord (κ h²/8 for spacing h)."""
    if len(poly) < 3:
        return 0.0
    a, b, c = poly[:-2], poly[1:-1], poly[2:]
    ac = c - a
    n = np.linalg.norm(ac, axis=1)
    ok = n > 0
    d = np.linalg.norm(np.cross(b - a, ac), axis=1)[ok] / n[ok]
    return float(d.max() / 4) if d.size else 0.0


def _shared_edge_candidates(boxes: np.ndarray, radii: np.ndarray) -> list[np.ndarray]:
    r"""Per edge i, the edges j > i (ascending) whose 3-D bounding boxes could pass the shared-edge test.

    Two edges within Hausdorff distance ``tol`` of each other (every sample of each within ``tol``
    of the other polyline, which lies in its own bounding box) have bounding boxes
    ``[lo, hi]`` with ``|lo_i - lo_j|_∞ <= tol`` and ``|hi_i - hi_j|_∞ <= tol``: the 6-vectors
    ``(lo, hi)`` are within ``tol`` in the max norm. With ``tol_ij = max(r_i, r_j)``, a ball of
    radius ``r_i`` around every edge's 6-vector (a k-d tree, ``scipy.spatial.cKDTree``) finds
    every such pair from the edge with the larger radius: a superset of the pairs that pass,
    found in ``O(n log n)`` for edges spread in space (instead of all ``n (n - 1) / 2`` pairs).

    Args:
        boxes: (n, 6) ``(lo, hi)`` per edge.
        radii: (n,) search radius per edge (already widened for round-off).

    Returns:
        n int arrays, sorted.
    """
    from scipy.spatial import cKDTree

    n = len(boxes)
    if n == 0:
        return []
    tree = cKDTree(boxes)
    hits = tree.query_ball_point(boxes, r=radii, p=np.inf)
    a = np.repeat(np.arange(n), [len(h) for h in hits])
    b = np.concatenate([np.asarray(h, dtype=np.intp) for h in hits]) if n else np.zeros(0, np.intp)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    keep = lo != hi
    pairs = np.unique(_stack([lo[keep], hi[keep]], axis=1), axis=0) if keep.any() else np.zeros((0, 2), np.intp)
    starts = np.searchsorted(pairs[:, 0], np.arange(n + 1))
    return [pairs[starts[i]:starts[i + 1], 1] for i in range(n)]


def shared_edge_pairs(panels: Sequence[FlatPanel], rel_tol: float = 1e-5) -> list[tuple[int, BoundaryEdge, int, BoundaryEdge]]:
    """Boundary edges shared in 3-D by two panels (or the two sides of a seam in one panel).

    Two edges match when every 3-D sample of each lies within ``rel_tol`` · model size (plus the
    polyline sagitta) of the other. Edges are paired greedily in boundary order (edge i with the
    first unpaired j > i that matches). Candidate pairs come from a k-d tree over the edges'
    bounding boxes (:func:`_shared_edge_candidates`), so the cost grows like ``n log n`` with the
    number of edges for panels spread in space; the pairs are exactly those of testing all pairs.

    Returns:
        ``(panel index, edge, panel index, edge)`` per shared edge, in boundary order.
    """
    allpts = np.concatenate([e.xyz for p in panels for lp in p.loops for e in lp], axis=0)
    size = float(np.max(allpts.max(axis=0) - allpts.min(axis=0)))
    pairs: list[tuple[int, BoundaryEdge, int, BoundaryEdge]] = []
    items = [(pi, e) for pi, p in enumerate(panels) for lp in p.loops for e in lp]
    sags = [_sagitta3(e.xyz) for _, e in items]
    used: set[int] = set()
    # cheap prefilter on the end points (either direction; closed edges must both be closed); the
    # exact test below runs on the survivors only
    starts = np.array([e.xyz[0] for _, e in items]).reshape(-1, 3)
    ends = np.array([e.xyz[-1] for _, e in items]).reshape(-1, 3)
    gap = np.linalg.norm(starts - ends, axis=1)
    sag = np.asarray(sags, dtype=float)
    live = np.array([e.length_3d != 0 for _, e in items], dtype=bool)
    boxes = np.array([np.concatenate([e.xyz.min(axis=0), e.xyz.max(axis=0)]) for _, e in items]).reshape(-1, 6)
    base = rel_tol * size
    # widened by 1e-6 relative and 1e-12 model sizes: round-off in the distances of the exact test
    cands = _shared_edge_candidates(boxes, (base + sag) * (1 + 1e-6) + 1e-12 * size)

    def dist(p: np.ndarray, q: np.ndarray) -> np.ndarray:
        return np.linalg.norm(q - p, axis=1)

    for i in range(len(items)):
        if not live[i] or i in used:
            continue
        js = cands[i]
        if not js.size:
            continue
        tols = base + np.maximum(sag[i], sag[js])
        c1 = gap[i] <= tols
        ok = live[js] & (c1 == (gap[js] <= tols))
        fwd = np.maximum(dist(starts[i], starts[js]), dist(ends[i], ends[js]))
        bwd = np.maximum(dist(starts[i], ends[js]), dist(ends[i], starts[js]))
        ok &= c1 | (np.minimum(fwd, bwd) <= tols)
        for j in js[ok].tolist():
            (pi, e1), (pj, e2) = items[i], items[j]
            if i in used or j in used:
                continue
            tol = base + max(sags[i], sags[j])
            d12, _ = _polyline_param(e2.xyz, e1.xyz)
            if d12.max() > tol:
                continue
            d21, _ = _polyline_param(e1.xyz, e2.xyz)
            if d21.max() > tol:
                continue
            used.update((i, j))
            pairs.append((pi, e1, pj, e2))
    return pairs


def mark_shared_edges(panels: Sequence[FlatPanel], rel_tol: float = 1e-5) -> int:
    """Give boundary edges shared in 3-D by two panels matching marks (in place).

    The edges of :func:`shared_edge_pairs` (every 3-D sample of each within ``rel_tol`` · model
    size, plus the polyline sagitta, of the other). Both get a label ``E<k>`` and ticks across the
    edge at the points of 3-D arc-length fraction 0.2, 0.25, 0.5, 0.75 (the same 3-D points on
    both panels; the double tick near the start makes the joining direction unambiguous). Ticks
    reach ``tick = min(0.02 × largest panel extent, 0.1 × smallest extent of this panel)`` to each
    side of the edge; the label, ``1.5 tick`` high, sits ``3 tick`` inside the panel.

    Returns:
        Number of shared edges found.
    """
    pairs = shared_edge_pairs(panels, rel_tol)
    if not pairs:
        return 0
    tick_all = 0.02 * max(float(np.max(hi - lo)) for lo, hi in (p.bbox() for p in panels))
    for k, (pi, e1, pj, e2) in enumerate(pairs, start=1):
        cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(e1.xyz, axis=0), axis=1))])
        frac_idx = np.interp(np.array(MARK_FRACTIONS) * cum[-1], cum, np.arange(len(cum)))
        p3, _ = _interp_polyline(e1.xyz, frac_idx)
        _, s2 = _polyline_param(e2.xyz, p3)
        for panel, edge, s in ((panels[pi], e1, frac_idx), (panels[pj], e2, s2)):
            loops = panel.loop_polylines()
            lo, hi = panel.bbox()
            tick = min(tick_all, 0.1 * float(np.min(hi - lo)))  # a narrow panel gets smaller marks
            pos, tan = _interp_polyline(edge.flat + panel.offset, s)
            nrm = _stack([-tan[:, 1], tan[:, 0]], axis=1)
            probe = pos[2] + 2 * tick * nrm[2]
            if not _inside(probe[None], loops)[0]:
                nrm = -nrm
            for q, nv in zip(pos, nrm):
                panel.marks.append(np.array([q - tick * nv, q + tick * nv]))
            tp = pos[2] + 3 * tick * nrm[2]
            panel.texts.append((float(tp[0]), float(tp[1]), f"E{k}", 1.5 * tick))
    return len(pairs)


def arcs_to_rational_quadratic(points: np.ndarray, bulges: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed chain of lines and arcs as one exact rational quadratic B-spline.

    A segment ``p0 -> p1`` with bulge b (sweep ``θ = 4 atan b``, halved while ``|θ| > 90°``:
    ``b -> b / (1 + sqrt(1 + b²))``) has the control points ``p0, C, p1`` with
    ``C = m - ½ tan(θ/2) rot90(p1 - p0)`` (the end tangents' intersection, m the chord's middle,
    ``tan(θ/2) = 2b / (1 - b²)``) and weights ``1, cos(θ/2) = (1 - b²)/(1 + b²), 1`` (a line: C = m,
    weight 1). Segments join at double knots (C0: the corners stay corners).

    Returns:
        control points (2n + 1, 2) (the last = the first), weights (2n + 1,), knots (2n + 4,).
    """
    p = np.asarray(points, dtype=float)
    q = np.concatenate([p[1:], p[:1]])
    segs: list[tuple[np.ndarray, np.ndarray, float]] = []
    for a, c, b in zip(p, q, np.asarray(bulges, dtype=float).tolist()):
        todo = [(a, c, b)]
        while todo:
            a0, a1, bb = todo.pop()
            if abs(bb) > math.tan(math.pi / 8) + 1e-15:  # |θ| > 90°: split at the arc's middle
                d = a1 - a0
                mid = 0.5 * (a0 + a1) - 0.5 * bb * np.array([-d[1], d[0]])
                half = bb / (1.0 + math.sqrt(1.0 + bb * bb))
                todo += [(mid, a1, half), (a0, mid, half)]
            else:
                segs.append((a0, a1, bb))
    cp, w = [p[0]], [1.0]
    for a0, a1, bb in segs:
        d = a1 - a0
        cp += [0.5 * (a0 + a1) - (bb / (1.0 - bb * bb)) * np.array([-d[1], d[0]]), a1]
        w += [(1.0 - bb * bb) / (1.0 + bb * bb), 1.0]
    n = len(segs)
    knots = np.concatenate([[0.0, 0.0, 0.0], np.repeat(np.arange(1.0, n), 2), [float(n)] * 3])
    return np.array(cp), np.array(w), knots


def svg_arc_path(points: np.ndarray, bulges: np.ndarray, tr: Callable[[np.ndarray], tuple[float, float]]) -> str:
    """SVG path data of a closed chain of lines and arcs: ``M`` the first point, then per segment
    ``L x y`` (bulge 0) or ``A r r 0 large sweep x y`` with ``r = L / (2 |sin(θ/2)|)``,
    ``large = |θ| > π`` and ``sweep = (b < 0)`` (``tr`` flips y: a counter-clockwise arc is drawn
    with sweep flag 0), then ``Z``; coordinates through ``tr`` (model -> SVG user units)."""
    p = np.asarray(points, dtype=float)
    xy = [tr(v) for v in p]
    d = [f"M{xy[0][0]:.12g},{xy[0][1]:.12g}"]
    for i, b in enumerate(np.asarray(bulges, dtype=float).tolist()):
        j = (i + 1) % len(xy)
        x, y = xy[j]
        if b == 0.0:
            d.append(f"L{x:.12g},{y:.12g}")
            continue
        th = 4.0 * math.atan(b)
        r = math.hypot(*(p[j] - p[i])) / (2.0 * abs(math.sin(0.5 * th)))
        d.append(f"A{r:.15g},{r:.15g} 0 {int(abs(th) > math.pi)} {int(b < 0)} {x:.12g},{y:.12g}")
    d.append("Z")
    return " ".join(d)


class FlatPattern:
    """A flat pattern: one or more panels in the plane, with report and exports.

    Attributes:
        panels: the :class:`FlatPanel` list.
        units: length unit ("mm", "cm", "m", "in", "ft", "unitless").
    """

    def __init__(self, panels: Sequence[FlatPanel], units: str = "mm") -> None:
        if units not in INSUNITS:
            raise GHTError(f"units={units!r} is not allowed; allowed units are {tuple(INSUNITS)}")
        self.panels = list(panels)
        self.units = units
        #: default chord tolerance of the DXF/SVG outlines (pattern units): 1e-3 mm
        self.chord_tol = default_chord_tol(units)

    # -- geometry ------------------------------------------------------------------------
    @property
    def outlines(self) -> list[np.ndarray]:
        """All closed loops (outer and holes of every panel), (n, 2) arrays, last point not repeated."""
        return [lp for p in self.panels for lp in p.loop_polylines()]

    @property
    def outline(self) -> np.ndarray:
        """Outer loop of the first panel, (n, 2) (last point not repeated)."""
        return self.panels[0].loop_polylines()[0]

    def outline_arcs(self, chord_tol: float | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
        """All closed loops as lines and circular arcs (:meth:`FlatPanel.loop_arcs`): per loop
        ``(points (n, 2), bulges (n,))``, segment i from ``points[i]`` to ``points[i + 1 mod n]``
        with DXF bulge ``tan(θ/4)``.

        Args:
            chord_tol: largest distance between an exact flat edge and its arcs, pattern units
                (None: :attr:`chord_tol`, 1e-3 mm by default). Straight and circular edges are
                written exactly whatever the tolerance.
        """
        tol = self._chord_tol(chord_tol)
        return [(p, b) for panel in self.panels for p, b, _ in panel.loop_arcs(tol)]

    def _chord_tol(self, chord_tol: float | None) -> float:
        tol = self.chord_tol if chord_tol is None else chord_tol
        try:
            ok = float(tol) > 0 and math.isfinite(float(tol))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise GHTError(f"chord_tol={tol!r} is not allowed; allowed: a positive length in the pattern's "
                           f"units ({self.units})")
        return float(tol)

    @property
    def outer_outlines(self) -> list[np.ndarray]:
        return [p.loop_polylines()[0] for p in self.panels]

    @property
    def bend_lines(self) -> np.ndarray:
        """All bend lines (rulings), shape (k, 2, 2)."""
        arrs = [p.bend_lines for p in self.panels if p.bend_lines.size]
        return np.concatenate(arrs, axis=0) if arrs else np.zeros((0, 2, 2))

    @property
    def marks(self) -> list[np.ndarray]:
        return [m for p in self.panels for m in p.marks]

    @property
    def labels(self) -> list[tuple[float, float, str, float]]:
        """(x, y, text, height) of every label (panel labels and edge marks)."""
        return [t for p in self.panels for t in p.texts]

    def map(self, u: Any, v: Any) -> np.ndarray:
        """Flat image of surface parameters of the (single) panel."""
        if len(self.panels) != 1:
            raise GHTError(f"map() needs a single-panel pattern; this one has {len(self.panels)} panels")
        return self.panels[0].map(u, v)

    @property
    def area(self) -> float:
        return float(sum(p.area_flat for p in self.panels))

    @property
    def forming_labels(self) -> list[tuple[float, float, str, float, float]]:
        """(x, y, text, height, rotation deg) of the sheet forming labels (bend radius and angle)."""
        return [t for p in self.panels for t in p.forming_texts]

    @property
    def bend_labels(self) -> list[tuple[float, float, str, float, float]]:
        """Bend annotations of all panels (x, y, text, height, rotation in degrees): layer BEND."""
        return [t for p in self.panels for t in p.bend_texts]

    @property
    def sheet(self) -> dict[str, Any] | None:
        """Sheet data of the first panel unrolled with a thickness (``panel.info["sheet"]``:
        thickness, K, side, edge lengths inside/neutral/outside, forming rows), else None."""
        for p in self.panels:
            if p.info.get("sheet"):
                return p.info["sheet"]
        return None

    def forming_table(self) -> str:
        """Plain-text forming tables (one per panel unrolled with a thickness; :mod:`ght_cad.sheet`)."""
        from .sheet import FormingRow, forming_table_text

        out = []
        for p in self.panels:
            sh = p.info.get("sheet")
            if sh:
                rows = [FormingRow(**r) for r in sh["forming"]]
                out.append(f"{p.label}: T={sh['thickness']:g} K={sh['k_factor']:g} side={sh['side']}\n"
                           + forming_table_text(rows, self.units))
        return "\n\n".join(out)

    def plot_roll_chart(self, path: str | os.PathLike, *, dpi: int = 120, title: str | None = None) -> Path:
        """Roll-bending chart PNG (:func:`ght_cad.sheet.plot_roll_chart`)."""
        from .sheet import plot_roll_chart

        plot_roll_chart(self, path, dpi=dpi, title=title)
        return Path(path)

    # -- report --------------------------------------------------------------------------
    @property
    def report(self) -> DistortionReport:
        """Distortion report over all panels."""
        reps = [p.report for p in self.panels if p.report is not None]
        return reps[0] if len(reps) == 1 else DistortionReport.combine(reps)

    @property
    def errors(self) -> dict[str, float]:
        """Max relative errors: boundary_length, ruling_length, area, max; angle_deg (degrees)."""
        d = self.report.as_dict()
        out = {
            "boundary_length": d["boundary_length"]["max"],
            "ruling_length": d["ruling_length"]["max"],
            "area": d["area"]["max"],
            "angle_deg": d["angle_deg"]["max"],
        }
        out["max"] = max(out["boundary_length"], out["ruling_length"], out["area"])
        return out

    def summary(self) -> str:
        lines = [f"flat pattern: {len(self.panels)} panel(s), units {self.units}, area {self.area:.9g}"]
        lines.append(self.report.summary())
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"FlatPattern(panels={len(self.panels)}, units={self.units!r}, max_error={self.errors['max']:.2e})"

    # -- exports -------------------------------------------------------------------------
    def export_dxf(self, path: str | os.PathLike, *, spline: bool = False, chord_tol: float | None = None) -> Path:
        """Write a DXF (R2010) with layers OUTLINE, BEND, LABELS, MARKS (and FORMING for a sheet:
        bend radius and angle of every bend line, rotated along it); $INSUNITS from units.

        OUTLINE: every loop as one closed LWPOLYLINE of lines and circular arcs (vertex bulges,
        :meth:`outline_arcs`): a straight edge is one segment, a circular edge (a cone's rail) one
        arc, other edges arcs within ``chord_tol`` of the exact development; corners are the
        development's. ``spline=True``: every loop as one SPLINE carrying the same lines and arcs
        exactly as control data (rational quadratic: control points, weights, knots; no fit
        points). BEND: bend lines as LINEs with linetype DASHED. LABELS: TEXT. MARKS: edge-mark
        ticks. Without ezdxf (FreeCAD's Python) a plain R12 file with the same layers and the same
        outline arcs is written (:meth:`dxf_r12_text`).

        Args:
            path: the file to write (atomically).
            spline: loops as SPLINE entities instead of LWPOLYLINEs.
            chord_tol: outline chord tolerance in the pattern's units (None: :attr:`chord_tol`).

        Returns:
            The path written.
        """
        tol = self._chord_tol(chord_tol)
        try:
            import ezdxf
        except ImportError:  # e.g. FreeCAD's own Python: plain R12 writer, same layers
            return write_text_atomic(path, self.dxf_r12_text(chord_tol=tol))
        doc = ezdxf.new("R2010", setup=True)
        doc.header["$INSUNITS"] = INSUNITS[self.units]
        doc.header["$MEASUREMENT"] = 0 if self.units in ("in", "ft") else 1
        doc.layers.add("OUTLINE", color=7)
        doc.layers.add("BEND", color=1, linetype="DASHED")
        doc.layers.add("LABELS", color=3)
        doc.layers.add("MARKS", color=5)
        if self.forming_labels:
            doc.layers.add("FORMING", color=6)
        msp = doc.modelspace()
        for pts, bulges in self.outline_arcs(tol):
            if spline:
                cp, w, knots = arcs_to_rational_quadratic(pts, bulges)
                msp.add_rational_spline(cp.tolist(), w.tolist(), degree=2, knots=knots.tolist(),
                                        dxfattribs={"layer": "OUTLINE"})
            else:
                msp.add_lwpolyline(np.column_stack([pts, bulges]).tolist(), format="xyb", close=True,
                                   dxfattribs={"layer": "OUTLINE"})
        bl = self.bend_lines
        size = max(float(np.max(hi - lo)) for lo, hi in (p.bbox() for p in self.panels))
        for p, q in bl:
            msp.add_line(tuple(p), tuple(q), dxfattribs={"layer": "BEND", "linetype": "DASHED", "ltscale": size / 50.0})
        for m in self.marks:
            msp.add_line(tuple(m[0]), tuple(m[1]), dxfattribs={"layer": "MARKS"})
        for x, y, s, h in self.labels:
            t = msp.add_text(s, height=h, dxfattribs={"layer": "LABELS"})
            t.set_placement((x, y), align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)
        for layer, texts in (("FORMING", self.forming_labels), ("BEND", self.bend_labels)):
            for x, y, s, h, a in texts:
                t = msp.add_text(s, height=h, rotation=a, dxfattribs={"layer": layer})
                t.set_placement((x, y), align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)
        with atomic_path(path) as tmp:
            doc.saveas(tmp)
        return Path(path)

    def dxf_r12_text(self, chord_tol: float | None = None) -> str:
        """Minimal ASCII DXF R12 (no ezdxf needed): LTYPE DASHED, layers OUTLINE/BEND/LABELS/MARKS,
        every outline loop one closed POLYLINE of lines and arcs (VERTEX bulges, group 42; the
        same geometry as :meth:`export_dxf`), LINEs, TEXT; ``$INSUNITS`` in the header.
        Coordinates and bulges are written to 17 significant digits (they read back exactly).

        Args:
            chord_tol: outline chord tolerance in the pattern's units (None: :attr:`chord_tol`).
        """
        out: list[str] = []

        def put(code: int, value: Any) -> None:
            out.append(f"{code}\n{value:.12g}" if isinstance(value, float) else f"{code}\n{value}")

        put(0, "SECTION"), put(2, "HEADER"), put(9, "$ACADVER"), put(1, "AC1009")
        put(9, "$INSUNITS"), put(70, INSUNITS[self.units]), put(0, "ENDSEC")
        put(0, "SECTION"), put(2, "TABLES")
        put(0, "TABLE"), put(2, "LTYPE"), put(70, 2)
        put(0, "LTYPE"), put(2, "CONTINUOUS"), put(70, 0), put(3, "Solid line"), put(72, 65), put(73, 0), put(40, 0.0)
        put(0, "LTYPE"), put(2, "DASHED"), put(70, 0), put(3, "Dashed __ __ __"), put(72, 65), put(73, 2)
        put(40, 0.75), put(49, 0.5), put(49, -0.25)
        put(0, "ENDTAB")
        layers = (("OUTLINE", 7, "CONTINUOUS"), ("BEND", 1, "DASHED"), ("LABELS", 3, "CONTINUOUS"), ("MARKS", 5, "CONTINUOUS"))
        if self.forming_labels:
            layers += (("FORMING", 6, "CONTINUOUS"),)
        put(0, "TABLE"), put(2, "LAYER"), put(70, len(layers))
        for name, color, lt in layers:
            put(0, "LAYER"), put(2, name), put(70, 0), put(62, color), put(6, lt)
        put(0, "ENDTAB"), put(0, "ENDSEC")
        put(0, "SECTION"), put(2, "ENTITIES")
        for pts, bulges in self.outline_arcs(chord_tol):
            put(0, "POLYLINE"), put(8, "OUTLINE"), put(66, 1), put(70, 1)
            for (x, y), b in zip(pts.tolist(), bulges.tolist()):
                put(0, "VERTEX"), put(8, "OUTLINE"), put(10, repr(x)), put(20, repr(y)), put(30, 0.0)
                if b:
                    put(42, repr(b))
            put(0, "SEQEND"), put(8, "OUTLINE")
        for layer, segs in (("BEND", list(self.bend_lines)), ("MARKS", self.marks)):
            for p, q in segs:
                put(0, "LINE"), put(8, layer)
                if layer == "BEND":
                    put(6, "DASHED")
                put(10, float(p[0])), put(20, float(p[1])), put(30, 0.0)
                put(11, float(q[0])), put(21, float(q[1])), put(31, 0.0)
        for x, y, text, h in self.labels:
            put(0, "TEXT"), put(8, "LABELS"), put(10, float(x)), put(20, float(y)), put(30, 0.0)
            put(40, float(h)), put(1, _dxf_ascii(text)), put(72, 1), put(73, 2)
            put(11, float(x)), put(21, float(y)), put(31, 0.0)
        for layer, texts in (("FORMING", self.forming_labels), ("BEND", self.bend_labels)):
            for x, y, text, h, a in texts:
                put(0, "TEXT"), put(8, layer), put(10, float(x)), put(20, float(y)), put(30, 0.0)
                put(40, float(h)), put(1, _dxf_ascii(text)), put(50, float(a)), put(72, 1), put(73, 2)
                put(11, float(x)), put(21, float(y)), put(31, 0.0)
        put(0, "ENDSEC"), put(0, "EOF")
        return "\n".join(out) + "\n"

    def svg_text(self, margin: float | None = None, chord_tol: float | None = None) -> str:
        """The SVG document as a string (see :meth:`export_svg`).

        Every outline loop is one closed ``<path>`` of ``L`` (straight) and ``A`` (circular arc)
        commands, the same lines and arcs as the DXF (:meth:`outline_arcs`).

        The viewBox is in model units; ``width``/``height`` are the same extent in an SVG length
        unit (:data:`SVG_UNITS`: ``width = (extent + 2 margin) × scale`` with m → mm × 1000,
        ft → in × 12, mm/cm/in × 1), so the drawing prints at true scale. Lines are
        :data:`SVG_STROKE_MM` (0.25 mm) wide at that scale and bend-line dashes ``span / 130``
        long, kept within 1..10 mm (a unitless pattern: width ``span / 800``, dashes ``6×`` that).

        Args:
            margin: blank border in model units (default 3 % of the larger extent).
            chord_tol: outline chord tolerance in the pattern's units (None: :attr:`chord_tol`).

        Returns:
            The SVG text.
        """
        arcs = self.outline_arcs(chord_tol)
        pts = np.concatenate(self.outlines, axis=0)
        lo, hi = points_bbox(pts)
        span = float(np.max(hi - lo))
        m = 0.03 * span if margin is None else float(margin)
        W, H = float(hi[0] - lo[0]) + 2 * m, float(hi[1] - lo[1]) + 2 * m

        def tr(p: np.ndarray) -> tuple[float, float]:
            return float(p[0] - lo[0] + m), float(hi[1] - p[1] + m)

        unit, scale = SVG_UNITS[self.units]
        mm = _MM_PER_UNIT.get(self.units)  # millimetres per model unit (None: unitless)
        if mm is None:  # no physical size: lines and dashes relative to the drawing
            sw, dash = span / 800.0, 6 * span / 800.0
        else:  # printed/cut at true scale: 0.25 mm lines, dashes of span/130 within 1..10 mm
            sw = SVG_STROKE_MM / mm
            dash = min(max(span / 130.0, 1.0 / mm), 10.0 / mm)
        out = [
            '<?xml version="1.0" encoding="UTF-8" standalone="no"?>',
            f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
            f'version="1.1" width="{W * scale:.9g}{unit}" height="{H * scale:.9g}{unit}" viewBox="0 0 {W:.9g} {H:.9g}">',
            f'<g id="OUTLINE" inkscape:groupmode="layer" inkscape:label="OUTLINE" fill="none" stroke="black" stroke-width="{sw:.6g}">',
        ]
        for loop_pts, bulges in arcs:
            out.append(f'<path d="{svg_arc_path(loop_pts, bulges, tr)}"/>')
        out.append("</g>")
        out.append(
            f'<g id="BEND" inkscape:groupmode="layer" inkscape:label="BEND" fill="none" stroke="red" '
            f'stroke-width="{sw:.6g}" stroke-dasharray="{dash:.6g},{dash / 2:.6g}">'
        )
        for p, q in self.bend_lines:
            (x1, y1), (x2, y2) = tr(p), tr(q)
            out.append(f'<line x1="{x1:.9g}" y1="{y1:.9g}" x2="{x2:.9g}" y2="{y2:.9g}"/>')
        for x, y, s, h, a in self.bend_labels:
            X, Y = tr(np.array([x, y]))
            out.append(f'<text x="{X:.9g}" y="{Y:.9g}" font-size="{h:.6g}" text-anchor="middle" dominant-baseline="middle" '
                       f'fill="red" stroke="none" transform="rotate({-a:.6g} {X:.9g} {Y:.9g})">{escape(s)}</text>')
        out.append("</g>")
        out.append(f'<g id="MARKS" inkscape:groupmode="layer" inkscape:label="MARKS" stroke="blue" stroke-width="{sw:.6g}">')
        for mk in self.marks:
            (x1, y1), (x2, y2) = tr(mk[0]), tr(mk[1])
            out.append(f'<line x1="{x1:.9g}" y1="{y1:.9g}" x2="{x2:.9g}" y2="{y2:.9g}"/>')
        out.append("</g>")
        out.append('<g id="LABELS" inkscape:groupmode="layer" inkscape:label="LABELS" fill="green" font-family="sans-serif">')
        for x, y, s, h in self.labels:
            X, Y = tr(np.array([x, y]))
            out.append(
                f'<text x="{X:.9g}" y="{Y:.9g}" font-size="{h:.6g}" text-anchor="middle" '
                f'dominant-baseline="middle">{escape(s)}</text>'
            )
        out.append("</g>")
        if self.forming_labels:
            out.append('<g id="FORMING" inkscape:groupmode="layer" inkscape:label="FORMING" fill="magenta" font-family="sans-serif">')
            for x, y, s, h, a in self.forming_labels:
                X, Y = tr(np.array([x, y]))
                out.append(
                    f'<text x="{X:.9g}" y="{Y:.9g}" font-size="{h:.6g}" text-anchor="middle" dominant-baseline="middle" '
                    f'transform="rotate({-a:.6g} {X:.9g} {Y:.9g})">{escape(s)}</text>'
                )
            out.append("</g>")
        out.append("</svg>")
        return "\n".join(out) + "\n"

    def export_svg(self, path: str | os.PathLike, *, chord_tol: float | None = None) -> Path:
        """Write an SVG: groups (Inkscape layers) OUTLINE (one path of lines and arcs per loop),
        BEND (dashed), MARKS, LABELS; true-scale size in mm, cm or in (m and ft converted, see
        :meth:`svg_text`)."""
        return write_text_atomic(path, self.svg_text(chord_tol=chord_tol))

    def plot_png(self, path: str | os.PathLike, *, dpi: int = 120, title: str | None = None) -> Path:
        """PNG preview (matplotlib Agg): outline, dashed bend lines, marks, labels (and a sheet's
        forming labels), error summary."""
        from matplotlib.figure import Figure  # object API: no pyplot, no global backend switch

        fig = Figure(figsize=(8, 6))
        ax = fig.add_subplot(111)
        for lp in self.outlines:
            c = np.vstack([lp, lp[:1]])
            ax.plot(c[:, 0], c[:, 1], "k-", lw=1.0)
        for p, q in self.bend_lines:
            ax.plot([p[0], q[0]], [p[1], q[1]], "r--", lw=0.6)
        for mk in self.marks:
            ax.plot(mk[:, 0], mk[:, 1], "b-", lw=1.0)
        for x, y, s, h in self.labels:
            ax.text(x, y, s, ha="center", va="center", color="green", fontsize=9)
        for x, y, s, h, a in self.forming_labels:  # sheet: bend radius and angle along each bend line
            ax.text(x, y, s, ha="center", va="center", color="magenta", fontsize=5, rotation=a)
        for x, y, s, h, a in self.bend_labels:  # a blank's bends: direction, angle, inside radius
            ax.text(x, y, s, ha="center", va="center", color="red", fontsize=5, rotation=a)
        ax.set_aspect("equal")
        ax.set_xlabel(self.units)
        e = self.errors
        ax.set_title(
            title
            or f"flat pattern: max rel. length/area error {e['max']:.1e}, angle {e['angle_deg']:.1e} deg",
            fontsize=9,
        )
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=dpi, format="png")
        return Path(path)

    def to_face(self) -> Any:
        """Planar build123d Face(s) of the pattern (outline + holes); a list for composites."""
        from .cad.unroll_faces import flat_faces

        faces = flat_faces(self)
        return faces[0] if len(faces) == 1 else faces
