r"""Sheet recognition in build123d / cadquery / OCP solids and ``ght_cad.unfold`` (OCP adapter).

For every solid of a shape the faces are sorted into the sheet's two skins and its walls:

* from up to 6 interior points of every face (a 7 x 7 grid over its parameter box, kept where
  ``BRepClass_FaceClassifier`` puts them inside the trimmed face) a ray runs into the material
  along the inward normal; the first face it leaves through is at distance ``d``
  (``IntCurvesFace_ShapeIntersector``). The thickness ``T`` is ``d`` of the largest face whose
  rays all leave at one distance through a face of opposite normal;
* a face whose rays (most of them) leave at ``T`` through an opposite face is a skin face, others
  are walls (thickness walls, hole walls, cut faces);
* the faces at T must pair up one way only (faces sharing an edge on one side, a face and the
  faces its rays reach on opposite sides: :func:`ght_cad.sheetmetal.blank.classify_skin`), else the skin is
  ambiguous (a bar of square section T x T);
* two skin faces sharing an edge (``TopExp.MapShapesAndAncestors``) must meet tangentially
  (else: a sharp edge, zero bend radius); every skin face must be skin at all its points (else
  the skin is ambiguous); the skin faces form exactly two connected sets (inside and outside),
  each face's opposite face in the other set; ``T`` must be below a quarter of the square root
  of the smaller skin's area (else the solid is a block, not a sheet).

The smaller skin (or the one holding ``base_face``) goes to :func:`ght_cad.sheetmetal.blank.unfold_skins` as
:class:`ght_cad.sheetmetal.blank.SheetSkin` with every face as ``FaceData`` (:func:`ght_cad.cad.unroll_faces.face_data`)
whose edges are named ``E<k>`` by the solid's edge map.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_Surface
from OCP.BRepClass import BRepClass_FaceClassifier
from OCP.BRepGProp import BRepGProp
from OCP.BRepTools import BRepTools
from OCP.GProp import GProp_GProps
from OCP.gp import gp_Dir, gp_Lin, gp_Pnt, gp_Pnt2d, gp_Vec
from OCP.IntCurvesFace import IntCurvesFace_ShapeIntersector
from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE, TopAbs_IN, TopAbs_REVERSED, TopAbs_SOLID
from OCP.TopExp import TopExp, TopExp_Explorer

from ._ocp import TopoDS, TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape

from ..core._vec import cross
from ..sheetmetal.blank import DIST_TOL, BlankError, KFactorTable, SheetSkin, SkinFace, Unfolded, classify_skin, k_factor_table, unfold_skins
from .occ import unwrap
from .unroll_faces import _SurfEval, face_data

__all__ = ["sheet_skins", "unfold", "blank_plates"]

#: interior sample points per face (at most)
_SAMPLES = 6


def _face_points(face: Any, ad: BRepAdaptor_Surface) -> list[tuple[np.ndarray, np.ndarray]]:
    """Up to :data:`_SAMPLES` interior points of the face with their outward unit normals."""
    u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
    rev = face.Orientation() == TopAbs_REVERSED
    out = []
    g = (np.arange(7) + 0.5) / 7
    # centre first, then outwards: the points farthest from the boundary come first
    cand = sorted(((a, b) for a in g for b in g), key=lambda ab: (ab[0] - 0.5) ** 2 + (ab[1] - 0.5) ** 2)
    tol = 1e-9 * max(u1 - u0, v1 - v0)
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    for a, b in cand:
        u, v = u0 + a * (u1 - u0), v0 + b * (v1 - v0)
        if BRepClass_FaceClassifier(face, gp_Pnt2d(u, v), tol).State() != TopAbs_IN:
            continue
        ad.D1(u, v, p, du, dv)
        n = cross(np.array(du.Coord()), np.array(dv.Coord()))
        ln = np.linalg.norm(n)
        if ln == 0:
            continue
        n = n / ln * (-1.0 if rev else 1.0)
        out.append((np.array(p.Coord()), n))
        if len(out) >= _SAMPLES:
            break
    return out


def _normal_at(face: Any, u: float, v: float) -> np.ndarray:
    ad = BRepAdaptor_Surface(face)
    p, du, dv = gp_Pnt(), gp_Vec(), gp_Vec()
    ad.D1(u, v, p, du, dv)
    n = cross(np.array(du.Coord()), np.array(dv.Coord()))
    n = n / np.linalg.norm(n)
    return -n if face.Orientation() == TopAbs_REVERSED else n


def _area(face: Any) -> float:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face, props)
    return float(props.Mass())


def _solids(raw: Any) -> list[Any]:
    out, exp = [], TopExp_Explorer(raw, TopAbs_SOLID)
    while exp.More():
        out.append(TopoDS.Solid_s(exp.Current()))
        exp.Next()
    return out


def sheet_skins(shape: Any, *, base_face: int | None = None, name: str = "") -> tuple[list[SheetSkin], int]:
    """The sheet skin of every solid of a shape (see module doc) and the shape's face count.

    Faces are numbered 1.. in the shape's ``TopExp_Explorer`` order (as ``ght-cad unroll`` numbers
    them); solids ``S1``, ``S2``, ... (prefixed by ``name``).

    Raises:
        BlankError: no solid; a solid that is no sheet (a block), a sharp edge between skin faces
            (zero bend radius), an ambiguous skin; each one line naming the face/edge and the
            measured value.
    """
    raw = unwrap(shape)
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(raw, TopAbs_FACE, fmap)
    # the explorer's order (the CLI's face numbers), which MapShapes may not keep
    order, exp = [], TopExp_Explorer(raw, TopAbs_FACE)
    while exp.More():
        order.append(exp.Current())
        exp.Next()
    number_of = {fmap.FindIndex(f): k + 1 for k, f in reversed(list(enumerate(order)))}
    solids = _solids(raw)
    if not solids:
        raise BlankError(f"{name or 'the shape'} holds no solid ({len(order)} faces); allowed: sheet solids "
                         "(unroll single faces with face selections instead)")
    prefix = f"{name}:" if name else ""
    skins = []
    for si, solid in enumerate(solids, 1):
        skins.append(_solid_skin(solid, f"{prefix}S{si}", fmap, number_of, base_face))
    return skins, len(order)


def _solid_skin(solid: Any, sname: str, fmap: Any, number_of: dict[int, int], base_face: int | None) -> SheetSkin:
    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(solid, props)
    if props.Mass() < 0:  # an inside-out solid (e.g. thickened against its faces' normals): face normals inward
        solid = solid.Reversed()
    faces, exp = [], TopExp_Explorer(solid, TopAbs_FACE)
    seen = set()
    while exp.More():
        f = TopoDS.Face_s(exp.Current())
        k = fmap.FindIndex(f)
        if k not in seen:
            seen.add(k)
            faces.append(f)
        exp.Next()
    nums = [number_of[fmap.FindIndex(f)] for f in faces]
    idx_of = {fmap.FindIndex(f): i for i, f in enumerate(faces)}
    inter = IntCurvesFace_ShapeIntersector()
    from OCP.Bnd import Bnd_Box
    from OCP.BRepBndLib import BRepBndLib

    box = Bnd_Box()
    BRepBndLib.Add_s(solid, box)
    # CornerMin/CornerMax on OCP 7.9 and 8 alike (OCP 8's Bnd_Box.Get() returns a struct it cannot convert)
    size = float(np.max(np.array(box.CornerMax().Coord()) - np.array(box.CornerMin().Coord())))
    inter.Load(solid, 1e-9 * size)
    areas = [_area(f) for f in faces]
    rays: list[list[tuple[float, bool, int]]] = []  # per face: (distance, opposite normal, hit face index)
    for f in faces:
        ad = BRepAdaptor_Surface(f)
        row = []
        for p, n in _face_points(f, ad):
            inter.Perform(gp_Lin(gp_Pnt(*p), gp_Dir(*(-n))), 1e-7 * size, 10.0 * size)
            best = None
            for i in range(1, inter.NbPnt() + 1):
                w = inter.WParameter(i)
                if best is None or w < best[0]:
                    best = (w, i)
            if best is None:
                row.append((math.inf, False, -1))
                continue
            w, i = best
            hf = inter.Face(i)
            nh = _normal_at(hf, inter.UParameter(i), inter.VParameter(i))
            row.append((float(w), float(nh @ n) < -1.0 + DIST_TOL, idx_of.get(fmap.FindIndex(hf), -1)))
        rays.append(row)
    # edges shared by two faces of the solid
    emap = TopTools_IndexedDataMapOfShapeListOfShape()
    TopExp.MapShapesAndAncestors_s(solid, TopAbs_EDGE, TopAbs_FACE, emap)
    eindex = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(solid, TopAbs_EDGE, eindex)
    edges: dict[str, tuple[int, int]] = {}
    edge_of: dict[str, Any] = {}
    for k in range(1, emap.Extent() + 1):
        edge = emap.FindKey(k)
        anc = [idx_of.get(fmap.FindIndex(TopoDS.Face_s(x))) for x in emap.FindFromIndex(k)]
        anc = list(dict.fromkeys(a for a in anc if a is not None))
        if len(anc) == 2:
            key = f"E{eindex.FindIndex(edge)}"
            edges[key], edge_of[key] = (anc[0], anc[1]), edge
    T, comp, partner, shared, ref = classify_skin(
        sname, nums, areas, rays, edges, lambda key, a, b: _edge_angle(TopoDS.Edge_s(edge_of[key]), faces[a], faces[b]),
        base_face)
    sel = [i for i in range(len(faces)) if comp[i] == ref]

    def edge_name(e: Any) -> str:
        return f"E{eindex.FindIndex(e)}"

    skin_faces = []
    for i in sel:
        f = faces[i]
        fd = face_data(f, _SurfEval(BRepAdaptor_Surface(f)), BRepTools.UVBounds_s(f), edge_name)
        skin_faces.append(SkinFace(nums[i], fd, areas[i], nums[partner[i]]))
    sh = {k: (nums[a], nums[b]) for k, (a, b) in shared.items() if comp[a] == ref}
    walls = [nums[i] for i in range(len(faces)) if i not in sel]
    return SheetSkin(sname, T, skin_faces, sh, walls)


def _edge_angle(edge: Any, fa: Any, fb: Any) -> float:
    """Angle in degrees between the outward normals of two faces at the middle of their shared edge."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve2d

    out = []
    for f in (fa, fb):
        c2 = BRepAdaptor_Curve2d(edge, f)
        t = 0.5 * (c2.FirstParameter() + c2.LastParameter())
        uv = c2.Value(t)
        out.append(_normal_at(f, uv.X(), uv.Y()))
    del BRep_Tool
    return math.degrees(math.acos(max(-1.0, min(1.0, float(out[0] @ out[1])))))


def unfold(
    shape: Any,
    k_factor: float | None = None,
    *,
    k_factor_table: str | KFactorTable | None = None,
    base_face: int | None = None,
    bend_lines: str = "tangent",
    allow_split: bool = False,
    units: str = "mm",
) -> Unfolded:
    r"""One blank per sheet solid of a build123d / cadquery / OCP shape (issue 23).

    Each solid's sheet is recognised (module doc), its skin unfolded into one connected flat
    panel (:func:`ght_cad.sheetmetal.blank.unfold_skin`): bends on their neutral surface ``R + K T``,
    flanges as they are, bend lines and a bend table (``BA = (R + K T) A``, ``BD = 2 (R + T)
    tan(A/2) - BA``).

    Args:
        shape: a Solid/Compound/Part (build123d), a cadquery Workplane's shape, or a TopoDS_Shape.
        k_factor: ANSI K in [0, 1] (default 0.5 unless a table is given).
        k_factor_table: ``"ansi"``, ``"din"``, a file of ``R/T K`` lines, or a
            :class:`ght_cad.sheetmetal.blank.KFactorTable`: K per bend by its ``R / T``.
        base_face: 1-based face number (the shape's face order) of the face that keeps its place;
            default: the largest planar face of the smaller skin.
        bend_lines: ``"tangent"`` or ``"centre"``.
        allow_split: keep overlapping pieces apart as separate panels instead of refusing.
        units: length unit of the shape.

    Returns:
        :class:`ght_cad.sheetmetal.blank.Unfolded`: ``pattern`` (one panel per solid), ``blanks``.

    Raises:
        BlankError: see :func:`sheet_skins` and :func:`ght_cad.sheetmetal.blank.unfold_skin`.
    """
    if k_factor is not None and k_factor_table is not None:
        raise BlankError(f"k_factor={k_factor!r} and k_factor_table={k_factor_table!r} are both given; give one")
    K: float | KFactorTable
    if k_factor_table is not None:
        K = k_factor_table if isinstance(k_factor_table, KFactorTable) else k_factor_table_of(k_factor_table)
    else:
        K = 0.5 if k_factor is None else k_factor
    skins, n = sheet_skins(shape, base_face=base_face)
    return unfold_skins(skins, k_factor=K, base_face=base_face, bend_lines=bend_lines, allow_split=allow_split,
                        units=units, face_count=n)


k_factor_table_of = k_factor_table


def blank_plates(unfolded: Unfolded) -> list[Any]:
    """Every blank as a flat plate for CAM: the panel's outline and holes as a planar face at
    z = 0 (:func:`ght_cad.cad.unroll_faces.flat_faces`, spline edges through the outline points),
    extruded by the blank's thickness along +z (``BRepPrimAPI_MakePrism``); build123d Solids."""
    from build123d import Solid
    from OCP.BRepPrimAPI import BRepPrimAPI_MakePrism

    from ..pattern.flat_pattern import FlatPattern
    from .unroll_faces import flat_faces

    out = []
    for b in unfolded.blanks:
        for face in flat_faces(FlatPattern(b.panels, units=unfolded.pattern.units)):
            prism = BRepPrimAPI_MakePrism(face.wrapped, gp_Vec(0.0, 0.0, b.thickness))
            out.append(Solid(prism.Shape()))
    return out
