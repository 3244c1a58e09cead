"""Benchmark: control planes → valid developable B-rep face, against a plain build123d ruled face.

Times, in the same run:

* ``ght``: ``developable_from_planes(...)`` (with its input checks: neighbours, boundary planes,
  edge of regression) + ``.to_face()`` (6-D compatible-pole fit, face, ``BRepCheck_Analyzer``);
* ``build123d``: ``Face.make_surface_from_curves(edge_a, edge_b)`` between two B-spline edges of
  the same size (the very poles and knots of our fitted boundary curves) + ``is_valid``.

and prints both and their ratio (what the developability guarantee costs over a bare ruled face),
then where the ``ght`` time goes: construction with its checks, the boundary-curve fit
(``developable_bspline``: certified 6-D ``fit_function`` plus the B-spline's own θ check) and the
OCCT face with its validity check.

Run: ``python bench/bench_developable.py [--repeat R]``
"""

from __future__ import annotations

import argparse

from bench_basis import _best  # best-of-R wall time, shared by the bench scripts
def main(repeat: int = 5) -> dict[str, float]:
    from build123d import Face

    from ght_cad import developable_from_planes
    from ght_cad.surfaces.bspline import BSplineCurveData
    from ght_cad.cad.developable_faces import developable_surface_data
    from ght_cad.cad.occ import is_valid, make_edge
    from ght_cad.surfaces.planes import plane_from_point_normal

    planes = [
        plane_from_point_normal((0, 5, 0), (0, 1, -0.15)),
        plane_from_point_normal((4, 5.3, -0.5), (0.05, 1, -0.4)),
        plane_from_point_normal((8, 5.2, -1.2), (0.1, 1, -0.8)),
        plane_from_point_normal((12, 4.6, -2.0), (0.2, 0.8, -1.2)),
    ]
    frames = [(0, 1, 0, 0), (-12, 1, 0, 0)]

    def ght() -> None:
        face = developable_from_planes(planes, frames, 0.3, -0.2, 0.1).to_face()
        assert face is not None

    surf = developable_from_planes(planes, frames, 0.3, -0.2, 0.1)
    data = developable_surface_data(surf)
    ea = make_edge(BSplineCurveData(data.poles[:, 0], data.knots_u, data.degree_u))
    eb = make_edge(BSplineCurveData(data.poles[:, 1], data.knots_u, data.degree_u))

    def baseline() -> None:
        face = Face.make_surface_from_curves(ea, eb)
        assert is_valid(face)

    ght()
    baseline()  # warm up imports
    t_ght = _best(ght, repeat)
    t_base = _best(baseline, repeat)
    print(f"boundary poles per edge: {data.poles.shape[0]} (degree {data.degree_u})")
    print(f"ght_cad  control planes -> valid developable face: {t_ght * 1e3:9.2f} ms")
    print(f"build123d ruled face between two edges (+check):    {t_base * 1e3:9.2f} ms")
    print(f"ratio ght / build123d: {t_ght / t_base:.1f}x")
    from ght_cad.cad.occ import make_face
    from ght_cad.developables.envelope import EnvelopeDevelopable, developable_bspline

    stages = {
        "developable_from_planes (checks)": lambda: developable_from_planes(planes, frames, 0.3, -0.2, 0.1),
        "developable_bspline (fit + θ)": lambda: developable_bspline(
            EnvelopeDevelopable(planes, frames, 0.3, -0.2, 0.1, check=False)
        ),
        "make_face + is_valid": lambda: is_valid(make_face(data)),
    }
    for name, fn in stages.items():
        print(f"  stage {name:34s} {_best(fn, repeat) * 1e3:7.2f} ms")
    return {"ght_s": t_ght, "build123d_s": t_base, "ratio": t_ght / t_base}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    main(ap.parse_args().repeat)
