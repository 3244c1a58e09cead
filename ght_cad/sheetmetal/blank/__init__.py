r"""One blank per bent part: connected unfolding of a sheet's skin (kernel-free core).

A kernel adapter (:mod:`ght_cad.cad.unfold_solid` for OCP/build123d/cadquery) recognises the
sheet in a solid and describes its *skin* -- the faces of one side of the sheet -- as a
:class:`SheetSkin`: every face as a :class:`ght_cad.unrolling.face_unroll.FaceData` whose edges are named by
the solid's edge keys, the thickness ``T`` and which edges two skin faces share. This module

* develops every skin face exactly (:func:`ght_cad.unrolling.face_unroll.unroll_face_data`: closed forms
  for planes, cylinders and cones, quadrature along the rulings for other developables); a bend
  face is developed on its neutral surface, offset into the material by ``K T`` when the skin
  face is the inside of its bend and by ``(1 - K) T`` when it is the outside, so either skin gives
  the neutral radius ``R + K T`` (``R`` the inside radius, spec 6.1); planar faces (flanges) do not
  stretch, their flat is the face's own;
* walks the skin's face graph breadth first from a base face (largest planar face by default)
  and places every face by the rigid motion ``x -> Q x + c`` that maps its flat image of the
  shared edge onto the flat image its placed neighbour has of the same edge (both faces first
  made orientation-preserving with respect to the solid's outward normal, so a face lands on the
  far side of the edge); shared edges not on the spanning tree are cut and reported;
* merges all faces' boundary edges that are not shared inside the tree into closed loops: the
  outline (largest area) and holes, one :class:`ght_cad.pattern.flat_pattern.FlatPanel` per solid, with
  both tangent lines of every bend (or its centre line) as bend lines, the rulings of freeform
  bends, and a bend table (angle ``A``, inside radius ``R``, ``K``, bend allowance
  ``BA = (R + K T) A``, bend deduction ``BD = 2 (R + T) tan(A / 2) - BA``, direction up/down);
* refuses a blank whose pieces overlap in the plane (crossing outline segments; the overlap area
  of the crossing faces' outlines by Green's theorem, :func:`_overlap_area`) unless split into separate panels with matching edge marks.

The blank's length across a bend is therefore ``Σ flange lengths to the tangent lines +
Σ (R + K T) A`` exactly as the closed form (a freeform bend: inside length + ``K T`` × turn angle).

numpy only at import time; no CAD kernel.

Modules (issue 27, moved from ``ght_cad/sheetmetal/blank.py``): :mod:`.model` (:class:`BlankError`, the skin,
:class:`Blank`, :func:`bend_row`, :class:`Unfolded`), :mod:`.k_factor` (K-factor tables),
:mod:`.placement` (rigid motions, the geometry of one face), :mod:`.outline` (merging the faces'
edges into loops), :mod:`.overlap` (crossings, overlap area), :mod:`.recognition` (sheet
recognition: :func:`classify_skin`). :func:`unfold_skin` and :func:`unfold_skins` stay here and
call the helpers through this module's namespace, so every name (private ones included) is
importable and patchable as ``ght_cad.sheetmetal.blank.<name>``.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any, Sequence

import numpy as np

# The moved names (issue 27), all importable from here; unfold_skin below reads them from this namespace.
from .k_factor import K_TABLES, KFactorTable, _din_table, k_factor_rows, k_factor_table  # noqa: F401
from .model import Blank, BlankError, SheetSkin, SkinFace, Unfolded, bend_row  # noqa: F401
from .outline import _merge
from .overlap import _crossings, _oriented, _overlap_area, _overlaps, _segments  # noqa: F401
from .placement import (_apply_motion, _bend_angle, _curvature, _edge_chord, _edge_key_order, _edge_uv,
                        _gaussian_curvature, _jacobian_sign, _line_distance, _Motion, _motion_onto, _outward,
                        _panel_point, _side, _unit)  # noqa: F401
from .recognition import DIST_TOL, SHARP_DEG, _check_pairing, classify_skin  # noqa: F401

__all__ = [
    "BlankError",
    "KFactorTable",
    "K_TABLES",
    "k_factor_table",
    "k_factor_rows",
    "SkinFace",
    "SheetSkin",
    "Blank",
    "bend_row",
    "unfold_skin",
    "Unfolded",
    "unfold_skins",
    "classify_skin",
]


def unfold_skin(
    skin: SheetSkin,
    *,
    k_factor: float | KFactorTable = 0.5,
    base_face: int | None = None,
    bend_lines: str = "tangent",
    allow_split: bool = False,
    rulings: int = 8,
    samples: int = 129,
    tol_deg: float = 0.01,
    units: str = "mm",
) -> Blank:
    r"""Unfold one sheet skin into one blank (see module doc).

    Args:
        skin: the skin (:class:`SheetSkin`), from a kernel adapter.
        k_factor: ANSI K in [0, 1], or a :class:`KFactorTable` giving ``K(R/T)`` per bend.
        base_face: face number of the base face (default: the largest planar skin face, else the
            largest face).
        bend_lines: ``"tangent"`` (both tangent lines of every bend) or ``"centre"`` (the middle).
        allow_split: pieces that overlap in the plane become separate panels (one per face, with
            matching edge marks) instead of a refusal.
        rulings: bend lines drawn on a freeform (non-circular) bend.
        samples: points per boundary edge in the outline.
        tol_deg: largest accepted ``θ_max`` of a face (spec 5).
        units: length unit.

    Returns:
        :class:`Blank`.

    Raises:
        BlankError: a face that is not developable, a bad base face, overlapping pieces (without
            ``allow_split``), a face graph that is not connected.
    """
    from ...core.errors import NotDevelopableError
    from ...unrolling.face_unroll import unroll_face_data
    from ...pattern.flat_pattern import FlatPanel, layout_panels, mark_shared_edges, measure_panel
    from ..sheet import Sheet, SheetError

    if bend_lines not in ("tangent", "centre", "center"):
        raise BlankError(f"bend_lines={bend_lines!r} is not allowed; allowed: 'tangent' or 'centre'")
    T = float(skin.thickness)
    table = k_factor if isinstance(k_factor, KFactorTable) else None
    if table is None:
        K0 = float(k_factor)
        if not (math.isfinite(K0) and 0.0 <= K0 <= 1.0):
            raise BlankError(f"k_factor={k_factor!r} is not allowed; the ANSI K-factor lies in [0, 1]")
    by_num = {f.number: f for f in skin.faces}
    if not by_num:
        raise BlankError(f"{skin.name}: the sheet has no skin faces")
    # base face
    if base_face is None:
        planar = [f for f in skin.faces if f.data.surface.kind == "plane"]
        base = max(planar or skin.faces, key=lambda f: f.area).number
    else:
        base = int(base_face)
        if base not in by_num:
            partner = [f.number for f in skin.faces if f.partner == base]
            if not partner:
                raise BlankError(f"{skin.name}: base face F{base} is not a skin face of the sheet; allowed: "
                                 f"{', '.join(f'F{n}' for n in sorted(by_num))} or their opposite faces")
            base = partner[0]
    # develop every face (bends on their neutral surface)
    panels: dict[int, Any] = {}
    bend_info: dict[int, dict[str, Any]] = {}
    for f in skin.faces:
        fd, kind = f.data, f.data.surface.kind
        label = f"F{f.number}"
        sheet = None
        if kind != "plane":
            ruled = "v" if kind in ("cylinder", "cone", "extrusion") else None
            if ruled is None:
                from ...unrolling.face_unroll import ruling_direction

                ruled = ruling_direction(fd.surface, fd.bounds)[0]
                if ruled is None:
                    kg = _gaussian_curvature(fd)
                    raise BlankError(f"{skin.name}: face F{f.number} ({kind}) is not developable: it is not ruled "
                                     f"(no straight isolines) and its Gaussian curvature at the middle of its parameter "
                                     f"box is {kg:.6g} /{units}^2 (radius 1/sqrt|K| = {1 / math.sqrt(abs(kg)) if kg else math.inf:.6g} "
                                     f"{units}; a developable face has 0); allowed: planes, cylinders, cones and "
                                     "developable ruled faces")
            u0, u1, v0, v1 = fd.bounds
            kap, _ = _curvature(fd, ruled, 0.5 * (u0 + u1), 0.5 * (v0 + v1))
            inside = kap > 0  # bends towards its outward side: the concave (inside) skin of the bend
            r_here = 1.0 / abs(kap) if kap != 0 else math.inf
            if kind == "cylinder":
                r_here = float(fd.surface.radius)
            r_in = r_here if inside else r_here - T
            if not (r_in > 1e-9 * max(T, 1.0)):
                raise BlankError(f"{skin.name}: bend face F{f.number} has inside radius {r_in:.6g} "
                                 "(a sharp bend); allowed: bends of inside radius > 0")
            K = table(r_in, T) if table is not None else K0
            sheet = Sheet(T, K if inside else 1.0 - K, "reverse")
            bend_info[f.number] = {"ruled": ruled, "inside": inside, "radius": r_in, "k": K, "kind": kind}
        try:
            pat = unroll_face_data(fd, tol_deg=tol_deg, rulings=rulings if kind not in ("plane", "cylinder", "cone") else 0,
                                   samples=samples, units=units, label=label, sheet=sheet)
        except NotDevelopableError as exc:
            raise BlankError(f"{skin.name}: face F{f.number} is not developable: {' '.join(str(exc).split())}") from None
        except SheetError as exc:
            raise BlankError(f"{skin.name}: face F{f.number}: {' '.join(str(exc).split())}") from None
        panels[f.number] = pat.panels[0]
    # orientation: every face's development keeps the outward normal's sense, else mirror it
    mirror = {n: _jacobian_sign(panels[n], by_num[n].data) < 0 for n in panels}
    # breadth-first walk from the base face
    nbrs: dict[int, list[tuple[str, int]]] = {n: [] for n in by_num}
    for key in sorted(skin.shared, key=_edge_key_order):
        a, b = skin.shared[key]
        if a in by_num and b in by_num and a != b:
            nbrs[a].append((key, b))
            nbrs[b].append((key, a))
    motion: dict[int, _Motion] = {base: _Motion(mirror=mirror[base])}
    order = [base]
    tree: set[str] = set()
    residual = 0.0
    queue = deque([base])
    while queue:
        a = queue.popleft()
        for key, b in nbrs[a]:
            if b in motion:
                continue
            ca = _edge_chord(panels[a], key)
            cb = _edge_chord(panels[b], key)
            ea, eb = _edge_uv(by_num[a].data, key), _edge_uv(by_num[b].data, key)
            if ca is None or cb is None or ea is None or eb is None:
                continue
            a0, a1 = motion[a](ca[0]), motion[a](ca[1])
            q0, q1 = cb
            xa = np.asarray(ea.xyz(np.array([0.0, 1.0])), dtype=float)
            xb = np.asarray(eb.xyz(np.array([0.0, 1.0])), dtype=float)
            if np.linalg.norm(xa[0] - xb[0]) > np.linalg.norm(xa[0] - xb[1]):  # traversed the other way
                q0, q1 = q1, q0
            la, lq = float(np.linalg.norm(a1 - a0)), float(np.linalg.norm(q1 - q0))
            residual = max(residual, abs(la - lq) / max(la, 1e-300))
            m = _motion_onto(a0, a1, q0, q1, mirror[b])
            # the face must land on the far side of the edge from its neighbour
            side_a = _side(a0, a1, _panel_point(panels[a], motion[a]))
            side_b = _side(a0, a1, _panel_point(panels[b], m))
            if side_a * side_b > 0:  # same side: the development's sense was misjudged, mirror across the edge
                m = _motion_onto(a0, a1, q0, q1, not mirror[b])
            motion[b] = m
            order.append(b)
            tree.add(key)
            queue.append(b)
    missing = sorted(set(by_num) - set(motion))
    if missing:
        raise BlankError(f"{skin.name}: skin faces {', '.join(f'F{n}' for n in missing)} are not connected to the base "
                         f"face F{base} through shared edges; allowed: one connected sheet per solid")
    cut = sorted((k for k, (a, b) in skin.shared.items() if a in by_num and b in by_num and k not in tree),
                 key=_edge_key_order)
    # bend table and bend lines
    bends: list[dict[str, Any]] = []
    lines: list[np.ndarray] = []
    texts: list[tuple[float, float, str, float, float]] = []
    for n in order:
        bi = bend_info.get(n)
        if bi is None:
            continue
        tang = []
        for key, _ in nbrs[n]:
            c = _edge_chord(panels[n], key)
            if c is not None:
                tang.append(np.array([motion[n](c[0]), motion[n](c[1])]))
        fd = by_num[n].data
        angle = _bend_angle(fd, bi, tang)
        width = _line_distance(tang[0], tang[1]) if len(tang) == 2 else None
        name = f"B{len(bends) + 1}"
        row = bend_row(name, n, bi["kind"], angle, bi["radius"], T, bi["k"], bi["inside"],
                       None if bi["kind"] == "cylinder" else width)
        row["bend_lines_distance"] = width
        bends.append(row)
        if bend_lines == "tangent" or len(tang) != 2:
            lines.extend(tang)
        else:
            t0, t1 = tang
            if np.linalg.norm(t0[0] - t1[0]) > np.linalg.norm(t0[0] - t1[1]):
                t1 = t1[::-1]
            lines.append(0.5 * (t0 + t1))
        if bi["kind"] not in ("cylinder", "cone") and panels[n].bend_lines.size:
            bl = panels[n].bend_lines
            lines.extend(np.stack([motion[n](bl[:, 0]), motion[n](bl[:, 1])], axis=1))
        if tang:
            mid = np.mean(np.concatenate(tang), axis=0)
            d = tang[0][1] - tang[0][0]
            rot = math.degrees(math.atan2(d[1], d[0]))
            rot = rot - 180 if rot > 90 else rot + 180 if rot < -90 else rot
            texts.append((float(mid[0]), float(mid[1]),
                          f"{name} {row['direction'].upper()} {row['angle_deg']:.4g} deg R{bi['radius']:.4g}",
                          0.0, rot))
    area_faces = float(sum(p.area_flat for p in panels.values()))
    label = skin.name
    merged = _merge(panels, motion, order, tree, label, samples)
    overlap = _overlaps(merged, panels, motion, order)
    if overlap is not None and not allow_split:
        faces_txt, area = overlap
        raise BlankError(f"{skin.name}: pieces of the blank overlap in the plane (faces {faces_txt}, overlap area "
                         f"{area:.9g} {units}^2); allowed: --allow-split (allow_split=True) to keep them apart as "
                         "separate panels with matching marks, or another base face")
    if overlap is None:
        ruling3 = [panels[n].ruling_lengths_3d for n in order]
        rulingf = [panels[n].ruling_lengths_flat for n in order]
        metric = {k: np.concatenate([panels[n].metric[k] for n in order if panels[n].metric])
                  for k in ("angle_3d", "angle_flat", "xu_len", "yu_len")}
        panel = FlatPanel(label=label, loops=merged, bend_lines=np.zeros((0, 2, 2)),
                          ruling_lengths_3d=np.concatenate(ruling3), ruling_lengths_flat=np.concatenate(rulingf),
                          area_3d=float(sum(panels[n].area_3d for n in order)), metric=metric,
                          info={"method": "connected unfolding of the sheet's skin", "faces": order})
        measure_panel(panel)
        panel.bend_lines = np.asarray(lines, dtype=float).reshape(-1, 2, 2)
        h = panel.texts[0][3] if panel.texts else 1.0
        panel.bend_texts = [(x, y, s, 0.5 * h, a) for x, y, s, _, a in texts]
        out_panels = [panel]
    else:
        out_panels = []
        for n in order:
            p = panels[n]
            _apply_motion(p, motion[n])
            for loop in p.loops:  # shared edges by the skin's own 3-D edges (a bend's are on its neutral surface)
                for e in loop:
                    if e.name in skin.shared:
                        e.xyz_fn, e.xyz = _edge_uv(by_num[n].data, e.name).xyz, None
            out_panels.append(p)
        mark_shared_edges(out_panels)
        layout_panels(out_panels)
    return Blank(skin.name, out_panels, T, bends, base, order, cut, residual, area_faces)


def unfold_skins(
    skins: Sequence[SheetSkin],
    *,
    k_factor: float | KFactorTable = 0.5,
    base_face: int | None = None,
    bend_lines: str = "tangent",
    allow_split: bool = False,
    units: str = "mm",
    face_count: int = 0,
    tol_deg: float = 0.01,
    rulings: int = 8,
) -> Unfolded:
    """One blank per skin (:func:`unfold_skin`), laid out in one pattern.

    ``base_face`` applies to the skin holding it (or its opposite face); the others use their
    default base face.

    Raises:
        BlankError: from :func:`unfold_skin`; a ``base_face`` in none of the skins.
    """
    from ...pattern.flat_pattern import FlatPattern, layout_panels

    def holds(s: SheetSkin, n: int) -> bool:
        return any(f.number == n or f.partner == n for f in s.faces)

    if base_face is not None and not any(holds(s, base_face) for s in skins):
        nums = sorted(f.number for s in skins for f in s.faces)
        raise BlankError(f"base face F{base_face} is no skin face of any sheet; allowed: "
                         f"{', '.join(f'F{n}' for n in nums)} (or their opposite faces)")
    blanks = [unfold_skin(s, k_factor=k_factor, base_face=base_face if base_face is not None and holds(s, base_face) else None,
                          bend_lines=bend_lines, allow_split=allow_split, units=units, tol_deg=tol_deg, rulings=rulings)
              for s in skins]
    panels = [p for b in blanks for p in b.panels]
    if len(panels) > 1:
        layout_panels(panels)
    return Unfolded(FlatPattern(panels, units=units), blanks, face_count)
