"""Developable surfaces as B-rep faces/shells, measured from the faces themselves (OCCT normals)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

pytest.importorskip("OCP")
pytest.importorskip("build123d")

from OCP.BRep import BRep_Tool  # noqa: E402
from OCP.BRepAdaptor import BRepAdaptor_Surface  # noqa: E402
from OCP.BRepLProp import BRepLProp_SLProps  # noqa: E402
from OCP.GeomAPI import GeomAPI_ProjectPointOnSurf  # noqa: E402

from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.developable_faces import (  # noqa: E402
    _internal_edges,
    developable_face,
    developable_surface_data,
    face_developability,
    joint_normal_deviation,
    planes_from_build123d,
    shell_faces,
)
from ght_cad.cad.occ import is_valid, read_step, write_step  # noqa: E402
from ght_cad.developables.envelope import (  # noqa: E402
    CompositeDevelopable,
    RectifyingDevelopable,
    TangentDevelopable,
    developable_from_planes,
    join_developable,
)
from ght_cad.core.errors import GHTError  # noqa: E402
from ght_cad.surfaces.planes import plane_from_point_normal  # noqa: E402
from ght_cad.surfaces.ruled import CurvePairRuledSurface  # noqa: E402

THETA_FACE_DEG = 0.01  # acceptance: θ_max of a B-rep face, from OCCT normals

SHIP = [
    plane_from_point_normal((0, 5, 0), (0, 1, -0.15)),
    plane_from_point_normal((4, 5.3, -0.5), (0.05, 1, -0.4)),
    plane_from_point_normal((8, 5.2, -1.2), (0.1, 1, -0.8)),
    plane_from_point_normal((12, 4.6, -2.0), (0.2, 0.8, -1.2)),
]
FRAMES = [(0, 1, 0, 0), (-12, 1, 0, 0)]
SPACE = GHTCurve([(0, 0, 0), (1, 0.2, 0.1), (2, 1, 0.5), (3, 1.5, 1.5), (3.5, 3, 2)], mu=0.2, nu=-0.3, gamma=0.4)


@pytest.fixture(scope="module")
def ship():
    return developable_from_planes(SHIP, FRAMES, 0.3, -0.2, 0.1)


@pytest.fixture(scope="module")
def ship_face(ship):
    return developable_face(ship)


def _surface(face):
    return BRep_Tool.Surface_s(shell_faces(face)[0])


def test_face_is_one_valid_bspline_face_degree_1_across_rulings(ship, ship_face):
    assert is_valid(ship_face)
    assert len(shell_faces(ship_face)) == 1
    s = _surface(ship_face)
    assert s.VDegree() == 1 and s.UDegree() == 5 and s.NbVPoles() == 2
    # compatible poles: the face's iso-lines v=0 and v=1 are a(u) and b(u) at the SAME u
    data = developable_surface_data(ship)
    u = np.linspace(0, 1, 23)
    for v, side in ((0.0, ship.a), (1.0, ship.b)):
        P = np.array([[s.Value(float(x), v).X(), s.Value(float(x), v).Y(), s.Value(float(x), v).Z()] for x in u])
        assert np.abs(P - side(u)).max() <= 1.01 * data.max_deviation
    assert data.max_deviation <= 1e-7 * data.info["size"]
    # end rulings exactly: end poles are a(0), b(0), a(1), b(1)
    np.testing.assert_allclose(data.poles[0], np.vstack([ship.a(0.0), ship.b(0.0)]), atol=1e-12)
    np.testing.assert_allclose(data.poles[-1], np.vstack([ship.a(1.0), ship.b(1.0)]), atol=1e-12)


def test_face_developability_from_occt_normals(ship_face, tmp_path):
    fd = face_developability(ship_face)
    assert fd.theta_max <= THETA_FACE_DEG, fd
    path = write_step(ship_face, tmp_path / "plate.step")
    back = read_step(path)
    fb = face_developability(back)
    assert fb.theta_max <= THETA_FACE_DEG, fb
    assert abs(fb.theta_max - fd.theta_max) <= 1e-6


def test_measurement_detects_a_non_developable_face():
    """A twisted (hyperbolic-paraboloid) strip fails the same measurement: the check can fail."""
    twisted = CurvePairRuledSurface(
        GHTCurve([(0, 0, 0), (1, 0, 0), (2, 0, 0)]), GHTCurve([(0, 1, 0), (1, 1, 0.5), (2, 1, 1)])
    )
    fd = face_developability(developable_face(twisted))
    assert fd.theta_max > 10.0


@pytest.mark.parametrize(
    "surface",
    [TangentDevelopable(SPACE, 0.2, 1.0), RectifyingDevelopable(SPACE, -0.15, 0.25)],
    ids=["tangent", "rectifying"],
)
def test_spine_and_geodesic_faces(surface, tmp_path):
    face = surface.to_face()
    assert is_valid(face)
    assert face_developability(face).theta_max <= THETA_FACE_DEG
    back = read_step(write_step(face, tmp_path / "f.step"))
    assert face_developability(back).theta_max <= THETA_FACE_DEG


def test_cylinder_face_keeps_radius():
    r, H = 2.0, 3.0
    s = developable_from_planes([(-r, 1, 0, 0), (-r, 1, 1, 0), (-r, 0, 1, 0)], [(0, 0, 0, 1), (-H, 0, 0, 1)], gamma=-1)
    face = s.to_face(tol=1e-9)
    g = _surface(face)
    for u in np.linspace(0, 1, 17):
        for v in (0.0, 0.5, 1.0):
            p = g.Value(float(u), v)
            assert abs(math.hypot(p.X(), p.Y()) - r) <= 1e-9
    assert face_developability(face).theta_max <= 1e-9


def test_cone_face_keeps_apex_and_axis():
    k, h = 0.5, 2.0
    P = [(-k * h, 1, 0, k), (-k * h, 1, 1, k), (-k * h, 0, 1, k)]
    s = developable_from_planes(P, [(0, 0, 0, 1), (-1.2, 0, 0, 1)], gamma=-1)
    g = _surface(s.to_face(tol=1e-10))
    for u in np.linspace(0, 1, 17):
        pts = [g.Value(float(u), v) for v in (0.0, 1.0)]
        X = np.array([[p.X(), p.Y(), p.Z()] for p in pts])
        # on the cone sqrt(x² + y²) = k (h - z) and the ruling line passes through the apex (0, 0, h)
        assert np.abs(np.hypot(X[:, 0], X[:, 1]) - k * (h - X[:, 2])).max() <= 1e-9
        d = X[1] - X[0]
        assert np.linalg.norm(np.cross(np.array([0, 0, h]) - X[0], d)) / np.linalg.norm(d) <= 1e-9
    assert face_developability(s.to_face()).theta_max <= THETA_FACE_DEG


# -- composites: shells with shared edges, normal field continuous across the joint ----------
APEX = np.array([-25.0, 0.0, -2.0])


def _cone_plane(phi: float, tilt: float = 0.0) -> np.ndarray:
    n = np.array([tilt, math.cos(phi), -math.sin(phi)])
    return np.concatenate([[-n @ APEX], n])


FIRST = [_cone_plane(0.0, 0.1), _cone_plane(0.3, 0.12), _cone_plane(0.6, 0.16), _cone_plane(0.9, 0.18)]
NEXT = [_cone_plane(1.0), _cone_plane(1.1), _cone_plane(1.2), _cone_plane(1.35, 0.2), _cone_plane(1.5, 0.22), _cone_plane(1.6, 0.25)]


def _max_curvature_jump(shell) -> float:
    """Relative jump of the non-zero principal curvature across the shared edge (mid-point)."""
    (edge, (fa, fb)), = _internal_edges(shell)
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    c = BRepAdaptor_Curve(edge)
    ks = []
    for t in np.linspace(c.FirstParameter(), c.LastParameter(), 5)[1:-1]:
        p = c.Value(float(t))
        vals = []
        for f in (fa, fb):
            u, v = GeomAPI_ProjectPointOnSurf(p, BRep_Tool.Surface_s(f)).LowerDistanceParameters()
            props = BRepLProp_SLProps(BRepAdaptor_Surface(f), u, v, 2, 1e-12)
            assert props.IsCurvatureDefined()  # computes the curvatures: OCCT 8 returns 0 before it
            k = max(abs(props.MaxCurvature()), abs(props.MinCurvature()))
            vals.append(k)
        ks.append(abs(vals[0] - vals[1]) / max(vals))
    return max(ks)


@pytest.mark.parametrize("order", [1, 2, 3])
def test_composite_shell_joint(order, tmp_path):
    a = developable_from_planes(FIRST, FRAMES, 0.3, -0.2, 0.1)
    b = join_developable(a, f"G{order}", NEXT, k=1.3, beta2=0.2, beta3=-0.1)
    comp = CompositeDevelopable([a, b])
    shell = comp.to_shell()
    assert is_valid(shell)
    faces = shell_faces(shell)
    assert len(faces) == 2 and len(_internal_edges(shell)) == 1
    for f in faces:
        assert face_developability(f).theta_max <= THETA_FACE_DEG
    # G1 and higher: the normal field is continuous across the shared ruling
    assert max(joint_normal_deviation(shell)) <= 1e-6
    jump = _max_curvature_jump(shell)
    if order >= 2:
        assert jump <= 1e-4  # curvature continuous across the joint
    else:
        assert jump >= 1e-3  # a G1-only joint has a curvature jump (the check can fail)
    back = read_step(write_step(shell, tmp_path / "shell.step"))
    assert len(shell_faces(back)) == 2 and max(joint_normal_deviation(back)) <= 1e-6
    for f in shell_faces(back):
        assert face_developability(f).theta_max <= THETA_FACE_DEG


# -- planes from build123d, bad input ----------------------------------------------------------
def test_planes_from_build123d():
    import build123d as bd

    U = planes_from_build123d(bd.Plane.XY.offset(2.5))
    np.testing.assert_allclose(U, [-2.5, 0, 0, 1], atol=1e-15)
    face = bd.Face.make_rect(2, 3, bd.Plane((1, 2, 3), z_dir=(0, 1, 1)))
    V = planes_from_build123d(face)
    np.testing.assert_allclose(V[1:], np.array([0, 1, 1]) / math.sqrt(2), atol=1e-12)
    assert abs(V[0] + V[1:] @ np.array([1, 2, 3])) <= 1e-12
    # a developable from build123d planes
    planes = [planes_from_build123d(bd.Plane((2 * math.cos(p), 2 * math.sin(p), 0), z_dir=(math.cos(p), math.sin(p), 0.3))) for p in (0, 0.4, 0.8)]
    s = developable_from_planes(planes, [planes_from_build123d(bd.Plane.XY), planes_from_build123d(bd.Plane.XY.offset(-1))])
    assert s.developability().theta_max <= 1e-9


def test_bad_input_messages(ship):
    import build123d as bd

    with pytest.raises(GHTError, match=r"not planar; only planar faces define a plane"):
        planes_from_build123d([f for f in bd.Solid.make_cylinder(1, 2).faces() if f.geom_type != bd.GeomType.PLANE][0])
    with pytest.raises(GHTError, match=r"needs a build123d Plane or planar Face, got str"):
        planes_from_build123d("XY")
    with pytest.raises(GHTError, match=r"tol=-1.0 must be a positive finite number"):
        developable_surface_data(ship, tol=-1.0)
    with pytest.raises(GHTError, match=r"surface must be a RuledSurface, got list"):
        developable_surface_data([1, 2])
    with pytest.raises(GHTError, match=r"needs exactly one face; the shape has 6"):
        face_developability(bd.Solid.make_box(1, 1, 1))


@given(st.integers(0, 2**32 - 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
@settings(max_examples=6)
def test_faces_of_perturbed_designs_stay_developable(seed, mu, nu, gamma):
    """Random perturbations of the ship planes (when they give a usable strip): θ_max of the face,
    measured with OCCT normals, stays within 0.01°."""
    rng = np.random.default_rng(seed)
    P = np.array(SHIP) + rng.normal(scale=0.05, size=(4, 4))
    try:
        s = developable_from_planes(P, FRAMES, mu, nu, gamma)
    except GHTError:
        assume(False)
    assert s.developability().theta_max <= 1e-9
    assert face_developability(s.to_face()).theta_max <= THETA_FACE_DEG
