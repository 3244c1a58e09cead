r"""Per-strip fitting: loft or dual fit of each strip (seams of the dual strips, the greedy choice
of methods) and building a panel between two seams. Moved from ``ght_cad/approximation.py``
(issue 27); every name is importable from :mod:`ght_cad.approximation`.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.errors import GHTError
from .frame import _Frame
from .seams import _Seam
from .result import ConeStrip
from .splitting import _strip_range


def _strip_dev(frame: _Frame, A: _Seam, B: _Seam) -> float:
    """Sampled one-way deviation ``max |d|`` of the loft between two seams (the march's ruling
    samples); ``inf`` where the rulings cannot be found."""
    try:
        lo, hi = _strip_range(frame, A, B)
    except (GHTError, FloatingPointError, ValueError):
        return math.inf
    v = max(-lo, hi)
    return v if math.isfinite(v) else math.inf


def _dual_seams(frame: _Frame, loft: list[_Seam], duals: list[Any], chosen: list[bool]) -> list[_Seam]:
    r"""Seams of a method mix: seam j is the trimmed boundary ``δ_j = h(x, y_j)`` of the dual fit of
    the chosen neighbouring strip (the mean of the two Chebyshev series when both neighbours are
    dual), else the loft seam of step 2. Every panel is then the loft between its two seams, so
    neighbours share the seam curve exactly whatever their methods."""
    out = []
    for j, sm in enumerate(loft):
        props = []
        if j - 1 >= 0 and chosen[j - 1]:
            props.append(duals[j - 1].delta_hi)
        if j < len(chosen) and chosen[j]:
            props.append(duals[j].delta_lo)
        if not props or sm.point:
            out.append(sm)
            continue
        c = np.zeros(max(p.size for p in props))
        for p in props:
            c[: p.size] += p / len(props)
        out.append(_Seam(frame, sm.y, c))
    return out


def _choose_methods(frame: _Frame, loft: list[_Seam], duals: list[Any], method: str) -> tuple[list[bool], list[dict[str, float]]]:
    r"""Per strip: loft or dual (module doc, step 4). ``method="dual"``: every strip whose dual fit
    is usable. ``"auto"``: greedy by gain ``e_loft - e_dual`` (sampled deviations of the loft
    between the loft seams and between the dual fit's own trimmed seams); a strip turns dual only if
    the largest deviation of it and its two neighbours (whose shared seams change) goes down, a seam
    between two dual strips being the mean of their trimmed boundaries."""
    n = len(duals)
    e_loft = [_strip_dev(frame, A, B) for A, B in zip(loft[:-1], loft[1:])]
    e_dual = []
    for i, d in enumerate(duals):
        if d is None or not d.ok:
            e_dual.append(math.inf)
            continue
        A = loft[i] if loft[i].point else _Seam(frame, loft[i].y, d.delta_lo)
        B = loft[i + 1] if loft[i + 1].point else _Seam(frame, loft[i + 1].y, d.delta_hi)
        e_dual.append(_strip_dev(frame, A, B))
    info = [{"deviation_loft": e_loft[i], "deviation_dual": e_dual[i]} for i in range(n)]
    if method == "dual":
        return [bool(d is not None and d.ok and math.isfinite(e_dual[i])) for i, d in enumerate(duals)], info
    chosen = [False] * n
    cur = list(e_loft)
    for i in sorted(range(n), key=lambda k: e_dual[k] - e_loft[k]):
        if not e_dual[i] < e_loft[i]:
            break
        trial = chosen.copy()
        trial[i] = True
        seams = _dual_seams(frame, loft, duals, trial)
        near = [k for k in (i - 1, i, i + 1) if 0 <= k < n]
        alone = not any(0 <= k < n and chosen[k] for k in (i - 1, i + 1))
        new = {k: (e_dual[i] if k == i and alone else _strip_dev(frame, seams[k], seams[k + 1])) for k in near}
        if max(new.values()) < max(cur[k] for k in near):
            chosen = trial
            for k, v in new.items():
                cur[k] = v
    return chosen, info


def _build_panel(frame: _Frame, A: _Seam, B: _Seam) -> Any:
    if B.point:
        return ConeStrip(A.rail(), B.eval(np.array([0.5]), 0)[0][0])
    if A.point:
        return ConeStrip(B.rail(), A.eval(np.array([0.5]), 0)[0][0])
    from ..core.errors import NotDevelopableError
    from ..developables.loft import developable_loft

    try:
        return developable_loft(A.rail(), B.rail(), orientation="same", samples=65)
    except NotDevelopableError:  # the arc-length rails failed: the target's own parameters
        return developable_loft(A.rail(False), B.rail(False), orientation="same", samples=65)
