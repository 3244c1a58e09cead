r"""The blank's data: the error, the skin an adapter hands over (:class:`SkinFace`,
:class:`SheetSkin`), one blank (:class:`Blank`), its bend-table rows (:func:`bend_row`) and the
result of unfolding several skins (:class:`Unfolded`). Moved from ``ght_cad/sheetmetal/blank.py`` (issue 27);
every name is importable from :mod:`ght_cad.sheetmetal.blank`."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ...core.errors import GHTError


class BlankError(GHTError):
    """A solid cannot be made into one blank: no sheet, an ambiguous skin, a sharp edge, a face
    that is not developable, pieces that overlap in the plane. The message names the face/edge
    and the measured value."""



# -- the skin --------------------------------------------------------------------------------------
@dataclass
class SkinFace:
    """One face of a sheet's skin as an adapter describes it.

    Attributes:
        number: 1-based face number in the source shape (reports name faces ``F<number>``).
        data: the face (:class:`ght_cad.unrolling.face_unroll.FaceData`); its edges' ``name`` is the solid's
            edge key (e.g. ``E12``), the same in both faces sharing the edge; ``data.reversed``
            makes the normal the solid's outward normal.
        area: 3-D area (the default base face is the largest planar face).
        partner: face number of the opposite skin face (None when unknown).
    """

    number: int
    data: Any
    area: float
    partner: int | None = None


@dataclass
class SheetSkin:
    """The skin of one sheet solid (see module doc).

    Attributes:
        name: the solid's name (``S1``, ...).
        thickness: sheet thickness ``T``.
        faces: the skin's faces.
        shared: edge key -> the two face numbers of the skin faces sharing it.
        walls: face numbers of the solid's faces that are not skin (thickness walls, cut faces,
            the other skin), for the report.
    """

    name: str
    thickness: float
    faces: list[SkinFace]
    shared: dict[str, tuple[int, int]]
    walls: list[int] = field(default_factory=list)


@dataclass
class Blank:
    """The blank of one sheet solid.

    Attributes:
        name: the solid's name.
        panels: one :class:`ght_cad.pattern.flat_pattern.FlatPanel` (several with ``allow_split``).
        thickness: ``T``.
        bends: the bend table, one dict per bend (:func:`bend_row`).
        base_face: face number of the base face (it keeps its own flat coordinates).
        faces: skin face numbers in the order they were placed.
        cut_edges: shared edges cut to open cycles of the face graph.
        placement_residual: largest ``| |a1 - a0| - |q1 - q0| |`` of the shared edges' flat
            chords (the two faces' images of one edge), relative to the chord.
        area_faces: sum of the faces' own flat areas (equals the panel's area when nothing
            overlaps).
    """

    name: str
    panels: list[Any]
    thickness: float
    bends: list[dict[str, Any]]
    base_face: int
    faces: list[int]
    cut_edges: list[str]
    placement_residual: float
    area_faces: float

    def as_dict(self) -> dict[str, Any]:
        """Plain dict for reports and JSON."""
        return {"name": self.name, "thickness": self.thickness, "base_face": self.base_face, "faces": self.faces,
                "cut_edges": self.cut_edges, "panels": [p.label for p in self.panels],
                "area": float(sum(p.area_flat for p in self.panels)), "area_faces": self.area_faces,
                "placement_residual": self.placement_residual, "bends": self.bends}


def bend_row(name: str, face: int, kind: str, angle: float, radius: float, thickness: float, k: float,
             up: bool, allowance: float | None = None) -> dict[str, Any]:
    r"""One bend-table row.

    ``BA = (R + K T) A`` (the neutral arc of a circular bend; ``allowance`` overrides it for a
    cone or freeform bend: the measured distance of the bend lines), ``OSSB = (R + T) tan(A/2)``,
    ``BD = 2 OSSB - BA``.

    Args:
        name: bend name (``B1`` ...); face: its skin face number; kind: surface kind.
        angle: bend angle ``A`` in radians; radius: inside radius ``R``; thickness: ``T``; k: K.
        up: the bend turns towards the viewer (the skin's outward normal is +z in the flat).
    """
    ba = (radius + k * thickness) * angle if allowance is None else allowance
    ossb = (radius + thickness) * math.tan(0.5 * angle) if angle < math.pi else math.inf
    return {"bend": name, "face": face, "kind": kind, "angle_deg": math.degrees(angle), "inside_radius": radius,
            "k_factor": k, "thickness": thickness, "bend_allowance": ba, "bend_deduction": 2 * ossb - ba,
            "direction": "up" if up else "down"}


@dataclass
class Unfolded:
    """Result of :func:`unfold_skins` / ``ght_cad.unfold``.

    Attributes:
        pattern: a :class:`ght_cad.pattern.flat_pattern.FlatPattern` with one panel per solid (labelled
            with the solid's name; several per solid only with ``allow_split``), laid out in rows.
        blanks: one :class:`Blank` per solid, in the shape's order.
        face_count: faces of the source shape.
    """

    pattern: Any
    blanks: list[Blank]
    face_count: int = 0

    @property
    def bends(self) -> list[dict[str, Any]]:
        """All bend-table rows, each with its ``blank`` name."""
        return [{"blank": b.name, **row} for b in self.blanks for row in b.bends]

    def bend_table(self) -> str:
        """The bend table as text (one line a bend)."""
        lines = ["bend  face  direction  angle [deg]  inside R  K       allowance    deduction"]
        for r in self.bends:
            lines.append(f"{r['blank']}:{r['bend']:<4} F{r['face']:<4} {r['direction']:<9} {r['angle_deg']:11.6g}  "
                         f"{r['inside_radius']:8.6g}  {r['k_factor']:.4g}  {r['bend_allowance']:11.9g}  "
                         f"{r['bend_deduction']:11.9g}")
        return "\n".join(lines)

    def as_dict(self) -> dict[str, Any]:
        """Plain dict: the blanks (:meth:`Blank.as_dict`) and the total area."""
        return {"blanks": [b.as_dict() for b in self.blanks], "area": float(self.pattern.area),
                "panels": len(self.pattern.panels)}
