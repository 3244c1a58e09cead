r"""Flat-pattern unrolling inside FreeCAD: the core NURBS evaluator vs FreeCAD's point-by-point path.

The workbench's Flat pattern feature unrolls a Part face by
``ght_cad.unrolling.face_unroll.unroll_face_data(flat_pattern.face_data(face), rulings=8, samples=65)``.
``face_data(face, fast=True)`` reads B-spline/Bézier surfaces and line/circle/B-spline/Bézier
pcurves and edge curves into :mod:`ght_cad.surfaces.nurbs` (vectorized, exact pcurve derivatives);
``fast=False`` is the old path (``value``/``getDN``/``valueAt`` point by point, pcurve derivatives
by finite differences). Both are timed in the same FreeCAD process (fastest of ``GHT_BENCH_REPS``
calls, default 10, alternating) on the four faces of ``bench/flatmesh_compare.py:default_faces()``
exported to STEP by the OCP side and read back with ``Part.Shape().read``.

Driven from the venv (``python bench/bench_freecad_unroll.py``): exports the faces, reads the same
STEP files with OCP and unrolls them with :func:`ght_cad.cad.unroll_faces.unroll_face` (same
rulings and samples), runs ``freecadcmd`` on this file and prints, per face, both times, the ratio
new/old and the largest distance between the FreeCAD-path flat outlines (both paths) and the OCP
path's, relative to the pattern's size. ``freecadcmd bench/bench_freecad_unroll.py`` alone needs
``GHT_BENCH_DIR`` holding the STEP files (``<face>.step``) and prints the times only.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

FACES = ("cone_frustum", "half_cylinder_hole", "tangent_dev_bspline", "envelope_bspline")
OPTS = dict(rulings=8, samples=65)
REPO = Path(__file__).resolve().parents[1]


def _outline(pat) -> list[list[list[list[float]]]]:
    """Flat points of every edge (loops of edges of (samples, 2) arrays) with the panel offset."""
    return [[(np.asarray(e.flat) + p.offset).tolist() for e in loop] for p in pat.panels for loop in p.loops]


def _freecad_side(folder: Path) -> None:
    """Inside freecadcmd: time both paths and write the outlines to ``freecad.json``."""
    import Part

    from freecad.ght_workbench import flat_pattern
    from ght_cad.unrolling.face_unroll import unroll_face_data

    reps = int(os.environ.get("GHT_BENCH_REPS", "10"))
    out = {}
    for name in FACES:
        sh = Part.Shape()
        sh.read(str(folder / f"{name}.step"))
        face = sh.Faces[0]
        best = {True: float("inf"), False: float("inf")}
        pats = {}
        for _ in range(reps):
            for fast in (True, False):
                t0 = time.perf_counter()
                pats[fast] = unroll_face_data(flat_pattern.face_data(face, fast), **OPTS)
                best[fast] = min(best[fast], time.perf_counter() - t0)
        fd = flat_pattern.face_data(face)
        ev = flat_pattern.FreeCADSurface(face)
        edges = [flat_pattern._Edge(face, e, ev) for w in face.Wires for e in w.OrderedEdges]
        for e in edges:
            e.xyz(np.array([0.0, 1.0]))
        paths = {"surface": ev.path, "pcurves": sorted({e.paths["pcurve"] for e in edges}),
                 "curves3d": sorted({e.paths["curve3d"] for e in edges})}
        del fd
        out[name] = {"new_s": best[True], "old_s": best[False], "paths": paths,
                     "outline_new": _outline(pats[True]), "outline_old": _outline(pats[False]),
                     "area_new": pats[True].area, "area_old": pats[False].area}
        print(f"{name:22s} new {1e3 * best[True]:8.2f} ms  old {1e3 * best[False]:8.2f} ms  "
              f"new/old {best[True] / best[False]:.3f}  {paths}", flush=True)
    (folder / "freecad.json").write_text(json.dumps(out))


def _distance(a: list, b: list) -> float:
    """Largest distance between matching edges of two outlines (each edge of ``a`` matched with the
    edge of ``b`` closest in either direction)."""
    eb = [np.asarray(e) for loop in b for e in loop]
    worst = 0.0
    for loop in a:
        for e in loop:
            e = np.asarray(e)
            d = min(min(float(np.abs(e - f).max()), float(np.abs(e - f[::-1]).max())) for f in eb if f.shape == e.shape)
            worst = max(worst, d)
    return worst


def _venv_side() -> int:
    sys.path.insert(0, str(REPO / "bench"))
    import build123d as bd
    from flatmesh_compare import default_faces
    from OCP.STEPControl import STEPControl_Reader

    from ght_cad.cad.unroll_faces import shape_faces, unroll_face

    exe = shutil.which("freecadcmd")
    if exe is None:
        print("freecadcmd not found: install Debian's freecad-python3", file=sys.stderr)
        return 2
    folder = Path(tempfile.mkdtemp(prefix="ght_bench_fc_"))
    ocp = {}
    for name, f in default_faces().items():
        path = folder / f"{name}.step"
        bd.export_step(f, str(path))
        rd = STEPControl_Reader()
        rd.ReadFile(str(path))
        rd.TransferRoots()
        pat = unroll_face(shape_faces(rd.OneShape())[0], **OPTS)
        ocp[name] = {"outline": _outline(pat), "area": pat.area}
    import ght_cad

    env = dict(os.environ, GHT_BENCH_DIR=str(folder))
    env.pop("VIRTUAL_ENV", None)
    env.pop("PYTHONHOME", None)
    core = str(Path(ght_cad.__file__).resolve().parents[1])
    env["PYTHONPATH"] = os.pathsep.join([str(REPO / "freecad_workbench"), core])
    proc = subprocess.run([exe, str(Path(__file__).resolve())], env=env, cwd=folder, capture_output=True, text=True, timeout=1800)
    res_path = folder / "freecad.json"
    if proc.returncode != 0 or not res_path.exists():
        print(proc.stdout[-4000:], proc.stderr[-4000:], file=sys.stderr)
        return 1
    fc = json.loads(res_path.read_text())
    print(f"FreeCAD flat-pattern unrolling (unroll_face_data(face_data(face)), rulings=8, samples=65): fastest of "
          f"{os.environ.get('GHT_BENCH_REPS', '10')} alternating calls; load average {os.getloadavg()[0]:.1f}")
    print("agreement: largest outline distance to the OCP path's (same STEP file), relative to the pattern's diagonal")
    hdr = f"{'face':22s} {'new ms':>8s} {'old ms':>8s} {'new/old':>8s} | {'new vs OCP':>10s} {'old vs OCP':>10s} {'area new':>9s} {'area old':>9s} | surface"
    print(hdr)
    print("-" * len(hdr))
    for name in FACES:
        r, o = fc[name], ocp[name]
        pts = np.concatenate([np.asarray(e) for loop in o["outline"] for e in loop])
        size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
        dn, do = _distance(r["outline_new"], o["outline"]) / size, _distance(r["outline_old"], o["outline"]) / size
        an, ao = abs(r["area_new"] / o["area"] - 1), abs(r["area_old"] / o["area"] - 1)
        print(f"{name:22s} {1e3 * r['new_s']:8.2f} {1e3 * r['old_s']:8.2f} {r['new_s'] / r['old_s']:8.3f} | "
              f"{dn:10.1e} {do:10.1e} {an:9.1e} {ao:9.1e} | {r['paths']['surface']}, pcurves {r['paths']['pcurves']}, "
              f"3-D {r['paths']['curves3d']}")
    shutil.rmtree(folder, ignore_errors=True)
    return 0


if "FreeCAD" in sys.modules:  # freecadcmd runs this file as a script
    _folder = os.environ.get("GHT_BENCH_DIR")
    if not _folder:
        print("set GHT_BENCH_DIR to a folder holding <face>.step for " + ", ".join(FACES), file=sys.stderr)
    else:
        _freecad_side(Path(_folder))
elif __name__ == "__main__":
    sys.exit(_venv_side())
