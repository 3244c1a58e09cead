"""DXF writers of a flat pattern: DXF R2010 through ezdxf and a hand-written ASCII R12 writer
(no ezdxf needed, e.g. in FreeCAD's Python); the same layers and outline arcs in both.

Moved from :class:`ght_cad.pattern.flat_pattern.FlatPattern` (issue 27): the methods ``export_dxf`` and
``dxf_r12_text`` call these functions. ``pattern`` is a :class:`ght_cad.pattern.flat_pattern.FlatPattern`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ...core.io import atomic_path, write_text_atomic
from ..model import INSUNITS


def _dxf_ascii(text: str) -> str:
    """Text for an ASCII DXF R12 file: every non-ASCII character as the DXF escape ``\\U+XXXX``
    (outside the BMP: ``?``; control characters, which would break the group-code/value lines, as
    spaces)."""
    out = []
    for ch in text:
        code = ord(ch)
        if code < 32:
            out.append(" ")
        elif code < 128:
            out.append(ch)
        elif code <= 0xFFFF:
            out.append(f"\\U+{code:04X}")
        else:  # outside the BMP (emoji ...): \U+ has four hex digits
            out.append("?")
    return "".join(out)


def arcs_to_rational_quadratic(points: np.ndarray, bulges: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A closed chain of lines and arcs as one exact rational quadratic B-spline.

    A segment ``p0 -> p1`` with bulge b (sweep ``θ = 4 atan b``, halved while ``|θ| > 90°``:
    ``b -> b / (1 + sqrt(1 + b²))``) has the control points ``p0, C, p1`` with
    ``C = m - ½ tan(θ/2) rot90(p1 - p0)`` (the end tangents' intersection, m the chord's middle,
    ``tan(θ/2) = 2b / (1 - b²)``) and weights ``1, cos(θ/2) = (1 - b²)/(1 + b²), 1`` (a line: C = m,
    weight 1). Segments join at double knots (C0: the corners stay corners).

    Returns:
        control points (2n + 1, 2) (the last = the first), weights (2n + 1,), knots (2n + 4,).
    """
    p = np.asarray(points, dtype=float)
    q = np.concatenate([p[1:], p[:1]])
    segs: list[tuple[np.ndarray, np.ndarray, float]] = []
    for a, c, b in zip(p, q, np.asarray(bulges, dtype=float).tolist()):
        todo = [(a, c, b)]
        while todo:
            a0, a1, bb = todo.pop()
            if abs(bb) > math.tan(math.pi / 8) + 1e-15:  # |θ| > 90°: split at the arc's middle
                d = a1 - a0
                mid = 0.5 * (a0 + a1) - 0.5 * bb * np.array([-d[1], d[0]])
                half = bb / (1.0 + math.sqrt(1.0 + bb * bb))
                todo += [(mid, a1, half), (a0, mid, half)]
            else:
                segs.append((a0, a1, bb))
    cp, w = [p[0]], [1.0]
    for a0, a1, bb in segs:
        d = a1 - a0
        cp += [0.5 * (a0 + a1) - (bb / (1.0 - bb * bb)) * np.array([-d[1], d[0]]), a1]
        w += [(1.0 - bb * bb) / (1.0 + bb * bb), 1.0]
    n = len(segs)
    knots = np.concatenate([[0.0, 0.0, 0.0], np.repeat(np.arange(1.0, n), 2), [float(n)] * 3])
    return np.array(cp), np.array(w), knots


def export_dxf(pattern: Any, path: str | os.PathLike, *, spline: bool = False, chord_tol: float | None = None) -> Path:
    """Write ``pattern`` (a :class:`ght_cad.pattern.flat_pattern.FlatPattern`): the body of
    :meth:`ght_cad.pattern.flat_pattern.FlatPattern.export_dxf`, whose docstring states the format."""
    tol = pattern._chord_tol(chord_tol)
    try:
        import ezdxf
    except ImportError:  # e.g. FreeCAD's own Python: plain R12 writer, same layers
        return write_text_atomic(path, dxf_r12_text(pattern, chord_tol=tol))
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = INSUNITS[pattern.units]
    doc.header["$MEASUREMENT"] = 0 if pattern.units in ("in", "ft") else 1
    doc.layers.add("OUTLINE", color=7)
    doc.layers.add("BEND", color=1, linetype="DASHED")
    doc.layers.add("LABELS", color=3)
    doc.layers.add("MARKS", color=5)
    if pattern.forming_labels:
        doc.layers.add("FORMING", color=6)
    msp = doc.modelspace()
    for pts, bulges in pattern.outline_arcs(tol):
        if spline:
            cp, w, knots = arcs_to_rational_quadratic(pts, bulges)
            msp.add_rational_spline(cp.tolist(), w.tolist(), degree=2, knots=knots.tolist(),
                                    dxfattribs={"layer": "OUTLINE"})
        else:
            msp.add_lwpolyline(np.column_stack([pts, bulges]).tolist(), format="xyb", close=True,
                               dxfattribs={"layer": "OUTLINE"})
    bl = pattern.bend_lines
    size = max(float(np.max(hi - lo)) for lo, hi in (p.bbox() for p in pattern.panels))
    for p, q in bl:
        msp.add_line(tuple(p), tuple(q), dxfattribs={"layer": "BEND", "linetype": "DASHED", "ltscale": size / 50.0})
    for m in pattern.marks:
        msp.add_line(tuple(m[0]), tuple(m[1]), dxfattribs={"layer": "MARKS"})
    for x, y, s, h in pattern.labels:
        t = msp.add_text(s, height=h, dxfattribs={"layer": "LABELS"})
        t.set_placement((x, y), align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)
    for layer, texts in (("FORMING", pattern.forming_labels), ("BEND", pattern.bend_labels)):
        for x, y, s, h, a in texts:
            t = msp.add_text(s, height=h, rotation=a, dxfattribs={"layer": layer})
            t.set_placement((x, y), align=ezdxf.enums.TextEntityAlignment.MIDDLE_CENTER)
    with atomic_path(path) as tmp:
        doc.saveas(tmp)
    return Path(path)


def dxf_r12_text(pattern: Any, chord_tol: float | None = None) -> str:
    """The text of ``pattern`` (a :class:`ght_cad.pattern.flat_pattern.FlatPattern`): the body of
    :meth:`ght_cad.pattern.flat_pattern.FlatPattern.dxf_r12_text`, whose docstring states the format."""
    out: list[str] = []

    def put(code: int, value: Any) -> None:
        out.append(f"{code}\n{value:.12g}" if isinstance(value, float) else f"{code}\n{value}")

    put(0, "SECTION"), put(2, "HEADER"), put(9, "$ACADVER"), put(1, "AC1009")
    put(9, "$INSUNITS"), put(70, INSUNITS[pattern.units]), put(0, "ENDSEC")
    put(0, "SECTION"), put(2, "TABLES")
    put(0, "TABLE"), put(2, "LTYPE"), put(70, 2)
    put(0, "LTYPE"), put(2, "CONTINUOUS"), put(70, 0), put(3, "Solid line"), put(72, 65), put(73, 0), put(40, 0.0)
    put(0, "LTYPE"), put(2, "DASHED"), put(70, 0), put(3, "Dashed __ __ __"), put(72, 65), put(73, 2)
    put(40, 0.75), put(49, 0.5), put(49, -0.25)
    put(0, "ENDTAB")
    layers = (("OUTLINE", 7, "CONTINUOUS"), ("BEND", 1, "DASHED"), ("LABELS", 3, "CONTINUOUS"), ("MARKS", 5, "CONTINUOUS"))
    if pattern.forming_labels:
        layers += (("FORMING", 6, "CONTINUOUS"),)
    put(0, "TABLE"), put(2, "LAYER"), put(70, len(layers))
    for name, color, lt in layers:
        put(0, "LAYER"), put(2, name), put(70, 0), put(62, color), put(6, lt)
    put(0, "ENDTAB"), put(0, "ENDSEC")
    put(0, "SECTION"), put(2, "ENTITIES")
    for pts, bulges in pattern.outline_arcs(chord_tol):
        put(0, "POLYLINE"), put(8, "OUTLINE"), put(66, 1), put(70, 1)
        for (x, y), b in zip(pts.tolist(), bulges.tolist()):
            put(0, "VERTEX"), put(8, "OUTLINE"), put(10, repr(x)), put(20, repr(y)), put(30, 0.0)
            if b:
                put(42, repr(b))
        put(0, "SEQEND"), put(8, "OUTLINE")
    for layer, segs in (("BEND", list(pattern.bend_lines)), ("MARKS", pattern.marks)):
        for p, q in segs:
            put(0, "LINE"), put(8, layer)
            if layer == "BEND":
                put(6, "DASHED")
            put(10, float(p[0])), put(20, float(p[1])), put(30, 0.0)
            put(11, float(q[0])), put(21, float(q[1])), put(31, 0.0)
    for x, y, text, h in pattern.labels:
        put(0, "TEXT"), put(8, "LABELS"), put(10, float(x)), put(20, float(y)), put(30, 0.0)
        put(40, float(h)), put(1, _dxf_ascii(text)), put(72, 1), put(73, 2)
        put(11, float(x)), put(21, float(y)), put(31, 0.0)
    for layer, texts in (("FORMING", pattern.forming_labels), ("BEND", pattern.bend_labels)):
        for x, y, text, h, a in texts:
            put(0, "TEXT"), put(8, layer), put(10, float(x)), put(20, float(y)), put(30, 0.0)
            put(40, float(h)), put(1, _dxf_ascii(text)), put(50, float(a)), put(72, 1), put(73, 2)
            put(11, float(x)), put(21, float(y)), put(31, 0.0)
    put(0, "ENDSEC"), put(0, "EOF")
    return "\n".join(out) + "\n"
