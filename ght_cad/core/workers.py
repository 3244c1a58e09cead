"""Worker processes shared by ``ght-cad batch`` (:mod:`ght_cad.app.batch`) and the parallel STEP unroll
(:func:`ght_cad.app.design.step_input.map_step_faces`): BLAS/OpenMP threads per worker, the Dask client,
one-line error text.

Moved from :mod:`ght_cad.app.batch` (issue 27) with the parallel STEP unroll moved into
:mod:`ght_cad.app.design.step_input`, so that the STEP input no longer imports ``ght_cad.app.batch``
(which runs designs through ``ght_cad.app.design``: the cycle batch -> design -> step_input -> batch).
``ght_cad.app.batch`` imports these names back.
"""

from __future__ import annotations

import os
from typing import Any

from .errors import GHTError

__all__: list[str] = []


def _one_line(exc: BaseException | str) -> str:
    return " ".join(str(exc).split())


def _limit_threads(threads: int) -> None:
    """Worker initializer: at most ``threads`` BLAS/OpenMP threads in this process.

    numpy's and scipy's OpenBLAS and OCCT's OpenMP start one thread per core in every process;
    ``n`` workers on as many cores would run ``n`` times too many (and OpenBLAS's idle threads spin),
    so each worker gets ``max(1, cores // n)`` (:mod:`threadpoolctl` when installed; else unchanged).
    """
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - threadpoolctl comes with scikit-learn (build123d)
        return
    threadpool_limits(threads)


def _worker_threads(n: int) -> int:
    return max(1, (os.cpu_count() or 1) // max(1, n))


def _dask_client(scheduler: str) -> Any:
    """A ``distributed.Client`` connected to ``scheduler`` (GHTError if dask is missing or it is unreachable)."""
    try:
        from distributed import Client
    except ImportError:
        raise GHTError("--scheduler needs dask.distributed; install it with pip install 'ght_cad[dask]'") from None
    try:
        return Client(scheduler, timeout="15s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise GHTError(f"cannot reach the Dask scheduler {scheduler!r}: {_one_line(exc)}; allowed: the address "
                       "of a running scheduler, e.g. tcp://127.0.0.1:8786") from None
