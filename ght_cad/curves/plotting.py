r"""PNG figures of GHT bases, curves, curvature, surfaces, flat patterns and optimizer runs.

Headless: matplotlib is imported inside each function and only its object-oriented API with the
Agg canvas is used (no ``pyplot``, no global backend switch), so ``import ght_cad`` never imports
matplotlib. Every PNG is written atomically through :func:`ght_cad.core.io.atomic_path` and has a
fixed pixel size, listed in :data:`SIZES` (width, height in pixels at 100 dpi):

==============  ===========
figure          pixels
==============  ===========
basis           1200 x 800
curve            800 x 700
curvature        900 x 500
surface          900 x 700
flat_pattern     900 x 700
convergence      800 x 500
==============  ===========
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

from ..core._validate import check_degree, check_shape_parameter
from ..core.errors import GHTError
from ..core.io import atomic_path

__all__ = [
    "SIZES",
    "DPI",
    "MAX_PLOT_DEGREE",
    "plot_basis",
    "plot_curve",
    "plot_curvature",
    "plot_surface",
    "plot_flat_pattern",
    "plot_convergence",
]

#: Largest degree :func:`plot_basis` draws (m + 1 lines per panel; beyond this the plot is unreadable
#: and matplotlib takes minutes).
MAX_PLOT_DEGREE = 200

#: Dots per inch used for every figure (pixel size = inches x DPI, exactly).
DPI = 100

#: Fixed pixel sizes ``(width, height)`` of each figure kind.
SIZES: dict[str, tuple[int, int]] = {
    "basis": (1200, 800),
    "curve": (800, 700),
    "curvature": (900, 500),
    "surface": (900, 700),
    "flat_pattern": (900, 700),
    "convergence": (800, 500),
}


def _figure(kind: str) -> Any:
    """A matplotlib ``Figure`` with an Agg canvas of the fixed size of ``kind``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    w, h = SIZES[kind]
    fig = Figure(figsize=(w / DPI, h / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Any, path: str | os.PathLike) -> Path:
    """Save ``fig`` as PNG atomically (no ``bbox_inches``: the pixel size stays fixed)."""
    target = Path(path)
    with atomic_path(target) as tmp:
        fig.savefig(str(tmp), format="png", dpi=DPI)
    return target


def _check_params(params: Iterable[Sequence[float]]) -> list[tuple[float, float, float]]:
    out = []
    for k, p in enumerate(params):
        try:
            mu, nu, gamma = p
        except (TypeError, ValueError):
            raise GHTError(f"params[{k}]={p!r} must be a triple (mu, nu, gamma)") from None
        out.append(
            (
                check_shape_parameter("mu", mu),
                check_shape_parameter("nu", nu),
                check_shape_parameter("gamma", gamma),
            )
        )
    if not out:
        raise GHTError("params is empty; give at least one (mu, nu, gamma) triple")
    if len(out) > 12:
        raise GHTError(f"params has {len(out)} triples; at most 12 panels are drawn")
    return out


def plot_basis(
    path: str | os.PathLike,
    degree: int,
    params: Iterable[Sequence[float]] = ((0.0, 0.0, -1.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (-0.8, 0.8, 0.0)),
    derivative: int = 0,
    samples: int = 301,
) -> Path:
    r"""Plot the degree-m GHT-Bernstein basis ``b^{(r)}_{i,m}(t; μ,ν,γ)``, one panel per triple.

    ``b_{i,m}(t) = B_{i,n} f0 + B_{i-1,n} f1 + B_{i-2,n} f2`` (spec section 2). Each panel also
    shows the classical Bernstein basis of the same degree (thin dashed grey) for comparison.

    Args:
        path: PNG file to write (1200 x 800 pixels).
        degree: basis degree m, 2 <= m <= :data:`MAX_PLOT_DEGREE`.
        params: 1..12 shape-parameter triples ``(mu, nu, gamma)``, each in [-1, 1].
        derivative: derivative order r in 0..3.
        samples: number of parameter values along [0, 1].

    Returns:
        The written path.

    Raises:
        GHTError: degree < 2 or > MAX_PLOT_DEGREE, a parameter outside [-1, 1], bad derivative order or bad params.
    """
    from .basis import basis

    m = check_degree(degree)
    if m > MAX_PLOT_DEGREE:
        raise GHTError(f"degree={degree} is too large to plot (one line per basis function); "
                       f"allowed for the plot: 2..{MAX_PLOT_DEGREE}")
    triples = _check_params(params)
    t = np.linspace(0.0, 1.0, int(samples))
    ref = basis(t, m, 0.0, 0.0, 1.0, derivative)
    fig = _figure("basis")
    n = len(triples)
    cols = min(n, 2 if n <= 4 else 3 if n <= 9 else 4)
    rows = math.ceil(n / cols)
    label = "b" if derivative == 0 else "b" + "'" * int(derivative)
    for k, (mu, nu, gamma) in enumerate(triples):
        ax = fig.add_subplot(rows, cols, k + 1)
        B = basis(t, m, mu, nu, gamma, derivative)
        for i in range(m + 1):
            ax.plot(t, ref[:, i], color="0.7", lw=0.7, ls="--")
            ax.plot(t, B[:, i], lw=1.5, label=f"{label}$_{{{i},{m}}}$")
        ax.set_title(f"μ={mu:g}, ν={nu:g}, γ={gamma:g}", fontsize=10)
        ax.set_xlim(0.0, 1.0)
        ax.grid(True, lw=0.3)
        if k == 0 and m <= 8:
            ax.legend(fontsize=7, ncol=2, loc="best")
    fig.suptitle(
        f"GHT-Bernstein basis, degree {m}" + (f", derivative {derivative}" if derivative else "")
        + " (dashed: classical Bernstein)",
        fontsize=12,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    return _save(fig, path)


def _project(points: np.ndarray, azim: float = -60.0, elev: float = 25.0) -> np.ndarray:
    """2-D view coordinates of (N, 3) points (orthographic projection, viewer angles in degrees)."""
    a, e = math.radians(azim), math.radians(elev)
    right = np.array([-math.sin(a), math.cos(a), 0.0])
    up = np.array([-math.sin(e) * math.cos(a), -math.sin(e) * math.sin(a), math.cos(e)])
    return np.column_stack([points @ right, points @ up])


def _as_curves(curve: Any) -> list[Any]:
    curves = list(curve) if isinstance(curve, (list, tuple)) else [curve]
    if not curves:
        raise GHTError("no curve to plot; give a GHTCurve or a non-empty list of them")
    return curves


def plot_curve(curve: Any, path: str | os.PathLike, show_polygon: bool = True, samples: int = 400) -> Path:
    r"""Plot a GHT-Bézier curve ``P(t) = Σ b_{i,m}(t) P_i`` (or several) with the control polygon.

    2-D curves are drawn as they are; 3-D curves on a matplotlib 3-D axis; other dimensions use
    their first two coordinates. A list of curves (e.g. joined segments) is drawn in one figure.

    Args:
        curve: a :class:`ght_cad.GHTCurve` (anything with ``evaluate`` and ``control_points``)
            or a list of them.
        path: PNG file to write (800 x 700 pixels).
        show_polygon: also draw the control polygons and their points.
        samples: number of parameter values per curve.

    Returns:
        The written path.
    """
    curves = _as_curves(curve)
    t = np.linspace(0.0, 1.0, int(samples))
    fig = _figure("curve")
    dims = {int(np.asarray(c.control_points).shape[1]) for c in curves}
    three_d = dims == {3}
    if len(curves) == 1:
        c0 = curves[0]
        title = f"GHT-Bézier curve, degree {c0.degree}"
        if hasattr(c0, "shape_parameters"):
            mu, nu, gamma = c0.shape_parameters
            title += f"  (μ={mu:g}, ν={nu:g}, γ={gamma:g})"
    else:
        title = f"{len(curves)} GHT-Bézier curves"
    ax = fig.add_subplot(1, 1, 1, projection="3d") if three_d else fig.add_subplot(1, 1, 1)
    for k, c in enumerate(curves):
        pts = np.asarray(c.evaluate(t), dtype=float)
        cps = np.asarray(c.control_points, dtype=float)
        col = f"C{(2 * k) % 10}"
        lab = "curve" if len(curves) == 1 else f"curve {k + 1}"
        poly_lab = "control polygon" if k == 0 else None
        if three_d:
            ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], lw=2.0, color=col, label=lab)
            if show_polygon:
                ax.plot(cps[:, 0], cps[:, 1], cps[:, 2], "o--", color="C3", lw=0.9, ms=3.5, label=poly_lab)
        else:
            y = pts[:, 1] if pts.shape[1] > 1 else np.zeros(len(pts))
            ax.plot(pts[:, 0], y, lw=2.0, color=col, label=lab)
            if show_polygon:
                cy = cps[:, 1] if cps.shape[1] > 1 else np.zeros(len(cps))
                ax.plot(cps[:, 0], cy, "o--", color="C3", lw=0.9, ms=3.5, label=poly_lab)
                if len(curves) == 1:
                    for i, (x, yy) in enumerate(zip(cps[:, 0], cy)):
                        ax.annotate(f"P{i}", (x, yy), textcoords="offset points", xytext=(4, 4), fontsize=8)
    if three_d:
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_zlabel("z")
    else:
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, lw=0.3)
        ax.set_xlabel("x")
        ax.set_ylabel("y")
    ax.legend(fontsize=8, loc="best")
    ax.set_title(title, fontsize=11)
    return _save(fig, path)


def plot_curvature(curve: Any, path: str | os.PathLike, samples: int = 400) -> Path:
    r"""Plot the curvature ``κ(t) = |P' × P''| / |P'|³`` along a curve (and torsion for 3-D).

    For a list of curves (joined segments) segment k is drawn over ``[k, k+1]``, so a G2 joint
    shows as a continuous curvature graph and a G1 joint as a jump.

    Args:
        curve: a :class:`ght_cad.GHTCurve` or a list of them.
        path: PNG file to write (900 x 500 pixels).
        samples: number of parameter values per curve.

    Returns:
        The written path.
    """
    from .curve import curvature_from_derivatives

    curves = _as_curves(curve)
    t = np.linspace(0.0, 1.0, int(samples))
    fig = _figure("curvature")
    ax = fig.add_subplot(1, 1, 1)
    kmax = 0.0
    ax2 = None
    for k, c in enumerate(curves):
        with np.errstate(all="ignore"):
            kappa = curvature_from_derivatives(c.derivative(t, 1), c.derivative(t, 2))  # NaN where P' = 0
        if np.isfinite(kappa).any():  # all NaN: the control points coincide (a point)
            kmax = max(kmax, float(np.nanmax(kappa)))
        ax.plot(t + k, kappa, lw=1.8, color="C0", label="curvature κ" if k == 0 else None)
        if getattr(c, "dim", 0) == 3:
            tau = np.asarray(c.torsion(t), dtype=float)
            if np.all(np.isfinite(tau)) and np.max(np.abs(tau)) > 1e-12:
                if ax2 is None:
                    ax2 = ax.twinx()
                    ax2.set_ylabel("torsion τ", color="C2")
                ax2.plot(t + k, tau, lw=1.0, color="C2", ls="--", label="torsion τ (right axis)" if k == 0 else None)
        if k:
            ax.axvline(k, color="0.5", lw=0.6, ls=":")
    ax.set_xlabel("t" if len(curves) == 1 else "segment index + t")
    ax.set_ylabel("curvature κ", color="C0")
    ax.set_xlim(0.0, float(len(curves)))
    ax.grid(True, lw=0.3)
    handles, labels = ax.get_legend_handles_labels()
    if ax2 is not None:
        h2, l2 = ax2.get_legend_handles_labels()
        handles, labels = handles + h2, labels + l2
    ax.legend(handles, labels, fontsize=8, loc="upper left")
    ax.set_title(f"Curvature along the curve{'s' if len(curves) > 1 else ''} (max κ = {kmax:.4g})", fontsize=11)
    fig.tight_layout()
    return _save(fig, path)


def plot_surface(
    surface: Any,
    path: str | os.PathLike,
    nu: int = 41,
    nv: int = 9,
    title: str | None = None,
    colour_by_theta: bool = True,
) -> Path:
    r"""Rendered 3-D view of a ruled surface ``X(u, v) = (1-v) a(u) + v b(u)``.

    Faces are coloured by the normal angle ``θ(u)`` between the ruling ends (spec section 5)
    when ``colour_by_theta`` (a developable surface is uniform), else by a fixed light shading.

    Args:
        surface: a :class:`ght_cad.surfaces.ruled.RuledSurface` (anything with ``grid`` and ``theta``).
        path: PNG file to write (900 x 700 pixels).
        nu, nv: grid resolution along u and v.
        title: figure title.
        colour_by_theta: colour map on θ(u) in degrees when θ_max > 0.001° (else one colour).

    Returns:
        The written path.
    """
    from matplotlib import cm, colors

    G = np.asarray(surface.grid(int(nu), int(nv)), dtype=float)
    fig = _figure("surface")
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    u = np.linspace(0.0, 1.0, int(nu))
    th = None
    if hasattr(surface, "theta"):
        th = np.asarray(surface.theta(u), dtype=float)
        th = np.where(np.isfinite(th), th, 0.0)
    if colour_by_theta and th is not None and float(th.max()) > 1e-3:
        norm = colors.Normalize(vmin=0.0, vmax=float(th.max()))
        cmap = cm.YlOrRd
        face = cmap(norm(np.repeat(th[:, None], int(nv), axis=1)))
        ax.plot_surface(G[..., 0], G[..., 1], G[..., 2], facecolors=face, shade=True, lw=0.2, edgecolor="0.3")
        sm = cm.ScalarMappable(norm=norm, cmap=cmap)
        sm.set_array(th)
        fig.colorbar(sm, ax=ax, shrink=0.5, pad=0.12, label="θ(u) [deg]")
    else:
        ax.plot_surface(G[..., 0], G[..., 1], G[..., 2], color="#8fb3dc", shade=True, lw=0.2, edgecolor="0.45")
    # rulings
    for i in range(0, int(nu), max(1, int(nu) // 10)):
        ax.plot(G[i, :, 0], G[i, :, 1], G[i, :, 2], color="k", lw=0.6)
    lo = G.reshape(-1, 3).min(axis=0)
    hi = G.reshape(-1, 3).max(axis=0)
    span = float(np.max(hi - lo)) or 1.0
    # true proportions, but no axis shorter than 35 % of the longest (keeps long plates readable)
    ext = np.maximum(hi - lo, 0.35 * span)
    mid = 0.5 * (lo + hi)
    ax.set_xlim(mid[0] - ext[0] / 2, mid[0] + ext[0] / 2)
    ax.set_ylim(mid[1] - ext[1] / 2, mid[1] + ext[1] / 2)
    ax.set_zlim(mid[2] - ext[2] / 2, mid[2] + ext[2] / 2)
    ax.set_box_aspect(tuple(float(e) for e in ext / ext.max()), zoom=1.1)
    # look at the surface along its mean normal (from the side the normal points to)
    if hasattr(surface, "normal"):
        uu = np.repeat(np.linspace(0.1, 0.9, 9), 3)
        vv = np.tile([0.25, 0.5, 0.75], 9)
        n = np.asarray(surface.normal(uu, vv), dtype=float)
        n = n[np.all(np.isfinite(n), axis=1)]
        if len(n):
            m = n.mean(axis=0)
            if np.linalg.norm(m) > 1e-9:
                m = m / np.linalg.norm(m)
                azim = math.degrees(math.atan2(m[1], m[0])) + 20.0
                elev = float(np.clip(math.degrees(math.asin(np.clip(m[2], -1, 1))), 15.0, 50.0))
                ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    head = title or "Ruled surface"
    if th is not None:
        head += f"  (θ_max = {float(th.max()):.2g}°)"
    ax.set_title(head, fontsize=11)
    return _save(fig, path)


def plot_flat_pattern(outlines: Sequence[np.ndarray], path: str | os.PathLike,
                      rulings: Sequence[np.ndarray] = (), title: str | None = None,
                      labels: Sequence[tuple] = (), marks: Sequence[np.ndarray] = ()) -> Path:
    """Flat pattern: closed outline polylines (N, 2) and optional ruling segments (2, 2).

    Args:
        outlines: polylines in the plane (drawn closed).
        path: PNG file to write (900 x 700 pixels).
        rulings: line segments to draw thinly (the rulings in the plane).
        title: figure title.
        labels: ``(x, y, text, ...)`` tuples: panel names and edge marks (``FlatPattern.labels``).
        marks: polylines of the matching edge marks (``FlatPattern.marks``).

    Returns:
        The written path.
    """
    fig = _figure("flat_pattern")
    ax = fig.add_subplot(1, 1, 1)
    for seg in rulings:
        s = np.asarray(seg, dtype=float)
        ax.plot(s[:, 0], s[:, 1], color="0.6", lw=0.5)
    for k, poly in enumerate(outlines):
        p = np.asarray(poly, dtype=float)
        p = np.vstack([p, p[:1]])
        ax.plot(p[:, 0], p[:, 1], color="C0", lw=1.6)
        ax.fill(p[:, 0], p[:, 1], color="C0", alpha=0.12)
    for mk in marks:
        m = np.asarray(mk, dtype=float)
        ax.plot(m[:, 0], m[:, 1], color="C3", lw=1.2)
    for lab in labels:
        ax.text(float(lab[0]), float(lab[1]), str(lab[2]), ha="center", va="center", fontsize=9,
                color="C3" if str(lab[2]).startswith("E") else "k")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, lw=0.3)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(title or "Flat pattern", fontsize=11)
    return _save(fig, path)


def plot_convergence(histories: Mapping[str, Sequence[float]], path: str | os.PathLike,
                     title: str | None = None, log: bool = True) -> Path:
    """Best objective value per iteration, one line per optimizer run.

    Args:
        histories: ``{label: best value per iteration}``.
        path: PNG file to write (800 x 500 pixels).
        title: figure title.
        log: logarithmic y axis (when all values are positive).

    Returns:
        The written path.
    """
    if not histories:
        raise GHTError("histories is empty; give at least one optimizer history")
    fig = _figure("convergence")
    ax = fig.add_subplot(1, 1, 1)
    allpos = True
    for label, hist in histories.items():
        h = np.asarray(list(hist), dtype=float)
        allpos &= bool(np.all(h > 0))
        ax.plot(np.arange(len(h)), h, lw=1.6, label=str(label))
    if log and allpos:
        ax.set_yscale("log")
    ax.set_xlabel("iteration")
    ax.set_ylabel("best objective")
    ax.grid(True, lw=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title(title or "Optimizer convergence", fontsize=11)
    fig.tight_layout()
    return _save(fig, path)
