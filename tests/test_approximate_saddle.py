"""The saddle ``z = x y / L`` of issue 24's acceptance list in its OWN parametrization: x, y on a
square, a B-spline face of the bilinear graph (tests/test_approximate.py::test_saddle_patch turns
it 45° so that its parameter lines are the principal directions).

Here both families of parameter lines are straight lines on the surface (the hyperbolic paraboloid
is doubly ruled): the normal curvature along them is zero, they are its asymptotic lines. Seams
along them are skew straight lines, and no developable joins two skew lines (``det(a', b', b - a)``
keeps one sign): before the diagonal strips every direction option failed ("the march needed more
than 30 strips"). ``direction="auto"`` now ranks the strips by the conjugate estimate (maths
10.2: u and v about 88 strips, the diagonals 5.5) and puts the seams along the isolines of
``u + v``, cones at the two corners the diagonal seams shrink to. Measured (tol 2 mm): 8 panels (the first march, 6 strips, reached 2.32 mm), 1.29
mm by the algorithm's own measure, ~40 s.
"""

from __future__ import annotations

import pytest

pytest.importorskip("OCP")

import ght_cad  # noqa: E402
from ght_cad.cad.approximate import panels_shell  # noqa: E402
from ght_cad.cad.unroll_faces import shape_faces  # noqa: E402

from test_approximate import bspline_face, twist_deg, two_way  # noqa: E402

L = 2000.0
TOL = 2.0
#: along the principal directions (normal curvature ±1/L at most) a strip of width w deviates
#: κ w² / 16 both ways: w <= sqrt(16 tol L) = 253 mm, so the 1414 mm diagonal needs about 6 strips;
#: 16 leaves room for strips that follow a parameter direction only roughly
MAX_PANELS = 16


def saddle_face():
    """``z = x y / L``, x, y in [-500, 500] (mm), parametrized by x and y (bicubic interpolation of
    a bilinear graph on a 9 × 9 grid: exact up to OCCT's 1e-6 fit)."""
    return bspline_face(lambda s, t: (1000 * s - 500, 1000 * t - 500, (1000 * s - 500) * (1000 * t - 500) / L), 9, 9)


@pytest.mark.slow
def test_saddle_in_its_own_parametrization(tmp_path):
    from ght_cad.cad.occ import read_step, write_step

    from test_approximate import face_area, free_wires

    face = saddle_face()
    res = ght_cad.approximate(face, TOL, max_panels=30)
    assert res.direction in ("diagonal", "antidiagonal")
    assert len(res.panels) <= MAX_PANELS
    # the corners the diagonal seams shrink to are cone apexes; a seam on the kink y = 1/2
    assert res.seams[0]["point"] and res.seams[-1]["point"]
    assert any(abs(s["y"] - 0.5) <= 1e-12 for s in res.seams)
    shell = panels_shell(res)
    step = write_step(shell, tmp_path / "panels.step")
    back = read_step(step)
    faces = shape_faces(back)
    assert len(faces) == len(res.panels)
    # independent two-way deviation (OCCT distances), within tol (0.1 % for sampling)
    assert two_way(face, back, n_target=(20, 20), n_panel=(12, 5)) <= TOL * 1.001
    assert max(twist_deg(f) for f in faces) <= 0.01
    # flat pattern areas = STEP face areas (1e-6)
    flat = sorted(p.area_flat for p in res.flat_pattern().panels)
    step_areas = sorted(face_area(f) for f in faces)
    for a, b in zip(flat, step_areas):
        assert abs(a - b) <= 1e-6 * b
    # watertight to 1e-6 of the size: one free wire, the outline of the square
    assert free_wires(back, 1e-6 * res.size) == 1
