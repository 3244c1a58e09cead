"""One blank per bent part (issue 23): wall time of ``ght-cad unroll part.step`` (a fresh process,
start-up included) and of the in-process ``ght_cad.unfold``, on the parts of tests/sheet_parts.py,
with the blank's area against the closed-form neutral blank ``Σ flats + Σ (R + K T) A``.

The ratio column is in-process time over the same run's time of the closed-form check itself
(``Profile.blank_area``: a few float operations), i.e. a same-run baseline of the interpreter's
speed; ``/OCP`` is the CLI's wall time over a fresh Python's ``import OCP.STEPControl`` (the
start-up floor every STEP command pays) in the same run; compare ratios between runs, not seconds (this VM's speed drifts by ±30 % and by far more
when other processes share its two cores: the load average is printed).

Run: ``.venv/bin/python bench/bench_blank.py [--runs N]``.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

K = 0.42


def parts():
    import math

    from sheet_parts import bracket, cone_bend, freeform_bend, profile_solid, tray, u_channel, z_profile

    hole = [(1, 30.0, 10.0)]
    yield "L-bracket", profile_solid(bracket()), lambda k: bracket().blank_area(k)
    yield "Z-profile", profile_solid(z_profile()), lambda k: z_profile().blank_area(k)
    yield "U-channel + hole", profile_solid(u_channel(), hole), lambda k: u_channel().blank_area(k) - math.pi * 25.0
    solid, area = tray()
    yield "tray (4 flanges)", solid, area
    for sign in (-1, 1):
        solid, area = freeform_bend(sign)
        yield f"spline bend ({'convex' if sign < 0 else 'concave'} side)", solid, area
    solid, area = cone_bend()
    yield "cone-segment bend (R 3 -> 8)", solid, area


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=3, help="in-process calls per part (the best is shown)")
    args = ap.parse_args()
    import ght_cad
    from ght_cad.cad.occ import write_step

    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import OCP.STEPControl"], check=True)
    ocp = time.perf_counter() - t0
    print(f"start-up floor: a fresh Python importing OCP.STEPControl: {ocp:.2f} s wall")
    print(f"{'part':28s} {'faces':>5s} {'CLI wall [s]':>12s} {'/OCP':>8s} {'unfold [s]':>10s} {'ratio':>9s} {'area rel. err':>13s}")
    exe = Path(sys.executable).parent / "ght-cad"
    with tempfile.TemporaryDirectory() as tmp:
        for name, solid, area in parts():
            step = Path(tmp) / "part.step"
            write_step(solid, step)
            t0 = time.perf_counter()
            rc = subprocess.run([str(exe), "unroll", str(step), "--k-factor", str(K)], capture_output=True).returncode
            cli = time.perf_counter() - t0
            best = float("inf")
            for _ in range(args.runs):
                t0 = time.perf_counter()
                res = ght_cad.unfold(solid, k_factor=K)
                best = min(best, time.perf_counter() - t0)
            t0 = time.perf_counter()
            for _ in range(1000):
                want = area(K)
            base = (time.perf_counter() - t0) / 1000
            err = res.pattern.area / want - 1
            print(f"{name:28s} {len(solid.faces()):5d} {cli:12.2f} {cli / ocp:8.2f} {best:10.3f} {best / base:9.3g} {err:13.2e}"
                  + ("" if rc == 0 else f"  (CLI exit {rc})"))


if __name__ == "__main__":
    main()
