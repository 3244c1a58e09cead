"""Read flat-pattern outlines back from DXF and SVG files with other people's tools (ezdxf's path
tools, svgelements), independently of the writer: areas, vertices, bulges."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: ``segments`` of ezdxf's make_path: Bézier pieces per full circle for bulges and arcs (a cubic
#: spanning a quadrant is 2.7e-4 of the radius off, the error falls as the sweep's 6th power; at 64
#: a half circle was 1.6e-10 off in area, at 1024 it is below round-off)
ARC_SEGMENTS = 1024


def outline_entities(path: Path | str) -> list:
    """The OUTLINE entities of a DXF (LWPOLYLINE, POLYLINE, SPLINE, LINE, ARC), read by ezdxf."""
    import ezdxf

    return [e for e in ezdxf.readfile(path).modelspace() if e.dxf.layer == "OUTLINE"]


def entity_area(entity) -> float:
    """|area| of one closed OUTLINE entity measured on ezdxf's own path: ``ezdxf.path.make_path``
    (bulges and arcs as cubic Béziers, :data:`ARC_SEGMENTS` per circle), Green's theorem
    ``½ ∮ x dy - y dx`` integrated exactly on every command (3-point Gauss–Legendre is exact for
    the degree-5 integrand of a cubic; a line's term is the shoelace term)."""
    from ezdxf import path as ezpath
    from ezdxf.path import Command

    p = ezpath.make_path(entity, segments=ARC_SEGMENTS)
    x, w = np.polynomial.legendre.leggauss(3)
    t, w = 0.5 * (x + 1.0), 0.5 * w
    total, start = 0.0, np.array([p.start.x, p.start.y])
    for cmd in p.commands():
        end = np.array([cmd.end.x, cmd.end.y])
        if cmd.type == Command.CURVE4_TO:
            P = np.array([start, (cmd.ctrl1.x, cmd.ctrl1.y), (cmd.ctrl2.x, cmd.ctrl2.y), end])
            s = 1.0 - t
            B = (s**3)[:, None] * P[0] + (3 * s * s * t)[:, None] * P[1] + (3 * s * t * t)[:, None] * P[2] + (t**3)[:, None] * P[3]
            D = 3 * ((s * s)[:, None] * (P[1] - P[0]) + (2 * s * t)[:, None] * (P[2] - P[1]) + (t * t)[:, None] * (P[3] - P[2]))
            total += 0.5 * float(np.sum(w * (B[:, 0] * D[:, 1] - B[:, 1] * D[:, 0])))
        else:
            assert cmd.type in (Command.LINE_TO, Command.MOVE_TO), cmd.type
            total += 0.5 * float(start[0] * end[1] - end[0] * start[1])
        start = end
    return abs(total)


def flattened_area(entity, distance: float) -> float:
    """|area| of ezdxf's own flattening of the entity (``Path.flattening(distance)``, then
    ``ezdxf.math.area``): the polygon a CAM post-processor would cut."""
    from ezdxf import path as ezpath
    from ezdxf.math import area

    p = ezpath.make_path(entity, segments=ARC_SEGMENTS)
    return abs(float(area(list(p.flattening(distance, segments=16)))))


def dxf_outline_areas(path: Path | str) -> list[float]:
    """ezdxf-measured areas (:func:`entity_area`) of every closed OUTLINE entity of a DXF."""
    return [entity_area(e) for e in outline_entities(path)]


def outline_vertices(entity) -> np.ndarray:
    """(n, 2) vertices of an LWPOLYLINE/POLYLINE (control points of a SPLINE)."""
    if entity.dxftype() == "LWPOLYLINE":
        return np.array([(p[0], p[1]) for p in entity.get_points("xy")])
    if entity.dxftype() == "POLYLINE":
        return np.array([(v.dxf.location.x, v.dxf.location.y) for v in entity.vertices])
    return np.array([(p[0], p[1]) for p in entity.control_points])


def outline_bulges(entity) -> np.ndarray:
    """(n,) vertex bulges of an LWPOLYLINE/POLYLINE."""
    if entity.dxftype() == "LWPOLYLINE":
        return np.array([p[2] for p in entity.get_points("xyb")])
    return np.array([v.dxf.bulge for v in entity.vertices])


def svg_outline_areas(path_or_text: Path | str) -> list[float]:
    """|area| of every ``<path>`` in the SVG's OUTLINE group, parsed by svgelements: Green's
    theorem on its segments, exact for lines and for arcs (chord polygon plus the circular segment
    ``r² (θ - sin θ) / 2`` of the parsed sweep θ and radius)."""
    import xml.etree.ElementTree as ET

    from svgelements import Arc, Close, Line, Move, Path as SvgPath

    text = Path(path_or_text).read_text() if isinstance(path_or_text, Path) else path_or_text
    root = ET.fromstring(text)
    ns = {"s": "http://www.w3.org/2000/svg"}
    group = next(g for g in root.findall("s:g", ns) if g.get("id") == "OUTLINE")
    out = []
    for el in group.findall("s:path", ns):
        total = 0.0
        for seg in SvgPath(el.get("d")):
            if isinstance(seg, Move):
                continue
            assert isinstance(seg, (Line, Arc, Close)), type(seg)
            a, b = seg.start, seg.end
            total += 0.5 * (a.x * b.y - b.x * a.y)
            if isinstance(seg, Arc):
                th = float(seg.sweep)
                total += 0.5 * float(seg.rx) ** 2 * (th - math.sin(th))
        out.append(abs(total))
    return out
