r"""Typed getters of a parsed TOML table (:class:`_Checker`) whose errors name the file, the key and
what is allowed; value and type names for the messages. Moved from ``ght_cad/app/design/schema.py`` (issue 27); every name is importable from
:mod:`ght_cad.app.design.schema` (and, as before, the re-exported ones from :mod:`ght_cad.app.design`).
"""

from __future__ import annotations

import math
from typing import Any, Sequence

from .constants import MAX_DESIGN_COORDINATE, MAX_ROWS
from .specs import DesignError


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
