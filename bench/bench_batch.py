"""Volume work: ``ght-cad batch`` speed-up, STEP unrolling with many faces, sweeps; growth with count.

1. ``--jobs 2`` against ``--jobs 1`` on the same 16 designs (quarter cone frustums, full pipeline
   of ``ght-cad run`` with STEP, DXF, SVG, JSON, Markdown and the flat-pattern PNG), same run.
   This process first imports what a run needs and runs one design (``run_batch`` forks its
   workers from it, so they start warm: the several seconds of OCP/matplotlib imports are
   not part of either time); then 1, 2, 1, 2 alternately, the best of each. Prints both wall
   times, the ratio (>= 1.6 expected on 2 idle cores), the load average before and after, and
   the workers' CPU time / wall time per design (about 1 when each worker had a core).
2. ``unroll_step`` of STEP files with n = 250, 500, 1,000 developable faces (partial cylinders,
   cones, ruled B-spline strips and whole cylinders whose faces share edges), serial and with
   ``jobs=2``: wall time, peak memory (each case in its own process: peak resident set of that
   process and of its largest worker, and the growth over the resident set after imports),
   time per face and the growth exponents fitted by least squares to ``log t`` and
   ``log (peak - base)`` against ``log n`` (1 = linear). The STEP files are written once, before.
3. A sweep of n = 25, 50, 100 variants (one ``[sweep]`` list) through ``run_batch(jobs=2)``
   (modules preloaded before the clock starts): wall time, peak memory, growth exponents.

Run: ``.venv/bin/python bench/bench_batch.py`` (about 5 to 10 minutes on 2 idle cores),
``--quick`` (smaller counts, about 2 minutes), ``--only jobs|faces|sweep``.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))

from cone_designs import cone_design  # noqa: E402  (shared with tests/test_batch.py)


def many_faces_step(path: str | os.PathLike, n_faces: int) -> int:
    """Write a STEP file with at least ``n_faces`` developable faces; returns the face count.

    Per index i on a grid (spacing 100 mm): i % 4 == 0 a partial cylinder's lateral face,
    1 a partial cone's, 2 a ruled B-spline strip (degree 3 x 1, 4 x 2 poles), 3 a whole cylinder
    solid (lateral face and two caps sharing its circles).
    """
    import build123d as bd
    import numpy as np

    from ght_cad.surfaces.bspline import BSplineSurfaceData
    from ght_cad.cad.occ import make_face, write_step

    shapes: list[Any] = []
    count = 0
    i = 0
    while count < n_faces:
        x, y = 100.0 * (i % 20), 100.0 * (i // 20)
        kind = i % 4
        r = 10.0 + (i % 7)
        plane = bd.Plane.XY.offset(0).move(bd.Location((x, y, 0)))
        if kind == 0:
            s = bd.Solid.make_cylinder(r, 20.0 + i % 5, plane, angle=90 + (i % 5) * 30)
            shapes.append(next(f for f in s.faces() if f.geom_type == bd.GeomType.CYLINDER))
            count += 1
        elif kind == 1:
            s = bd.Solid.make_cone(r, 0.5 * r, 25.0, plane, angle=120 + (i % 4) * 40)
            shapes.append(next(f for f in s.faces() if f.geom_type == bd.GeomType.CONE))
            count += 1
        elif kind == 2:
            a = np.array([[x, y, 0], [x + 10, y + 5 + i % 3, 0], [x + 20, y - 5, 2], [x + 30, y, 0]], float)
            b = a + np.array([0.0, 3.0, 25.0])
            shapes.append(make_face(BSplineSurfaceData(np.stack([a, b], axis=1), [0] * 4 + [1] * 4, [0, 0, 1, 1], 3, 1)))
            count += 1
        else:
            s = bd.Solid.make_cylinder(0.5 * r, 15.0, plane)
            shapes.append(s)
            count += len(s.faces())
        i += 1
    write_step(bd.Compound(shapes), path)
    return count


def _status_mb(key: str) -> float | None:
    """``/proc/self/status`` entry ``key`` (VmRSS, VmHWM) in MB; None where there is none."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return None


def _start_peak() -> float:
    """Reset this process's peak resident set (Linux: ``5`` into ``/proc/self/clear_refs``), so the
    peak measured afterwards is that of the timed work, not of the imports; returns the current RSS, MB."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass
    return _status_mb("VmRSS") or 0.0


def _cpu_s() -> float:
    """CPU time (user + system) of this process and its finished children, s: less sensitive than wall
    time to other work on a shared machine."""
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _peaks_mb() -> tuple[float, float]:
    """Peak resident set of this process since :func:`_start_peak` (else since start) and of its
    largest finished child (forked after it), MB."""
    me = _status_mb("VmHWM") or resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024.0
    return me, kids


def case_faces(step: str, jobs: int) -> dict[str, Any]:
    """One measurement in this process: unroll_step of a STEP file (imports done before the clock)."""
    import ght_cad.app.batch  # noqa: F401 - the modules the workers fork with
    from ght_cad.app.design import unroll_step

    unroll_step(Path(step), faces=[1])  # loads OCP, scipy and the unroll code
    base = _start_peak()
    t0, c0 = time.perf_counter(), _cpu_s()
    res = unroll_step(Path(step), jobs=jobs)
    dt, cpu = time.perf_counter() - t0, _cpu_s() - c0
    me, kids = _peaks_mb()
    return {"faces": res.face_count, "panels": len(res.pattern.panels), "time": dt, "cpu": cpu, "peak_mb": me,
            "worker_peak_mb": kids, "base_mb": base,
            "marks": sum(1 for p in res.pattern.panels for t in p.texts if t[2].startswith("E"))}


def case_sweep(n: int, jobs: int) -> dict[str, Any]:
    """One measurement in this process: a sweep of n variants through run_batch (modules preloaded)."""
    from ght_cad.app.batch import preload_run_modules, run_batch

    preload_run_modules()
    base = _start_peak()
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "sweep.toml"
        p.write_text(cone_design("sweep", 800.0, 0.5, 400.0, figures="[]")
                     + f'\n[sweep]\n"surface.boundary_planes.1.0" = {{ start = -100, stop = -500, num = {n} }}\n')
        t0, c0 = time.perf_counter(), _cpu_s()
        res = run_batch([p], Path(tmp) / "out", jobs=jobs, progress=False)
        dt, cpu = time.perf_counter() - t0, _cpu_s() - c0
        assert res.exit_code == 0, res.rows
    me, kids = _peaks_mb()
    return {"designs": n, "time": dt, "cpu": cpu, "peak_mb": me, "worker_peak_mb": kids, "base_mb": base}


def _in_subprocess(*case: Any) -> dict[str, Any]:
    out = subprocess.run([sys.executable, __file__, "--case", *map(str, case)], capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def growth_exponent(n: list[float], y: list[float]) -> float:
    """Least-squares slope of ``log y`` against ``log n`` (1 = linear growth)."""
    import numpy as np

    x, v = np.log(np.asarray(n, float)), np.log(np.maximum(np.asarray(y, float), 1e-12))
    return float(np.polyfit(x, v, 1)[0])


def _growth_text(rows: list[dict[str, Any]], key: str) -> str:
    n = [r[key] for r in rows]
    t = growth_exponent(n, [r["time"] for r in rows])
    c = growth_exponent(n, [r["cpu"] for r in rows])
    m = growth_exponent(n, [max(r["peak_mb"], r["worker_peak_mb"]) - r["base_mb"] for r in rows])
    return (f"growth exponents (1 = linear): wall time {t:.2f}, CPU time {c:.2f}, "
            f"peak memory above the base {m:.2f}")


def _load() -> str:
    return "/".join(f"{x:.1f}" for x in os.getloadavg())


def bench_jobs(n_designs: int) -> float:
    """Best-of-two wall times of run_batch with jobs 1 and 2 on the same designs; returns the ratio."""
    from ght_cad.app.batch import preload_run_modules, run_batch

    load0 = _load()
    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for i in range(n_designs):
            p = Path(tmp) / f"d{i}.toml"
            p.write_text(cone_design(f"d{i:02d}", 600.0 + 40 * i, 0.3 + 0.05 * (i % 6), 200.0 + 10 * i))
            paths.append(p)
        pre = preload_run_modules()
        run_batch(paths[:1], Path(tmp) / "warm", jobs=1, progress=False)  # first-use costs (fonts, caches)
        times: dict[int, list[float]] = {1: [], 2: []}
        util: dict[int, list[float]] = {1: [], 2: []}
        for rep, jobs in enumerate((1, 2, 1, 2)):
            t0 = time.perf_counter()
            res = run_batch(paths, Path(tmp) / f"out{rep}", jobs=jobs, progress=False)
            times[jobs].append(time.perf_counter() - t0)
            assert res.exit_code == 0, res.rows
            util[jobs].append(sum(r["cpu_s"] for r in res.rows) / sum(r["elapsed_s"] for r in res.rows))
    t1, t2 = min(times[1]), min(times[2])
    print(f"1. batch of {n_designs} designs (imports preloaded in {pre:.1f} s, workers forked warm): "
          f"--jobs 1 {t1:.2f} s, --jobs 2 {t2:.2f} s (best of 2 each), speed-up {t1 / t2:.2f}x "
          f"(>= 1.6 expected on 2 idle cores; cores here: {os.cpu_count()}); worker CPU/wall per design "
          f"jobs 1 {max(util[1]):.2f}, jobs 2 {max(util[2]):.2f} (1 = a core each); load average "
          f"(1/5/15 min) before {load0}, after {_load()}", flush=True)
    return t1 / t2


def bench_faces(counts: tuple[int, ...]) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        steps = {}
        for n in counts:
            steps[n] = Path(tmp) / f"faces{n}.step"
            many_faces_step(steps[n], n)
        for jobs in (1, 2):
            rows = [_in_subprocess("faces", steps[n], jobs) for n in counts]
            for r in rows:
                print(f"2. unroll_step jobs={jobs}: {r['faces']:5d} faces {r['time']:7.2f} s "
                      f"({1e3 * r['time'] / r['faces']:.1f} ms/face; CPU {r['cpu']:.2f} s), {r['marks']} edge marks, peak memory "
                      f"{r['peak_mb']:.0f} MB (worker {r['worker_peak_mb']:.0f} MB; base after imports "
                      f"{r['base_mb']:.0f} MB)", flush=True)
            print(f"   {_growth_text(rows, 'faces')}; load average {_load()}", flush=True)


def bench_sweep(counts: tuple[int, ...]) -> None:
    rows = [_in_subprocess("sweep", n, 2) for n in counts]
    for r in rows:
        print(f"3. sweep jobs=2: {r['designs']:4d} variants {r['time']:7.2f} s "
              f"({r['time'] / r['designs']:.2f} s/variant; CPU {r['cpu']:.2f} s), peak memory {r['peak_mb']:.0f} MB "
              f"(worker {r['worker_peak_mb']:.0f} MB; base after imports {r['base_mb']:.0f} MB)", flush=True)
    print(f"   {_growth_text(rows, 'designs')}; load average {_load()}", flush=True)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller counts (a smoke run)")
    ap.add_argument("--only", choices=("jobs", "faces", "sweep"), help="run one part")
    ap.add_argument("--case", nargs=3, metavar=("KIND", "ARG", "JOBS"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.case:
        kind, arg, jobs = args.case[0], args.case[1], int(args.case[2])
        print(json.dumps(case_faces(arg, jobs) if kind == "faces" else case_sweep(int(arg), jobs)))
        return 0
    t0 = time.perf_counter()
    print(f"bench_batch: {os.cpu_count()} cores, load average {_load()}", flush=True)
    if args.only in (None, "jobs"):
        bench_jobs(6 if args.quick else 16)
    if args.only in (None, "faces"):
        bench_faces((50, 100, 200) if args.quick else (250, 500, 1000))
    if args.only in (None, "sweep"):
        bench_sweep((10, 20, 40) if args.quick else (25, 50, 100))
    print(f"total {time.perf_counter() - t0:.0f} s", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
