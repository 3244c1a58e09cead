r"""A text scan of a STEP file before a CAD kernel reads it (kernel-free; issue 26).

OCCT's reader never finished (> 150 s in ``TransferRoots``) on a coordinate written ``1.E400``, and
coordinates near 1e290 gave NaN measures with numpy overflow warnings. :func:`check_step_numbers`
refuses such a file first: every real number of the file whose magnitude is beyond
:data:`MAX_STEP_NUMBER` (1e12 of the file's unit) or not finite as a double, naming the entity
(``#12 CARTESIAN_POINT``) that holds it.

Cost: literal searches for reals with an exponent >= 10 or 13+ integer digits (others cannot
exceed 1e12), about 10 ms per MB here (a 14 MB file: 0.14 s); only those candidates are parsed.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

from .errors import GHTError

__all__ = ["MAX_STEP_NUMBER", "check_step_numbers"]

#: largest magnitude of a real number in a STEP file read by ght-cad (in the file's unit)
MAX_STEP_NUMBER = 1e12

# where a real might exceed 1e12: an exponent of two or more digits (not negative) -- a literal
# first byte, so the search runs at memory speed -- or 13+ integer digits before the point (found as a
# literal in a copy whose digits are all "0")
_EXPONENTS = (re.compile(rb"E\+?0*[1-9]\d"), re.compile(rb"e\+?0*[1-9]\d"))
_LONG_INTEGER = re.compile(re.escape(b"0" * 13 + b"."))
_ZEROS = bytes.maketrans(b"123456789", b"000000000")
_TOKEN = frozenset(b"0123456789.+-Ee")
_ENTITY = re.compile(rb"#(\d+)\s*=\s*\(?\s*([A-Za-z_][A-Za-z_0-9]*)?")
_NAME = frozenset(b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_#")


def _candidates(data: bytes) -> list[tuple[int, bytes]]:
    """(start, token) of every real in ``data`` that might exceed 1e12 in magnitude."""
    hits = [m.start() for rx in _EXPONENTS for m in rx.finditer(data)]
    hits += [m.start() for m in _LONG_INTEGER.finditer(data.translate(_ZEROS))]
    out = {}
    n = len(data)
    for h in hits:
        a = h
        while a > 0 and data[a - 1] in _TOKEN and data[a - 1] not in b"Ee":
            a -= 1
        if a > 0 and data[a - 1] in _NAME:  # part of a name (an identifier such as PIPE12), not a number
            continue
        b = h + 1
        while b < n and data[b] in _TOKEN:
            b += 1
        out[a] = data[a:b]
    return sorted(out.items())


def _entity_at(data: bytes, pos: int) -> str:
    """``#<id> <TYPE>`` of the entity instance holding byte ``pos`` ("" if none is found)."""
    start = data.rfind(b";", 0, pos) + 1
    m = _ENTITY.search(data, start, pos)
    if m is None:
        return ""
    kind = (m.group(2) or b"").decode("ascii", "replace")
    return f"#{m.group(1).decode()}" + (f" {kind}" if kind else "")


def check_step_numbers(path: str | os.PathLike, data: bytes | None = None) -> None:
    """Refuse a STEP file holding a real number beyond ±:data:`MAX_STEP_NUMBER` or not finite.

    Args:
        path: the file (read unless ``data`` is given); named in the message.
        data: the file's bytes, if already read.

    Raises:
        GHTError: one line naming the file, the entity (``#id TYPE``) and the number.
        OSError: the file cannot be read.
    """
    if data is None:
        data = Path(path).read_bytes()
    for start, tok in _candidates(data):
        try:
            x = float(tok)
        except ValueError:  # not a number after all (e.g. "1.5E+20E" in a text)
            continue
        if math.isfinite(x) and abs(x) <= MAX_STEP_NUMBER:
            continue
        what = "is not finite as a double" if not math.isfinite(x) else f"is beyond ±{MAX_STEP_NUMBER:g}"
        where = _entity_at(data, start)
        raise GHTError(
            f"{path}: {('entity ' + where) if where else 'the file'} has the number {tok.decode('ascii')}, which "
            f"{what}; allowed: coordinates and other reals within ±{MAX_STEP_NUMBER:g} of the file's unit "
            "(a hostile or corrupt file; it is not given to the CAD kernel)"
        )
