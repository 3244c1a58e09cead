"""``ght-cad batch``: 12 designs + 1 broken in local processes and on a real Dask cluster
(scheduler and two workers on 127.0.0.1), killed workers, and ``[sweep]`` variants.

The designs are quarter cone frustums (spec section 1, exact circles: planes
``(-k h, 1, 0, k), (-k h, 1, 1, k), (-k h, 0, 1, k)`` with gamma = -1 and the boundary planes
z = 0, z = z1): apex at height h, radius ``k (h - z)``, slant distance ``rho(z) = (h - z) sqrt(1 + k^2)``.
The flat pattern is an annular sector of area

    A = (pi / 4) k sqrt(1 + k^2) (h^2 - (h - z1)^2),

which every folder's report.json must match to 1e-9 (relative).
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cone_designs import cone_area, cone_design

from ght_cad.app.batch import run_batch
from ght_cad.app.cli import main

pytestmark = [pytest.mark.timeout(300), pytest.mark.slow]  # process pools and dask clusters

FILES = ["flat_pattern.dxf", "flat_pattern.png", "flat_pattern.svg", "model.step", "report.json", "report.md"]

# (h, k, z1): 12 frustums
CONES = [(800.0, 0.5, 400.0), (800.0, 0.25, 400.0), (600.0, 0.5, 300.0), (1000.0, 0.4, 250.0),
         (500.0, 1.0, 100.0), (900.0, 0.3, 600.0), (700.0, 0.6, 350.0), (1200.0, 0.2, 200.0),
         (400.0, 0.75, 150.0), (650.0, 0.45, 500.0), (850.0, 0.35, 425.0), (300.0, 1.5, 120.0)]


@pytest.fixture(scope="module")
def designs(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[Path], dict[str, float]]:
    d = tmp_path_factory.mktemp("designs")
    paths, areas = [], {}
    for i, (h, k, z1) in enumerate(CONES, start=1):
        name = f"cone-{i:02d}"
        p = d / f"{name}.toml"
        p.write_text(cone_design(name, h, k, z1))
        paths.append(p)
        areas[name] = cone_area(h, k, z1)
    broken = d / "broken.toml"
    broken.write_text('name = "broken"\n[surface]\ntype = "planes"\nplanes = [[1, 0, 0]]\n')
    paths.insert(5, broken)
    return paths, areas


def check_batch(out: Path, areas: dict[str, float], *, expect_broken: bool = True) -> dict:
    summary = json.loads((out / "batch.json").read_text())
    rows = {r["name"]: r for r in summary["rows"]}
    assert summary["designs"] == len(areas) + expect_broken
    for name, area in areas.items():
        r = rows[name]
        assert r["status"] == "ok", r
        folder = out / name
        assert sorted(p.name for p in folder.iterdir()) == FILES
        rep = json.loads((folder / "report.json").read_text())
        assert rep["out_dir"] == str(folder)
        assert abs(rep["flat_pattern"]["area"] - area) <= 1e-9 * area
        assert abs(r["area"] - area) <= 1e-9 * area
        assert r["theta_max"] <= 1e-9 and r["pattern_error"] <= 1e-9
        assert r["host"] and r["pid"] > 0 and r["elapsed_s"] > 0
    if expect_broken:
        b = rows["broken"]
        assert b["status"] == "bad input" and "planes" in b["error"] and b["folder"] is None
        assert not (out / "broken").exists()
    # nothing half-written: no staging folders are left in DIR
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]
    md = (out / "batch.md").read_text()
    assert all(name in md for name in rows)
    return summary


def test_batch_local_processes(designs, tmp_path, capsys):
    paths, areas = designs
    out = tmp_path / "out"
    code = main(["batch", *map(str, paths), "--out", str(out), "--jobs", "2", "--no-progress"])
    assert code == 2  # one bad design
    err = capsys.readouterr().err
    assert "broken" in err and len([ln for ln in err.splitlines() if ln.strip()]) == 1
    summary = check_batch(out, areas)
    assert summary["executor"] == "local processes (2 jobs)"
    assert len({r["pid"] for r in summary["rows"] if r["pid"]}) == 2  # both processes worked
    assert summary["exit_code"] == 2 and summary["succeeded"] == 12 and summary["bad_input"] == 1


def test_batch_all_ok_exit_0_and_json(designs, tmp_path, capsys):
    paths, areas = designs
    good = [p for p in paths if p.stem != "broken"][:2]
    code = main(["batch", *map(str, good), "--out", str(tmp_path / "o"), "--jobs", "1", "--json"])
    assert code == 0
    res = json.loads(capsys.readouterr().out)
    assert res["ok"] is True and res["designs"] == 2 and {r["status"] for r in res["rows"]} == {"ok"}


def test_batch_usage_errors(tmp_path, capsys):
    assert main(["batch", "x.toml", "--out", str(tmp_path), "--jobs", "0"]) == 2
    assert "--jobs 0" in capsys.readouterr().err
    assert main(["batch", "x.toml", "--out", str(tmp_path), "--jobs", "2", "--scheduler", "tcp://127.0.0.1:1"]) == 2
    f = tmp_path / "file"
    f.write_text("")
    assert main(["batch", "x.toml", "--out", str(f)]) == 2
    assert "not a folder" in capsys.readouterr().err


def test_batch_duplicate_names_and_missing_file(designs, tmp_path):
    paths, areas = designs
    p = paths[0]
    res = run_batch([p, p, tmp_path / "nope.toml"], tmp_path / "o", jobs=1, progress=False)
    st = [r["status"] for r in res.rows]
    assert st == ["ok", "bad input", "bad input"] and res.exit_code == 2
    assert "already used" in res.rows[1]["error"] and "no such design file" in res.rows[2]["error"]


def _children(pid: int) -> list[int]:
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return []
    return [int(x) for x in text.split()]


def _running_marker(tmpdir: Path, timeout: float = 90.0) -> tuple[int, int]:
    """Wait until a local worker runs a design: (its index in the batch, the worker's pid), read
    from the batch's marker files (``ght-cad-batch-markers.*`` in the batch's TMPDIR)."""
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout:
        for d in tmpdir.glob("ght-cad-batch-markers.*"):
            for m in d.iterdir():
                try:
                    return int(m.name), int(m.read_text())
                except (OSError, ValueError):  # being written
                    pass
        time.sleep(0.02)
    raise AssertionError("no design started within the timeout")


def test_batch_local_worker_killed(designs, tmp_path):
    """SIGKILL the worker process while it runs a design: that design is run again (attempts 2),
    all complete and exact, nothing half-written in DIR."""
    paths, areas = designs
    good = [p for p in paths if p.stem != "broken"][:4]
    out = tmp_path / "out"
    tmpdir = tmp_path / "tmp"
    tmpdir.mkdir()
    proc = subprocess.Popen([sys.executable, "-m", "ght_cad.app.cli", "batch", *map(str, good), "--out", str(out),
                             "--jobs", "2", "--no-progress"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, "TMPDIR": str(tmpdir)})
    index, pid = _running_marker(tmpdir)
    assert pid in _children(proc.pid)
    os.kill(pid, signal.SIGKILL)
    stdout, stderr = proc.communicate(timeout=240)
    assert proc.returncode == 0, stderr
    summary = check_batch(out, {p.stem: areas[p.stem] for p in good}, expect_broken=False)
    killed = summary["rows"][index]
    assert killed["attempts"] == 2 and killed["pid"] != pid  # run again, in another process
    assert all(r["attempts"] in (1, 2) for r in summary["rows"])
    assert not list(tmpdir.glob("ght-cad-batch*"))  # markers and workers' folders (the killed one's too) removed


from ght_cad.app.batch import run_task  # noqa: E402 - the real one (the test below patches the module's)


def crash_on_cone_03(task):
    """run_task, except that the worker process running cone-03 kills itself (SIGKILL) mid-design."""
    if task["folder"] == "cone-03":
        Path(task["marker"]).write_text(str(os.getpid()))
        os.kill(os.getpid(), signal.SIGKILL)
    return run_task(task)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forked workers inherit the patched task")
def test_batch_local_design_that_always_kills_its_worker(designs, tmp_path, monkeypatch):
    """A design whose worker dies every time: reported failed after MAX_ATTEMPTS deaths, the design
    running beside it (terminated by the pool) is run again without counting, all others exact."""
    import ght_cad.app.batch as gb

    paths, areas = designs
    good = [p for p in paths if p.stem != "broken"][:5]
    monkeypatch.setattr(gb, "run_task", crash_on_cone_03)
    out = tmp_path / "out"
    res = run_batch(good, out, jobs=2, progress=False)
    rows = {r["name"]: r for r in res.rows}
    bad = rows.pop("cone-03")
    assert bad["status"] == "failed" and bad["attempts"] == gb.MAX_ATTEMPTS and bad["folder"] is None
    assert f"died {gb.MAX_ATTEMPTS} times" in bad["error"]
    assert not (out / "cone-03").exists()
    assert res.exit_code == 1
    assert all(r["status"] == "ok" for r in rows.values())
    summary = json.loads((out / "batch.json").read_text())
    assert summary["failed"] == 1 and summary["succeeded"] == 4
    for name in rows:
        folder = out / name
        assert sorted(p.name for p in folder.iterdir()) == FILES
        rep = json.loads((folder / "report.json").read_text())
        assert abs(rep["flat_pattern"]["area"] - areas[name]) <= 1e-9 * areas[name]
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]


# ---------------------------------------------------------------------------------------------
# Dask: a real scheduler and two workers on 127.0.0.1
# ---------------------------------------------------------------------------------------------
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _dask_bin() -> str:
    return str(Path(sys.executable).with_name("dask"))


def _start_worker(address: str, log: Path) -> subprocess.Popen:
    return subprocess.Popen([_dask_bin(), "worker", address, "--host", "127.0.0.1", "--nthreads", "1",
                             "--no-nanny", "--no-dashboard", "--local-directory", str(log.parent / "dask")],
                            stdout=subprocess.DEVNULL, stderr=open(log, "w"))


@contextlib.contextmanager
def start_cluster(tmp_path: Path, env: dict[str, str] | None = None):
    """A scheduler and two 1-thread workers (no nanny, scratch space in ``tmp_path``) on 127.0.0.1:
    yields (address, processes). Afterwards the workers are killed (SIGKILL: a worker that has
    imported ght_cad and OCP takes seconds to finish on SIGTERM, 6-20 s on a loaded machine) and
    the scheduler is terminated."""
    pytest.importorskip("distributed")
    from distributed import Client

    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    penv = {**os.environ, **(env or {})}
    procs = [subprocess.Popen([_dask_bin(), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=open(tmp_path / "scheduler.log", "w"),
                              env=penv)]
    try:
        procs += [_start_worker(address, tmp_path / f"worker{i}.log") for i in range(2)]
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(2, timeout=90)
        yield address, procs
    finally:
        for p in reversed(procs):  # the workers, then the scheduler (procs[0])
            if p.poll() is None:
                if p is procs[0]:
                    p.terminate()
                else:
                    p.kill()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.fixture
def dask_cluster(tmp_path):
    with start_cluster(tmp_path) as c:
        yield c


def test_batch_dask_cluster(designs, dask_cluster, tmp_path, capsys):
    paths, areas = designs
    address, _ = dask_cluster
    out = tmp_path / "out"
    code = main(["batch", *map(str, paths), "--out", str(out), "--scheduler", address, "--no-progress"])
    assert code == 2
    summary = check_batch(out, areas)
    assert summary["executor"] == f"dask {address}"
    workers = {r["worker"] for r in summary["rows"] if r["status"] == "ok"}
    assert len(workers) == 2 and all(w.startswith("tcp://127.0.0.1:") for w in workers)
    # the same files as local processes write (the flat pattern is deterministic)
    local = tmp_path / "local"
    run_batch([paths[0]], local, jobs=1, progress=False)
    assert (local / "cone-01" / "flat_pattern.svg").read_bytes() == (out / "cone-01" / "flat_pattern.svg").read_bytes()


def _kill_running_worker(client, victim: str, worker_proc: subprocess.Popen) -> set[str]:
    """Wait until ``victim`` runs a task, let it run 0.5 s, SIGKILL the worker; returns the design
    folders of the tasks it held at that moment."""
    t0 = time.monotonic()
    keys: list[str] = []
    while time.monotonic() - t0 < 90 and not keys:
        keys = [str(k) for k in client.processing(workers=[victim]).get(victim, ())]
        time.sleep(0.05)
    assert keys, "no task reached the worker"
    time.sleep(0.5)
    keys = [str(k) for k in client.processing(workers=[victim]).get(victim, ())] or keys
    worker_proc.kill()
    return {k.split("ght-cad-batch-", 1)[1].rsplit("-", 2)[0] for k in keys}


def test_batch_dask_worker_killed(designs, dask_cluster, tmp_path):
    """SIGKILL one of the two Dask workers while it runs a design: the scheduler reruns that task
    on the other worker, all complete and exact, nothing half-written."""
    from distributed import Client

    paths, areas = designs
    address, procs = dask_cluster
    good = [p for p in paths if p.stem != "broken"][:4]
    out = tmp_path / "out"
    with Client(address, timeout="30s") as client:
        victim = next(a for a, pid in client.run(os.getpid).items() if pid == procs[1].pid)
        proc = subprocess.Popen([sys.executable, "-m", "ght_cad.app.cli", "batch", *map(str, good), "--out", str(out),
                                 "--scheduler", address, "--no-progress"], stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
        held = _kill_running_worker(client, victim, procs[1])
    stdout, stderr = proc.communicate(timeout=240)
    assert proc.returncode == 0, stderr
    summary = check_batch(out, {p.stem: areas[p.stem] for p in good}, expect_broken=False)
    rows = {r["name"]: r for r in summary["rows"]}
    assert held and any(rows[n]["worker"] != victim for n in held)  # run again on the other worker


def test_batch_dask_worker_killed_no_retry(designs, tmp_path):
    """A scheduler allowing no failures (allowed-failures 0): SIGKILL the worker running a design,
    that design is reported failed (KilledWorker) in batch.json, the others complete and are exact,
    no folder or staging is left for it."""
    from distributed import Client

    paths, areas = designs
    good = [p for p in paths if p.stem != "broken"][:4]
    out = tmp_path / "out"
    with start_cluster(tmp_path, {"DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES": "0"}) as (address, procs):
        with Client(address, timeout="30s") as client:
            victim = next(a for a, pid in client.run(os.getpid).items() if pid == procs[1].pid)
            proc = subprocess.Popen([sys.executable, "-m", "ght_cad.app.cli", "batch", *map(str, good), "--out", str(out),
                                     "--scheduler", address, "--no-progress"], stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True)
            seen = _kill_running_worker(client, victim, procs[1])
            stdout, stderr = proc.communicate(timeout=240)
    assert proc.returncode == 1, stderr
    summary = json.loads((out / "batch.json").read_text())
    rows = {r["name"]: r for r in summary["rows"]}
    failed = [n for n, r in rows.items() if r["status"] == "failed"]
    assert failed and set(failed) <= seen, (failed, seen)
    for n in failed:
        assert "KilledWorker" in rows[n]["error"] and rows[n]["folder"] is None and not (out / n).exists()
    ok = {n: areas[n] for n, r in rows.items() if r["status"] == "ok"}
    assert len(ok) + len(failed) == 4 and ok
    for n, area in ok.items():
        assert sorted(p.name for p in (out / n).iterdir()) == FILES
        rep = json.loads((out / n / "report.json").read_text())
        assert abs(rep["flat_pattern"]["area"] - area) <= 1e-9 * area
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]


# ---------------------------------------------------------------------------------------------
# sweeps
# ---------------------------------------------------------------------------------------------
def test_batch_sweep(tmp_path):
    h, k = 800.0, 0.5
    text = cone_design("swept", h, k, 400.0) + '\n[sweep]\n"surface.boundary_planes.1.0" = { start = -300, stop = -100, num = 3 }\nplot = ["area", "pattern_error"]\n'
    p = tmp_path / "swept.toml"
    p.write_text(text)
    res = run_batch([p], tmp_path / "out", jobs=2, progress=False)
    assert res.exit_code == 0
    names = [r["name"] for r in res.rows]
    assert names == ["swept-1", "swept-2", "swept-3"]
    for r, z1 in zip(res.rows, (300.0, 200.0, 100.0)):
        assert r["sweep"]["values"] == {"surface.boundary_planes.1.0": -z1}
        assert abs(r["area"] - cone_area(h, k, z1)) <= 1e-9 * cone_area(h, k, z1)
    png = tmp_path / "out" / "sweep-swept.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    md = (tmp_path / "out" / "batch.md").read_text()
    assert "## Sweep of swept" in md and "sweep-swept.png" in md
    # ght-cad run does not silently ignore the sweep: it says where sweeps run
    assert main(["run", str(p), "--out", str(tmp_path / "run")]) == 2
    assert not (tmp_path / "run").exists()


def test_batch_sweep_of_a_plated_two_surface_design(tmp_path):
    """A ``[sweep]`` over the sheet of a plated design with several surfaces (the skiff of
    examples/design_skiff_plated.toml: bottom and a side panel pointed at the bow, one [sheet]),
    run by ``ght-cad batch`` in two processes: the common thickness and the side panel's own
    (``surfaces.1.sheet.thickness``) in a grid; every variant's plates are valid with volumes
    within 1e-6 of their closed form, its pattern exact (errors max <= 1e-12), the swept
    thickness is the one each plate has, and the neutral patterns' areas change with it."""
    base = (Path(__file__).resolve().parents[1] / "examples" / "design_skiff_plated.toml").read_text()
    base = base.replace('figures = ["surface", "flat_pattern"]', "figures = []")
    # the side panel's own sheet (what "surfaces.1.sheet.thickness" sweeps: a key the design has)
    base = base.replace('curve_a = "chine"\ncurve_b = "sheer"\n', 'curve_a = "chine"\ncurve_b = "sheer"\nsheet = { thickness = 6 }\n')
    assert "sheet = { thickness = 6 }" in base
    text = base + '\n[sweep]\n"sheet.thickness" = [4, 6]\n"surfaces.1.sheet.thickness" = [3, 5]\nplot = ["area"]\n'
    p = tmp_path / "skiff_sweep.toml"
    p.write_text(text)
    res = run_batch([p], tmp_path / "out", jobs=2, progress=False)
    assert res.exit_code == 0, [r.get("error") for r in res.rows]
    assert [r["name"] for r in res.rows] == [f"skiff-{i}" for i in range(1, 5)]
    areas = {}
    for r in res.rows:
        assert r["status"] == "ok"
        vals = r["sweep"]["values"]
        rep = json.loads((tmp_path / "out" / r["name"] / "report.json").read_text())
        assert rep["flat_pattern"]["errors"]["max"] <= 1e-12
        plate = rep["plate"]
        assert plate["valid"] and plate["solids"] == 2
        assert abs(plate["volume"] / plate["volume_closed_form"] - 1.0) <= 1e-6
        bottom, side = plate["surfaces"]
        assert (bottom["surface"], side["surface"]) == ("bottom", "side")
        assert bottom["thickness"] == vals["sheet.thickness"]
        assert side["thickness"] == vals["surfaces.1.sheet.thickness"]
        areas[(vals["sheet.thickness"], vals["surfaces.1.sheet.thickness"])] = r["area"]
    assert len(set(areas.values())) == 4  # each thickness pair unrolls its own neutral surfaces
    md = (tmp_path / "out" / "batch.md").read_text()
    assert "## Sweep of skiff" in md and (tmp_path / "out" / "sweep-skiff.png").read_bytes()[:4] == b"\x89PNG"


def test_sweep_expansion_grid_zip_and_errors():
    from ght_cad.app.sweep import SweepError, expand_sweep

    base = {"name": "d", "surface": {"gamma": -1.0, "planes": [[1, 2, 3, 4]]}, "unroll": {"rulings": 12}}
    sw = expand_sweep({**base, "sweep": {"surface.gamma": [-1, 0], "unroll.rulings": {"start": 8, "stop": 16, "step": 4}}})
    assert [v.name for v in sw.variants] == [f"d-{i}" for i in range(1, 7)]
    assert [v.values["unroll.rulings"] for v in sw.variants] == [8, 12, 16, 8, 12, 16]
    assert all(isinstance(v.data["unroll"]["rulings"], int) and "sweep" not in v.data for v in sw.variants)
    assert base["surface"]["gamma"] == -1.0  # the base design is not changed
    sz = expand_sweep({**base, "sweep": {"mode": "zip", "surface.gamma": [-1, 0], "surface.planes.0.3": [4, 5]}})
    assert [v.values for v in sz.variants] == [{"surface.gamma": -1, "surface.planes.0.3": 4},
                                               {"surface.gamma": 0, "surface.planes.0.3": 5}]
    for bad, what in [({"surface.mu": [0]}, "no 'surface.mu'"), ({"surface.planes.2.0": [1]}, "out of range"),
                      ({"surface.gamma": []}, "empty list"), ({"surface.gamma": {"start": 0, "stop": 1}}, "a range is"),
                      ({"surface.gamma": {"start": 0, "stop": 1, "step": -1}}, "step=-1"),
                      ({"mode": "zip", "surface.gamma": [1], "unroll.rulings": [1, 2]}, "one length"),
                      ({"surface.gamma": [0], "plot": ["volume"]}, "plot=['volume']"),
                      ({"name": [1]}, "not a number")]:
        with pytest.raises(SweepError, match=__import__("re").escape(what)):
            expand_sweep({**base, "sweep": bad}, "f.toml")


def test_pattern_error_is_the_largest_relative_error_not_the_angle() -> None:
    """``pattern_error`` is the pattern's relative ``max``; ``angle_deg`` (degrees, the metric
    check's difference residual, e.g. 3e-9 on a sheet's neutral surface) is not a relative error."""
    from ght_cad.app.batch import _figures

    errors = {"boundary_length": 1.2e-16, "ruling_length": 2.5e-16, "area": 1.8e-16, "angle_deg": 3.1e-9, "max": 2.5e-16}
    assert _figures({"flat_pattern": {"errors": errors}})["pattern_error"] == 2.5e-16
    del errors["max"]  # an older report without "max": the largest of the relative ones
    assert _figures({"flat_pattern": {"errors": errors}})["pattern_error"] == 2.5e-16
    assert _figures({})["pattern_error"] is None
