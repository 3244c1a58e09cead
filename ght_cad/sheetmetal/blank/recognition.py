r"""Sheet recognition, the kernel-free part shared by the OCP and FreeCAD adapters: the sheet's
thickness, its two skins and its walls from the adapter's probes. Moved from ``ght_cad/sheetmetal/blank.py``
(issue 27); every name is importable from :mod:`ght_cad.sheetmetal.blank`."""

from __future__ import annotations

import math
from collections import deque
from typing import Callable, Sequence

import numpy as np

from .model import BlankError


# -- sheet recognition (the kernel-free part shared by the OCP and FreeCAD adapters) ------------------
#: relative tolerance on the distance of a skin point to the other skin (of T) and on antiparallel normals
DIST_TOL = 1e-6
#: largest angle (degrees) between two skin faces' normals across a shared edge that counts as tangent
SHARP_DEG = 1e-3


def _check_pairing(sname: str, nums: Sequence[int], T: float, skin_of: Sequence[bool],
                   rays: Sequence[Sequence[tuple[float, bool, int]]], edges: dict[str, tuple[int, int]]) -> None:
    """Refuse a solid whose faces at distance T pair up in more than one way (an ambiguous skin).

    Skin faces sharing an edge lie on one side of the sheet, a face and the faces its probes reach
    at T on opposite sides: a two-colouring of the skin faces under these relations. A cycle with an
    odd number of "opposite" relations (e.g. a bar of square section T x T: top opposite bottom and
    left opposite right, yet top shares an edge with left and right) has none: no inside and
    outside skin exist.

    Raises:
        BlankError: naming the faces of the contradiction and the distance T.
    """
    rel: dict[int, list[tuple[int, int, str]]] = {}
    for key, (a, b) in edges.items():
        if skin_of[a] and skin_of[b] and a != b:
            rel.setdefault(a, []).append((b, 0, f"shares edge {key} with"))
            rel.setdefault(b, []).append((a, 0, f"shares edge {key} with"))
    for i, row in enumerate(rays):
        for d, ok, h in row:
            if skin_of[i] and h >= 0 and h != i and skin_of[h] and ok and abs(d - T) <= DIST_TOL * T:
                rel.setdefault(i, []).append((h, 1, f"lies at {d:.9g} opposite"))
                rel.setdefault(h, []).append((i, 1, f"lies at {d:.9g} opposite"))
    side: dict[int, int] = {}
    via: dict[int, tuple[int, str]] = {}
    for start in (i for i in range(len(nums)) if skin_of[i]):
        if start in side:
            continue
        side[start] = 0
        queue = deque([start])
        while queue:
            x = queue.popleft()
            for y, flip, how in rel.get(x, []):
                want = side[x] ^ flip
                if y not in side:
                    side[y], via[y] = want, (x, how)
                    queue.append(y)
                elif side[y] != want:
                    def chain(z: int) -> list[str]:
                        out = []
                        while z in via:
                            p, h = via[z]
                            out.append(f"F{nums[z]} {h} F{nums[p]}")
                            z = p
                        return out
                    steps = "; ".join(chain(x)[::-1] + [f"F{nums[y]} {how} F{nums[x]}"] + chain(y))
                    raise BlankError(f"{sname}: ambiguous skin: the faces at distance {T:.9g} from an opposite face pair "
                                     f"up in more than one way ({steps}): no inside and outside skin separate them; "
                                     "allowed: a sheet whose faces at distance T form exactly two sides")


def classify_skin(sname: str, nums: Sequence[int], areas: Sequence[float],
                  rays: Sequence[Sequence[tuple[float, bool, int]]], edges: dict[str, tuple[int, int]],
                  angle: Callable[[str, int, int], float], base_face: int | None = None,
                  ) -> tuple[float, list[int], dict[int, int], dict[str, tuple[int, int]], int]:
    r"""Sort a solid's faces into the sheet's two skins and its walls from the adapter's probes.

    ``T`` is the distance of the largest face whose probes all leave the material at one distance
    through a face of opposite normal; a face is skin when most of its probes leave at ``T``
    (relative :data:`DIST_TOL`) through an opposite face; the skin faces must pair up one way only
    (:func:`_check_pairing`); a block (every face skin, or ``T`` more
    than a quarter of the square root of the largest skin face's area) is no sheet; two skin faces
    sharing an edge must be tangent there (at most :data:`SHARP_DEG`); every skin face must be skin
    at all its probes; the skin faces form exactly two connected sets, each face's opposite face in
    the other set.

    Args:
        sname: the solid's name (messages); nums: face numbers (messages); areas: face areas.
        rays: per face, per probe ``(distance, opposite normal, index of the face hit or -1)``.
        edges: edge key (``E<k>``) -> the indices of the two faces sharing it.
        angle: ``angle(key, a, b)``: degrees between faces a and b's normals at the edge.
        base_face: a face number whose skin is the one returned (default: the smaller skin).

    Returns:
        ``(T, comp, partner, shared, ref)``: per face its skin (0, 1) or -1 (wall), each skin face's
        opposite face index, the shared edges of skin faces, the chosen skin (0 or 1).

    Raises:
        BlankError: no sheet (a block), a sharp edge, an ambiguous skin; one line naming the
            face/edge and the measured value.
    """
    n = len(nums)
    # thickness: the largest face whose rays all leave at one distance through an opposite face
    T = None
    for i in sorted(range(n), key=lambda i: -areas[i]):
        row = rays[i]
        if row and all(ok for _, ok, _ in row):
            ds = [d for d, _, _ in row]
            if max(ds) - min(ds) <= DIST_TOL * max(ds):
                T = float(np.mean(ds))
                break
    if T is None:
        raise BlankError(f"{sname}: no sheet: no face lies at a constant distance from an opposite face "
                         f"(largest face F{nums[int(np.argmax(areas))]}); allowed: sheet solids of one thickness")
    skin_of = []
    for i, row in enumerate(rays):
        good = [ok and abs(d - T) <= DIST_TOL * T for d, ok, _ in row]
        skin_of.append(bool(row) and sum(good) * 2 > len(row))
    if all(skin_of):
        raise BlankError(f"{sname}: no sheet: every face lies at distance {T:.9g} from an opposite face, no thickness "
                         "walls separate two sides (a block); allowed: sheet solids")
    big = max(areas[i] for i in range(n) if skin_of[i])
    if T > 0.25 * math.sqrt(big):
        raise BlankError(f"{sname}: no sheet: its thickness {T:.9g} is more than a quarter of the square root of its "
                         f"largest skin face's area {big:.9g} (a block); allowed: sheets thinner than that")
    _check_pairing(sname, nums, T, skin_of, rays, edges)
    shared: dict[str, tuple[int, int]] = {}
    for key, (a, b) in edges.items():
        if not (skin_of[a] and skin_of[b]):
            continue
        ang = float(angle(key, a, b))
        if ang > SHARP_DEG:
            raise BlankError(f"{sname}: sharp edge {key} between skin faces F{nums[a]} and F{nums[b]}: "
                             f"they meet at {ang:.6g} deg (a bend of zero radius); allowed: bends with an inside "
                             "radius > 0 (tangent faces)")
        shared[key] = (a, b)
    for i, row in enumerate(rays):
        if not skin_of[i]:
            continue
        bad = [d for d, ok, _ in row if not (ok and abs(d - T) <= DIST_TOL * T)]
        if bad:
            raise BlankError(f"{sname}: ambiguous skin: face F{nums[i]} lies at distance {T:.9g} from the other skin "
                             f"at {len(row) - len(bad)} of {len(row)} points but {min(bad):.9g} at others; allowed: "
                             "sheets of one thickness whose faces pair up")
    # connected sets of skin faces
    comp = [-1] * n
    adj: dict[int, list[int]] = {}
    for a, b in shared.values():
        adj.setdefault(a, []).append(b)
        adj.setdefault(b, []).append(a)
    ncomp = 0
    for i in range(n):
        if skin_of[i] and comp[i] < 0:
            stack = [i]
            comp[i] = ncomp
            while stack:
                x = stack.pop()
                for y in adj.get(x, []):
                    if comp[y] < 0:
                        comp[y] = ncomp
                        stack.append(y)
            ncomp += 1
    if ncomp != 2:
        what = ("one closed skin: no thickness walls separate two sides (a block)" if ncomp == 1 else
                f"{ncomp} separate sets of faces at distance {T:.9g}")
        raise BlankError(f"{sname}: {'no sheet' if ncomp == 1 else 'ambiguous skin'}: the faces at distance {T:.9g} "
                         f"from an opposite face form {what}; allowed: one sheet solid with an inside and an outside skin")
    partner: dict[int, int] = {}
    for i, row in enumerate(rays):
        if not skin_of[i]:
            continue
        hits = [h for _, _, h in row if h >= 0]
        other = [h for h in hits if comp[h] != comp[i]]
        if not hits or len(other) != len(hits):
            raise BlankError(f"{sname}: ambiguous skin: face F{nums[i]}'s opposite points lie on its own side of the "
                             "sheet; allowed: an inside and an outside skin")
        partner[i] = max(set(other), key=other.count)
    area_c = [sum(areas[i] for i in range(n) if comp[i] == c) for c in (0, 1)]
    ref = int(np.argmin(area_c))
    if base_face is not None and base_face in nums:
        bi = list(nums).index(base_face)
        if skin_of[bi]:
            ref = comp[bi]
    return T, comp, partner, shared, ref
