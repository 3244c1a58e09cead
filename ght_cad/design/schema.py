r"""Design-file schema: the dataclasses of a design and their validation (:func:`parse_design`).

Every check names the file, the key and the allowed values and raises :class:`DesignError`
(a :class:`~ght_cad.errors.GHTError`, so ``ght-cad`` exits with code 2). The schema is documented
in ``docs/design-files.md``.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

from ..errors import GHTError


#: file outputs a design may request
FILE_OUTPUTS = ("step", "dxf", "svg", "json", "md")


#: figures a design may request (PNG)
FIGURE_OUTPUTS = ("basis", "curve", "curvature", "surface", "flat_pattern", "convergence", "deviation")


#: optimizers
METHODS = ("hybrid", "pso", "gwo", "igwo")


#: objectives: fairness of the dual curve (planes) or developability R (curve-pair strips)
PLANE_OBJECTIVES = ("AL", "En", "CVEn", "weighted")


STRIP_OBJECTIVES = ("R",)


#: objectives of a ``rails`` surface (the developable loft, :data:`ght_cad.loft.LOFT_OBJECTIVES`) and their
#: weighted sum ``w0 fan_share + w1 fairness + w2 regression``
RAILS_OBJECTIVES = ("fan_share", "fairness", "regression", "weighted")
SURFACE_TYPES = ("planes", "curves", "rails", "composite", "approximate")
#: the parameter the rulings of an ``approximate`` surface run along (:func:`ght_cad.approximate`)
APPROX_DIRECTIONS = ("auto", "u", "v")
#: largest ``max_panels`` of an ``approximate`` surface (each panel is a developable loft)
MAX_APPROX_PANELS = 256
#: largest degree of an inline NURBS target (and rows/columns of a target net: :data:`MAX_ROWS`)
MAX_TARGET_DEGREE = 25
#: orientations of the second rail of a ``rails`` surface (:func:`ght_cad.developable_loft`)
RAIL_ORIENTATIONS = ("auto", "same", "reversed")


#: joins between the strips of a composite surface (spec 5.6)
STRIP_JOINS = ("G1", "G2", "G3")


CONTINUITIES = ("C0", "C1", "C2", "C3", "G0", "G1", "G2", "G3")


UNITS = ("mm", "cm", "m", "in", "ft")


#: what ``sheet.side`` refers to with several surfaces (``SheetSpec.side_reference``)
SIDE_REFERENCES = ("shell", "surface")


SHAPE_NAMES = ("mu", "nu", "gamma")


# output file names inside the output folder
FILE_NAMES = {
    "step": "model.step",
    "dxf": "flat_pattern.dxf",
    "svg": "flat_pattern.svg",
    "json": "report.json",
    "md": "report.md",
}


FIGURE_NAMES = {k: f"{k}.png" for k in FIGURE_OUTPUTS}


#: largest coordinate (or plane coefficient) a design file may give, in its unit (as for STEP input)
MAX_DESIGN_COORDINATE = 1e12
#: most control points (planes) of one curve (surface) in a design file: degree 999 (an unused
#: curve of 100,000 points allocated 1.7 GiB, one of 2,000,000 ran past 120 s)
MAX_ROWS = 1000
#: largest ``unroll.samples * (unroll.rulings + 1)``: the flat pattern's grid (20001 x 1001 inside the
#: single ranges allocated 8.9 GiB; the defaults are 257 x 17)
MAX_UNROLL_GRID = 1_000_000


class DesignError(GHTError):
    """An invalid design file: one line naming the file, the key and the allowed values."""


@dataclass
class CurveSpec:
    """One GHT-Bézier curve ``P(t) = Σ b_{i,m}(t; μ,ν,γ) P_i`` of a design."""

    name: str
    control_points: list[list[float]]
    mu: float = 0.0
    nu: float = 0.0
    gamma: float = 0.0


@dataclass
class JoinSpec:
    """Re-solve the first points of curve ``second`` so that it meets ``first`` (spec section 4)."""

    first: str
    second: str
    continuity: str = "G1"
    k: float = 1.0
    beta2: float = 0.0
    beta3: float = 0.0


@dataclass
class SegmentSpec:
    """One strip of a ``composite`` surface: an enveloping developable of control planes.

    Strip 0 is built from its planes (spec 5.2); strip i > 0 is joined to strip i-1 with
    ``continuity`` (G1/G2/G3) by :func:`ght_cad.developable.join_developable`, which re-solves
    its first ``r+1`` control planes (``r`` = the order) and keeps the others.
    """

    name: str
    planes: list[list[float]]
    mu: float = 0.0
    nu: float = 0.0
    gamma: float = 0.0
    continuity: str | None = None
    k: float = 1.0
    beta2: float = 0.0
    beta3: float = 0.0


@dataclass
class SurfaceSpec:
    """A surface of the design: ``type = "planes"`` (spec 5.2), ``"curves"`` (equal-parameter ruled
    strip, quasi-developable), ``"rails"`` (the exact developable loft between two curves, spec 5.7)
    or ``"composite"`` (several strips from control planes joined G1/G2/G3, spec 5.6). ``name`` is
    the surface's name in ``[[surfaces]]`` (None for a single ``[surface]``)."""

    type: str
    planes: list[list[float]] | None = None
    boundary_planes: list[list[float]] | None = None
    mu: float = 0.0
    nu: float = 0.0
    gamma: float = 0.0
    curve_a: str | None = None
    curve_b: str | None = None
    normalize: bool = False
    segments: list[SegmentSpec] | None = None
    orientation: str = "auto"
    name: str | None = None
    #: where the surface is in the file (``surface`` or ``surfaces[i]``), for error messages
    key: str = "surface"
    #: ``[surfaces.sheet]``: this surface's overrides of the design's ``[sheet]`` (any of
    #: ``thickness``, ``k_factor``, ``side``; None: the design's sheet as it is)
    sheet: dict[str, Any] | None = None
    #: ``type = "approximate"``: the target (:class:`TargetSpec`), the tolerance (both ways, in the
    #: design's unit), the largest panel count and the parameter the rulings run along
    target: "TargetSpec | None" = None
    tol: float = 0.0
    max_panels: int = 64
    direction: str = "auto"


@dataclass
class TargetSpec:
    """The target of an ``approximate`` surface (``[surfaces.target]``): a face of a STEP file
    (``step``: path relative to the design file, ``face``: 1-based), a GHT patch (``control_points``
    net (m+1) x (n+1) x 3 and ``mu_u`` ... ``gamma_v``) or a NURBS patch (``poles`` net, ``knots_u``,
    ``knots_v``, ``degree_u``, ``degree_v``, optional ``weights``)."""

    kind: str  # "step", "ght" or "nurbs"
    step: str | None = None
    face: int = 1
    control_points: list[list[list[float]]] | None = None
    shape: dict[str, float] = field(default_factory=dict)
    knots_u: list[float] | None = None
    knots_v: list[float] | None = None
    degree_u: int = 3
    degree_v: int = 3
    weights: list[list[float]] | None = None


@dataclass
class OptimizeSpec:
    """Shape-parameter optimization (spec sections 7, 8)."""

    method: str = "hybrid"
    objective: str = "CVEn"
    weights: list[float] = field(default_factory=lambda: [1.0, 0.0, 0.0])
    parameters: list[str] = field(default_factory=lambda: list(SHAPE_NAMES))
    population: int = 20
    iterations: int = 40
    seed: int = 1


@dataclass
class UnrollSpec:
    """Flat-pattern options (see :func:`ght_cad.unroll`)."""

    rulings: int = 16
    tol_deg: float = 0.01
    #: points per boundary edge of the outline polylines (the DXF/SVG outline is that polygon)
    samples: int = 257
    #: "joined": strips/surfaces meeting at G1 or smoother are one blank; "per-surface": one panel each
    panels: str = "joined"


#: the values of ``[unroll] panels``
PANELS_CHOICES = ("joined", "per-surface")


@dataclass
class OutputSpec:
    """Which files and figures to write."""

    files: list[str] = field(default_factory=lambda: list(FILE_OUTPUTS))
    figures: list[str] = field(default_factory=lambda: list(FIGURE_OUTPUTS))
    #: ``[outputs] chord_tol``: largest distance between a curved (not line, not circle) boundary edge
    #: and the arcs the DXF/SVG outline writes for it, in the design's units (None: 1e-3 mm,
    #: :attr:`ght_cad.flat_pattern.FlatPattern.chord_tol`); ``--chord-tol`` takes precedence
    chord_tol: float | None = None


@dataclass
class SheetSpec:
    """``[sheet]``: the plate the surface is made of (spec 6.1).

    Attributes:
        thickness: sheet thickness T >= 0 (0: the surface itself).
        k_factor: ANSI K-factor in [0, 1] (``din_k_factor = 2K`` in the file is converted).
        side: "normal" (material along the surface normal) or "reverse".
    """

    thickness: float
    k_factor: float = 0.5
    side: str = "normal"
    #: with several ``[[surfaces]]``: what ``side`` is measured on, ``"shell"`` (the shell's
    #: orientation: the first surface's normal carried consistently across the shared rails) or
    #: ``"surface"`` (each surface's own normal); one surface: its own normal either way
    side_reference: str = "shell"
    #: ``k_factor_table``: a :class:`ght_cad.blank.KFactorTable` giving K by the surface's ``R / T``
    #: (R its smallest inside bending radius, :func:`ght_cad.design.build.table_k_factor`); until a
    #: built surface resolves it, ``k_factor`` is the table's largest K (the strictest neutral offset)
    k_factor_table: Any = None
    #: ``R / T`` the table was read at (set with ``k_factor`` when a built surface resolves it)
    k_factor_ratio: float | None = None

    def to_sheet(self) -> Any:
        """The :class:`ght_cad.sheet.Sheet`."""
        from ..sheet import Sheet

        return Sheet(self.thickness, self.k_factor, self.side)


@dataclass
class Design:
    """A validated design (see ``docs/design-files.md``)."""

    name: str
    units: str = "mm"
    curves: list[CurveSpec] = field(default_factory=list)
    joins: list[JoinSpec] = field(default_factory=list)
    surface: SurfaceSpec | None = None
    optimize: OptimizeSpec | None = None
    unroll: UnrollSpec = field(default_factory=UnrollSpec)
    outputs: OutputSpec = field(default_factory=OutputSpec)
    source: str = "<design>"
    sheet: SheetSpec | None = None
    #: every surface: ``[surface]`` gives one (``surface`` is then that one), ``[[surfaces]]`` one per
    #: entry (``surface`` is the only one for a single entry, else None)
    surfaces: list[SurfaceSpec] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.surfaces and self.surface is not None:
            self.surfaces = [self.surface]

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (as it would be written in TOML)."""
        from dataclasses import asdict

        d = asdict(self)
        d.pop("source")
        for sd in [d["surface"] or {}] + d["surfaces"]:
            sd.pop("key", None)
            if sd.get("type") != "approximate":  # the keys of an approximate surface only
                for k in ("target", "tol", "max_panels", "direction"):
                    sd.pop(k, None)
            if sd.get("sheet", 0) is None:  # no per-surface sheet overrides: as before
                sd.pop("sheet")
        if d["sheet"] is not None:
            tab = self.sheet.k_factor_table if self.sheet is not None else None
            for k in ("k_factor_table", "k_factor_ratio"):
                d["sheet"].pop(k)
            if tab is not None:  # as the file gives it: a table's name, or its [R/T, K] rows
                d["sheet"]["k_factor_table"] = (tab.name if tab.name in ("ansi", "din") else
                                                [[r, k] for r, k in zip(tab.ratios, tab.k_factors)])
        if d["sheet"] is not None and len(self.surfaces) <= 1:
            d["sheet"].pop("side_reference")  # one surface: its own normal (as before)
        if len(self.surfaces) <= 1 and all(s.name is None for s in self.surfaces):
            d.pop("surfaces")  # a single [surface]: as before
        if d["outputs"]["chord_tol"] is None:  # the default: as before (TOML has no null)
            d["outputs"].pop("chord_tol")
        return d


def _tname(v: Any) -> str:
    if isinstance(v, bool):
        return "boolean"
    if isinstance(v, int):
        return "integer"
    if isinstance(v, float):
        return "float"
    if isinstance(v, str):
        return "string"
    if isinstance(v, list):
        return "array"
    if isinstance(v, dict):
        return "table"
    return type(v).__name__


def _short(v: Any) -> str:
    s = repr(v)
    return s if len(s) <= 60 else s[:57] + "..."


class _Checker:
    """Typed getters that raise :class:`DesignError` naming ``source``, the key and what is allowed."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, key: str, message: str) -> DesignError:
        return DesignError(f"{self.source}: key '{key}': {message}")

    def table(self, data: dict, key: str, path: str, *, required: bool = False) -> dict | None:
        if key not in data:
            if required:
                raise self.fail(path, "missing; this table is required")
            return None
        v = data[key]
        if not isinstance(v, dict):
            raise self.fail(path, f"expected a table [{path}], got {_tname(v)} {_short(v)}")
        return v

    def keys(self, tbl: dict, path: str, allowed: Sequence[str]) -> None:
        for k in tbl:
            if k not in allowed:
                where = f"{path}.{k}" if path else k
                raise self.fail(where, f"unknown key; allowed keys{' in ' + path if path else ''}: {', '.join(allowed)}")

    def required(self, tbl: dict, key: str, path: str, what: str) -> Any:
        if key not in tbl:
            raise self.fail(f"{path}.{key}" if path else key, f"missing; required: {what}")
        return tbl[key]

    def number(self, tbl: dict, key: str, path: str, default: float | None = None, *,
               lo: float | None = None, hi: float | None = None, lo_open: bool = False,
               required: bool = False, allowed: str | None = None) -> float:
        full = f"{path}.{key}" if path else key
        rng = allowed or _range_text(lo, hi, lo_open)
        if key not in tbl:
            if required or default is None:
                raise self.fail(full, f"missing; required: a number {rng}")
            return default
        v = tbl[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise self.fail(full, f"expected a number {rng}, got {_tname(v)} {_short(v)}")
        x = float(v)
        if not math.isfinite(x):
            raise self.fail(full, f"{x} is not finite; allowed: a number {rng}")
        if (lo is not None and (x <= lo if lo_open else x < lo)) or (hi is not None and x > hi):
            raise self.fail(full, f"{x:g} is out of range; allowed: {rng}")
        return x

    def integer(self, tbl: dict, key: str, path: str, default: int, *, lo: int, hi: int) -> int:
        full = f"{path}.{key}" if path else key
        if key not in tbl:
            return default
        v = tbl[key]
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail(full, f"expected an integer in [{lo}, {hi}], got {_tname(v)} {_short(v)}")
        if not lo <= v <= hi:
            raise self.fail(full, f"{v} is out of range; allowed: an integer in [{lo}, {hi}]")
        return int(v)

    def string(self, tbl: dict, key: str, path: str, default: str | None = None, *,
               choices: Sequence[str] | None = None, required: bool = False) -> str:
        full = f"{path}.{key}" if path else key
        allowed = f"one of {', '.join(choices)}" if choices else "a non-empty string"
        if key not in tbl:
            if required or default is None:
                raise self.fail(full, f"missing; required: {allowed}")
            return default
        v = tbl[key]
        if not isinstance(v, str):
            raise self.fail(full, f"expected a string ({allowed}), got {_tname(v)} {_short(v)}")
        if choices is not None:
            match = [c for c in choices if c.lower() == v.lower()]
            if not match:
                raise self.fail(full, f"{v!r} is not allowed; allowed: {', '.join(choices)}")
            return match[0]
        if not v.strip():
            raise self.fail(full, "is empty; allowed: a non-empty string")
        return v

    def matrix(self, tbl: dict, key: str, path: str, *, cols: Sequence[int], min_rows: int,
               max_rows: int | None = None, required: bool = True) -> list[list[float]] | None:
        full = f"{path}.{key}" if path else key
        colt = " or ".join(str(c) for c in cols)
        what = f"an array of at least {min_rows} arrays of {colt} numbers" if max_rows != min_rows else \
            f"an array of exactly {min_rows} arrays of {colt} numbers"
        if key not in tbl:
            if required:
                raise self.fail(full, f"missing; required: {what}")
            return None
        v = tbl[key]
        if not isinstance(v, list) or not all(isinstance(r, list) for r in v):
            raise self.fail(full, f"expected {what}, got {_tname(v)} {_short(v)}")
        if len(v) < min_rows or (max_rows is not None and len(v) > max_rows):
            raise self.fail(full, f"has {len(v)} rows; allowed: {what}")
        if len(v) > MAX_ROWS:  # checked before anything is allocated for them
            raise self.fail(full, f"has {len(v)} rows; allowed: at most {MAX_ROWS} (degree {MAX_ROWS - 1})")
        n = len(v[0])
        out = []
        for i, row in enumerate(v):
            if len(row) != n or n not in cols:
                raise self.fail(f"{full}[{i}]", f"has {len(row)} numbers; allowed: {colt} numbers, the same for every row")
            vals = []
            for j, x in enumerate(row):
                if isinstance(x, bool) or not isinstance(x, (int, float)):
                    raise self.fail(f"{full}[{i}][{j}]", f"expected a number, got {_tname(x)} {_short(x)}")
                if not math.isfinite(float(x)):
                    raise self.fail(f"{full}[{i}][{j}]", f"{x} is not finite; allowed: a finite number")
                if abs(float(x)) > MAX_DESIGN_COORDINATE:
                    raise self.fail(f"{full}[{i}][{j}]", f"{float(x):g} is beyond ±{MAX_DESIGN_COORDINATE:g}; "
                                    f"allowed: a number within ±{MAX_DESIGN_COORDINATE:g} (of the design's unit)")
                vals.append(float(x))
            out.append(vals)
        return out

    def boolean(self, tbl: dict, key: str, path: str, default: bool) -> bool:
        full = f"{path}.{key}" if path else key
        if key not in tbl:
            return default
        v = tbl[key]
        if not isinstance(v, bool):
            raise self.fail(full, f"expected a boolean (true or false), got {_tname(v)} {_short(v)}")
        return v

    def string_list(self, tbl: dict, key: str, path: str, default: list[str], *, choices: Sequence[str]) -> list[str]:
        full = f"{path}.{key}" if path else key
        if key not in tbl:
            return list(default)
        v = tbl[key]
        if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
            raise self.fail(full, f"expected an array of strings from: {', '.join(choices)}; got {_tname(v)} {_short(v)}")
        out = []
        for x in v:
            match = [c for c in choices if c.lower() == x.lower()]
            if not match:
                raise self.fail(full, f"{x!r} is not allowed; allowed: {', '.join(choices)}")
            if match[0] not in out:
                out.append(match[0])
        return out


def _range_text(lo: float | None, hi: float | None, lo_open: bool = False) -> str:
    if lo is not None and hi is not None:
        return f"in [{lo:g}, {hi:g}]"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo:g}"
    if hi is not None:
        return f"<= {hi:g}"
    return ""


_TOP_KEYS = ("name", "units", "curves", "joins", "surface", "surfaces", "optimize", "unroll", "outputs", "sheet")


def parse_design(data: dict[str, Any], source: str = "<design>") -> Design:
    """Validate a parsed design file (a dict from ``tomllib``) and return a :class:`Design`.

    Every check names ``source``, the key and the allowed values.

    Args:
        data: the parsed TOML document.
        source: file name used in error messages.

    Returns:
        The validated design.

    Raises:
        DesignError: missing key, wrong type, value out of range, unknown key or unknown output.
    """
    ck = _Checker(source)
    if not isinstance(data, dict):
        raise DesignError(f"{source}: the document must be a TOML table")
    if isinstance(data.get("sweep"), dict):  # expanded into variants by ght-cad batch (ght_cad.sweep)
        raise ck.fail("sweep", f"a [sweep] table is expanded into variants by 'ght-cad batch {source} --out DIR' "
                               "(ght_cad.sweep.expand_sweep); allowed here: a design without [sweep]")
    ck.keys(data, "", _TOP_KEYS)
    default_name = Path(source).stem if not source.startswith("<") else "design"
    name = ck.string(data, "name", "", default_name or "design")
    units = ck.string(data, "units", "", "mm", choices=UNITS)

    # curves
    curves: list[CurveSpec] = []
    raw_curves = data.get("curves", [])
    if not isinstance(raw_curves, list) or not all(isinstance(c, dict) for c in raw_curves):
        raise ck.fail("curves", f"expected an array of tables [[curves]], got {_tname(raw_curves)}")
    seen: set[str] = set()
    for i, c in enumerate(raw_curves):
        path = f"curves[{i}]"
        ck.keys(c, path, ("name", "control_points", "mu", "nu", "gamma"))
        cname = ck.string(c, "name", path, f"curve{i + 1}")
        if cname in seen:
            raise ck.fail(f"{path}.name", f"{cname!r} is used twice; allowed: a name unique among [[curves]]")
        seen.add(cname)
        pts = ck.matrix(c, "control_points", path, cols=(2, 3), min_rows=3)
        shape = {k: ck.number(c, k, path, 0.0, lo=-1.0, hi=1.0) for k in SHAPE_NAMES}
        curves.append(CurveSpec(cname, pts, **shape))  # type: ignore[arg-type]

    # joins
    joins: list[JoinSpec] = []
    raw_joins = data.get("joins", [])
    if not isinstance(raw_joins, list) or not all(isinstance(j, dict) for j in raw_joins):
        raise ck.fail("joins", f"expected an array of tables [[joins]], got {_tname(raw_joins)}")
    for i, j in enumerate(raw_joins):
        path = f"joins[{i}]"
        ck.keys(j, path, ("first", "second", "continuity", "k", "beta2", "beta3"))
        names = sorted(seen) or ["(no curves defined)"]
        first = ck.string(j, "first", path, required=True, choices=names if seen else None)
        second = ck.string(j, "second", path, required=True, choices=names if seen else None)
        if not seen:
            raise ck.fail(f"{path}.first", "refers to a curve but no [[curves]] are defined")
        if first == second:
            raise ck.fail(f"{path}.second", f"{second!r} equals first; allowed: another curve name from {', '.join(names)}")
        cont = ck.string(j, "continuity", path, "G1", choices=CONTINUITIES)
        k = ck.number(j, "k", path, 1.0, lo=0.0, lo_open=True)
        b2 = ck.number(j, "beta2", path, 0.0)
        b3 = ck.number(j, "beta3", path, 0.0)
        joins.append(JoinSpec(first, second, cont, k, b2, b3))
    seconds = [j.second for j in joins]
    for s in seconds:
        if seconds.count(s) > 1:
            raise ck.fail("joins", f"curve {s!r} is the 'second' of two joins; allowed: each curve re-solved at most once")

    # surface(s)
    surfaces = _parse_surfaces(ck, data, curves)
    surface = surfaces[0] if len(surfaces) == 1 else None
    approx = [s for s in surfaces if s.type == "approximate"]
    if approx and len(surfaces) > 1:
        raise ck.fail(f"{approx[0].key}.type", f"\"approximate\" covers its target with panels of its own and must be "
                      f"the design's only surface (this design has {len(surfaces)}); allowed: one [[surfaces]] entry "
                      "(or [surface]) of type \"approximate\", or other surface types together")

    # optimize
    optimize = None
    ot = ck.table(data, "optimize", "optimize")
    if ot is not None:
        if surface is None:
            raise ck.fail("optimize", ("needs a [surface] table to optimize" if not surfaces else
                                       f"optimizes one surface; this design has {len(surfaces)} [[surfaces]]; "
                                       "allowed: [optimize] with a single [surface] or [[surfaces]] entry"))
        if surface.type == "approximate":
            raise ck.fail("optimize", "an approximate surface is fitted and optimized by ght_cad.approximate itself; "
                          "allowed: [optimize] with a planes, curves, rails or composite surface")
        ck.keys(ot, "optimize", ("method", "objective", "weights", "parameters", "population", "iterations", "seed"))
        method = ck.string(ot, "method", "optimize", "hybrid", choices=METHODS)
        objs = _objectives_for(surface.type)
        objective = ck.string(ot, "objective", "optimize", default_objective(surface.type), choices=objs)
        weights = [1.0, 0.0, 0.0]
        if "weights" in ot:
            w = ot["weights"]
            if (not isinstance(w, list) or len(w) != 3
                    or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and x >= 0
                               for x in w)
                    or not any(x > 0 for x in w)):
                raise ck.fail("optimize.weights", f"{_short(w)} is not allowed; allowed: three numbers >= 0 (weights of "
                              f"{', '.join(_weight_names(surface.type))}), not all 0")
            weights = [float(x) for x in w]
        pchoices = _shape_names(surface)
        if surface.type == "composite":
            params = _composite_parameters(ck, ot, surface)
        else:
            params = ck.string_list(ot, "parameters", "optimize", list(pchoices), choices=pchoices)
        if not params:
            raise ck.fail("optimize.parameters", f"is empty; allowed: a non-empty subset of {', '.join(pchoices)}")
        pop = ck.integer(ot, "population", "optimize", 20, lo=4, hi=500)
        its = ck.integer(ot, "iterations", "optimize", 40, lo=1, hi=5000)
        seed = ck.integer(ot, "seed", "optimize", 1, lo=0, hi=2**32 - 1)
        optimize = OptimizeSpec(method, objective, weights, params, pop, its, seed)

    # unroll
    unroll = UnrollSpec()
    ut = ck.table(data, "unroll", "unroll")
    if ut is not None:
        ck.keys(ut, "unroll", ("rulings", "tol_deg", "samples", "panels"))
        unroll = UnrollSpec(ck.integer(ut, "rulings", "unroll", 16, lo=0, hi=1000),
                            ck.number(ut, "tol_deg", "unroll", 0.01, lo=0.0, hi=90.0, lo_open=True),
                            ck.integer(ut, "samples", "unroll", 257, lo=9, hi=20001),
                            ck.string(ut, "panels", "unroll", "joined", choices=PANELS_CHOICES))
        if unroll.samples * (unroll.rulings + 1) > MAX_UNROLL_GRID:
            raise ck.fail("unroll.samples", f"{unroll.samples} samples with unroll.rulings = {unroll.rulings} make a grid "
                          f"of {unroll.samples * (unroll.rulings + 1):,} points; allowed: samples * (rulings + 1) "
                          f"<= {MAX_UNROLL_GRID:,}")

    # sheet (spec 6.1)
    sheet = None
    st = ck.table(data, "sheet", "sheet")
    if st is not None:
        ck.keys(st, "sheet", ("thickness", "k_factor", "din_k_factor", "k_factor_table", "side", "side_reference"))
        if not surfaces:
            raise ck.fail("sheet", "needs a [surface] table or [[surfaces]] (the sheet is the surfaces' plate)")
        T = ck.number(st, "thickness", "sheet", required=True, lo=0.0, allowed="a length >= 0")
        given = [k for k in ("k_factor", "din_k_factor", "k_factor_table") if k in st]
        if len(given) > 1:
            raise ck.fail(f"sheet.{given[1]}", f"given together with sheet.{given[0]}; allowed: one of k_factor, "
                          "din_k_factor (DIN k = 2K), k_factor_table (K by R/T)")
        table = None
        if "din_k_factor" in st:
            K = ck.number(st, "din_k_factor", "sheet", lo=0.0, hi=2.0, required=True) / 2.0
        elif "k_factor_table" in st:
            table = _k_factor_table(ck, st["k_factor_table"], source)
            K = max(table.k_factors)  # until a built surface gives its R/T (the strictest neutral offset)
        else:
            K = ck.number(st, "k_factor", "sheet", 0.5, lo=0.0, hi=1.0)
        sheet = SheetSpec(T, K, ck.string(st, "side", "sheet", "normal", choices=("normal", "reverse")),
                          ck.string(st, "side_reference", "sheet", "shell", choices=SIDE_REFERENCES), k_factor_table=table)
    else:
        for spec in surfaces:
            if spec.sheet is not None:
                raise ck.fail(f"{spec.key}.sheet", "overrides the design's sheet but the design has no [sheet] table; "
                              "allowed: a [sheet] table (thickness, k_factor, side) with per-surface overrides")

    # outputs
    outputs = OutputSpec()
    ot2 = ck.table(data, "outputs", "outputs")
    if ot2 is not None:
        ck.keys(ot2, "outputs", ("files", "figures", "chord_tol"))
        outputs = OutputSpec(ck.string_list(ot2, "files", "outputs", list(FILE_OUTPUTS), choices=FILE_OUTPUTS),
                             ck.string_list(ot2, "figures", "outputs", list(FIGURE_OUTPUTS), choices=FIGURE_OUTPUTS))
        if "chord_tol" in ot2:
            outputs.chord_tol = ck.number(ot2, "chord_tol", "outputs", lo=0.0, lo_open=True,
                                          allowed=f"> 0 (a length in the design's units, {units}; default 1e-3 mm)")
    if not surfaces:
        for key, kinds in (("files", ("dxf", "svg")), ("figures", ("surface", "flat_pattern"))):
            explicit = ot2 is not None and key in ot2
            needs = [f for f in getattr(outputs, key) if f in kinds]
            if explicit and needs:
                allowed = [f for f in (FILE_OUTPUTS if key == "files" else FIGURE_OUTPUTS) if f not in kinds]
                raise ck.fail(f"outputs.{key}", f"{', '.join(needs)} need a [surface] table; allowed without one: {', '.join(allowed)}")
            setattr(outputs, key, [f for f in getattr(outputs, key) if f not in kinds])
        if not curves:
            raise ck.fail("surface", "missing; a design needs a [surface] table or at least one [[curves]] entry")
    explicit_figs = ot2 is not None and "figures" in ot2
    if optimize is None:
        if explicit_figs and "convergence" in outputs.figures:
            raise ck.fail("outputs.figures", "'convergence' needs an [optimize] table; allowed without one: "
                          + ", ".join(f for f in FIGURE_OUTPUTS if f != "convergence"))
        outputs.figures = [f for f in outputs.figures if f != "convergence"]
    if not approx:
        if explicit_figs and "deviation" in outputs.figures:
            raise ck.fail("outputs.figures", "'deviation' needs a surface of type \"approximate\"; allowed without one: "
                          + ", ".join(f for f in FIGURE_OUTPUTS if f != "deviation"))
        outputs.figures = [f for f in outputs.figures if f != "deviation"]
    if not curves:
        if explicit_figs and any(f in ("curve", "curvature") for f in outputs.figures):
            raise ck.fail("outputs.figures", "'curve' and 'curvature' need at least one [[curves]] entry; allowed without: "
                          + ", ".join(f for f in FIGURE_OUTPUTS if f not in ("curve", "curvature")))
        outputs.figures = [f for f in outputs.figures if f not in ("curve", "curvature")]
    if not outputs.files and not outputs.figures:
        raise ck.fail("outputs", "requests nothing; allowed files: " + ", ".join(FILE_OUTPUTS) + "; figures: " + ", ".join(FIGURE_OUTPUTS))
    return Design(name, units, curves, joins, surface, optimize, unroll, outputs, source, sheet=sheet, surfaces=surfaces)


def _objectives_for(surface_type: str) -> tuple[str, ...]:
    """Objectives allowed for a surface type: dual-curve fairness for planes and composites, R for
    curve-pair strips, the loft objectives for rails."""
    if surface_type == "rails":
        return RAILS_OBJECTIVES
    return STRIP_OBJECTIVES if surface_type == "curves" else PLANE_OBJECTIVES


def default_objective(surface_type: str) -> str:
    """The objective of ``[optimize]`` when none is given: R (curves), fan_share (rails), CVEn (else)."""
    return {"curves": "R", "rails": "fan_share"}.get(surface_type, "CVEn")


def _weight_names(surface_type: str) -> tuple[str, str, str]:
    """What ``optimize.weights`` weighs: (fan_share, fairness, regression) for rails, else (AL, En, CVEn)."""
    return ("fan_share", "fairness", "regression") if surface_type == "rails" else ("AL", "En", "CVEn")


def _parse_surfaces(ck: _Checker, data: dict, curves: list[CurveSpec]) -> list[SurfaceSpec]:
    """``[surface]`` (one surface) or ``[[surfaces]]`` (named surfaces of any type; names unique)."""
    if "surface" in data and "surfaces" in data:
        raise ck.fail("surfaces", "given together with [surface]; allowed: either one [surface] table or "
                      "a [[surfaces]] array of tables")
    st = ck.table(data, "surface", "surface")
    if st is not None:
        return [_parse_surface(ck, st, "surface", curves)]
    if "surfaces" not in data:
        return []
    raw = data["surfaces"]
    if not isinstance(raw, list) or not raw or not all(isinstance(x, dict) for x in raw):
        raise ck.fail("surfaces", f"expected a non-empty array of tables [[surfaces]], got {_tname(raw)} {_short(raw)}")
    out: list[SurfaceSpec] = []
    for i, t in enumerate(raw):
        path = f"surfaces[{i}]"
        name = ck.string(t, "name", path, f"surface{i + 1}")
        if any(s.name == name for s in out):
            raise ck.fail(f"{path}.name", f"{name!r} is used twice; allowed: a name unique among [[surfaces]]")
        over = t.get("sheet")
        spec = _parse_surface(ck, t, path, curves)
        spec.name, spec.key = name, path
        if over is not None:
            spec.sheet = _parse_sheet_override(ck, over, f"{path}.sheet")
        out.append(spec)
    return out


#: what ``[sheet] k_factor_table`` allows (the messages)
K_TABLE_ALLOWED = ("'ansi', 'din', a file of 'R/T K' lines (relative to the design file; a first line 'din' for "
                   "DIN k = 2K) or an inline array of [R/T, K] rows (R/T from 0 ascending, K in [0, 1])")


def _k_factor_table(ck: _Checker, value: Any, source: str) -> Any:
    """``[sheet] k_factor_table`` (:func:`ght_cad.blank.k_factor_table` semantics: a built-in table by
    name, a file of ``R/T K`` lines, or inline ``[[R/T, K], ...]`` rows of ANSI K)."""
    from ..blank import K_TABLES, BlankError, k_factor_rows, k_factor_table

    key = "sheet.k_factor_table"
    try:
        if isinstance(value, str):
            if value.strip().lower() in K_TABLES:
                return K_TABLES[value.strip().lower()]
            path = Path(value).expanduser()
            if not path.is_absolute() and not source.startswith("<"):
                path = Path(source).parent / path
            if not path.is_file():
                raise ck.fail(key, f"{value!r} is neither a built-in table nor a file ({path} not found); allowed: "
                              + K_TABLE_ALLOWED)
            return k_factor_table(path)
        if isinstance(value, list):
            return k_factor_rows(value, name="inline", where="inline table", source=f"{source} [sheet] k_factor_table")
    except BlankError as exc:
        raise ck.fail(key, f"{' '.join(str(exc).split())}; allowed: {K_TABLE_ALLOWED}") from None
    raise ck.fail(key, f"expected a string or an array, got {_tname(value)} {_short(value)}; allowed: {K_TABLE_ALLOWED}")


#: keys of a ``[surfaces.sheet]`` table (overrides of the design's ``[sheet]`` for one surface)
SURFACE_SHEET_KEYS = ("thickness", "k_factor", "din_k_factor", "side")


def _parse_sheet_override(ck: _Checker, st: Any, path: str) -> dict[str, Any]:
    """``[surfaces.sheet]`` at ``path``: ``thickness``, ``k_factor`` (or ``din_k_factor``), ``side``."""
    if not isinstance(st, dict):
        raise ck.fail(path, f"expected a table [{path.rsplit('[', 1)[0]}.sheet] of {', '.join(SURFACE_SHEET_KEYS)}, "
                      f"got {_tname(st)} {_short(st)}")
    ck.keys(st, path, SURFACE_SHEET_KEYS)
    out: dict[str, Any] = {}
    if "thickness" in st:
        out["thickness"] = ck.number(st, "thickness", path, required=True, lo=0.0, allowed="a length >= 0")
    if "k_factor" in st and "din_k_factor" in st:
        raise ck.fail(f"{path}.din_k_factor", f"given together with {path}.k_factor; allowed: one of them (DIN k = 2K)")
    if "din_k_factor" in st:
        out["k_factor"] = ck.number(st, "din_k_factor", path, lo=0.0, hi=2.0, required=True) / 2.0
    elif "k_factor" in st:
        out["k_factor"] = ck.number(st, "k_factor", path, required=True, lo=0.0, hi=1.0)
    if "side" in st:
        out["side"] = ck.string(st, "side", path, required=True, choices=("normal", "reverse"))
    return out


def _parse_surface(ck: _Checker, st: dict, path: str, curves: list[CurveSpec]) -> SurfaceSpec:
    """One surface table (``[surface]`` or an entry of ``[[surfaces]]`` at ``path``)."""
    stype = ck.string(st, "type", path, "planes", choices=SURFACE_TYPES)
    extra = ("name", "sheet") if path != "surface" else ()
    if stype != "composite" and "segments" in st:
        raise ck.fail(f"{path}.segments", f"strips need type = \"composite\" (this surface has type = \"{stype}\"); "
                      f"allowed: [[{path}.segments]] only with type = \"composite\"")
    if stype == "planes":
        ck.keys(st, path, ("type", "planes", "boundary_planes", "mu", "nu", "gamma", "normalize") + extra)
        planes = ck.matrix(st, "planes", path, cols=(4,), min_rows=3)
        bplanes = ck.matrix(st, "boundary_planes", path, cols=(4,), min_rows=2, max_rows=2)
        for key, rows in (("planes", planes), ("boundary_planes", bplanes)):
            for i, r in enumerate(rows or []):
                if math.hypot(*r[1:]) < 1e-12:
                    raise ck.fail(f"{path}.{key}[{i}]", f"{r} has a zero normal (u1, u2, u3); allowed: a plane u0 + u1 x + u2 y + u3 z = 0 with a non-zero normal")
        shape = {k: ck.number(st, k, path, 0.0, lo=-1.0, hi=1.0) for k in SHAPE_NAMES}
        normalize = ck.boolean(st, "normalize", path, False)
        return SurfaceSpec("planes", planes, bplanes, **shape, normalize=normalize)  # type: ignore[arg-type]
    if stype == "composite":
        return _parse_composite(ck, st, path, extra)
    if stype == "approximate":
        return _parse_approximate(ck, st, path, extra)
    rails = stype == "rails"
    ck.keys(st, path, ("type", "curve_a", "curve_b") + (("orientation",) if rails else ()) + extra)
    names = sorted(c.name for c in curves)
    if not names:
        raise ck.fail(f"{path}.curve_a", f"a '{stype}' surface needs two 3-D [[curves]]; none are defined")
    ca = ck.string(st, "curve_a", path, required=True, choices=names)
    cb = ck.string(st, "curve_b", path, required=True, choices=names)
    for key, cn in (("curve_a", ca), ("curve_b", cb)):
        spec = next(c for c in curves if c.name == cn)
        if len(spec.control_points[0]) != 3:
            raise ck.fail(f"{path}.{key}", f"curve {cn!r} is 2-D; allowed: a 3-D curve")
    if ca == cb:
        raise ck.fail(f"{path}.curve_b", f"{cb!r} equals curve_a; allowed: another 3-D curve")
    orientation = ck.string(st, "orientation", path, "auto", choices=RAIL_ORIENTATIONS) if rails else "auto"
    return SurfaceSpec(stype, curve_a=ca, curve_b=cb, orientation=orientation)


_APPROX_KEYS = ("type", "target", "tol", "max_panels", "direction")
#: the keys of ``[surfaces.target]`` by kind of target (the kind is told by its first key)
TARGET_KEYS = {
    "step": ("step", "face"),
    "ght": ("control_points", "mu_u", "nu_u", "gamma_u", "mu_v", "nu_v", "gamma_v"),
    "nurbs": ("poles", "weights", "knots_u", "knots_v", "degree_u", "degree_v"),
}
_TARGET_FIRST = {"step": "step", "ght": "control_points", "nurbs": "poles"}


def _parse_approximate(ck: _Checker, st: dict, path: str, extra: tuple[str, ...] = ()) -> SurfaceSpec:
    """``type = "approximate"`` at ``path``: ``tol`` (> 0), ``max_panels`` (1..256), ``direction``
    (auto|u|v) and the ``[<path>.target]`` table (:func:`_parse_target`)."""
    ck.keys(st, path, _APPROX_KEYS + extra)
    tol = ck.number(st, "tol", path, required=True, lo=0.0, lo_open=True,
                    allowed="a length > 0 (largest deviation both ways, in the design's unit)")
    max_panels = ck.integer(st, "max_panels", path, 64, lo=1, hi=MAX_APPROX_PANELS)
    direction = ck.string(st, "direction", path, "auto", choices=APPROX_DIRECTIONS)
    target = _parse_target(ck, st, f"{path}.target")
    return SurfaceSpec("approximate", target=target, tol=tol, max_panels=max_panels, direction=direction)


def _parse_target(ck: _Checker, st: dict, tpath: str) -> TargetSpec:
    """``[<surface>.target]``: ``step`` + ``face``, or a GHT patch (``control_points``), or a NURBS
    patch (``poles``); exactly one of the three."""
    forms = "step = \"FILE.step\" (+ face = N), control_points = [[[x, y, z], ...], ...] (a GHT patch) or " \
            "poles = [[[x, y, z], ...], ...] with knots_u, knots_v, degree_u, degree_v (a NURBS patch)"
    t = st.get("target")
    if t is None:
        raise ck.fail(tpath, f"missing; required: a table [{tpath.rsplit('[', 1)[0]}.target] with {forms}")
    if not isinstance(t, dict):
        raise ck.fail(tpath, f"expected a table with {forms}; got {_tname(t)} {_short(t)}")
    kinds = [k for k, first in _TARGET_FIRST.items() if first in t]
    if len(kinds) != 1:
        what = "none of step, control_points, poles" if not kinds else " and ".join(_TARGET_FIRST[k] for k in kinds)
        raise ck.fail(tpath, f"gives {what}; allowed: exactly one of {forms}")
    kind = kinds[0]
    ck.keys(t, tpath, TARGET_KEYS[kind])
    if kind == "step":
        step = ck.string(t, "step", tpath, required=True)
        if Path(step).suffix.lower() not in (".step", ".stp"):
            raise ck.fail(f"{tpath}.step", f"{step!r} is not allowed; allowed: a STEP file (.step/.stp), "
                          "its path relative to the design file")
        return TargetSpec("step", step=step, face=ck.integer(t, "face", tpath, 1, lo=1, hi=1_000_000))
    if kind == "ght":
        net = _net(ck, t, "control_points", tpath, 3, MAX_TARGET_DEGREE + 1)
        shape = {k: ck.number(t, k, tpath, 0.0, lo=-1.0, hi=1.0) for k in TARGET_KEYS["ght"][1:]}
        return TargetSpec("ght", control_points=net, shape=shape)
    pu = ck.integer(t, "degree_u", tpath, 3, lo=1, hi=MAX_TARGET_DEGREE)
    pv = ck.integer(t, "degree_v", tpath, 3, lo=1, hi=MAX_TARGET_DEGREE)
    net = _net(ck, t, "poles", tpath, 2, MAX_ROWS)
    nu, nv = len(net), len(net[0])
    knots = []
    for key, p, n in (("knots_u", pu, nu), ("knots_v", pv, nv)):
        full = f"{tpath}.{key}"
        v = ck.required(t, key, tpath, f"an array of {n + p + 1} non-decreasing numbers")
        if not isinstance(v, list) or not all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                              and math.isfinite(x) for x in v):
            raise ck.fail(full, f"expected an array of {n + p + 1} finite non-decreasing numbers, got {_tname(v)} {_short(v)}")
        k = [float(x) for x in v]
        if len(k) != n + p + 1 or any(b < a for a, b in zip(k, k[1:])) or not k[-p - 1] > k[p]:
            raise ck.fail(full, f"{_short(k)} is not allowed; allowed: {n + p + 1} non-decreasing numbers ({n} poles "
                          f"+ degree {p} + 1) with {key}[{p}] < {key}[{n}]")
        knots.append(k)
    weights = None
    if "weights" in t:
        weights = ck.matrix(t, "weights", tpath, cols=(nv,), min_rows=nu, max_rows=nu)
        for i, row in enumerate(weights or []):
            for j, w in enumerate(row):
                if not w > 0:
                    raise ck.fail(f"{tpath}.weights[{i}][{j}]", f"{w:g} is not allowed; allowed: a weight > 0")
    return TargetSpec("nurbs", control_points=net, knots_u=knots[0], knots_v=knots[1], degree_u=pu, degree_v=pv,
                      weights=weights)


def _net(ck: _Checker, t: dict, key: str, tpath: str, least: int, most: int) -> list[list[list[float]]]:
    """A net of points ``t[key]``: at least ``least`` and at most ``most`` rows of as many
    ``[x, y, z]`` points each (the same count in every row)."""
    full = f"{tpath}.{key}"
    what = f"an array of {least}..{most} rows, each an array of {least}..{most} points [x, y, z] (the same count in every row)"
    v = ck.required(t, key, tpath, what)
    if not isinstance(v, list) or not all(isinstance(r, list) for r in v):
        raise ck.fail(full, f"expected {what}, got {_tname(v)} {_short(v)}")
    if not least <= len(v) <= most:
        raise ck.fail(full, f"has {len(v)} rows; allowed: {what}")
    net = []
    for i, row in enumerate(v):
        rows = ck.matrix({f"{key}[{i}]": row}, f"{key}[{i}]", tpath, cols=(3,), min_rows=least, max_rows=None)
        assert rows is not None
        if len(rows) > most or (net and len(rows) != len(net[0])):
            raise ck.fail(f"{full}[{i}]", f"has {len(rows)} points; allowed: {what}")
        net.append(rows)
    return net


def _composite_parameters(ck: _Checker, ot: dict, surface: SurfaceSpec) -> list[str]:
    """``optimize.parameters`` of a composite: ``"<segment name>.mu|nu|gamma"`` (default: all).

    Raises:
        DesignError: not an array of strings, an unknown segment or shape name, or an empty list.
    """
    segs = [g.name for g in surface.segments or []]
    key = "optimize.parameters"
    form = f"'<segment>.mu', '<segment>.nu' or '<segment>.gamma' with <segment> one of {', '.join(segs)}"
    if "parameters" not in ot:
        return list(_shape_names(surface))
    v = ot["parameters"]
    if not isinstance(v, list) or not all(isinstance(x, str) for x in v):
        raise ck.fail(key, f"expected an array of strings {form}; got {_tname(v)} {_short(v)}")
    out: list[str] = []
    for x in v:
        seg, dot, name = x.rpartition(".")
        if not dot or seg not in segs:
            what = f"unknown segment {seg!r} in {x!r}" if dot else f"{x!r} names no segment"
            raise ck.fail(key, f"{what}; allowed: {form}")
        match = [k for k in SHAPE_NAMES if k == name.lower()]
        if not match:
            raise ck.fail(key, f"unknown shape parameter {name!r} in {x!r}; allowed: {form}")
        full = f"{seg}.{match[0]}"
        if full not in out:
            out.append(full)
    if not out:
        raise ck.fail(key, f"is empty; allowed: a non-empty array of {form}")
    return out


_SEGMENT_KEYS = ("name", "planes", "mu", "nu", "gamma", "continuity", "k", "beta2", "beta3")


def _parse_composite(ck: _Checker, st: dict, path: str = "surface", extra: tuple[str, ...] = ()) -> SurfaceSpec:
    """``type = "composite"`` at ``path``: shared boundary planes and ``[[<path>.segments]]``."""
    ck.keys(st, path, ("type", "boundary_planes", "normalize", "segments") + extra)
    bplanes = ck.matrix(st, "boundary_planes", path, cols=(4,), min_rows=2, max_rows=2)
    for i, r in enumerate(bplanes or []):
        if math.hypot(*r[1:]) < 1e-12:
            raise ck.fail(f"{path}.boundary_planes[{i}]", f"{r} has a zero normal (u1, u2, u3); allowed: a plane "
                          "u0 + u1 x + u2 y + u3 z = 0 with a non-zero normal")
    normalize = ck.boolean(st, "normalize", path, False)
    raw = ck.required(st, "segments", path, f"an array of at least 2 tables [[{path}.segments]]")
    if not isinstance(raw, list) or not all(isinstance(x, dict) for x in raw):
        raise ck.fail(f"{path}.segments", f"expected an array of tables [[{path}.segments]], got {_tname(raw)} {_short(raw)}")
    if len(raw) < 2:
        raise ck.fail(f"{path}.segments", f"has {len(raw)} strip(s); allowed: at least 2 (one strip: use type = \"planes\")")
    segs: list[SegmentSpec] = []
    names: set[str] = set()
    prev: dict[str, float] = {k: 0.0 for k in SHAPE_NAMES}
    for i, t in enumerate(raw):
        spath = f"{path}.segments[{i}]"
        ck.keys(t, spath, _SEGMENT_KEYS)
        name = ck.string(t, "name", spath, f"strip{i + 1}")
        if name in names:
            raise ck.fail(f"{spath}.name", f"{name!r} is used twice; allowed: a name unique among the strips")
        names.add(name)
        if i == 0:
            for key in ("continuity", "k", "beta2", "beta3"):
                if key in t:
                    raise ck.fail(f"{spath}.{key}", "the first strip has no joint before it; allowed: "
                                  "continuity, k, beta2, beta3 on segments[1] and later")
            cont, k, b2, b3 = None, 1.0, 0.0, 0.0
        else:
            cont = ck.string(t, "continuity", spath, "G1", choices=STRIP_JOINS)
            k = ck.number(t, "k", spath, 1.0, lo=0.0, lo_open=True)
            b2 = ck.number(t, "beta2", spath, 0.0)
            b3 = ck.number(t, "beta3", spath, 0.0)
        order = int(cont[1]) if cont else 0
        planes = ck.matrix(t, "planes", spath, cols=(4,), min_rows=max(3, order + 1))
        for j, r in enumerate(planes or []):
            if math.hypot(*r[1:]) < 1e-12:
                raise ck.fail(f"{spath}.planes[{j}]", f"{r} has a zero normal (u1, u2, u3); allowed: a plane with a non-zero normal")
        # shape parameters default to the previous strip's (as join_developable does)
        shape = {key: ck.number(t, key, spath, prev[key], lo=-1.0, hi=1.0) for key in SHAPE_NAMES}
        prev = shape
        segs.append(SegmentSpec(name, planes, shape["mu"], shape["nu"], shape["gamma"], cont, k, b2, b3))  # type: ignore[arg-type]
    return SurfaceSpec("composite", boundary_planes=bplanes, normalize=normalize, segments=segs)


def parse_design_text(text: str, source: str = "<design>") -> Design:
    """Parse TOML text and validate it (see :func:`parse_design`)."""
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise DesignError(f"{source}: not valid TOML: {' '.join(str(exc).split())}") from None
    return parse_design(data, source)


def load_design(path: str | os.PathLike) -> Design:
    """Read and validate a design file.

    Raises:
        DesignError: unreadable file, invalid TOML or an invalid design (one-line message).
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DesignError(f"{p}: no such design file") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise DesignError(f"{p}: cannot read the design file: {exc}") from None
    return parse_design_text(text, str(p))


def _shape_names(spec: SurfaceSpec) -> tuple[str, ...]:
    if spec.type == "planes":
        return SHAPE_NAMES
    if spec.type == "composite":
        return tuple(f"{g.name}.{k}" for g in spec.segments or [] for k in SHAPE_NAMES)
    return tuple(f"{s}.{k}" for s in ("a", "b") for k in SHAPE_NAMES)
