"""The project's one caching scheme for pure functions: :func:`readonly_cache` (issue 27).

A function of small hashable arguments (a node count, a degree, a byte string of an array) whose
result is an array, or tuples/lists holding arrays, is cached with :func:`functools.lru_cache` and
its arrays are made read-only, so every caller shares one copy that no caller can change. A
caller that needs to write makes its own copy.

Caches keyed by the contents of a large array and kept per object (a surface's jets at the last
few parameter arrays) are not of this kind: they live on their objects (see the modules).
"""

from __future__ import annotations

import functools
from typing import Any, Callable, TypeVar

import numpy as np


__all__ = ["readonly_cache"]

F = TypeVar("F", bound=Callable[..., Any])


def _freeze(value: Any) -> Any:
    """``value`` with every array in it (itself, or inside tuples/lists at any depth) made read-only."""
    if isinstance(value, np.ndarray):
        value.flags.writeable = False
    elif isinstance(value, (tuple, list)):
        for item in value:
            _freeze(item)
    return value


def readonly_cache(maxsize: int) -> Callable[[F], F]:
    """Decorator: ``functools.lru_cache(maxsize)`` of a pure function whose arrays are returned
    read-only (the same objects on every hit; the values are those of the first call).

    Args:
        maxsize: how many argument tuples are kept (least recently used dropped first); a
            positive int.

    Raises:
        ValueError: ``maxsize`` is not a positive int.
    """
    if not isinstance(maxsize, int) or isinstance(maxsize, bool) or maxsize < 1:
        raise ValueError(f"maxsize={maxsize!r} is not allowed; allowed: a positive int")

    def wrap(fun: F) -> F:
        @functools.lru_cache(maxsize=maxsize)
        @functools.wraps(fun)
        def cached(*args: Any) -> Any:
            return _freeze(fun(*args))

        return cached  # type: ignore[return-value]

    return wrap
