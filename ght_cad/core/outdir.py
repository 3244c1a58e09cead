"""Output folders and files under faults and concurrency: locks, staging folders, manifests.

Every ght_cad writer that puts results on disk goes through this module (``ght-cad run``/``demo``/
``batch`` folders, the single-file outputs of ``curve``/``surface``/``unroll``/``export``, the
FreeCAD workbench's exports). Three mechanisms, all plain ``os`` with ``fcntl`` locks (``msvcrt``
on Windows; a platform with neither is refused with a :class:`~ght_cad.core.errors.GHTError`):

**Locks.** A run that writes a folder (or a file) first takes an exclusive ``fcntl.flock`` on a
lock file beside it, ``.<name>.ght-cad-lock``, which holds the owner's pid and command line. A
second process on the same target either waits for it (``wait=True``, optional ``timeout``) or
is refused with :class:`FolderBusy` (a :class:`~ght_cad.core.errors.GHTError`: exit code 2 on the
command line) naming the target and the other process. The kernel drops a flock when its
process dies, so a killed run (SIGKILL, OOM) never leaves a stuck lock; the lock file itself is
removed on release (a waiter that locked the removed file notices the changed inode and retries).
Lock files are created exclusively and opened with ``O_NOFOLLOW``; an existing one must be a plain
file with one link: a symbolic or hard link planted at that name (to another user's file, say) is
refused and never written through.

**Staging folders.** Results are computed into ``.<name>.<pid>-<random>.ght-cad-tmp`` beside the
target (inside the target when that is an existing folder on another file system than its
parent -- a mount point, or a link to a folder elsewhere -- so that every final rename stays on
one file system), with a lock file ``.lock`` inside that the live process holds. A later run tells a dead
run's folder from a live one: the lock is free (its process is gone), or there is no lock yet
and the pid in the name does not exist. :func:`sweep_dead` removes dead runs' folders (also the
pid-less ``.<name>.<random>.ght-cad-tmp`` and ``.ght-cad-export.<random>`` folders of earlier
versions, which had no lock) and never touches a live one.

**Manifests.** A folder holds one design's results: the run's ``report.json`` lists every file
the run wrote under ``files`` (a ght-cad report: it also has ``ght_definition`` or
``"tool": "ght-cad"``); a run without such a report leaves ``.ght-cad-manifest.json`` instead.
:meth:`OutputFolder.commit` moves the new files in, then removes the files the previous manifest
listed and this run did not write again; files a person put there are never listed, so they are
kept. During the moves ``.ght-cad-manifest.json`` holds the union of old and new names, so a run
killed half-way leaves a manifest that still covers every file of ours in the folder, and the
next run cleans up exactly.

Typical use::

    with OutputFolder("duct-out", wait=False) as out:   # lock, sweep dead staging folders
        write_step(shape, out.path("model.step"))         # write into the staging folder
        names = out.commit()                              # move in, remove stale files

    with StagedFiles(["a.step", "plots/a.png"]) as stage:  # single files, all or nothing
        write(stage.path(Path("a.step"))) ...
        stage.commit()
"""

from __future__ import annotations

import errno
import json
import os
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

from .errors import GHTError

try:  # POSIX
    import fcntl
except ImportError:  # pragma: no cover - Windows (msvcrt below) or an exotic platform
    fcntl = None  # type: ignore[assignment]
try:  # Windows
    import msvcrt
except ImportError:
    msvcrt = None  # type: ignore[assignment]

__all__ = [
    "FolderBusy",
    "TargetLock",
    "lock_target",
    "StagingDir",
    "sweep_dead",
    "is_dead",
    "read_manifest",
    "write_manifest",
    "OutputFolder",
    "StagedFiles",
    "MANIFEST_NAME",
    "REPORT_NAME",
    "LOCK_SUFFIX",
    "STAGING_SUFFIX",
]

#: file in an output folder listing the files the last run wrote (one JSON object)
MANIFEST_NAME = ".ght-cad-manifest.json"
#: suffix of the lock file beside a locked target: ``.<name>.ght-cad-lock``
LOCK_SUFFIX = ".ght-cad-lock"
#: suffix of a staging folder: ``.<name>.<pid>-<random>.ght-cad-tmp``
STAGING_SUFFIX = ".ght-cad-tmp"
#: the lock file inside a staging folder
_STAGING_LOCK = ".lock"
#: earlier versions' pid-less staging folders of single-file exports
_LEGACY_EXPORT_PREFIX = ".ght-cad-export."
_PID_RE = re.compile(r"\.(\d+)-[A-Za-z0-9_]+" + re.escape(STAGING_SUFFIX) + r"$")
#: seconds between two attempts while waiting for a busy target
POLL_S = 0.05


class FolderBusy(GHTError):
    """The target folder (or file) is in use by another live process.

    Attributes:
        path: the target.
        pid: the other process's pid (None if it could not be read).
        owner: its command line as recorded in the lock file ("" if unknown).
    """

    def __init__(self, message: str, path: Path, pid: int | None, owner: str) -> None:
        super().__init__(message)
        self.path = path
        self.pid = pid
        self.owner = owner


def _owner_text() -> str:
    argv = [Path(sys.argv[0]).name if sys.argv and sys.argv[0] else "python", *sys.argv[1:]]
    return " ".join(argv)[:300]


def _pid_alive(pid: int) -> bool:
    """True if a process ``pid`` exists (a zombie counts as existing)."""
    if pid <= 0:
        return False
    if os.name == "nt":  # pragma: no cover - os.kill(pid, 0) would send CTRL_C_EVENT there: assume alive
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, another user's
        return True
    except OSError:  # pragma: no cover - be safe: do not delete
        return True
    return True


def _read_owner(fd_or_path: int | Path) -> tuple[int | None, str]:
    """(pid, command) recorded in a lock file ("<pid> <command>"), (None, "") if empty/unreadable."""
    try:
        if isinstance(fd_or_path, int):
            os.lseek(fd_or_path, 0, os.SEEK_SET)
            data = os.read(fd_or_path, 4096)
        else:
            data = fd_or_path.read_bytes()[:4096]
    except OSError:
        return None, ""
    text = data.decode("utf-8", "replace").strip()
    head, _, rest = text.partition(" ")
    return (int(head), rest) if head.isdigit() else (None, "")


def _write_owner(fd: int) -> None:
    os.ftruncate(fd, 0)
    os.lseek(fd, 0, os.SEEK_SET)
    os.write(fd, f"{os.getpid()} {_owner_text()}\n".encode("utf-8", "replace"))


def _try_flock(fd: int) -> bool:
    """Take an exclusive lock on the open file ``fd`` without blocking; False if another holds it.

    ``fcntl.flock`` on POSIX, ``msvcrt.locking`` of the first byte on Windows (both dropped by the
    kernel when the process dies).

    Raises:
        GHTError: the platform has neither (named, instead of an ImportError at import).
    """
    _check_lock_support()
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        else:
            os.lseek(fd, 0, os.SEEK_SET)
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        return True
    except OSError as exc:
        if exc.errno in (errno.EAGAIN, errno.EACCES, errno.EWOULDBLOCK, errno.EDEADLK):
            return False
        raise


def _check_lock_support() -> None:
    """Raise a :class:`GHTError` (exit code 2, one line) on a platform with neither lock call."""
    if fcntl is None and msvcrt is None:
        raise GHTError(f"ght-cad cannot lock output folders on this platform ({sys.platform}: neither fcntl "
                       "nor msvcrt is available); allowed: a POSIX system or Windows")


#: ``O_NOFOLLOW`` where the platform has it (a symbolic link at a lock file's name is never followed)
_O_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_O_CLOEXEC = getattr(os, "O_CLOEXEC", 0)


def _open_lock_file(path: Path) -> int:
    """Open (creating it exclusively if missing) the lock file ``path`` for reading and writing.

    Never follows a symbolic link and never opens anything but a plain file with one link, so a
    link planted at ``path`` (to another user's file) is never written through.

    Raises:
        GHTError: ``path`` is a symbolic link, a hard link, or not a plain file (named).
        OSError: the folder is not writable, ... (the caller names the target).
    """
    import stat

    for _ in range(100):
        try:
            return os.open(path, os.O_RDWR | os.O_CREAT | os.O_EXCL | _O_NOFOLLOW | _O_CLOEXEC, 0o644)
        except FileExistsError:
            pass
        try:
            if not _O_NOFOLLOW and os.path.islink(path):  # pragma: no cover - no O_NOFOLLOW (Windows)
                raise OSError(errno.ELOOP, "a symbolic link", str(path))
            fd = os.open(path, os.O_RDWR | _O_NOFOLLOW | _O_CLOEXEC)
        except FileNotFoundError:  # removed by its holder meanwhile: create it again
            continue
        except OSError as exc:
            if exc.errno in (errno.ELOOP, errno.EMLINK) or os.path.islink(path):
                raise GHTError(f"lock file {path} is a symbolic link, which ght-cad never writes through; "
                               "allowed: remove it (ght-cad's lock files are plain files)") from None
            raise
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_nlink != 1:
            os.close(fd)
            what = "not a plain file" if not stat.S_ISREG(st.st_mode) else f"a file with {st.st_nlink} hard links"
            raise GHTError(f"lock file {path} is {what}, which ght-cad never writes into; "
                           "allowed: remove it (ght-cad's lock files are plain files with one link)")
        return fd
    raise GHTError(f"lock file {path} keeps appearing and disappearing; allowed: try again")  # pragma: no cover


# ---------------------------------------------------------------------------------------------
# locks on targets
# ---------------------------------------------------------------------------------------------
def lock_path_for(target: str | os.PathLike) -> Path:
    """The lock file of ``target``: ``<parent>/.<name>.ght-cad-lock``."""
    t = Path(target).absolute()
    return t.parent / f".{t.name}{LOCK_SUFFIX}"


class TargetLock:
    """An exclusive lock on a folder or file path (see the module docstring); a context manager.

    Args:
        target: the folder or file to protect (need not exist; its parent is created).
        wait: wait while another process holds the lock instead of raising :class:`FolderBusy`.
        timeout: with ``wait``, give up after this many seconds (None: wait as long as it takes).
        what: "folder" or "file", for messages.
        hint: how to resolve the conflict, appended to the refusal message.
        on_wait: called once with the FolderBusy describing the holder when a wait begins.
    """

    def __init__(self, target: str | os.PathLike, *, wait: bool = False, timeout: float | None = None,
                 what: str = "folder", hint: str = "run again with --wait, or choose another output",
                 on_wait: Callable[[FolderBusy], None] | None = None) -> None:
        if timeout is not None and not (timeout >= 0 and timeout == timeout):
            raise GHTError(f"timeout={timeout!r} is not allowed; allowed: a number of seconds >= 0 or none")
        self.target = Path(target)
        self.path = lock_path_for(target)
        self.wait = wait
        self.timeout = timeout
        self.what = what
        self.hint = hint
        self.on_wait = on_wait
        self.fd: int | None = None

    def _busy(self, fd: int, waited: float | None = None) -> FolderBusy:
        pid, owner = _read_owner(fd)
        # the holder writes "<pid> <command>" right after it took the lock (truncate, then write):
        # a refusal in that window would name nobody, so read again for up to 1 s
        t_end = time.monotonic() + 1.0
        while pid is None and time.monotonic() < t_end:
            time.sleep(0.02)
            pid, owner = _read_owner(fd)
        who = f"pid {pid}" if pid is not None else "a process that is starting"
        if owner:
            who += f": {owner}"
        if waited is not None:
            msg = (f"{self.what} {self.target} is still in use by another ght-cad process ({who}) after waiting "
                   f"{waited:g} s; allowed: a longer --wait-timeout, or another output")
        else:
            msg = f"{self.what} {self.target} is in use by another ght-cad process ({who}); allowed: {self.hint}"
        return FolderBusy(msg, self.target, pid, owner)

    def acquire(self) -> "TargetLock":
        """Take the lock (waiting if asked); raises :class:`FolderBusy` or ``GHTError``."""
        if self.fd is not None:
            return self
        _check_lock_support()  # before anything is created
        parent = self.path.parent
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise GHTError(f"cannot create the folder {parent} for {self.target}: {exc.strerror or exc}; "
                           "allowed: a path whose parent folders can be created") from None
        t0 = time.monotonic()
        told = False
        while True:
            try:
                fd = _open_lock_file(self.path)
            except OSError as exc:
                raise GHTError(f"cannot lock {self.target} (lock file {self.path}): {exc.strerror or exc}; "
                               "allowed: a writable folder") from None
            if _try_flock(fd):
                # the holder before us may have removed the file we opened: then lock the new one
                try:
                    same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
                except FileNotFoundError:
                    same = False
                if same:
                    _write_owner(fd)
                    self.fd = fd
                    return self
                os.close(fd)
                continue
            if not self.wait:
                err = self._busy(fd)
                os.close(fd)
                raise err
            if not told and self.on_wait is not None:
                told = True
                self.on_wait(self._busy(fd))
            waited = time.monotonic() - t0
            if self.timeout is not None and waited >= self.timeout:
                err = self._busy(fd, waited=self.timeout)
                os.close(fd)
                raise err
            os.close(fd)
            time.sleep(POLL_S if self.timeout is None else max(0.0, min(POLL_S, self.timeout - waited)))

    def release(self) -> None:
        """Remove the lock file and drop the lock (no-op if not held)."""
        if self.fd is None:
            return
        try:
            if os.fstat(self.fd).st_ino == os.stat(self.path).st_ino:
                os.unlink(self.path)
        except OSError:
            pass
        os.close(self.fd)  # closing drops the flock
        self.fd = None

    @property
    def held(self) -> bool:
        return self.fd is not None

    def __enter__(self) -> "TargetLock":
        return self.acquire()

    def __exit__(self, *exc: Any) -> None:
        self.release()


def lock_target(target: str | os.PathLike, *, wait: bool = False, timeout: float | None = None,
                what: str = "file", hint: str = "try again when the other export has finished") -> TargetLock:
    """An acquired :class:`TargetLock` on ``target`` (use as ``with lock_target(p): ...``)."""
    return TargetLock(target, wait=wait, timeout=timeout, what=what, hint=hint).acquire()


# ---------------------------------------------------------------------------------------------
# staging folders
# ---------------------------------------------------------------------------------------------
class StagingDir:
    """A staging folder ``<parent>/.<label>.<pid>-<random>.ght-cad-tmp`` whose ``.lock`` this
    process holds while it lives; :meth:`remove` deletes it.

    Args:
        parent: folder to create it in (created if missing).
        label: readable part of the name (the target's name).
    """

    def __init__(self, parent: str | os.PathLike, label: str) -> None:
        self.parent = Path(parent)
        label = label.lstrip(".") or "out"
        self.path = Path(tempfile.mkdtemp(prefix=f".{label}.{os.getpid()}-", suffix=STAGING_SUFFIX, dir=self.parent))
        self.lock_file = self.path / _STAGING_LOCK
        try:
            self.fd: int | None = os.open(self.lock_file, os.O_RDWR | os.O_CREAT | os.O_EXCL | _O_NOFOLLOW | _O_CLOEXEC,
                                          0o644)
            if not _try_flock(self.fd):  # pragma: no cover - a file this process just created
                raise OSError(errno.EAGAIN, "staging lock taken", str(self.lock_file))
            _write_owner(self.fd)
        except BaseException:
            shutil.rmtree(self.path, ignore_errors=True)
            raise
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(self.path, 0o777 & ~umask)  # mkdtemp makes 0700; the result is an ordinary folder

    def files(self) -> list[str]:
        """Names of the finished files in the folder (no lock file, no ``.part`` leftovers)."""
        return sorted(p.name for p in self.path.iterdir()
                      if p.is_file() and p.name != _STAGING_LOCK and not p.name.endswith(".part"))

    def drop_lock_file(self) -> None:
        """Delete the lock file (keeping the lock itself) before the folder is renamed into place."""
        try:
            self.lock_file.unlink()
        except FileNotFoundError:
            pass

    def release(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def remove(self) -> None:
        """Delete the folder (if still there) and drop its lock."""
        shutil.rmtree(self.path, ignore_errors=True)
        self.release()


def is_dead(folder: str | os.PathLike) -> bool:
    """True if ``folder`` is a staging folder whose run is gone (see the module docstring).

    Live: its ``.lock`` is held by a process, or it has no (or an empty) lock file yet and the pid
    in its name exists. Dead: the lock can be taken, or no lock and no such pid (or no pid in the
    name: an earlier version's folder).
    """
    folder = Path(folder)
    m = _PID_RE.search(folder.name)
    pid = int(m.group(1)) if m else None
    lock = folder / _STAGING_LOCK
    try:
        fd = os.open(lock, os.O_RDWR | _O_NOFOLLOW | _O_CLOEXEC)
    except FileNotFoundError:
        return pid is None or not _pid_alive(pid)
    except OSError:
        return False
    try:
        if not _try_flock(fd):
            return False
        owner, _ = _read_owner(fd)
        if owner is None and pid is not None and _pid_alive(pid):
            return False  # created, not yet stamped by its (live) process
        return True
    finally:
        os.close(fd)


def _staging_candidates(parent: Path) -> list[Path]:
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return []
    out = []
    for e in entries:
        if (e.name.endswith(STAGING_SUFFIX) or e.name.startswith(_LEGACY_EXPORT_PREFIX)) and e.name.startswith("."):
            try:
                if e.is_dir(follow_symlinks=False):
                    out.append(Path(e.path))
            except OSError:
                pass
    return out


def sweep_dead(parent: str | os.PathLike) -> list[Path]:
    """Remove the dead runs' staging folders in ``parent``; returns those removed.

    Only hidden folders named ``*.ght-cad-tmp`` (or ``.ght-cad-export.*`` of earlier versions)
    are looked at, and only the dead ones (:func:`is_dead`) removed; a live run's folder is
    never touched.
    """
    removed = []
    for d in _staging_candidates(Path(parent)):
        if is_dead(d):
            shutil.rmtree(d, ignore_errors=True)
            if not d.exists():
                removed.append(d)
    return removed


# ---------------------------------------------------------------------------------------------
# manifests
# ---------------------------------------------------------------------------------------------
def _safe_names(names: Iterable[Any]) -> list[str]:
    """Plain file names only (a manifest can never name a path outside its folder)."""
    out = []
    for n in names:
        if isinstance(n, str) and n and n not in (".", "..") and "/" not in n and "\\" not in n and "\0" not in n \
                and n != MANIFEST_NAME:
            out.append(n)
    return out


#: the run's report, which lists the files of the run under ``files`` (the usual manifest)
REPORT_NAME = "report.json"


def _report_files(path: Path) -> list[str] | None:
    """The ``files`` list of a ght-cad report (one with ``files`` and ``ght_definition`` or
    ``"tool": "ght-cad"``), None for anything else (a person's file of the same name)."""
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    if not isinstance(data, dict) or not isinstance(data.get("files"), list):
        return None
    if "ght_definition" not in data and data.get("tool") != "ght-cad":
        return None
    return _safe_names(data["files"]) + [path.name]


def read_manifest(folder: str | os.PathLike) -> list[str]:
    """The files the last run wrote into ``folder`` ([] for a folder no ght-cad run wrote).

    The union of ``report.json``'s ``files`` (a ght-cad report; the usual manifest) and
    ``.ght-cad-manifest.json`` (written by runs without a report, and during a commit as the
    union of the old and new names, so that a run killed half-way through still names every
    file of ours).
    """
    folder = Path(folder)
    names: list[str] = []
    try:
        data = json.loads((folder / MANIFEST_NAME).read_text(encoding="utf-8"))
        if isinstance(data, dict) and isinstance(data.get("files"), list):
            names += _safe_names(data["files"])
    except (OSError, ValueError):
        pass
    names += _report_files(folder / REPORT_NAME) or []
    return sorted(set(names))


def write_manifest(folder: str | os.PathLike, files: Iterable[str], *, pending: bool = False) -> Path:
    """Write ``.ght-cad-manifest.json`` (``{"tool", "files", "pending"}``) into ``folder`` atomically."""
    from .io import write_text_atomic

    body = {"tool": "ght-cad", "files": sorted(set(_safe_names(files))), "pending": bool(pending)}
    return write_text_atomic(Path(folder) / MANIFEST_NAME, json.dumps(body, indent=1) + "\n")


def _listed_by_report(folder: Path, names: Sequence[str]) -> bool:
    """True if ``folder/report.json`` is a ght-cad report whose ``files`` list all of ``names``."""
    listed = _report_files(folder / REPORT_NAME)
    return listed is not None and set(names) <= set(listed)


def _remove_part_leftovers(folder: Path) -> None:
    """Remove half-written manifests (``..ght-cad-manifest.*.json.part``, named by
    :func:`ght_cad.core.io.atomic_path`) a killed run left in ``folder``."""
    stem = Path(MANIFEST_NAME).stem
    try:
        for p in folder.glob(f".{stem}.*.part"):
            if p.is_file():
                p.unlink()
    except OSError:
        pass


# ---------------------------------------------------------------------------------------------
# the two writers' front ends
# ---------------------------------------------------------------------------------------------
class OutputFolder:
    """An output folder written by one run: locked, staged, committed with a manifest.

    ``with OutputFolder(out) as f:`` takes the folder's lock (:class:`TargetLock`; ``wait``,
    ``timeout``), removes dead runs' staging folders beside it (:func:`sweep_dead`) and creates
    this run's staging folder; write each result to ``f.path(name)`` and call :meth:`commit`.
    Leaving the block without a commit (an exception, Ctrl-C) removes the staging folder and the
    parent folders made for it; the output folder is then exactly as it was.

    Args:
        out_dir: the output folder (new, or an existing folder).
        wait, timeout: see :class:`TargetLock`.
        on_wait: called once if the run has to wait (e.g. to print "waiting for pid N").

    Raises:
        FolderBusy: another live process writes ``out_dir`` (and not ``wait``, or the timeout passed).
        GHTError: ``out_dir`` is a file, or its parent cannot be created.
    """

    def __init__(self, out_dir: str | os.PathLike, *, wait: bool = False, timeout: float | None = None,
                 on_wait: Callable[[FolderBusy], None] | None = None) -> None:
        _refuse_empty(out_dir, "output folder")
        self.out = Path(out_dir)
        self.wait = wait
        self.timeout = timeout
        self.on_wait = on_wait
        self.lock: TargetLock | None = None
        self.stage: StagingDir | None = None
        self.made_parents: list[Path] = []
        self.committed: list[str] | None = None

    def open(self) -> "OutputFolder":
        """Lock, sweep and stage (what ``__enter__`` does).

        The staging folder goes beside the output folder, or inside it when the output folder
        exists on another file system than its parent (a mount point, a link to a folder
        elsewhere), so that :meth:`commit`'s renames never cross file systems. An existing
        output folder must be writable (probed by creating and removing a file in it).
        """
        out = self.out
        if out.exists() and not out.is_dir():
            raise GHTError(f"{out} exists and is not a folder; allowed: a folder or a new path")
        parent = out.absolute().parent
        self.made_parents = [d for d in (parent, *parent.parents) if not d.exists()][::-1]
        try:
            self.lock = TargetLock(out, wait=self.wait, timeout=self.timeout, what="output folder",
                                   hint="run again with --wait (waits until it has finished), or choose another --out",
                                   on_wait=self.on_wait).acquire()
            sweep_dead(parent)
            where = parent
            if out.is_dir():
                _probe_writable(out)
                if _other_device(out, parent):
                    where = out
                    sweep_dead(out)
                _remove_part_leftovers(out)
            try:
                self.stage = StagingDir(where, out.name)
            except OSError as exc:
                raise GHTError(
                    f"cannot create the output folder {out}: {exc.strerror or exc}"
                    f"{f' ({exc.filename})' if exc.filename else ''}; allowed: a folder or a new path "
                    "whose parent folders can be created") from None
        except BaseException:
            self.close(failed=True)
            raise
        return self

    def path(self, name: str) -> Path:
        """Where to write the result file ``name`` (inside the staging folder)."""
        if self.stage is None:
            raise RuntimeError("OutputFolder is not open")
        return self.stage.path / name

    def files(self) -> list[str]:
        """Names of the files written into the staging folder so far."""
        return self.stage.files() if self.stage is not None else []

    def commit(self) -> list[str]:
        """Move the staged files into the output folder; returns their names (sorted).

        A new folder appears by one rename. Into an existing folder: ``.ght-cad-manifest.json``
        is first written as old ∪ new (pending), every new file replaces its target
        (``os.replace``), the files of the previous manifest not written again are removed, and
        the hidden manifest is removed again if the new ``report.json`` lists every new file
        (else rewritten as the new names). Files not in the previous manifest (a person's) are
        kept.

        Raises:
            GHTError: a staged name is a folder in the output folder (checked before any move).
        """
        if self.stage is None:
            raise RuntimeError("OutputFolder is not open")
        out = self.out
        names = self.stage.files()
        by_report = _listed_by_report(self.stage.path, names)  # report.json is the manifest
        if not out.exists():
            if not by_report:
                write_manifest(self.stage.path, names)
            self.stage.drop_lock_file()
            try:
                os.replace(self.stage.path, out)  # one atomic rename: the folder appears complete
                self.stage.release()
                self.stage = None
                self.made_parents = []
                self.committed = names
                return names
            except OSError as exc:
                if not out.is_dir():
                    raise _folder_error(out, exc) from None
                # a folder appeared meanwhile (made by hand): fall through to the file moves
                if not by_report:
                    os.unlink(self.stage.path / MANIFEST_NAME)
        if not out.is_dir():
            raise GHTError(f"{out} exists and is not a folder; allowed: a folder or a new path")
        for n in names:  # checked before the first move: a failure must not leave a mixed folder
            if (out / n).is_dir():
                raise GHTError(f"cannot write {out / n}: it is a folder; allowed: a file path "
                               "(remove or rename the folder)")
        previous = read_manifest(out)
        manifest = out / MANIFEST_NAME
        try:
            before = manifest.read_bytes() if manifest.is_file() and not manifest.is_symlink() else None
        except OSError:
            before = None
        moved = 0
        try:
            write_manifest(out, set(previous) | set(names), pending=True)
            for n in names:
                os.replace(self.stage.path / n, out / n)
                moved += 1
        except OSError as exc:
            if moved == 0:  # nothing of this run reached the folder: leave it as it was
                _restore_file(manifest, before)
            raise _folder_error(out, exc) from None
        for n in sorted(set(previous) - set(names)):
            p = out / n
            try:
                if p.is_file() or p.is_symlink():
                    p.unlink()
            except OSError:
                pass
        if by_report:
            os.unlink(out / MANIFEST_NAME)  # the new report.json lists every file
        else:
            write_manifest(out, names)
        self.stage.remove()
        self.stage = None
        self.made_parents = []
        self.committed = names
        return names

    def close(self, failed: bool = False) -> None:
        """Remove the staging folder (and, after a failure, the parents made for it); unlock."""
        if self.stage is not None:
            self.stage.remove()
            self.stage = None
        if self.lock is not None:
            self.lock.release()
            self.lock = None
        if failed or self.committed is None:
            for d in reversed(self.made_parents):
                try:
                    d.rmdir()  # only if still empty
                except OSError:
                    pass
            self.made_parents = []

    def __enter__(self) -> "OutputFolder":
        return self.open()

    def __exit__(self, exc_type: Any, *exc: Any) -> None:
        self.close(failed=exc_type is not None)


def _refuse_empty(path: str | os.PathLike, what: str) -> None:
    """An empty path (``--out ""``) means no folder at all, not the current folder: refuse it."""
    if not os.fspath(path).strip():
        raise GHTError(f"{what} path {os.fspath(path)!r} is empty; allowed: a folder path (use '.' for the current folder)")


def _probe_writable(folder: Path) -> None:
    """Create and remove a file in ``folder``; a read-only or unwritable folder is refused (named).

    (``os.access`` is not enough: it says yes to root in a folder of mode 0555 on a read-only mount.)
    """
    try:
        fd, name = tempfile.mkstemp(prefix=".ght-cad-probe.", dir=folder)
        os.close(fd)
        os.unlink(name)
    except OSError as exc:
        raise GHTError(f"output folder {folder} is not writable ({exc.strerror or exc}); "
                       "allowed: a folder this user can write on a writable file system") from None


def _other_device(folder: Path, parent: Path) -> bool:
    """True if ``folder`` (followed if a link) lies on another file system than ``parent``."""
    try:
        return os.stat(folder).st_dev != os.stat(parent).st_dev
    except OSError:
        return False


def _restore_file(path: Path, content: bytes | None) -> None:
    """Put ``path`` back as it was (``content`` None: it did not exist); best effort."""
    try:
        if content is None:
            if path.is_file() and not path.is_symlink():
                path.unlink()
        else:
            from .io import write_bytes_atomic

            write_bytes_atomic(path, content)
    except OSError:  # pragma: no cover - the folder just failed us; the manifest still covers our files
        pass


#: errors of the place the files go (not of ght-cad): a refusal naming the folder (exit code 2)
_PLACE_ERRNOS = {errno.EROFS, errno.EACCES, errno.EPERM, errno.EXDEV, errno.ENOSPC, getattr(errno, "EDQUOT", -1)}


def _folder_error(folder: Path, exc: OSError) -> Exception:
    """A :class:`GHTError` naming ``folder`` for a read-only, full or foreign place; else ``exc`` itself."""
    if exc.errno in _PLACE_ERRNOS:
        return GHTError(f"cannot write into output folder {folder}: {exc.strerror or exc}; "
                        "allowed: a writable folder with free space")
    return exc


class StagedFiles:
    """Several single output files written all or nothing (``curve``/``surface``/``unroll``/``export``).

    One :class:`StagingDir` per target folder (pid + lock, swept by later runs if this process
    dies); :meth:`commit` moves every staged file onto its target only when each writer produced
    one. Leaving the block without commit removes the staging folders and the folders made for
    missing parents; every existing target is then as it was.

    Args:
        targets: the files to write.
        lock: take a :class:`TargetLock` on every target first, so that two processes writing the
            same file never leave one's set mixed with the other's.
        wait, timeout: see :class:`TargetLock`.

    Raises:
        FolderBusy: (with ``lock``) another live process writes one of the targets.
        GHTError: a target is a folder, or a target folder cannot be created or written.
    """

    def __init__(self, targets: Sequence[str | os.PathLike], *, lock: bool = True, wait: bool = False,
                 timeout: float | None = None) -> None:
        self.dirs: dict[Path, StagingDir] = {}
        self.made: list[Path] = []
        self.map: dict[Path, Path] = {}
        self.locks: list[TargetLock] = []
        try:
            for t in targets:
                _refuse_empty(t, "output file")
            paths = [Path(t) for t in targets]
            for t in paths:
                if t.exists() and t.is_dir():
                    raise GHTError(f"cannot write {t}: it is a folder; allowed: a file path")
            if lock:
                for t in sorted({p.absolute() for p in paths}):
                    self._mkdirs(t.parent, t)
                    self.locks.append(TargetLock(t, wait=wait, timeout=timeout, what="file",
                                                 hint="try again when the other process has finished").acquire())
            for t in paths:
                parent = t.parent.absolute()
                if t.exists() and t.is_dir():
                    raise GHTError(f"cannot write {t}: it is a folder; allowed: a file path")
                if parent not in self.dirs:
                    self._mkdirs(parent, t)
                    sweep_dead(parent)
                    try:
                        self.dirs[parent] = StagingDir(parent, "ght-cad-export")
                    except OSError as exc:
                        raise GHTError(
                            f"cannot write {t}: folder {parent} is not writable ({exc.strerror or exc})"
                        ) from None
                # a numbered name keeps repeated or equal base names apart; the suffix is kept for writers
                self.map[t] = self.dirs[parent].path / f"{len(self.map)}{t.suffix}"
        except BaseException:
            self.cleanup()
            raise

    def _mkdirs(self, parent: Path, target: Path) -> None:
        missing = []
        p = parent
        while not p.exists() and p != p.parent:
            missing.append(p)
            p = p.parent
        for d in reversed(missing):
            try:
                d.mkdir()
            except OSError as exc:
                raise GHTError(f"cannot write {target}: cannot create folder {d} ({exc.strerror or exc})") from None
            self.made.append(d)

    def path(self, target: str | os.PathLike) -> Path:
        """The staging path for ``target``."""
        return self.map[Path(target)]

    def commit(self) -> None:
        """Move every staged file onto its target (same file system: ``os.replace`` each)."""
        for t, tmp in self.map.items():
            if not tmp.is_file():
                raise GHTError(f"writing {t} produced no file")
        for t, tmp in self.map.items():
            os.replace(tmp, t)
        self.made = []  # the folders now hold results

    def cleanup(self) -> None:
        """Remove the staging folders (and the folders made for missing parents, if uncommitted)."""
        for d in self.dirs.values():
            d.remove()
        self.dirs = {}
        for lk in self.locks:
            lk.release()
        self.locks = []
        for d in reversed(self.made):
            try:
                d.rmdir()
            except OSError:
                pass
        self.made = []

    def __enter__(self) -> "StagedFiles":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.cleanup()
