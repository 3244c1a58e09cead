r"""``[sheet]`` validation shared by the surfaces: the K-factor table (a built-in name, a file or
inline rows) and a surface's ``[surfaces.sheet]`` override. Moved from ``ght_cad/app/design/schema.py`` (issue 27); every name is importable from
:mod:`ght_cad.app.design.schema` (and, as before, the re-exported ones from :mod:`ght_cad.app.design`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .checker import _Checker, _short, _tname


#: what ``[sheet] k_factor_table`` allows (the messages)
K_TABLE_ALLOWED = ("'ansi', 'din', a file of 'R/T K' lines (relative to the design file; a first line 'din' for "
                   "DIN k = 2K) or an inline array of [R/T, K] rows (R/T from 0 ascending, K in [0, 1])")


def _k_factor_table(ck: _Checker, value: Any, source: str) -> Any:
    """``[sheet] k_factor_table`` (:func:`ght_cad.sheetmetal.blank.k_factor_table` semantics: a built-in table by
    name, a file of ``R/T K`` lines, or inline ``[[R/T, K], ...]`` rows of ANSI K)."""
    from ....sheetmetal.blank import K_TABLES, BlankError, k_factor_rows, k_factor_table

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
