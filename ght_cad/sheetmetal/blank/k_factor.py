r"""K-factor tables: ANSI ``K`` as a step function of ``R / T`` (built-in ``ansi`` and DIN 6935,
text files, design-file rows). Moved from ``ght_cad/sheetmetal/blank.py`` (issue 27); every name is importable
from :mod:`ght_cad.sheetmetal.blank`."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from .model import BlankError


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
