"""The GHT curves of a chain (kernel-free): shared by the build123d adapters (:mod:`.curves`) and the
cadquery plugin (:mod:`.cq_plugin`), which must not import build123d (the ``[cadquery]`` extra)."""

from __future__ import annotations

from typing import Any

from ..curves.curve import GHTCurve
from ..core.errors import GHTError


def _as_curve(curve: Any) -> GHTCurve:
    if isinstance(curve, GHTCurve):
        if curve.dim not in (2, 3):
            raise GHTError(f"a CAD edge needs a 2-D or 3-D curve; this curve has dim={curve.dim}")
        return curve
    raise GHTError(f"expected a GHTCurve, got {type(curve).__name__}")


def segments_of(curves: Any) -> tuple[list[GHTCurve], bool | None]:
    """``(segments, closed)`` of a CompositeCurve (``.segments``, ``.closed``), a GHTCurve or a list.

    ``closed`` is the composite's own flag, or ``None`` when not known (then decided by geometry).
    """
    if isinstance(curves, GHTCurve):
        return [curves], None
    segs = getattr(curves, "segments", None)
    closed = getattr(curves, "closed", None)
    if segs is None:
        segs = curves
    try:
        segs = list(segs)
    except TypeError:
        raise GHTError(
            f"expected a GHTCurve, a CompositeCurve or a sequence of GHTCurves; got {type(curves).__name__}"
        ) from None
    if not segs:
        raise GHTError("no segments: a wire needs at least one GHT curve")
    return [_as_curve(s) for s in segs], (None if closed is None else bool(closed))
