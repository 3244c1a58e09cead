r"""``type = "approximate"`` surfaces: their keys and ``[surfaces.target]`` (a STEP face or an
inline GHT/NURBS patch) with its control net. Moved from ``ght_cad/app/design/schema.py`` (issue 27); every name is importable from
:mod:`ght_cad.app.design.schema` (and, as before, the re-exported ones from :mod:`ght_cad.app.design`).
"""

from __future__ import annotations

import math
from pathlib import Path

from .constants import APPROX_DIRECTIONS, APPROX_METHODS, MAX_APPROX_PANELS, MAX_ROWS, MAX_TARGET_DEGREE
from .specs import SurfaceSpec, TargetSpec
from .checker import _Checker, _short, _tname


_APPROX_KEYS = ("type", "target", "tol", "max_panels", "direction", "method", "untrimmed")


#: the keys of ``[surfaces.target]`` by kind of target (the kind is told by its first key)
TARGET_KEYS = {
    "step": ("step", "face"),
    "ght": ("control_points", "mu_u", "nu_u", "gamma_u", "mu_v", "nu_v", "gamma_v"),
    "nurbs": ("poles", "weights", "knots_u", "knots_v", "degree_u", "degree_v"),
}


_TARGET_FIRST = {"step": "step", "ght": "control_points", "nurbs": "poles"}


def _parse_approximate(ck: _Checker, st: dict, path: str, extra: tuple[str, ...] = ()) -> SurfaceSpec:
    """``type = "approximate"`` at ``path``: ``tol`` (> 0), ``max_panels`` (1..256), ``direction``
    (:data:`APPROX_DIRECTIONS`), ``method`` (:data:`APPROX_METHODS`, default ``auto``), ``untrimmed``
    (a boolean, default false: a trimmed STEP face is covered over its whole (u, v) box only with it) and the
    ``[<path>.target]`` table (:func:`_parse_target`)."""
    ck.keys(st, path, _APPROX_KEYS + extra)
    tol = ck.number(st, "tol", path, required=True, lo=0.0, lo_open=True,
                    allowed="a length > 0 (largest deviation both ways, in the design's unit)")
    max_panels = ck.integer(st, "max_panels", path, 64, lo=1, hi=MAX_APPROX_PANELS)
    direction = ck.string(st, "direction", path, "auto", choices=APPROX_DIRECTIONS)
    method = ck.string(st, "method", path, "auto", choices=APPROX_METHODS)
    untrimmed = ck.boolean(st, "untrimmed", path, False)
    target = _parse_target(ck, st, f"{path}.target")
    return SurfaceSpec("approximate", target=target, tol=tol, max_panels=max_panels, direction=direction,
                       method=method, untrimmed=untrimmed)


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
