r"""Design-file surfaces of ``type = "approximate"`` (issue 24): developable panels covering a target.

The target of ``[[surfaces]] type = "approximate"`` (``[surfaces.target]``, :class:`~ght_cad.app.design.schema.TargetSpec`)
is a face of a STEP file (path relative to the design file, 1-based face number, as ``ght-cad
approximate --face``), a GHT patch ``S(u, v) = Σ_i Σ_j b_{i,m}(u) b_{j,n}(v) P_ij``
(:class:`ght_cad.surfaces.patch.GHTSurface`) or a NURBS patch (:class:`ght_cad.surfaces.nurbs.NurbsSurface`). It is
covered by :func:`ght_cad.approximate` with the surface's ``tol``, ``max_panels``, ``direction`` and
``method``: the same call ``ght-cad approximate``
(:mod:`ght_cad.app.approximate_cli`) makes, and both write their
outputs through the functions of this module: the panels sewn into one shell
(:func:`ght_cad.cad.approximate.panels_shell`), their flat patterns on one sheet with seam marks
(:func:`panel_pattern`), the deviation map (:func:`plot_deviation`), the per-panel report
(:func:`approximation_report`, :func:`report_markdown`) and, with a sheet, one plate solid per panel
(:func:`panel_plates`; a design's ``[sheet]`` plates the panels as any other surface's parts,
:func:`ght_cad.app.design.build.sheet_parts`) with the neutral surfaces' flat patterns.

The CAD kernel is imported only inside the functions that need it (a STEP target, plates).
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ...core.errors import GHTError
from .schema import DesignError, SurfaceSpec

__all__ = ["ApproximatedSurface", "approximation_target", "build_approximation", "is_approximation",
           "plot_deviation",
           "report_markdown", "approximation_report", "panel_sheets", "panel_pattern", "panel_plates"]


class ApproximatedSurface:
    """The built ``approximate`` surface of a design: the :class:`~ght_cad.approximation.ApproximationResult`
    and its panels' exact developables (``parts``: a :class:`~ght_cad.developables.loft.DevelopableLoft` per strip,
    a :class:`~ght_cad.approximation.ConeStrip` where a seam is one point) and the ``method`` asked for."""

    def __init__(self, result: Any, target: Any, method: str = "auto") -> None:
        self.result = result
        self.target = target
        self.method = method
        self.parts = [p.exact if p.exact is not None else p.surface for p in result.panels]

    def part_sheets(self, sheet: Any) -> list[Any] | None:
        """Per panel the sheet with ``side`` on the target's normal (:func:`panel_sheets`)."""
        return panel_sheets(self.result, self.target, sheet)

    def __repr__(self) -> str:
        return f"ApproximatedSurface({len(self.parts)} panels, max deviation {self.result.max_deviation:.4g})"


def is_approximation(surface: Any) -> bool:
    """True for the built surface of an ``approximate`` surface."""
    return isinstance(surface, ApproximatedSurface)


def _fail(source: str, key: str, message: str) -> DesignError:
    return DesignError(f"{source}: key '{key}': {message}")


def approximation_target(spec: SurfaceSpec, source: str) -> Any:
    """The :class:`~ght_cad.approximation.SurfaceTarget` of an ``approximate`` surface.

    A STEP path is taken relative to the design file (``source``); the target is checked to be a
    regular surface: finite, and ``|S_u × S_v| > 1e-12 size²`` on a 9 × 9 grid of its interior.

    Raises:
        DesignError: a missing or unreadable STEP file, a face number past the file's faces, or a
            degenerate target (naming the file and the key).
    """
    from ...approximation import as_target

    t = spec.target
    key = f"{spec.key}.target"
    if t is None:  # pragma: no cover - the schema requires it
        raise _fail(source, key, "missing")
    if t.kind == "step":
        assert t.step is not None
        p = Path(t.step)
        if not p.is_absolute() and not source.startswith("<"):
            p = Path(source).parent / p
        if not p.is_file():
            raise _fail(source, f"{key}.step", f"{str(p)!r} does not exist; allowed: a STEP file, its path relative "
                        "to the design file")
        from ...cad.approximate import step_target

        try:
            tgt = step_target(p, t.face - 1)
        except GHTError as exc:
            raise _fail(source, f"{key}.face" if "face=" in str(exc) else f"{key}.step",
                        " ".join(str(exc).split())) from None
        from ...approximation.target import TRIM_ALLOWED, is_trimmed, trim_words

        if is_trimmed(tgt.trim) and not spec.untrimmed:
            raise _fail(source, key, f"face {t.face} of {t.step!r} is {trim_words(tgt.trim['covered'], tgt.trim['holes'])}; "
                        f"{TRIM_ALLOWED}, or untrimmed = true on {spec.key} to cover the underlying surface over its "
                        "whole (u, v) box knowingly")
    else:
        try:
            tgt = as_target(_patch(t))
        except GHTError as exc:
            raise _fail(source, key, " ".join(str(exc).split())) from None
    _check_regular(tgt, source, key)
    return tgt


def _patch(t: Any) -> Any:
    """The GHTSurface or NurbsSurface of an inline target."""
    net = np.asarray(t.control_points, dtype=float)
    if t.kind == "ght":
        from ...surfaces.patch import GHTSurface

        s = t.shape
        return GHTSurface(net, s.get("mu_u", 0.0), s.get("nu_u", 0.0), s.get("gamma_u", 0.0),
                          s.get("mu_v", 0.0), s.get("nu_v", 0.0), s.get("gamma_v", 0.0))
    from ...surfaces.nurbs import NurbsSurface

    return NurbsSurface.from_poles(t.knots_u, t.knots_v, t.degree_u, t.degree_v, net, t.weights)


def _check_regular(tgt: Any, source: str, key: str) -> None:
    r"""Refuse a target that is not a regular surface: non-finite points or derivatives, or
    ``|S_u × S_v| <= 1e-12 size²`` at an interior point of a 9 × 9 grid (a collapsed net)."""
    u0, u1, v0, v1 = tgt.bounds
    g = np.linspace(0.05, 0.95, 9)
    U, V = np.meshgrid(u0 + (u1 - u0) * g, v0 + (v1 - v0) * g, indexing="ij")
    with np.errstate(all="ignore"):
        S, Su, Sv = tgt.jet(U.ravel(), V.ravel(), 1)
        finite = bool(np.all(np.isfinite(S)) and np.all(np.isfinite(Su)) and np.all(np.isfinite(Sv)))
        size = float(np.linalg.norm(S.max(axis=0) - S.min(axis=0))) if finite else math.nan
        area = np.linalg.norm(np.cross(Su * (u1 - u0), Sv * (v1 - v0)), axis=1) if finite else np.zeros(1)
    if not finite or not math.isfinite(size) or size > 1e15:
        raise _fail(source, key, "the target has non-finite or overflowing points (|size| beyond 1e15); allowed: a "
                    "surface with finite coordinates")
    if size <= 0 or float(area.min()) <= 1e-12 * size * size:
        raise _fail(source, key, f"the target is degenerate (|S_u x S_v| = {float(area.min()):.3g} at an interior "
                    f"point, size {size:.6g}); allowed: a regular surface (control net not collapsed to a curve or point)")


def build_approximation(spec: SurfaceSpec, source: str) -> ApproximatedSurface:
    """:func:`ght_cad.approximate` of the surface's target with its ``tol``, ``max_panels``,
    ``direction`` and ``method`` (the call ``ght-cad approximate`` makes).

    Raises:
        DesignError: a bad target (:func:`approximation_target`).
        GHTError: no approximation within ``tol`` with ``max_panels`` panels (the message names the
            best deviation reached; the caller adds the file and key).
    """
    from ...approximation import approximate

    tgt = approximation_target(spec, source)
    with np.errstate(all="ignore"):
        result = approximate(tgt, spec.tol, direction=spec.direction, max_panels=spec.max_panels,
                             method=spec.method, untrimmed=spec.untrimmed)
    return ApproximatedSurface(result, tgt, spec.method)


# ------------------------------------------------------------------------------------------------
# outputs (ght-cad approximate and ght-cad run write them through these)
# ------------------------------------------------------------------------------------------------
def plot_deviation(result: Any, path: str | os.PathLike, *, title: str | None = None) -> Path:
    """PNG (900 × 700 px) of the signed deviation (panel minus target along the target normal)
    over the target's (u, v), seams drawn as lines."""
    from ...curves.plotting import _figure, _save

    fig = _figure("surface")
    ax = fig.add_subplot(1, 1, 1)
    m = result.deviation_map
    uv, d = m["uv"], m["d"]
    lim = max(float(np.max(np.abs(d))), 1e-300)
    sc = ax.scatter(uv[:, 0], uv[:, 1], c=d, s=6, cmap="coolwarm", vmin=-lim, vmax=lim)
    fig.colorbar(sc, ax=ax, label="deviation (panel - target, along the normal)")
    u0, u1, v0, v1 = result.info.get("bounds", (uv[:, 0].min(), uv[:, 0].max(), uv[:, 1].min(), uv[:, 1].max()))
    from ...approximation.frame import strip_uv

    for s in result.seams:  # every seam is a segment in (u, v), a point at a box corner
        su, sv = strip_uv(result.direction, (u0, u1, v0, v1), np.array([0.0, 1.0]), np.full(2, s["y"]))
        ax.plot(su, sv, "k-", lw=0.6)
    ax.set_xlabel("u")
    ax.set_ylabel("v")
    ax.set_title(title or f"{len(result.panels)} panels, max deviation {result.max_deviation:.4g} (tol {result.tol:g})")
    return _save(fig, path)


def _direction_text(direction: str) -> str:
    """``rulings along u`` / ``v``, ``seams along the diagonal`` / ``antidiagonal`` (of the parameter box)."""
    return f"rulings along {direction}" if direction in ("u", "v") else f"seams along the {direction} of the (u, v) box"


def report_markdown(report: dict[str, Any], heading: str = "#") -> str:
    """The report as a Markdown table (``heading``: the title's level, ``"##"`` inside a design's report)."""
    methods = [p.get("method", "loft") for p in report["panel_report"]]
    mix = ", ".join(f"{methods.count(m)} {m}" for m in ("dual", "loft") if m in methods)
    lines = [f"{heading} Developable approximation: {report.get('name', 'target')}", "",
             f"- panels: {report['panels']} ({_direction_text(report['direction'])})",
             f"- method: {report.get('method', 'auto')} (per strip: {mix})",
             f"- tolerance: {report['tol']:g}; largest deviation: {report['max_deviation']:.6g}",
             f"- total area: {report['total_area']:.6g}", "",
             "| panel | max out | max in | theta_max (deg) | area | flat area |",
             "|---|---|---|---|---|---|"]
    trim = report.get("trim") or (report.get("info") or {}).get("trim")
    if trim and (trim["holes"] or trim["covered"] < 1.0 - 1e-6):
        lines[6:6] = [f"- trimmed target covered over its whole (u, v) box (untrimmed): the face covers "
                      f"{trim['covered']:.4g} of it, {trim['holes']} hole(s)"]
    for p in report["panel_report"]:
        lines.append(f"| P{p['index']} | {p['max_out']:.4g} | {p['max_in']:.4g} | {p['theta_max_deg']:.2e} | "
                     f"{p['area']:.8g} | {p.get('flat_area', float('nan')):.8g} |")
    files = report.get("files")
    if files:
        lines += ["", "Files: " + ", ".join(files)]
    return "\n".join(lines) + "\n"


def approximation_report(result: Any, pattern: Any = None, *, name: str = "target",
                         method: str = "auto", info: bool = True) -> dict[str, Any]:
    """The report of an approximation (``report.json`` of ``ght-cad approximate``, ``surface.approximation``
    of a design's ``approximate`` surface): :meth:`ApproximationResult.as_dict` with the name, the
    ``method`` asked for (each panel's ``method`` says what it got) and, given the flat ``pattern``,
    every panel's flat area and label. ``info=False`` (a design's report) leaves the core's ``info``
    out but its ``trim`` (a trimmed face covered over its (u, v) box: the fraction, the holes)."""
    report = result.as_dict()
    if not info:
        trim = (report.pop("info", None) or {}).get("trim")
        if trim is not None:
            report["trim"] = trim
    report["name"] = name
    report["method"] = method
    if pattern is not None:
        for p, fp in zip(report["panel_report"], pattern.panels):
            p["flat_area"] = float(fp.area_flat)
            p["label"] = fp.label
    return report


def panel_sheets(result: Any, target: Any, sheet: Any) -> list[Any] | None:
    r"""Per panel the sheet whose ``side`` is measured on the TARGET's normal ``n = S_u × S_v / |..|``
    (None without a sheet or with T = 0). A panel's own normal ``X_u × X_v`` (``X = a + v (b - a)``)
    can point the other way: the strips run along the target's u, v or a diagonal (``direction``), and a cone
    panel with its apex on the strip's first seam has its rail as ``a``; where
    ``n · (X_u × X_v) < 0`` at the panel's middle (``u = v = 1/2``, the target at the middle of its
    strip) the panel gets :meth:`ght_cad.sheetmetal.sheet.Sheet.flipped`, so ``side = "normal"`` puts the
    material of every panel on the target's normal side."""
    if sheet is None or sheet.is_zero:
        return None
    from ...approximation.frame import strip_uv

    u0, u1, v0, v1 = target.bounds
    out = []
    for p in result.panels:
        part = p.exact if p.exact is not None else p.surface
        u, v = strip_uv(result.direction, target.bounds, np.array([0.5]), np.array([0.5 * (p.y0 + p.y1)]))
        _, Su, Sv = target.jet(u, v, 1)
        a, b = part.a(np.array([0.5])), part.b(np.array([0.5]))
        xu = 0.5 * (part.a(np.array([0.5]), 1) + part.b(np.array([0.5]), 1))
        sign = float(np.dot(np.cross(Su[0] * (u1 - u0), Sv[0] * (v1 - v0)), np.cross(xu[0], b[0] - a[0])))
        out.append(sheet if sign >= 0 else sheet.flipped())
    return out


def panel_pattern(result: Any, sheets: Any = None, **kwargs: Any) -> Any:
    """All panels' flat patterns on one sheet with seam marks; with the panels' sheets
    (:func:`panel_sheets`) each panel's neutral surface (at ``K T`` from the panel on its material
    side), the seam marks matched on the panels' own seams (the neutral surfaces of two panels
    meeting at an angle part along their seam)."""
    if sheets is not None:
        kwargs.update(sheet=list(sheets), marks_on="design")
    return result.flat_pattern(**kwargs)


def panel_plates(result: Any, sheets: Any, name: str = "panel") -> list[Any]:
    """One plate solid of thickness T per panel (:func:`ght_cad.cad.sheet_solid.plate_solid` of its
    exact developable with its sheet of :func:`panel_sheets`), labelled ``<name> part <i>`` in
    messages and named ``P<i>`` (faces ``P<i>.inside``, ``P<i>.outside``, ``P<i>.edgeN`` in STEP), as
    the panels of the flat pattern."""
    from ...cad.sheet_solid import plate_solid

    parts = [p.exact if p.exact is not None else p.surface for p in result.panels]
    plates = [plate_solid(s, sh, label=f"{name} part {i + 1}") for i, (s, sh) in enumerate(zip(parts, sheets))]
    for i, p in enumerate(plates):
        p.name = f"P{i + 1}"
    return plates
