r"""Flat-pattern model: boundary edges, panels, the distortion report and the geometry they use.

Moved from :mod:`ght_cad.pattern.flat_pattern` (issue 27; every name stays importable from there). The
distortion measures are defined in the docstring of :mod:`ght_cad.pattern.flat_pattern` (spec section 6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np

from ..core._cache import readonly_cache
from ..core.errors import GHTError
from ..core._vec import einsum as _einsum
from ..core._vec import stack as _stack


#: DXF $INSUNITS codes
INSUNITS = {"unitless": 0, "in": 1, "ft": 2, "mm": 4, "cm": 5, "m": 6}

#: millimetres per model unit (the SVG's physical stroke width and dash lengths)
_MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "ft": 304.8}

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


def _chords(p: np.ndarray) -> float:
    d = p[1:] - p[:-1]
    return float(np.sum(np.sqrt(_einsum("ij,ij->i", d, d))))


@readonly_cache(maxsize=8)
def _unit_samples(n: int) -> np.ndarray:
    """``linspace(0, 1, n)``, made once per n (read-only)."""
    return np.linspace(0.0, 1.0, n)


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
    #: sheet forming labels (x, y, text, height, rotation in degrees): layer FORMING (ght_cad.sheetmetal.sheet)
    forming_texts: list[tuple[float, float, str, float, float]] = field(default_factory=list)
    #: bend annotations (x, y, text, height, rotation in degrees): layer BEND (a blank's bend
    #: direction, angle and inside radius, ght_cad.sheetmetal.blank)
    bend_texts: list[tuple[float, float, str, float, float]] = field(default_factory=list)
    report: DistortionReport | None = None
    area_flat: float = float("nan")
    _arcs: dict[float, list[tuple[np.ndarray, np.ndarray, list[str]]]] = field(
        default_factory=dict, init=False, repr=False, compare=False)

    def loop_arcs(self, chord_tol: float) -> list[tuple[np.ndarray, np.ndarray, list[str]]]:
        """Closed loops as lines and circular arcs (:mod:`ght_cad.pattern.outline_arcs`), offset applied.

        Every boundary edge becomes an :class:`~ght_cad.pattern.outline_arcs.ArcChain`: one exact line or
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
