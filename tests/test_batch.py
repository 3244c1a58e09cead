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

import json
import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from ght_cad.batch import run_batch
from ght_cad.cli import main

pytestmark = pytest.mark.timeout(300)

FILES = ["flat_pattern.dxf", "flat_pattern.png", "flat_pattern.svg", "model.step", "report.json", "report.md"]

# (h, k, z1): 12 frustums
CONES = [(800.0, 0.5, 400.0), (800.0, 0.25, 400.0), (600.0, 0.5, 300.0), (1000.0, 0.4, 250.0),
         (500.0, 1.0, 100.0), (900.0, 0.3, 600.0), (700.0, 0.6, 350.0), (1200.0, 0.2, 200.0),
         (400.0, 0.75, 150.0), (650.0, 0.45, 500.0), (850.0, 0.35, 425.0), (300.0, 1.5, 120.0)]


def cone_design(name: str, h: float, k: float, z1: float) -> str:
    return f"""name = "{name}"
units = "mm"

[surface]
type = "planes"
planes = [[{-k * h!r}, 1, 0, {k!r}], [{-k * h!r}, 1, 1, {k!r}], [{-k * h!r}, 0, 1, {k!r}]]
boundary_planes = [[0, 0, 0, 1], [{-z1!r}, 0, 0, 1]]
mu = 0.0
nu = 0.0
gamma = -1.0
normalize = false

[unroll]
rulings = 8
tol_deg = 0.001

[outputs]
files = ["step", "dxf", "svg", "json", "md"]
figures = ["flat_pattern"]
"""


def cone_area(h: float, k: float, z1: float) -> float:
    return math.pi / 4 * k * math.sqrt(1 + k * k) * (h * h - (h - z1) ** 2)


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


def test_batch_local_worker_killed(designs, tmp_path):
    """SIGKILL one worker process mid-run: the designs it was running are run again, all complete."""
    paths, areas = designs
    good = [p for p in paths if p.stem != "broken"][:4]
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "ght_cad.cli", "batch", *map(str, good), "--out", str(out),
                             "--jobs", "2", "--no-progress"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.monotonic()
    kids: list[int] = []
    while time.monotonic() - t0 < 60 and len(kids) < 2:
        kids = _children(proc.pid)
        time.sleep(0.05)
    assert len(kids) >= 2, "the batch never started its worker processes"
    time.sleep(1.0)  # the workers are importing / running their first design
    os.kill(kids[0], signal.SIGKILL)
    stdout, stderr = proc.communicate(timeout=240)
    assert proc.returncode == 0, stderr
    summary = check_batch(out, {p.stem: areas[p.stem] for p in good}, expect_broken=False)
    assert max(r["attempts"] for r in summary["rows"]) == 2  # the killed one was retried


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
                             "--no-nanny", "--no-dashboard"], stdout=subprocess.DEVNULL,
                            stderr=open(log, "w"))


@pytest.fixture
def dask_cluster(tmp_path):
    pytest.importorskip("distributed")
    from distributed import Client

    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = [subprocess.Popen([_dask_bin(), "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=open(tmp_path / "scheduler.log", "w"))]
    try:
        procs += [_start_worker(address, tmp_path / f"worker{i}.log") for i in range(2)]
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(2, timeout=90)
        yield address, procs
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


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


def test_unroll_step_on_dask_identical_to_serial(dask_cluster, tmp_path):
    import importlib.util

    from ght_cad.design import unroll_step

    address, _ = dask_cluster
    spec = importlib.util.spec_from_file_location("bench_batch", Path(__file__).parents[1] / "bench" / "bench_batch.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    step = tmp_path / "few.step"
    bench.many_faces_step(step, 24)
    serial = unroll_step(step)
    remote = unroll_step(step, scheduler=address)
    assert remote.faces == serial.faces
    for a, b in zip(serial.pattern.panels, remote.pattern.panels):
        assert a.label == b.label and a.offset.tobytes() == b.offset.tobytes()
        assert [e.flat.tobytes() for lp in a.loops for e in lp] == [e.flat.tobytes() for lp in b.loops for e in lp]
        assert [m.tobytes() for m in a.marks] == [m.tobytes() for m in b.marks] and a.texts == b.texts


def test_batch_dask_worker_killed(designs, dask_cluster, tmp_path):
    """SIGKILL one of the two Dask workers mid-run: the scheduler reruns its task, all complete."""
    paths, areas = designs
    address, procs = dask_cluster
    good = [p for p in paths if p.stem != "broken"][:4]
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "ght_cad.cli", "batch", *map(str, good), "--out", str(out),
                             "--scheduler", address, "--no-progress"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    from distributed import Client

    with Client(address, timeout="30s") as client:
        t0 = time.monotonic()
        while time.monotonic() - t0 < 60:
            proc_info = client.processing()
            if sum(len(v) for v in proc_info.values()) >= 2:
                break
            time.sleep(0.1)
    time.sleep(1.0)
    procs[1].kill()
    stdout, stderr = proc.communicate(timeout=240)
    assert proc.returncode == 0, stderr
    summary = check_batch(out, {p.stem: areas[p.stem] for p in good}, expect_broken=False)
    assert len({r["worker"] for r in summary["rows"]}) >= 1


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


def test_sweep_expansion_grid_zip_and_errors():
    from ght_cad.sweep import SweepError, expand_sweep

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
