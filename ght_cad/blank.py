r"""One blank per bent part: connected unfolding of a sheet's skin (kernel-free core).

A kernel adapter (:mod:`ght_cad.cad.unfold_solid` for OCP/build123d/cadquery) recognises the
sheet in a solid and describes its *skin* -- the faces of one side of the sheet -- as a
:class:`SheetSkin`: every face as a :class:`ght_cad.face_unroll.FaceData` whose edges are named by
the solid's edge keys, the thickness ``T`` and which edges two skin faces share. This module

* develops every skin face exactly (:func:`ght_cad.face_unroll.unroll_face_data`: closed forms
  for planes, cylinders and cones, quadrature along the rulings for other developables); a bend
  face is developed on its neutral surface, offset into the material by ``K T`` when the skin
  face is the inside of its bend and by ``(1 - K) T`` when it is the outside, so either skin gives
  the neutral radius ``R + K T`` (``R`` the inside radius, spec 6.1); planar faces (flanges) do not
  stretch, their flat is the face's own;
* walks the skin's face graph breadth first from a base face (largest planar face by default)
  and places every face by the rigid motion ``x -> Q x + c`` that maps its flat image of the
  shared edge onto the flat image its placed neighbour has of the same edge (both faces first
  made orientation-preserving with respect to the solid's outward normal, so a face lands on the
  far side of the edge); shared edges not on the spanning tree are cut and reported;
* merges all faces' boundary edges that are not shared inside the tree into closed loops: the
  outline (largest area) and holes, one :class:`ght_cad.flat_pattern.FlatPanel` per solid, with
  both tangent lines of every bend (or its centre line) as bend lines, the rulings of freeform
  bends, and a bend table (angle ``A``, inside radius ``R``, ``K``, bend allowance
  ``BA = (R + K T) A``, bend deduction ``BD = 2 (R + T) tan(A / 2) - BA``, direction up/down);
* refuses a blank whose pieces overlap in the plane (crossing outline segments; the overlap area
  of the crossing faces' outlines by Green's theorem, :func:`_overlap_area`) unless split into separate panels with matching edge marks.

The blank's length across a bend is therefore ``Σ flange lengths to the tangent lines +
Σ (R + K T) A`` exactly as the closed form (a freeform bend: inside length + ``K T`` × turn angle).

numpy only at import time; no CAD kernel.
"""

from __future__ import annotations

import math
import os
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from .errors import GHTError

__all__ = [
    "BlankError",
    "KFactorTable",
    "K_TABLES",
    "k_factor_table",
    "k_factor_rows",
    "SkinFace",
    "SheetSkin",
    "Blank",
    "bend_row",
    "unfold_skin",
    "Unfolded",
    "unfold_skins",
    "classify_skin",
]


class BlankError(GHTError):
    """A solid cannot be made into one blank: no sheet, an ambiguous skin, a sharp edge, a face
    that is not developable, pieces that overlap in the plane. The message names the face/edge
    and the measured value."""


# -- K-factor tables -----------------------------------------------------------------------------
@dataclass(frozen=True)
class KFactorTable:
    r"""ANSI K-factor as a step function of ``R / T`` (inside radius over thickness).

    ``K(R/T) = k_i`` for ``r_i <= R/T < r_{i+1}`` (``r_0 = 0``); DIN tables (``k = 2K``) are
    stored as ANSI K.

    Attributes:
        name: table name (``ansi``, ``din`` or a file name).
        ratios: ascending lower bounds ``r_i`` of ``R/T`` (the first is 0).
        k_factors: ANSI ``K`` for each range.
        source: where the values come from.
    """

    name: str
    ratios: tuple[float, ...]
    k_factors: tuple[float, ...]
    source: str = ""

    def __call__(self, radius: float, thickness: float) -> float:
        """``K`` for an inside radius ``radius`` and thickness ``thickness``."""
        x = radius / thickness
        i = int(np.searchsorted(np.asarray(self.ratios), x, side="right")) - 1
        return float(self.k_factors[max(i, 0)])


def _din_table() -> KFactorTable:
    # DIN 6935 correction factor k = 0.65 + 0.5 lg(r/s) (r/s < 5), k = 1 beyond; ANSI K = k / 2
    r = (0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0)
    k = [max(0.65 + 0.5 * math.log10(max(x, 0.1)), 0.0) / 2 for x in (0.1,) + r[1:-1]] + [0.5]
    return KFactorTable("din", r, tuple(round(v, 4) for v in k),
                        "DIN 6935: k = 0.65 + 0.5 lg(r/s) for r/s < 5, k = 1 from r/s = 5 (ANSI K = k/2), "
                        "evaluated at the lower bound of each range")


#: the built-in tables: ``ansi`` is the generic air-bending chart for medium materials (steel):
#: R < T: 0.38, T <= R < 3T: 0.43, R >= 3T: 0.50 (the K-factor table of Wikipedia's "Bending
#: (metalworking)"); ``din`` is DIN 6935's correction factor (see :func:`_din_table`)
K_TABLES: dict[str, KFactorTable] = {
    "ansi": KFactorTable("ansi", (0.0, 1.0, 3.0), (0.38, 0.43, 0.50),
                         "generic air-bending K-factor chart, medium materials (steel): Wikipedia, "
                         "'Bending (metalworking)', K-factor table"),
    "din": _din_table(),
}


def k_factor_table(spec: str | os.PathLike) -> KFactorTable:
    r"""A K-factor table by name (``ansi``, ``din``) or from a text file.

    The file has one ``R/T  K`` pair a line (comma, semicolon or blanks between; ``#`` comments);
    a first line ``din`` (or ``# din``) marks DIN ``k = 2K`` values. Ratios ascending from 0.

    Raises:
        BlankError: unknown name, missing file, a bad line (naming the file and line), ratios not
            ascending, K outside [0, 1].
    """
    if isinstance(spec, str) and spec.lower() in K_TABLES:
        return K_TABLES[spec.lower()]
    p = Path(spec)
    if not p.is_file():
        raise BlankError(f"k_factor_table={str(spec)!r} is neither a built-in table nor a file; allowed: "
                         f"{', '.join(K_TABLES)} or a file of 'R/T K' lines")
    din = False
    rows: list[tuple[float, float]] = []
    for n, line in enumerate(p.read_text().splitlines(), 1):
        s = line.split("#", 1)[0].strip() if not line.strip().lower().startswith("# din") else "din"
        if not s:
            continue
        if s.lower() in ("din", "ansi") and not rows:
            din = s.lower() == "din"
            continue
        parts = s.replace(",", " ").replace(";", " ").split()
        try:
            r, k = float(parts[0]), float(parts[1])
            if len(parts) != 2:
                raise ValueError
        except (ValueError, IndexError):
            raise BlankError(f"{p}:{n}: {line.strip()!r} is not an 'R/T K' pair; allowed: two numbers a line") from None
        rows.append((r, k / 2 if din else k))
    if not rows:
        raise BlankError(f"{p}: no 'R/T K' rows; allowed: one pair a line")
    return k_factor_rows([(r, k) for r, k in rows], name=p.name, where=str(p), source=f"file {p}" + (" (DIN k)" if din else ""))


def k_factor_rows(rows: Sequence[Sequence[float]], *, name: str = "table", where: str = "k_factor_table",
                  din: bool = False, source: str = "") -> KFactorTable:
    r"""A K-factor table from ``(R/T, K)`` rows: ``K(R/T) = K_i`` for ``r_i <= R/T < r_{i+1}``.

    Args:
        rows: ``(r_i, K_i)`` pairs, ``r_0 = 0``, ``r_i`` ascending; ANSI ``K`` in [0, 1] (DIN
            ``k = 2K`` in [0, 2] with ``din``).
        name: the table's name; where: what the messages name (a file, a design key).
        din: the values are DIN ``k = 2K``.

    Raises:
        BlankError: no rows, a row that is not two finite numbers, ratios not starting at 0 or not
            ascending, K outside [0, 1] (naming ``where`` and the value).
    """
    out: list[tuple[float, float]] = []
    for i, row in enumerate(rows):
        try:
            if isinstance(row, (str, bytes)) or len(row) != 2:
                raise TypeError
            r, k = (float(x) for x in row)
            if any(isinstance(x, bool) for x in row) or not (math.isfinite(r) and math.isfinite(k)):
                raise TypeError
        except (TypeError, ValueError):
            raise BlankError(f"{where}: row {i + 1} {row!r} is not an [R/T, K] pair of numbers; allowed: "
                             "two finite numbers a row") from None
        out.append((r, k / 2 if din else k))
    if not out:
        raise BlankError(f"{where}: no [R/T, K] rows; allowed: at least one row, the first at R/T = 0")
    ratios = [r for r, _ in out]
    if ratios[0] != 0.0 or any(b <= a for a, b in zip(ratios, ratios[1:])):
        raise BlankError(f"{where}: R/T values {ratios} must start at 0 and ascend")
    for r, k in out:
        if not 0.0 <= k <= 1.0:
            raise BlankError(f"{where}: K={k!r} at R/T={r:g} is outside [0, 1] (ANSI K; DIN k = 2K lies in [0, 2])")
    return KFactorTable(name, tuple(ratios), tuple(k for _, k in out), source or where)


# -- the skin --------------------------------------------------------------------------------------
@dataclass
class SkinFace:
    """One face of a sheet's skin as an adapter describes it.

    Attributes:
        number: 1-based face number in the source shape (reports name faces ``F<number>``).
        data: the face (:class:`ght_cad.face_unroll.FaceData`); its edges' ``name`` is the solid's
            edge key (e.g. ``E12``), the same in both faces sharing the edge; ``data.reversed``
            makes the normal the solid's outward normal.
        area: 3-D area (the default base face is the largest planar face).
        partner: face number of the opposite skin face (None when unknown).
    """

    number: int
    data: Any
    area: float
    partner: int | None = None


@dataclass
class SheetSkin:
    """The skin of one sheet solid (see module doc).

    Attributes:
        name: the solid's name (``S1``, ...).
        thickness: sheet thickness ``T``.
        faces: the skin's faces.
        shared: edge key -> the two face numbers of the skin faces sharing it.
        walls: face numbers of the solid's faces that are not skin (thickness walls, cut faces,
            the other skin), for the report.
    """

    name: str
    thickness: float
    faces: list[SkinFace]
    shared: dict[str, tuple[int, int]]
    walls: list[int] = field(default_factory=list)


@dataclass
class Blank:
    """The blank of one sheet solid.

    Attributes:
        name: the solid's name.
        panels: one :class:`ght_cad.flat_pattern.FlatPanel` (several with ``allow_split``).
        thickness: ``T``.
        bends: the bend table, one dict per bend (:func:`bend_row`).
        base_face: face number of the base face (it keeps its own flat coordinates).
        faces: skin face numbers in the order they were placed.
        cut_edges: shared edges cut to open cycles of the face graph.
        placement_residual: largest ``| |a1 - a0| - |q1 - q0| |`` of the shared edges' flat
            chords (the two faces' images of one edge), relative to the chord.
        area_faces: sum of the faces' own flat areas (equals the panel's area when nothing
            overlaps).
    """

    name: str
    panels: list[Any]
    thickness: float
    bends: list[dict[str, Any]]
    base_face: int
    faces: list[int]
    cut_edges: list[str]
    placement_residual: float
    area_faces: float

    def as_dict(self) -> dict[str, Any]:
        """Plain dict for reports and JSON."""
        return {"name": self.name, "thickness": self.thickness, "base_face": self.base_face, "faces": self.faces,
                "cut_edges": self.cut_edges, "panels": [p.label for p in self.panels],
                "area": float(sum(p.area_flat for p in self.panels)), "area_faces": self.area_faces,
                "placement_residual": self.placement_residual, "bends": self.bends}


def bend_row(name: str, face: int, kind: str, angle: float, radius: float, thickness: float, k: float,
             up: bool, allowance: float | None = None) -> dict[str, Any]:
    r"""One bend-table row.

    ``BA = (R + K T) A`` (the neutral arc of a circular bend; ``allowance`` overrides it for a
    cone or freeform bend: the measured distance of the bend lines), ``OSSB = (R + T) tan(A/2)``,
    ``BD = 2 OSSB - BA``.

    Args:
        name: bend name (``B1`` ...); face: its skin face number; kind: surface kind.
        angle: bend angle ``A`` in radians; radius: inside radius ``R``; thickness: ``T``; k: K.
        up: the bend turns towards the viewer (the skin's outward normal is +z in the flat).
    """
    ba = (radius + k * thickness) * angle if allowance is None else allowance
    ossb = (radius + thickness) * math.tan(0.5 * angle) if angle < math.pi else math.inf
    return {"bend": name, "face": face, "kind": kind, "angle_deg": math.degrees(angle), "inside_radius": radius,
            "k_factor": k, "thickness": thickness, "bend_allowance": ba, "bend_deduction": 2 * ossb - ba,
            "direction": "up" if up else "down"}


# -- rigid motions ---------------------------------------------------------------------------------
@dataclass
class _Motion:
    """``x -> Q (m x) + c``: ``m`` mirrors x (``diag(-1, 1)``) when ``mirror``."""

    Q: np.ndarray = field(default_factory=lambda: np.eye(2))
    c: np.ndarray = field(default_factory=lambda: np.zeros(2))
    mirror: bool = False

    def __call__(self, p: np.ndarray) -> np.ndarray:
        p = np.asarray(p, dtype=float)
        if self.mirror:
            p = p * np.array([-1.0, 1.0])
        return p @ self.Q.T + self.c


def _motion_onto(a0: np.ndarray, a1: np.ndarray, q0: np.ndarray, q1: np.ndarray, mirror: bool) -> _Motion:
    """The rigid motion (after the optional mirror) taking the segment q0 q1 onto a0 a1 (q0 -> a0,
    direction q1 - q0 -> a1 - a0)."""
    m = _Motion(mirror=mirror)
    q0m, q1m = m(q0), m(q1)
    da, dq = a1 - a0, q1m - q0m
    ang = math.atan2(da[1], da[0]) - math.atan2(dq[1], dq[0])
    c, s = math.cos(ang), math.sin(ang)
    m.Q = np.array([[c, -s], [s, c]])
    m.c = a0 - m.Q @ q0m
    return m


# -- geometry of one face ------------------------------------------------------------------------------
def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _outward(face: Any, u: float, v: float) -> tuple[np.ndarray, list[np.ndarray]]:
    """Outward unit normal ``o (S_u × S_v)/|.|`` and the jet ``[S, S_u, S_v, S_uu, S_vv, S_uv]`` at (u, v)."""
    d = face.surface.d2(np.array([u]), np.array([v]))
    d = [x[0] for x in d]
    n = _unit(np.cross(d[1], d[2]))
    return (-n if face.reversed else n), d


def _curvature(face: Any, ruled: str, u: float, v: float) -> tuple[float, np.ndarray]:
    r"""Signed principal curvature across the rulings ``κ = (S_xx · n) / |w|²`` (``x`` the
    parameter across the rulings, ``w`` the part of ``S_x`` normal to the ruling; ``n`` outward)
    and the outward normal: ``κ > 0`` when the face bends towards its outward side."""
    n, d = _outward(face, u, v)
    sx, sxx, r = (d[1], d[3], d[2]) if ruled == "v" else (d[2], d[4], d[1])
    r = _unit(r)
    w = sx - (sx @ r) * r
    return float(sxx @ n) / float(w @ w), n


def _gaussian_curvature(face: Any) -> float:
    r"""Gaussian curvature ``K = (L N - M²) / (E G - F²)`` at the middle of the face's parameter box
    (first fundamental form ``E = S_u·S_u``, ``F = S_u·S_v``, ``G = S_v·S_v``; second ``L = S_uu·n``,
    ``M = S_uv·n``, ``N = S_vv·n``); 0 on a developable face."""
    u0, u1, v0, v1 = face.bounds
    n, d = _outward(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1))
    E, F, G = d[1] @ d[1], d[1] @ d[2], d[2] @ d[2]
    L, M, N = d[3] @ n, d[5] @ n, d[4] @ n
    return float((L * N - M * M) / (E * G - F * F))


def _edge_uv(face: Any, name: str) -> Any:
    for wire in face.wires:
        for e in wire:
            if e.name == name:
                return e
    return None


# -- the walk --------------------------------------------------------------------------------------
def _edge_chord(panel: Any, name: str) -> tuple[np.ndarray, np.ndarray] | None:
    for loop in panel.loops:
        for e in loop:
            if e.name == name:
                f = np.asarray(e.flat_fn(np.array([0.0, 1.0])), dtype=float) + panel.offset
                return f[0], f[1]
    return None


def _jacobian_sign(panel: Any, face: Any) -> float:
    """Sign of ``det dF/d(u, v)`` times the face orientation: +1 when the development keeps the
    outward normal's sense (x, y, +z)."""
    u0, u1, v0, v1 = face.bounds
    u, v = 0.5 * (u0 + u1), 0.5 * (v0 + v1)
    hu, hv = 1e-4 * (u1 - u0), 1e-4 * (v1 - v0)
    p = panel.map(np.array([u - hu, u + hu, u, u]), np.array([v, v, v - hv, v + hv]))
    fu, fv = p[1] - p[0], p[3] - p[2]
    det = fu[0] * fv[1] - fu[1] * fv[0]
    o = -1.0 if face.reversed else 1.0  # (u, v) against the outward normal: reversed faces
    return math.copysign(1.0, det) * o


def unfold_skin(
    skin: SheetSkin,
    *,
    k_factor: float | KFactorTable = 0.5,
    base_face: int | None = None,
    bend_lines: str = "tangent",
    allow_split: bool = False,
    rulings: int = 8,
    samples: int = 129,
    tol_deg: float = 0.01,
    units: str = "mm",
) -> Blank:
    r"""Unfold one sheet skin into one blank (see module doc).

    Args:
        skin: the skin (:class:`SheetSkin`), from a kernel adapter.
        k_factor: ANSI K in [0, 1], or a :class:`KFactorTable` giving ``K(R/T)`` per bend.
        base_face: face number of the base face (default: the largest planar skin face, else the
            largest face).
        bend_lines: ``"tangent"`` (both tangent lines of every bend) or ``"centre"`` (the middle).
        allow_split: pieces that overlap in the plane become separate panels (one per face, with
            matching edge marks) instead of a refusal.
        rulings: bend lines drawn on a freeform (non-circular) bend.
        samples: points per boundary edge in the outline.
        tol_deg: largest accepted ``θ_max`` of a face (spec 5).
        units: length unit.

    Returns:
        :class:`Blank`.

    Raises:
        BlankError: a face that is not developable, a bad base face, overlapping pieces (without
            ``allow_split``), a face graph that is not connected.
    """
    from .errors import NotDevelopableError
    from .face_unroll import unroll_face_data
    from .flat_pattern import FlatPanel, layout_panels, mark_shared_edges, measure_panel
    from .sheet import Sheet, SheetError

    if bend_lines not in ("tangent", "centre", "center"):
        raise BlankError(f"bend_lines={bend_lines!r} is not allowed; allowed: 'tangent' or 'centre'")
    T = float(skin.thickness)
    table = k_factor if isinstance(k_factor, KFactorTable) else None
    if table is None:
        K0 = float(k_factor)
        if not (math.isfinite(K0) and 0.0 <= K0 <= 1.0):
            raise BlankError(f"k_factor={k_factor!r} is not allowed; the ANSI K-factor lies in [0, 1]")
    by_num = {f.number: f for f in skin.faces}
    if not by_num:
        raise BlankError(f"{skin.name}: the sheet has no skin faces")
    # base face
    if base_face is None:
        planar = [f for f in skin.faces if f.data.surface.kind == "plane"]
        base = max(planar or skin.faces, key=lambda f: f.area).number
    else:
        base = int(base_face)
        if base not in by_num:
            partner = [f.number for f in skin.faces if f.partner == base]
            if not partner:
                raise BlankError(f"{skin.name}: base face F{base} is not a skin face of the sheet; allowed: "
                                 f"{', '.join(f'F{n}' for n in sorted(by_num))} or their opposite faces")
            base = partner[0]
    # develop every face (bends on their neutral surface)
    panels: dict[int, Any] = {}
    bend_info: dict[int, dict[str, Any]] = {}
    for f in skin.faces:
        fd, kind = f.data, f.data.surface.kind
        label = f"F{f.number}"
        sheet = None
        if kind != "plane":
            ruled = "v" if kind in ("cylinder", "cone", "extrusion") else None
            if ruled is None:
                from .face_unroll import ruling_direction

                ruled = ruling_direction(fd.surface, fd.bounds)[0]
                if ruled is None:
                    kg = _gaussian_curvature(fd)
                    raise BlankError(f"{skin.name}: face F{f.number} ({kind}) is not developable: it is not ruled "
                                     f"(no straight isolines) and its Gaussian curvature at the middle of its parameter "
                                     f"box is {kg:.6g} /{units}^2 (radius 1/sqrt|K| = {1 / math.sqrt(abs(kg)) if kg else math.inf:.6g} "
                                     f"{units}; a developable face has 0); allowed: planes, cylinders, cones and "
                                     "developable ruled faces")
            u0, u1, v0, v1 = fd.bounds
            kap, _ = _curvature(fd, ruled, 0.5 * (u0 + u1), 0.5 * (v0 + v1))
            inside = kap > 0  # bends towards its outward side: the concave (inside) skin of the bend
            r_here = 1.0 / abs(kap) if kap != 0 else math.inf
            if kind == "cylinder":
                r_here = float(fd.surface.radius)
            r_in = r_here if inside else r_here - T
            if not (r_in > 1e-9 * max(T, 1.0)):
                raise BlankError(f"{skin.name}: bend face F{f.number} has inside radius {r_in:.6g} "
                                 "(a sharp bend); allowed: bends of inside radius > 0")
            K = table(r_in, T) if table is not None else K0
            sheet = Sheet(T, K if inside else 1.0 - K, "reverse")
            bend_info[f.number] = {"ruled": ruled, "inside": inside, "radius": r_in, "k": K, "kind": kind}
        try:
            pat = unroll_face_data(fd, tol_deg=tol_deg, rulings=rulings if kind not in ("plane", "cylinder", "cone") else 0,
                                   samples=samples, units=units, label=label, sheet=sheet)
        except NotDevelopableError as exc:
            raise BlankError(f"{skin.name}: face F{f.number} is not developable: {' '.join(str(exc).split())}") from None
        except SheetError as exc:
            raise BlankError(f"{skin.name}: face F{f.number}: {' '.join(str(exc).split())}") from None
        panels[f.number] = pat.panels[0]
    # orientation: every face's development keeps the outward normal's sense, else mirror it
    mirror = {n: _jacobian_sign(panels[n], by_num[n].data) < 0 for n in panels}
    # breadth-first walk from the base face
    nbrs: dict[int, list[tuple[str, int]]] = {n: [] for n in by_num}
    for key in sorted(skin.shared, key=_edge_key_order):
        a, b = skin.shared[key]
        if a in by_num and b in by_num and a != b:
            nbrs[a].append((key, b))
            nbrs[b].append((key, a))
    motion: dict[int, _Motion] = {base: _Motion(mirror=mirror[base])}
    order = [base]
    tree: set[str] = set()
    residual = 0.0
    queue = deque([base])
    while queue:
        a = queue.popleft()
        for key, b in nbrs[a]:
            if b in motion:
                continue
            ca = _edge_chord(panels[a], key)
            cb = _edge_chord(panels[b], key)
            ea, eb = _edge_uv(by_num[a].data, key), _edge_uv(by_num[b].data, key)
            if ca is None or cb is None or ea is None or eb is None:
                continue
            a0, a1 = motion[a](ca[0]), motion[a](ca[1])
            q0, q1 = cb
            xa = np.asarray(ea.xyz(np.array([0.0, 1.0])), dtype=float)
            xb = np.asarray(eb.xyz(np.array([0.0, 1.0])), dtype=float)
            if np.linalg.norm(xa[0] - xb[0]) > np.linalg.norm(xa[0] - xb[1]):  # traversed the other way
                q0, q1 = q1, q0
            la, lq = float(np.linalg.norm(a1 - a0)), float(np.linalg.norm(q1 - q0))
            residual = max(residual, abs(la - lq) / max(la, 1e-300))
            m = _motion_onto(a0, a1, q0, q1, mirror[b])
            # the face must land on the far side of the edge from its neighbour
            side_a = _side(a0, a1, _panel_point(panels[a], motion[a]))
            side_b = _side(a0, a1, _panel_point(panels[b], m))
            if side_a * side_b > 0:  # same side: the development's sense was misjudged, mirror across the edge
                m = _motion_onto(a0, a1, q0, q1, not mirror[b])
            motion[b] = m
            order.append(b)
            tree.add(key)
            queue.append(b)
    missing = sorted(set(by_num) - set(motion))
    if missing:
        raise BlankError(f"{skin.name}: skin faces {', '.join(f'F{n}' for n in missing)} are not connected to the base "
                         f"face F{base} through shared edges; allowed: one connected sheet per solid")
    cut = sorted((k for k, (a, b) in skin.shared.items() if a in by_num and b in by_num and k not in tree),
                 key=_edge_key_order)
    # bend table and bend lines
    bends: list[dict[str, Any]] = []
    lines: list[np.ndarray] = []
    texts: list[tuple[float, float, str, float, float]] = []
    for n in order:
        bi = bend_info.get(n)
        if bi is None:
            continue
        tang = []
        for key, _ in nbrs[n]:
            c = _edge_chord(panels[n], key)
            if c is not None:
                tang.append(np.array([motion[n](c[0]), motion[n](c[1])]))
        fd = by_num[n].data
        angle = _bend_angle(fd, bi, tang)
        width = _line_distance(tang[0], tang[1]) if len(tang) == 2 else None
        name = f"B{len(bends) + 1}"
        row = bend_row(name, n, bi["kind"], angle, bi["radius"], T, bi["k"], bi["inside"],
                       None if bi["kind"] == "cylinder" else width)
        row["bend_lines_distance"] = width
        bends.append(row)
        if bend_lines == "tangent" or len(tang) != 2:
            lines.extend(tang)
        else:
            t0, t1 = tang
            if np.linalg.norm(t0[0] - t1[0]) > np.linalg.norm(t0[0] - t1[1]):
                t1 = t1[::-1]
            lines.append(0.5 * (t0 + t1))
        if bi["kind"] not in ("cylinder", "cone") and panels[n].bend_lines.size:
            bl = panels[n].bend_lines
            lines.extend(np.stack([motion[n](bl[:, 0]), motion[n](bl[:, 1])], axis=1))
        if tang:
            mid = np.mean(np.concatenate(tang), axis=0)
            d = tang[0][1] - tang[0][0]
            rot = math.degrees(math.atan2(d[1], d[0]))
            rot = rot - 180 if rot > 90 else rot + 180 if rot < -90 else rot
            texts.append((float(mid[0]), float(mid[1]),
                          f"{name} {row['direction'].upper()} {row['angle_deg']:.4g} deg R{bi['radius']:.4g}",
                          0.0, rot))
    area_faces = float(sum(p.area_flat for p in panels.values()))
    label = skin.name
    merged = _merge(panels, motion, order, tree, label, samples)
    overlap = _overlaps(merged, panels, motion, order)
    if overlap is not None and not allow_split:
        faces_txt, area = overlap
        raise BlankError(f"{skin.name}: pieces of the blank overlap in the plane (faces {faces_txt}, overlap area "
                         f"{area:.9g} {units}^2); allowed: --allow-split (allow_split=True) to keep them apart as "
                         "separate panels with matching marks, or another base face")
    if overlap is None:
        ruling3 = [panels[n].ruling_lengths_3d for n in order]
        rulingf = [panels[n].ruling_lengths_flat for n in order]
        metric = {k: np.concatenate([panels[n].metric[k] for n in order if panels[n].metric])
                  for k in ("angle_3d", "angle_flat", "xu_len", "yu_len")}
        panel = FlatPanel(label=label, loops=merged, bend_lines=np.zeros((0, 2, 2)),
                          ruling_lengths_3d=np.concatenate(ruling3), ruling_lengths_flat=np.concatenate(rulingf),
                          area_3d=float(sum(panels[n].area_3d for n in order)), metric=metric,
                          info={"method": "connected unfolding of the sheet's skin", "faces": order})
        measure_panel(panel)
        panel.bend_lines = np.asarray(lines, dtype=float).reshape(-1, 2, 2)
        h = panel.texts[0][3] if panel.texts else 1.0
        panel.bend_texts = [(x, y, s, 0.5 * h, a) for x, y, s, _, a in texts]
        out_panels = [panel]
    else:
        out_panels = []
        for n in order:
            p = panels[n]
            _apply_motion(p, motion[n])
            for loop in p.loops:  # shared edges by the skin's own 3-D edges (a bend's are on its neutral surface)
                for e in loop:
                    if e.name in skin.shared:
                        e.xyz_fn, e.xyz = _edge_uv(by_num[n].data, e.name).xyz, None
            out_panels.append(p)
        mark_shared_edges(out_panels)
        layout_panels(out_panels)
    return Blank(skin.name, out_panels, T, bends, base, order, cut, residual, area_faces)


def _edge_key_order(key: str) -> tuple[int, str]:
    digits = "".join(ch for ch in key if ch.isdigit())
    return (int(digits) if digits else 0, key)


def _side(a0: np.ndarray, a1: np.ndarray, p: np.ndarray) -> float:
    d = a1 - a0
    w = p - a0
    return float(d[0] * w[1] - d[1] * w[0])


def _panel_point(panel: Any, m: _Motion) -> np.ndarray:
    """An interior point of a placed face: its outline's area centroid (vertex mean if outside)."""
    from .flat_pattern import _centroid

    return m(_centroid(panel.loop_polylines()[0]))


def _line_distance(l0: np.ndarray, l1: np.ndarray) -> float:
    """Distance from the midpoint of segment ``l1`` to the line of ``l0``."""
    d = _unit(l0[1] - l0[0])
    w = 0.5 * (l1[0] + l1[1]) - l0[0]
    return abs(float(d[0] * w[1] - d[1] * w[0]))


def _bend_angle(fd: Any, bi: dict[str, Any], tang: Sequence[np.ndarray]) -> float:
    """Bend angle: a cylinder's ``|Δu|``; else the angle between the outward normals at the two
    tangent edges (up to π)."""
    u0, u1, v0, v1 = fd.bounds
    if bi["kind"] == "cylinder":
        return abs(u1 - u0)
    if bi["ruled"] == "v":
        pts = ((u0, 0.5 * (v0 + v1)), (u1, 0.5 * (v0 + v1)))
    else:
        pts = ((0.5 * (u0 + u1), v0), (0.5 * (u0 + u1), v1))
    n0, _ = _outward(fd, *pts[0])
    n1, _ = _outward(fd, *pts[1])
    if bi["kind"] == "cone":
        return abs(u1 - u0)  # the cone turns by Δu about its axis (the angle between the end rulings' planes)
    return math.acos(max(-1.0, min(1.0, float(n0 @ n1))))


def _apply_motion(panel: Any, m: _Motion) -> None:
    """Move a face's panel by ``m`` in place (outline functions, bend lines; texts dropped)."""
    off = panel.offset.copy()
    for loop in panel.loops:
        for e in loop:
            f = e.flat_fn
            e.flat_fn = (lambda t, f=f: m(np.asarray(f(t), dtype=float) + off))
            e.flat = m(e.flat + off)
            if e.dense_flat.size:
                e.dense_flat = m(e.dense_flat + off)
    if panel.bend_lines.size:
        bl = panel.bend_lines
        panel.bend_lines = np.stack([m(bl[:, 0]), m(bl[:, 1])], axis=1)
    texts = [(m(np.array([x, y]) + off), s, h) for x, y, s, h in panel.texts]
    panel.offset = np.zeros(2)
    panel.texts = [(float(p[0]), float(p[1]), s, h) for p, s, h in texts]
    panel.forming_texts, panel.marks = [], []
    panel.development = None


def _merge(panels: dict[int, Any], motion: dict[int, _Motion], order: list[int], tree: set[str],
           label: str, samples: int) -> list[list[Any]]:
    """The blank's loops: every face's boundary edges except the tree's shared edges, moved into
    place and chained end to start (reversing where needed); the largest loop first."""
    from .flat_pattern import BoundaryEdge, _shoelace

    pieces = []
    for n in order:
        p = panels[n]
        off = p.offset.copy()
        m = motion[n]
        for loop in p.loops:
            for e in loop:
                if e.name in tree:
                    continue
                f = e.flat_fn
                ends = m(np.asarray(f(np.array([0.0, 1.0])), dtype=float) + off)
                pieces.append((n, e, ends))
    if not pieces:
        raise BlankError(f"{label}: the skin has no boundary edges")
    size = max(float(np.ptp(np.concatenate([pc[2] for pc in pieces]), axis=0).max()), 1e-300)
    tol = 1e-6 * size
    used = [False] * len(pieces)
    loops: list[list[Any]] = []
    for i0 in range(len(pieces)):
        if used[i0]:
            continue
        used[i0] = True
        chain = [(i0, False)]
        start = pieces[i0][2][0]
        end = pieces[i0][2][1]
        while np.linalg.norm(end - start) > tol:
            best, best_d, rev = -1, tol, False
            for j, pc in enumerate(pieces):
                if used[j]:
                    continue
                d0 = float(np.linalg.norm(pc[2][0] - end))
                d1 = float(np.linalg.norm(pc[2][1] - end))
                if d0 < best_d:
                    best, best_d, rev = j, d0, False
                if d1 < best_d:
                    best, best_d, rev = j, d1, True
            if best < 0:
                n, e, ends = pieces[chain[-1][0]]
                raise BlankError(f"{label}: the outline does not close after edge {e.name} of face F{n} (open end at "
                                 f"({end[0]:.6g}, {end[1]:.6g})); allowed: a skin whose boundary edges form closed loops")
            used[best] = True
            chain.append((best, rev))
            end = pieces[best][2][0 if rev else 1]
        loop = []
        for j, rev in chain:
            n, e, _ = pieces[j]
            m, off = motion[n], panels[n].offset.copy()
            f, x = e.flat_fn, e.xyz_fn
            if rev:
                flat_fn = (lambda t, f=f, m=m, off=off: m(np.asarray(f(1.0 - np.asarray(t)), dtype=float) + off))
                xyz_fn = (lambda t, x=x: x(1.0 - np.asarray(t)))
            else:
                flat_fn = (lambda t, f=f, m=m, off=off: m(np.asarray(f(t), dtype=float) + off))
                xyz_fn = x
            loop.append(BoundaryEdge(name=f"F{n}:{e.name}", flat_fn=flat_fn, xyz_fn=xyz_fn, length_3d=e.length_3d,
                                     samples=samples, breaks=tuple(1.0 - b for b in reversed(e.breaks)) if rev else e.breaks))
        loops.append(loop)
    areas = []
    for loop in loops:
        pts = np.concatenate([le.flat_fn(np.linspace(0.0, 1.0, 17))[:-1] for le in loop], axis=0)
        areas.append(abs(_shoelace(pts)))
    k = int(np.argmax(areas))
    loops.insert(0, loops.pop(k))
    return loops


def _segments(polys: Sequence[np.ndarray]) -> np.ndarray:
    return np.concatenate([np.stack([p, np.roll(p, -1, axis=0)], axis=1) for p in polys], axis=0)


def _crossings(segs: np.ndarray, eps: float) -> np.ndarray:
    """Index pairs (i, j), i < j, of segments that cross properly (interior points, beyond ``eps``
    of their ends in parameter)."""
    p, r = segs[:, 0], segs[:, 1] - segs[:, 0]
    n = len(segs)
    i, j = np.triu_indices(n, 1)
    # bounding boxes first
    lo = np.minimum(segs[:, 0], segs[:, 1])
    hi = np.maximum(segs[:, 0], segs[:, 1])
    ok = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    i, j = i[ok], j[ok]
    den = r[i, 0] * r[j, 1] - r[i, 1] * r[j, 0]
    w = p[j] - p[i]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (w[:, 0] * r[j, 1] - w[:, 1] * r[j, 0]) / den
        t = (w[:, 0] * r[i, 1] - w[:, 1] * r[i, 0]) / den
    hit = (np.abs(den) > 1e-300) & (s > eps) & (s < 1 - eps) & (t > eps) & (t < 1 - eps)
    return np.stack([i[hit], j[hit]], axis=1)


def _oriented(loops: Sequence[np.ndarray]) -> list[np.ndarray]:
    """A region's loops with the outer loop counter-clockwise and the holes clockwise."""
    from .flat_pattern import _shoelace

    out = []
    for i, lp in enumerate(loops):
        ccw = _shoelace(lp) > 0
        out.append(lp if ccw == (i == 0) else lp[::-1])
    return out


def _overlap_area(a: Sequence[np.ndarray], b: Sequence[np.ndarray]) -> float:
    r"""Area of the intersection of two polygonal regions (loops: outer first, then holes) by
    Green's theorem: ``∂(A ∩ B) = (∂A ∩ B) ∪ (∂B ∩ A)``, so with ``∂A``, ``∂B`` oriented (outer
    loop counter-clockwise, holes clockwise)

        area(A ∩ B) = ½ Σ_{s ⊂ ∂A ∩ B} (x_0 y_1 - x_1 y_0) + ½ Σ_{s ⊂ ∂B ∩ A} (x_0 y_1 - x_1 y_0),

    the boundary segments clipped to the other region (:func:`ght_cad.flat_pattern.clip_segments`).
    Exact for the polygons (the outline polylines of the faces)."""
    from .flat_pattern import clip_segments

    total = 0.0
    for p, q in ((a, b), (b, a)):
        segs = clip_segments(_segments(_oriented(p)), list(q))
        if len(segs):
            total += 0.5 * float(np.sum(segs[:, 0, 0] * segs[:, 1, 1] - segs[:, 1, 0] * segs[:, 0, 1]))
    return total


def _overlaps(loops: list[list[Any]], panels: dict[int, Any], motion: dict[int, _Motion],
              order: list[int]) -> tuple[str, float] | None:
    """None when the blank's loops do not cross each other or themselves; else (the faces whose
    edges cross, the overlap area). The area is the sum over the pairs of distinct faces whose
    edges cross of their placed outlines' intersection area (:func:`_overlap_area`, exact for the
    outline polygons); a face crossing only itself is estimated on a 200 x 200 grid over the
    blank's box (cells covered twice)."""
    from .flat_pattern import _inside

    polys, owner = [], []
    for loop in loops:
        pts, who = [], []
        for e in loop:
            q = e.flat_fn(np.linspace(0.0, 1.0, 33))[:-1]
            pts.append(q)
            who.extend([e.name.split(":", 1)[0]] * len(q))
        polys.append(np.concatenate(pts, axis=0))
        owner.append(who)
    allpts = np.concatenate(polys)
    segs = _segments(polys)
    cross = _crossings(segs, 1e-9)
    # a crossing closer than 1e-9 of the size to a segment end is a touching joint, not an overlap
    if not len(cross):
        return None
    names = [w for who in owner for w in who]
    faces = sorted({names[a] for a, b in cross} | {names[b] for a, b in cross}, key=lambda s: int(s[1:]))
    placed = {n: [motion[n](lp) for lp in panels[n].loop_polylines()] for n in order}
    pairs = sorted({tuple(sorted((int(names[a][1:]), int(names[b][1:])))) for a, b in cross})
    distinct = [(i, j) for i, j in pairs if i != j]
    if distinct:
        return ", ".join(faces), float(sum(_overlap_area(placed[i], placed[j]) for i, j in distinct))
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    g = 200
    xs = lo[0] + (np.arange(g) + 0.5) / g * (hi[0] - lo[0])
    ys = lo[1] + (np.arange(g) + 0.5) / g * (hi[1] - lo[1])
    X, Y = np.meshgrid(xs, ys)
    pts = np.stack([X.ravel(), Y.ravel()], axis=1)
    count = np.zeros(len(pts), dtype=int)
    for n in order:
        count += _inside(pts, placed[n]).astype(int)
    cell = (hi[0] - lo[0]) * (hi[1] - lo[1]) / g ** 2
    return ", ".join(faces), float((count > 1).sum() * cell)


@dataclass
class Unfolded:
    """Result of :func:`unfold_skins` / ``ght_cad.unfold``.

    Attributes:
        pattern: a :class:`ght_cad.flat_pattern.FlatPattern` with one panel per solid (labelled
            with the solid's name; several per solid only with ``allow_split``), laid out in rows.
        blanks: one :class:`Blank` per solid, in the shape's order.
        face_count: faces of the source shape.
    """

    pattern: Any
    blanks: list[Blank]
    face_count: int = 0

    @property
    def bends(self) -> list[dict[str, Any]]:
        """All bend-table rows, each with its ``blank`` name."""
        return [{"blank": b.name, **row} for b in self.blanks for row in b.bends]

    def bend_table(self) -> str:
        """The bend table as text (one line a bend)."""
        lines = ["bend  face  direction  angle [deg]  inside R  K       allowance    deduction"]
        for r in self.bends:
            lines.append(f"{r['blank']}:{r['bend']:<4} F{r['face']:<4} {r['direction']:<9} {r['angle_deg']:11.6g}  "
                         f"{r['inside_radius']:8.6g}  {r['k_factor']:.4g}  {r['bend_allowance']:11.9g}  "
                         f"{r['bend_deduction']:11.9g}")
        return "\n".join(lines)

    def as_dict(self) -> dict[str, Any]:
        """Plain dict: the blanks (:meth:`Blank.as_dict`) and the total area."""
        return {"blanks": [b.as_dict() for b in self.blanks], "area": float(self.pattern.area),
                "panels": len(self.pattern.panels)}


def unfold_skins(
    skins: Sequence[SheetSkin],
    *,
    k_factor: float | KFactorTable = 0.5,
    base_face: int | None = None,
    bend_lines: str = "tangent",
    allow_split: bool = False,
    units: str = "mm",
    face_count: int = 0,
    tol_deg: float = 0.01,
    rulings: int = 8,
) -> Unfolded:
    """One blank per skin (:func:`unfold_skin`), laid out in one pattern.

    ``base_face`` applies to the skin holding it (or its opposite face); the others use their
    default base face.

    Raises:
        BlankError: from :func:`unfold_skin`; a ``base_face`` in none of the skins.
    """
    from .flat_pattern import FlatPattern, layout_panels

    def holds(s: SheetSkin, n: int) -> bool:
        return any(f.number == n or f.partner == n for f in s.faces)

    if base_face is not None and not any(holds(s, base_face) for s in skins):
        nums = sorted(f.number for s in skins for f in s.faces)
        raise BlankError(f"base face F{base_face} is no skin face of any sheet; allowed: "
                         f"{', '.join(f'F{n}' for n in nums)} (or their opposite faces)")
    blanks = [unfold_skin(s, k_factor=k_factor, base_face=base_face if base_face is not None and holds(s, base_face) else None,
                          bend_lines=bend_lines, allow_split=allow_split, units=units, tol_deg=tol_deg, rulings=rulings)
              for s in skins]
    panels = [p for b in blanks for p in b.panels]
    if len(panels) > 1:
        layout_panels(panels)
    return Unfolded(FlatPattern(panels, units=units), blanks, face_count)


# -- sheet recognition (the kernel-free part shared by the OCP and FreeCAD adapters) ------------------
#: relative tolerance on the distance of a skin point to the other skin (of T) and on antiparallel normals
DIST_TOL = 1e-6
#: largest angle (degrees) between two skin faces' normals across a shared edge that counts as tangent
SHARP_DEG = 1e-3


def _check_pairing(sname: str, nums: Sequence[int], T: float, skin_of: Sequence[bool],
                   rays: Sequence[Sequence[tuple[float, bool, int]]], edges: dict[str, tuple[int, int]]) -> None:
    """Refuse a solid whose faces at distance T pair up in more than one way (an ambiguous skin).

    Skin faces sharing an edge lie on one side of the sheet, a face and the faces its probes reach
    at T on opposite sides: a two-colouring of the skin faces under these relations. A cycle with an
    odd number of "opposite" relations (e.g. a bar of square section T x T: top opposite bottom and
    left opposite right, yet top shares an edge with left and right) has none: no inside and
    outside skin exist.

    Raises:
        BlankError: naming the faces of the contradiction and the distance T.
    """
    rel: dict[int, list[tuple[int, int, str]]] = {}
    for key, (a, b) in edges.items():
        if skin_of[a] and skin_of[b] and a != b:
            rel.setdefault(a, []).append((b, 0, f"shares edge {key} with"))
            rel.setdefault(b, []).append((a, 0, f"shares edge {key} with"))
    for i, row in enumerate(rays):
        for d, ok, h in row:
            if skin_of[i] and h >= 0 and h != i and skin_of[h] and ok and abs(d - T) <= DIST_TOL * T:
                rel.setdefault(i, []).append((h, 1, f"lies at {d:.9g} opposite"))
                rel.setdefault(h, []).append((i, 1, f"lies at {d:.9g} opposite"))
    side: dict[int, int] = {}
    via: dict[int, tuple[int, str]] = {}
    for start in (i for i in range(len(nums)) if skin_of[i]):
        if start in side:
            continue
        side[start] = 0
        queue = deque([start])
        while queue:
            x = queue.popleft()
            for y, flip, how in rel.get(x, []):
                want = side[x] ^ flip
                if y not in side:
                    side[y], via[y] = want, (x, how)
                    queue.append(y)
                elif side[y] != want:
                    def chain(z: int) -> list[str]:
                        out = []
                        while z in via:
                            p, h = via[z]
                            out.append(f"F{nums[z]} {h} F{nums[p]}")
                            z = p
                        return out
                    steps = "; ".join(chain(x)[::-1] + [f"F{nums[y]} {how} F{nums[x]}"] + chain(y))
                    raise BlankError(f"{sname}: ambiguous skin: the faces at distance {T:.9g} from an opposite face pair "
                                     f"up in more than one way ({steps}): no inside and outside skin separate them; "
                                     "allowed: a sheet whose faces at distance T form exactly two sides")


def classify_skin(sname: str, nums: Sequence[int], areas: Sequence[float],
                  rays: Sequence[Sequence[tuple[float, bool, int]]], edges: dict[str, tuple[int, int]],
                  angle: Callable[[str, int, int], float], base_face: int | None = None,
                  ) -> tuple[float, list[int], dict[int, int], dict[str, tuple[int, int]], int]:
    r"""Sort a solid's faces into the sheet's two skins and its walls from the adapter's probes.

    ``T`` is the distance of the largest face whose probes all leave the material at one distance
    through a face of opposite normal; a face is skin when most of its probes leave at ``T``
    (relative :data:`DIST_TOL`) through an opposite face; the skin faces must pair up one way only
    (:func:`_check_pairing`); a block (every face skin, or ``T`` more
    than a quarter of the square root of the largest skin face's area) is no sheet; two skin faces
    sharing an edge must be tangent there (at most :data:`SHARP_DEG`); every skin face must be skin
    at all its probes; the skin faces form exactly two connected sets, each face's opposite face in
    the other set.

    Args:
        sname: the solid's name (messages); nums: face numbers (messages); areas: face areas.
        rays: per face, per probe ``(distance, opposite normal, index of the face hit or -1)``.
        edges: edge key (``E<k>``) -> the indices of the two faces sharing it.
        angle: ``angle(key, a, b)``: degrees between faces a and b's normals at the edge.
        base_face: a face number whose skin is the one returned (default: the smaller skin).

    Returns:
        ``(T, comp, partner, shared, ref)``: per face its skin (0, 1) or -1 (wall), each skin face's
        opposite face index, the shared edges of skin faces, the chosen skin (0 or 1).

    Raises:
        BlankError: no sheet (a block), a sharp edge, an ambiguous skin; one line naming the
            face/edge and the measured value.
    """
    n = len(nums)
    # thickness: the largest face whose rays all leave at one distance through an opposite face
    T = None
    for i in sorted(range(n), key=lambda i: -areas[i]):
        row = rays[i]
        if row and all(ok for _, ok, _ in row):
            ds = [d for d, _, _ in row]
            if max(ds) - min(ds) <= DIST_TOL * max(ds):
                T = float(np.mean(ds))
                break
    if T is None:
        raise BlankError(f"{sname}: no sheet: no face lies at a constant distance from an opposite face "
                         f"(largest face F{nums[int(np.argmax(areas))]}); allowed: sheet solids of one thickness")
    skin_of = []
    for i, row in enumerate(rays):
        good = [ok and abs(d - T) <= DIST_TOL * T for d, ok, _ in row]
        skin_of.append(bool(row) and sum(good) * 2 > len(row))
    if all(skin_of):
        raise BlankError(f"{sname}: no sheet: every face lies at distance {T:.9g} from an opposite face, no thickness "
                         "walls separate two sides (a block); allowed: sheet solids")
    big = max(areas[i] for i in range(n) if skin_of[i])
    if T > 0.25 * math.sqrt(big):
        raise BlankError(f"{sname}: no sheet: its thickness {T:.9g} is more than a quarter of the square root of its "
                         f"largest skin face's area {big:.9g} (a block); allowed: sheets thinner than that")
    _check_pairing(sname, nums, T, skin_of, rays, edges)
    shared: dict[str, tuple[int, int]] = {}
    for key, (a, b) in edges.items():
        if not (skin_of[a] and skin_of[b]):
            continue
        ang = float(angle(key, a, b))
        if ang > SHARP_DEG:
            raise BlankError(f"{sname}: sharp edge {key} between skin faces F{nums[a]} and F{nums[b]}: "
                             f"they meet at {ang:.6g} deg (a bend of zero radius); allowed: bends with an inside "
                             "radius > 0 (tangent faces)")
        shared[key] = (a, b)
    for i, row in enumerate(rays):
        if not skin_of[i]:
            continue
        bad = [d for d, ok, _ in row if not (ok and abs(d - T) <= DIST_TOL * T)]
        if bad:
            raise BlankError(f"{sname}: ambiguous skin: face F{nums[i]} lies at distance {T:.9g} from the other skin "
                             f"at {len(row) - len(bad)} of {len(row)} points but {min(bad):.9g} at others; allowed: "
                             "sheets of one thickness whose faces pair up")
    # connected sets of skin faces
    comp = [-1] * n
    adj: dict[int, list[int]] = {}
    for a, b in shared.values():
        adj.setdefault(a, []).append(b)
        adj.setdefault(b, []).append(a)
    ncomp = 0
    for i in range(n):
        if skin_of[i] and comp[i] < 0:
            stack = [i]
            comp[i] = ncomp
            while stack:
                x = stack.pop()
                for y in adj.get(x, []):
                    if comp[y] < 0:
                        comp[y] = ncomp
                        stack.append(y)
            ncomp += 1
    if ncomp != 2:
        what = ("one closed skin: no thickness walls separate two sides (a block)" if ncomp == 1 else
                f"{ncomp} separate sets of faces at distance {T:.9g}")
        raise BlankError(f"{sname}: {'no sheet' if ncomp == 1 else 'ambiguous skin'}: the faces at distance {T:.9g} "
                         f"from an opposite face form {what}; allowed: one sheet solid with an inside and an outside skin")
    partner: dict[int, int] = {}
    for i, row in enumerate(rays):
        if not skin_of[i]:
            continue
        hits = [h for _, _, h in row if h >= 0]
        other = [h for h in hits if comp[h] != comp[i]]
        if not hits or len(other) != len(hits):
            raise BlankError(f"{sname}: ambiguous skin: face F{nums[i]}'s opposite points lie on its own side of the "
                             "sheet; allowed: an inside and an outside skin")
        partner[i] = max(set(other), key=other.count)
    area_c = [sum(areas[i] for i in range(n) if comp[i] == c) for c in (0, 1)]
    ref = int(np.argmin(area_c))
    if base_face is not None and base_face in nums:
        bi = list(nums).index(base_face)
        if skin_of[bi]:
            ref = comp[bi]
    return T, comp, partner, shared, ref
