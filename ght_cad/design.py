r"""Design files (TOML): schema, validation and the pipeline runner behind ``ght-cad run``/``demo``.

A design file describes GHT-Bézier curves (control points and shape parameters, optional joins),
one surface (an enveloping developable from control planes, spec 5.2, a ruled strip between two
curves, or a composite of developable strips joined G1/G2/G3, spec 5.6), an optional
shape-parameter optimization (of one strip, or of every strip of a composite with its joints kept) and the
outputs to write. The schema is
documented in ``docs/design-files.md``; :func:`parse_design` validates a parsed file completely
before anything is computed, and every error is one line naming the file, the key and the
allowed values, raised as :class:`DesignError` (a :class:`~ght_cad.errors.GHTError`, so
``ght-cad`` exits with code 2).

:func:`run_design` computes everything into a temporary folder beside the output folder and moves
the files in only when every step succeeded, so a failure leaves the output folder untouched.

:func:`unroll_step` unrolls the developable faces of a STEP file made by any CAD tool (one panel
per face), for ``ght-cad unroll FILE.step``.

Imports numpy at module level only; scipy, matplotlib and the CAD kernel are imported inside the
functions that need them.
"""

from __future__ import annotations

import functools
import math
import os
import shutil
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

import numpy as np

from .errors import GHTError

__all__ = [
    "DesignError",
    "Design",
    "CurveSpec",
    "JoinSpec",
    "SegmentSpec",
    "SurfaceSpec",
    "OptimizeSpec",
    "UnrollSpec",
    "OutputSpec",
    "FILE_OUTPUTS",
    "FIGURE_OUTPUTS",
    "load_design",
    "parse_design",
    "parse_design_text",
    "build_curves",
    "build_surface",
    "BuiltSurface",
    "brep_shape",
    "shared_edge_count",
    "surface_view",
    "unroll_step",
    "StepUnroll",
    "MM_PER_UNIT",
    "surface_summary",
    "optimize_design",
    "unroll_surface",
    "pattern_errors",
    "export_step",
    "export_files",
    "plot_pattern",
    "run_design",
    "dual_curve_objectives",
    "composite_dual_objectives",
    "composite_objective",
]

#: file outputs a design may request
FILE_OUTPUTS = ("step", "dxf", "svg", "json", "md")
#: figures a design may request (PNG)
FIGURE_OUTPUTS = ("basis", "curve", "curvature", "surface", "flat_pattern", "convergence")
#: optimizers
METHODS = ("pso", "gwo", "igwo")
#: objectives: fairness of the dual curve (planes) or developability R (curve-pair strips)
PLANE_OBJECTIVES = ("AL", "En", "CVEn", "weighted")
STRIP_OBJECTIVES = ("R",)
SURFACE_TYPES = ("planes", "curves", "composite")
#: joins between the strips of a composite surface (spec 5.6)
STRIP_JOINS = ("G1", "G2", "G3")
CONTINUITIES = ("C0", "C1", "C2", "C3", "G0", "G1", "G2", "G3")
UNITS = ("mm", "cm", "m", "in", "ft")
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


class DesignError(GHTError):
    """An invalid design file: one line naming the file, the key and the allowed values."""


# ---------------------------------------------------------------------------------------------
# schema
# ---------------------------------------------------------------------------------------------
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
    """The design's surface: ``type = "planes"`` (spec 5.2), ``"curves"`` (ruled strip) or
    ``"composite"`` (several strips from control planes joined G1/G2/G3, spec 5.6)."""

    type: str
    planes: list[list[float]] | None = None
    boundary_planes: list[list[float]] | None = None
    mu: float = 0.0
    nu: float = 0.0
    gamma: float = 0.0
    curve_a: str | None = None
    curve_b: str | None = None
    normalize: bool = True
    segments: list[SegmentSpec] | None = None


@dataclass
class OptimizeSpec:
    """Shape-parameter optimization (spec sections 7, 8)."""

    method: str = "igwo"
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


@dataclass
class OutputSpec:
    """Which files and figures to write."""

    files: list[str] = field(default_factory=lambda: list(FILE_OUTPUTS))
    figures: list[str] = field(default_factory=lambda: list(FIGURE_OUTPUTS))


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

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (as it would be written in TOML)."""
        from dataclasses import asdict

        d = asdict(self)
        d.pop("source")
        return d


# ---------------------------------------------------------------------------------------------
# validation
# ---------------------------------------------------------------------------------------------
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


_TOP_KEYS = ("name", "units", "curves", "joins", "surface", "optimize", "unroll", "outputs")


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

    # surface
    surface = None
    st = ck.table(data, "surface", "surface")
    if st is not None:
        stype = ck.string(st, "type", "surface", "planes", choices=SURFACE_TYPES)
        if stype != "composite" and "segments" in st:
            raise ck.fail("surface.segments", f"strips need type = \"composite\" (this surface has type = \"{stype}\"); "
                          "allowed: [[surface.segments]] only with type = \"composite\"")
        if stype == "planes":
            ck.keys(st, "surface", ("type", "planes", "boundary_planes", "mu", "nu", "gamma", "normalize"))
            planes = ck.matrix(st, "planes", "surface", cols=(4,), min_rows=3)
            bplanes = ck.matrix(st, "boundary_planes", "surface", cols=(4,), min_rows=2, max_rows=2)
            for key, rows in (("planes", planes), ("boundary_planes", bplanes)):
                for i, r in enumerate(rows or []):
                    if math.hypot(*r[1:]) < 1e-12:
                        raise ck.fail(f"surface.{key}[{i}]", f"{r} has a zero normal (u1, u2, u3); allowed: a plane u0 + u1 x + u2 y + u3 z = 0 with a non-zero normal")
            shape = {k: ck.number(st, k, "surface", 0.0, lo=-1.0, hi=1.0) for k in SHAPE_NAMES}
            normalize = ck.boolean(st, "normalize", "surface", True)
            surface = SurfaceSpec("planes", planes, bplanes, **shape, normalize=normalize)  # type: ignore[arg-type]
        elif stype == "composite":
            surface = _parse_composite(ck, st)
        else:
            ck.keys(st, "surface", ("type", "curve_a", "curve_b"))
            names = sorted(seen)
            if not names:
                raise ck.fail("surface.curve_a", "a 'curves' surface needs two 3-D [[curves]]; none are defined")
            ca = ck.string(st, "curve_a", "surface", required=True, choices=names)
            cb = ck.string(st, "curve_b", "surface", required=True, choices=names)
            for key, cn in (("curve_a", ca), ("curve_b", cb)):
                spec = next(c for c in curves if c.name == cn)
                if len(spec.control_points[0]) != 3:
                    raise ck.fail(f"surface.{key}", f"curve {cn!r} is 2-D; allowed: a 3-D curve")
            if ca == cb:
                raise ck.fail("surface.curve_b", f"{cb!r} equals curve_a; allowed: another 3-D curve")
            surface = SurfaceSpec("curves", curve_a=ca, curve_b=cb)

    # optimize
    optimize = None
    ot = ck.table(data, "optimize", "optimize")
    if ot is not None:
        if surface is None:
            raise ck.fail("optimize", "needs a [surface] table to optimize")
        ck.keys(ot, "optimize", ("method", "objective", "weights", "parameters", "population", "iterations", "seed"))
        method = ck.string(ot, "method", "optimize", "igwo", choices=METHODS)
        objs = _objectives_for(surface.type)
        objective = ck.string(ot, "objective", "optimize", objs[0] if surface.type == "curves" else "CVEn", choices=objs)
        weights = [1.0, 0.0, 0.0]
        if "weights" in ot:
            w = ot["weights"]
            if (not isinstance(w, list) or len(w) != 3
                    or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and x >= 0
                               for x in w)
                    or not any(x > 0 for x in w)):
                raise ck.fail("optimize.weights", f"{_short(w)} is not allowed; allowed: three numbers >= 0 (weights of AL, En, CVEn), not all 0")
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
        ck.keys(ut, "unroll", ("rulings", "tol_deg"))
        unroll = UnrollSpec(ck.integer(ut, "rulings", "unroll", 16, lo=0, hi=1000),
                            ck.number(ut, "tol_deg", "unroll", 0.01, lo=0.0, hi=90.0, lo_open=True))

    # outputs
    outputs = OutputSpec()
    ot2 = ck.table(data, "outputs", "outputs")
    if ot2 is not None:
        ck.keys(ot2, "outputs", ("files", "figures"))
        outputs = OutputSpec(ck.string_list(ot2, "files", "outputs", list(FILE_OUTPUTS), choices=FILE_OUTPUTS),
                             ck.string_list(ot2, "figures", "outputs", list(FIGURE_OUTPUTS), choices=FIGURE_OUTPUTS))
    if surface is None:
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
    if not curves:
        if explicit_figs and any(f in ("curve", "curvature") for f in outputs.figures):
            raise ck.fail("outputs.figures", "'curve' and 'curvature' need at least one [[curves]] entry; allowed without: "
                          + ", ".join(f for f in FIGURE_OUTPUTS if f not in ("curve", "curvature")))
        outputs.figures = [f for f in outputs.figures if f not in ("curve", "curvature")]
    if not outputs.files and not outputs.figures:
        raise ck.fail("outputs", "requests nothing; allowed files: " + ", ".join(FILE_OUTPUTS) + "; figures: " + ", ".join(FIGURE_OUTPUTS))
    return Design(name, units, curves, joins, surface, optimize, unroll, outputs, source)


def _objectives_for(surface_type: str) -> tuple[str, ...]:
    """Objectives allowed for a surface type: dual-curve fairness for planes and composites, R for
    curve-pair strips."""
    return STRIP_OBJECTIVES if surface_type == "curves" else PLANE_OBJECTIVES


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


def _parse_composite(ck: _Checker, st: dict) -> SurfaceSpec:
    """``[surface] type = "composite"``: shared boundary planes and ``[[surface.segments]]``."""
    ck.keys(st, "surface", ("type", "boundary_planes", "normalize", "segments"))
    bplanes = ck.matrix(st, "boundary_planes", "surface", cols=(4,), min_rows=2, max_rows=2)
    for i, r in enumerate(bplanes or []):
        if math.hypot(*r[1:]) < 1e-12:
            raise ck.fail(f"surface.boundary_planes[{i}]", f"{r} has a zero normal (u1, u2, u3); allowed: a plane "
                          "u0 + u1 x + u2 y + u3 z = 0 with a non-zero normal")
    normalize = ck.boolean(st, "normalize", "surface", True)
    raw = ck.required(st, "segments", "surface", "an array of at least 2 tables [[surface.segments]]")
    if not isinstance(raw, list) or not all(isinstance(x, dict) for x in raw):
        raise ck.fail("surface.segments", f"expected an array of tables [[surface.segments]], got {_tname(raw)} {_short(raw)}")
    if len(raw) < 2:
        raise ck.fail("surface.segments", f"has {len(raw)} strip(s); allowed: at least 2 (one strip: use type = \"planes\")")
    segs: list[SegmentSpec] = []
    names: set[str] = set()
    prev: dict[str, float] = {k: 0.0 for k in SHAPE_NAMES}
    for i, t in enumerate(raw):
        path = f"surface.segments[{i}]"
        ck.keys(t, path, _SEGMENT_KEYS)
        name = ck.string(t, "name", path, f"strip{i + 1}")
        if name in names:
            raise ck.fail(f"{path}.name", f"{name!r} is used twice; allowed: a name unique among the strips")
        names.add(name)
        if i == 0:
            for key in ("continuity", "k", "beta2", "beta3"):
                if key in t:
                    raise ck.fail(f"{path}.{key}", "the first strip has no joint before it; allowed: "
                                  "continuity, k, beta2, beta3 on segments[1] and later")
            cont, k, b2, b3 = None, 1.0, 0.0, 0.0
        else:
            cont = ck.string(t, "continuity", path, "G1", choices=STRIP_JOINS)
            k = ck.number(t, "k", path, 1.0, lo=0.0, lo_open=True)
            b2 = ck.number(t, "beta2", path, 0.0)
            b3 = ck.number(t, "beta3", path, 0.0)
        order = int(cont[1]) if cont else 0
        planes = ck.matrix(t, "planes", path, cols=(4,), min_rows=max(3, order + 1))
        for j, r in enumerate(planes or []):
            if math.hypot(*r[1:]) < 1e-12:
                raise ck.fail(f"{path}.planes[{j}]", f"{r} has a zero normal (u1, u2, u3); allowed: a plane with a non-zero normal")
        # shape parameters default to the previous strip's (as join_developable does)
        shape = {key: ck.number(t, key, path, prev[key], lo=-1.0, hi=1.0) for key in SHAPE_NAMES}
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


# ---------------------------------------------------------------------------------------------
# building
# ---------------------------------------------------------------------------------------------
GHT_DEFINITION = (
    "GHT seed (this project's definition, spec section 1): f0 = (1-w)(1-s)(1-mu s) + w(1-t)^2, "
    "f2 = (1-w)(1-c)(1-nu c) + w t^2, f1 = 1 - f0 - f2, s = sin(pi t/2), c = cos(pi t/2), "
    "w = (1+gamma)/2; degree m: b_i,m = B_i,m-2 f0 + B_i-1,m-2 f1 + B_i-2,m-2 f2"
)


def build_curves(design: Design, shape: dict[str, float] | None = None) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """GHT curves of the design with its joins applied, and a measured report per join.

    Joins are applied in file order: ``second`` gets its first ``r+1`` control points re-solved
    (:func:`ght_cad.continuity.join`) so that the joint ``first(1) → second(0)`` has the requested
    continuity; :func:`ght_cad.continuity.measure_continuity` then measures it independently.

    Args:
        design: a validated design.
        shape: for a ``curves`` surface, strip shape parameters ``{"a.mu", ..., "b.gamma"}`` (any
            subset) that replace the file's ``mu, nu, gamma`` of ``curve_a`` / ``curve_b``
            *before* the joins, so that joined curves follow them (as after an optimization).

    Returns:
        ``({name: GHTCurve}, [join report dicts])``.
    """
    return _joined_curves(design, shape, measure=True)


def _joined_curves(design: Design, shape: dict[str, float] | None, *, measure: bool) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """:func:`build_curves`; ``measure=False`` skips the join reports (optimizer candidates)."""
    from .curve import GHTCurve

    side_of: dict[str, str] = {}
    if shape and design.surface is not None and design.surface.type == "curves":
        side_of = {str(design.surface.curve_a): "a", str(design.surface.curve_b): "b"}
    curves: dict[str, Any] = {}
    for c in design.curves:
        sh = {"mu": c.mu, "nu": c.nu, "gamma": c.gamma}
        if c.name in side_of:
            sh.update({k: float(shape[f"{side_of[c.name]}.{k}"]) for k in SHAPE_NAMES  # type: ignore[index]
                       if f"{side_of[c.name]}.{k}" in shape})  # type: ignore[operator]
        curves[c.name] = GHTCurve(c.control_points, sh["mu"], sh["nu"], sh["gamma"])
    reports = []
    for i, j in enumerate(design.joins):
        from .continuity import join, measure_continuity

        a, b = curves[j.first], curves[j.second]
        if a.dim != b.dim:
            raise DesignError(
                f"{design.source}: key 'joins': curves {j.first!r} (dim {a.dim}) and {j.second!r} (dim {b.dim}) "
                "have different dimensions; allowed: curves of the same dimension"
            )
        geometric = j.continuity.startswith("G")
        kw = {"k": j.k, "beta2": j.beta2, "beta3": j.beta3} if geometric else {}
        try:
            curves[j.second] = join(a, j.continuity, b, **kw)
        except DesignError:
            raise
        except GHTError as exc:
            raise type(exc)(f"{design.source}: key 'joins[{i}]': {' '.join(str(exc).split())}") from None
        if not measure:
            continue
        rep = measure_continuity(a, curves[j.second])
        reports.append(
            {
                "first": j.first,
                "second": j.second,
                "requested": j.continuity,
                "achieved_C": int(rep.c_order),
                "achieved_G": int(rep.g_order),
                "satisfied": bool(rep.satisfies(j.continuity)),
                "c_residuals": [float(x) for x in rep.c_residuals],
                "g_residuals": [float(x) for x in rep.g_residuals],
                "tol": float(rep.tol),
            }
        )
    return curves, reports


@dataclass
class BuiltSurface:
    """A design's surface with the shape parameters it was built with."""

    design: Design
    surface: Any
    curves: dict[str, Any]
    shape: dict[str, float]


def _shape_names(spec: SurfaceSpec) -> tuple[str, ...]:
    if spec.type == "planes":
        return SHAPE_NAMES
    if spec.type == "composite":
        return tuple(f"{g.name}.{k}" for g in spec.segments or [] for k in SHAPE_NAMES)
    return tuple(f"{s}.{k}" for s in ("a", "b") for k in SHAPE_NAMES)


def _initial_shape(design: Design, curves: dict[str, Any]) -> dict[str, float]:
    spec = design.surface
    assert spec is not None
    if spec.type == "planes":
        return {"mu": spec.mu, "nu": spec.nu, "gamma": spec.gamma}
    if spec.type == "composite":
        return {f"{g.name}.{k}": float(getattr(g, k)) for g in spec.segments or [] for k in SHAPE_NAMES}
    out = {}
    for side, cname in (("a", spec.curve_a), ("b", spec.curve_b)):
        c = curves[cname]
        out.update({f"{side}.mu": c.mu, f"{side}.nu": c.nu, f"{side}.gamma": c.gamma})
    return out


def _make_surface(design: Design, curves: dict[str, Any], shape: dict[str, float]) -> Any:
    spec = design.surface
    assert spec is not None
    if spec.type == "planes":
        from .developable import developable_from_planes

        return developable_from_planes(
            spec.planes, spec.boundary_planes, shape["mu"], shape["nu"], shape["gamma"], normalize=spec.normalize
        )
    if spec.type == "composite":
        return _make_composite(design, shape)
    from .ruled import CurvePairRuledSurface

    ca = curves[spec.curve_a].with_shape(shape["a.mu"], shape["a.nu"], shape["a.gamma"])
    cb = curves[spec.curve_b].with_shape(shape["b.mu"], shape["b.nu"], shape["b.gamma"])
    return CurvePairRuledSurface(ca, cb)


def _make_composite(design: Design, shape: dict[str, float]) -> Any:
    r"""Strips of a ``composite`` surface: strip 0 from its planes, strip i joined to strip i-1.

    Join (spec 5.6): the 4-D dual curves meet with ``V(0) = U(1)`` and G1 ``V' = k U'``,
    G2 ``V'' = k² U'' + β2 U'``, G3 ``V''' = k³ U''' + 3kβ2 U'' + β3 U'``
    (:func:`ght_cad.developable.join_developable`); all strips share the boundary planes, so
    consecutive strips share their joint ruling segment.

    Raises:
        GHTError: a join that cannot be solved or a degenerate strip, naming the segment.
    """
    from .developable import CompositeDevelopable, developable_from_planes, join_developable
    from .planes import normalize_planes

    spec = design.surface
    assert spec is not None and spec.segments
    segs: list[Any] = []
    for i, g in enumerate(spec.segments):
        P = np.asarray(g.planes, dtype=float)
        if spec.normalize:
            P = normalize_planes(P)
        sh = {k: shape[f"{g.name}.{k}"] for k in SHAPE_NAMES}
        try:
            if i == 0:
                segs.append(developable_from_planes(P, spec.boundary_planes, sh["mu"], sh["nu"], sh["gamma"]))
            else:
                segs.append(join_developable(segs[-1], g.continuity or "G1", P, mu=sh["mu"], nu=sh["nu"],
                                             gamma=sh["gamma"], k=g.k, beta2=g.beta2, beta3=g.beta3))
        except GHTError as exc:
            raise type(exc)(f"{design.source}: key 'surface.segments[{i}]' ({g.name}): {' '.join(str(exc).split())}") from None
    try:
        comp = CompositeDevelopable(segs)
    except GHTError as exc:
        raise type(exc)(f"{design.source}: key 'surface.segments': {' '.join(str(exc).split())}") from None
    return comp


def _is_composite(surface: Any) -> bool:
    return hasattr(surface, "segments") and hasattr(surface, "joints")


def _developability_dict(surface: Any) -> dict[str, float]:
    """Developability degree of a surface; for a composite the worst strip per quantity
    (θ_max and residual max, θ_rms as the root mean square over strips, DD min, R summed)."""
    if not _is_composite(surface):
        return surface.developability().as_dict()
    ds = [d.as_dict() for d in surface.developability()]
    return {
        "theta_max": max(d["theta_max"] for d in ds),
        "theta_rms": float(math.sqrt(sum(d["theta_rms"] ** 2 for d in ds) / len(ds))),
        "dd": min(d["dd"] for d in ds),
        "R": float(sum(d["R"] for d in ds)),
        "residual_max": max(d["residual_max"] for d in ds),
    }


class _CompositeView:
    """A composite surface seen as one ruled strip for plots: ``grid`` and ``theta`` by strip."""

    def __init__(self, composite: Any) -> None:
        self.segments = list(composite.segments)

    def _split(self, n: int) -> list[int]:
        k = len(self.segments)
        return [max(2, n // k + (1 if i < n % k else 0)) for i in range(k)]

    def grid(self, nu: int, nv: int) -> np.ndarray:
        return np.concatenate([s.grid(m, nv) for s, m in zip(self.segments, self._split(int(nu)))], axis=0)

    def theta(self, u: Any) -> np.ndarray:
        n = int(np.size(u))
        return np.concatenate([np.asarray(s.theta(np.linspace(0.0, 1.0, m)), dtype=float)
                               for s, m in zip(self.segments, self._split(n))])


def surface_view(built: "BuiltSurface") -> Any:
    """What :func:`ght_cad.plotting.plot_surface` draws: the surface, or all strips of a composite."""
    return _CompositeView(built.surface) if _is_composite(built.surface) else built.surface


def build_surface(design: Design, shape: dict[str, float] | None = None,
                  curves: dict[str, Any] | None = None) -> BuiltSurface:
    """Build the design's surface with its own (or the given) shape parameters.

    Raises:
        DesignError: the design has no [surface] table.
        GHTError: degenerate geometry (parallel planes, edge of regression inside the strip, ...).
    """
    if design.surface is None:
        raise DesignError(f"{design.source}: key 'surface': missing; this command needs a [surface] table")
    if curves is None:
        curves, _ = build_curves(design)
    sh = dict(_initial_shape(design, curves))
    if shape:
        sh.update(shape)
    try:
        surf = _make_surface(design, curves, sh)
    except DesignError:
        raise
    except GHTError as exc:
        msg = " ".join(str(exc).split())
        if msg.startswith(f"{design.source}: key 'surface"):  # already names the file and key (a strip)
            raise
        raise type(exc)(f"{design.source}: key 'surface': {msg}") from None
    return BuiltSurface(design, surf, curves, sh)


def ruled_area(surface: Any, nodes: int = 64) -> float:
    r"""Area ``∫_0^1 ∫_0^1 |X_u × X_v| dv du`` of a ruled surface (Gauss–Legendre, both directions)."""
    from .curve import gauss_legendre

    t, w = gauss_legendre(nodes)
    v, wv = gauss_legendre(16)
    U = np.repeat(t, v.size)
    V = np.tile(v, t.size)
    xu, xv = surface.partials(U, V)
    dens = np.linalg.norm(np.cross(xu, xv), axis=1)
    return float(np.sum(dens * np.repeat(w, v.size) * np.tile(wv, t.size)))


def surface_summary(built: BuiltSurface) -> dict[str, Any]:
    """Developability degree (θ_max, θ_rms, DD, R), area and shape parameters of a built surface.

    A composite surface also gets ``surface.strips`` (per strip: name, shape parameters, area,
    ruling lengths, developability) and ``surface.joints`` (per joint: requested continuity, the
    order measured by :func:`ght_cad.developable.measure_developable_joint`, its residuals, the
    angle between the end tangent planes and the ruling distance); ``developability`` is then the
    worst strip's (see ``_developability_dict``).
    """
    s = built.surface
    if _is_composite(s):
        return _composite_summary(built)
    dev = s.developability()
    out: dict[str, Any] = {
        "surface": {
            "type": built.design.surface.type if built.design.surface else None,
            "shape_parameters": dict(built.shape),
            "area_3d": ruled_area(s),
            "ruling_length_min": float(np.min(s.ruling_lengths(np.linspace(0, 1, 257)))),
            "ruling_length_max": float(np.max(s.ruling_lengths(np.linspace(0, 1, 257)))),
        },
        "developability": dev.as_dict(),
    }
    spec = built.design.surface
    if spec is not None and spec.type == "planes":
        out["surface"]["control_planes"] = np.asarray(s.planes).tolist()
        out["surface"]["boundary_planes"] = np.asarray(s.boundary_planes).tolist()
        out["surface"]["normalized"] = bool(spec.normalize)
        out["surface"]["edge_of_regression"] = "outside the strip (checked on construction)"
    return out


def _composite_summary(built: BuiltSurface) -> dict[str, Any]:
    from .unroll import ruled_area as exact_area

    comp = built.surface
    spec = built.design.surface
    assert spec is not None and spec.segments
    u = np.linspace(0, 1, 257)
    strips = []
    for g, seg, dev in zip(spec.segments, comp.segments, comp.developability()):
        L = seg.ruling_lengths(u)
        strips.append({
            "name": g.name,
            "shape_parameters": {k: float(built.shape.get(f"{g.name}.{k}", getattr(g, k))) for k in SHAPE_NAMES},
            "control_planes": np.asarray(seg.planes).tolist(),
            "dual_curve_fairness": dual_curve_objectives(seg.dual_curve),
            "area_3d": exact_area(seg),
            "ruling_length_min": float(np.min(L)),
            "ruling_length_max": float(np.max(L)),
            "developability": dev.as_dict(),
        })
    joints = []
    for i, (g, rep) in enumerate(zip(spec.segments[1:], comp.joints())):
        joints.append({
            "first": spec.segments[i].name,
            "second": g.name,
            "requested": g.continuity,
            "k": g.k,
            "beta2": g.beta2,
            "beta3": g.beta3,
            "achieved_G": int(rep.order),
            "satisfied": bool(rep.satisfies(g.continuity or "G1")),
            "residuals": [float(r) for r in rep.residuals],
            "plane_angle_deg": float(rep.plane_angle),
            "ruling_distance": float(rep.ruling_distance),
            "tol": float(rep.tol),
        })
    return {
        "surface": {
            "type": "composite",
            "shape_parameters": dict(built.shape),
            "area_3d": float(sum(x["area_3d"] for x in strips)),
            "ruling_length_min": min(x["ruling_length_min"] for x in strips),
            "ruling_length_max": max(x["ruling_length_max"] for x in strips),
            "boundary_planes": np.asarray(comp.segments[0].boundary_planes).tolist(),
            "normalized": bool(spec.normalize),
            "strips": strips,
            "joints": joints,
        },
        "developability": _developability_dict(comp),
    }


# ---------------------------------------------------------------------------------------------
# optimization
# ---------------------------------------------------------------------------------------------
@functools.lru_cache(maxsize=8)
def _gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Cached Gauss–Legendre nodes/weights on [0, 1] (numpy's leggauss costs an eigensolve)."""
    from .curve import gauss_legendre

    t, w = gauss_legendre(n)
    t.setflags(write=False)
    w.setflags(write=False)
    return t, w


def dual_curve_objectives(curve: Any, nodes: int = 64) -> dict[str, float]:
    r"""Fairness of a curve (spec section 7) by ``nodes``-point Gauss–Legendre quadrature.

    ``AL = ∫|X'|``, ``En = ∫|X''|²``, ``CVEn = ∫|X'''|²`` with analytic derivatives.
    """
    t, w = _gauss_legendre(nodes)
    d1 = curve.derivative(t, 1)
    d2 = curve.derivative(t, 2)
    d3 = curve.derivative(t, 3)
    return {
        "AL": float(np.sum(w * np.linalg.norm(d1, axis=1))),
        "En": float(np.sum(w * np.sum(d2 * d2, axis=1))),
        "CVEn": float(np.sum(w * np.sum(d3 * d3, axis=1))),
    }


@dataclass
class OptimizationOutcome:
    """Result of :func:`optimize_design`."""

    method: str
    objective: str
    parameters: list[str]
    x: np.ndarray
    best_value: float
    initial_value: float
    history: np.ndarray
    nfev: int
    nit: int
    time: float
    shape: dict[str, float]
    weights: list[float]
    #: composite only: per strip ``name``, ``initial``/``best`` measures (AL, En, CVEn, value)
    strips: list[dict[str, Any]] | None = None
    #: composite only: per joint ``first``, ``second``, ``requested``, ``achieved_G`` (after), ``satisfied``
    joints: list[dict[str, Any]] | None = None

    def summary(self) -> dict[str, Any]:
        """Plain-data form for the report (``optimization`` block); composites add ``strips``
        (before/after per strip) and ``joints`` (requested vs measured order after optimization)."""
        extra: dict[str, Any] = {}
        if self.strips is not None:
            extra["strips"] = [dict(x) for x in self.strips]
        if self.joints is not None:
            extra["joints"] = [dict(x) for x in self.joints]
        return {**{
            "method": self.method,
            "objective": self.objective,
            "weights": list(self.weights) if self.objective == "weighted" else None,
            "parameters": list(self.parameters),
            "best_parameters": {k: float(v) for k, v in zip(self.parameters, self.x)},
            "best_value": float(self.best_value),
            "initial_value": float(self.initial_value),
            "nfev": int(self.nfev),
            "iterations": int(self.nit),
            "time_s": float(self.time),
            "history": [float(h) for h in self.history],
        }, **extra}


def _fairness_value(vals: dict[str, float], objective: str, weights: Sequence[float]) -> float:
    """``AL``, ``En``, ``CVEn`` or ``weighted`` = ``w0 AL + w1 En + w2 CVEn`` from the three measures."""
    if objective == "weighted":
        return float(weights[0] * vals["AL"] + weights[1] * vals["En"] + weights[2] * vals["CVEn"])
    return float(vals[objective])


def composite_dual_objectives(composite: Any, objective: str = "CVEn", weights: Sequence[float] = (1.0, 0.0, 0.0),
                              nodes: int = 64) -> tuple[float, list[dict[str, float]]]:
    r"""Fairness of a composite developable: the sum over strips of its dual curve's measure.

    For strip ``s`` with dual curve ``U_s`` *as built* (strip 0 from its planes, strip i > 0 with
    its first ``r+1`` control planes re-solved by the join; no rescaling afterwards, the plane
    scale being a weight of the surface), ``AL_s = ∫_0^1 |U_s'|``, ``En_s = ∫_0^1 |U_s''|²``,
    ``CVEn_s = ∫_0^1 |U_s'''|²`` (:func:`dual_curve_objectives`: ``nodes``-point Gauss–Legendre,
    analytic derivatives) and ``F = Σ_s f(AL_s, En_s, CVEn_s)`` with ``f`` the chosen measure or
    ``w0 AL + w1 En + w2 CVEn``.

    Args:
        composite: a :class:`ght_cad.developable.CompositeDevelopable` of enveloping developables.
        objective: ``AL``, ``En``, ``CVEn`` or ``weighted``.
        weights: ``(w0, w1, w2)`` for ``weighted``.
        nodes: Gauss–Legendre nodes per strip.

    Returns:
        ``(F, per_strip)`` with ``per_strip[s] = {"AL", "En", "CVEn", "value"}``.

    Raises:
        GHTError: an objective that is not one of AL, En, CVEn, weighted.
    """
    if objective not in PLANE_OBJECTIVES:
        raise GHTError(f"objective={objective!r} is not allowed for a composite; allowed: {', '.join(PLANE_OBJECTIVES)}")
    per = []
    for seg in composite.segments:
        vals = dual_curve_objectives(seg.dual_curve, nodes)
        vals["value"] = _fairness_value(vals, objective, weights)
        per.append(vals)
    return float(sum(v["value"] for v in per)), per


def _composite_joint_rows(design: Design, composite: Any) -> list[dict[str, Any]]:
    """Requested vs measured order (:func:`ght_cad.developable.measure_developable_joint`) per joint."""
    segs = design.surface.segments if design.surface is not None else None
    assert segs
    rows = []
    for i, (g, rep) in enumerate(zip(segs[1:], composite.joints())):
        req = g.continuity or "G1"
        rows.append({"first": segs[i].name, "second": g.name, "requested": req, "achieved_G": int(rep.order),
                     "satisfied": bool(rep.satisfies(req))})
    return rows


def _composite_candidate(design: Design, shape: dict[str, float]) -> Any:
    """The composite of ``shape`` (:func:`_make_composite`, every strip checked on construction),
    refused unless every joint measures at least its requested order.

    Raises:
        GHTError: a singular join, a degenerate strip, or a joint below its requested order.
    """
    from .errors import SingularJoinError

    comp = _make_composite(design, shape)
    for row in _composite_joint_rows(design, comp):
        if not row["satisfied"]:
            raise SingularJoinError(f"joint {row['first']} -> {row['second']} measures G{row['achieved_G']}, "
                                    f"requested {row['requested']}")
    return comp


def composite_objective(design: Design, shape: dict[str, float], objective: str = "CVEn",
                        weights: Sequence[float] = (1.0, 0.0, 0.0)) -> float:
    r"""Objective of one candidate of a composite design: ``F`` of :func:`composite_dual_objectives`.

    The strips are built exactly as for the geometry (strip 0 from its planes, strip i > 0 joined
    G1/G2/G3 to strip i-1, every strip checked on construction) and every joint is measured
    (:func:`ght_cad.developable.measure_developable_joint`).

    Args:
        design: a validated design with a ``composite`` surface.
        shape: ``{"<segment>.mu|nu|gamma": value}``; missing names keep the file's values.
        objective: ``AL``, ``En``, ``CVEn`` or ``weighted``.
        weights: ``(w0, w1, w2)`` for ``weighted``.

    Returns:
        ``F``, or ``+inf`` for a candidate whose join is singular, whose strip degenerates (parallel
        planes, stationary dual curve, edge of regression inside, ...) or whose joint measures
        below its requested order.

    Raises:
        DesignError: the design's surface is not a composite.
    """
    if design.surface is None or design.surface.type != "composite":
        raise DesignError(f"{design.source}: key 'surface.type': composite_objective needs type = \"composite\"")
    sh = dict(_initial_shape(design, {}))
    sh.update(shape)
    try:
        with np.errstate(all="ignore"):
            value = composite_dual_objectives(_composite_candidate(design, sh), objective, weights)[0]
    except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
        return math.inf
    return value if math.isfinite(value) else math.inf


def _objective_fn(design: Design, curves: dict[str, Any], spec: OptimizeSpec) -> Callable[[dict[str, float]], float]:
    surf = design.surface
    assert surf is not None
    if surf.type == "composite":
        def fc(sh: dict[str, float]) -> float:
            return composite_objective(design, sh, spec.objective, spec.weights)

        return fc
    if surf.type == "planes":
        from .curve import GHTCurve
        from .planes import normalize_planes

        U = normalize_planes(np.asarray(surf.planes, dtype=float))
        w = np.asarray(spec.weights, dtype=float)

        def f(sh: dict[str, float]) -> float:
            # the surface is built (and checked) first: a candidate whose strip degenerates (stationary
            # dual curve at a box corner, edge of regression inside, ...) raises and gets +inf in F
            _make_surface(design, curves, sh)
            vals = dual_curve_objectives(GHTCurve(U, sh["mu"], sh["nu"], sh["gamma"]))
            if spec.objective == "weighted":
                return float(w[0] * vals["AL"] + w[1] * vals["En"] + w[2] * vals["CVEn"])
            return vals[spec.objective]

        return f
    from .ruled import developability_from_jets

    t, wq = _gauss_legendre(64)

    rejoin = bool({str(surf.curve_a), str(surf.curve_b)} & {j.second for j in design.joins})

    def g(sh: dict[str, float]) -> float:
        # a boundary curve that is a join's 'second' is re-solved for the candidate's shape
        # parameters (as build_curves(design, shape) does for the result)
        cv = _joined_curves(design, sh, measure=False)[0] if rejoin else curves
        s = _make_surface(design, cv, sh)
        return developability_from_jets(s.a(t), s.a(t, 1), s.b(t), s.b(t, 1), wq)[3]  # (θ_max, θ_rms, DD, R)

    return g


def optimize_design(design: Design, overrides: dict[str, Any] | None = None, *, progress: bool = True,
                    curves: dict[str, Any] | None = None) -> OptimizationOutcome:
    r"""Minimize the design's objective over its shape parameters (box ``[-1, 1]^k``).

    Objectives: for a ``planes`` surface the fairness of the dual curve of unit-normal control
    planes (``AL = ∫|U'|``, ``En = ∫|U''|²``, ``CVEn = ∫|U'''|²`` or ``w·(AL, En, CVEn)``); for a
    ``composite`` the sum over strips of the same measure of each strip's dual curve as built
    (after the joins, :func:`composite_dual_objectives`), every joint keeping its requested
    G1/G2/G3 order; for a ``curves`` strip the developability objective
    ``R = ∫(1 - n_a·n_b) du`` (spec 5, 7). Optimizers: PSO, GWO, I-GWO of
    :mod:`ght_cad.optimize` (spec 8). The start values (those of the file) are in the first
    population and the result is never worse than them; candidates whose surface degenerates
    (singular join, edge of regression inside a strip, ...) get ``+inf``.

    Args:
        design: validated design with a [surface] table.
        overrides: replaces ``method``, ``objective``, ``iterations``, ``population``, ``seed``.
        progress: progress bar on a terminal.
        curves: already built curves (joins applied).

    Returns:
        :class:`OptimizationOutcome` (for a composite with ``strips``: the measures of every strip
        before and after, and ``joints``: requested vs measured order after optimization).

    Raises:
        DesignError: no [surface], or an override that is not allowed.
        GHTError: no admissible shape parameters found.
    """
    from .optimize import minimize
    from .progress import Progress

    if design.surface is None:
        raise DesignError(f"{design.source}: key 'surface': missing; optimization needs a [surface] table")
    stype = design.surface.type
    spec = design.optimize or OptimizeSpec(
        objective="R" if stype == "curves" else "CVEn",
        parameters=list(_shape_names(design.surface)),
    )
    spec = OptimizeSpec(**{**spec.__dict__})
    for k, v in (overrides or {}).items():
        setattr(spec, k, v)
    # validate overrides with the same rules as the file
    ck = _Checker(design.source + " (command-line override)")
    objs = _objectives_for(stype)
    spec.method = ck.string({"method": spec.method}, "method", "optimize", choices=METHODS)
    spec.objective = ck.string({"objective": spec.objective}, "objective", "optimize", choices=objs)
    spec.iterations = ck.integer({"iterations": spec.iterations}, "iterations", "optimize", 40, lo=1, hi=5000)
    spec.population = ck.integer({"population": spec.population}, "population", "optimize", 20, lo=4, hi=500)
    spec.seed = ck.integer({"seed": spec.seed}, "seed", "optimize", 1, lo=0, hi=2**32 - 1)
    if stype == "composite":
        spec.parameters = _composite_parameters(ck, {"parameters": list(spec.parameters)}, design.surface)
    if curves is None:
        curves, _ = build_curves(design)
    base = _initial_shape(design, curves)
    f = _objective_fn(design, curves, spec)
    names = list(spec.parameters)

    def shape_of(x: np.ndarray) -> dict[str, float]:
        sh = dict(base)
        sh.update({k: float(np.clip(v, -1.0, 1.0)) for k, v in zip(names, x)})
        return sh

    def F(X: np.ndarray) -> np.ndarray:
        # one candidate at a time: each builds (and checks) its own strips and joins
        out = np.empty(X.shape[0])
        for i, x in enumerate(X):
            try:
                with np.errstate(all="ignore"):
                    out[i] = f(shape_of(x))
            except (GHTError, np.linalg.LinAlgError, ZeroDivisionError, FloatingPointError):
                out[i] = np.inf  # a degenerate candidate (singular join, edge of regression, ...) is rejected
            if not np.isfinite(out[i]):
                out[i] = np.inf
        return out

    x0 = np.array([base[k] for k in names])
    initial = float(F(x0[None, :])[0])
    bounds = (-np.ones(len(names)), np.ones(len(names)))
    with Progress(spec.iterations, f"optimizing ({spec.method}, {spec.objective})",
                  enabled=None if progress else False) as bar:
        res = minimize(F, bounds, method=spec.method, pop_size=spec.population, max_iter=spec.iterations,
                       seed=spec.seed, callback=bar.callback, x0=x0)
    if not np.isfinite(res.fun):
        raise GHTError(f"{design.source}: optimization found no admissible shape parameters")
    x = np.clip(np.asarray(res.x, dtype=float), -1.0, 1.0)
    best = float(res.fun)
    if initial <= best:  # never report something worse than the start
        x, best = x0, initial
    out = OptimizationOutcome(spec.method, spec.objective, names, x, best, initial, np.asarray(res.history),
                              int(res.nfev), int(res.nit), float(res.time), shape_of(x), list(spec.weights))
    if stype == "composite":
        out.strips, out.joints = _composite_before_after(design, spec, base, out.shape)
    return out


def _composite_before_after(design: Design, spec: OptimizeSpec, before: dict[str, float],
                            after: dict[str, float]) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Per strip the measures before/after optimization; per joint requested vs measured order after."""
    segs = design.surface.segments if design.surface is not None else None
    assert segs
    try:
        _, per0 = composite_dual_objectives(_make_composite(design, before), spec.objective, spec.weights)
    except GHTError:
        per0 = [None] * len(segs)
    comp = _make_composite(design, after)
    _, per1 = composite_dual_objectives(comp, spec.objective, spec.weights)
    strips = []
    for g, a, b in zip(segs, per0, per1):
        strips.append({
            "name": g.name,
            "initial_parameters": {k: float(before[f"{g.name}.{k}"]) for k in SHAPE_NAMES},
            "best_parameters": {k: float(after[f"{g.name}.{k}"]) for k in SHAPE_NAMES},
            "initial_value": None if a is None else a["value"],
            "best_value": b["value"],
            "initial_measures": None if a is None else {k: a[k] for k in ("AL", "En", "CVEn")},
            "best_measures": {k: b[k] for k in ("AL", "En", "CVEn")},
        })
    return strips, _composite_joint_rows(design, comp)


# ---------------------------------------------------------------------------------------------
# B-rep, flat pattern, exports
# ---------------------------------------------------------------------------------------------
def _ruled_face(surface: Any, tol: float) -> Any:
    """B-spline face of degree (p, 1) through the paired boundary curves ``a(u)``, ``b(u)``.

    ``a`` and ``b`` are fitted together as one 6-D function (one knot vector, pole i of each at
    the same parameter), so the face is ``(1-v) A(u) + v B(u)`` with ``|A - a|, |B - b| <= tol``.
    """
    from .bspline import BSplineSurfaceData, fit_function
    from .cad.occ import make_face

    fit = fit_function(lambda t: np.hstack([surface.a(t), surface.b(t)]), tol=tol, degree=5)
    poles = np.stack([fit.poles[:, :3], fit.poles[:, 3:]], axis=1)
    data = BSplineSurfaceData(poles, fit.knots, np.array([0.0, 0.0, 1.0, 1.0]), fit.degree, 1,
                              max_deviation=fit.max_deviation)
    return make_face(data)


def brep_face(built: BuiltSurface, tol: float | None = None) -> Any:
    """A build123d face of the built surface (``surface.to_face()`` when it has one)."""
    s = built.surface
    if tol is None:
        g = s.grid(17, 3).reshape(-1, 3)
        tol = 1e-7 * float(np.linalg.norm(g.max(axis=0) - g.min(axis=0)))
    if hasattr(s, "to_face"):
        try:
            return s.to_face(tol=tol)
        except ImportError:
            pass
    return _ruled_face(s, tol)


def brep_shape(built: BuiltSurface, tol: float | None = None) -> Any:
    """The B-rep of the built surface: one face (:func:`brep_face`), or for a composite one shell
    of one B-spline face per strip sewn along the joint rulings
    (:func:`ght_cad.cad.developable_faces.composite_shell`)."""
    if _is_composite(built.surface):
        from .cad.developable_faces import composite_shell

        return composite_shell(built.surface, tol=tol)
    return brep_face(built, tol)


def shared_edge_count(shape: Any) -> int:
    """Number of edges of a B-rep shared by two or more of its faces (``TopExp`` edge→face map)."""
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape

    from .cad.occ import unwrap

    m = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(unwrap(shape), TopAbs_EDGE, TopAbs_FACE, m)
    return sum(1 for i in range(1, m.Extent() + 1) if m.FindFromIndex(i).Size() >= 2)


def curve_edges(curves: dict[str, Any]) -> list[Any]:
    """Certified B-spline edges (``curve_to_bspline``) of the 2-D/3-D curves."""
    from .bspline import curve_to_bspline
    from .cad.occ import make_edge

    return [make_edge(curve_to_bspline(c)) for c in curves.values() if c.dim in (2, 3)]


def export_step(built: BuiltSurface, path: str | os.PathLike, *, with_curves: bool = True) -> Path:
    """Write the surface face (and the design's curves as edges) to one STEP file, atomically."""
    from .cad.occ import write_step

    shapes = [brep_shape(built)]
    if with_curves:
        shapes += curve_edges(built.curves)
    write_step(shapes, path, units=built.design.units)
    return Path(path)


def unroll_surface(built: BuiltSurface) -> Any:
    """Flat pattern of the built surface (:func:`ght_cad.unroll`).

    A ``curves`` strip is flattened with ``best_effort=True`` (it is only quasi-developable); its
    distortion is then in the pattern's errors.
    """
    from .unroll import unroll

    d = built.design
    if _is_composite(built.surface):
        from .unroll import unroll_composite

        return unroll_composite(built.surface.segments, tol_deg=d.unroll.tol_deg, rulings=d.unroll.rulings,
                                units=d.units, labels=[g.name for g in d.surface.segments or []])
    best_effort = d.surface is not None and d.surface.type == "curves"
    return unroll(built.surface, best_effort=best_effort, tol_deg=d.unroll.tol_deg, rulings=d.unroll.rulings,
                  units=d.units, label=d.name[:24])


def pattern_report(pattern: Any) -> dict[str, Any]:
    """The ``flat_pattern`` entry of a report: area, errors, distortion report, outline and bend-line
    counts, bounding box, per-panel areas and the edge-mark labels (``E<n>``, panel labels excluded)."""
    import re

    panel_labels = {pn.label for pn in pattern.panels}
    return {
        "area": float(pattern.area),
        "errors": pattern_errors(pattern),
        "report": pattern.report.as_dict(),
        "outline_points": int(sum(len(o) for o in pattern.outlines)),
        "bend_lines": int(len(pattern.bend_lines)),
        "bbox": [np.min(np.concatenate(pattern.outlines), axis=0).tolist(),
                 np.max(np.concatenate(pattern.outlines), axis=0).tolist()],
        "panels": [{"label": pn.label, "area_flat": float(pn.area_flat), "area_3d": float(pn.area_3d),
                    "max_error": float(pn.report.max_relative_error) if pn.report is not None else None}
                   for pn in pattern.panels],
        "edge_marks": sorted({t[2] for t in pattern.labels
                              if t[2] not in panel_labels and re.fullmatch(r"E\d+", t[2])}, key=lambda m: int(m[1:])),
    }


def pattern_errors(pattern: Any) -> dict[str, float]:
    """Max relative length/area errors of a flat pattern (``FlatPattern.errors``) as floats."""
    return {k: float(v) for k, v in pattern.errors.items()}


def plot_pattern(pattern: Any, path: str | os.PathLike, title: str | None = None) -> Path:
    """Fixed-size PNG (900 x 700) of a flat pattern: outlines and bend lines."""
    from .plotting import plot_flat_pattern

    e = pattern.errors
    t = (title + ": " if title else "") + f"flat pattern, max rel. error {e['max']:.1e}"
    return plot_flat_pattern(pattern.outlines, path, rulings=list(pattern.bend_lines), title=t,
                             labels=list(pattern.labels), marks=list(pattern.marks))


def export_files(design: Design, files: Iterable[str | os.PathLike]) -> dict[str, str]:
    """Build the design with its given shape parameters and write each file by its suffix.

    ``.step``/``.stp``: face + curves; ``.dxf``/``.svg``: flat pattern; ``.json``: name, units,
    surface summary, curves and (with a surface) the ``flat_pattern`` entry of :func:`pattern_report`;
    ``.png``: rendered surface (or the curves when the design has no surface).

    All or nothing: every file is first written into a temporary folder beside its target
    (which also proves the target's folder is writable) and the files are moved into place only
    when every one was written; a failure leaves every target as it was (existing files
    untouched, no new file).

    Args:
        design: a validated design (:func:`load_design`).
        files: output paths; the suffix selects the content.

    Raises:
        DesignError: a suffix that is not allowed, a surface output without [surface], or a
            target whose folder cannot be written (the message names the target).

    Returns:
        ``{kind: path}`` for each written file (``kind`` = suffix without dot, ``_<n>`` appended
        for repeats).
    """
    files = [Path(f) for f in files]
    allowed = (".step", ".stp", ".dxf", ".svg", ".json", ".png")
    for f in files:
        if f.suffix.lower() not in allowed:
            raise DesignError(f"{f}: unknown output suffix {f.suffix!r}; allowed: {', '.join(allowed)}")
    curves, _ = build_curves(design)
    built = build_surface(design, curves=curves) if design.surface is not None else None
    if built is None:
        for f in files:
            if f.suffix.lower() in (".dxf", ".svg"):
                raise DesignError(f"{design.source}: key 'surface': missing; {f} needs a [surface] table")
    stage = _FileStage(files)
    try:
        out: dict[str, str] = {}
        pattern = None
        for f in files:
            pattern = _export_one(design, curves, built, f, stage.path(f), pattern)
            suf = f.suffix.lower().lstrip(".")
            out[suf + (f"_{len(out)}" if suf in out else "")] = str(f)
        stage.commit()
    finally:
        stage.cleanup()
    return out


def _export_one(design: Design, curves: dict[str, Any], built: BuiltSurface | None, target: Path,
                tmp: Path, pattern: Any) -> Any:
    """Write the content for ``target`` (chosen by its suffix) into ``tmp``; returns the flat pattern."""
    import json

    from .io import write_text_atomic

    suf = target.suffix.lower()
    if suf in (".step", ".stp"):
        if built is not None:
            export_step(built, tmp)
        else:
            from .cad.occ import write_step

            write_step(curve_edges(curves), tmp, units=design.units)
    elif suf in (".dxf", ".svg"):
        pattern = pattern or unroll_surface(built)
        (pattern.export_dxf if suf == ".dxf" else pattern.export_svg)(tmp)
    elif suf == ".json":
        summ = {"name": design.name, "units": design.units}
        summ.update(surface_summary(built) if built is not None else {})
        summ["curves"] = {k: c.to_dict() for k, c in curves.items()}
        if built is not None:
            pattern = pattern or unroll_surface(built)
            summ["flat_pattern"] = pattern_report(pattern)
        write_text_atomic(tmp, json.dumps(_jsonable(summ), indent=2) + "\n")
    else:
        from .plotting import plot_curve, plot_surface

        if built is not None:
            plot_surface(surface_view(built), tmp, title=design.name)
        else:
            plot_curve(list(curves.values()), tmp)
    return pattern


class _FileStage:
    """One temporary folder beside each target's folder; :meth:`commit` moves all files into place.

    Creating the temporary folders up front checks that every target folder is writable before
    anything is computed or written. Folders created for missing parents are removed again on
    failure.
    """

    def __init__(self, targets: Sequence[Path]) -> None:
        self.dirs: dict[Path, Path] = {}
        self.made: list[Path] = []
        self.map: dict[Path, Path] = {}
        try:
            for t in targets:
                parent = t.parent.absolute()
                if t.exists() and t.is_dir():
                    raise DesignError(f"cannot write {t}: it is a folder; allowed: a file path")
                if parent not in self.dirs:
                    self._mkdirs(parent, t)
                    try:
                        self.dirs[parent] = Path(tempfile.mkdtemp(prefix=".ght-cad-export.", dir=parent))
                    except OSError as exc:
                        raise DesignError(
                            f"cannot write {t}: folder {parent} is not writable ({exc.strerror or exc})"
                        ) from None
                # a numbered name keeps repeated or equal base names apart; the suffix is kept for writers
                self.map[t] = self.dirs[parent] / f"{len(self.map)}{t.suffix}"
        except BaseException:
            self.cleanup()
            raise

    def _mkdirs(self, parent: Path, target: Path) -> None:
        missing = []
        p = parent
        while not p.exists() and p != p.parent:
            missing.append(p)
            p = p.parent
        for d in reversed(missing):
            try:
                d.mkdir()
            except OSError as exc:
                raise DesignError(f"cannot write {target}: cannot create folder {d} ({exc.strerror or exc})") from None
            self.made.append(d)

    def path(self, target: Path) -> Path:
        return self.map[target]

    def commit(self) -> None:
        """Move every staged file onto its target (same file system: ``os.replace`` each)."""
        for t, tmp in self.map.items():
            if not tmp.is_file():
                raise GHTError(f"writing {t} produced no file")
        for t, tmp in self.map.items():
            os.replace(tmp, t)
        self.made = []  # the folders now hold results

    def cleanup(self) -> None:
        for d in self.dirs.values():
            shutil.rmtree(d, ignore_errors=True)
        for d in reversed(self.made):
            try:
                d.rmdir()
            except OSError:
                pass
        self.made = []


def _jsonable(o: Any) -> Any:
    if isinstance(o, dict):
        return {str(k): _jsonable(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_jsonable(v) for v in o]
    if isinstance(o, np.ndarray):
        return _jsonable(o.tolist())
    if isinstance(o, (np.floating, float)):
        x = float(o)
        return x if math.isfinite(x) else None
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (np.bool_,)):
        return bool(o)
    return o


# ---------------------------------------------------------------------------------------------
# the pipeline
# ---------------------------------------------------------------------------------------------
class _Stage:
    """A temporary folder beside ``out_dir``; :meth:`commit` moves its files into ``out_dir``."""

    def __init__(self, out_dir: Path) -> None:
        self.out = out_dir
        parent = out_dir.parent
        # folders created for out_dir's parent: removed again by cleanup() after a failed run
        self.made_parents = [d for d in (parent, *parent.parents) if not d.exists()][::-1]
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self.tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", suffix=".ght-cad-tmp", dir=parent))
        except OSError as exc:  # e.g. a part of the path is a regular file, or a read-only folder
            self._remove_made_parents()
            raise GHTError(
                f"cannot create the output folder {out_dir}: {exc.strerror or exc}"
                f"{f' ({exc.filename})' if exc.filename else ''}; allowed: a folder or a new path "
                "whose parent folders can be created"
            ) from None
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(self.tmp, 0o777 & ~umask)  # mkdtemp makes 0700; the result is an ordinary folder

    def path(self, name: str) -> Path:
        return self.tmp / name

    def commit(self) -> list[str]:
        names = sorted(p.name for p in self.tmp.iterdir() if p.is_file() and not p.name.endswith(".part"))
        if not self.out.exists():
            os.replace(self.tmp, self.out)  # one atomic rename: the folder appears complete
            return names
        if not self.out.is_dir():
            raise GHTError(f"{self.out} exists and is not a folder; allowed: a folder or a new path")
        for n in names:  # checked before the first move: a failure must not leave a mixed folder
            if (self.out / n).is_dir():
                raise GHTError(f"cannot write {self.out / n}: it is a folder; allowed: a file path "
                               "(remove or rename the folder)")
        for n in names:
            os.replace(self.tmp / n, self.out / n)
        shutil.rmtree(self.tmp, ignore_errors=True)
        return names

    def cleanup(self) -> None:
        """Remove the temporary folder and the parent folders created for it (after a failure)."""
        shutil.rmtree(self.tmp, ignore_errors=True)
        self._remove_made_parents()

    def _remove_made_parents(self) -> None:
        for d in reversed(self.made_parents):
            try:
                d.rmdir()  # only if still empty
            except OSError:
                pass


def _versions() -> dict[str, str]:
    import platform

    from . import __version__

    out = {"ght_cad": __version__, "python": platform.python_version(), "numpy": np.__version__}
    try:
        import scipy

        out["scipy"] = scipy.__version__
    except ImportError:  # pragma: no cover
        pass
    return out


def _curves_report(curves: dict[str, Any]) -> list[dict[str, Any]]:
    """Per curve: degree, dimension, shape parameters, control points, arc length, max curvature."""
    return [
        {
            "name": k,
            "degree": c.degree,
            "dim": c.dim,
            "mu": c.mu,
            "nu": c.nu,
            "gamma": c.gamma,
            "control_points": c.control_points.tolist(),
            "arc_length": c.arc_length(),
            "curvature_max": float(np.nanmax(c.curvature(np.linspace(0, 1, 513)))),
        }
        for k, c in curves.items()
    ]


def run_design(design: Design, out_dir: str | os.PathLike, *, progress: bool = True) -> dict[str, Any]:
    """Run the whole pipeline of a design and write its outputs into ``out_dir``.

    Steps: GHT curves (+ joins, measured) → surface (developable from control planes, or a ruled
    strip between two curves) → shape-parameter optimization (if ``[optimize]``) → developability
    degree → B-rep face → STEP (face + curve edges) → flat pattern (DXF, SVG) → PNG figures
    (basis, curve, curvature, surface, flat_pattern, convergence) → ``report.json`` and
    ``report.md``. File names: ``model.step``, ``flat_pattern.dxf``, ``flat_pattern.svg``,
    ``report.json``, ``report.md``, ``<figure>.png``.

    Everything is computed into a temporary folder beside ``out_dir``; only when every step has
    succeeded are the files moved in (a new ``out_dir`` appears by one rename). On any error the
    temporary folder is removed and ``out_dir`` is untouched.

    Args:
        design: a validated :class:`Design`.
        out_dir: output folder.
        progress: progress bar on stderr when it is a terminal.

    Returns:
        The report dictionary (the content of ``report.json``).

    Raises:
        GHTError: degenerate geometry, non-developable surface, ...; nothing is written.
    """
    import sys

    from .progress import progress_enabled

    t_start = time.perf_counter()
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise GHTError(f"{out} exists and is not a folder; allowed: a folder or a new path")
    want_files = set(design.outputs.files)
    want_figs = set(design.outputs.figures)
    steps = ["curves", "surface", "optimize", "measure", "B-rep + STEP", "flat pattern", "figures", "report"]
    show = bool(progress) and progress_enabled()
    report: dict[str, Any] = {
        "name": design.name,
        "source": design.source,
        "units": design.units,
        "ght_definition": GHT_DEFINITION,
        "design": design.to_dict(),
    }

    def step(name: str) -> None:
        if show:
            i = steps.index(name) + 1
            sys.stderr.write(f"[{i}/{len(steps)}] {design.name}: {name} ({time.perf_counter() - t_start:.1f} s)\n")
            sys.stderr.flush()

    stage = _Stage(out)
    try:
        # 1. curves
        step("curves")
        curves, joins = build_curves(design)
        report["curves"] = _curves_report(curves)
        report["joins"] = joins

        built = None
        opt = None
        if design.surface is not None:
            # 2. surface
            step("surface")
            try:
                built = build_surface(design, curves=curves)
                report["developability_initial"] = _developability_dict(built.surface)
            except GHTError as exc:
                if design.optimize is None:
                    raise
                # the file's values are one rejected candidate; the optimization may find admissible ones
                report["developability_initial"] = None
                report["initial_surface_error"] = " ".join(str(exc).split())
            # 3. optimization
            if design.optimize is not None:
                step("optimize")
                opt = optimize_design(design, progress=progress, curves=curves)
                if design.surface.type == "curves":
                    # the strip's boundary curves (and the curves joined to them) take the optimized
                    # shape parameters: STEP curve edges, figures and the report show those
                    curves, joins = build_curves(design, opt.shape)
                    report["curves"] = _curves_report(curves)
                    report["joins"] = joins
                built = build_surface(design, opt.shape, curves=curves)
                report["optimization"] = opt.summary()
            # 4. measures
            step("measure")
            report.update(surface_summary(built))
            # 5. B-rep
            step("B-rep + STEP")
            face = brep_shape(built)
            from .cad.occ import is_valid

            valid = is_valid(face)
            nfaces = len(face.faces()) if hasattr(face, "faces") else 1
            report["brep"] = {"valid": bool(valid), "area": float(face.area), "faces": nfaces}
            if _is_composite(built.surface):
                from .cad.developable_faces import joint_normal_deviation

                report["brep"]["shape"] = "shell"
                report["brep"]["shared_edges"] = shared_edge_count(face)
                report["brep"]["joint_normal_deviation_deg"] = [float(x) for x in joint_normal_deviation(face)]
            if not valid:
                raise GHTError(f"{design.source}: the B-rep of the surface is not valid (BRepCheck)")
            edges = curve_edges(curves)
            report["brep"]["curve_edges"] = len(edges)
            if "step" in want_files:
                from .cad.occ import write_step

                write_step([face] + edges, stage.path(FILE_NAMES["step"]), units=design.units)
            # 6. flat pattern
            step("flat pattern")
            pattern = unroll_surface(built)
            report["flat_pattern"] = pattern_report(pattern)
            if "dxf" in want_files:
                pattern.export_dxf(stage.path(FILE_NAMES["dxf"]))
            if "svg" in want_files:
                pattern.export_svg(stage.path(FILE_NAMES["svg"]))
        else:
            pattern = None
            if "step" in want_files and curves:
                from .cad.occ import write_step

                write_step(curve_edges(curves), stage.path(FILE_NAMES["step"]), units=design.units)

        # 7. figures
        step("figures")
        from . import plotting as P

        if "basis" in want_figs:
            if built is not None and design.surface is not None and design.surface.type == "composite":
                deg = max(sg.dual_curve.degree for sg in built.surface.segments)
                params = [(0.0, 0.0, -1.0), (0.0, 0.0, 1.0)] + [(g.mu, g.nu, g.gamma) for g in design.surface.segments or []]
                params += [tuple(built.shape[f"{g.name}.{k}"] for k in SHAPE_NAMES) for g in design.surface.segments or []]
            elif built is not None and design.surface is not None and design.surface.type == "planes":
                deg = built.surface.dual_curve.degree
                sh = built.shape
                params = [(0.0, 0.0, -1.0), (0.0, 0.0, 1.0), (design.surface.mu, design.surface.nu, design.surface.gamma),
                          (sh["mu"], sh["nu"], sh["gamma"])]
            elif curves:
                c0 = next(iter(curves.values()))
                deg = c0.degree
                params = [(0.0, 0.0, -1.0), (0.0, 0.0, 1.0), (c0.mu, c0.nu, c0.gamma)]
            else:  # pragma: no cover - validation guarantees curves or a surface
                deg, params = 3, [(0.0, 0.0, 0.0)]
            uniq = []
            for p in params:
                if p not in uniq:
                    uniq.append(p)
            # the basis figure stops at MAX_PLOT_DEGREE (a plot of more functions is unreadable)
            P.plot_basis(stage.path(FIGURE_NAMES["basis"]), min(max(deg, 2), P.MAX_PLOT_DEGREE), uniq)
        if "curve" in want_figs and curves:
            P.plot_curve(list(curves.values()), stage.path(FIGURE_NAMES["curve"]))
        if "curvature" in want_figs and curves:
            P.plot_curvature(list(curves.values()), stage.path(FIGURE_NAMES["curvature"]))
        if "surface" in want_figs and built is not None:
            P.plot_surface(surface_view(built), stage.path(FIGURE_NAMES["surface"]), title=f"{design.name}: surface")
        if "flat_pattern" in want_figs and pattern is not None:
            plot_pattern(pattern, stage.path(FIGURE_NAMES["flat_pattern"]), title=design.name)
        if "convergence" in want_figs and opt is not None:
            P.plot_convergence({f"{opt.method} ({opt.objective})": opt.history},
                               stage.path(FIGURE_NAMES["convergence"]), title=f"{design.name}: optimizer convergence")

        # 8. report
        step("report")
        files = sorted(p.name for p in stage.tmp.iterdir() if p.is_file())
        if "json" in want_files:
            files.append(FILE_NAMES["json"])
        if "md" in want_files:
            files.append(FILE_NAMES["md"])
        report["files"] = sorted(files)
        report["out_dir"] = str(out)
        report["versions"] = _versions()
        report["elapsed_s"] = time.perf_counter() - t_start
        report = _jsonable(report)
        from .io import write_text_atomic
        import json

        if "json" in want_files:
            write_text_atomic(stage.path(FILE_NAMES["json"]), json.dumps(report, indent=2) + "\n")
        if "md" in want_files:
            write_text_atomic(stage.path(FILE_NAMES["md"]), report_markdown(report))
        stage.commit()
    except BaseException:
        stage.cleanup()
        raise
    return report


def _f(x: Any, fmt: str = ".6g") -> str:
    return "n/a" if x is None else format(x, fmt)


def report_markdown(r: dict[str, Any]) -> str:
    """Markdown report of :func:`run_design` (tables of the measured numbers, figure links)."""
    L = [f"# {r['name']}: ght_cad report", ""]
    L.append(f"Design: `{r['source']}` · units: {r['units']} · ght_cad {r['versions']['ght_cad']} · "
             f"computed in {r['elapsed_s']:.1f} s")
    L.append("")
    L.append(f"GHT definition: {r['ght_definition']}.")
    L.append("")
    if r.get("curves"):
        L += ["## Curves", "", "| name | degree | dim | μ | ν | γ | arc length | max curvature |", "|---|---|---|---|---|---|---|---|"]
        for c in r["curves"]:
            L.append(f"| {c['name']} | {c['degree']} | {c['dim']} | {c['mu']:.4g} | {c['nu']:.4g} | {c['gamma']:.4g} | "
                     f"{c['arc_length']:.6g} | {_f(c['curvature_max'], '.4g')} |")
        L.append("")
    if r.get("joins"):
        L += ["### Joins (measured independently of the construction)", "",
              "| first → second | requested | achieved C | achieved G | satisfied |", "|---|---|---|---|---|"]
        for j in r["joins"]:
            L.append(f"| {j['first']} → {j['second']} | {j['requested']} | C{j['achieved_C']} | G{j['achieved_G']} | "
                     f"{'yes' if j['satisfied'] else 'NO'} |")
        L.append("")
    if r.get("surface"):
        s = r["surface"]
        L += ["## Surface", "", f"Type: `{s['type']}` · shape parameters: "
              + ", ".join(f"{k} = {v:.6g}" for k, v in s["shape_parameters"].items())
              + f" · area {s['area_3d']:.9g} {r['units']}² · ruling length {s['ruling_length_min']:.6g}–"
              f"{s['ruling_length_max']:.6g} {r['units']}", ""]
        L += ["### Developability degree (spec section 5)", "", "| | θ_max [deg] | θ_rms [deg] | DD | R |", "|---|---|---|---|---|"]
        for label, key in (("initial", "developability_initial"), ("final", "developability")):
            d = r.get(key)
            if d:
                L.append(f"| {label} | {d['theta_max']:.3e} | {d['theta_rms']:.3e} | {d['dd']:.12f} | {d['R']:.3e} |")
        L.append("")
        if r.get("initial_surface_error"):
            L += [f"The file's shape parameters give no surface ({r['initial_surface_error']}); the values above "
                  "are those of the optimized parameters.", ""]
        if s.get("strips"):
            L += ["### Strips", "", "| strip | μ | ν | γ | area | θ_max [deg] | DD |", "|---|---|---|---|---|---|---|"]
            for x in s["strips"]:
                sp, d = x["shape_parameters"], x["developability"]
                L.append(f"| {x['name']} | {sp['mu']:.4g} | {sp['nu']:.4g} | {sp['gamma']:.4g} | {x['area_3d']:.9g} | "
                         f"{d['theta_max']:.3e} | {d['dd']:.12f} |")
            L.append("")
        if s.get("joints"):
            L += ["### Joints between strips (measured independently of the construction)", "",
                  "| first → second | requested | achieved | satisfied | plane angle [deg] | residuals |",
                  "|---|---|---|---|---|---|"]
            for j in s["joints"]:
                L.append(f"| {j['first']} → {j['second']} | {j['requested']} | G{j['achieved_G']} | "
                         f"{'yes' if j['satisfied'] else 'NO'} | {j['plane_angle_deg']:.2e} | "
                         + ", ".join(f"{x:.1e}" for x in j["residuals"]) + " |")
            L.append("")
    if r.get("optimization"):
        o = r["optimization"]
        L += ["## Shape-parameter optimization", "",
              f"{o['method']} on {o['objective']}: {_f(o['initial_value'], '.8g')} → {o['best_value']:.8g} in "
              f"{o['iterations']} iterations ({o['nfev']} evaluations, {o['time_s']:.2f} s); best "
              + ", ".join(f"{k} = {v:.6g}" for k, v in o["best_parameters"].items()), ""]
        if o.get("strips"):
            L += [f"Per strip ({o['objective']} of its dual curve as built):", "",
                  "| strip | before | after | μ, ν, γ before | μ, ν, γ after |", "|---|---|---|---|---|"]
            for x in o["strips"]:
                L.append(f"| {x['name']} | {_f(x['initial_value'], '.8g')} | {x['best_value']:.8g} | "
                         + ", ".join(f"{v:.4g}" for v in x["initial_parameters"].values()) + " | "
                         + ", ".join(f"{v:.4g}" for v in x["best_parameters"].values()) + " |")
            L.append("")
        if o.get("joints"):
            L += ["Joints after optimization:", "", "| first → second | requested | measured | satisfied |",
                  "|---|---|---|---|"]
            for j in o["joints"]:
                L.append(f"| {j['first']} → {j['second']} | {j['requested']} | G{j['achieved_G']} | "
                         f"{'yes' if j['satisfied'] else 'NO'} |")
            L.append("")
    if r.get("brep"):
        b = r["brep"]
        L += ["## B-rep", "", f"{b['faces']} face(s){' in one shell' if b.get('shape') == 'shell' else ''} "
              f"(valid: {b['valid']}), area {b['area']:.9g} {r['units']}², "
              f"{b['curve_edges']} curve edge(s).", ""]
    if r.get("flat_pattern"):
        p = r["flat_pattern"]
        L += ["## Flat pattern (spec section 6)", "", f"Area {p['area']:.9g} {r['units']}², {p['bend_lines']} bend lines, "
              f"{len(p.get('panels') or [1])} panel(s)" + (f", edge marks {', '.join(p['edge_marks'])}" if p.get("edge_marks") else "")
              + ".", "",
              "| quantity | max | rms |", "|---|---|---|"]
        for k, v in p["report"].items():
            L.append(f"| {k} | {v['max']:.3e} | {v['rms']:.3e} |")
        L.append("")
    L += ["## Files", ""]
    for f in r.get("files", []):
        L.append(f"- [{f}]({f})" + (f"\n\n  ![{f}]({f})" if f.endswith(".png") else ""))
    L.append("")
    return "\n".join(L)


# ---------------------------------------------------------------------------------------------
# STEP input: unroll the developable faces of a STEP file (``ght-cad unroll FILE.step``)
# ---------------------------------------------------------------------------------------------
#: millimetres per unit (OCCT's STEP reader converts lengths to its system unit, mm by default)
MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "ft": 304.8}
_STEP_UNIT_NAMES = {
    "millimetre": "mm", "millimeter": "mm", "mm": "mm",
    "centimetre": "cm", "centimeter": "cm", "cm": "cm",
    "metre": "m", "meter": "m", "m": "m",
    "inch": "in", "in": "in",
    "foot": "ft", "feet": "ft", "ft": "ft",
}
STEP_SUFFIXES = (".step", ".stp")


@dataclass
class StepUnroll:
    """Result of :func:`unroll_step`: the pattern and a per-face report.

    Attributes:
        pattern: one panel per selected face, labelled ``F<n>`` (``n`` = 1-based face number).
        units: length unit of the pattern (and of the face geometry as read).
        file_units: the length unit the STEP file declares (OCCT name), or None.
        face_count: number of faces in the file.
        faces: per selected face: number, surface type, unroll method, 3-D and flat area,
            developability (θ_max, θ_rms, DD, R) when measured, max relative errors.
    """

    pattern: Any
    units: str
    file_units: str | None
    face_count: int
    faces: list[dict[str, Any]]


def _step_unit(name: str | None) -> str | None:
    if not name:
        return None
    return _STEP_UNIT_NAMES.get(name.strip().lower())


def _read_step_in(path: Path, units: str | None) -> tuple[Any, str, str | None]:
    """Read a STEP file with lengths in ``units`` (default: the file's own length unit, else mm).

    OCCT converts STEP lengths to its system length unit (``SetSystemLengthUnit``, in mm), so
    asking for ``MM_PER_UNIT[u]`` gives the coordinates in unit ``u``.
    """
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    from OCP.TColStd import TColStd_SequenceOfAsciiString

    from .cad.occ import quiet_occt

    with quiet_occt():
        reader = STEPControl_Reader()
        if reader.ReadFile(str(path)) != IFSelect_RetDone:
            raise DesignError(f"{path}: not a readable STEP file (OCCT STEPControl_Reader failed)")
        lengths, angles, solids = (TColStd_SequenceOfAsciiString() for _ in range(3))
        file_unit: str | None = None
        try:
            reader.FileUnits(lengths, angles, solids)
            if lengths.Length() >= 1:
                file_unit = lengths.Value(1).ToCString()
        except Exception:  # pragma: no cover - FileUnits is advisory
            file_unit = None
        unit = units or _step_unit(file_unit) or "mm"
        reader.SetSystemLengthUnit(MM_PER_UNIT[unit])
        reader.TransferRoots()
        shape = reader.OneShape()
    if shape is None or shape.IsNull():
        raise DesignError(f"{path}: the STEP file holds no shape")
    return shape, unit, file_unit


def unroll_step(
    path: str | os.PathLike,
    *,
    faces: Sequence[int] | None = None,
    best_effort: bool = False,
    units: str | None = None,
    tol_deg: float = 0.01,
    rulings: int = 16,
) -> StepUnroll:
    r"""Unroll the developable faces of a STEP file: one labelled panel per face (spec section 6).

    Each face goes through :func:`ght_cad.unroll` (closed forms for planes, cylinders
    ``(u, v) ↦ (R u, v)`` and cones ``ρ (cos(s u), sin(s u))``; quadrature along the rulings
    ``φ = ∫ d'·e``, ``A = ∫ (a'·d) D + (a'·e) D⊥`` for other ruled faces). Panels are labelled
    ``F<n>`` with the 1-based face number ``n`` (file order, ``TopExp_Explorer``); edges shared
    by two selected faces get matching edge marks (:func:`ght_cad.flat_pattern.mark_shared_edges`).

    Args:
        path: ``.step``/``.stp`` file.
        faces: 1-based face numbers to unroll (default: every face).
        best_effort: flatten faces that are not developable within ``tol_deg`` anyway (their
            distortion is in the report) instead of refusing them.
        units: length unit of the pattern, one of mm, cm, m, in, ft; default: the file's
            declared length unit, else mm. Coordinates are converted by OCCT's reader.
        tol_deg: largest accepted ``θ_max`` in degrees.
        rulings: bend lines per face.

    Returns:
        :class:`StepUnroll`.

    Raises:
        DesignError: missing/unreadable file, no faces, a face number out of range, a unit that
            is not allowed.
        NotDevelopableError: a face is not developable within ``tol_deg`` (and not
            ``best_effort``); the one-line message names the file, the face number and the
            measured ``θ_max`` and ``DD``.
    """
    from .errors import NotDevelopableError
    from .flat_pattern import FlatPattern, layout_panels, mark_shared_edges
    from .unroll import unroll

    p = Path(path)
    if p.suffix.lower() not in STEP_SUFFIXES:
        raise DesignError(f"{p}: unknown suffix {p.suffix!r}; allowed STEP suffixes: {', '.join(STEP_SUFFIXES)}")
    if not p.is_file():
        raise DesignError(f"{p}: no such STEP file")
    if units is not None and units not in MM_PER_UNIT:
        raise DesignError(f"{p}: units={units!r} is not allowed; allowed: {', '.join(MM_PER_UNIT)}")
    if not (isinstance(tol_deg, (int, float)) and math.isfinite(tol_deg) and 0 < tol_deg <= 90):
        raise DesignError(f"{p}: tol_deg={tol_deg!r} is out of range; allowed: a number in (0, 90]")
    if isinstance(rulings, bool) or not isinstance(rulings, (int, np.integer)) or not 0 <= rulings <= 1000:
        raise DesignError(f"{p}: rulings={rulings!r} is out of range; allowed: an integer in [0, 1000]")
    shape, unit, file_unit = _read_step_in(p, units)
    from .cad.unroll_faces import shape_faces

    try:
        all_faces = shape_faces(shape)
    except GHTError:
        raise DesignError(f"{p}: the STEP file holds no faces to unroll") from None
    n = len(all_faces)
    chosen = list(range(1, n + 1)) if not faces else list(faces)
    for k in chosen:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 1 <= k <= n:
            raise DesignError(f"{p}: face {k!r} does not exist; allowed: face numbers 1..{n}")
    if len(set(chosen)) != len(chosen):
        raise DesignError(f"{p}: face numbers {chosen} repeat a face; allowed: each face once")
    panels = []
    report: list[dict[str, Any]] = []
    for k in chosen:
        face = all_faces[k - 1]
        kw = dict(tol_deg=tol_deg, rulings=rulings, units=unit, label=f"F{k}")
        try:
            pat = unroll(face, best_effort=best_effort, **kw)
        except NotDevelopableError as exc:
            info_be: dict[str, Any] = {}
            be_error = ""
            try:  # measure how far off it is (for a non-ruled face: the ruled surface between its boundary isolines)
                info_be = unroll(face, best_effort=True, **kw).panels[0].info or {}
            except GHTError as be_exc:  # e.g. a full sphere: no two boundary curves to span rulings between
                info_be = {}
                be_error = " ".join(str(be_exc).split())
            dev = info_be.get("developability")
            straight = min(info_be.get("deviation_u", 0.0), info_be.get("deviation_v", 0.0))
            how = (f"theta_max={dev['theta_max']:.6g} deg, developability degree DD={dev['dd']:.12f} (1 = developable)"
                   if dev else " ".join(str(exc).split()))
            if straight > 1e-9:  # θ_max and DD (spec 5) are defined along rulings: report the straightness
                how = (f"it is not ruled: its straightest isolines deviate {straight:.3g} from straight lines "
                       "relative to their lengths (allowed 1e-9), so it has no rulings to unroll along")
            if be_error and "cannot be flattened" not in how and "cannot flatten" not in how:
                how += f"; --best-effort cannot flatten it either: {be_error}"
            allowed = ("allowed: developable faces" if be_error else
                       "allowed: developable faces, or --best-effort to flatten it with a distortion report")
            raise NotDevelopableError(
                f"{p}: face {k} of {n} is not developable within tol_deg={tol_deg:g}: {how}; {allowed}"
            ) from None
        except GHTError as exc:
            raise type(exc)(f"{p}: face {k} of {n}: {' '.join(str(exc).split())}") from None
        panel = pat.panels[0]
        info = panel.info or {}
        rep = panel.report.as_dict() if panel.report is not None else {}
        report.append({
            "face": k,
            "label": panel.label,
            "surface_type": _face_type_name(face),
            "method": info.get("method"),
            "best_effort": bool(best_effort),
            "area_3d": float(panel.area_3d),
            "area_flat": float(panel.area_flat),
            "developability": info.get("developability"),
            "errors": {q: v["max"] for q, v in rep.items()},
        })
        panels.extend(pat.panels)
    mark_shared_edges(panels)
    layout_panels(panels)
    return StepUnroll(FlatPattern(panels, units=unit), unit, file_unit, n, report)


def _face_type_name(face: Any) -> str:
    from OCP.BRepAdaptor import BRepAdaptor_Surface

    t = BRepAdaptor_Surface(face).GetType()
    name = getattr(t, "name", str(t))
    return name.replace("GeomAbs_", "").lower()
