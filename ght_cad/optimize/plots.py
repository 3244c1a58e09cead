"""Convergence and Pareto plots (PNG via matplotlib's Agg backend, written atomically).

matplotlib is imported inside the functions only (``import ght_cad.optimize`` stays light).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from ..core.errors import GHTError
from ..core.io import atomic_path
from .optimizers import OptimizeResult

__all__ = ["plot_convergence", "plot_pareto"]


def _pyplot() -> Any:
    # a bare Figure renders with the Agg canvas and never touches pyplot's global backend state
    from matplotlib.figure import Figure

    return Figure


def _runs(results: Mapping[str, Any] | Sequence[OptimizeResult] | OptimizeResult) -> dict[str, list[OptimizeResult]]:
    if isinstance(results, OptimizeResult):
        return {results.method: [results]}
    if isinstance(results, Mapping):
        out = {}
        for k, v in results.items():
            out[str(k)] = [v] if isinstance(v, OptimizeResult) else list(v)
        return out
    out: dict[str, list[OptimizeResult]] = {}
    for r in results:
        out.setdefault(r.method, []).append(r)
    return out


def plot_convergence(
    results: Mapping[str, Any] | Sequence[OptimizeResult] | OptimizeResult,
    path: str | os.PathLike,
    *,
    title: str | None = None,
    log: bool = True,
    x: str = "nfev",
) -> Path:
    """Best value so far against objective evaluations (or iterations), one colour per method.

    Several runs of one method (e.g. seeds) are drawn thin with their median bold. Runs with
    ``phases`` (``hybrid``: global phase, then L-BFGS-B) get a ``|`` marker where the second phase
    starts (and a dotted vertical line for a single run), labelled with the phase names.

    Args:
        results: an OptimizeResult, a list of them (grouped by ``method``) or a mapping
            ``label -> OptimizeResult | list of OptimizeResult``.
        path: PNG file, written atomically.
        title: figure title.
        log: logarithmic y axis (values <= 0 are shifted by the smallest value, noted in the label).
        x: ``"nfev"`` (evaluations, fair across methods) or ``"nit"`` (iterations).

    Returns:
        The written path.

    Raises:
        GHTError: no results, or an unknown ``x``.
    """
    groups = _runs(results)
    if not groups or not any(groups.values()):
        raise GHTError("results is empty; give at least one OptimizeResult")
    if x not in ("nfev", "nit"):
        raise GHTError(f"x={x!r} is not allowed; use 'nfev' or 'nit'")
    Figure = _pyplot()
    fig = Figure(figsize=(8, 5), dpi=100)
    ax = fig.add_subplot(1, 1, 1)
    allv = np.concatenate([r.history for rs in groups.values() for r in rs])
    finite = allv[np.isfinite(allv)]
    shift = 0.0
    if log and finite.size and finite.min() <= 0:
        shift = -finite.min() + 1e-16 * max(1.0, abs(finite).max())
    colors = ["C0", "C1", "C2", "C3", "C4", "C5", "C6", "C7"]
    for i, (label, rs) in enumerate(groups.items()):
        c = colors[i % len(colors)]
        for r in rs:
            xs = r.history_nfev if x == "nfev" else np.arange(r.history.size)
            ax.plot(xs, r.history + shift, color=c, lw=0.6 if len(rs) > 1 else 1.6,
                    alpha=0.35 if len(rs) > 1 else 1.0,
                    label=None if len(rs) > 1 else label)
        # multi-phase runs (hybrid): a marker where the local phase starts, the phase names once
        for j, r in enumerate(rs):
            for k, (pname, at) in enumerate(getattr(r, "phases", ())[1:]):
                if 0 < at < r.history.size:
                    xs = r.history_nfev if x == "nfev" else np.arange(r.history.size)
                    ax.plot([xs[at - 1]], [r.history[at - 1] + shift], marker="|", ms=12, mew=1.5, color=c,
                            ls="none", label=(f"{label}: {r.phases[k][0]} | {pname}" if j == 0 else None))
                    if len(rs) == 1:
                        ax.axvline(xs[at - 1], color=c, lw=0.6, ls=":")
        if len(rs) > 1:
            n = min(r.history.size for r in rs)
            med = np.median(np.array([r.history[:n] for r in rs]), axis=0) + shift
            xs = rs[0].history_nfev[:n] if x == "nfev" else np.arange(n)
            ax.plot(xs, med, color=c, lw=2.0, label=f"{label} (median of {len(rs)})")
    if log:
        ax.set_yscale("log")
    ax.set_xlabel("objective evaluations" if x == "nfev" else "iteration")
    ax.set_ylabel("best value" + (f" + {shift:.3g}" if shift else ""))
    ax.grid(True, lw=0.3, which="both")
    ax.legend(fontsize=8)
    ax.set_title(title or "Convergence", fontsize=11)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    return Path(path)


def plot_pareto(front: Any, path: str | os.PathLike, *, title: str | None = None) -> Path:
    """Pareto front: first two objectives as axes, the third as colour.

    Args:
        front: a :class:`~ght_cad.optimize.pareto.ParetoResult` (``.f``, ``.names``).
        path: PNG file, written atomically.
        title: figure title.

    Returns:
        The written path.

    Raises:
        GHTError: fewer than two objectives or an empty front.
    """
    F = np.asarray(front.f, dtype=float)
    if F.ndim != 2 or F.shape[0] == 0 or F.shape[1] < 2:
        raise GHTError(f"the front has shape {F.shape}; need at least one point and two objectives")
    names = tuple(front.names)
    Figure = _pyplot()
    fig = Figure(figsize=(7, 5.5), dpi=100)
    ax = fig.add_subplot(1, 1, 1)
    if F.shape[1] >= 3:
        sc = ax.scatter(F[:, 0], F[:, 1], c=F[:, 2], s=10, cmap="viridis")
        fig.colorbar(sc, ax=ax, label=names[2])
    else:
        ax.scatter(F[:, 0], F[:, 1], s=10)
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1])
    ax.set_yscale("log")
    ax.grid(True, lw=0.3, which="both")
    ax.set_title(title or f"Pareto front ({len(F)} non-dominated points)", fontsize=11)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    return Path(path)
