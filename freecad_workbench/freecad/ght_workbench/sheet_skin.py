r"""Sheet recognition in FreeCAD solids (the FreeCAD adapter of :mod:`ght_cad.sheetmetal.blank`, issue 23).

For every solid of a shape (a ``Part`` feature, a PartDesign Body's tip, an imported STEP) the
faces are sorted into the sheet's two skins and its walls, as the OCP adapter does
(:mod:`ght_cad.cad.unfold_solid`), with FreeCAD's own geometry calls:

* up to 6 interior points of every face (a 7 x 7 grid over ``ParameterRange``, kept where
  ``isPartOfDomain``), each with the face's outward normal ``normalAt`` (orientation included);
  from each the other faces of the solid are probed along the inward normal: the foot of the
  perpendicular on the other face's surface (``Surface.parameter``) that lies straight behind the
  point (``(q - p)·(-n) >= (1 - 1e-6) |q - p|``), inside that face (``isPartOfDomain``), whose
  outward normal is opposite (``n_q·n <= -1 + 1e-6``); the nearest such foot is where the ray
  leaves the material, at distance ``d``;
* the classification is the core's (:func:`ght_cad.sheetmetal.blank.classify_skin`, shared with the OCP
  adapter): ``T`` from the largest face whose probes all agree, skin faces
  (most probes at ``T`` through an opposite face), walls, the shared edges of skin faces
  (tangent within 1e-3 degrees, else a sharp edge is refused), exactly two connected skins.

The smaller skin (or the one holding the base face) becomes a :class:`ght_cad.sheetmetal.blank.SheetSkin`
whose faces are :func:`.face_reader.face_data` with every edge named ``E<k>`` by its index in
the solid's ``Edges``; faces are numbered by their index in the whole shape's ``Faces`` (1-based,
the ``FaceN`` names FreeCAD shows).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

import Part  # noqa: F401  (FreeCAD's geometry: the shapes passed in are Part shapes)

from ght_cad.sheetmetal.blank import DIST_TOL, BlankError, SheetSkin, SkinFace, classify_skin

from .face_reader import face_data

__all__ = ["sheet_skins", "shape_of_source"]

#: interior sample points per face (at most)
_SAMPLES = 6


def shape_of_source(obj: Any) -> Any:
    """The solid shape of a Source object: a Body's ``Shape`` (its tip), any other object's ``Shape``.

    Raises:
        BlankError: the object has no solid.
    """
    shape = getattr(obj, "Shape", None)
    if shape is None or not shape.Solids:
        raise BlankError(f"{obj.Label} holds no solid ({len(shape.Faces) if shape is not None else 0} faces); allowed: a "
                         "sheet solid (Part feature, PartDesign Body, imported STEP), or select one face to unroll it alone")
    return shape


def _face_points(face: Any) -> list[tuple[np.ndarray, np.ndarray]]:
    """Up to :data:`_SAMPLES` interior points of the face (centre first) with outward unit normals."""
    u0, u1, v0, v1 = (float(x) for x in face.ParameterRange)
    g = (np.arange(7) + 0.5) / 7
    cand = sorted(((a, b) for a in g for b in g), key=lambda ab: (ab[0] - 0.5) ** 2 + (ab[1] - 0.5) ** 2)
    out = []
    for a, b in cand:
        u, v = u0 + a * (u1 - u0), v0 + b * (v1 - v0)
        if not face.isPartOfDomain(u, v):
            continue
        n = np.array(tuple(face.normalAt(u, v)), dtype=float)
        ln = float(np.linalg.norm(n))
        if not ln > 0:
            continue
        out.append((np.array(tuple(face.valueAt(u, v)), dtype=float), n / ln))
        if len(out) >= _SAMPLES:
            break
    return out


def _probe(p: np.ndarray, n: np.ndarray, faces: list[Any], own: int) -> tuple[float, bool, int]:
    """``(distance, opposite normal, face index)`` of the nearest face straight behind ``p`` along
    ``-n`` (see module doc); ``(inf, False, -1)`` when none."""
    import FreeCAD as App

    best = (math.inf, False, -1)
    P = App.Vector(*p)
    for j, g in enumerate(faces):
        if j == own:
            continue
        try:
            u, v = g.Surface.parameter(P)
        except Exception:  # noqa: BLE001 - no projection onto this surface
            continue
        q = np.array(tuple(g.Surface.value(u, v)), dtype=float)
        d = q - p
        dist = float(np.linalg.norm(d))
        if not dist > 0 or dist >= best[0] or float(d @ -n) < (1.0 - DIST_TOL) * dist:
            continue
        if not g.isPartOfDomain(u, v):
            continue
        nq = np.array(tuple(g.normalAt(u, v)), dtype=float)
        nq = nq / max(float(np.linalg.norm(nq)), 1e-300)
        best = (dist, float(nq @ n) <= -1.0 + DIST_TOL, j)
    return best


def _edge_angle(edge: Any, fa: Any, fb: Any) -> float:
    """Angle in degrees between the outward normals of two faces at the middle of their shared edge."""
    t0, t1 = edge.ParameterRange
    p = edge.valueAt(0.5 * (t0 + t1))
    ns = []
    for f in (fa, fb):
        u, v = f.Surface.parameter(p)
        n = np.array(tuple(f.normalAt(u, v)), dtype=float)
        ns.append(n / np.linalg.norm(n))
    return math.degrees(math.acos(max(-1.0, min(1.0, float(ns[0] @ ns[1])))))


def _indexer(items: list[Any]) -> Any:
    """``f(shape) -> 1-based index in items`` (``isSame``, looked up by ``hashCode``; 0 when absent)."""
    by_hash: dict[int, list[tuple[int, Any]]] = {}
    for i, s in enumerate(items, 1):
        by_hash.setdefault(s.hashCode(), []).append((i, s))

    def index(s: Any) -> int:
        for i, t in by_hash.get(s.hashCode(), []):
            if t.isSame(s):
                return i
        for i, t in enumerate(items, 1):  # hash codes differ for the same TShape under another location
            if t.isSame(s):
                return i
        return 0

    return index


def sheet_skins(shape: Any, *, base_face: int | None = None, name: str = "") -> tuple[list[SheetSkin], int]:
    """The sheet skin of every solid of a FreeCAD shape (module doc) and the shape's face count.

    Raises:
        BlankError: no solid; a solid that is no sheet (a block), a sharp edge between skin faces,
            an ambiguous skin; each one line naming the face/edge and the measured value.
    """
    if not shape.Solids:
        raise BlankError(f"{name or 'the shape'} holds no solid ({len(shape.Faces)} faces); allowed: sheet solids")
    face_no = _indexer(list(shape.Faces))
    prefix = f"{name}:" if name else ""
    return [_solid_skin(s, f"{prefix}S{k}", face_no, base_face) for k, s in enumerate(shape.Solids, 1)], len(shape.Faces)


def _solid_skin(solid: Any, sname: str, face_no: Any, base_face: int | None) -> SheetSkin:
    faces = list(solid.Faces)
    nums = [face_no(f) for f in faces]
    areas = [float(f.Area) for f in faces]
    rays = [[_probe(p, n, faces, i) for p, n in _face_points(f)] for i, f in enumerate(faces)]
    edges = list(solid.Edges)
    edge_no = _indexer(edges)
    ancestors: dict[int, list[int]] = {}
    for i, f in enumerate(faces):
        for e in f.Edges:
            k = edge_no(e)
            if k and i not in ancestors.setdefault(k, []):
                ancestors[k].append(i)
    T, comp, partner, shared, ref = classify_skin(
        sname, nums, areas, rays,
        {f"E{k}": (a[0], a[1]) for k, a in sorted(ancestors.items()) if len(a) == 2},
        lambda key, a, b: _edge_angle(edges[int(key[1:]) - 1], faces[a], faces[b]), base_face)
    sel = [i for i in range(len(faces)) if comp[i] == ref]

    def edge_name(e: Any) -> str:
        return f"E{edge_no(e)}"

    skin_faces = [SkinFace(nums[i], face_data(faces[i], edge_name=edge_name), areas[i], nums[partner[i]]) for i in sel]
    sh = {k: (nums[a], nums[b]) for k, (a, b) in shared.items() if comp[a] == ref}
    walls = [nums[i] for i in range(len(faces)) if i not in sel]
    return SheetSkin(sname, T, skin_faces, sh, walls)
