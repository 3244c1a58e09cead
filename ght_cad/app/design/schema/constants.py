r"""The design schema's allowed values and limits: outputs and their file names, optimizers and
objectives, surface types, joins, continuities, units, size limits. Moved from ``ght_cad/app/design/schema.py`` (issue 27); every name is importable from
:mod:`ght_cad.app.design.schema` (and, as before, the re-exported ones from :mod:`ght_cad.app.design`).
"""

from __future__ import annotations


#: file outputs a design may request
FILE_OUTPUTS = ("step", "dxf", "svg", "json", "md")


#: figures a design may request (PNG)
FIGURE_OUTPUTS = ("basis", "curve", "curvature", "surface", "flat_pattern", "convergence", "deviation")


#: optimizers
METHODS = ("hybrid", "pso", "gwo", "igwo")


#: objectives: fairness of the dual curve (planes) or developability R (curve-pair strips)
PLANE_OBJECTIVES = ("AL", "En", "CVEn", "weighted")


STRIP_OBJECTIVES = ("R",)


#: objectives of a ``rails`` surface (the developable loft, :data:`ght_cad.optimize.problems.loft.LOFT_OBJECTIVES`) and their
#: weighted sum ``w0 fan_share + w1 fairness + w2 regression``
RAILS_OBJECTIVES = ("fan_share", "fairness", "regression", "weighted")


SURFACE_TYPES = ("planes", "curves", "rails", "composite", "approximate")


#: the strips of an ``approximate`` surface: the parameter the rulings run along, or seams along the
#: diagonals of the parameter box (= :data:`ght_cad.approximation.DIRECTIONS`)
APPROX_DIRECTIONS = ("auto", "u", "v", "diagonal", "antidiagonal")


#: how each strip of an ``approximate`` surface is fitted (:func:`ght_cad.approximate` ``method``):
#: ``auto`` the closer of the rails loft and the dual fit of the tangent planes (spec 10.1),
#: ``loft`` the rails loft only, ``dual`` the dual fit wherever it is usable
APPROX_METHODS = ("auto", "loft", "dual")


#: largest ``max_panels`` of an ``approximate`` surface (each panel is a developable loft)
MAX_APPROX_PANELS = 256


#: largest degree of an inline NURBS target (and rows/columns of a target net: :data:`MAX_ROWS`)
MAX_TARGET_DEGREE = 25


#: orientations of the second rail of a ``rails`` surface (:func:`ght_cad.developable_loft`)
RAIL_ORIENTATIONS = ("auto", "same", "reversed")


#: joins between the strips of a composite surface (spec 5.6)
STRIP_JOINS = ("G1", "G2", "G3")


CONTINUITIES = ("C0", "C1", "C2", "C3", "G0", "G1", "G2", "G3")


UNITS = ("mm", "cm", "m", "in", "ft")


#: what ``sheet.side`` refers to with several surfaces (``SheetSpec.side_reference``)
SIDE_REFERENCES = ("shell", "surface")


SHAPE_NAMES = ("mu", "nu", "gamma")


# output file names inside the output folder
FILE_NAMES = {
    "step": "model.step",
    "dxf": "flat_pattern.dxf",
    "svg": "flat_pattern.svg",
    "json": "report.json",
    "md": "report.md",
}


FIGURE_NAMES = {k: f"{k}.png" for k in FIGURE_OUTPUTS}


#: largest coordinate (or plane coefficient) a design file may give, in its unit (as for STEP input)
MAX_DESIGN_COORDINATE = 1e12


#: most control points (planes) of one curve (surface) in a design file: degree 999 (an unused
#: curve of 100,000 points allocated 1.7 GiB, one of 2,000,000 ran past 120 s)
MAX_ROWS = 1000


#: largest ``unroll.samples * (unroll.rulings + 1)``: the flat pattern's grid (20001 x 1001 inside the
#: single ranges allocated 8.9 GiB; the defaults are 257 x 17)
MAX_UNROLL_GRID = 1_000_000


#: the values of ``[unroll] panels``
PANELS_CHOICES = ("joined", "per-surface")
