"""Quarter cone frustum designs for the batch tests (tests/test_batch.py) and bench/bench_batch.py.

Spec section 1, exact circles: planes ``(-k h, 1, 0, k), (-k h, 1, 1, k), (-k h, 0, 1, k)`` with
gamma = -1 and the boundary planes z = 0, z = z1: apex at height h, radius ``k (h - z)``, slant
distance ``rho(z) = (h - z) sqrt(1 + k^2)``; the flat pattern is an annular sector of area
``A = (pi / 4) k sqrt(1 + k^2) (h^2 - (h - z1)^2)``.
"""

from __future__ import annotations

import math


def cone_design(name: str, h: float, k: float, z1: float, figures: str = '["flat_pattern"]') -> str:
    """Design text (TOML) of the quarter cone frustum (apex height h, radius k (h - z), cut at z = 0
    and z = z1) with the full ``ght-cad run`` outputs (STEP, DXF, SVG, JSON, Markdown) and
    ``figures`` (a TOML array)."""
    return f"""name = "{name}"
units = "mm"

[surface]
type = "planes"
planes = [[{-k * h!r}, 1, 0, {k!r}], [{-k * h!r}, 1, 1, {k!r}], [{-k * h!r}, 0, 1, {k!r}]]
boundary_planes = [[0, 0, 0, 1], [{-z1!r}, 0, 0, 1]]
mu = 0.0
nu = 0.0
gamma = -1.0
normalize = false

[unroll]
rulings = 8
tol_deg = 0.001

[outputs]
files = ["step", "dxf", "svg", "json", "md"]
figures = {figures}
"""


def cone_area(h: float, k: float, z1: float) -> float:
    """Flat-pattern area ``A = (pi / 4) k sqrt(1 + k^2) (h^2 - (h - z1)^2)`` of :func:`cone_design`."""
    return math.pi / 4 * k * math.sqrt(1 + k * k) * (h * h - (h - z1) ** 2)
