"""One call from a problem to the optimized object, its B-rep, STEP file and flat pattern.

:func:`optimize_design` runs an optimizer on a problem of :mod:`ght_cad.optimize.problems`
(starting population contains the base design, so the result is never worse), builds the
optimized object (``problem.build(x)``: a ruled/developable surface or a curve), and optionally

* the B-rep: a build123d ``Face`` for surfaces (``surface.to_face()``, else
  :func:`ght_cad.cad.developable_faces.developable_face`), an ``Edge`` for curves
  (certified B-spline, :func:`ght_cad.surfaces.bspline.curve_to_bspline`);
* ``<stem>.step`` (:func:`ght_cad.cad.occ.write_step`, atomic);
* ``<stem>.dxf`` flat pattern of a surface (:func:`ght_cad.unroll`; a quasi-developable strip
  whose ``θ_max`` exceeds the unroll tolerance is flattened with ``best_effort=True`` and its
  distortion is reported in the notes);
* ``<stem>_convergence.png`` and ``<stem>.json`` (parameters, measures before/after, run data).

CAD pieces are imported lazily; a missing piece is skipped with a note, and a flat pattern the
unroll refuses (e.g. a strip whose boundary curves meet) is a note too (never a crash of the
optimization result). Non-finite numbers are written as ``null`` in the JSON file.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..core._kernel import adapter
from ..core.errors import GHTError
from ..core.io import strict_json, write_text_atomic
from ..core.progress import Progress
from ..surfaces.ruled import RuledSurface
from .optimizers import OptimizeResult, OptimizerState, minimize

__all__ = ["DesignResult", "optimize_design"]


@dataclass
class DesignResult:
    """What :func:`optimize_design` produced.

    Attributes:
        problem: the problem.
        result: the optimizer's :class:`OptimizeResult`.
        parameters: all named shape parameters of the optimized design.
        before: ``problem.report`` at the base design.
        after: ``problem.report`` at the optimum.
        object: the optimized curve or surface.
        shape: its build123d ``Face`` (surface) or ``Edge`` (curve), when ``cad=True``.
        flat: the :class:`~ght_cad.pattern.flat_pattern.FlatPattern` of a surface, when ``flat=True``.
        files: written files by kind (``"step"``, ``"dxf"``, ``"png"``, ``"json"``).
        notes: skipped steps and warnings, in words.
    """

    problem: Any
    result: OptimizeResult
    parameters: dict[str, float]
    before: dict[str, float]
    after: dict[str, float]
    object: Any
    shape: Any = None
    flat: Any = None
    files: dict[str, Path] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    def summary(self) -> str:
        """Markdown summary: parameters and measures before/after."""
        lines = [f"{getattr(self.problem, 'label', 'problem')}: {self.result}", "",
                 "| measure | before | after |", "|---|---|---|"]
        for k in self.after:
            b = self.before.get(k, math.nan)
            lines.append(f"| {k} | {b:.6g} | {self.after[k]:.6g} |")
        lines += ["", "| parameter | value |", "|---|---|"]
        lines += [f"| {k} | {v:.6f} |" for k, v in self.parameters.items()]
        if self.notes:
            lines += [""] + [f"- {n}" for n in self.notes]
        return "\n".join(lines)


_strict = strict_json  # moved to ght_cad.core.io (shared with the approximation's report)


def _brep(obj: Any, notes: list[str]) -> Any:
    try:
        if isinstance(obj, RuledSurface):
            if hasattr(obj, "to_face"):
                return obj.to_face()
            return adapter("developable_face")(obj)
        from ..surfaces.bspline import curve_to_bspline

        if getattr(obj, "dim", 3) not in (2, 3):
            notes.append(f"no B-rep for a {obj.dim}-D curve")
            return None
        return adapter("make_edge")(curve_to_bspline(obj))
    except ImportError as exc:  # CAD kernel or adapter missing
        notes.append(f"B-rep skipped: {exc}")
        return None


def optimize_design(
    problem: Any,
    method: str = "igwo",
    *,
    pop_size: int = 30,
    max_iter: int | None = 200,
    max_nfev: int | None = None,
    seed: Any = 0,
    out_dir: str | os.PathLike | None = None,
    stem: str = "optimized",
    cad: bool = True,
    flat: bool = True,
    plot: bool = True,
    progress: bool | None = None,
    callback: Callable[[OptimizerState], Any] | None = None,
    tol_deg: float | None = None,
    **options: Any,
) -> DesignResult:
    """Optimize a problem's shape parameters and turn the result into CAD output.

    Args:
        problem: a problem of :mod:`ght_cad.optimize.problems` (callable on populations, with
            ``bounds``, ``x0``, ``build``, ``report``, ``parameters``).
        method: ``"igwo"``, ``"pso"``, ``"gwo"`` or ``"de"``.
        pop_size, max_iter, max_nfev, seed: optimizer budget and random stream.
        out_dir: directory for the files; None writes nothing (the objects are still built).
        stem: base name of the files.
        cad: build the B-rep face/edge (and the STEP file when ``out_dir`` is set).
        flat: unroll a surface (and write the DXF when ``out_dir`` is set).
        plot: write the convergence PNG (``out_dir`` only).
        progress: progress bar on stderr; None shows it when stderr is a terminal.
        callback: also called after every iteration; returning True stops the run.
        tol_deg: developability tolerance of the unroll (default :data:`ght_cad.unroll.DEFAULT_TOL_DEG`).
        **options: more optimizer options (``tol``, ``target``, ...).

    Returns:
        DesignResult.

    Raises:
        GHTError: bad optimizer arguments, a bad ``stem``, an ``out_dir`` that is a file (checked
            before the run), no candidate with a finite objective,
            or a failed export (the target file is left untouched: all writes are atomic).
    """
    if not stem or any(c in stem for c in "/\\") or stem in (".", ".."):
        raise GHTError(f"stem={stem!r} is not allowed; use a plain file name without directories")
    if out_dir is not None and Path(out_dir).exists() and not Path(out_dir).is_dir():
        raise GHTError(f"out_dir={str(out_dir)!r} is a file; allowed: a folder or a new path")
    notes: list[str] = []
    total = max_iter if max_iter is not None else None
    with Progress(total, f"{method} {getattr(problem, 'label', '')}".strip(),
                  enabled=progress if progress is not None else None) as bar:
        def cb(state: OptimizerState) -> bool:
            bar.set(state.nit)
            return bool(callback(state)) if callback is not None else False

        res = minimize(problem, problem.bounds, method, pop_size=pop_size, max_iter=max_iter,
                       max_nfev=max_nfev, seed=seed, callback=cb, x0=problem.x0, **options)
    if not res.success:
        raise GHTError(
            f"{method} found no parameters with a finite objective in {res.nfev} evaluations "
            f"({getattr(problem, 'label', 'problem')}: every candidate, the base design included, is degenerate)"
        )
    obj = problem.build(res.x)
    after = problem.report(res.x)
    try:
        before = problem.report(problem.x0)
    except GHTError as exc:  # the base design itself is degenerate: nothing to compare with
        before = {k: math.nan for k in after}
        notes.append(f"the base design cannot be built ({' '.join(str(exc).split())[:200]}); 'before' is NaN")
    out = DesignResult(problem, res, problem.parameters(res.x), before, after, obj, notes=notes)
    folder = None if out_dir is None else Path(out_dir)
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
    if cad:
        out.shape = _brep(obj, notes)
        if out.shape is not None and folder is not None:
            adapter("write_step")(out.shape, folder / f"{stem}.step")
            out.files["step"] = folder / f"{stem}.step"
    if flat and isinstance(obj, RuledSurface):
        try:
            from ..unrolling.unroll import DEFAULT_TOL_DEG
            from ..unrolling.unroll import unroll as _unroll

            tol = DEFAULT_TOL_DEG if tol_deg is None else float(tol_deg)
            theta = float(after.get("theta_max", obj.developability().theta_max))
            best = theta > tol
            fp = _unroll(obj, best_effort=best, tol_deg=tol)
            if best:
                notes.append(
                    f"theta_max={theta:.4g} deg > unroll tolerance {tol:g} deg: flattened with best_effort; "
                    f"distortion {fp.errors}"
                )
            out.flat = fp
            if folder is not None:
                fp.export_dxf(folder / f"{stem}.dxf")
                out.files["dxf"] = folder / f"{stem}.dxf"
        except ImportError as exc:
            notes.append(f"flat pattern skipped: {exc}")
        except GHTError as exc:  # e.g. a pinched strip: the optimization result stands, no DXF
            notes.append(f"flat pattern failed: {' '.join(str(exc).split())}")
    elif flat:
        notes.append("no flat pattern: the optimized object is a curve")
    if folder is not None:
        if plot:
            from .plots import plot_convergence

            out.files["png"] = plot_convergence({method: res}, folder / f"{stem}_convergence.png",
                                                title=f"{getattr(problem, 'label', 'problem')}: {method}")
        data = {
            "problem": getattr(problem, "label", type(problem).__name__),
            "method": method,
            "parameters": out.parameters,
            "before": before,
            "after": after,
            "fun": res.fun,
            "nfev": res.nfev,
            "nit": res.nit,
            "time": res.time,
            "message": res.message,
            "history": res.history.tolist(),
            "history_nfev": res.history_nfev.tolist(),
            "notes": notes,
        }
        write_text_atomic(folder / f"{stem}.json", json.dumps(_strict(data), indent=1, allow_nan=False))
        out.files["json"] = folder / f"{stem}.json"
    return out
