"""build123d / cadquery front ends of the exact developable loft (spec 5.7): OCP edge rails, the
sewn B-spline shell, STEP round trip, builder/algebra mode (the cadquery Workplane method: tests/test_cq_world.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

pytest.importorskip("OCP")
pytest.importorskip("build123d")

from build123d import Axis, BuildLine, BuildPart, BuildSketch, Edge, Mode, Plane, Shell, Face  # noqa: E402
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeVertex  # noqa: E402
from OCP.BRepExtrema import BRepExtrema_DistShapeShape  # noqa: E402
from OCP.gp import gp_Pnt  # noqa: E402
from OCP.TopAbs import TopAbs_REVERSED  # noqa: E402

import ght_cad  # noqa: E402
from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.curves import ght_edge  # noqa: E402
from ght_cad.cad.developable_faces import _internal_edges, face_developability, shell_faces  # noqa: E402
from ght_cad.cad.loft import OCPCurveRail, developable_loft, rail_of  # noqa: E402
from ght_cad.cad.occ import is_valid, read_step, write_step  # noqa: E402
from ght_cad.core.errors import DegenerateGeometryError, GHTError, NotDevelopableError  # noqa: E402

THETA_STEP_DEG = 0.01  # acceptance: twist of every face read back from STEP
COVER_REL = 1e-6  # acceptance: rails covered by the faces' edges, relative to the size
AREA_REL = 1e-6  # acceptance: flat area = STEP face area

# cone x² + y² = (K (Z_APEX - z))², apex (0, 0, Z_APEX): circles r = 5 at z = 0 and r = 2 at z = 6
K, Z_APEX = 0.5, 10.0
APEX = np.array([0.0, 0.0, Z_APEX])

# the dory's chine and sheer (examples/design_hull_plate.toml)
CHINE = GHTCurve([[0, -700, 300], [1500, -1050, 200], [3000, -1150, 250], [4500, -950, 450]])
SHEER = GHTCurve([[0, -900, 1200], [1500, -1250, 1150], [3000, -1300, 1180], [4500, -1100, 1300]])


def _size(shape) -> float:
    bb = shape.bounding_box()
    return float(bb.diagonal)


def _reversed(edge: Edge) -> Edge:
    return Edge(edge.wrapped.Reversed())


def _ruling_apex_distance(shape, apex: np.ndarray, n: int = 101) -> float:
    """max distance (relative to the size) from ``apex`` to the ruling lines of the shape's faces
    (iso-lines of the degree-1 direction of each B-spline face)."""
    from OCP.BRep import BRep_Tool

    worst = 0.0
    for f in shell_faces(shape):
        s = BRep_Tool.Surface_s(f)
        assert s.VDegree() == 1 and s.NbVPoles() == 2
        for u in np.linspace(s.UKnot(1), s.UKnot(s.NbUKnots()), n):
            p, q = s.Value(float(u), 0.0), s.Value(float(u), 1.0)
            A, B = np.array([p.X(), p.Y(), p.Z()]), np.array([q.X(), q.Y(), q.Z()])
            d = (B - A) / np.linalg.norm(B - A)
            worst = max(worst, float(np.linalg.norm(np.cross(apex - A, d))))
    return worst / _size(shape)


def _core_apex_distance(surface, apex: np.ndarray, n: int = 401) -> float:
    """max distance from ``apex`` to the rulings a(u)-b(u) of a core ruled surface (absolute)."""
    u = np.linspace(0.0, 1.0, n)
    A, B = surface.a(u), surface.b(u)
    d = (B - A) / np.linalg.norm(B - A, axis=1)[:, None]
    return float(np.max(np.linalg.norm(np.cross(apex - A, d), axis=1)))


def _rail_cover(shape, rail, n: int = 41) -> float:
    """max distance from points of the rail (t = 0..1) to the shape's edges."""
    worst = 0.0
    pts = rail.evaluate(np.linspace(0.0, 1.0, n))
    edges = [e.wrapped for e in shape.edges()]
    for p in pts:
        v = BRepBuilderAPI_MakeVertex(gp_Pnt(*map(float, p))).Vertex()
        best = math.inf
        for e in edges:
            d = BRepExtrema_DistShapeShape(v, e)
            if d.IsDone():
                best = min(best, d.Value())
        worst = max(worst, best)
    return worst


def _step_checks(shape, rails, tmp_path, name: str) -> dict:
    """STEP round trip: valid, same face count, twist per face, rails covered, flat area = face area."""
    path = tmp_path / f"{name}.step"
    write_step(shape, path)
    back = read_step(path)
    assert is_valid(back)
    faces = shell_faces(back)
    assert len(faces) == len(shell_faces(shape))
    theta = max(face_developability(Face(f)).theta_max for f in faces)
    assert theta <= THETA_STEP_DEG, theta
    from build123d import Shape

    back_shape = Shape.cast(back)
    size = _size(back_shape)
    cover = max(_rail_cover(back_shape, r) for r in rails)
    assert cover <= COVER_REL * size, (cover, size)
    flat = ght_cad.unroll(shape.ght_loft)
    assert len(flat.panels) == 1  # one panel, fans included
    step_area = sum(p.area_3d for p in ght_cad.unroll(back_shape).panels)
    assert abs(flat.area - step_area) <= AREA_REL * step_area, (flat.area, step_area)
    return {"theta": theta, "cover": cover / size, "area": abs(flat.area - step_area) / step_area}


# -- rails ------------------------------------------------------------------------------------
@given(st.floats(0.0, 1.0), st.sampled_from([False, True]))
def test_edge_rail_derivatives_of_a_circle(t: float, reverse: bool) -> None:
    """OCPCurveRail on a circle edge of radius R: r(t) = R(cos 2πt, sin 2πt) (reversed: angle
    2π(1 - t)), r^(k)(t) the closed-form k-th derivatives (1e-12 relative)."""
    R = 3.0
    edge = Edge.make_circle(R)
    rail = OCPCurveRail(_reversed(edge) if reverse else edge)
    w = -2 * math.pi if reverse else 2 * math.pi
    ph = 2 * math.pi * (1 - t) if reverse else 2 * math.pi * t
    closed = [
        R * np.array([math.cos(ph), math.sin(ph), 0.0]),
        R * w * np.array([-math.sin(ph), math.cos(ph), 0.0]),
        R * w**2 * np.array([-math.cos(ph), -math.sin(ph), 0.0]),
        R * w**3 * np.array([math.sin(ph), -math.cos(ph), 0.0]),
    ]
    for k, ref in enumerate(closed):
        got = rail.derivative(t, k)[0]
        assert np.linalg.norm(got - ref) <= 1e-12 * np.linalg.norm(ref) * 10, (k, got, ref)


def _edges_of_every_kind() -> dict[str, Edge]:
    from build123d import Location

    moved = Location((1.0, -2.0, 0.5), (20.0, 35.0, -10.0))
    return {
        "line": Edge.make_line((0, 0, 0), (3, 1, 2)),
        "circle arc": Edge.make_circle(2.0, start_angle=30, end_angle=250).moved(moved),
        "ellipse": Edge.make_ellipse(4.0, 1.5).moved(moved),
        "bspline": Edge.make_spline([(0, 0, 0), (1, 2, 0), (3, 2, 1), (4, 0, 2)]).moved(moved),
        "periodic bspline": Edge.make_spline([(0, 0, 0), (2, 1, 0), (3, 3, 1), (0, 2, 2)], periodic=True),
        "rational bspline (GHT certified)": ght_edge(CHINE),
        "bezier": Edge.make_bezier((0, 0, 0), (1, 3, 0), (3, 3, 1), (4, 0, 0)),
    }


@pytest.mark.parametrize("kind", list(_edges_of_every_kind()))
def test_closed_form_rail_equals_occt_dn(kind: str) -> None:
    """The numpy closed forms of OCPCurveRail (line, circle, ellipse, Bézier, B-spline; moved
    edges; reversed) equal OCCT's BRepAdaptor_Curve.DN point by point (1e-10 of the scale)."""
    edge = _edges_of_every_kind()[kind]
    t = np.linspace(0.0, 1.0, 37)
    for e in (edge, _reversed(edge)):
        fast = OCPCurveRail(e)
        assert fast._exact is not None, kind
        slow = OCPCurveRail(e)
        slow._exact = None
        for k in range(4):
            a, b = fast.derivative(t, k), slow.derivative(t, k)
            scale = max(float(np.max(np.linalg.norm(b, axis=1))), float(np.max(np.linalg.norm(slow.derivative(t, 0), axis=1))))
            assert np.max(np.linalg.norm(a - b, axis=1)) <= 1e-10 * scale, (kind, k)


def test_rail_of_kinds_and_refusals() -> None:
    circle = Edge.make_circle(1.0)
    assert isinstance(rail_of(circle), OCPCurveRail)
    assert isinstance(rail_of(circle.wrapped), OCPCurveRail)
    from build123d import Wire

    assert isinstance(rail_of(Wire([circle])), OCPCurveRail)
    assert rail_of(CHINE) is CHINE
    with pytest.raises(GHTError, match="rail_a is a face"):
        rail_of(Face.make_rect(1, 1), "rail_a")
    with pytest.raises(GHTError, match="is a float"):
        rail_of(1.5)
    with pytest.raises(GHTError, match="order=4"):
        OCPCurveRail(circle).derivative(0.5, 4)
    with pytest.raises(GHTError, match="unknown loft option"):
        developable_loft(circle, Edge.make_circle(2.0, Plane.XY.offset(3)), tolerance=1e-3)


# -- known developables ----------------------------------------------------------------------
@pytest.fixture(scope="module")
def cone_pair() -> tuple[Edge, Edge]:
    return Edge.make_circle(5.0), Edge.make_circle(2.0, Plane.XY.offset(6.0))


@pytest.mark.parametrize("reverse_b", [False, True])
def test_cone_circles_give_the_cone(cone_pair, reverse_b: bool, tmp_path) -> None:
    """Two full circles of a cone (one edge reversed): one valid face closed by a seam, rulings
    through the apex, twist/coverage/area after STEP within the acceptance tolerances."""
    ea, eb = cone_pair
    eb = _reversed(eb) if reverse_b else eb
    shape = developable_loft(ea, eb)
    loft = shape.ght_loft
    assert [sg.kind for sg in loft.segments] == ["main"]
    assert loft.reversed_b is reverse_b
    assert isinstance(shape, Face) and is_valid(shape)
    # closed around: the two ruling edges were sewn into one seam edge (3 edges: 2 circles + seam)
    assert len(shape.edges()) == 3
    # the core's rulings through the apex to round-off, the B-rep's within the fit tolerance
    assert _core_apex_distance(loft, APEX, 401) <= 1e-9 * _size(shape)
    assert _ruling_apex_distance(shape, APEX) <= 1e-6
    # flat pattern: annular sector of the frustum, slant radii ρ = z' sqrt(1 + K²) from the apex
    rho1, rho2 = Z_APEX * math.hypot(1, K), (Z_APEX - 6.0) * math.hypot(1, K)
    exact = 0.5 * (2 * math.pi * 5.0 / rho1) * (rho1**2 - rho2**2)
    assert abs(ght_cad.unroll(loft).area - exact) <= 1e-9 * exact
    res = _step_checks(shape, [OCPCurveRail(ea), OCPCurveRail(eb)], tmp_path, "cone")
    print(f"cone circles (reverse_b={reverse_b}): STEP θ_max={res['theta']:.3g}°, cover {res['cover']:.2g}, area {res['area']:.2g}")


def test_cone_with_offset_starts_gets_fans_in_one_closed_shell(cone_pair, tmp_path) -> None:
    """Rail b's start turned by 40°: fans at the rail ends complete the loft; the three faces sew
    into one valid shell closed around (3 shared rulings), fans' apexes at rail ends."""
    ea, eb = cone_pair
    eb = eb.rotate(Axis.Z, 40)
    shape = developable_loft(ea, eb)
    loft = shape.ght_loft
    assert [sg.kind for sg in loft.segments] == ["fan_b", "main", "fan_a"]
    assert isinstance(shape, Shell) and is_valid(shape)
    assert len(_internal_edges(shape.wrapped)) == 3
    np.testing.assert_allclose(loft.segments[0].apex, OCPCurveRail(eb).evaluate(0.0)[0], atol=1e-9)
    np.testing.assert_allclose(loft.segments[2].apex, OCPCurveRail(ea).evaluate(1.0)[0], atol=1e-9)
    # the main part still lies on the cone: its rulings pass through the apex
    main = loft.segments[1]
    assert _core_apex_distance(main, APEX, 201) <= 1e-9 * _size(shape)
    _step_checks(shape, [OCPCurveRail(ea), OCPCurveRail(eb)], tmp_path, "cone_fans")


def test_elliptic_cone_from_ellipse_edges(tmp_path) -> None:
    """Two similar ellipses about the apex (0, 0, 8) (ellipse edges, scale 1/2): an elliptic cone,
    rulings through the apex."""
    ea = Edge.make_ellipse(6.0, 3.0)
    eb = Edge.make_ellipse(3.0, 1.5, Plane.XY.offset(4.0))
    shape = developable_loft(ea, eb)
    loft = shape.ght_loft
    assert [sg.kind for sg in loft.segments] == ["main"]
    apex = np.array([0.0, 0.0, 8.0])
    assert _core_apex_distance(loft, apex) <= 1e-9 * _size(shape)
    assert _ruling_apex_distance(shape, apex) <= 1e-6
    _step_checks(shape, [OCPCurveRail(ea), OCPCurveRail(eb)], tmp_path, "ellipse")


def test_quarter_circle_edge_and_ght_rail() -> None:
    """Mixed rails: a build123d arc edge (r = 5, z = 0) and a GHT quarter circle (γ = -1, r = 2,
    z = 6) on the same cone: one face, rulings through the apex."""
    ea = Edge.make_circle(5.0, start_angle=0, end_angle=90)
    r = 2.0
    eb = GHTCurve([(r, 0, 6), (r, r, 6), (0, r, 6)], gamma=-1)
    shape = developable_loft(ea, eb)
    loft = shape.ght_loft
    assert [sg.kind for sg in loft.segments] == ["main"]
    assert _core_apex_distance(loft, APEX, 201) <= 1e-9 * _size(shape)


# -- a boat panel between B-spline edges -------------------------------------------------------
@pytest.fixture(scope="module")
def dory_shape():
    return developable_loft(ght_edge(CHINE), ght_edge(SHEER))


def test_dory_panel_from_bspline_edges(dory_shape, tmp_path) -> None:
    """Chine and sheer as certified B-spline edges: fans at the sheer's ends, one valid shell with
    2 shared rulings, θ ≤ 1e-8° in the core, ≤ 0.01° from STEP, rails covered, flat = STEP area."""
    loft = dory_shape.ght_loft
    assert [sg.kind for sg in loft.segments] == ["fan_b", "main", "fan_b"]
    assert isinstance(dory_shape, Shell) and is_valid(dory_shape)
    assert len(_internal_edges(dory_shape.wrapped)) == 2
    assert loft.report.theta_max_deg <= 1e-8
    size = _size(dory_shape)
    assert dory_shape.ght_max_deviation <= 1e-7 * size
    res = _step_checks(dory_shape, [CHINE, SHEER], tmp_path, "dory")
    print(f"dory: STEP θ_max={res['theta']:.3g}°, cover {res['cover']:.2g} of size, area {res['area']:.2g}")


def test_edge_rails_equal_ght_rails(dory_shape) -> None:
    """The loft between the B-spline edges equals the loft between the exact GHT curves: same
    segments; σ (which depends on the rails' tangents, fitted to 1e-7 of the size in position)
    agrees to 1e-5 (measured 1.0e-6), the fan share to 1e-6."""
    exact = ght_cad.developable_loft(CHINE, SHEER)
    loft = dory_shape.ght_loft
    assert [sg.kind for sg in loft.segments] == [sg.kind for sg in exact.segments]
    t = np.linspace(0.05, 0.95, 19)
    assert np.max(np.abs(loft.sigma(t) - exact.sigma(t))) <= 1e-5
    assert abs(loft.report.fan_share - exact.report.fan_share) <= 1e-6


# -- refusals -----------------------------------------------------------------------------------
def test_skew_lines_refused() -> None:
    a = Edge.make_line((0, 0, 0), (10, 0, 0))
    b = Edge.make_line((0, 5, 3), (0, 8, 10))
    with BuildPart() as part:
        with pytest.raises(NotDevelopableError, match="no developable joins the rails"):
            developable_loft(a, b)
    assert part.pending_faces == []  # nothing half added
    with pytest.raises(DegenerateGeometryError, match="coplanar"):
        developable_loft(a, Edge.make_line((0, 2, 0), (10, 3, 0)))


# -- builder and algebra mode -------------------------------------------------------------------
def test_builder_mode_adds_pending_faces(cone_pair) -> None:
    ea, eb = cone_pair
    eb = eb.rotate(Axis.Z, 40)
    with BuildPart() as part:
        shape = developable_loft(ea, eb)
    assert len(part.pending_faces) == len(shape.faces()) == 3
    with BuildPart() as private:
        developable_loft(ea, eb, mode=Mode.PRIVATE)
    assert private.pending_faces == []
    with BuildSketch():
        with pytest.raises(GHTError, match="BuildSketch"):
            developable_loft(ea, eb)
    with BuildLine():
        with pytest.raises(GHTError, match="BuildLine"):
            developable_loft(ea, eb)


def test_builder_thicken_gives_a_valid_solid() -> None:
    """A half cone's loft faces in BuildPart thicken into a sheet: |V - T A| <= T A · T max|H|
    (offset volume T A + T² ∫H dA; mean curvature H = 1/(2 r) <= 1/4 for radii r >= 2)."""
    from build123d import thicken

    ea = Edge.make_circle(5.0, start_angle=0, end_angle=180)
    eb = Edge.make_circle(2.0, Plane.XY.offset(6.0), start_angle=0, end_angle=180)
    with BuildPart() as part:
        shape = developable_loft(ea, eb)
        thicken(amount=0.2)
    assert part.part.is_valid
    area = ght_cad.unroll(shape.ght_loft).area
    assert abs(part.part.volume - 0.2 * area) <= (0.2 * 0.25) * 0.2 * area


# -- the example --------------------------------------------------------------------------------
def test_example_build123d_loft(tmp_path) -> None:
    """examples/build123d_loft.py: round-to-oval transition, one panel, STEP twist/area acceptance."""
    import importlib.util
    from pathlib import Path

    import ezdxf

    path = Path(__file__).resolve().parent.parent / "examples" / "build123d_loft.py"
    spec = importlib.util.spec_from_file_location("example_build123d_loft", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    res = mod.main(tmp_path)
    assert res["segments"] == ["main"] and res["panels"] == 1
    assert res["valid"] and res["sheet_valid"]
    assert res["theta_core_deg"] <= 1e-8 and res["theta_step_deg"] <= THETA_STEP_DEG
    assert res["area_rel_error"] <= AREA_REL
    # the 2 mm sheet: volume = T × area to O(T / radius) (radii >= 22 here: within 2%)
    assert abs(res["sheet_volume"] - mod.T * res["flat_area"]) <= 0.02 * mod.T * res["flat_area"]
    ezdxf.readfile(res["dxf"])
    assert Path(res["svg"]).stat().st_size > 0 and Path(res["png"]).stat().st_size > 0
