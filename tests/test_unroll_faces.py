"""Unrolling build123d/OCP faces: closed forms, B-spline developables, holes, refusals, flatmesh."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import build123d as bd
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from conftest import freecadcmd_or_skip
from ght_cad.surfaces.bspline import BSplineSurfaceData
from ght_cad.cad.occ import make_face
from ght_cad.cad.unroll_faces import face_ruling_direction, unroll_face
from ght_cad.core.errors import GHTError, NotDevelopableError
from ght_cad.unrolling.unroll import unroll, unroll_composite

RTOL = 1e-9


def _face(shape, kind):
    return next(f for f in shape.faces() if f.geom_type == kind)


def _length(edge) -> float:
    """Arc length of an edge by adaptive quadrature of |c'| (scipy, relative 1e-13)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.gp import gp_Pnt, gp_Vec

    c = BRepAdaptor_Curve(edge.wrapped)
    p, v = gp_Pnt(), gp_Vec()

    def speed(t: float) -> float:
        c.D1(t, p, v)
        return v.Magnitude()

    return quad(speed, c.FirstParameter(), c.LastParameter(), epsabs=0, epsrel=1e-13, limit=400)[0]


def _edge_lengths(pat):
    return [(e.length_3d, e.length_flat) for lp in pat.panels[0].loops for e in lp]


@pytest.mark.parametrize("R, H, arc", [(2.0, 5.0, 360), (7.5, 3.0, 90), (0.3, 11.0, 200)])
def test_cylinder_face_is_rectangle(R: float, H: float, arc: float) -> None:
    f = _face(bd.Cylinder(R, H, arc_size=arc), bd.GeomType.CYLINDER)
    pat = unroll(f, rulings=5)
    out = pat.outlines[0]
    w = R * math.radians(arc)
    np.testing.assert_allclose(np.ptp(out, axis=0), [w, H], rtol=RTOL)
    np.testing.assert_allclose(pat.area, w * H, rtol=RTOL)
    # every outline point lies on the rectangle's border
    x, y = out[:, 0] - out[:, 0].min(), out[:, 1] - out[:, 1].min()
    border = np.minimum.reduce([np.abs(x), np.abs(x - w), np.abs(y), np.abs(y - H)])
    assert border.max() < RTOL * max(w, H)
    assert pat.errors["max"] < 1e-12
    assert len(pat.bend_lines) == 5


@pytest.mark.parametrize("r1, r2, h, arc", [(1.0, 2.0, 1.5, 90), (4.0, 1.0, 2.0, 360), (2.0, 3.0, 0.5, 120)])
def test_cone_face_is_annular_sector(r1: float, r2: float, h: float, arc: float) -> None:
    """Sector radii ρ = slant · r / |r2 - r1| and angle θ r_big / ρ_big (2π r/ρ for a full cone)."""
    f = _face(bd.Solid.make_cone(r1, r2, h, angle=arc), bd.GeomType.CONE)
    pat = unroll(f, rulings=3)
    slant = math.hypot(r2 - r1, h)
    rho = {r: slant * r / abs(r2 - r1) for r in (r1, r2)}
    angle = math.radians(arc) * r2 / rho[r2]
    panel = pat.panels[0]
    # apex image: the closed-form map F = ρ (cos su, sin su) sends the apex (ρ = 0) to the origin,
    # which placement moves to the panel offset
    C = panel.offset
    pts = np.concatenate([e.flat for e in panel.loops[0]]) + panel.offset
    d = np.linalg.norm(pts - C, axis=1)
    lo, hi = sorted(rho.values())
    assert d.min() == pytest.approx(lo, rel=RTOL)
    assert d.max() == pytest.approx(hi, rel=RTOL)
    on_arc = np.minimum(np.abs(d - lo), np.abs(d - hi)) < RTOL * hi
    radial = ~on_arc
    assert on_arc.sum() > 100 and radial.sum() > 10
    ang = np.unwrap(np.arctan2(pts[:, 1] - C[1], pts[:, 0] - C[0]))
    assert np.ptp(ang) == pytest.approx(angle, rel=RTOL)
    assert pat.area == pytest.approx(0.5 * angle * (hi**2 - lo**2), rel=RTOL)
    assert pat.errors["max"] < 1e-12


def test_extrusion_face_is_rectangle() -> None:
    edge = bd.Edge.make_spline([(0, 0, 0), (1, 0.5, 0), (2, -0.3, 0), (3, 0, 0)])
    f = bd.Face.extrude(edge, (0, 0, 2.5))
    assert f.geom_type == bd.GeomType.EXTRUSION
    pat = unroll(f, rulings=4)
    L = _length(edge)
    np.testing.assert_allclose(np.ptp(pat.outlines[0], axis=0), [L, 2.5], rtol=RTOL)
    assert pat.area == pytest.approx(2.5 * L, rel=RTOL)
    assert pat.panels[0].info["method"].startswith("quadrature")


def test_oblique_extrusion_preserves_lengths_and_area() -> None:
    edge = bd.Edge.make_spline([(0, 0, 0), (1, 0.5, 0), (2, -0.3, 0), (3, 0, 0)])
    pat = unroll(bd.Face.extrude(edge, (0.3, 0, 2)))
    assert pat.errors["max"] < 1e-12
    # parallel rulings: every bend line has the extrusion length |(0.3, 0, 2)|
    lens = np.linalg.norm(pat.bend_lines[:, 1] - pat.bend_lines[:, 0], axis=1)
    np.testing.assert_allclose(lens, math.hypot(0.3, 2.0), rtol=1e-12)


def _tangent_developable_face(v0: float = 0.3, v1: float = 1.0, transpose: bool = False):
    """Tangent developable of c(t) = (t, t², t³): a = c + v0 c', b = c + v1 c' as an exact cubic ×
    linear Bézier B-spline face (exactly developable)."""
    M = np.array([[1, 0, 0, 0], [1, 1 / 3, 0, 0], [1, 2 / 3, 1 / 3, 0], [1, 1, 1, 1]])
    c = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    cp = np.array([[1, 0, 0], [0, 2, 0], [0, 0, 3], [0, 0, 0]], float)
    net = np.stack([M @ (c + v0 * cp), M @ (c + v1 * cp)], axis=1)
    if transpose:
        return make_face(BSplineSurfaceData(net.transpose(1, 0, 2), [0, 0, 1, 1], [0] * 4 + [1] * 4, 1, 3))
    return make_face(BSplineSurfaceData(net, [0] * 4 + [1] * 4, [0, 0, 1, 1], 3, 1))


@pytest.mark.parametrize("transpose", [False, True])
def test_bspline_developable_face_preserves_lengths_and_area(transpose: bool) -> None:
    f = _tangent_developable_face(transpose=transpose)
    assert face_ruling_direction(f)[0] == ("u" if transpose else "v")
    pat = unroll(f)
    e = pat.errors
    assert e["boundary_length"] < 1e-10 and e["ruling_length"] < 1e-10 and e["area"] < 1e-10
    for L3, L2 in _edge_lengths(pat):
        assert L2 == pytest.approx(L3, rel=1e-10)


def test_affine_ruled_face_maps_like_the_projection() -> None:
    """A polynomial face of degree 1 across (the tangent developable) is affine along its rulings:
    it is ruled by structure (no isoline measurement) and mapped with its own ruling parameter;
    projecting every point onto its ruling instead gives the same pattern (outline, bend lines,
    area) to 1e-12 of its size."""
    from ght_cad.cad.unroll_faces import _open_face, face_data
    from ght_cad.unrolling.face_unroll import unroll_face_data

    tf, _, bounds, ev = _open_face(_tangent_developable_face())
    assert ev.ruled_hint == "v" and ev.affine_ruled
    fast = unroll_face_data(face_data(tf, ev, bounds))
    ev.affine_ruled = False
    slow = unroll_face_data(face_data(tf, ev, bounds))
    assert fast.panels[0].info["ruled_by"] == "structure" and fast.panels[0].info["deviation_v"] == 0.0
    size = float(np.ptp(slow.outlines[0], axis=0).max())
    np.testing.assert_allclose(fast.outlines[0], slow.outlines[0], rtol=0, atol=1e-12 * size)
    np.testing.assert_allclose(fast.bend_lines, slow.bend_lines, rtol=0, atol=1e-12 * size)
    assert fast.area == pytest.approx(slow.area, rel=1e-13)


def test_weights_across_the_rulings_are_not_affine() -> None:
    """Weights 1 and 2 on the two rows of a ruled Bézier face reparametrize its rulings (u is not
    affine along them) without changing the surface: not affine_ruled, and the pattern is the
    same rectangle as the unweighted face's."""
    from ght_cad.cad.unroll_faces import _open_face

    row = np.array([(0, 0, 0), (1, 0, 1), (2, 0, 0), (3, 0, 1)], float)
    pts = [[tuple(p) for p in row], [tuple(p + (0.0, 2.0, 0.0)) for p in row]]
    plain = bd.Face.make_bezier_surface(pts)
    weighted = bd.Face.make_bezier_surface(pts, weights=[[1.0] * 4, [2.0] * 4])
    assert _open_face(plain)[3].affine_ruled and not _open_face(weighted)[3].affine_ruled
    p0, p1 = unroll(plain), unroll(weighted)
    np.testing.assert_allclose(np.sort(np.ptp(p1.outlines[0], axis=0)), np.sort(np.ptp(p0.outlines[0], axis=0)), rtol=1e-12)
    assert p1.area == pytest.approx(p0.area, rel=1e-12) and p1.errors["max"] < 1e-10


def test_project_developable_face_matches_ruled_unroll() -> None:
    """developable_from_planes(...).to_face() (B-spline, degree 1 across): 1e-7 or better, and
    the same area as unrolling the exact surface (up to the face's fit tolerance)."""
    from ght_cad import developable_from_planes

    planes = [(-10.0, 1.0, 0.0, 0.2), (-10.0, 1.0, 1.0, 0.1), (-10.0, 0.0, 1.0, 0.2)]
    boundary = [(0.0, 0.0, 0.0, 1.0), (-20.0, 0.0, 0.0, 1.0)]
    surf = developable_from_planes(planes, boundary, 0.1, -0.2, -0.6)
    face = surf.to_face()
    pf = unroll(face)
    ps = unroll(surf)
    assert pf.errors["max"] < 1e-9
    assert ps.errors["max"] < 1e-12
    assert pf.area == pytest.approx(ps.area, rel=1e-6)


def test_dxf_of_faces_with_holes_lines_and_arcs(tmp_path) -> None:
    """DXF for CAM of STEP-like faces with holes (issue 25): a plate 40 × 30 drilled with r = 5
    writes its outline as 4 exact lines and the hole as exact arcs of radius 5 (area on ezdxf's
    path 1200 - 25π to 1e-12); the half cylinder R = 20 pierced by r = 5 writes its rectangle as 4
    lines (the circles develop to lines) and the hole (not a circle in the flat) as arcs within
    the 1e-3 mm chord tolerance, R2010 and R12 giving the exact flat area within chord_tol × the
    hole's length and 1e-7 (measured 8.6e-9)."""
    from dxf_read import dxf_outline_areas, outline_bulges, outline_entities

    plate = bd.Box(40.0, 30.0, 5.0) - bd.Cylinder(5.0, 10.0)
    top = max(plate.faces().filter_by(bd.GeomType.PLANE), key=lambda f: f.center().Z)
    pat = unroll(top)
    kinds = [k for _, _, k in pat.panels[0].loop_arcs(pat.chord_tol)]
    assert kinds[0] == ["line"] * 4 and set(kinds[1]) <= {"arc", "arcs"}, kinds
    ents = outline_entities(pat.export_dxf(tmp_path / "plate.dxf"))
    outer, hole = sorted(ents, key=lambda e: -len(e))
    assert not np.any(outline_bulges(outer))
    b = outline_bulges(hole)
    assert np.all(b != 0) and 4 * np.sum(np.abs(np.arctan(b))) == pytest.approx(2 * math.pi, rel=1e-12)
    a_out, a_hole = sorted(dxf_outline_areas(tmp_path / "plate.dxf"), reverse=True)
    assert a_out - a_hole == pytest.approx(1200.0 - 25.0 * math.pi, rel=1e-12)

    part = bd.Cylinder(20.0, 50.0, arc_size=180) - bd.Cylinder(5.0, 100.0, rotation=(90, 0, 0))
    pat = unroll(_face(part, bd.GeomType.CYLINDER), rulings=4)
    kinds = [k for _, _, k in pat.panels[0].loop_arcs(pat.chord_tol)]
    assert all(k == "line" for k in kinds[0]) and "curve" in kinds[1], kinds
    (tmp_path / "r12.dxf").write_text(pat.dxf_r12_text())
    for path in (pat.export_dxf(tmp_path / "cyl.dxf"), tmp_path / "r12.dxf"):
        a_out, a_hole = sorted(dxf_outline_areas(path), reverse=True)
        hole_length = sum(e.length_flat for e in pat.panels[0].loops[1])
        assert abs(a_out - a_hole - pat.area) <= min(pat.chord_tol * hole_length, 1e-7 * pat.area)


def test_holes_and_planar_face_output() -> None:
    """Half cylinder (R=20) pierced by a cylinder (r=5): the hole is kept; areas match the exact
    integral; the planar build123d face has the hole as inner wire."""
    part = bd.Cylinder(20.0, 50.0, arc_size=180) - bd.Cylinder(5.0, 100.0, rotation=(90, 0, 0))
    f = _face(part, bd.GeomType.CYLINDER)
    pat = unroll(f, rulings=20)
    assert len(pat.outlines) == 2
    th0 = math.acos(0.25)
    hole, _ = quad(lambda t: 2 * math.sqrt(max(25 - 400 * math.cos(t) ** 2, 0.0)) * 20, th0, math.pi - th0,
                   epsabs=0, epsrel=1e-13, limit=200)
    exact = math.pi * 20 * 50 - hole
    assert pat.area == pytest.approx(exact, rel=1e-9)
    # boundary lengths against the edges' own 3-D curves: the boolean's intersection curve lies
    # within its tolerance 1e-7 of the surface, its length differs from the pcurve image's by 3.2e-10
    assert pat.errors["max"] < 1e-9
    # bend lines are clipped by the hole: some rulings are split in two
    assert len(pat.bend_lines) > 20
    # clipped in (u, v): every end lies on the outline (outer boundary or hole); the cylinder's
    # development (R u, v) is linear, so the (u, v) polyline maps onto the flat one exactly
    ends = pat.bend_lines.reshape(-1, 2)
    d = np.full(len(ends), np.inf)
    for poly in pat.panels[0].loop_polylines():
        a, b = poly, np.roll(poly, -1, axis=0)
        s = np.clip(np.einsum("pkj,kj->pk", ends[:, None, :] - a[None], b - a) / np.einsum("kj,kj->k", b - a, b - a), 0, 1)
        d = np.minimum(d, np.linalg.norm(a[None] + s[..., None] * (b - a)[None] - ends[:, None, :], axis=2).min(axis=1))
    assert d.max() < 1e-12 * 50
    flat = pat.to_face()
    assert isinstance(flat, bd.Face) and len(flat.inner_wires()) == 1
    assert flat.area == pytest.approx(pat.area, rel=1e-7)
    assert flat.geom_type == bd.GeomType.PLANE
    assert abs(abs(flat.normal_at().Z) - 1.0) < 1e-12
    assert max(abs(v.Z) for v in flat.vertices()) < 1e-12


def test_non_ruled_face_is_refused_with_deviation() -> None:
    sphere = bd.Sphere(3.0).faces()[0]
    with pytest.raises(NotDevelopableError, match="not ruled") as exc:
        unroll(sphere)
    assert "u-isolines" in str(exc.value) and "best_effort" in str(exc.value)
    # best_effort on a hemisphere: rulings from the equator to the pole (a cone); the report
    # shows the distortion (a full sphere is refused: test_full_sphere_best_effort_is_refused_naming_poles)
    pat = unroll(bd.Sphere(3.0, arc_size1=0).faces()[0], best_effort=True)
    assert pat.errors["max"] > 1e-2


def test_twisted_bilinear_face_is_refused_with_theta() -> None:
    net = np.array([[[0, 0, 0], [0, 1, 1]], [[1, 0, 0], [1, 1, 0]]], float)
    f = make_face(BSplineSurfaceData(net, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1))
    with pytest.raises(NotDevelopableError, match=r"theta_max=45 deg.*DD=0\.75"):
        unroll(f)
    pat = unroll(f, best_effort=True)
    assert pat.errors["area"] > 1e-3


def test_face_input_errors() -> None:
    with pytest.raises(GHTError, match="6 faces.*unroll_composite"):
        unroll_face(bd.Box(1, 2, 3))
    with pytest.raises(GHTError, match="cannot unroll"):
        unroll_face(42)


@settings(max_examples=6, deadline=None)
@given(
    R=st.floats(5.0, 40.0),
    ratio=st.floats(0.05, 0.6),
    phi=st.floats(0.0, 360.0),
    z_frac=st.floats(0.2, 0.8),
)
def test_radially_drilled_cylinder_over_a_parameter_box(R: float, ratio: float, phi: float, z_frac: float) -> None:
    """A cylinder R × 2R drilled through its axis (r = ratio R) at any angle φ, the holes
    anywhere including across the seam: area 2π R H − 2 ∫ 2 R asin(√(r² − z²)/R) dz to 1e-9,
    every hole inside the outline, boundary lengths to the model's edge tolerance (1e-8)."""
    H, r = 2 * R, ratio * R
    z = r + z_frac * (H - 2 * r)
    drill = bd.Pos(0, 0, z) * bd.Rot(0, 0, phi) * bd.Cylinder(r, 3 * R, rotation=(0, 90, 0))
    part = bd.Cylinder(R, H, align=(bd.Align.CENTER, bd.Align.CENTER, bd.Align.MIN)) - drill
    f = max((f for f in part.faces() if f.geom_type == bd.GeomType.CYLINDER), key=lambda f: f.area)
    pat = unroll(f, rulings=2, samples=65)
    hole = quad(lambda t: 2 * R * math.asin(math.sqrt(max(r * r - t * t, 0.0)) / R), -r, r, epsabs=0, epsrel=1e-13, limit=200)[0]
    exact = 2 * math.pi * R * H - 2 * hole
    assert pat.area == pytest.approx(exact, rel=1e-9)
    assert pat.panels[0].area_3d == pytest.approx(exact, rel=1e-9)
    outline = pat.outlines[0]
    np.testing.assert_allclose(np.ptp(outline, axis=0), [2 * math.pi * R, H], rtol=1e-9)
    for loop in pat.outlines[1:]:
        assert np.all(loop.min(axis=0) > outline.min(axis=0)) and np.all(loop.max(axis=0) < outline.max(axis=0))
    assert pat.errors["boundary_length"] < 1e-8 and pat.errors["area"] < 1e-9


@pytest.mark.parametrize("which", ["plane", "cylinder"])
def test_unbounded_face_is_refused(which: str) -> None:
    """Faces of whole OCCT surfaces (BRepBuilderAPI_MakeFace(gp_Pln()), an infinite cylinder):
    bounds ±2e100 (OCCT 8: ±1e100 for the cylinder; before: ZeroDivisionError for the plane, 'wire 2
    (a hole) lies outside the outer wire' for the cylinder)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeFace
    from OCP.gp import gp_Ax3, gp_Cylinder, gp_Pln

    from ght_cad.core.errors import DegenerateGeometryError

    geom = gp_Pln() if which == "plane" else gp_Cylinder(gp_Ax3(), 5.0)
    face = bd.Face(BRepBuilderAPI_MakeFace(geom).Face())
    with pytest.raises(DegenerateGeometryError, match=r"unbounded or empty: parameter bounds .*[12]e\+100.*allowed: a face trimmed"):
        unroll(face)


def test_composite_of_cylinder_faces_marks_shared_edges() -> None:
    faces = bd.Cylinder(2.0, 5.0).faces()
    pat = unroll_composite(list(faces), rulings=4)
    assert len(pat.panels) == 3
    marks = [t[2] for t in pat.labels if t[2].startswith("E")]
    # the two circles (side/top, side/bottom) and the seam (two sides of the rectangle)
    assert sorted(set(marks)) == ["E1", "E2", "E3"] and len(marks) == 6
    assert pat.errors["max"] < 1e-12


def _load_bench():
    path = Path(__file__).resolve().parents[1] / "bench" / "flatmesh_compare.py"
    spec = importlib.util.spec_from_file_location("flatmesh_compare", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.freecad
def test_error_is_100x_smaller_than_freecad_flatmesh() -> None:
    exe = freecadcmd_or_skip()
    bench = _load_bench()
    faces = {
        "cone": _face(bd.Solid.make_cone(20.0, 40.0, 30.0, angle=90), bd.GeomType.CONE),
        "tangent_dev": _tangent_developable_face(),
    }
    rows = bench.compare(faces, rel_deflection=1e-3, freecadcmd=exe)
    for r in rows:
        assert r["fm_nodes"] > 20
        assert r["ours_err"] * 100 <= r["fm_err"], r
    cone = rows[0]
    assert cone["ours_err"] * 100 <= cone["fm_err_intrinsic"], cone  # also vs flatmesh's own mesh


def test_shell_gives_one_panel_per_face() -> None:
    """A box (6 faces, 12 edges): 6 labelled panels, every edge marked on its two panels."""
    pat = unroll(bd.Box(1.0, 2.0, 3.0), rulings=0)
    assert len(pat.panels) == 6
    marks = [t[2] for t in pat.labels if t[2].startswith("E")]
    assert len(set(marks)) == 12 and len(marks) == 24
    np.testing.assert_allclose(pat.area, 2 * (2 + 3 + 6), rtol=1e-12)
    boxes = [p.bbox() for p in pat.panels]
    for i in range(6):
        for j in range(i + 1, 6):
            (lo1, hi1), (lo2, hi2) = boxes[i], boxes[j]
            assert (hi1 < lo2).any() or (hi2 < lo1).any(), "panels overlap"
    tops = {round(float(hi[1]), 9) for _, hi in boxes}
    assert len(tops) >= 2  # six panels are packed in more than one row (rows align their tops)


def test_bezier_and_rational_bezier_faces() -> None:
    """Bézier ruled faces (rulings along u here): a general cylinder on a cubic, and a rational
    one on a weighted cubic (the rulings are lines but v is not affine along them) -> rectangles."""
    row = np.array([(0, 0, 0), (1, 0, 1), (2, 0, 0), (3, 0, 1)], float)
    shift = np.array([0.0, 2.0, 0.0])
    pts = [[tuple(p) for p in row], [tuple(p + shift) for p in row]]
    for weights in (None, [[1.0, 2.0, 0.5, 1.0], [1.0, 2.0, 0.5, 1.0]]):
        f = bd.Face.make_bezier_surface(pts, weights=weights)
        assert f.geom_type == bd.GeomType.BEZIER
        assert face_ruling_direction(f)[0] == "u"
        pat = unroll(f)
        width = _length(next(e for e in f.edges() if abs(e.length - 2.0) > 1e-6))
        np.testing.assert_allclose(np.sort(np.ptp(pat.outlines[0], axis=0)), np.sort([width, 2.0]), rtol=RTOL)
        assert pat.errors["max"] < 1e-10


def _torus_face(major_angle: float = 360.0):
    return _face(bd.Torus(10.0, 2.0, major_angle=major_angle), bd.GeomType.TORUS)


def _vase_face():
    """A revolved spline profile: a closed surface of revolution that is not ruled."""
    with bd.BuildPart() as p:
        with bd.BuildSketch(bd.Plane.XZ):
            with bd.BuildLine():
                bd.Spline((2, 0), (4, 5), (3, 10))
                bd.Polyline((3, 10), (0, 10), (0, 0), (2, 0))
            bd.make_face()
        bd.revolve(axis=bd.Axis.Z)
    return _face(p.part, bd.GeomType.REVOLUTION)


# 33 samples of a closed circle: the best-fitting line is a diameter, max distance R, polygon
# length 64 R sin(π/32), so the relative deviation is 1/(64 sin(π/32)) = 0.15941 (→ 1/(2π)).
CLOSED_DEV = 1.0 / (64.0 * math.sin(math.pi / 32.0))


@pytest.mark.parametrize("phi_deg", [20.0, 90.0, 180.0, 300.0, 359.9])
def test_isoline_deviation_is_sagitta_over_arc_length(phi_deg: float) -> None:
    """A torus sector's u-isolines are circular arcs of angle φ: distance of the arc from its chord
    line relative to its length is (1 - cos(φ/2)) / φ (to the 32-segment sampling, 2e-3); its
    v-isolines are closed circles: finite 0.159, never 0 (a closed isoline is not straight)."""
    d, info = face_ruling_direction(_torus_face(phi_deg))
    phi = math.radians(phi_deg)
    assert d is None
    assert info["deviation_u"] == pytest.approx((1.0 - math.cos(phi / 2.0)) / phi, rel=2e-3)
    assert info["deviation_v"] == pytest.approx(CLOSED_DEV, rel=1e-9)
    assert info["openness_v"] < 1e-12 < info["openness_u"]


@pytest.mark.parametrize("which", ["torus", "sphere", "vase"])
def test_closed_faces_are_not_ruled_with_finite_deviation(which: str) -> None:
    face = {"torus": _torus_face, "sphere": lambda: bd.Sphere(5.0).faces()[0], "vase": _vase_face}[which]()
    d, info = face_ruling_direction(face)
    assert d is None
    devs = [info["deviation_u"], info["deviation_v"]]
    assert all(math.isfinite(x) and 0.05 < x < 0.5 for x in devs), devs
    with pytest.raises(NotDevelopableError, match="not ruled") as exc:
        unroll(face)
    msg = str(exc.value)
    assert "nan" not in msg and "e+" not in msg
    assert f"{info['deviation_u']:.3g} (u-isolines)" in msg and f"{info['deviation_v']:.3g} (v-isolines)" in msg
    assert "relative to their lengths" in msg


def test_sphere_deviations_are_circle_and_half_circle() -> None:
    _, info = face_ruling_direction(bd.Sphere(5.0).faces()[0])
    assert info["deviation_u"] == pytest.approx(CLOSED_DEV, rel=1e-9)  # latitude circles (closed)
    assert info["deviation_v"] == pytest.approx(1.0 / (64.0 * math.sin(math.pi / 64.0)), rel=1e-9)  # meridians


def test_full_torus_best_effort_names_why() -> None:
    from ght_cad.core.errors import DegenerateGeometryError

    with pytest.raises(DegenerateGeometryError, match="closed in both directions") as exc:
        unroll(_torus_face(), best_effort=True)
    assert "ruling length" not in str(exc.value) and "nan" not in str(exc.value)


def test_full_sphere_best_effort_is_refused_naming_poles() -> None:
    """A full sphere: the meridians (v-isolines) are open but run from pole to pole, so the ruled
    surface between the boundary isolines S(·, -π/2), S(·, π/2) (two points) is a segment
    (before: a "pattern" of area 7.7e-14 for a 3-D area 100π, reported as error 1.0)."""
    from ght_cad.core.errors import DegenerateGeometryError

    with pytest.raises(DegenerateGeometryError, match=r"v-isolines run between two points.*sphere into sectors"):
        unroll(bd.Sphere(5.0).faces()[0], best_effort=True)


@pytest.mark.slow
@pytest.mark.parametrize("arc", [10.0, 45.0])
def test_sphere_gore_best_effort(arc: float) -> None:
    """A sphere sector (a gore, Δu = arc): rulings between its two meridians (u-isolines open,
    the latitude ends are poles); area within the reported error of the 3-D area 2 R² Δu."""
    R = 5.0
    face = bd.Sphere(R, arc_size3=arc).faces()[0]
    pat = unroll(face, best_effort=True)
    panel = pat.panels[0]
    exact = 2 * R * R * math.radians(arc)
    assert panel.area_3d == pytest.approx(exact, rel=1e-9)
    assert panel.info["ruling_direction"] == "u"
    assert pat.area > 0.85 * exact
    assert abs(pat.area - exact) / exact == pytest.approx(pat.errors["area"], rel=1e-9)
    assert 1e-4 < pat.errors["max"] < 0.2


@pytest.mark.parametrize("which", ["torus90", "vase"])
def test_best_effort_uses_open_boundary_isolines(which: str) -> None:
    """best_effort spans rulings between the open boundary isolines (never two copies of one
    closed isoline) and reports the distortion; the ruled surface's rulings have length > 0."""
    face = {"torus90": lambda: _torus_face(90.0), "vase": _vase_face}[which]()
    _, info = face_ruling_direction(face)
    pat = unroll(face, best_effort=True)
    panel = pat.panels[0]
    assert panel.ruling_lengths_3d.min() > 1e-6
    assert np.isfinite(pat.errors["max"]) and pat.errors["max"] > 1e-3  # distortion is reported
    assert panel.info["best_effort"] is True
    open_dir = "u" if which == "torus90" else "v"
    assert panel.info["ruling_direction"] == open_dir
    assert info[f"openness_{open_dir}"] > 0.1 and info[f"openness_{'v' if open_dir == 'u' else 'u'}"] < 1e-12


def _nurbs_faces():
    """A multi-span cubic x linear B-spline face and a rational (NURBS-converted) cylinder face."""
    import build123d as bd
    from OCP.BRepBuilderAPI import BRepBuilderAPI_NurbsConvert

    from ght_cad.surfaces.bspline import BSplineSurfaceData
    from ght_cad.cad.occ import make_face

    rng = np.random.default_rng(7)
    P = np.stack([np.c_[np.linspace(0, 40, 6), rng.uniform(-3, 3, 6), np.zeros(6)],
                  np.c_[np.linspace(2, 38, 6), rng.uniform(-3, 3, 6), np.full(6, 15.0)]], axis=1)
    spline = make_face(BSplineSurfaceData(P, [0] * 4 + [0.3, 0.55] + [1] * 4, [0, 0, 1, 1], 3, 1))
    cyl = next(f for f in bd.Cylinder(20.0, 50.0, arc_size=120).faces() if f.geom_type == bd.GeomType.CYLINDER)
    conv = BRepBuilderAPI_NurbsConvert(cyl.wrapped, True)
    return [spline, bd.Face(conv.Shape())]


def test_numpy_nurbs_evaluation_matches_occt():
    """The numpy NURBS evaluator (Chebyshev span patches for S, S_u, S_v; difference nets for the
    second derivatives; the area-density grid) agrees with OCCT's BRepAdaptor_Surface.D2 to 1e-12
    of each quantity's size, at random points and on a grid (rational and multi-span surfaces)."""
    from ght_cad.cad.unroll_faces import _open_face

    rng = np.random.default_rng(3)
    for face in _nurbs_faces():
        _, _, (u0, u1, v0, v1), ev = _open_face(face)
        assert ev._nurbs is not None and ev._nurbs.patches is not None
        u, v = rng.uniform(u0, u1, 200), rng.uniform(v0, v1, 200)
        occ = ev._occ_d2(u, v)
        for order in (0, 1, 2):
            ours = ev.jet(u, v, order)
            for a, b in zip(ours, occ):
                assert np.abs(a - b).max() <= 1e-12 * max(1.0, np.abs(b).max())
        s, vv = np.linspace(u0, u1, 7), np.linspace(v0, v1, 5)
        dens = ev.density_grid(s, vv)
        d = ev._occ_d2(np.repeat(s, vv.size), np.tile(vv, s.size))
        ref = np.linalg.norm(np.cross(d[1], d[2]), axis=1).reshape(s.size, vv.size)
        assert np.abs(dens - ref).max() <= 1e-12 * ref.max()


def test_numpy_edge_curves_match_occt():
    """B-spline edge curves (3-D curve and pcurve) evaluated in numpy agree with OCCT's adaptors to
    1e-12 of the curve's size, derivatives too (the rational cylinder's circular edges)."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Curve2d
    from OCP.gp import gp_Pnt2d, gp_Vec2d

    from ght_cad.cad.unroll_faces import _curve_eval, shape_faces

    checked = 0
    for face in _nurbs_faces():
        f = shape_faces(face)[0]
        for e in face.edges():
            for c, dim in ((BRepAdaptor_Curve(e.wrapped), 3), (BRepAdaptor_Curve2d(e.wrapped, f), 2)):
                fn = _curve_eval(c, dim)
                if fn is None or not hasattr(fn, "derivative"):
                    continue
                p = np.linspace(c.FirstParameter(), c.LastParameter(), 33)
                ref = np.array([c.Value(x).Coord() for x in p.tolist()])
                scale = max(1.0, np.abs(ref).max())
                assert np.abs(fn(p) - ref).max() <= 1e-12 * scale
                if dim == 2:
                    q, vec, der = gp_Pnt2d(), gp_Vec2d(), []
                    for x in p.tolist():
                        c.D1(x, q, vec)
                        der.append(vec.Coord())
                    der = np.array(der)
                    assert np.abs(fn.derivative(p) - der).max() <= 1e-12 * max(1.0, np.abs(der).max())
                checked += 1
    assert checked >= 4
