"""Closed-form checks shared by the CAD tests of both kernels (build123d and cadquery)."""

from __future__ import annotations

import numpy as np

from ght_cad.curves.curve import gauss_legendre


def green_area(segments) -> float:
    """Exact enclosed area ½∮(x y' - y x') dt of a closed chain of planar GHT curves (Gauss 64)."""
    t, w = gauss_legendre(64)
    total = 0.0
    for s in segments:
        p, d = s.evaluate(t), s.derivative(t, 1)
        total += 0.5 * float(np.sum(w * (p[:, 0] * d[:, 1] - p[:, 1] * d[:, 0])))
    return abs(total)
