r"""Flat patterns: outline loops, bend lines, labels, distortion report and DXF/SVG/PNG export.

A :class:`FlatPattern` holds one :class:`FlatPanel` per unrolled surface/face. Every panel is
checked against its 3-D original (spec section 6) in a :class:`DistortionReport`:

* boundary length: relative error ``|ℓ_flat - ℓ_3d| / ℓ_3d`` per boundary edge; flat lengths by
  Romberg-extrapolated chord sums (``N, 2N, 4N`` uniform samples, error O(h⁶)), 3-D lengths by
  adaptive Gauss–Legendre quadrature of ``|c'|`` where available;
* ruling length: ``| |Y(u,1) - Y(u,0)| - |g(u)| | / |g(u)|`` at 129 rulings;
* area: ``|area_flat - area_3d| / area_3d``, flat area by Romberg-extrapolated shoelace sums over
  all loops (outer minus holes), 3-D area by quadrature of ``|X_u × X_v|``;
* angle: ``|angle(Y_u, Y_v) - angle(X_u, X_v)|`` in degrees on a parameter grid (first
  fundamental form), flat partials by 5-point central differences of the development map.

Exports write atomically through :mod:`ght_cad.core.io`; ezdxf and matplotlib are imported inside the
exporting methods only.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..core.errors import GHTError
from ..core.io import write_text_atomic
# The model, layout and writers live in ght_cad.pattern (issue 27); their names stay importable here.
from .io import dxf as _dxf_io
from .io import png as _png_io
from .io import svg as _svg_io
from .io.dxf import _dxf_ascii, arcs_to_rational_quadratic  # noqa: F401
from .io.svg import SVG_STROKE_MM, SVG_UNITS, svg_arc_path  # noqa: F401
from .forming import FormingRow, forming_table_text, plot_roll_chart
from .layout import (MARK_FRACTIONS, _interp_polyline, _polyline_param, _sagitta3, _shared_edge_candidates,
                             layout_panels, mark_shared_edges, shared_edge_pairs)  # noqa: F401
from .model import (_MM_PER_UNIT, _ROMBERG_ACCEPT, _ROMBERG_N, CHORD_TOL_MM, INSUNITS, BoundaryEdge,
                            DistortionReport, FlatPanel, _centroid, _chords, _get_xyz, _inside, _next,
                            _outline_serves_length, _point_in_polygon, _romberg_pair, _romberg_pairs, _sagitta,
                            _set_xyz, _shoelace, _unit_samples, clip_segments, default_chord_tol, measure_panel,
                            piecewise_romberg_length, piecewise_samples, points_bbox, romberg_length)  # noqa: F401

__all__ = [
    "BoundaryEdge",
    "FlatPanel",
    "FlatPattern",
    "DistortionReport",
    "measure_panel",
    "romberg_length",
    "layout_panels",
    "mark_shared_edges",
    "shared_edge_pairs",
    "INSUNITS",
    "SVG_UNITS",
    "CHORD_TOL_MM",
    "default_chord_tol",
]


class FlatPattern:
    """A flat pattern: one or more panels in the plane, with report and exports.

    Attributes:
        panels: the :class:`FlatPanel` list.
        units: length unit ("mm", "cm", "m", "in", "ft", "unitless").
    """

    def __init__(self, panels: Sequence[FlatPanel], units: str = "mm") -> None:
        if units not in INSUNITS:
            raise GHTError(f"units={units!r} is not allowed; allowed units are {tuple(INSUNITS)}")
        self.panels = list(panels)
        self.units = units
        #: default chord tolerance of the DXF/SVG outlines (pattern units): 1e-3 mm
        self.chord_tol = default_chord_tol(units)

    # -- geometry ------------------------------------------------------------------------
    @property
    def outlines(self) -> list[np.ndarray]:
        """All closed loops (outer and holes of every panel), (n, 2) arrays, last point not repeated."""
        return [lp for p in self.panels for lp in p.loop_polylines()]

    @property
    def outline(self) -> np.ndarray:
        """Outer loop of the first panel, (n, 2) (last point not repeated)."""
        return self.panels[0].loop_polylines()[0]

    def outline_arcs(self, chord_tol: float | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
        """All closed loops as lines and circular arcs (:meth:`FlatPanel.loop_arcs`): per loop
        ``(points (n, 2), bulges (n,))``, segment i from ``points[i]`` to ``points[i + 1 mod n]``
        with DXF bulge ``tan(θ/4)``.

        Args:
            chord_tol: largest distance between an exact flat edge and its arcs, pattern units
                (None: :attr:`chord_tol`, 1e-3 mm by default). Straight and circular edges are
                written exactly whatever the tolerance.
        """
        tol = self._chord_tol(chord_tol)
        return [(p, b) for panel in self.panels for p, b, _ in panel.loop_arcs(tol)]

    def _chord_tol(self, chord_tol: float | None) -> float:
        tol = self.chord_tol if chord_tol is None else chord_tol
        try:
            ok = float(tol) > 0 and math.isfinite(float(tol))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise GHTError(f"chord_tol={tol!r} is not allowed; allowed: a positive length in the pattern's "
                           f"units ({self.units})")
        return float(tol)

    @property
    def outer_outlines(self) -> list[np.ndarray]:
        return [p.loop_polylines()[0] for p in self.panels]

    @property
    def bend_lines(self) -> np.ndarray:
        """All bend lines (rulings), shape (k, 2, 2)."""
        arrs = [p.bend_lines for p in self.panels if p.bend_lines.size]
        return np.concatenate(arrs, axis=0) if arrs else np.zeros((0, 2, 2))

    @property
    def marks(self) -> list[np.ndarray]:
        return [m for p in self.panels for m in p.marks]

    @property
    def labels(self) -> list[tuple[float, float, str, float]]:
        """(x, y, text, height) of every label (panel labels and edge marks)."""
        return [t for p in self.panels for t in p.texts]

    def map(self, u: Any, v: Any) -> np.ndarray:
        """Flat image of surface parameters of the (single) panel."""
        if len(self.panels) != 1:
            raise GHTError(f"map() needs a single-panel pattern; this one has {len(self.panels)} panels")
        return self.panels[0].map(u, v)

    @property
    def area(self) -> float:
        return float(sum(p.area_flat for p in self.panels))

    @property
    def forming_labels(self) -> list[tuple[float, float, str, float, float]]:
        """(x, y, text, height, rotation deg) of the sheet forming labels (bend radius and angle)."""
        return [t for p in self.panels for t in p.forming_texts]

    @property
    def bend_labels(self) -> list[tuple[float, float, str, float, float]]:
        """Bend annotations of all panels (x, y, text, height, rotation in degrees): layer BEND."""
        return [t for p in self.panels for t in p.bend_texts]

    @property
    def sheet(self) -> dict[str, Any] | None:
        """Sheet data of the first panel unrolled with a thickness (``panel.info["sheet"]``:
        thickness, K, side, edge lengths inside/neutral/outside, forming rows), else None."""
        for p in self.panels:
            if p.info.get("sheet"):
                return p.info["sheet"]
        return None

    def forming_table(self) -> str:
        """Plain-text forming tables (one per panel unrolled with a thickness; :mod:`ght_cad.sheetmetal.sheet`,
        :func:`ght_cad.pattern.forming.forming_table_text`)."""
        out = []
        for p in self.panels:
            sh = p.info.get("sheet")
            if sh:
                rows = [FormingRow(**r) for r in sh["forming"]]
                out.append(f"{p.label}: T={sh['thickness']:g} K={sh['k_factor']:g} side={sh['side']}\n"
                           + forming_table_text(rows, self.units))
        return "\n\n".join(out)

    def plot_roll_chart(self, path: str | os.PathLike, *, dpi: int = 120, title: str | None = None) -> Path:
        """Roll-bending chart PNG (:func:`ght_cad.pattern.forming.plot_roll_chart`)."""
        plot_roll_chart(self, path, dpi=dpi, title=title)
        return Path(path)

    # -- report --------------------------------------------------------------------------
    @property
    def report(self) -> DistortionReport:
        """Distortion report over all panels."""
        reps = [p.report for p in self.panels if p.report is not None]
        return reps[0] if len(reps) == 1 else DistortionReport.combine(reps)

    @property
    def errors(self) -> dict[str, float]:
        """Max relative errors: boundary_length, ruling_length, area, max; angle_deg (degrees)."""
        d = self.report.as_dict()
        out = {
            "boundary_length": d["boundary_length"]["max"],
            "ruling_length": d["ruling_length"]["max"],
            "area": d["area"]["max"],
            "angle_deg": d["angle_deg"]["max"],
        }
        out["max"] = max(out["boundary_length"], out["ruling_length"], out["area"])
        return out

    def summary(self) -> str:
        lines = [f"flat pattern: {len(self.panels)} panel(s), units {self.units}, area {self.area:.9g}"]
        lines.append(self.report.summary())
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"FlatPattern(panels={len(self.panels)}, units={self.units!r}, max_error={self.errors['max']:.2e})"

    # -- exports -------------------------------------------------------------------------
    def export_dxf(self, path: str | os.PathLike, *, spline: bool = False, chord_tol: float | None = None) -> Path:
        """Write a DXF (R2010) with layers OUTLINE, BEND, LABELS, MARKS (and FORMING for a sheet:
        bend radius and angle of every bend line, rotated along it); $INSUNITS from units.

        OUTLINE: every loop as one closed LWPOLYLINE of lines and circular arcs (vertex bulges,
        :meth:`outline_arcs`): a straight edge is one segment, a circular edge (a cone's rail) one
        arc, other edges arcs within ``chord_tol`` of the exact development; corners are the
        development's. ``spline=True``: every loop as one SPLINE carrying the same lines and arcs
        exactly as control data (rational quadratic: control points, weights, knots; no fit
        points). BEND: bend lines as LINEs with linetype DASHED. LABELS: TEXT. MARKS: edge-mark
        ticks. Without ezdxf (FreeCAD's Python) a plain R12 file with the same layers and the same
        outline arcs is written (:meth:`dxf_r12_text`).

        Args:
            path: the file to write (atomically).
            spline: loops as SPLINE entities instead of LWPOLYLINEs.
            chord_tol: outline chord tolerance in the pattern's units (None: :attr:`chord_tol`).

        Returns:
            The path written.
        """
        return _dxf_io.export_dxf(self, path, spline=spline, chord_tol=chord_tol)

    def dxf_r12_text(self, chord_tol: float | None = None) -> str:
        """Minimal ASCII DXF R12 (no ezdxf needed): LTYPE DASHED, layers OUTLINE/BEND/LABELS/MARKS,
        every outline loop one closed POLYLINE of lines and arcs (VERTEX bulges, group 42; the
        same geometry as :meth:`export_dxf`), LINEs, TEXT; ``$INSUNITS`` in the header.
        Coordinates and bulges are written to 17 significant digits (they read back exactly).

        Args:
            chord_tol: outline chord tolerance in the pattern's units (None: :attr:`chord_tol`).
        """
        return _dxf_io.dxf_r12_text(self, chord_tol)

    def svg_text(self, margin: float | None = None, chord_tol: float | None = None) -> str:
        """The SVG document as a string (see :meth:`export_svg`).

        Every outline loop is one closed ``<path>`` of ``L`` (straight) and ``A`` (circular arc)
        commands, the same lines and arcs as the DXF (:meth:`outline_arcs`).

        The viewBox is in model units; ``width``/``height`` are the same extent in an SVG length
        unit (:data:`SVG_UNITS`: ``width = (extent + 2 margin) × scale`` with m → mm × 1000,
        ft → in × 12, mm/cm/in × 1), so the drawing prints at true scale. Lines are
        :data:`SVG_STROKE_MM` (0.25 mm) wide at that scale and bend-line dashes ``span / 130``
        long, kept within 1..10 mm (a unitless pattern: width ``span / 800``, dashes ``6×`` that).

        Args:
            margin: blank border in model units (default 3 % of the larger extent).
            chord_tol: outline chord tolerance in the pattern's units (None: :attr:`chord_tol`).

        Returns:
            The SVG text.
        """
        return _svg_io.svg_text(self, margin, chord_tol)

    def export_svg(self, path: str | os.PathLike, *, chord_tol: float | None = None) -> Path:
        """Write an SVG: groups (Inkscape layers) OUTLINE (one path of lines and arcs per loop),
        BEND (dashed), MARKS, LABELS; true-scale size in mm, cm or in (m and ft converted, see
        :meth:`svg_text`)."""
        return write_text_atomic(path, self.svg_text(chord_tol=chord_tol))

    def plot_png(self, path: str | os.PathLike, *, dpi: int = 120, title: str | None = None) -> Path:
        """PNG preview (matplotlib Agg): outline, dashed bend lines, marks, labels (and a sheet's
        forming labels), error summary."""
        return _png_io.plot_png(self, path, dpi=dpi, title=title)

    def to_face(self) -> Any:
        """Planar build123d Face(s) of the pattern (outline + holes); a list for composites."""
        from ..core._kernel import adapter

        faces = adapter("flat_faces")(self)
        return faces[0] if len(faces) == 1 else faces
