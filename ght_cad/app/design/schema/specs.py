r"""The dataclasses of a validated design (:class:`Design` and its curve, join, surface, target,
optimize, unroll, output and sheet specs) and :class:`DesignError`. Moved from ``ght_cad/app/design/schema.py`` (issue 27); every name is importable from
:mod:`ght_cad.app.design.schema` (and, as before, the re-exported ones from :mod:`ght_cad.app.design`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ....core.errors import GHTError
from .constants import FIGURE_OUTPUTS, FILE_OUTPUTS, SHAPE_NAMES


class DesignError(GHTError):
    """An invalid design file: one line naming the file, the key and the allowed values."""


@dataclass
class CurveSpec:
    """One GHT-Bézier curve ``P(t) = Σ b_{i,m}(t; μ,ν,γ) P_i`` of a design."""

    name: str
    control_points: list[list[float]]
    mu: float = 0.0
    nu: float = 0.0
    gamma: float = 0.0


@dataclass
class JoinSpec:
    """Re-solve the first points of curve ``second`` so that it meets ``first`` (spec section 4)."""

    first: str
    second: str
    continuity: str = "G1"
    k: float = 1.0
    beta2: float = 0.0
    beta3: float = 0.0


@dataclass
class SegmentSpec:
    """One strip of a ``composite`` surface: an enveloping developable of control planes.

    Strip 0 is built from its planes (spec 5.2); strip i > 0 is joined to strip i-1 with
    ``continuity`` (G1/G2/G3) by :func:`ght_cad.developables.envelope.join_developable`, which re-solves
    its first ``r+1`` control planes (``r`` = the order) and keeps the others.
    """

    name: str
    planes: list[list[float]]
    mu: float = 0.0
    nu: float = 0.0
    gamma: float = 0.0
    continuity: str | None = None
    k: float = 1.0
    beta2: float = 0.0
    beta3: float = 0.0


@dataclass
class SurfaceSpec:
    """A surface of the design: ``type = "planes"`` (spec 5.2), ``"curves"`` (equal-parameter ruled
    strip, quasi-developable), ``"rails"`` (the exact developable loft between two curves, spec 5.7)
    or ``"composite"`` (several strips from control planes joined G1/G2/G3, spec 5.6). ``name`` is
    the surface's name in ``[[surfaces]]`` (None for a single ``[surface]``)."""

    type: str
    planes: list[list[float]] | None = None
    boundary_planes: list[list[float]] | None = None
    mu: float = 0.0
    nu: float = 0.0
    gamma: float = 0.0
    curve_a: str | None = None
    curve_b: str | None = None
    normalize: bool = False
    segments: list[SegmentSpec] | None = None
    orientation: str = "auto"
    name: str | None = None
    #: where the surface is in the file (``surface`` or ``surfaces[i]``), for error messages
    key: str = "surface"
    #: ``[surfaces.sheet]``: this surface's overrides of the design's ``[sheet]`` (any of
    #: ``thickness``, ``k_factor``, ``side``; None: the design's sheet as it is)
    sheet: dict[str, Any] | None = None
    #: ``type = "approximate"``: the target (:class:`TargetSpec`), the tolerance (both ways, in the
    #: design's unit), the largest panel count, the parameter the rulings run along and how each
    #: strip is fitted (``auto``, ``loft`` or ``dual``: :func:`ght_cad.approximate` ``method``)
    target: "TargetSpec | None" = None
    tol: float = 0.0
    max_panels: int = 64
    direction: str = "auto"
    method: str = "auto"
    #: ``type = "approximate"``: cover a trimmed STEP face over its whole (u, v) box knowingly
    untrimmed: bool = False


@dataclass
class TargetSpec:
    """The target of an ``approximate`` surface (``[surfaces.target]``): a face of a STEP file
    (``step``: path relative to the design file, ``face``: 1-based), a GHT patch (``control_points``
    net (m+1) x (n+1) x 3 and ``mu_u`` ... ``gamma_v``) or a NURBS patch (``poles`` net, ``knots_u``,
    ``knots_v``, ``degree_u``, ``degree_v``, optional ``weights``)."""

    kind: str  # "step", "ght" or "nurbs"
    step: str | None = None
    face: int = 1
    control_points: list[list[list[float]]] | None = None
    shape: dict[str, float] = field(default_factory=dict)
    knots_u: list[float] | None = None
    knots_v: list[float] | None = None
    degree_u: int = 3
    degree_v: int = 3
    weights: list[list[float]] | None = None


@dataclass
class OptimizeSpec:
    """Shape-parameter optimization (spec sections 7, 8)."""

    method: str = "hybrid"
    objective: str = "CVEn"
    weights: list[float] = field(default_factory=lambda: [1.0, 0.0, 0.0])
    parameters: list[str] = field(default_factory=lambda: list(SHAPE_NAMES))
    population: int = 20
    iterations: int = 40
    seed: int = 1


@dataclass
class UnrollSpec:
    """Flat-pattern options (see :func:`ght_cad.unroll`)."""

    rulings: int = 16
    tol_deg: float = 0.01
    #: points per boundary edge of the outline polylines (the DXF/SVG outline is that polygon)
    samples: int = 257
    #: "joined": strips/surfaces meeting at G1 or smoother are one blank; "per-surface": one panel each
    panels: str = "joined"


@dataclass
class OutputSpec:
    """Which files and figures to write."""

    files: list[str] = field(default_factory=lambda: list(FILE_OUTPUTS))
    figures: list[str] = field(default_factory=lambda: list(FIGURE_OUTPUTS))
    #: ``[outputs] chord_tol``: largest distance between a curved (not line, not circle) boundary edge
    #: and the arcs the DXF/SVG outline writes for it, in the design's units (None: 1e-3 mm,
    #: :attr:`ght_cad.pattern.flat_pattern.FlatPattern.chord_tol`); ``--chord-tol`` takes precedence
    chord_tol: float | None = None


@dataclass
class SheetSpec:
    """``[sheet]``: the plate the surface is made of (spec 6.1).

    Attributes:
        thickness: sheet thickness T >= 0 (0: the surface itself).
        k_factor: ANSI K-factor in [0, 1] (``din_k_factor = 2K`` in the file is converted).
        side: "normal" (material along the surface normal) or "reverse".
    """

    thickness: float
    k_factor: float = 0.5
    side: str = "normal"
    #: with several ``[[surfaces]]``: what ``side`` is measured on, ``"shell"`` (the shell's
    #: orientation: the first surface's normal carried consistently across the shared rails) or
    #: ``"surface"`` (each surface's own normal); one surface: its own normal either way
    side_reference: str = "shell"
    #: ``k_factor_table``: a :class:`ght_cad.sheetmetal.blank.KFactorTable` giving K by the surface's ``R / T``
    #: (R its smallest inside bending radius, :func:`ght_cad.app.design.build.table_k_factor`); until a
    #: built surface resolves it, ``k_factor`` is the table's largest K (the strictest neutral offset)
    k_factor_table: Any = None
    #: ``R / T`` the table was read at (set with ``k_factor`` when a built surface resolves it)
    k_factor_ratio: float | None = None

    def to_sheet(self) -> Any:
        """The :class:`ght_cad.sheetmetal.sheet.Sheet`."""
        from ....sheetmetal.sheet import Sheet

        return Sheet(self.thickness, self.k_factor, self.side)


@dataclass
class Design:
    """A validated design (see ``docs/design-files.md``)."""

    name: str
    units: str = "mm"
    curves: list[CurveSpec] = field(default_factory=list)
    joins: list[JoinSpec] = field(default_factory=list)
    surface: SurfaceSpec | None = None
    optimize: OptimizeSpec | None = None
    unroll: UnrollSpec = field(default_factory=UnrollSpec)
    outputs: OutputSpec = field(default_factory=OutputSpec)
    source: str = "<design>"
    sheet: SheetSpec | None = None
    #: every surface: ``[surface]`` gives one (``surface`` is then that one), ``[[surfaces]]`` one per
    #: entry (``surface`` is the only one for a single entry, else None)
    surfaces: list[SurfaceSpec] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.surfaces and self.surface is not None:
            self.surfaces = [self.surface]

    def to_dict(self) -> dict[str, Any]:
        """Plain-data form (as it would be written in TOML)."""
        from dataclasses import asdict

        d = asdict(self)
        d.pop("source")
        for sd in [d["surface"] or {}] + d["surfaces"]:
            sd.pop("key", None)
            if sd.get("type") != "approximate":  # the keys of an approximate surface only
                for k in ("target", "tol", "max_panels", "direction", "method", "untrimmed"):
                    sd.pop(k, None)
            if sd.get("sheet", 0) is None:  # no per-surface sheet overrides: as before
                sd.pop("sheet")
        if d["sheet"] is not None:
            tab = self.sheet.k_factor_table if self.sheet is not None else None
            for k in ("k_factor_table", "k_factor_ratio"):
                d["sheet"].pop(k)
            if tab is not None:  # as the file gives it: a table's name, or its [R/T, K] rows
                d["sheet"]["k_factor_table"] = (tab.name if tab.name in ("ansi", "din") else
                                                [[r, k] for r, k in zip(tab.ratios, tab.k_factors)])
        if d["sheet"] is not None and len(self.surfaces) <= 1:
            d["sheet"].pop("side_reference")  # one surface: its own normal (as before)
        if len(self.surfaces) <= 1 and all(s.name is None for s in self.surfaces):
            d.pop("surfaces")  # a single [surface]: as before
        if d["outputs"]["chord_tol"] is None:  # the default: as before (TOML has no null)
            d["outputs"].pop("chord_tol")
        return d
