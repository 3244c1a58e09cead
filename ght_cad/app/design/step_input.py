r"""STEP input: unroll the developable faces of a STEP file made by any CAD tool
(``ght-cad unroll FILE.step``), one panel per face.
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from ...core.errors import GHTError
from ...core._validate import is_real
from ...core.workers import _dask_client, _limit_threads, _worker_threads
from .schema import DesignError


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
        file_units: the length unit the STEP file declares, in the spelling of ``units``
            (mm, cm, m, in, ft, whatever the file writes: 'MM', 'millimetre', 'FOOT', ...); a unit
            name not in that list as the file spells it, lower case; None if the file declares none.
        face_count: number of faces in the file.
        faces: per selected face: number, surface type, unroll method, 3-D and flat area,
            developability (θ_max, θ_rms, DD, R) when measured, max relative errors.
    """

    pattern: Any
    units: str
    file_units: str | None
    face_count: int
    faces: list[dict[str, Any]]
    #: the plate solid found in the file (sheet options without a face selection): inside_face,
    #: outside_face (1-based), thickness, side, found_by; None otherwise
    plate: dict[str, Any] | None = None
    #: a file of several plate solids (e.g. ``ght-cad run`` of ``[[surfaces]]`` with a ``[sheet]``):
    #: one such dict per plate (with its ``name`` when the file names it); ``plate`` is then None
    plates: list[dict[str, Any]] | None = None


def _step_unit(name: str | None) -> str | None:
    if not name:
        return None
    return _STEP_UNIT_NAMES.get(name.strip().lower())


#: seconds OCCT's STEP reader may take in its worker process (``GHT_CAD_STEP_TIMEOUT`` overrides)
STEP_READ_TIMEOUT_S = 300.0


def _read_step_in(path: Path, units: str | None) -> tuple[Any, str, str | None]:
    """Read a STEP file with lengths in ``units`` (default: the file's own length unit, else mm).

    OCCT converts STEP lengths to its system length unit (``SetSystemLengthUnit``, in mm), so
    asking for ``MM_PER_UNIT[u]`` gives the coordinates in unit ``u``.

    Guards (issue 26): the file's text is scanned first (:func:`ght_cad.core.step_guard.check_step_numbers`:
    a real beyond ±1e12 or not finite -- OCCT hung on ``1.E400`` -- is refused before OCCT sees it);
    then, where ``os.fork`` exists, OCCT reads the file in a forked worker process that hands the
    shape back as a BRep file: a reader that crashes (mutated files made OCCT segfault) or runs
    past ``STEP_READ_TIMEOUT_S`` (killed) gives a :class:`DesignError` naming the file instead of
    taking the process down or hanging it. ``GHT_CAD_STEP_INPROCESS=1`` reads in this process.

    Raises:
        DesignError: unreadable, hostile or crashing file; a reader past the time limit.
    """
    from ...core.step_guard import check_step_numbers

    try:
        check_step_numbers(path)  # absurd or overflowing reals: refused before OCCT sees them (it hung)
    except OSError as exc:
        raise DesignError(f"{path}: cannot read the STEP file ({exc.strerror or exc})") from None
    except GHTError as exc:
        raise DesignError(str(exc)) from None
    if not hasattr(os, "fork") or os.environ.get("GHT_CAD_STEP_INPROCESS"):
        return _transfer_step(path, units)
    return _transfer_step_in_worker(path, units)


def _transfer_step_in_worker(path: Path, units: str | None) -> tuple[Any, str, str | None]:
    """:func:`_transfer_step` in a forked child with a wall-clock limit; the shape comes back as BRep."""
    import json
    import shutil
    import signal
    import tempfile
    import time

    from OCP.BRep import BRep_Builder
    from OCP.BRepTools import BRepTools
    from OCP.TopoDS import TopoDS_Shape

    limit = float(os.environ.get("GHT_CAD_STEP_TIMEOUT", STEP_READ_TIMEOUT_S))
    tmp = Path(tempfile.mkdtemp(prefix="ght-cad-step."))
    brep, meta = tmp / "shape.brep", tmp / "meta.json"
    try:
        pid = os.fork()
        if pid == 0:  # the worker: never returns, never runs the parent's exit handlers
            code = 3
            try:
                import faulthandler

                faulthandler.disable()  # a crash is reported by the parent; no dump on a copied stderr fd
                null = os.open(os.devnull, os.O_WRONLY)  # the kernel's own parser messages, a crash report
                os.dup2(null, 1)
                os.dup2(null, 2)
                try:
                    shape, unit, file_unit = _transfer_step(path, units)
                    BRepTools.Write_s(shape, str(brep))
                    meta.write_text(json.dumps({"unit": unit, "file_unit": file_unit}))
                    code = 0
                except DesignError as exc:
                    meta.write_text(json.dumps({"error": str(exc)}))
                    code = 2
            finally:
                os._exit(code)
        deadline = time.monotonic() + limit
        while True:
            done, status = os.waitpid(pid, os.WNOHANG)
            if done:
                break
            if time.monotonic() > deadline:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                raise DesignError(f"{path}: OCCT's STEP reader did not finish within {limit:g} s (stopped); allowed: "
                                  "a valid STEP file (GHT_CAD_STEP_TIMEOUT sets the limit in seconds)")
            time.sleep(0.005)
        if os.WIFSIGNALED(status):
            sig = os.WTERMSIG(status)
            name = signal.Signals(sig).name if sig in signal.Signals._value2member_map_ else str(sig)
            raise DesignError(f"{path}: OCCT's STEP reader crashed on this file ({name}); allowed: a valid STEP file")
        code = os.WEXITSTATUS(status)
        info = json.loads(meta.read_text()) if meta.is_file() else {}
        if code == 2 and "error" in info:
            raise DesignError(info["error"])
        if code != 0 or "unit" not in info:
            raise DesignError(f"{path}: OCCT's STEP reader failed on this file (worker exit {code}); "
                              "allowed: a valid STEP file")
        shape = TopoDS_Shape()
        if not BRepTools.Read_s(shape, str(brep), BRep_Builder()):  # pragma: no cover - our own file
            raise DesignError(f"{path}: the shape read from the STEP file could not be handed over")
        return shape, info["unit"], info["file_unit"]
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _transfer_step(path: Path, units: str | None) -> tuple[Any, str, str | None]:
    """OCCT's STEP reader and transfer in this process (see :func:`_read_step_in`)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPControl import STEPControl_Reader
    from ...cad._ocp import TColStd_SequenceOfAsciiString

    from ...cad.occ import quiet_occt

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
    thickness: float | None = None,
    k_factor: float | None = None,
    din_k_factor: float | None = None,
    side: str | None = None,
    jobs: int = 1,
    scheduler: str | None = None,
) -> StepUnroll:
    r"""Unroll the developable faces of a STEP file: one labelled panel per face (spec section 6).

    Each face goes through :func:`ght_cad.unroll` (closed forms for planes, cylinders
    ``(u, v) ↦ (R u, v)`` and cones ``ρ (cos(s u), sin(s u))``; quadrature along the rulings
    ``φ = ∫ d'·e``, ``A = ∫ (a'·d) D + (a'·e) D⊥`` for other ruled faces). Panels are labelled
    ``F<n>`` with the 1-based face number ``n`` (file order, ``TopExp_Explorer``); edges shared
    by two selected faces get matching edge marks (:func:`ght_cad.pattern.flat_pattern.mark_shared_edges`).

    Args:
        path: ``.step``/``.stp`` file.
        faces: 1-based face numbers to unroll (default: every face).
        best_effort: flatten faces that are not developable within ``tol_deg`` anyway (their
            distortion is in the report) instead of refusing them.
        units: length unit of the pattern, one of mm, cm, m, in, ft; default: the file's
            declared length unit, else mm. Coordinates are converted by OCCT's reader.
        tol_deg: largest accepted ``θ_max`` in degrees.
        rulings: bend lines per face.
        thickness, k_factor, din_k_factor, side: the sheet (:func:`ght_cad.sheetmetal.sheet.make_sheet`,
            spec 6.1): every face's neutral surface at ``±K T`` along its normal is unrolled. When
            the file holds one solid plate (:func:`ght_cad.cad.sheet_solid.plate_faces`: its two
            large faces at a constant distance) and no faces are selected, only its inside face
            is unrolled, with the thickness between the faces and the side towards the other
            face (a given ``thickness`` must match it to 1e-6); a K-factor without a thickness
            needs such a plate.
        jobs: local worker processes for the faces (1: in this process); with ``scheduler``,
            the faces go to that ``dask.distributed`` cluster instead
            (:func:`map_step_faces`). The panels are identical to the serial ones;
            those computed elsewhere carry no development map (``panel.map`` raises).
        scheduler: address of a Dask scheduler (``tcp://host:port``).

    Returns:
        :class:`StepUnroll`.

    Raises:
        DesignError: missing/unreadable file, no faces, a face number out of range, a unit that
            is not allowed.
        NotDevelopableError: a face is not developable within ``tol_deg`` (and not
            ``best_effort``); the one-line message names the file, the face number and the
            measured ``θ_max`` and ``DD``.
    """
    from ...pattern.flat_pattern import FlatPattern, layout_panels, mark_shared_edges

    p = Path(path)
    if p.suffix.lower() not in STEP_SUFFIXES:
        raise DesignError(f"{p}: unknown suffix {p.suffix!r}; allowed STEP suffixes: {', '.join(STEP_SUFFIXES)}")
    if p.is_dir():
        raise DesignError(f"{p}: is a directory, not a STEP file; allowed: a .step/.stp file")
    if not p.is_file():
        raise DesignError(f"{p}: no such STEP file")
    if units is not None and units not in MM_PER_UNIT:
        raise DesignError(f"{p}: units={units!r} is not allowed; allowed: {', '.join(MM_PER_UNIT)}")
    if not (is_real(tol_deg) and math.isfinite(tol_deg) and 0 < tol_deg <= 90):
        raise DesignError(f"{p}: tol_deg={tol_deg!r} is out of range; allowed: a number in (0, 90]")
    if isinstance(rulings, bool) or not isinstance(rulings, (int, np.integer)) or not 0 <= rulings <= 1000:
        raise DesignError(f"{p}: rulings={rulings!r} is out of range; allowed: an integer in [0, 1000]")
    shape, unit, file_unit = _read_step_in(p, units)
    from ...cad.unroll_faces import shape_faces

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
    face_names = _face_names_once(p)
    plates = _step_plates(p, shape, faces, thickness, k_factor, din_k_factor, side, face_names)
    if plates is not None:  # several plate solids: every plate's inside face with its own sheet
        sheet, plate = None, None
        chosen = [pl["inside_face"] for pl, _ in plates]
        face_sheets = {pl["inside_face"]: sh for pl, sh in plates}
    else:
        sheet, plate = _step_sheet(p, shape, faces, thickness, k_factor, din_k_factor, side, face_names)
        if plate is not None:
            chosen = [plate["inside_face"]]
        face_sheets = {k: sheet for k in chosen}
    panels = []
    report: list[dict[str, Any]] = []
    fkw = dict(best_effort=best_effort, tol_deg=tol_deg, rulings=rulings, unit=unit, sheet=sheet)
    if (jobs == 1 or len(chosen) < 2) and scheduler is None:
        results = [unroll_step_face(p, all_faces[k - 1], k, n, **{**fkw, "sheet": face_sheets[k]}) for k in chosen]
    else:
        by_face: dict[int, Any] = {}
        for sh in dict.fromkeys(face_sheets.values()):  # the faces of one sheet together
            group = [k for k in chosen if face_sheets[k] == sh]
            for k, res in zip(group, map_step_faces(p, all_faces, group, {**fkw, "sheet": sh}, jobs=jobs, scheduler=scheduler)):
                by_face[k] = res
        results = [by_face[k] for k in chosen]
    for pans, row in results:
        panels.extend(pans)
        report.append(row)
    mark_shared_edges(panels)
    layout_panels(panels)
    declared = _step_unit(file_unit) or (file_unit.strip().lower() if file_unit and file_unit.strip() else None)
    return StepUnroll(FlatPattern(panels, units=unit), unit, declared, n, report, plate,
                      None if plates is None else [pl for pl, _ in plates])


def _face_names_once(p: Path) -> Callable[[], dict[int, str]]:
    """``{face index: name}`` of the STEP file ``p`` (:func:`ght_cad.cad.sheet_solid.read_step_face_names`),
    read on the first call only (the plate readers below may both ask)."""
    memo: list[dict[int, str]] = []

    def names() -> dict[int, str]:
        if not memo:
            from ...cad.sheet_solid import read_step_face_names

            memo.append(read_step_face_names(p)[1])
        return memo[0]

    return names


def _step_plates(p: Path, shape: Any, faces: Sequence[int] | None, thickness: Any, k_factor: Any,
                 din_k_factor: Any, side: str | None,
                 face_names: Callable[[], dict[int, str]]) -> list[tuple[dict[str, Any], Any]] | None:
    """Several plate solids in the file (sheet options, no face selection, two or more solids each
    a plate: :func:`ght_cad.cad.sheet_solid.plate_faces` per solid, by its face names
    ``<plate>.inside``/``<plate>.outside`` when the file has them, else geometrically): per plate
    its dict (as :attr:`StepUnroll.plate`, plus ``name``) and its sheet (its own thickness, the side
    towards its outside face, the given K). None when that is not the case (one solid, a face
    selection, no sheet options, a solid that is no plate: :func:`_step_sheet` decides).

    Raises:
        SheetError: a given ``thickness`` that differs from a plate's.
    """
    from ...sheetmetal.sheet import make_sheet

    if faces or (thickness is None and k_factor is None and din_k_factor is None and side is None) or thickness == 0:
        return None
    from OCP.TopAbs import TopAbs_SOLID
    from OCP.TopExp import TopExp_Explorer

    from ...cad.sheet_solid import _faces, plate_faces

    solids = []
    exp = TopExp_Explorer(shape, TopAbs_SOLID)
    while exp.More():
        solids.append(exp.Current())
        exp.Next()
    if len(solids) < 2:
        return None
    everything = _faces(shape)
    names = face_names()  # the same file, the same face order (TopExp)
    out = []
    for solid in solids:
        local = _faces(solid)
        index = [next(k for k, g in enumerate(everything) if g.IsSame(f)) for f in local]
        found = plate_faces(solid, {i: names[k] for i, k in enumerate(index) if k in names})
        if found is None:
            return None
        name = names.get(index[found.inside_index], "")
        name = name[: -len(".inside")] if name.endswith(".inside") else None
        _check_plate_thickness(p, thickness, k_factor, din_k_factor, found.thickness,
                               f"the plate solid {name or ''} in the file",
                               (index[found.inside_index] + 1, index[found.outside_index] + 1))
        info = {"name": name, "inside_face": index[found.inside_index] + 1, "outside_face": index[found.outside_index] + 1,
                "thickness": found.thickness, "spread": found.spread, "side": found.side, "found_by": found.how}
        out.append((info, make_sheet(found.thickness, k_factor, din_k_factor=din_k_factor, side=found.side)))
    return out


def _check_plate_thickness(p: Path, thickness: Any, k_factor: Any, din_k_factor: Any, found: float, what: str,
                           faces: tuple[int, int]) -> None:
    """A ``--thickness`` given with a plate solid must be the plate's own (to 1e-6 relative).

    Raises:
        SheetError: a bad value, or one that does not match ``found`` (naming ``what`` and its faces).
    """
    from ...sheetmetal.sheet import SheetError, make_sheet

    if thickness is None:
        return
    make_sheet(thickness, k_factor, din_k_factor=din_k_factor)  # the value itself first
    if abs(float(thickness) - found) > 1e-6 * found:
        raise SheetError(
            f"{p}: --thickness={float(thickness)!r} does not match {what}, which is {found:.9g} thick "
            f"(faces {faces[0]} and {faces[1]}); allowed: its own thickness, or leave --thickness out"
        )


def _step_sheet(p: Path, shape: Any, faces: Sequence[int] | None, thickness: Any, k_factor: Any,
                din_k_factor: Any, side: str | None,
                face_names: Callable[[], dict[int, str]]) -> tuple[Any, dict[str, Any] | None]:
    """The sheet of :func:`unroll_step` and the plate found in the file (see there)."""
    from ...sheetmetal.sheet import SheetError, make_sheet

    if thickness is None and k_factor is None and din_k_factor is None and side is None:
        return None, None
    plate = None
    if not faces and thickness != 0:
        from ...cad.sheet_solid import plate_faces

        from OCP.TopAbs import TopAbs_SOLID
        from OCP.TopExp import TopExp_Explorer

        exp, solids = TopExp_Explorer(shape, TopAbs_SOLID), 0
        while exp.More():
            solids += 1
            exp.Next()
        # by the faces' names (inside/outside, as ght_cad writes plates) when the file has them: the
        # geometric rule (the smaller face is the inside) is wrong when the material lies on the
        # concave side, where the design face is the larger one (measured: a duct plate's neutral
        # pattern 2.4 % short)
        found = plate_faces(shape, face_names()) if solids == 1 else None
        if found is not None:
            _check_plate_thickness(p, thickness, k_factor, din_k_factor, found.thickness, "the plate solid in the file",
                                   (found.inside_index + 1, found.outside_index + 1))
            plate = {"inside_face": found.inside_index + 1, "outside_face": found.outside_index + 1,
                     "thickness": found.thickness, "spread": found.spread, "side": found.side, "found_by": found.how}
            return make_sheet(found.thickness, k_factor, din_k_factor=din_k_factor, side=found.side), plate
    if thickness is None:
        raise SheetError(
            f"{p}: a K-factor or side was given but no thickness, and the file holds no plate solid (one solid "
            "whose two large faces lie at a constant distance) to read it from; allowed: --thickness T"
        )
    return make_sheet(thickness, k_factor, din_k_factor=din_k_factor, side=side or "normal"), None


def unroll_step_face(p: Path, face: Any, k: int, n: int, *, best_effort: bool, tol_deg: float, rulings: int,
                     unit: str, sheet: Any = None) -> tuple[list[Any], dict[str, Any]]:
    """Unroll face ``k`` (of ``n``) of the STEP file ``p`` for :func:`unroll_step`: its panels and report row.

    Raises:
        NotDevelopableError: the face is not developable within ``tol_deg`` (and not ``best_effort``).
        GHTError: any other refusal, the message prefixed with the file and face number.
    """
    from ...core.errors import NotDevelopableError
    from ...unrolling.unroll import unroll

    kw = dict(tol_deg=tol_deg, rulings=rulings, units=unit, label=f"F{k}")
    try:
        pat = unroll(face, best_effort=best_effort, sheet=sheet, **kw)
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
    row = {
        "face": k,
        "label": panel.label,
        "surface_type": _face_type_name(face),
        "method": info.get("method"),
        "best_effort": bool(best_effort),
        "area_3d": float(panel.area_3d),
        "area_flat": float(panel.area_flat),
        "developability": info.get("developability"),
        "errors": {q: v["max"] for q, v in rep.items()},
    }
    return list(pat.panels), row


def _face_type_name(face: Any) -> str:
    from OCP.BRepAdaptor import BRepAdaptor_Surface

    t = BRepAdaptor_Surface(face).GetType()
    name = getattr(t, "name", str(t))
    return name.replace("GeomAbs_", "").lower()


# faces of one STEP file in parallel (ght-cad unroll FILE.step --jobs / --scheduler)
# ---------------------------------------------------------------------------------------------
#: Faces of STEP files already read in this process, by (digest or path+mtime, unit). The caller
#: fills it before forking its local workers, so they start with the faces in memory.
_STEP_FACES: dict[tuple[str, str], list[Any]] = {}


def _file_key(path: Path) -> str:
    st = path.stat()
    return f"{path.resolve()}:{st.st_size}:{st.st_mtime_ns}"


def _portable(panels: list[Any]) -> list[Any]:
    """The panels without what cannot leave the process (edge functions, development map over
    an OCCT adaptor): their sampled outlines, marks, rulings and report are kept."""
    for panel in panels:
        panel.development = None
        for loop in panel.loops:
            for e in loop:
                _ = e.xyz  # the 3-D samples travel, their function does not
                e.flat_fn = e.xyz_fn = None
    return panels


def _step_faces_task(spec: dict[str, Any], data: bytes | None = None) -> list[tuple[Any, ...]]:
    """Unroll some faces of one STEP file in a worker: per face ``("ok", panels, row)`` or
    ``("error", exception)`` (the file is read once per process, :data:`_STEP_FACES`)."""
    from ...cad.unroll_faces import shape_faces

    key = (spec["key"], spec["unit"])
    if key not in _STEP_FACES:
        if data is not None:  # a Dask worker, maybe on another machine: the file came as bytes
            with tempfile.TemporaryDirectory(prefix="ght-cad-step.") as tmp:
                f = Path(tmp) / "input.step"
                f.write_bytes(data)
                shape, _, _ = _read_step_in(f, spec["unit"])
        else:
            shape, _, _ = _read_step_in(Path(spec["path"]), spec["unit"])
        _STEP_FACES[key] = shape_faces(shape)
    faces = _STEP_FACES[key]
    out: list[tuple[Any, ...]] = []
    for k in spec["faces"]:
        try:
            pans, row = unroll_step_face(Path(spec["path"]), faces[k - 1], k, spec["n"], **spec["fkw"])
            out.append(("ok", _portable(pans), row))
        except GHTError as exc:
            out.append(("error", exc))
    return out


def map_step_faces(path: Path, all_faces: list[Any], chosen: Sequence[int], fkw: dict[str, Any], *,
                   jobs: int | None = None, scheduler: str | None = None) -> list[tuple[list[Any], dict[str, Any]]]:
    """:func:`unroll_step_face` of the ``chosen`` faces in parallel.

    The faces are cut into about four chunks per worker, in face order. Local workers are forked
    processes (``concurrent.futures``) that start with ``all_faces`` in memory; Dask workers get
    the file's bytes once (``scatter``, broadcast) and read it once each. Results come back in
    face order; the first face (in that order) that fails raises its error, as the serial loop
    would.

    Args:
        path: the STEP file.
        all_faces: its faces as read here (used by forked local workers).
        chosen: 1-based face numbers.
        fkw: ``best_effort``, ``tol_deg``, ``rulings``, ``unit``.
        jobs: local processes (default: the machine's cores); ignored with ``scheduler``.
        scheduler: Dask scheduler address.

    Returns:
        Per chosen face ``(panels, report row)``.

    Raises:
        GHTError: the first failing face's error, ``jobs < 1``, or an unreachable scheduler.
    """
    import hashlib

    if jobs is None:
        jobs = os.cpu_count() or 1
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise GHTError(f"jobs={jobs!r}; allowed: an integer >= 1")
    chosen = list(chosen)
    workers = jobs if scheduler is None else 8
    size = max(1, -(-len(chosen) // (4 * workers)))
    chunks = [chosen[i:i + size] for i in range(0, len(chosen), size)]
    base = {"path": str(path), "unit": fkw["unit"], "n": len(all_faces), "fkw": dict(fkw)}
    parts: list[list[tuple[Any, ...]]]
    if scheduler is None:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        key = _file_key(Path(path))
        _STEP_FACES[(key, fkw["unit"])] = all_faces
        ctx = multiprocessing.get_context("fork" if sys.platform.startswith("linux") else None)
        try:
            workers = min(jobs, len(chunks))
            with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_limit_threads,
                                     initargs=(_worker_threads(workers),)) as ex:
                parts = list(ex.map(_step_faces_task, [{**base, "key": key, "faces": c} for c in chunks]))
        finally:
            _STEP_FACES.pop((key, fkw["unit"]), None)
    else:
        client = _dask_client(scheduler)
        try:
            data = Path(path).read_bytes()
            key = hashlib.sha256(data).hexdigest()
            remote = client.scatter(data, broadcast=True)
            futs = [client.submit(_step_faces_task, {**base, "key": key, "faces": c}, remote, pure=False)
                    for c in chunks]
            parts = client.gather(futs)
        finally:
            client.close()
    results = []
    for part in parts:
        for item in part:
            if item[0] == "error":
                raise item[1]
            results.append((item[1], item[2]))
    return results
