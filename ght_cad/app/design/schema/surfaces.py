r"""``[surface]`` / ``[[surfaces]]`` validation: one surface of any type, composites and their
segments, the objectives and shape parameters a surface type allows. Moved from ``ght_cad/app/design/schema.py`` (issue 27); every name is importable from
:mod:`ght_cad.app.design.schema` (and, as before, the re-exported ones from :mod:`ght_cad.app.design`).
"""

from __future__ import annotations

import math

from .constants import (PLANE_OBJECTIVES, RAIL_ORIENTATIONS, RAILS_OBJECTIVES, SHAPE_NAMES,
                        STRIP_JOINS, STRIP_OBJECTIVES, SURFACE_TYPES)
from .specs import CurveSpec, SegmentSpec, SurfaceSpec
from .checker import _Checker, _short, _tname
from .sheet import _parse_sheet_override
from .target import _parse_approximate


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


def _shape_names(spec: SurfaceSpec) -> tuple[str, ...]:
    if spec.type == "planes":
        return SHAPE_NAMES
    if spec.type == "composite":
        return tuple(f"{g.name}.{k}" for g in spec.segments or [] for k in SHAPE_NAMES)
    return tuple(f"{s}.{k}" for s in ("a", "b") for k in SHAPE_NAMES)
