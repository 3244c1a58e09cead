"""`ght-cad run` under faults and concurrency, end to end (real processes, real SIGKILL).

* A folder holding design A and a person's files; ten runs of design B killed with SIGKILL at
  moments spread over a run's duration, then one complete run of B: no temporary folder or lock
  left, and the folder equal to a clean run's of B (file set, STEP entities, SVG, report) plus the
  person's files (so also: design A then design B leaves exactly B's files and the person's).
* Two runs on one folder at the same time: the second is refused (exit 2, one line naming the
  folder and the first run's pid) or, with ``--wait``, waits and then writes its own design alone;
  never a folder with one design's report and the other's figures.

The designs are the quarter-cone duct of ``examples/design_duct.toml`` with few figures. ``commit``
itself (the few renames at the end of a run) is killed at every single rename in ``tests/test_outdir.py``.

Every run is a process of its own, forked from one Python process (:class:`_Runs`, one per test
module) that has imported what a run imports (the modules an instrumented first run loaded): a run
costs its own work, not the seconds of Python + OCP + build123d imports, which touch no folder; so
the ten kill moments spread over the run's work itself (the lock, the staging folder, the files,
the commit). The child runs ``ght_cad.app.cli.main`` with ``sys.argv`` of ``python -m
ght_cad.app.cli`` (the lock records it), its stdout/stderr into files; a SIGKILL is sent to its pid
by this test, and it is reaped before the next run (its pid gone, as after a real crash).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
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


def _env() -> dict[str, str]:
    import ght_cad

    return dict(os.environ, PYTHONPATH=str(Path(ght_cad.__file__).resolve().parents[1]))


#: imported by the forking process before anything else (what every run needs; the rest comes from
#: the instrumented first run's list of modules)
PRELOAD = ["ght_cad.app.cli", "build123d", "matplotlib.backends.backend_agg"]

#: the forking process: JSON requests on stdin, one JSON answer line each on stdout
ZYGOTE = r"""
import importlib, json, os, sys, traceback
for name in json.loads(sys.argv[1]):
    importlib.import_module(name)
import ght_cad.app.cli as cli


def child(req):
    os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
    os.dup2(os.open(req["stdout"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC), 1)
    os.dup2(os.open(req["stderr"], os.O_WRONLY | os.O_CREAT | os.O_TRUNC), 2)
    sys.argv = [cli.__file__, *req["argv"]]  # as for python -m ght_cad.app.cli
    before = set(sys.modules)
    try:
        code = cli.main(req["argv"])
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    except BaseException:
        traceback.print_exc()
        code = 1
    if req.get("modules"):
        with open(req["modules"], "w") as f:
            json.dump(sorted(set(sys.modules) - before), f)
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


for line in sys.stdin:
    req = json.loads(line)
    reply = {}
    if req["op"] == "import":
        for name in req["names"]:
            try:
                importlib.import_module(name)
            except Exception:
                pass
    elif req["op"] == "run":
        pid = os.fork()
        if pid == 0:
            child(req)
        reply = {"pid": pid}
    else:  # "poll": the exit code of an ended child (reaped), or None
        pid, status = os.waitpid(req["pid"], os.WNOHANG)
        reply = {"code": os.waitstatus_to_exitcode(status) if pid else None}
    print(json.dumps(reply), flush=True)
os._exit(0)  # stdin closed: no interpreter teardown of OCP's modules (seconds)
"""


class _Runs:
    """``ght-cad run`` processes forked from one process that has imported what a run imports."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.codes: dict[int, int] = {}
        self.names: dict[int, int] = {}
        self.proc = subprocess.Popen([sys.executable, "-c", ZYGOTE, json.dumps(PRELOAD)], env=_env(),
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def _ask(self, **req: object) -> dict:
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.proc.stdin.write(json.dumps(req) + "\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        assert line, f"the forking process ended (exit {self.proc.wait()})"
        return json.loads(line)

    def warm_up(self, design: Path) -> None:
        """One instrumented run of ``design`` (into a scratch folder); then import every module it loaded."""
        modules = self.folder / "modules.json"
        pid = self.start(design, self.folder / "warm-up", modules=modules)
        assert self.wait(pid) == 0, self.output(pid)[1]
        self._ask(op="import", names=json.loads(modules.read_text()))

    def start(self, design: Path, out: Path, *extra: str, modules: Path | None = None) -> int:
        """Start ``ght-cad run design --out out --no-progress *extra``; its pid."""
        n = len(self.names)
        paths = {k: str(self.folder / f"{n}.{k}") for k in ("stdout", "stderr")}
        argv = ["run", str(design), "--out", str(out), "--no-progress", *extra]
        pid = self._ask(op="run", argv=argv, modules=str(modules) if modules else None, **paths)["pid"]
        self.names[pid] = n
        return pid

    def poll(self, pid: int) -> int | None:
        """The exit code of run ``pid`` (-9 for SIGKILL) once it has ended (then reaped), else None."""
        if pid not in self.codes:
            code = self._ask(op="poll", pid=pid)["code"]
            if code is not None:
                self.codes[pid] = code
        return self.codes.get(pid)

    def wait(self, pid: int, limit: float = 300.0) -> int:
        t0 = time.monotonic()
        while (code := self.poll(pid)) is None:
            assert time.monotonic() - t0 < limit, f"run {pid} still running after {limit} s"
            time.sleep(0.01)
        return code

    def output(self, pid: int) -> tuple[str, str]:
        """(stdout, stderr) of run ``pid``."""
        return tuple((self.folder / f"{self.names[pid]}.{k}").read_text() for k in ("stdout", "stderr"))

    def run(self, design: Path, out: Path, *extra: str) -> tuple[int, str, str]:
        """A whole run: (exit code, stdout, stderr)."""
        pid = self.start(design, out, *extra)
        return (self.wait(pid), *self.output(pid))

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


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


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[_Runs]:
    """The forking process of this module, warmed up by one instrumented run of a design with every
    figure these tests ask for."""
    folder = tmp_path_factory.mktemp("runs")
    forks = _Runs(folder)
    try:
        forks.warm_up(_design(folder, "warm-up", ["basis", "surface", "flat_pattern"]))
        yield forks
    finally:
        forks.close()


def test_sigkill_at_ten_moments_then_one_run_equals_a_clean_run(tmp_path: Path, runs: _Runs) -> None:
    design_a = _design(tmp_path, "fault-a", ["basis", "surface", "flat_pattern"])
    design_b = _design(tmp_path, "fault-b", ["flat_pattern"])
    ref = tmp_path / "ref" / "out"
    t0 = time.monotonic()
    code, _, err = runs.run(design_b, ref)
    duration = time.monotonic() - t0
    assert code == 0, err

    work = tmp_path / "work"
    out = work / "out"
    assert runs.run(design_a, out)[0] == 0  # the folder holds design A ...
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
        pid = runs.start(design_b, out)
        moment = start + (k + 0.5) / 10 * duration
        while runs.poll(pid) is None and time.monotonic() < moment:
            time.sleep(0.005)
        if runs.poll(pid) is None:
            os.kill(pid, signal.SIGKILL)
            killed += 1
        else:
            # it ended before its moment: the machine got faster than when the reference run was
            # timed (another test's load ended); later moments spread over this run's duration
            duration = min(duration, time.monotonic() - start)
        runs.wait(pid)  # reaped: its pid is gone, as after a real crash
        # the folder is always one whole design: A's (not yet replaced) or B's (committed)
        names = json.loads((out / "report.json").read_text())["name"]
        assert names in ("fault-a", "fault-b")
    assert killed >= 7, f"only {killed} of 10 runs were still running when killed (run takes {duration:.1f} s)"
    code, _, err = runs.run(design_b, out)
    assert code == 0, err
    assert _leftovers(work) == [], _leftovers(work)
    assert _listing(work) == ["out"]
    # design A then design B: exactly B's files (A's basis.png and surface.png gone) + the person's
    _assert_same_result(out, ref, person)


def _wait_for(path: Path, runs: _Runs, pid: int, limit: float = 120.0) -> None:
    t0 = time.monotonic()
    while not path.exists():
        assert runs.poll(pid) is None, "the first run ended before it took the folder's lock"
        assert time.monotonic() - t0 < limit, f"{path} did not appear"
        time.sleep(0.005)


def test_two_runs_on_one_folder_refused_or_waiting_never_mixed(tmp_path: Path, runs: _Runs) -> None:
    design_a = _design(tmp_path, "fault-a", ["basis", "surface", "flat_pattern"])
    design_b = _design(tmp_path, "fault-b", ["flat_pattern"])
    out = tmp_path / "out"
    lock = tmp_path / ".out.ght-cad-lock"
    first = runs.start(design_a, out)
    try:
        _wait_for(lock, runs, first)
        # a second run while the first holds the folder: refused at once, naming folder and pid
        code, _, err = runs.run(design_b, out)
        assert code == 2, err
        lines = err.strip().splitlines()
        assert len(lines) == 1 and str(out) in lines[0] and f"pid {first}" in lines[0] and "--wait" in lines[0], lines
        # --wait-timeout shorter than the first run: exit 2 after that time
        t0 = time.monotonic()
        code, _, err = runs.run(design_b, out, "--wait-timeout", "0.5")
        assert code == 2 and "after waiting 0.5 s" in err, err
        assert time.monotonic() - t0 >= 0.5
        # --wait: starts when the first run has finished and leaves its own design alone
        code3, out3, err3 = runs.run(design_b, out, "--wait", "--json")
    finally:
        first_code = runs.wait(first)
    assert first_code == 0, runs.output(first)[1]
    assert code3 == 0, err3
    assert f"waiting for pid {first}" in err3 or not lock.exists()
    report = json.loads((out / "report.json").read_text())
    assert report["name"] == "fault-b" and json.loads(out3)["name"] == "fault-b"
    assert _listing(out) == sorted(report["files"]), (_listing(out), report["files"])
    assert _leftovers(tmp_path) == []


def test_concurrent_starts_one_wins_one_is_refused(tmp_path: Path, runs: _Runs) -> None:
    """Both started at the same moment without --wait: exactly one exits 0; the other exits 0
    too only if it started after the first had finished; the folder is one design's, whole."""
    design_a = _design(tmp_path, "fault-a", ["basis", "surface", "flat_pattern"])
    design_b = _design(tmp_path, "fault-b", ["flat_pattern"])
    out = tmp_path / "out"
    pids = [runs.start(d, out) for d in (design_a, design_b)]
    codes = [runs.wait(pid) for pid in pids]
    errs = [runs.output(pid)[1] for pid in pids]
    assert sorted(codes) in ([0, 2], [0, 0]), (codes, errs)
    for code, err in zip(codes, errs):
        if code == 2:
            assert "is in use by another ght-cad process (pid" in err, err
    report = json.loads((out / "report.json").read_text())
    assert _listing(out) == sorted(report["files"])  # one design's files, nothing of the other
    assert _leftovers(tmp_path) == []
