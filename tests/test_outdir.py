"""ght_cad.core.outdir: locks, staging folders that tell dead runs from live ones, manifests.

Other processes are real processes (``subprocess`` running a few lines of Python), killed with
SIGKILL where a crash is the point: a flock must vanish with its process, and a later run must
remove what the dead one left while never touching a live run's folder.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from ght_cad.core.errors import GHTError
from ght_cad.core.outdir import (
    MANIFEST_NAME,
    FolderBusy,
    OutputFolder,
    StagedFiles,
    StagingDir,
    TargetLock,
    is_dead,
    lock_path_for,
    read_manifest,
    sweep_dead,
)

REPO = Path(__file__).resolve().parents[1]


def _python(code: str, *args: str) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=str(REPO))
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code), *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_line(proc: subprocess.Popen, expect: str) -> str:
    line = proc.stdout.readline()
    assert line.strip() == expect, (line, proc.stderr.read() if proc.poll() is not None else "")
    return line


HOLD = """
import sys, time
from ght_cad.core.outdir import OutputFolder
f = OutputFolder(sys.argv[1]).open()
(f.path("model.step")).write_text("x")
print("held", flush=True)
time.sleep(60)
"""


def _kill(proc: subprocess.Popen) -> None:
    proc.send_signal(signal.SIGKILL)
    proc.wait()  # reaped: its pid no longer exists


def test_second_process_is_refused_naming_folder_and_pid(tmp_path: Path) -> None:
    out = tmp_path / "out"
    holder = _python(HOLD, str(out))
    try:
        _wait_line(holder, "held")
        with pytest.raises(FolderBusy) as ei:
            OutputFolder(out).open()
        msg = str(ei.value)
        assert str(out) in msg and f"pid {holder.pid}" in msg and "--wait" in msg, msg
        assert ei.value.pid == holder.pid and isinstance(ei.value, GHTError)
        # waiting with a timeout gives up after about that time, naming the pid again
        t0 = time.monotonic()
        with pytest.raises(FolderBusy) as ei:
            OutputFolder(out, wait=True, timeout=0.3).open()
        assert 0.25 <= time.monotonic() - t0 < 5.0
        assert f"pid {holder.pid}" in str(ei.value) and "after waiting 0.3 s" in str(ei.value)
        # the holder's staging folder is live: a sweep leaves it alone
        staged = list(tmp_path.glob(".out.*.ght-cad-tmp"))
        assert len(staged) == 1 and not is_dead(staged[0])
        assert sweep_dead(tmp_path) == [] and staged[0].is_dir()
    finally:
        _kill(holder)
    # the kernel dropped the dead holder's lock: the next run gets the folder and removes the
    # dead run's staging folder, and after it no lock file or staging folder is left
    assert is_dead(staged[0])
    with OutputFolder(out) as f:
        assert not staged[0].exists()
        f.path("a.txt").write_text("a")
        assert f.commit() == ["a.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert sorted(p.name for p in out.iterdir()) == sorted(["a.txt", MANIFEST_NAME])


def test_wait_gets_the_folder_when_the_holder_finishes(tmp_path: Path) -> None:
    out = tmp_path / "out"
    holder = _python("""
        import sys, time
        from ght_cad.core.outdir import OutputFolder
        with OutputFolder(sys.argv[1]) as f:
            f.path("first.txt").write_text("1")
            print("held", flush=True)
            time.sleep(0.8)
            f.commit()
        """, str(out))
    _wait_line(holder, "held")
    waits = []
    t0 = time.monotonic()
    with OutputFolder(out, wait=True, timeout=30, on_wait=waits.append) as f:
        took = time.monotonic() - t0
        assert (out / "first.txt").read_text() == "1"  # the holder committed before we got it
        f.path("second.txt").write_text("2")
        f.commit()
    assert holder.wait() == 0
    assert 0.3 < took < 20 and len(waits) == 1 and waits[0].pid == holder.pid
    # the first run's file was listed in its manifest and not written again: removed
    assert sorted(p.name for p in out.iterdir()) == sorted(["second.txt", MANIFEST_NAME])


def test_lock_file_removed_and_a_waiter_on_the_removed_inode_retries(tmp_path: Path) -> None:
    target = tmp_path / "part.step"
    a = TargetLock(target).acquire()
    lock = lock_path_for(target)
    assert lock.is_file() and lock.read_text().split()[0] == str(os.getpid())
    # a second lock object in this very process is refused too (flock is per open file)
    with pytest.raises(FolderBusy):
        TargetLock(target).acquire()
    fd = os.open(lock, os.O_RDWR)  # a waiter that opened the file before the release ...
    a.release()
    assert not lock.exists()
    b = TargetLock(target).acquire()  # ... and a newcomer that locks a new file
    try:
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # the old inode is free: locking it means nothing
        with pytest.raises(FolderBusy):  # the retry logic sees the new file, which b holds
            TargetLock(target).acquire()
    finally:
        os.close(fd)
        b.release()


def test_bad_timeout_is_a_clear_error(tmp_path: Path) -> None:
    with pytest.raises(GHTError, match="timeout=-1"):
        TargetLock(tmp_path / "x", wait=True, timeout=-1)


def test_dead_and_live_staging_folders(tmp_path: Path) -> None:
    live = StagingDir(tmp_path, "out")
    assert not is_dead(live.path)
    # a run that was SIGKILLed after staging: lock free -> dead
    proc = _python("""
        import sys
        from ght_cad.core.outdir import StagingDir
        d = StagingDir(sys.argv[1], "out")
        print(d.path, flush=True)
        import time; time.sleep(60)
        """, str(tmp_path))
    dead = Path(proc.stdout.readline().strip())
    assert dead.is_dir() and not is_dead(dead)
    _kill(proc)
    assert is_dead(dead)
    # an earlier version's pid-less folder (no lock) is dead; so is a pid-named one of a gone pid
    legacy = tmp_path / ".out.k2j3h4l5.ght-cad-tmp"
    legacy.mkdir()
    (legacy / "basis.png").write_text("x")
    legacy_export = tmp_path / ".ght-cad-export.abcd1234"
    legacy_export.mkdir()
    gone = tmp_path / f".out.{proc.pid}-zzzz.ght-cad-tmp"
    gone.mkdir()
    # a folder being created (no lock file yet) by a live pid is live
    starting = tmp_path / f".out.{os.getpid()}-new1.ght-cad-tmp"
    starting.mkdir()
    # a person's folders are never candidates
    (tmp_path / "notes.ght-cad-tmp").mkdir()
    (tmp_path / ".hidden").mkdir()
    removed = sweep_dead(tmp_path)
    assert sorted(p.name for p in removed) == sorted([dead.name, legacy.name, legacy_export.name, gone.name])
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == sorted([live.path.name, starting.name, "notes.ght-cad-tmp", ".hidden"])
    live.remove()
    assert not live.path.exists()


def test_one_design_per_folder_person_files_kept(tmp_path: Path) -> None:
    out = tmp_path / "out"
    with OutputFolder(out) as f:  # design A: new folder by one rename
        for n in ("model.step", "basis.png", "report.json"):
            f.path(n).write_text("A " + n)
        assert f.commit() == ["basis.png", "model.step", "report.json"]
    assert read_manifest(out) == ["basis.png", "model.step", "report.json"]
    (out / "notes.txt").write_text("mine")  # a person's file
    with OutputFolder(out) as f:  # design B: no basis.png
        for n in ("model.step", "report.json", "curve.png"):
            f.path(n).write_text("B " + n)
        f.commit()
    assert sorted(p.name for p in out.iterdir()) == sorted(["model.step", "report.json", "curve.png", "notes.txt", MANIFEST_NAME])
    assert (out / "model.step").read_text() == "B model.step" and (out / "notes.txt").read_text() == "mine"
    assert json.loads((out / MANIFEST_NAME).read_text())["pending"] is False
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_folder_of_an_earlier_version_is_cleaned_by_its_report(tmp_path: Path) -> None:
    out = tmp_path / "out"
    out.mkdir()
    (out / "report.json").write_text(json.dumps({"ght_definition": "x", "files": ["basis.png", "report.json", "../x"]}))
    (out / "basis.png").write_text("old")
    (tmp_path / "x").write_text("outside: a manifest never reaches it")
    (out / "mine.json").write_text(json.dumps({"files": ["keep.txt"]}))
    with OutputFolder(out) as f:
        f.path("model.step").write_text("new")
        f.commit()
    assert sorted(p.name for p in out.iterdir()) == sorted(["model.step", "mine.json", MANIFEST_NAME])
    assert (tmp_path / "x").exists()


def test_failure_leaves_folder_and_parents_as_they_were(tmp_path: Path) -> None:
    out = tmp_path / "a" / "b" / "out"
    with pytest.raises(RuntimeError):
        with OutputFolder(out) as f:
            f.path("model.step").write_text("x")
            raise RuntimeError("boom")
    assert not (tmp_path / "a").exists()
    existing = tmp_path / "out"
    existing.mkdir()
    (existing / "model.step").write_text("old")
    with pytest.raises(RuntimeError):
        with OutputFolder(existing) as f:
            f.path("model.step").write_text("new")
            raise RuntimeError("boom")
    assert [p.name for p in existing.iterdir()] == ["model.step"] and (existing / "model.step").read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    (tmp_path / "file").write_text("x")
    with pytest.raises(GHTError, match="not a folder"):
        OutputFolder(tmp_path / "file").open()


KILL_IN_COMMIT = """
import json, os, signal, sys
from ght_cad import outdir
out, k, design = sys.argv[1], int(sys.argv[2]), sys.argv[3]
names = {"A": ["basis.png", "model.step", "report.json", "surface.png"], "B": ["model.step", "report.json", "curve.png"]}[design]
calls = [0]
real_replace = os.replace
def replace(a, b):
    if calls[0] == k:
        os.kill(os.getpid(), signal.SIGKILL)
    calls[0] += 1
    real_replace(a, b)
os.replace = replace
with outdir.OutputFolder(out) as f:
    for n in names:  # report.json lists the run's files: it is the manifest
        f.path(n).write_text(json.dumps({"tool": "ght-cad", "files": names}) if n == "report.json" else design + " " + n)
    f.commit()
"""


@pytest.mark.slow
@pytest.mark.parametrize("k", range(8))
def test_kill_inside_commit_then_one_run_gives_exactly_its_files(tmp_path: Path, k: int) -> None:
    """SIGKILL before the k-th rename of a commit (manifest writes and file moves alike)."""
    out = tmp_path / "out"
    assert _python(KILL_IN_COMMIT, str(out), "99", "A").wait() == 0  # design A complete
    (out / "mine.txt").write_text("a person's file")
    proc = _python(KILL_IN_COMMIT, str(out), str(k), "B")
    assert proc.wait() in (-signal.SIGKILL, 0)
    assert _python(KILL_IN_COMMIT, str(out), "99", "B").wait() == 0
    # exactly B's files and the person's: no hidden manifest either (B's report.json lists its files)
    assert sorted(p.name for p in out.iterdir()) == sorted(["model.step", "report.json", "curve.png", "mine.txt"])
    assert all((out / n).read_text() == "B " + n for n in ("model.step", "curve.png"))
    assert read_manifest(out) == ["curve.png", "model.step", "report.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no staging folder, no lock file


def test_staged_files_all_or_nothing_and_locked(tmp_path: Path) -> None:
    a, b = tmp_path / "a.step", tmp_path / "sub" / "b.png"
    a.write_text("old")
    with pytest.raises(RuntimeError):
        with StagedFiles([a, b]) as st:
            st.path(a).write_text("new")
            with pytest.raises(FolderBusy, match="a.step"):
                StagedFiles([a])
            raise RuntimeError("b failed")
    assert a.read_text() == "old" and not (tmp_path / "sub").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.step"]
    with StagedFiles([a, b]) as st:
        st.path(a).write_text("new")
        st.path(b).write_text("png")
        st.commit()
    assert a.read_text() == "new" and b.read_text() == "png"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.step", "sub"]
    with pytest.raises(GHTError, match="produced no file"):
        with StagedFiles([a]) as st:
            st.commit()
    with pytest.raises(GHTError, match="it is a folder"):
        StagedFiles([tmp_path / "sub"])
