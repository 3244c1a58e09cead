"""Volume work: ``ght-cad batch`` speed-up, STEP unrolling with many faces, sweeps; growth with count.

1. ``--jobs 2`` against ``--jobs 1`` on the same designs (quarter cone frustums, full pipeline of
   ``ght-cad run`` with STEP, DXF, SVG, JSON, Markdown and the flat-pattern PNG), same run:
   prints both wall times and the ratio (>= 1.6 expected on 2 idle cores).
2. ``unroll_step`` of STEP files with n = 250, 500, 1,000 developable faces (partial cylinders,
   cones, ruled B-spline strips and whole cylinders whose faces share edges), serial and with
   ``jobs=2``: wall time and peak memory (each case in its own process), time per face and the
   growth exponent ``log(t2/t1) / log(n2/n1)`` (1 = linear).
3. A sweep of n = 25, 50, 100 variants (one ``[sweep]`` list) through ``run_batch(jobs=2)``:
   wall time, peak memory, growth exponent.

Run: ``.venv/bin/python bench/bench_batch.py [--quick]`` (``--quick``: smaller counts).
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


def cone_design(name: str, h: float, k: float, z1: float, figures: str = '["flat_pattern"]') -> str:
    """A quarter cone frustum design (apex height h, radius k (h - z), cut at z = 0 and z = z1)."""
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
figures = {figures}
"""


def many_faces_step(path: str | os.PathLike, n_faces: int) -> int:
    """Write a STEP file with at least ``n_faces`` developable faces; returns the face count.

    Per index i on a grid (spacing 100 mm): i % 4 == 0 a partial cylinder's lateral face,
    1 a partial cone's, 2 a ruled B-spline strip (degree 3 x 1, 4 x 2 poles), 3 a whole cylinder
    solid (lateral face and two caps sharing its circles).
    """
    import build123d as bd
    import numpy as np

    from ght_cad.bspline import BSplineSurfaceData
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


def _peak_mb() -> float:
    """Peak resident memory of this process and its finished children, MB (ru_maxrss is in kB)."""
    me = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    kids = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return max(me, kids) / 1024.0


def case_faces(n: int, jobs: int) -> dict[str, Any]:
    """One measurement in this process: unroll_step of an n-face STEP file."""
    from ght_cad.design import unroll_step

    with tempfile.TemporaryDirectory() as tmp:
        step = Path(tmp) / "many.step"
        faces = many_faces_step(step, n)
        t0 = time.perf_counter()
        res = unroll_step(step, jobs=jobs)
        dt = time.perf_counter() - t0
    return {"faces": faces, "panels": len(res.pattern.panels), "time": dt, "peak_mb": _peak_mb()}


def case_sweep(n: int, jobs: int) -> dict[str, Any]:
    """One measurement in this process: a sweep of n variants through run_batch."""
    from ght_cad.batch import run_batch

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "sweep.toml"
        p.write_text(cone_design("sweep", 800.0, 0.5, 400.0, figures="[]")
                     + f'\n[sweep]\n"surface.boundary_planes.1.0" = {{ start = -100, stop = -500, num = {n} }}\n')
        t0 = time.perf_counter()
        res = run_batch([p], Path(tmp) / "out", jobs=jobs, progress=False)
        dt = time.perf_counter() - t0
        assert res.exit_code == 0, res.rows
    return {"designs": n, "time": dt, "peak_mb": _peak_mb()}


def _in_subprocess(kind: str, n: int, jobs: int) -> dict[str, Any]:
    out = subprocess.run([sys.executable, __file__, "--case", kind, str(n), str(jobs)], capture_output=True,
                         text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def _growth(rows: list[dict[str, Any]], key: str) -> str:
    a, b = rows[0], rows[-1]
    if a["time"] <= 0 or a[key] == b[key]:
        return "n/a"
    return f"{math.log(b['time'] / a['time']) / math.log(b[key] / a[key]):.2f}"


def bench_jobs(n_designs: int) -> None:
    from ght_cad.batch import run_batch

    with tempfile.TemporaryDirectory() as tmp:
        paths = []
        for i in range(n_designs):
            p = Path(tmp) / f"d{i}.toml"
            p.write_text(cone_design(f"d{i:02d}", 600.0 + 40 * i, 0.3 + 0.05 * (i % 6), 200.0 + 10 * i))
            paths.append(p)
        times = {}
        for jobs in (1, 2):
            t0 = time.perf_counter()
            res = run_batch(paths, Path(tmp) / f"out{jobs}", jobs=jobs, progress=False)
            times[jobs] = time.perf_counter() - t0
            assert res.exit_code == 0
    print(f"1. batch of {n_designs} designs: --jobs 1 {times[1]:.2f} s, --jobs 2 {times[2]:.2f} s, "
          f"speed-up {times[1] / times[2]:.2f}x (expected >= 1.6 on 2 idle cores; cores here: {os.cpu_count()}, "
          f"load average {os.getloadavg()[0]:.1f})")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller counts")
    ap.add_argument("--case", nargs=3, metavar=("KIND", "N", "JOBS"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.case:
        kind, n, jobs = args.case[0], int(args.case[1]), int(args.case[2])
        print(json.dumps(case_faces(n, jobs) if kind == "faces" else case_sweep(n, jobs)))
        return 0
    bench_jobs(4 if args.quick else 8)
    counts = (50, 100, 200) if args.quick else (250, 500, 1000)
    for jobs in (1, 2):
        rows = [_in_subprocess("faces", n, jobs) for n in counts]
        for r in rows:
            print(f"2. unroll_step jobs={jobs}: {r['faces']:5d} faces {r['time']:7.2f} s "
                  f"({1e3 * r['time'] / r['faces']:.1f} ms/face), peak memory {r['peak_mb']:.0f} MB")
        print(f"   growth exponent of time with the face count (1 = linear): {_growth(rows, 'faces')}")
    counts = (10, 20, 40) if args.quick else (25, 50, 100)
    rows = [_in_subprocess("sweep", n, 2) for n in counts]
    for r in rows:
        print(f"3. sweep jobs=2: {r['designs']:4d} variants {r['time']:7.2f} s "
              f"({r['time'] / r['designs']:.2f} s/variant), peak memory {r['peak_mb']:.0f} MB")
    print(f"   growth exponent of time with the variant count (1 = linear): {_growth(rows, 'designs')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
