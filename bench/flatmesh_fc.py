"""FreeCAD side of bench/flatmesh_compare.py: mesh STEP faces and unwrap them with ``flatmesh``.

Run by Debian's FreeCAD as a separate, persistent process (``freecadcmd bench/flatmesh_fc.py``;
``-M``/``-P`` crash on that build) that the bench drives call by call, so that FreeCAD's calls and
ours alternate and both sides see the same machine (this VM's single-core speed drifts by +-30 %
within a minute: two processes timed one after the other compare two different machines).

The job is a JSON file named by the environment variable ``GHT_FLATMESH_JOB``::

    {"faces": [{"name": ..., "step": ..., "deflection": ..., "angular": ...}]}

Then one command per line on standard input, one answer per line on standard output, prefixed by
``GHTFM `` (FreeCAD prints its banner to the same stream):

* ``call NAME K``: K calls of ``MeshPart.meshFromShape`` (absolute linear deflection) plus
  ``flatmesh.FaceUnwrapper(nodes, triangles).findFlatNodes(5, 0.95)`` (the settings of FreeCAD's
  "Unwrap Mesh" command); answers the fastest one's ``{"time_mesh": s, "time_unwrap": s}``, or
  ``{"error": ...}``;
* ``result NAME``: nodes, triangles and flat nodes of the fastest call so far and its two times;
* ``quit``.
"""

import json
import os
import sys
import time
import traceback

import FreeCAD  # noqa: F401  (initializes the application)
import flatmesh
import MeshPart
import numpy as np
import Part


def _load(spec):
    shape = Part.Shape()
    shape.read(spec["step"])
    return {"spec": spec, "face": shape.Faces[0], "best": None}


def _call(entry):
    """One mesh + unwrap of the face; keeps the fastest call's mesh and times."""
    spec, face = entry["spec"], entry["face"]
    t0 = time.perf_counter()
    mesh = MeshPart.meshFromShape(
        Shape=face, LinearDeflection=float(spec["deflection"]), AngularDeflection=float(spec.get("angular", 0.1)),
        Relative=False,
    )
    nodes = np.array([[p.x, p.y, p.z] for p in mesh.Points], dtype=float)
    tris = np.array([list(t) for t in mesh.Topology[1]], dtype=np.int64)
    t1 = time.perf_counter()
    unwrapper = flatmesh.FaceUnwrapper(nodes, tris)
    unwrapper.findFlatNodes(5, 0.95)
    flat = np.array(unwrapper.ze_nodes, dtype=float)
    t2 = time.perf_counter()
    best = entry["best"]
    if best is None or t2 - t0 < best["time_mesh"] + best["time_unwrap"]:
        entry["best"] = {"nodes": nodes, "tris": tris, "flat": flat, "time_mesh": t1 - t0, "time_unwrap": t2 - t1}
    return {"time_mesh": t1 - t0, "time_unwrap": t2 - t1}


def _answer(obj):
    sys.stdout.write("GHTFM " + json.dumps(obj) + "\n")
    sys.stdout.flush()


def main():
    job = json.load(open(os.environ["GHT_FLATMESH_JOB"]))
    faces = {}
    for spec in job["faces"]:
        try:
            faces[spec["name"]] = _load(spec)
        except Exception:
            faces[spec["name"]] = {"error": traceback.format_exc()}
    _answer({"ready": sorted(faces)})
    for line in sys.stdin:
        cmd, _, rest = line.strip().partition(" ")
        name, _, count = rest.partition(" ")
        if cmd == "quit":
            break
        entry = faces.get(name)
        if entry is None or "error" in entry:
            _answer({"error": entry["error"] if entry else f"no face {name!r}"})
            continue
        try:
            if cmd == "call":
                _answer(min((_call(entry) for _ in range(max(1, int(count or 1)))),
                            key=lambda t: t["time_mesh"] + t["time_unwrap"]))
            elif cmd == "result":
                b = entry["best"]
                _answer({"name": name, "nodes": b["nodes"].tolist(), "tris": b["tris"].tolist(),
                         "flat": b["flat"][:, :2].tolist(), "time_mesh": b["time_mesh"],
                         "time_unwrap": b["time_unwrap"], "face_area_freecad": entry["face"].Area})
            else:
                _answer({"error": f"unknown command {cmd!r}"})
        except Exception:  # report per face, keep serving
            _answer({"error": traceback.format_exc()})


main()
