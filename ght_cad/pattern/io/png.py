"""PNG preview of a flat pattern (matplotlib's object API, Agg; no pyplot).

Moved from :class:`ght_cad.pattern.flat_pattern.FlatPattern` (issue 27): the method ``plot_png`` calls
:func:`plot_png`. ``pattern`` is a :class:`ght_cad.pattern.flat_pattern.FlatPattern`.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from ...core.io import atomic_path


def plot_png(pattern: Any, path: str | os.PathLike, *, dpi: int = 120, title: str | None = None) -> Path:
    """Write ``pattern`` (a :class:`ght_cad.pattern.flat_pattern.FlatPattern`): the body of
    :meth:`ght_cad.pattern.flat_pattern.FlatPattern.plot_png`, whose docstring states the format."""
    from matplotlib.figure import Figure  # object API: no pyplot, no global backend switch

    fig = Figure(figsize=(8, 6))
    ax = fig.add_subplot(111)
    for lp in pattern.outlines:
        c = np.vstack([lp, lp[:1]])
        ax.plot(c[:, 0], c[:, 1], "k-", lw=1.0)
    for p, q in pattern.bend_lines:
        ax.plot([p[0], q[0]], [p[1], q[1]], "r--", lw=0.6)
    for mk in pattern.marks:
        ax.plot(mk[:, 0], mk[:, 1], "b-", lw=1.0)
    for x, y, s, h in pattern.labels:
        ax.text(x, y, s, ha="center", va="center", color="green", fontsize=9)
    for x, y, s, h, a in pattern.forming_labels:  # sheet: bend radius and angle along each bend line
        ax.text(x, y, s, ha="center", va="center", color="magenta", fontsize=5, rotation=a)
    for x, y, s, h, a in pattern.bend_labels:  # a blank's bends: direction, angle, inside radius
        ax.text(x, y, s, ha="center", va="center", color="red", fontsize=5, rotation=a)
    ax.set_aspect("equal")
    ax.set_xlabel(pattern.units)
    e = pattern.errors
    ax.set_title(
        title
        or f"flat pattern: max rel. length/area error {e['max']:.1e}, angle {e['angle_deg']:.1e} deg",
        fontsize=9,
    )
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png")
    return Path(path)
