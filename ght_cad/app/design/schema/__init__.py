r"""Design-file schema: the dataclasses of a design and their validation (:func:`parse_design`).

Every check names the file, the key and the allowed values and raises :class:`DesignError`
(a :class:`~ght_cad.core.errors.GHTError`, so ``ght-cad`` exits with code 2). The schema is documented
in ``docs/design-files.md``.

Modules (issue 27, moved from ``ght_cad/app/design/schema.py``): :mod:`.constants` (allowed values
and limits), :mod:`.specs` (the dataclasses, :class:`DesignError`), :mod:`.checker` (typed getters
naming file and key), :mod:`.sheet` (K-factor tables, per-surface sheet overrides), :mod:`.target`
(``approximate`` surfaces and their targets), :mod:`.surfaces` (surfaces of every type,
composites); :func:`parse_design`, :func:`parse_design_text` and :func:`load_design` stay here. Every
name (private ones included) is importable as ``ght_cad.app.design.schema.<name>``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

# The moved names (issue 27), all importable from here.
from .constants import (APPROX_DIRECTIONS, APPROX_METHODS, CONTINUITIES, FIGURE_NAMES, FIGURE_OUTPUTS, FILE_NAMES,
                        FILE_OUTPUTS, MAX_APPROX_PANELS, MAX_DESIGN_COORDINATE, MAX_ROWS,
                        MAX_TARGET_DEGREE, MAX_UNROLL_GRID, METHODS, PANELS_CHOICES,
                        PLANE_OBJECTIVES, RAIL_ORIENTATIONS, RAILS_OBJECTIVES, SHAPE_NAMES,
                        SIDE_REFERENCES, STRIP_JOINS, STRIP_OBJECTIVES, SURFACE_TYPES, UNITS)  # noqa: F401
from .specs import (CurveSpec, Design, DesignError, JoinSpec, OptimizeSpec, OutputSpec, SegmentSpec,
                    SheetSpec, SurfaceSpec, TargetSpec, UnrollSpec)  # noqa: F401
from .checker import _Checker, _range_text, _short, _tname  # noqa: F401
from .sheet import _k_factor_table, K_TABLE_ALLOWED, _parse_sheet_override, SURFACE_SHEET_KEYS  # noqa: F401
from .target import _APPROX_KEYS, _net, _parse_approximate, _parse_target, _TARGET_FIRST, TARGET_KEYS  # noqa: F401
from .surfaces import (_composite_parameters, default_objective, _objectives_for, _parse_composite,
                       _parse_surface, _parse_surfaces, _SEGMENT_KEYS, _shape_names, _weight_names)  # noqa: F401


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
    if isinstance(data.get("sweep"), dict):  # expanded into variants by ght-cad batch (ght_cad.app.sweep)
        raise ck.fail("sweep", f"a [sweep] table is expanded into variants by 'ght-cad batch {source} --out DIR' "
                               "(ght_cad.app.sweep.expand_sweep); allowed here: a design without [sweep]")
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
                      f"the design's only surface (this design has {len(surfaces)}: a design's surfaces are sewn into one shell "
                      "along shared rails, and the panels' outer seams lie off the target); allowed: one [[surfaces]] entry "
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
