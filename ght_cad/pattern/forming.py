r"""Forming data of a flat pattern's bend lines, as the pattern presents it: the row of one bend line
(:class:`FormingRow`), the plain-text forming table and the roll-bending chart PNG.

The rows are computed from the sheet's neutral surface by :func:`ght_cad.sheetmetal.sheet.forming_rows`
(spec section 6.1); the pattern (:meth:`ght_cad.pattern.flat_pattern.FlatPattern.forming_table`,
``plot_roll_chart``) only reads them back from ``panel.info["sheet"]``. Moved from
:mod:`ght_cad.sheetmetal.sheet` (issue 27) so that the flat pattern no longer imports the sheet, which
unrolls into flat patterns (the import cycle flat_pattern -> sheet -> flat_pattern);
:mod:`ght_cad.sheetmetal.sheet` imports every name back.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..core.errors import GHTError

__all__ = ["FormingRow", "forming_table_text", "plot_roll_chart"]


@dataclass
class FormingRow:
    """One bend line of a pattern (a ruling) with its roll-forming data.

    Attributes:
        line: 1-based bend-line number (0: the whole plate, constant radius).
        u: ruling parameter in [0, 1] of the (ruled) surface.
        radius_a, radius_b: neutral bending radius ``|ρ_0 + δ|`` at the two ends of the ruling
            (``inf`` where flat).
        angle_deg: angle the plate turns over this bend line's share (module doc), degrees.
        position: neutral arc length of the mid-line from the first ruling to this one.
        xy: where its label goes in the pattern (pattern coordinates, before panel placement).
    """

    line: int
    u: float
    radius_a: float
    radius_b: float
    angle_deg: float
    position: float
    xy: tuple[float, float] = (0.0, 0.0)

    def as_dict(self) -> dict[str, Any]:
        return {
            "line": self.line,
            "u": self.u,
            "radius_a": self.radius_a,
            "radius_b": self.radius_b,
            "angle_deg": self.angle_deg,
            "position": self.position,
        }

    def label(self, digits: int = 4) -> str:
        """Text of the DXF label: ``R<a>/<b> A<angle>°`` (``R<r>`` when both ends agree)."""
        fa, fb = _fmt_r(self.radius_a, digits), _fmt_r(self.radius_b, digits)
        r = f"R{fa}" if fa == fb else f"R{fa}/{fb}"
        return f"{'B' + str(self.line) + ' ' if self.line else ''}{r} A{self.angle_deg:.{max(digits - 2, 1)}f}deg"


def _fmt_r(r: float, digits: int) -> str:
    return "flat" if not math.isfinite(r) else f"{r:.{digits}g}"


def forming_table_text(rows: Sequence[FormingRow], units: str = "mm") -> str:
    """The forming rows as a plain-text table (bend line, u, radii at both ruling ends, angle, position)."""
    head = f"{'bend':>5} {'u':>9} {'R_a [' + units + ']':>14} {'R_b [' + units + ']':>14} {'angle [deg]':>12} {'at [' + units + ']':>12}"
    lines = [head]
    for r in rows:
        lines.append(
            f"{('all' if r.line == 0 else str(r.line)):>5} {r.u:9.6f} {_fmt_r(r.radius_a, 9):>14} {_fmt_r(r.radius_b, 9):>14} "
            f"{r.angle_deg:12.6f} {r.position:12.6g}"
        )
    return "\n".join(lines)


def plot_roll_chart(pattern: Any, path: Any, *, dpi: int = 120, title: str | None = None) -> Any:
    """Roll-bending chart PNG: neutral bending radius at both ruling ends along the plate (one
    subplot per panel; bend lines marked), written atomically.

    Raises:
        GHTError: the pattern has no sheet data (unrolled without a thickness).
    """
    from matplotlib.figure import Figure

    from ..core.io import atomic_path

    panels = [p for p in pattern.panels if p.info.get("sheet")]
    if not panels:
        raise GHTError("the pattern has no sheet data; unroll it with a thickness (sheet=...) for a roll-bending chart")
    fig = Figure(figsize=(8, 2.2 + 2.0 * len(panels)))
    for k, p in enumerate(panels):
        ax = fig.add_subplot(len(panels), 1, k + 1)
        sh = p.info["sheet"]
        ch = sh["chart"]
        pos = np.asarray(ch["position"])
        for key, style, name in (("radius_a", "b-", "a end"), ("radius_b", "g--", "b end")):
            r = np.asarray(ch[key], dtype=float)
            ax.plot(pos, np.where(np.isfinite(r), r, np.nan), style, lw=1.2, label=f"R ({name})")
        for row in sh["forming"]:
            if row["line"]:
                ax.axvline(row["position"], color="r", lw=0.4, ls=":")
        ax.set_ylabel(f"neutral radius [{pattern.units}]")
        ax.set_title(
            f"{p.label}: T={sh['thickness']:g}, K={sh['k_factor']:g} ({sh['side']}), {len(sh['forming'])} bend line(s)",
            fontsize=9,
        )
        ax.legend(fontsize=7, loc="best")
        ax.grid(True, lw=0.3)
    fig.axes[-1].set_xlabel(f"position along the plate (neutral mid-line) [{pattern.units}]")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format="png")
    return path
