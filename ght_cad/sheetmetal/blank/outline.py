r"""The blank's outline: the placed faces' boundary edges chained into closed loops (the tree's
shared edges left out). Moved from ``ght_cad/sheetmetal/blank.py`` (issue 27); every name is importable from
:mod:`ght_cad.sheetmetal.blank`."""

from __future__ import annotations

from typing import Any

import numpy as np

from .model import BlankError
from .placement import _Motion


def _merge(panels: dict[int, Any], motion: dict[int, _Motion], order: list[int], tree: set[str],
           label: str, samples: int) -> list[list[Any]]:
    """The blank's loops: every face's boundary edges except the tree's shared edges, moved into
    place and chained end to start (reversing where needed); the largest loop first."""
    from ...pattern.flat_pattern import BoundaryEdge, _shoelace

    pieces = []
    for n in order:
        p = panels[n]
        off = p.offset.copy()
        m = motion[n]
        for loop in p.loops:
            for e in loop:
                if e.name in tree:
                    continue
                f = e.flat_fn
                ends = m(np.asarray(f(np.array([0.0, 1.0])), dtype=float) + off)
                pieces.append((n, e, ends))
    if not pieces:
        raise BlankError(f"{label}: the skin has no boundary edges")
    size = max(float(np.ptp(np.concatenate([pc[2] for pc in pieces]), axis=0).max()), 1e-300)
    tol = 1e-6 * size
    used = [False] * len(pieces)
    loops: list[list[Any]] = []
    for i0 in range(len(pieces)):
        if used[i0]:
            continue
        used[i0] = True
        chain = [(i0, False)]
        start = pieces[i0][2][0]
        end = pieces[i0][2][1]
        while np.linalg.norm(end - start) > tol:
            best, best_d, rev = -1, tol, False
            for j, pc in enumerate(pieces):
                if used[j]:
                    continue
                d0 = float(np.linalg.norm(pc[2][0] - end))
                d1 = float(np.linalg.norm(pc[2][1] - end))
                if d0 < best_d:
                    best, best_d, rev = j, d0, False
                if d1 < best_d:
                    best, best_d, rev = j, d1, True
            if best < 0:
                n, e, ends = pieces[chain[-1][0]]
                raise BlankError(f"{label}: the outline does not close after edge {e.name} of face F{n} (open end at "
                                 f"({end[0]:.6g}, {end[1]:.6g})); allowed: a skin whose boundary edges form closed loops")
            used[best] = True
            chain.append((best, rev))
            end = pieces[best][2][0 if rev else 1]
        loop = []
        for j, rev in chain:
            n, e, _ = pieces[j]
            m, off = motion[n], panels[n].offset.copy()
            f, x = e.flat_fn, e.xyz_fn
            if rev:
                flat_fn = (lambda t, f=f, m=m, off=off: m(np.asarray(f(1.0 - np.asarray(t)), dtype=float) + off))
                xyz_fn = (lambda t, x=x: x(1.0 - np.asarray(t)))
            else:
                flat_fn = (lambda t, f=f, m=m, off=off: m(np.asarray(f(t), dtype=float) + off))
                xyz_fn = x
            loop.append(BoundaryEdge(name=f"F{n}:{e.name}", flat_fn=flat_fn, xyz_fn=xyz_fn, length_3d=e.length_3d,
                                     samples=samples, breaks=tuple(1.0 - b for b in reversed(e.breaks)) if rev else e.breaks))
        loops.append(loop)
    areas = []
    for loop in loops:
        pts = np.concatenate([le.flat_fn(np.linspace(0.0, 1.0, 17))[:-1] for le in loop], axis=0)
        areas.append(abs(_shoelace(pts)))
    k = int(np.argmax(areas))
    loops.insert(0, loops.pop(k))
    return loops
