r"""Unrolling developable surfaces and faces into flat patterns (spec 6): the entry points.

:func:`unroll` takes a ruled surface (developed by quadrature along the rulings,
:mod:`ght_cad.unrolling.ruled_development`, where the formulas are), a CAD face, or a list of them
(:func:`unroll_composite`, one panel per part or joined blanks, :mod:`ght_cad.sheetmetal.join_panels`); with
a sheet the neutral surface is developed (:func:`ght_cad.sheetmetal.sheet.unroll_ruled_sheet`). The names of
:mod:`ght_cad.unrolling.ruled_development` (``RuledDevelopment``, ``ruled_area``, ``DEFAULT_TOL_DEG``,
``metric_angles`` ...) were defined here before issue 27 and are still importable from here.

Non-ruled input (build123d / OCP faces) is handed to :mod:`ght_cad.cad.unroll_faces` (imported
lazily: this module imports numpy and scipy only).
"""

from __future__ import annotations

import math
import sys
import types
from typing import Any, Sequence

import numpy as np

from ..core.errors import GHTError
from ..core._validate import is_real
from ..pattern.flat_pattern import BoundaryEdge, FlatPanel, FlatPattern, measure_panel  # noqa: F401
from ..surfaces.ruled import RuledSurface
# the development of one ruled surface moved to ght_cad.unrolling.ruled_development (issue 27); every name is still given here
from .ruled_development import (_EDGES0, _INT, _K, _N, _ONES, _V, _VI, _X, DEFAULT_TOL_DEG, RULED_EDGE_UV,  # noqa: F401
                                RuledDevelopment, _PanelSeries, _check_developable, _cheb_rows_of, _chebint, _clenshaw,
                                _coefficients, _fd5, _frame, _initial_edges, _metric_samples, _panel_nodes, _ruled_edges,
                                _smooth_pieces, broadcast_uv, first_nodes, metric_angles, metric_stencil, ruled_area,
                                unroll_ruled_surface)

__all__ = [
    "unroll",
    "unroll_composite",
    "unroll_ruled",
    "ruled_area",
    "RuledDevelopment",
    "DEFAULT_TOL_DEG",
]

def unroll_ruled(
    surface: RuledSurface,
    *,
    best_effort: bool = False,
    tol_deg: float = DEFAULT_TOL_DEG,
    rulings: int = 16,
    samples: int = 257,
    units: str = "mm",
    label: str = "P1",
    breakpoints: Sequence[float] = (),
    sheet: Any = None,
) -> FlatPattern:
    r"""Unroll a :class:`~ght_cad.surfaces.ruled.RuledSurface` by quadrature along its rulings.

    ``Y(u, v) = A(u) + v |g(u)| D(u)`` with ``φ = ∫ d'·e``, ``A = ∫ (a'·d) D + (a'·e) D⊥`` (module
    doc); the panel's outline is a(u), the ruling u = 1, b(u) reversed and the ruling u = 0.

    Args:
        surface: the ruled surface (u, v ∈ [0, 1]).
        best_effort, tol_deg, rulings, samples, units, label: as in :func:`unroll`.
        breakpoints: parameters where a, b are not smooth (B-spline knots).
        sheet: a :class:`ght_cad.sheetmetal.sheet.Sheet` with ``T > 0``: the pattern is the development of
            the neutral offset ``S + σ K T n`` (:func:`ght_cad.sheetmetal.sheet.unroll_ruled_sheet`); None
            or ``T = 0``: the surface itself.

    Returns:
        Single-panel FlatPattern; ``pattern.map(u, v)`` is the development map.

    Raises:
        NotDevelopableError: ``θ_max > tol_deg`` and not best_effort (message: θ_max, θ_rms, DD).
        DegenerateGeometryError: a zero-length ruling or a directrix tangent to a ruling.
        SheetError: a thickness beyond a bending radius of the surface.
    """
    if sheet is not None and not sheet.is_zero:
        from ..sheetmetal.sheet import unroll_ruled_sheet

        return unroll_ruled_sheet(surface, sheet, best_effort=best_effort, tol_deg=tol_deg, rulings=rulings,
                                  samples=samples, units=units, label=label)
    return unroll_ruled_surface(surface, best_effort=best_effort, tol_deg=tol_deg, rulings=rulings, samples=samples,
                                units=units, label=label, breakpoints=breakpoints)


def unroll(
    surface_or_face: Any,
    *,
    best_effort: bool = False,
    tol_deg: float = DEFAULT_TOL_DEG,
    rulings: int = 16,
    samples: int = 257,
    units: str = "mm",
    label: str = "P1",
    sheet: Any = None,
    thickness: float | None = None,
    k_factor: float | None = None,
    din_k_factor: float | None = None,
    side: str = "normal",
) -> FlatPattern:
    r"""Unroll a developable surface or face into a flat pattern (spec section 6).

    For a :class:`~ght_cad.surfaces.ruled.RuledSurface` the development is computed by quadrature along the
    rulings: ``φ = ∫ d'·e``, ``A = ∫ (a'·d) D + (a'·e) D⊥``, ``Y(u, v) = A(u) + v |g(u)| D(u)``
    (adaptive Chebyshev panels, near machine precision). Anything else (a build123d/cadquery
    ``Face`` or an OCP ``TopoDS_Face``: cylinder, cone, plane, surface of extrusion, B-spline or
    Bézier ruled face) goes to :func:`ght_cad.cad.unroll_faces.unroll_face`, which keeps holes and
    trimmed boundaries.

    Args:
        surface_or_face: a RuledSurface, a face, or a list of them or a shell/solid/compound
            with several faces (then one panel per face, see :func:`unroll_composite`).
        best_effort: flatten a surface that is not developable within ``tol_deg`` anyway; its
            distortion is in ``.report``.
        tol_deg: largest accepted ``θ_max`` (degrees) of the developability degree (spec 5).
        rulings: number of interior rulings drawn as bend lines.
        samples: points per boundary edge in the outline polylines.
        units: length unit of the coordinates ("mm", "cm", "m", "in", "ft"); DXF $INSUNITS.
        label: panel label.
        sheet: a :class:`ght_cad.sheetmetal.sheet.Sheet` (thickness, K-factor, side), or give
        thickness, k_factor, din_k_factor, side: the sheet's values (:func:`ght_cad.sheetmetal.sheet.make_sheet`;
            K default 0.5, DIN k = 2K, side "normal" = material along the surface normal or
            "reverse"). With ``T > 0`` the pattern is the development of the neutral surface
            ``S + δ n``, ``δ = ±K T`` (spec 6.1), ``panel.info["sheet"]`` holds the inside, neutral
            and outside lengths of every boundary edge and the forming data (bend radius and
            angle per bend line); ``T = 0`` gives the surface's own pattern.

    Returns:
        FlatPattern with ``.errors``, ``.report``, ``.export_dxf``, ``.export_svg``, ``.plot_png``.

    Raises:
        NotDevelopableError: θ_max > tol_deg (message gives θ_max, θ_rms, DD) and not best_effort.
        SheetError: a bad thickness/K-factor/side or a thickness beyond a bending radius.
        GHTError: unsupported input or bad arguments.
    """
    sheet = _sheet_arg(sheet, thickness, k_factor, din_k_factor, side)
    if isinstance(surface_or_face, (list, tuple)):
        return unroll_composite(
            surface_or_face, best_effort=best_effort, tol_deg=tol_deg, rulings=rulings, samples=samples, units=units,
            sheet=sheet,
        )
    _check_args(tol_deg, rulings, samples, units)
    if isinstance(surface_or_face, RuledSurface):
        return unroll_ruled(
            surface_or_face,
            best_effort=best_effort,
            tol_deg=tol_deg,
            rulings=rulings,
            samples=samples,
            units=units,
            label=label,
            breakpoints=getattr(surface_or_face, "breakpoints", ()),
            sheet=sheet,
        )
    if hasattr(surface_or_face, "wrapped") or type(surface_or_face).__module__.startswith("OCP"):
        from ..core._kernel import adapter

        faces = adapter("shape_faces")(surface_or_face)
        if len(faces) > 1:  # a shell, solid or compound: one panel per face
            return unroll_composite(
                faces, best_effort=best_effort, tol_deg=tol_deg, rulings=rulings, samples=samples, units=units,
                sheet=sheet,
            )

        return adapter("unroll_face")(
            surface_or_face,
            best_effort=best_effort,
            tol_deg=tol_deg,
            rulings=rulings,
            samples=samples,
            units=units,
            label=label,
            sheet=sheet,
        )
    raise GHTError(
        f"cannot unroll a {type(surface_or_face).__name__}; allowed: a ght_cad RuledSurface, a "
        "build123d/cadquery Face or an OCP TopoDS_Face, or a list of them"
    )


_UNITS = ("mm", "cm", "m", "in", "ft", "unitless")


def _sheet_arg(sheet: Any, thickness: Any, k_factor: Any, din_k_factor: Any, side: str) -> Any:
    """The Sheet of ``sheet=`` or of the loose values (:func:`ght_cad.sheetmetal.sheet.make_sheet`); None
    when neither is given. Giving both is refused."""
    loose = thickness is not None or k_factor is not None or din_k_factor is not None or side != "normal"
    if sheet is None and not loose:
        return None
    from ..sheetmetal.sheet import Sheet, SheetError, make_sheet

    if sheet is not None:
        if loose:
            raise SheetError("give either sheet=Sheet(...) or thickness/k_factor/din_k_factor/side, not both")
        if not isinstance(sheet, Sheet):
            raise SheetError(f"sheet={sheet!r} is not allowed; give a ght_cad.sheet.Sheet (or thickness=..., k_factor=...)")
        return sheet
    if thickness is None:
        raise SheetError(f"side={side!r} or a K-factor was given without a thickness; give thickness=T (a length >= 0) too")
    return make_sheet(thickness, k_factor, din_k_factor=din_k_factor, side=side)


def _check_args(tol_deg: float, rulings: int, samples: int, units: str) -> None:
    if not (is_real(tol_deg) and math.isfinite(tol_deg) and tol_deg > 0):
        raise GHTError(f"tol_deg={tol_deg!r} is not allowed; it must be a finite angle > 0 in degrees")
    if isinstance(rulings, bool) or not isinstance(rulings, (int, np.integer)) or rulings < 0:
        raise GHTError(f"rulings={rulings!r} is not allowed; it must be an integer >= 0")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 9:
        raise GHTError(f"samples={samples!r} is not allowed; it must be an integer >= 9")
    if units not in _UNITS:
        raise GHTError(f"units={units!r} is not allowed; allowed units are {_UNITS}")


def unroll_composite(
    parts: Sequence[Any],
    *,
    best_effort: bool = False,
    tol_deg: float = DEFAULT_TOL_DEG,
    rulings: int = 16,
    samples: int = 257,
    units: str = "mm",
    labels: Sequence[str] | None = None,
    gap: float | None = None,
    sheet: Any = None,
    marks_on: str = "pattern",
    join: bool = False,
    join_label: str | None = None,
) -> FlatPattern:
    """Unroll several surfaces/faces into one pattern: one labelled panel per face, or with
    ``join`` one blank per set of surfaces that meet tangentially.

    Panels are laid side by side along +x (``gap`` between bounding boxes, default 5% of the
    largest panel). Boundary edges shared in 3-D by two panels (same points within 1e-6 of the
    model size, either direction) get matching edge marks: a label ``E<k>`` on both panels and
    ticks at the same 3-D arc-length fractions 0.2, 0.25, 0.5, 0.75 (double tick at the start).

    Args:
        parts: RuledSurfaces and/or faces.
        labels: panel labels (default P1, P2, ...).
        gap: spacing between panels in model units.
        best_effort, tol_deg, rulings, samples, units: as in :func:`unroll`.
        sheet: one :class:`ght_cad.sheetmetal.sheet.Sheet` for every part, or a sequence of them (one per
            part, None for none): each panel is its part's neutral surface.
        marks_on: ``"pattern"``: edges are matched on the panels' own 3-D edges (the neutral
            surfaces' with a sheet); ``"design"``: on the design surfaces' edges at the same
            parameters, so panels whose neutral surfaces part along a shared rail (plates of
            surfaces meeting at an angle: the offsets ``±K T n`` differ there) still get their
            marks, at the same rail points (ruled parts; faces keep their own edges).
        join: ruled parts that share a whole boundary edge and meet there at G1 or smoother
            (tangent half-planes within ``tol_deg`` of each other, on opposite sides) become one
            panel (:func:`ght_cad.sheetmetal.join_panels.join_panels`: every part developed as on its own,
            placed by the rigid motion that continues its neighbour across the shared edge, the
            joint a bend line or marks); parts meeting at an angle (chines) stay apart with marks.
        join_label: the label of a blank made of all parts (default: the labels joined by ``+``).

    Returns:
        FlatPattern with one panel per part (per blank with ``join``); ``.report`` aggregates all panels.

    Raises:
        GHTError: an empty list, a label count that does not match, an unknown ``marks_on``.
    """
    parts = list(parts)
    if not parts:
        raise GHTError("parts is empty; unroll_composite needs at least one surface or face")
    if labels is None:
        labels = [f"P{i + 1}" for i in range(len(parts))]
    if len(labels) != len(parts):
        raise GHTError(f"{len(labels)} labels given for {len(parts)} parts; give one label per part")
    sheets = list(sheet) if isinstance(sheet, (list, tuple)) else [sheet] * len(parts)
    if len(sheets) != len(parts):
        raise GHTError(f"{len(sheets)} sheets given for {len(parts)} parts; give one sheet (or None) per part")
    if marks_on not in ("pattern", "design"):
        raise GHTError(f"marks_on={marks_on!r} is not allowed; allowed: 'pattern', 'design'")
    panels: list[FlatPanel] = []
    conormals: list[Any] = []  # per panel, for join: the inward conormals of its design surface's edges
    swap: list[tuple[Any, np.ndarray]] = []  # (edge, design points) for marks_on="design"
    for part, lab, sh in zip(parts, labels, sheets):
        pat = unroll(part, best_effort=best_effort, tol_deg=tol_deg, rulings=rulings, samples=samples, units=units, label=lab,
                     sheet=sh)
        panels.extend(pat.panels)
        if join:
            from ..sheetmetal.join_panels import ruled_conormals

            ruled = isinstance(part, RuledSurface) and len(pat.panels) == 1
            conormals.extend([ruled_conormals(part) if ruled else None] * len(pat.panels))
        if marks_on == "design" and sh is not None and not sh.is_zero and isinstance(part, RuledSurface):
            for pn in pat.panels:
                for e in pn.loops[0]:
                    if e.name in RULED_EDGE_UV:
                        u, v = RULED_EDGE_UV[e.name](np.linspace(0.0, 1.0, len(e.xyz)))
                        swap.append((e, np.asarray(part.evaluate(u, v), dtype=float)))
    from ..pattern.flat_pattern import layout_panels, mark_shared_edges

    kept = [e.xyz for e, _ in swap]
    for e, pts in swap:
        e.xyz = pts
    try:
        if join:  # matched on the same edges as the marks (the design's with marks_on="design")
            from ..sheetmetal.join_panels import join_panels

            panels = join_panels(panels, conormals, tol_deg=tol_deg, label=join_label)
        mark_shared_edges(panels)
    finally:
        for (e, _), old in zip(swap, kept):
            e.xyz = old
        if swap:  # a blank's edges carry the design points they were matched on: their own again
            for e in (e for p in panels if "joints" in p.info for lp in p.loops for e in lp):
                e.xyz = None
    layout_panels(panels, gap)
    return FlatPattern(panels, units=units)


class _CallableModule(types.ModuleType):
    """``ght_cad.unroll`` is this module, and calling it calls :func:`unroll` (the stable function
    of spec section 9): ``ght_cad.unroll(surface)``, ``from ght_cad import unroll; unroll(surface)``,
    ``import ght_cad.unroll`` and ``from ght_cad.unroll import unroll_composite`` all work, in any
    import order. ``__call__`` is :func:`unroll` itself and ``inspect.signature`` gives its
    signature."""

    __call__ = staticmethod(unroll)

    @property
    def __signature__(self) -> Any:
        import inspect

        return inspect.signature(unroll)


sys.modules[__name__].__class__ = _CallableModule
