"""`ght-cad run` under faults and concurrency, end to end (real processes, real SIGKILL).

* A folder holding design A and a person's files; ten runs of design B killed with SIGKILL at
  moments spread over a run's duration, then one complete run of B: no temporary folder or lock
  left, and the folder equal to a clean run's of B (file set, STEP entities, SVG, report) plus the
  person's files (so also: design A then design B leaves exactly B's files and the person's).
* Two runs on one folder at the same time: the second is refused (exit 2, one line naming the
  folder and the first run's pid) or, with ``--wait``, waits and then writes its own design alone;
  never a folder with one design's report and the other's figures.

The designs are the quarter-cone duct of ``examples/design_duct.toml`` with few figures (a run
takes a few seconds). ``commit`` itself (the few renames at the end of a run) is killed at every
single rename in ``tests/test_outdir.py``.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # processes killed mid-run


REPO = Path(__file__).resolve().parents[1]
DUCT = (REPO / "examples" / "design_duct.toml").read_text()


def _design(tmp: Path, name: str, figures: list[str]) -> Path:
    text = re.sub(r'^name = .*$', f'name = "{name}"', DUCT, flags=re.M)
    text = re.sub(r'^figures = .*$', "figures = " + json.dumps(figures), text, flags=re.M)
    path = tmp / f"{name}.toml"
    path.write_text(text)
    return path


def _cmd(design: Path, out: Path, *extra: str) -> list[str]:
    return [sys.executable, "-m", "ght_cad.app.cli", "run", str(design), "--out", str(out), "--no-progress", *extra]


def _env() -> dict[str, str]:
    import ght_cad

    return dict(os.environ, PYTHONPATH=str(Path(ght_cad.__file__).resolve().parents[1]))


def _run(design: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run(_cmd(design, out, *extra), env=_env(), capture_output=True, text=True, timeout=300)


def _listing(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


def _step_entities(path: Path) -> list[str]:
    """The STEP file without its FILE_NAME header line (which holds the time of writing)."""
    return [l for l in path.read_text().splitlines() if not l.startswith("FILE_NAME")]


def _assert_same_result(got: Path, ref: Path, person: dict[str, str]) -> None:
    assert _listing(got) == sorted(_listing(ref) + list(person)), (_listing(got), _listing(ref))
    assert _step_entities(got / "model.step") == _step_entities(ref / "model.step")
    assert (got / "flat_pattern.svg").read_bytes() == (ref / "flat_pattern.svg").read_bytes()
    a, b = (json.loads((d / "report.json").read_text()) for d in (got, ref))
    for k in ("name", "files", "developability", "flat_pattern", "brep"):
        assert a[k] == b[k], k
    for name, text in person.items():
        assert (got / name).read_text() == text


def _leftovers(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.endswith((".ght-cad-tmp", ".ght-cad-lock")))


def test_sigkill_at_ten_moments_then_one_run_equals_a_clean_run(tmp_path: Path) -> None:
    design_a = _design(tmp_path, "fault-a", ["basis", "surface", "flat_pattern"])
    design_b = _design(tmp_path, "fault-b", ["flat_pattern"])
    ref = tmp_path / "ref" / "out"
    t0 = time.monotonic()
    done = _run(design_b, ref)
    duration = time.monotonic() - t0
    assert done.returncode == 0, done.stderr

    work = tmp_path / "work"
    out = work / "out"
    assert _run(design_a, out).returncode == 0  # the folder holds design A ...
    a_files = set(json.loads((out / "report.json").read_text())["files"])
    b_files = set(json.loads((ref / "report.json").read_text())["files"])
    assert {"basis.png", "surface.png"} <= a_files - b_files  # files of A that B does not write
    # ... and a person's files (one named like ours)
    person = {"notes.txt": "mine, put here by hand", "basis.png.mine": "looks like ours, is not"}
    for name, text in person.items():
        (out / name).write_text(text)
    killed = 0
    for k in range(10):
        start = time.monotonic()
        proc = subprocess.Popen(_cmd(design_b, out), env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        moment = start + (k + 0.5) / 10 * duration
        while proc.poll() is None and time.monotonic() < moment:
            time.sleep(0.01)
        if proc.poll() is None:
            proc.send_signal(signal.SIGKILL)
            killed += 1
        else:
            # it ended before its moment: the machine got faster than when the reference run was
            # timed (another test's load ended); later moments spread over this run's duration
            duration = min(duration, time.monotonic() - start)
        proc.wait()  # reaped: its pid is gone, as after a real crash
        # the folder is always one whole design: A's (not yet replaced) or B's (committed)
        names = json.loads((out / "report.json").read_text())["name"]
        assert names in ("fault-a", "fault-b")
    assert killed >= 7, f"only {killed} of 10 runs were still running when killed (run takes {duration:.1f} s)"
    final = _run(design_b, out)
    assert final.returncode == 0, final.stderr
    assert _leftovers(work) == [], _leftovers(work)
    assert _listing(work) == ["out"]
    # design A then design B: exactly B's files (A's basis.png and surface.png gone) + the person's
    _assert_same_result(out, ref, person)


def _wait_for(path: Path, proc: subprocess.Popen, limit: float = 120.0) -> None:
    t0 = time.monotonic()
    while not path.exists():
        assert proc.poll() is None, "the first run ended before it took the folder's lock"
        assert time.monotonic() - t0 < limit, f"{path} did not appear"
        time.sleep(0.01)


def test_two_runs_on_one_folder_refused_or_waiting_never_mixed(tmp_path: Path) -> None:
    design_a = _design(tmp_path, "fault-a", ["basis", "surface", "flat_pattern"])
    design_b = _design(tmp_path, "fault-b", ["flat_pattern"])
    out = tmp_path / "out"
    lock = tmp_path / ".out.ght-cad-lock"
    first = subprocess.Popen(_cmd(design_a, out), env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        _wait_for(lock, first)
        # a second run while the first holds the folder: refused at once, naming folder and pid
        second = _run(design_b, out)
        assert second.returncode == 2, second.stderr
        err = second.stderr.strip().splitlines()
        assert len(err) == 1 and str(out) in err[0] and f"pid {first.pid}" in err[0] and "--wait" in err[0], err
        # --wait-timeout shorter than the first run: exit 2 after that time
        t0 = time.monotonic()
        short = _run(design_b, out, "--wait-timeout", "0.5")
        assert short.returncode == 2 and "after waiting 0.5 s" in short.stderr, short.stderr
        assert time.monotonic() - t0 >= 0.5
        # --wait: starts when the first run has finished and leaves its own design alone
        third = subprocess.Popen(_cmd(design_b, out, "--wait", "--json"), env=_env(), stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True)
        out3, err3 = third.communicate(timeout=300)
    finally:
        first.wait(timeout=300)
    assert first.returncode == 0, first.stderr.read()
    assert third.returncode == 0, err3
    assert f"waiting for pid {first.pid}" in err3 or not lock.exists()
    report = json.loads((out / "report.json").read_text())
    assert report["name"] == "fault-b" and json.loads(out3)["name"] == "fault-b"
    assert _listing(out) == sorted(report["files"]), (_listing(out), report["files"])
    assert _leftovers(tmp_path) == []


def test_concurrent_starts_one_wins_one_is_refused(tmp_path: Path) -> None:
    """Both started at the same moment without --wait: exactly one exits 0; the other exits 0
    too only if it started after the first had finished; the folder is one design's, whole."""
    design_a = _design(tmp_path, "fault-a", ["basis", "surface", "flat_pattern"])
    design_b = _design(tmp_path, "fault-b", ["flat_pattern"])
    out = tmp_path / "out"
    procs = [subprocess.Popen(_cmd(d, out), env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
             for d in (design_a, design_b)]
    codes = [p.wait(timeout=300) for p in procs]
    errs = [p.stderr.read() for p in procs]
    assert sorted(codes) in ([0, 2], [0, 0]), (codes, errs)
    for code, err in zip(codes, errs):
        if code == 2:
            assert "is in use by another ght-cad process (pid" in err, err
    report = json.loads((out / "report.json").read_text())
    assert _listing(out) == sorted(report["files"])  # one design's files, nothing of the other
    assert _leftovers(tmp_path) == []
