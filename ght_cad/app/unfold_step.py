r"""``ght-cad unroll part.step`` for sheet solids: one blank per solid (issue 23).

The application layer over :func:`ght_cad.cad.unfold_solid.sheet_skins` (sheet recognition, OCP)
and :func:`ght_cad.sheetmetal.blank.unfold_skins` (connected unfolding, core). Only what the blank needs is
imported (OCP and the core; no build123d, no scipy), so the command's start-up is OCP's.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["StepBlanks", "unfold_step"]


@dataclass
class StepBlanks:
    """Result of :func:`unfold_step`: the blanks (:class:`ght_cad.sheetmetal.blank.Unfolded`), the units
    and the file's declared units."""

    unfolded: Any
    units: str
    file_units: str | None
    face_count: int
    shape: Any = None


def unfold_step(
    path: str | os.PathLike,
    *,
    units: str | None = None,
    thickness: float | None = None,
    k_factor: float | None = None,
    din_k_factor: float | None = None,
    k_factor_table: str | None = None,
    base_face: int | None = None,
    bend_lines: str = "tangent",
    allow_split: bool = False,
    tol_deg: float = 0.01,
    rulings: int = 8,
    force: bool = False,
) -> StepBlanks | None:
    r"""The blanks of the sheet solids of a STEP file, or None when the file is for the per-face
    unroll (no solid; or only flat-skinned single-face plates such as ght_cad's own plate solids,
    whose per-face unroll reports the plate, unless ``force``).

    Args:
        path: ``.step``/``.stp`` file.
        units: pattern units (default the file's, else mm).
        thickness: must equal the thickness found (to 1e-6 relative) when given.
        k_factor / din_k_factor / k_factor_table: ANSI K, DIN ``k = 2K`` or a table by ``R/T``
            (``ansi``, ``din`` or a file); default K = 0.5.
        base_face, bend_lines, allow_split, tol_deg, rulings: see :func:`ght_cad.sheetmetal.blank.unfold_skin`.
        force: blank options were given: never hand back to the per-face unroll.

    Raises:
        DesignError: unreadable file, bad units.
        BlankError: refusals (no sheet, sharp edge, ambiguous skin, not developable, overlap),
            the message prefixed with the file name.
    """
    from ..sheetmetal.blank import BlankError, k_factor_table as _table, unfold_skins
    from .design.step_input import MM_PER_UNIT, STEP_SUFFIXES, _read_step_in, _step_unit
    from .design.schema import DesignError

    p = Path(path)
    if p.suffix.lower() not in STEP_SUFFIXES or not p.is_file():
        return None  # the per-face unroll names the problem
    if units is not None and units not in MM_PER_UNIT:
        raise DesignError(f"{p}: units={units!r} is not allowed; allowed: {', '.join(MM_PER_UNIT)}")
    given = [n for n, v in (("--k-factor", k_factor), ("--din-k-factor", din_k_factor),
                            ("--k-factor-table", k_factor_table)) if v is not None]
    if len(given) > 1:
        raise BlankError(f"{p}: {' and '.join(given)} are both given; allowed: one of them")
    shape, unit, file_unit = _read_step_in(p, units)
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    if not TopExp_Explorer(shape, TopAbs_SOLID).More() or _loose_faces(shape):
        if force:
            raise BlankError(f"{p}: the file holds faces outside any solid; blank options apply to files of sheet solids")
        return None  # faces (or faces beside solids): the per-face unroll
    from ..cad.unfold_solid import sheet_skins

    try:
        skins, n = sheet_skins(shape, base_face=base_face)
    except BlankError as exc:
        if not force and (thickness is not None or ((k_factor is not None or din_k_factor is not None) and _plates(p))):
            # an explicit --thickness asks for every face's neutral surface (the per-face sheet unroll);
            # ght_cad's plate solids (named inside/outside faces): the per-face unroll reports them
            return None
        raise BlankError(f"{p}: {exc}") from None
    if not force and all(len(s.faces) == 1 and not s.shared for s in skins):
        return None
    for s in skins:
        if thickness is not None and abs(float(thickness) - s.thickness) > 1e-6 * s.thickness:
            raise BlankError(f"{p}: --thickness={float(thickness)!r} does not match the sheet solid {s.name}, which is "
                             f"{s.thickness:.9g} thick; allowed: its own thickness, or leave --thickness out")
    K: Any
    if k_factor_table is not None:
        K = _table(k_factor_table)
    elif din_k_factor is not None:
        if not (math.isfinite(din_k_factor) and 0.0 <= din_k_factor <= 2.0):
            raise BlankError(f"{p}: --din-k-factor={din_k_factor!r} is not allowed; the DIN k-factor k = 2K lies in [0, 2]")
        K = din_k_factor / 2.0
    else:
        K = 0.5 if k_factor is None else k_factor
    try:
        unfolded = unfold_skins(skins, k_factor=K, base_face=base_face, bend_lines=bend_lines, allow_split=allow_split,
                                units=unit, face_count=n, tol_deg=tol_deg, rulings=rulings)
    except BlankError as exc:
        raise BlankError(f"{p}: {exc}") from None
    declared = _step_unit(file_unit) or (file_unit.strip().lower() if file_unit and file_unit.strip() else None)
    return StepBlanks(unfolded, unit, declared, n, shape)


def _loose_faces(shape: Any) -> bool:
    """The shape holds faces that belong to no solid."""
    from OCP.TopAbs import TopAbs_FACE, TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    n_all = n_solid = 0
    exp = TopExp_Explorer(shape, TopAbs_FACE)
    while exp.More():
        n_all += 1
        exp.Next()
    exp = TopExp_Explorer(shape, TopAbs_SOLID)
    while exp.More():
        sub = TopExp_Explorer(exp.Current(), TopAbs_FACE)
        while sub.More():
            n_solid += 1
            sub.Next()
        exp.Next()
    return n_all > n_solid


def _plates(p: Path) -> bool:
    """Every solid of the file is a plate ght_cad wrote: :func:`ght_cad.cad.sheet_solid.plate_faces`
    finds its inside and outside faces by their STEP names."""
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    from ..cad.sheet_solid import _faces, plate_faces, read_step_face_names

    shape, names = read_step_face_names(p)
    everything = _faces(shape)
    exp = TopExp_Explorer(shape, TopAbs_SOLID)
    found = False
    while exp.More():
        local = _faces(exp.Current())
        index = [next(k for k, g in enumerate(everything) if g.IsSame(f)) for f in local]
        pf = plate_faces(exp.Current(), {i: names[k] for i, k in enumerate(index) if k in names})
        if pf is None or pf.how != "names":
            return False
        found = True
        exp.Next()
    return found
