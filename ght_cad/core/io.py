"""Atomic file output: a failed export leaves no partial file and never damages an existing one."""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterator, IO

__all__ = ["atomic_path", "atomic_write", "write_text_atomic", "write_bytes_atomic", "strict_json"]


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike, suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on success it replaces ``path`` atomically.

    For writers that want a file name (OCCT's STEP writer, matplotlib, ezdxf). If the block raises,
    or leaves no file behind, the temporary file is removed and ``path`` is untouched.

    Example:
        >>> with atomic_path("part.step") as tmp:        # doctest: +SKIP
        ...     writer.Write(str(tmp))
    """
    target = Path(path)
    sfx = target.suffix if suffix is None else suffix
    blocker = _file_in_the_way(target.parent)
    if blocker is not None:
        raise NotADirectoryError(
            20, f"cannot write {target}: {blocker} is a file, not a folder; allowed: a path whose folders "
            "are folders or can be created"
        )
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp_name = tempfile.mkstemp(prefix=f".{target.stem}.", suffix=sfx + ".part", dir=target.parent)
    except OSError as exc:
        raise _named(exc, target) from None
    os.close(fd)
    tmp = Path(tmp_name)
    # Some writers refuse an existing file or append to it: hand them a path that does not exist.
    tmp.unlink()
    try:
        yield tmp
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise OSError("the writer produced no data")
        with open(tmp, "rb") as fh:
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except OSError as exc:
        # the user knows the target, not our temporary name beside it
        raise _named(exc, target) from None
    finally:
        if tmp.exists():
            tmp.unlink()


def _file_in_the_way(folder: Path) -> Path | None:
    """The nearest existing ancestor of ``folder`` (itself included) if it is not a folder, else None."""
    for p in (folder, *folder.parents):
        if os.path.lexists(p):
            return None if p.is_dir() else p
    return None


def _named(exc: OSError, target: Path) -> OSError:
    """The same kind of OSError, with a message that names ``target`` instead of a temporary file."""
    reason = exc.strerror or str(exc)
    return type(exc)(exc.errno, f"cannot write {target}: {reason}") if exc.errno else OSError(f"cannot write {target}: {reason}")


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", encoding: str | None = "utf-8") -> Iterator[IO]:
    """Open a temporary file beside ``path`` for writing; rename it over ``path`` on success."""
    binary = "b" in mode
    with atomic_path(path) as tmp:
        with open(tmp, mode, encoding=None if binary else encoding) as fh:
            yield fh
            fh.flush()


def write_text_atomic(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` to ``path`` atomically and return the path."""
    with atomic_write(path, "w") as fh:
        fh.write(text)
    return Path(path)


def write_bytes_atomic(path: str | os.PathLike, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically and return the path."""
    with atomic_write(path, "wb") as fh:
        fh.write(data)
    return Path(path)


def strict_json(o: Any) -> Any:
    """Plain JSON data for ``json.dumps(..., allow_nan=False)``: numpy scalars as Python numbers,
    numpy arrays as lists, a float that is not finite (NaN, ±inf) as None (null), in nested dicts
    (keys as str), lists and tuples (as lists); other values unchanged."""
    if isinstance(o, dict):
        return {str(k): strict_json(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [strict_json(v) for v in o]
    if getattr(o, "ndim", 0) and hasattr(o, "tolist"):  # numpy array
        return strict_json(o.tolist())
    if hasattr(o, "item") and not isinstance(o, (str, bytes)):  # numpy scalar
        o = o.item()
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    return o
