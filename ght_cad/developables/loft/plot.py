"""PNG of the sign of the loft function ``F(t, s)`` over the (t, s) square (matplotlib, imported
inside the function)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...core.errors import GHTError
from .equation import _Pair
from .rails import as_rail
from .surface import DevelopableLoft


def plot_loft_sign(rail_a: Any, rail_b: Any, path: Any, *, loft: DevelopableLoft | None = None, resolution: int = 241) -> Any:
    r"""PNG of the sign of ``F(t, s) = det(a'(t), b'(s), b(s) - a(t))`` over the (t, s) square.

    Blue where F < 0, red where F > 0: the zero set (the boundary between the colours) holds the
    possible rulings; a developable loft over the whole rails is an increasing branch from the
    lower-left to the upper-right sides. With ``loft`` its path (fans along the sides, the traced
    branch) is drawn in black. 800 x 800 pixels, written atomically (:mod:`ght_cad.curves.plotting`
    conventions: Agg canvas, no pyplot).

    Returns:
        The written path.
    """
    from ...curves.plotting import DPI, _save
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    if isinstance(resolution, bool) or not isinstance(resolution, (int, np.integer)) or resolution < 9:
        raise GHTError(f"resolution={resolution!r} is not allowed; it must be an integer >= 9")
    ra = as_rail(rail_a, "rail_a")
    rb = as_rail(rail_b, "rail_b")
    g = np.linspace(0.0, 1.0, resolution)
    T, S = np.meshgrid(g, g, indexing="ij")
    f = _Pair(ra, rb, 1.0).f(T.ravel(), S.ravel()).reshape(T.shape)
    fig = Figure(figsize=(800 / DPI, 800 / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.pcolormesh(g, g, np.sign(f).T, cmap=ListedColormap(["#4a7bd0", "#f0f0f0", "#d05a4a"]), vmin=-1, vmax=1, shading="nearest")
    ax.contour(g, g, f.T, levels=[0.0], colors="#303030", linewidths=0.6)
    if loft is not None:
        lam = np.linspace(0.0, 1.0, 801)
        t, s = loft.parameters(lam)
        ax.plot(t, s, color="black", lw=2.2, label="loft path (fans on the sides)")
        ax.legend(loc="upper left")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.set_aspect("equal")
    ax.set_xlabel("t (rail_a)")
    ax.set_ylabel("s (rail_b)")
    ax.set_title("sign of F(t, s) = det(a', b', b - a): red > 0, blue < 0")
    return _save(fig, path)

