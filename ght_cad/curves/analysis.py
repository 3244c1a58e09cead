r"""Curvature analysis of GHT curves and composite curves (spec sections 3–4).

Everything is analytic, from the derivatives up to order 3 (``d_r = X^(r)``, any dimension):

* curvature ``κ = sqrt(G) / a^{3/2}`` with ``a = |d1|²``, ``b = |d2|²``, ``c = d1·d2``,
  ``G = a b - c²`` (``= |d1 × d2|²`` in 3-D);
* curvature vector ``K = (d2 - (c/a) d1) / a`` (``|K| = κ``, pointing to the centre of curvature);
* ``dκ/dσ`` with respect to arc length σ: ``dκ/dt = [a (d2·d3) - c (d1·d3)] / (sqrt(G) a^{3/2})
  - 3 c sqrt(G) / a^{5/2}``, ``dκ/dσ = (dκ/dt) / sqrt(a)``. In 2-D the signed curvature
  ``κ_s = (d1 × d2) / a^{3/2}`` is used, ``dκ_s/dt = (d1 × d3)/a^{3/2} - 3 c (d1 × d2)/a^{5/2}``,
  and ``dκ/dσ = sign(κ_s) dκ_s/dσ``; in other dimensions ``dκ/dσ`` is NaN where ``κ = 0``
  (|κ| is not differentiable there).

The thesis compares the curvature continuity of GHT-Bézier and Bézier chains:
:func:`bezier_chain_like` builds the classical Bézier chain (γ = 1) on the same control points
and :func:`compare_curvature` reports the curvature jumps at the joints of both, with a
side-by-side PNG. PNGs are written atomically (matplotlib is imported inside the functions; figures
use the Agg canvas directly, pyplot and its global backend are never touched).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Union

import numpy as np

from .composite import CompositeCurve
from .curve import GHTCurve, curvature_from_derivatives
from ..core.errors import GHTError
from ..core._quadrature import leggauss
from ..core._validate import is_real
from ..core.io import atomic_path

__all__ = [
    "curvature",
    "signed_curvature",
    "curvature_vector",
    "curvature_derivative",
    "curvature_profile",
    "joint_curvatures",
    "curvature_comb_plot",
    "bezier_chain_like",
    "compare_curvature",
]

CurveLike = Union[GHTCurve, CompositeCurve]


def _check_curve(curve: Any) -> CurveLike:
    if not isinstance(curve, (GHTCurve, CompositeCurve)):
        raise GHTError(f"expected a GHTCurve or CompositeCurve, got {type(curve).__name__}")
    return curve


def _domain(curve: CurveLike) -> float:
    return float(curve.n_segments) if isinstance(curve, CompositeCurve) else 1.0


def _jets(curve: CurveLike, s: Any, order: int) -> list[np.ndarray]:
    d = [np.atleast_2d(curve.derivative(s, r)) for r in range(1, order + 1)]
    return d


def _cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]


def _maybe_scalar(s: Any, arr: np.ndarray) -> Any:
    return arr[0] if np.ndim(s) == 0 else arr


def curvature(curve: CurveLike, s: Any) -> np.ndarray:
    r"""Curvature ``κ = |X' × X''| / |X'|³ = |X'' - (X'·X''/|X'|²) X'| / |X'|²``.

    The second form (:func:`ght_cad.curves.curve.curvature_from_derivatives`) keeps a straight line's
    curvature at round-off level (the Gram form ``sqrt(a b - c²)/a^{3/2}`` gave ~1e-8 there).

    Args:
        curve: a GHTCurve (s = t ∈ [0, 1]) or CompositeCurve (s ∈ [0, n_segments]).
        s: parameter value(s).

    Returns:
        κ >= 0 at each s (inf where the speed vanishes).
    """
    d1, d2 = _jets(_check_curve(curve), s, 2)
    return _maybe_scalar(s, curvature_from_derivatives(d1, d2))


def signed_curvature(curve: CurveLike, s: Any) -> np.ndarray:
    r"""Signed curvature ``κ_s = (x'y'' - y'x'') / |X'|³`` of a 2-D curve (positive: turning left).

    Raises:
        GHTError: the curve is not 2-D.
    """
    curve = _check_curve(curve)
    if curve.dim != 2:
        raise GHTError(f"signed curvature needs a 2-D curve; this curve has dim={curve.dim}")
    d1, d2 = _jets(curve, s, 2)
    a = np.sum(d1 * d1, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return _maybe_scalar(s, _cross2(d1, d2) / a**1.5)


def curvature_vector(curve: CurveLike, s: Any) -> np.ndarray:
    r"""Curvature vector ``K = (X'' - (X'·X''/|X'|²) X') / |X'|²`` (``|K| = κ``, towards the centre).

    Returns:
        Array (len(s), dim), or (dim,) for scalar s.
    """
    d1, d2 = _jets(_check_curve(curve), s, 2)
    a = np.sum(d1 * d1, axis=1)[:, None]
    c = np.sum(d1 * d2, axis=1)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        K = (d2 - (c / a) * d1) / a
    return _maybe_scalar(s, K)


def curvature_derivative(curve: CurveLike, s: Any) -> np.ndarray:
    r"""Derivative ``dκ/dσ`` of the curvature with respect to arc length σ (analytic, order 3).

    General dimension: ``dκ/dt = [a (X''·X''') - c (X'·X''')] / (sqrt(G) a^{3/2}) - 3 c sqrt(G)/a^{5/2}``
    with ``G = a b - c²``; ``dκ/dσ = (dκ/dt)/|X'|``. NaN where κ = 0 (not differentiable).
    2-D: ``dκ/dσ = sign(κ_s) dκ_s/dσ`` with
    ``dκ_s/dt = (X' × X''')/a^{3/2} - 3 c (X' × X'')/a^{5/2}`` (defined at inflections too: there
    it is the one-sided value from the sign of κ_s, i.e. 0-crossings give ± |dκ_s/dσ|).

    Args:
        curve: GHTCurve or CompositeCurve.
        s: parameter value(s).

    Returns:
        dκ/dσ at each s.
    """
    curve = _check_curve(curve)
    d1, d2, d3 = _jets(curve, s, 3)
    a = np.sum(d1 * d1, axis=1)
    c = np.sum(d1 * d2, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        if curve.dim == 2:
            x12 = _cross2(d1, d2)
            dks = _cross2(d1, d3) / a**1.5 - 3.0 * c * x12 / a**2.5
            sign = np.where(x12 < 0, -1.0, 1.0)
            out = sign * dks / np.sqrt(a)
        else:
            b = np.sum(d2 * d2, axis=1)
            G = np.maximum(a * b - c * c, 0.0)
            sg = np.sqrt(G)
            num = a * np.sum(d2 * d3, axis=1) - c * np.sum(d1 * d3, axis=1)
            dk = num / (sg * a**1.5) - 3.0 * c * sg / a**2.5
            dk = np.where(sg > 1e-14 * np.sqrt(a * b + 1e-300), dk, np.nan)
            out = dk / np.sqrt(a)
    return _maybe_scalar(s, out)


def _check_samples(samples: Any, name: str = "samples_per_segment", minimum: int = 2) -> int:
    try:
        n = int(samples)
    except (TypeError, ValueError):
        raise GHTError(f"{name}={samples!r} is not an integer; it must be an integer >= {minimum}") from None
    if n != samples or n < minimum:
        raise GHTError(f"{name}={samples!r} is not allowed; it must be an integer >= {minimum}")
    return n


def _sample_parameters(curve: CurveLike, per_segment: int) -> np.ndarray:
    """Global parameters: per_segment points per unit interval, joints included once."""
    n = int(_domain(curve))
    return np.linspace(0.0, float(n), n * (per_segment - 1) + 1)


def curvature_profile(curve: CurveLike, samples_per_segment: int = 200) -> dict[str, np.ndarray]:
    r"""Sampled curvature along a curve: parameters, arc length, κ and dκ/dσ.

    Arc length ``σ(s) = ∫_0^s |X'|`` is accumulated with 8-point Gauss–Legendre on each sample
    interval (16th order in the sample spacing; use ``arc_length()`` of the curve for a
    certified total).

    Args:
        curve: GHTCurve or CompositeCurve.
        samples_per_segment: samples per unit parameter interval (>= 2).

    Returns:
        ``{"s", "arc_length", "kappa", "dkappa_ds"}`` arrays of equal length. At a joint the
        sample belongs to the segment on its right.
    """
    curve = _check_curve(curve)
    n = _check_samples(samples_per_segment)
    s = _sample_parameters(curve, n)
    x, w = leggauss(8)
    lo, hi = s[:-1], s[1:]
    h = 0.5 * (hi - lo)
    nodes = (lo[:, None] + h[:, None] * (x[None, :] + 1.0)).ravel()
    speed = np.linalg.norm(np.atleast_2d(curve.derivative(nodes, 1)), axis=1).reshape(-1, 8)
    pieces = np.sum(speed * w[None, :], axis=1) * h
    sigma = np.concatenate([[0.0], np.cumsum(pieces)])
    return {
        "s": s,
        "arc_length": sigma,
        "kappa": np.asarray(curvature(curve, s)),
        "dkappa_ds": np.asarray(curvature_derivative(curve, s)),
    }


def joint_curvatures(composite: CompositeCurve) -> dict[str, np.ndarray]:
    r"""Curvature on both sides of every joint of a composite curve.

    Returns:
        ``{"kappa_left", "kappa_right", "kappa_jump", "relative_jump", "curvature_vector_jump"}``,
        one entry per joint: ``κ_L = κ_A(1)``, ``κ_R = κ_B(0)``, jump ``|κ_R - κ_L|``,
        ``relative_jump = |κ_R - κ_L| / max(κ_L, κ_R)`` (0 when both vanish) and
        ``|K_R - K_L| / max(κ_L, κ_R)`` for the curvature vectors K (direction changes count too).
    """
    if not isinstance(composite, CompositeCurve):
        raise GHTError(f"joint_curvatures needs a CompositeCurve, got {type(composite).__name__}")
    kl, kr, vj = [], [], []
    for j in range(composite.n_joints):
        a, b = composite.joint_segments(j)
        KL = np.asarray(curvature_vector(a, 1.0))
        KR = np.asarray(curvature_vector(b, 0.0))
        kl.append(float(np.linalg.norm(KL)))
        kr.append(float(np.linalg.norm(KR)))
        vj.append(float(np.linalg.norm(KR - KL)))
    kl_a, kr_a, vj_a = np.array(kl), np.array(kr), np.array(vj)
    jump = np.abs(kr_a - kl_a)
    den = np.maximum(kl_a, kr_a)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(den > 0, jump / np.where(den > 0, den, 1.0), 0.0)
        relv = np.where(den > 0, vj_a / np.where(den > 0, den, 1.0), 0.0)
    return {
        "kappa_left": kl_a,
        "kappa_right": kr_a,
        "kappa_jump": jump,
        "relative_jump": rel,
        "curvature_vector_jump": relv,
    }


# -- plotting ------------------------------------------------------------------------------------
def _projector(points: np.ndarray):
    """Map points of any dimension to 2-D: identity for 2-D, else the best-fit plane (PCA)."""
    dim = points.shape[1]
    if dim == 2:
        return lambda p: p
    if dim == 1:
        return lambda p: np.column_stack([p[:, 0], np.zeros(len(p))])
    centre = points.mean(axis=0)
    _, _, vt = np.linalg.svd(points - centre, full_matrices=False)
    basis2 = vt[:2].T
    return lambda p: (p - centre) @ basis2


def _segments_of(curve: CurveLike) -> list[GHTCurve]:
    return curve.segments if isinstance(curve, CompositeCurve) else [curve]


def _draw_comb(ax, curve: CurveLike, per_segment: int, scale: float | None, show_polygon: bool, project=None):
    from matplotlib.collections import LineCollection

    segs = _segments_of(curve)
    t = np.linspace(0.0, 1.0, per_segment)
    pts = [seg.evaluate(t) for seg in segs]
    Ks = [np.asarray(curvature_vector(seg, t)) for seg in segs]
    allp = np.vstack(pts + [seg.control_points for seg in segs])
    proj = project or _projector(allp)
    kmax = max(float(np.nanmax(np.linalg.norm(K, axis=1))) for K in Ks)
    diag = float(np.linalg.norm(np.ptp(allp, axis=0))) or 1.0
    if scale is None:
        scale = 0.25 * diag / kmax if kmax > 0 and math.isfinite(kmax) else 0.0
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
    for j, (P, K) in enumerate(zip(pts, Ks)):
        col = colors[j % len(colors)]
        tips = P - scale * np.nan_to_num(K)  # comb drawn on the outer side (away from the centre)
        p2, t2 = proj(P), proj(tips)
        ax.add_collection(LineCollection(np.stack([p2, t2], axis=1), colors=col, linewidths=0.5, alpha=0.6))
        ax.plot(t2[:, 0], t2[:, 1], color=col, linewidth=0.8, alpha=0.8)
        ax.plot(p2[:, 0], p2[:, 1], color="black", linewidth=1.6)
        if show_polygon:
            cp = proj(segs[j].control_points)
            ax.plot(cp[:, 0], cp[:, 1], "--o", color="grey", linewidth=0.7, markersize=3)
    joints = np.array([seg.control_points[0] for seg in segs[1:]] + ([segs[0].control_points[0]] if isinstance(curve, CompositeCurve) and curve.closed else []))
    if len(joints):
        j2 = proj(joints)
        ax.plot(j2[:, 0], j2[:, 1], "s", color="black", markersize=5, label="joints")
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    return proj, scale


def _save(fig, path: str | Path, dpi: int) -> Path:
    target = Path(path)
    with atomic_path(target) as tmp:
        fig.savefig(tmp, format="png", dpi=dpi)
    return target


def _figure(figsize: tuple[float, float], ncols: int = 1):
    """A stand-alone Agg figure (no pyplot, so no global backend switch in a host GUI)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, ncols)
    return fig, axes


def curvature_comb_plot(
    curve: CurveLike,
    path: str | Path,
    *,
    samples_per_segment: int = 120,
    scale: float | None = None,
    show_control_polygon: bool = True,
    title: str | None = None,
    dpi: int = 120,
) -> Path:
    r"""Write a PNG with the curve, its curvature comb and (optionally) its control polygon.

    Teeth go from ``X(t)`` to ``X(t) - scale K(t)`` (K the curvature vector, so teeth point away
    from the centre of curvature and have length ``scale κ``). Curves that are not 2-D are
    projected onto their best-fit plane (principal components of the samples).

    Args:
        curve: GHTCurve or CompositeCurve.
        path: output PNG path (written atomically: a failed write leaves no partial file).
        samples_per_segment: teeth per segment (>= 2).
        scale: comb scale; default ``0.25 · bbox diagonal / max κ``.
        show_control_polygon: draw the control polygon(s).
        title: figure title.
        dpi: resolution.

    Returns:
        The path written.

    Raises:
        GHTError: not a curve, bad sample count or scale.
    """
    curve = _check_curve(curve)
    n = _check_samples(samples_per_segment)
    if scale is not None and not (is_real(scale) and math.isfinite(scale) and scale >= 0):
        raise GHTError(f"scale={scale!r} is not allowed; it must be a finite number >= 0 or None")
    fig, ax = _figure((7, 6))
    _draw_comb(ax, curve, n, scale, show_control_polygon)
    ax.set_title(title or f"curvature comb ({type(curve).__name__})")
    fig.tight_layout()
    return _save(fig, path, dpi)


def bezier_chain_like(composite: CompositeCurve, *, resolve: bool = False) -> CompositeCurve:
    r"""The classical Bézier chain (every segment γ = 1, i.e. Bernstein basis) on the same points.

    Args:
        composite: a GHT composite curve.
        resolve: False (default): the *same control points* verbatim; the chain is built with C0
            joints, which the shared joint points already satisfy, so no point moves (this is the
            thesis' comparison: one control polygon, two bases). True: same free points and the
            same joints (continuity and k, β2, β3) re-solved for the Bernstein basis.

    Returns:
        A new CompositeCurve with Bernstein segments (μ = ν = 0, γ = 1).
    """
    if not isinstance(composite, CompositeCurve):
        raise GHTError(f"bezier_chain_like needs a CompositeCurve, got {type(composite).__name__}")
    segs = [GHTCurve(seg.control_points, 0.0, 0.0, 1.0) for seg in composite.segments]
    if not resolve:
        return CompositeCurve(segs, "C0", closed=composite.closed)
    k, b2, b3 = zip(*composite.g_parameters) if composite.n_joints else ((), (), ())
    return CompositeCurve(
        segs, composite.continuity, closed=composite.closed, k=list(k), beta2=list(b2), beta3=list(b3)
    )


def compare_curvature(
    composite: CompositeCurve,
    path: str | Path | None = None,
    *,
    samples_per_segment: int = 200,
    dpi: int = 110,
) -> dict[str, Any]:
    r"""Curvature continuity of a GHT chain versus the Bézier chain on the same control points.

    The Bézier chain is :func:`bezier_chain_like` (``resolve=False``): identical control points,
    every segment γ = 1. At each joint both chains are compared by :func:`joint_curvatures`
    (``κ_L``, ``κ_R``, ``|κ_R - κ_L| / max(κ_L, κ_R)``, curvature-vector jump) and by
    :func:`~ght_cad.curves.continuity.measure_continuity` (orders). A G2 GHT chain has relative jumps at
    rounding level; the Bézier chain on its points generally does not.

    Args:
        composite: the GHT composite curve.
        path: if given, a PNG with three panels: GHT comb, Bézier comb (same scale), and κ over
            the global parameter s for both, joints marked.
        samples_per_segment: samples per segment for the profiles and plots.
        dpi: PNG resolution.

    Returns:
        ``{"ght": {...}, "bezier": {...}, "joints": [s_j], "path": str | None}`` where each side
        holds the :func:`joint_curvatures` arrays as lists, ``"max_relative_jump"``,
        ``"max_curvature_vector_jump"``, ``"kappa_max"`` and ``"orders"`` (``(c_order, g_order)``
        per joint).
    """
    if not isinstance(composite, CompositeCurve):
        raise GHTError(f"compare_curvature needs a CompositeCurve, got {type(composite).__name__}")
    n = _check_samples(samples_per_segment)
    bez = bezier_chain_like(composite)
    result: dict[str, Any] = {"joints": [float(j + 1) for j in range(composite.n_joints)], "path": None}
    for name, cc in (("ght", composite), ("bezier", bez)):
        jc = joint_curvatures(cc)
        prof = curvature_profile(cc, n)
        result[name] = {key: val.tolist() for key, val in jc.items()}
        result[name]["max_relative_jump"] = float(jc["relative_jump"].max()) if len(jc["relative_jump"]) else 0.0
        result[name]["max_curvature_vector_jump"] = (
            float(jc["curvature_vector_jump"].max()) if len(jc["curvature_vector_jump"]) else 0.0
        )
        result[name]["kappa_max"] = float(np.nanmax(prof["kappa"]))
        result[name]["orders"] = [(r.c_order, r.g_order) for r in cc.joint_reports()]
    if composite.closed:
        result["joints"][-1] = float(composite.n_segments)  # wrap joint: s = n ≡ 0
    if path is not None:
        fig, axes = _figure((16, 5.2), 3)
        kmax = max(result["ght"]["kappa_max"], result["bezier"]["kappa_max"])
        allp = np.vstack([seg.control_points for seg in composite.segments])
        diag = float(np.linalg.norm(np.ptp(allp, axis=0))) or 1.0
        scale = 0.25 * diag / kmax if kmax > 0 and math.isfinite(kmax) else 0.0
        proj, _ = _draw_comb(axes[0], composite, min(n, 150), scale, True)
        _draw_comb(axes[1], bez, min(n, 150), scale, True, project=proj)
        g, b = result["ght"], result["bezier"]
        axes[0].set_title(f"GHT-Bézier chain: max rel. κ jump {g['max_relative_jump']:.2e}")
        axes[1].set_title(f"Bézier chain, same points: max rel. κ jump {b['max_relative_jump']:.2e}")
        ax = axes[2]
        for name, style in (("ght", "-"), ("bezier", "--")):
            # one line per segment so the jumps show as steps at the joints
            chain = composite if name == "ght" else bez
            tt = np.linspace(0.0, 1.0, n)
            for j, seg in enumerate(chain.segments):
                ax.plot(
                    j + tt,
                    np.asarray(curvature(seg, tt)),
                    style,
                    color="tab:blue" if name == "ght" else "tab:red",
                    label=("GHT-Bézier" if name == "ght" else "Bézier") if j == 0 else None,
                )
        for sj in result["joints"]:
            ax.axvline(sj, color="grey", linewidth=0.6)
        ax.set_xlabel("global parameter s")
        ax.set_ylabel("curvature κ")
        ax.set_title("curvature along the chain")
        ax.legend()
        fig.tight_layout()
        result["path"] = str(_save(fig, path, dpi))
    return result
