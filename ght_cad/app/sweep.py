r"""Parameter sweeps of a design file: ``[sweep]`` expands one design into named variants.

A design file may declare a ``[sweep]`` table. Every key except ``mode`` and ``plot`` is a
dotted path to a numeric value of the design (list items by their 0-based index) and its value
is the list of values to try, or a range::

    [sweep]
    "surface.boundary_planes.1.0" = [-400, -350, -300]       # a list
    "surface.planes.0.3" = { start = 0.4, stop = 0.6, num = 3 }   # num values, both ends included
    "unroll.rulings" = { start = 8, stop = 16, step = 4 }      # start, start + step, ... <= stop
    mode = "grid"              # "grid" (default): every combination; "zip": the k-th values together
    plot = ["area", "theta_max"]   # figures drawn against the swept values (default ["area"])

A range ``{start, stop, num}`` gives ``start + k (stop - start) / (num - 1)``, ``k = 0..num-1``;
``{start, stop, step}`` gives ``start + k step`` for every ``k >= 0`` with the value not past
``stop`` (``step`` towards ``stop``; a tolerance of ``1e-9 |step|`` keeps ``stop`` itself). With
``mode = "grid"`` the variants are the Cartesian product of the value lists (first key slowest);
with ``"zip"`` all lists must have the same length ``n`` and variant ``k`` takes the ``k``-th value
of each. Variant ``k`` (1-based) is named ``<name>-<k>`` (zero-padded to the width of the count),
its ``[sweep]`` table removed, every path set to its value; it is then an ordinary design.
"""

from __future__ import annotations

import itertools
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

from ..core.errors import GHTError

__all__ = ["SweepError", "Variant", "Sweep", "expand_sweep", "SWEEP_FIGURES", "MAX_VARIANTS", "plot_sweep"]

#: Figures of a batch row that ``plot`` may name (the row's key figures, see :mod:`ght_cad.app.batch`).
SWEEP_FIGURES = ("area", "theta_max", "pattern_error", "best_value", "elapsed_s")

#: Largest number of variants one sweep may expand into.
MAX_VARIANTS = 10000

_RESERVED = ("mode", "plot")


class SweepError(GHTError):
    """An invalid ``[sweep]`` table (bad path, not a number, empty list, bad range, ...)."""


@dataclass
class Variant:
    """One expanded variant: its name, the design data without ``[sweep]`` and the swept values."""

    name: str
    data: dict[str, Any]
    values: dict[str, float]


@dataclass
class Sweep:
    """The expansion of one design's ``[sweep]`` table."""

    base: str
    source: str
    keys: list[str]
    mode: str
    plot: list[str]
    variants: list[Variant] = field(default_factory=list)


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(float(v))


def _walk(data: Any, path: str, source: str) -> tuple[Any, Any]:
    """(container, key) of the dotted ``path`` in ``data``; the target must exist and be a number."""
    parts = path.split(".")
    cur = data
    for i, part in enumerate(parts):
        here = ".".join(parts[: i + 1])
        if isinstance(cur, list):
            try:
                idx = int(part)
            except ValueError:
                raise SweepError(f"{source}: [sweep] key {path!r}: {here!r} indexes a list, so {part!r} must be an "
                                 f"integer; allowed: 0..{len(cur) - 1}") from None
            if not 0 <= idx < len(cur):
                raise SweepError(f"{source}: [sweep] key {path!r}: index {idx} is out of range; allowed: 0..{len(cur) - 1}")
            key: Any = idx
        elif isinstance(cur, dict):
            if part not in cur:
                allowed = ", ".join(sorted(map(str, cur))) or "(none)"
                raise SweepError(f"{source}: [sweep] key {path!r}: the design has no {here!r}; allowed here: {allowed}")
            key = part
        else:
            raise SweepError(f"{source}: [sweep] key {path!r}: {'.'.join(parts[:i])!r} is a "
                             f"{type(cur).__name__}, not a table or list")
        if i == len(parts) - 1:
            if not _is_number(cur[key]):
                raise SweepError(f"{source}: [sweep] key {path!r} names {cur[key]!r}, not a number; "
                                 "allowed: paths to numeric values")
            return cur, key
        cur = cur[key]
    raise SweepError(f"{source}: [sweep] key {path!r} is empty")  # pragma: no cover - split gives >= 1 part


def _values(spec: Any, path: str, source: str) -> list[float]:
    """The value list of one swept key (a list, ``{start, stop, num}`` or ``{start, stop, step}``)."""
    where = f"{source}: [sweep] {path!r}"
    if isinstance(spec, list):
        if not spec:
            raise SweepError(f"{where} is an empty list; allowed: a non-empty list of numbers or a range")
        for v in spec:
            if not _is_number(v):
                raise SweepError(f"{where}: {v!r} is not a finite number; allowed: numbers")
        return [v for v in spec]
    if isinstance(spec, dict):
        extra = set(spec) - {"start", "stop", "num", "step"}
        if extra or not {"start", "stop"} <= set(spec) or ("num" in spec) == ("step" in spec):
            raise SweepError(f"{where} = {spec!r}: a range is {{start, stop, num}} or {{start, stop, step}}")
        a, b = spec["start"], spec["stop"]
        for k in ("start", "stop"):
            if not _is_number(spec[k]):
                raise SweepError(f"{where}: {k}={spec[k]!r} is not a finite number")
        if "num" in spec:
            n = spec["num"]
            if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= MAX_VARIANTS:
                raise SweepError(f"{where}: num={n!r}; allowed: an integer in 1..{MAX_VARIANTS}")
            if n == 1:
                return [a]
            return [a + k * (b - a) / (n - 1) for k in range(n)]
        s = spec["step"]
        if not _is_number(s) or s == 0 or (b - a) * s < 0:
            raise SweepError(f"{where}: step={s!r}; allowed: a non-zero number pointing from start={a!r} to stop={b!r}")
        n = int(math.floor((b - a) / s + 1e-9)) + 1
        if n > MAX_VARIANTS:
            raise SweepError(f"{where}: the range has {n} values; allowed: at most {MAX_VARIANTS}")
        return [a + k * s for k in range(n)]
    raise SweepError(f"{where} = {spec!r}: allowed: a list of numbers or a range {{start, stop, num|step}}")


def _typed(original: Any, value: float) -> Any:
    """``value`` as an int where the design had an int and the value is integral (e.g. rulings)."""
    if isinstance(original, int) and float(value).is_integer():
        return int(value)
    return float(value)


def expand_sweep(data: dict[str, Any], source: str = "<design>") -> Sweep | None:
    """Expand the ``[sweep]`` table of a parsed design file (see the module doc).

    Args:
        data: the parsed TOML document of one design.
        source: file name used in error messages.

    Returns:
        None without a ``[sweep]`` table, else the :class:`Sweep` with one :class:`Variant` per
        combination (grid) or per position (zip); each variant's data is a deep copy of
        ``data`` without ``[sweep]``, with the swept values set and ``name = <name>-<k>``.

    Raises:
        SweepError: a path that does not exist or names no number, an empty list, a bad range,
            unequal lengths in zip mode, an unknown figure in ``plot``, more than
            :data:`MAX_VARIANTS` variants.
    """
    import copy

    if "sweep" not in data:
        return None
    table = data["sweep"]
    if not isinstance(table, dict):
        raise SweepError(f"{source}: [sweep] must be a table of 'path = values' entries")
    mode = table.get("mode", "grid")
    if mode not in ("grid", "zip"):
        raise SweepError(f"{source}: [sweep] mode={mode!r}; allowed: grid, zip")
    plot = table.get("plot", ["area"])
    if not isinstance(plot, list) or not plot or any(p not in SWEEP_FIGURES for p in plot):
        raise SweepError(f"{source}: [sweep] plot={plot!r}; allowed: a non-empty list of {', '.join(SWEEP_FIGURES)}")
    base = dict(data)
    del base["sweep"]
    keys = [k for k in table if k not in _RESERVED]
    if not keys:
        raise SweepError(f"{source}: [sweep] names no key to sweep; write e.g. \"surface.gamma\" = [-1, -0.5, 0]")
    lists = []
    for k in keys:
        _walk(base, k, source)
        lists.append(_values(table[k], k, source))
    if mode == "zip":
        lengths = {len(v) for v in lists}
        if len(lengths) != 1:
            raise SweepError(f"{source}: [sweep] mode=\"zip\" needs lists of one length; got "
                             + ", ".join(f"{k}: {len(v)}" for k, v in zip(keys, lists)))
        combos = list(zip(*lists))
    else:
        count = math.prod(len(v) for v in lists)
        if count > MAX_VARIANTS:
            raise SweepError(f"{source}: [sweep] expands into {count} variants; allowed: at most {MAX_VARIANTS}")
        combos = list(itertools.product(*lists))
    name = data.get("name") if isinstance(data.get("name"), str) else None
    name = name or (Path(source).stem if not source.startswith("<") else "design")
    width = len(str(len(combos)))
    sweep = Sweep(base=name, source=source, keys=keys, mode=mode, plot=list(plot))
    for i, combo in enumerate(combos, start=1):
        d = copy.deepcopy(base)
        values = {}
        for k, v in zip(keys, combo):
            cont, key = _walk(d, k, source)
            cont[key] = _typed(cont[key], v)
            values[k] = cont[key]
        d["name"] = f"{name}-{i:0{width}d}"
        sweep.variants.append(Variant(d["name"], d, values))
    return sweep


def plot_sweep(sweep: Sweep, rows: Sequence[dict[str, Any]], path: str | os.PathLike) -> Path:
    """PNG (900 x 300 k pixels for k figures) of the chosen figures against the first swept value.

    One panel per figure in ``sweep.plot``; x is the first swept key's value, one line per
    combination of the other keys' values (grid) or one line (zip). Rows without the figure
    (a failed variant) are left out of their line.

    Args:
        sweep: the expanded sweep.
        rows: batch rows of its variants (``row["sweep"]["values"]`` and the figures).
        path: PNG file to write (atomically).

    Returns:
        The written path.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from ..core.io import atomic_path

    k = len(sweep.plot)
    fig = Figure(figsize=(9, 3 * k), dpi=100)
    FigureCanvasAgg(fig)
    x_key, others = sweep.keys[0], sweep.keys[1:]
    for j, fig_name in enumerate(sweep.plot):
        ax = fig.add_subplot(k, 1, j + 1)
        groups: dict[tuple, list[tuple[float, float]]] = {}
        for r in rows:
            vals = (r.get("sweep") or {}).get("values") or {}
            y = r.get(fig_name)
            if x_key not in vals or not isinstance(y, (int, float)) or not math.isfinite(y):
                continue
            g = tuple(vals.get(o) for o in others) if sweep.mode == "grid" else ()
            groups.setdefault(g, []).append((float(vals[x_key]), float(y)))
        for g, pts in groups.items():
            pts.sort()
            label = ", ".join(f"{o}={v:g}" for o, v in zip(others, g)) if g else None
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", lw=1.4, ms=4, label=label)
        ax.set_xlabel(x_key)
        ax.set_ylabel(fig_name)
        ax.grid(True, lw=0.3)
        if any(g for g in groups) and len(groups) <= 12:
            ax.legend(fontsize=7)
        if j == 0:
            ax.set_title(f"sweep of {sweep.base} ({len(sweep.variants)} variants, {sweep.mode})", fontsize=11)
    fig.tight_layout()
    target = Path(path)
    with atomic_path(target) as tmp:
        fig.savefig(str(tmp), format="png", dpi=100)
    return target
