"""SVG writer of a flat pattern: Inkscape layers, outline loops as paths of lines and arcs, true scale.

Moved from :class:`ght_cad.pattern.flat_pattern.FlatPattern` (issue 27): the methods ``svg_text`` and
``export_svg`` call these functions. ``pattern`` is a :class:`ght_cad.pattern.flat_pattern.FlatPattern`.
"""

from __future__ import annotations

import math
from typing import Any, Callable
from xml.sax.saxutils import escape

import numpy as np

from ..model import _MM_PER_UNIT, points_bbox


#: SVG width/height unit and scale per model unit: SVG lengths know mm, cm, in (not m, ft), so
#: ``1 m = 1000 mm`` and ``1 ft = 12 in``; the viewBox stays in model units (true-scale print).
SVG_UNITS = {
    "unitless": ("", 1.0),
    "mm": ("mm", 1.0),
    "cm": ("cm", 1.0),
    "m": ("mm", 1000.0),
    "in": ("in", 1.0),
    "ft": ("in", 12.0),
}

#: SVG stroke width of every line at true scale, millimetres
SVG_STROKE_MM = 0.25


def svg_arc_path(points: np.ndarray, bulges: np.ndarray, tr: Callable[[np.ndarray], tuple[float, float]]) -> str:
    """SVG path data of a closed chain of lines and arcs: ``M`` the first point, then per segment
    ``L x y`` (bulge 0) or ``A r r 0 large sweep x y`` with ``r = L / (2 |sin(θ/2)|)``,
    ``large = |θ| > π`` and ``sweep = (b < 0)`` (``tr`` flips y: a counter-clockwise arc is drawn
    with sweep flag 0), then ``Z``; coordinates through ``tr`` (model -> SVG user units)."""
    p = np.asarray(points, dtype=float)
    xy = [tr(v) for v in p]
    d = [f"M{xy[0][0]:.12g},{xy[0][1]:.12g}"]
    for i, b in enumerate(np.asarray(bulges, dtype=float).tolist()):
        j = (i + 1) % len(xy)
        x, y = xy[j]
        if b == 0.0:
            d.append(f"L{x:.12g},{y:.12g}")
            continue
        th = 4.0 * math.atan(b)
        r = math.hypot(*(p[j] - p[i])) / (2.0 * abs(math.sin(0.5 * th)))
        d.append(f"A{r:.15g},{r:.15g} 0 {int(abs(th) > math.pi)} {int(b < 0)} {x:.12g},{y:.12g}")
    d.append("Z")
    return " ".join(d)


def svg_text(pattern: Any, margin: float | None = None, chord_tol: float | None = None) -> str:
    """The text of ``pattern`` (a :class:`ght_cad.pattern.flat_pattern.FlatPattern`): the body of
    :meth:`ght_cad.pattern.flat_pattern.FlatPattern.svg_text`, whose docstring states the format."""
    arcs = pattern.outline_arcs(chord_tol)
    pts = np.concatenate(pattern.outlines, axis=0)
    lo, hi = points_bbox(pts)
    span = float(np.max(hi - lo))
    m = 0.03 * span if margin is None else float(margin)
    W, H = float(hi[0] - lo[0]) + 2 * m, float(hi[1] - lo[1]) + 2 * m

    def tr(p: np.ndarray) -> tuple[float, float]:
        return float(p[0] - lo[0] + m), float(hi[1] - p[1] + m)

    unit, scale = SVG_UNITS[pattern.units]
    mm = _MM_PER_UNIT.get(pattern.units)  # millimetres per model unit (None: unitless)
    if mm is None:  # no physical size: lines and dashes relative to the drawing
        sw, dash = span / 800.0, 6 * span / 800.0
    else:  # printed/cut at true scale: 0.25 mm lines, dashes of span/130 within 1..10 mm
        sw = SVG_STROKE_MM / mm
        dash = min(max(span / 130.0, 1.0 / mm), 10.0 / mm)
    out = [
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>',
        f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" '
        f'version="1.1" width="{W * scale:.9g}{unit}" height="{H * scale:.9g}{unit}" viewBox="0 0 {W:.9g} {H:.9g}">',
        f'<g id="OUTLINE" inkscape:groupmode="layer" inkscape:label="OUTLINE" fill="none" stroke="black" stroke-width="{sw:.6g}">',
    ]
    for loop_pts, bulges in arcs:
        out.append(f'<path d="{svg_arc_path(loop_pts, bulges, tr)}"/>')
    out.append("</g>")
    out.append(
        f'<g id="BEND" inkscape:groupmode="layer" inkscape:label="BEND" fill="none" stroke="red" '
        f'stroke-width="{sw:.6g}" stroke-dasharray="{dash:.6g},{dash / 2:.6g}">'
    )
    for p, q in pattern.bend_lines:
        (x1, y1), (x2, y2) = tr(p), tr(q)
        out.append(f'<line x1="{x1:.9g}" y1="{y1:.9g}" x2="{x2:.9g}" y2="{y2:.9g}"/>')
    for x, y, s, h, a in pattern.bend_labels:
        X, Y = tr(np.array([x, y]))
        out.append(f'<text x="{X:.9g}" y="{Y:.9g}" font-size="{h:.6g}" text-anchor="middle" dominant-baseline="middle" '
                   f'fill="red" stroke="none" transform="rotate({-a:.6g} {X:.9g} {Y:.9g})">{escape(s)}</text>')
    out.append("</g>")
    out.append(f'<g id="MARKS" inkscape:groupmode="layer" inkscape:label="MARKS" stroke="blue" stroke-width="{sw:.6g}">')
    for mk in pattern.marks:
        (x1, y1), (x2, y2) = tr(mk[0]), tr(mk[1])
        out.append(f'<line x1="{x1:.9g}" y1="{y1:.9g}" x2="{x2:.9g}" y2="{y2:.9g}"/>')
    out.append("</g>")
    out.append('<g id="LABELS" inkscape:groupmode="layer" inkscape:label="LABELS" fill="green" font-family="sans-serif">')
    for x, y, s, h in pattern.labels:
        X, Y = tr(np.array([x, y]))
        out.append(
            f'<text x="{X:.9g}" y="{Y:.9g}" font-size="{h:.6g}" text-anchor="middle" '
            f'dominant-baseline="middle">{escape(s)}</text>'
        )
    out.append("</g>")
    if pattern.forming_labels:
        out.append('<g id="FORMING" inkscape:groupmode="layer" inkscape:label="FORMING" fill="magenta" font-family="sans-serif">')
        for x, y, s, h, a in pattern.forming_labels:
            X, Y = tr(np.array([x, y]))
            out.append(
                f'<text x="{X:.9g}" y="{Y:.9g}" font-size="{h:.6g}" text-anchor="middle" dominant-baseline="middle" '
                f'transform="rotate({-a:.6g} {X:.9g} {Y:.9g})">{escape(s)}</text>'
            )
        out.append("</g>")
    out.append("</svg>")
    return "\n".join(out) + "\n"
