"""A tiny dependency-free progress bar for long runs.

The bar is drawn on ``stderr`` only when it is a terminal (``isatty()``); otherwise it is
silent, so logs, pipes, CI and tests see no output. Usage::

    from ght_cad.core.progress import Progress

    with Progress(200, "optimizing") as p:
        for _ in range(200):
            ...
            p.update()           # one step done

    # as an optimizer callback (the optimizers call it once per iteration):
    with Progress(200, "I-GWO") as p:
        result = igwo(f, bounds, max_iter=200, callback=p.callback)

``GHT_CAD_PROGRESS=0`` in the environment silences the bar even on a terminal,
``GHT_CAD_PROGRESS=1`` forces it on (for example under ``script``).
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any, TextIO

__all__ = ["Progress", "progress_enabled"]


def progress_enabled(stream: Any = None) -> bool:
    """Whether a progress bar should be drawn on ``stream`` (default ``sys.stderr``).

    True when the stream is a TTY, unless ``GHT_CAD_PROGRESS`` is ``0``/``false``/``off``;
    ``GHT_CAD_PROGRESS=1`` forces it on.

    Args:
        stream: a text stream with ``isatty()``; ``None`` means ``sys.stderr``.

    Returns:
        True if the bar is to be shown.
    """
    env = os.environ.get("GHT_CAD_PROGRESS", "").strip().lower()
    if env in ("0", "false", "off", "no"):
        return False
    if env in ("1", "true", "on", "yes"):
        return True
    stream = sys.stderr if stream is None else stream
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


class Progress:
    """Text progress bar ``label [#####.....]  42/200  21%  1.3s``, silent off a terminal.

    Args:
        total: number of steps (> 0; ``None`` or 0 shows a counter without a bar).
        label: text in front of the bar.
        stream: output stream (default ``sys.stderr``).
        enabled: force on/off; ``None`` decides by :func:`progress_enabled`.
        width: bar width in characters.
        min_interval: minimum seconds between redraws (the last step is always drawn).

    Attributes:
        count: steps done so far.
    """

    def __init__(
        self,
        total: int | None,
        label: str = "",
        *,
        stream: TextIO | None = None,
        enabled: bool | None = None,
        width: int = 30,
        min_interval: float = 0.1,
    ) -> None:
        if total is not None and (not isinstance(total, (int,)) or isinstance(total, bool)):
            try:
                total = int(total)
            except (TypeError, ValueError):
                raise ValueError(f"total={total!r} is not an integer; use a step count >= 0 or None") from None
        if total is not None and total < 0:
            raise ValueError(f"total={total!r} is negative; use a step count >= 0 or None")
        self.total = total or None
        self.label = str(label)
        self.stream = sys.stderr if stream is None else stream
        self.enabled = progress_enabled(self.stream) if enabled is None else bool(enabled)
        self.width = max(int(width), 5)
        self.min_interval = float(min_interval)
        self.count = 0
        self._t0 = time.perf_counter()
        self._last_draw = -1e300
        self._closed = False
        self._drawn = False

    # -- context manager -------------------------------------------------------------------
    def __enter__(self) -> "Progress":
        self._t0 = time.perf_counter()
        self._draw(force=True)
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    # -- updating --------------------------------------------------------------------------
    def update(self, n: int = 1) -> None:
        """Advance by ``n`` steps."""
        self.set(self.count + n)

    def set(self, value: int) -> None:
        """Set the number of steps done to ``value`` (clamped to ``total``)."""
        v = int(value)
        if self.total is not None:
            v = min(v, self.total)
        self.count = max(v, 0)
        self._draw(force=self.total is not None and self.count >= self.total)

    def callback(self, state: Any = None, *args: Any) -> bool:
        """Optimizer callback adapter: sets the count from ``state.nit`` (else adds one).

        Returns False (never asks the optimizer to stop), so it can be passed directly as
        ``callback=progress.callback``.
        """
        nit = getattr(state, "nit", None)
        if nit is None:
            self.update(1)
        else:
            self.set(int(nit))
        return False

    def close(self) -> None:
        """Finish the line (if anything was drawn); idempotent."""
        if self._closed:
            return
        self._closed = True
        if self.enabled and self._drawn:
            self._draw(force=True)
            try:
                self.stream.write("\n")
                self.stream.flush()
            except (ValueError, OSError):
                pass

    # -- drawing ---------------------------------------------------------------------------
    def render(self) -> str:
        """The current bar as a string (without carriage return)."""
        elapsed = time.perf_counter() - self._t0
        head = f"{self.label} " if self.label else ""
        if self.total:
            frac = self.count / self.total
            filled = int(round(frac * self.width))
            bar = "#" * filled + "." * (self.width - filled)
            return f"{head}[{bar}] {self.count}/{self.total} {100 * frac:3.0f}% {elapsed:.1f}s"
        return f"{head}{self.count} {elapsed:.1f}s"

    def _draw(self, force: bool = False) -> None:
        if not self.enabled or self._closed:
            return
        now = time.perf_counter()
        if not force and now - self._last_draw < self.min_interval:
            return
        self._last_draw = now
        try:
            self.stream.write("\r" + self.render())
            self.stream.flush()
            self._drawn = True
        except (ValueError, OSError):
            self.enabled = False
