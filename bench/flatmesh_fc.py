"""FreeCAD side of bench/flatmesh_compare.py: mesh STEP faces and unwrap them with ``flatmesh``.

Run by Debian's FreeCAD as a separate process (``freecadcmd bench/flatmesh_fc.py``; ``-M``/``-P``
crash on that build). The job is a JSON file named by the environment variable
``GHT_FLATMESH_JOB``::

    {"faces": [{"name": ..., "step": ..., "deflection": ..., "angular": ..., "reps": ...}], "out": "result.json"}

For every face: ``MeshPart.meshFromShape`` (absolute linear deflection), then
``flatmesh.FaceUnwrapper(nodes, triangles).findFlatNodes(5, 0.95)`` (the settings of FreeCAD's
"Unwrap Mesh" command), ``reps`` times. Writes nodes, triangles, flat nodes and the times of both
steps of the fastest call.
"""

import json
import os
import time
import traceback

import FreeCAD  # noqa: F401  (initializes the application)
import flatmesh
import MeshPart
import numpy as np
import Part


def _one(spec):
    shape = Part.Shape()
    shape.read(spec["step"])
    face = shape.Faces[0]
    best = None
    for _ in range(max(1, int(spec.get("reps", 1)))):  # the fastest of the calls (as on our side)
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
        if best is None or t2 - t0 < best[1] - best[0] + best[2] - best[1]:
            best = (t0, t1, t2)
    t0, t1, t2 = best
    return {
        "name": spec["name"],
        "nodes": nodes.tolist(),
        "tris": tris.tolist(),
        "flat": flat[:, :2].tolist(),
        "time_mesh": t1 - t0,
        "time_unwrap": t2 - t1,
        "face_area_freecad": face.Area,
    }


def main():
    job = json.load(open(os.environ["GHT_FLATMESH_JOB"]))
    results = []
    for spec in job["faces"]:
        try:
            results.append(_one(spec))
        except Exception:  # report per face, keep going
            results.append({"name": spec["name"], "error": traceback.format_exc()})
    tmp = job["out"] + ".part"
    with open(tmp, "w") as fh:
        json.dump({"results": results}, fh)
    os.replace(tmp, job["out"])


main()
