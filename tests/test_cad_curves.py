"""build123d / cadquery adapters and STEP export of GHT curves, wires, patches and solids."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("build123d")

from build123d import Axis, BuildLine, BuildPart, BuildSketch, Line, Plane, extrude, make_face, revolve  # noqa: E402
from OCP.BRepAdaptor import BRepAdaptor_Curve  # noqa: E402
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.BRepGProp import BRepGProp  # noqa: E402
from OCP.GCPnts import GCPnts_AbscissaPoint  # noqa: E402
from OCP.GProp import GProp_GProps  # noqa: E402
from OCP.TopAbs import TopAbs_EDGE, TopAbs_SOLID  # noqa: E402
from OCP.TopExp import TopExp, TopExp_Explorer  # noqa: E402
from ght_cad.cad._ocp import TopTools_IndexedMapOfShape  # noqa: E402
from ght_cad.cad._ocp import TopoDS  # noqa: E402

from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.curves import GHTBezierLine, GHTCompositeLine, exact_edges, export_step, ght_edge, ght_face, ght_shape, ght_wire  # noqa: E402
from ght_cad.cad.occ import read_step, volume, write_step  # noqa: E402
from ght_cad.curves.composite import CompositeCurve  # noqa: E402
from cad_checks import green_area as _green_area  # noqa: E402
from ght_cad.curves.curve import gauss_legendre  # noqa: E402
from ght_cad.core.errors import GHTError  # noqa: E402
from ght_cad.surfaces.patch import GHTSurface  # noqa: E402

shape = st.floats(-1.0, 1.0, allow_nan=False)


def _length(shape) -> float:
    """Total edge length by adaptive integration to 1e-13 (GProp's default is only ~1e-6)."""
    return sum(GCPnts_AbscissaPoint.Length_s(BRepAdaptor_Curve(e), 1e-13) for e in _edges(shape))


def _area(shape) -> float:
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(getattr(shape, "wrapped", shape), props, 1e-11)
    return props.Mass()


def _edges(shape) -> list:
    """Distinct edges (each once, whatever the number of faces using it)."""
    emap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(getattr(shape, "wrapped", shape), TopAbs_EDGE, emap)
    return [TopoDS.Edge_s(emap.FindKey(i)) for i in range(1, emap.Extent() + 1)]


def _valid(shape) -> bool:
    return bool(BRepCheck_Analyzer(getattr(shape, "wrapped", shape)).IsValid())


@settings(max_examples=10)
@given(degree=st.integers(2, 10), mu=shape, nu=shape, gamma=shape, seed=st.integers(0, 2**31 - 1))
def test_edge_keeps_parametrization_and_step_round_trip(tmp_path_factory, degree, mu, nu, gamma, seed):
    rng = np.random.default_rng(seed)
    curve = GHTCurve(rng.normal(size=(degree + 1, 3)) * 5, mu, nu, gamma)
    edge = ght_edge(curve)
    tol = edge.ght_bspline.info["tol"]
    ad = BRepAdaptor_Curve(edge.wrapped)
    assert (ad.FirstParameter(), ad.LastParameter()) == (0.0, 1.0)
    t = rng.uniform(0, 1, 400)
    got = np.array([[ad.Value(x).X(), ad.Value(x).Y(), ad.Value(x).Z()] for x in t])
    assert np.linalg.norm(got - curve.evaluate(t), axis=1).max() <= tol
    # edge length vs exact arc length: 1e-6 relative (the B-spline is tol = 1e-7 × diagonal close)
    assert abs(_length(edge) - curve.length) <= 1e-6 * curve.length
    path = tmp_path_factory.mktemp("step") / "edge.step"
    write_step(edge, path)
    back = read_step(path)
    assert _valid(back)
    assert abs(_length(back) - _length(edge)) <= 1e-9 * _length(edge)


def _geom_derivatives(edge, t: float) -> list[np.ndarray]:
    ad = BRepAdaptor_Curve(edge)
    out = [np.array(ad.Value(t).Coord())]
    for r in (1, 2, 3):
        v = ad.DN(t, r)
        out.append(np.array([v.X(), v.Y(), v.Z()]))
    return out


def _g_residuals(d: list[np.ndarray], e: list[np.ndarray]) -> tuple[float, float, float]:
    """G1/G2/G3 residuals of e (start of B) against d (end of A) with fitted k, β2, β3 (relative)."""
    d1 = d[1]
    den = d1 @ d1
    k = (e[1] @ d1) / den
    u2 = e[2] - k * k * d[2]
    b2 = (u2 @ d1) / den
    u3 = e[3] - k**3 * d[3] - 3 * k * b2 * d[2]
    b3 = (u3 @ d1) / den
    scale = [1.0, np.linalg.norm(e[1]), np.linalg.norm(e[2]) + np.linalg.norm(d[2]), np.linalg.norm(e[3]) + np.linalg.norm(d[3])]
    return (
        np.linalg.norm(e[1] - k * d1) / scale[1],
        np.linalg.norm(u2 - b2 * d1) / scale[2],
        np.linalg.norm(u3 - b3 * d1) / scale[3],
    )


@pytest.mark.parametrize("continuity", ["C2", "G2", "C3", "G3"])
def test_joint_continuity_survives_in_bspline_edges(continuity):
    rng = np.random.default_rng(21)
    segs = [GHTCurve(rng.normal(size=(m + 1, 3)) + 3 * i, *rng.uniform(-1, 1, 3)) for i, m in enumerate([5, 7, 6])]
    kw = {"k": 1.4, "beta2": 0.3, "beta3": -0.2} if continuity[0] == "G" else {}
    cc = CompositeCurve(segs, continuity, **kw)
    wire = ght_wire(cc)
    edges = _edges(wire)
    assert len(edges) == 3 and _valid(wire)
    assert max(d.max_deviation / d.info["tol"] for d in wire.ght_bspline) <= 1.0
    order = int(continuity[1])
    for j in range(2):
        d = _geom_derivatives(edges[j], 1.0)
        e = _geom_derivatives(edges[j + 1], 0.0)
        assert np.linalg.norm(d[0] - e[0]) <= 1e-12 * 10
        if continuity[0] == "C":
            for r in range(1, order + 1):
                assert np.linalg.norm(e[r] - d[r]) <= 1e-9 * np.linalg.norm(d[r]), r
            # not more than asked: the next order differs
            if order < 3:
                assert np.linalg.norm(e[order + 1] - d[order + 1]) > 1e-6 * np.linalg.norm(d[order + 1])
        else:
            res = _g_residuals(d, e)
            assert max(res[:order]) <= 1e-9, res
            # and not C1 (k != 1)
            assert np.linalg.norm(e[1] - d[1]) > 1e-3 * np.linalg.norm(d[1])


def test_wire_step_round_trip_keeps_length(tmp_path):
    rng = np.random.default_rng(8)
    segs = [GHTCurve(rng.normal(size=(m + 1, 3)) + 2 * i, *rng.uniform(-1, 1, 3)) for i, m in enumerate([3, 6, 4, 9])]
    cc = CompositeCurve(segs, ["G1", "C2", "G3"], k=[0.5, 1.0, 2.0])
    wire = ght_wire(cc)
    exact = sum(s.length for s in cc.segments)
    assert _length(wire) == pytest.approx(exact, rel=1e-6)
    write_step(wire, tmp_path / "wire.step")
    back = read_step(tmp_path / "wire.step")
    assert _valid(back) and len(_edges(back)) == 4
    assert abs(_length(back) - _length(wire)) <= 1e-9 * _length(wire)


def test_closed_g2_glyph_in_builders_has_exact_area(tmp_path):
    """BuildPart/BuildSketch/BuildLine with GHTCompositeLine: area = Green's-theorem area of the GHT chain."""
    ang = np.linspace(0, 2 * np.pi, 5)[:-1]
    segs = []
    for i, a in enumerate(ang):
        b = a + np.pi / 2
        pts = [(np.cos(a + s * (b - a)) * r, np.sin(a + s * (b - a)) * r) for s, r in zip(np.linspace(0, 1, 6), [3, 3.3, 2.2, 2.6, 3.4, 3])]
        segs.append(GHTCurve(pts, 0.2, -0.1, 0.3))
    cc = CompositeCurve(segs, "G2", closed=True)
    height = 0.75
    with exact_edges():
        with BuildPart() as part:
            with BuildSketch():
                with BuildLine():
                    GHTCompositeLine(cc)
                make_face()
            extrude(amount=height)
    solid = part.part
    assert len(_edges(solid)) == 12  # 4 bottom + 4 top + 4 seams: no edge was merged
    assert _valid(solid)
    exact = _green_area(cc.segments)
    # bound from the certified deviations δ_i of the edges (lengths L_i): |ΔA| <= Σ L_i δ_i + π δ_i²
    devs = [d.max_deviation for d in ght_wire(cc).ght_bspline]
    bound = height * sum(s.length * d + np.pi * d * d for s, d in zip(cc.segments, devs))
    assert abs(volume(solid) - exact * height) <= bound <= 1e-5 * exact * height
    path = tmp_path / "glyph.step"
    write_step(solid, path)
    back = read_step(path)
    ex = TopExp_Explorer(back, TopAbs_SOLID)
    assert ex.More() and _valid(back)
    assert volume(back) == pytest.approx(volume(solid), rel=1e-9)


def test_bezier_line_builder_and_algebra_mode_agree():
    pts = [(0, 0), (1, 2), (3, 2), (4, 0)]
    with BuildLine() as bl:
        line = GHTBezierLine(*pts, mu=0.4, nu=-0.2, gamma=0.1)
        Line((4, 0), (0, 0))
    assert len(bl.edges()) == 2
    algebra = ght_edge(GHTCurve(pts, 0.4, -0.2, 0.1))
    assert line.length == pytest.approx(algebra.length, rel=1e-12)
    assert isinstance(line.ght_curve, GHTCurve)
    with BuildLine() as bl2:
        GHTBezierLine(GHTCurve(pts, 0.4, -0.2, 0.1))
    assert bl2.edges()[0].length == pytest.approx(algebra.length, rel=1e-12)


def test_revolved_profile_volume_matches_pappus(tmp_path):
    """Revolve a closed profile (GHT curve + axis lines) about Z: V = 2π ∫ x dA = π ∫ x² z' dt."""
    prof = GHTCurve([(1.0, 0.0), (2.0, 0.5), (0.6, 1.5), (1.2, 2.5), (0.8, 3.0)], 0.3, 0.1, -0.4)
    with exact_edges(), BuildPart() as part:
        with BuildSketch(Plane.XZ):
            with BuildLine():
                GHTBezierLine(prof)
                Line((0.8, 3.0), (0.0, 3.0))
                Line((0.0, 3.0), (0.0, 0.0))
                Line((0.0, 0.0), (1.0, 0.0))
            make_face()
        revolve(axis=Axis.Z)
    solid = part.part
    t, w = gauss_legendre(64)
    p, d = prof.evaluate(t), prof.derivative(t, 1)
    exact = abs(np.pi * float(np.sum(w * p[:, 0] ** 2 * d[:, 1])))
    assert _valid(solid)
    assert volume(solid) == pytest.approx(exact, rel=1e-6)
    write_step(solid, tmp_path / "rev.step")
    assert volume(read_step(tmp_path / "rev.step")) == pytest.approx(volume(solid), rel=1e-9)


def test_face_from_patch_area_and_step(tmp_path):
    rng = np.random.default_rng(4)
    g = np.linspace(0, 3, 4)
    P = np.zeros((4, 4, 3))
    P[..., 0], P[..., 1] = np.meshgrid(g, g, indexing="ij")
    P[..., 2] = rng.normal(scale=0.5, size=(4, 4))
    s = GHTSurface(P, 0.2, -0.4, 0.1, 0.5, 0.0, -0.8)
    face = ght_face(s)
    assert _valid(face)
    x, w = gauss_legendre(48)
    U, V = np.meshgrid(x, x, indexing="ij")
    cr = np.cross(s.derivative(U.ravel(), V.ravel(), du=1), s.derivative(U.ravel(), V.ravel(), dv=1))
    exact = float(np.sum(np.outer(w, w).ravel() * np.linalg.norm(cr, axis=1)))
    assert _area(face) == pytest.approx(exact, rel=1e-6)
    write_step(face, tmp_path / "patch.step")
    back = read_step(tmp_path / "patch.step")
    assert _valid(back) and _area(back) == pytest.approx(_area(face), rel=1e-9)


def test_cadquery_and_build123d_share_wrapped_objects():
    """Needs build123d and cadquery in one environment (no CI venv has both: this skips there); the
    cadquery half of the old test runs in the [cadquery] world (tests/test_cq_world.py)."""
    cq = pytest.importorskip("cadquery")
    import ght_cad.cad.cq_plugin  # noqa: F401

    curve = GHTCurve([(0, 0), (1, 1.5), (2.5, 1.0), (3, 0)], 0.3)
    e = cq.Workplane("XZ").ghtCurve(curve).val()
    # no copies between build123d and cadquery
    b3d = ght_edge(curve)
    assert cq.Edge(b3d.wrapped).wrapped is b3d.wrapped
    from build123d import Edge

    assert Edge(e.wrapped).wrapped is e.wrapped


def test_exact_edges_restores_build123d_behaviour():
    """build123d's clean and SkipClean are never replaced; only the upgrader its modules construct
    is rebound for the block (and restored, also on error, also when nested)."""
    from build123d.topology import shape_core
    from build123d.topology.shape_core import Shape, SkipClean
    from OCP.ShapeUpgrade import ShapeUpgrade_UnifySameDomain

    before = Shape.clean
    with pytest.raises(RuntimeError):
        with exact_edges():
            assert Shape.clean is before and SkipClean.clean is True
            assert shape_core.ShapeUpgrade_UnifySameDomain is not ShapeUpgrade_UnifySameDomain
            with exact_edges():
                pass
            assert shape_core.ShapeUpgrade_UnifySameDomain is not ShapeUpgrade_UnifySameDomain
            raise RuntimeError("boom")
    assert Shape.clean is before and SkipClean.clean is True
    assert shape_core.ShapeUpgrade_UnifySameDomain is ShapeUpgrade_UnifySameDomain


def test_step_export_is_quiet_and_atomic(tmp_path, capfd):
    edge = ght_edge(GHTCurve([(0, 0), (1, 1), (2, 0)]))
    target = tmp_path / "quiet.step"
    write_step(edge, target)
    out, err = capfd.readouterr()
    assert "Statistics" not in out + err and out.strip() == ""
    assert target.stat().st_size > 0
    # a failed export (invalid path component) leaves nothing behind and raises
    bad = tmp_path / "file_not_dir"
    bad.write_text("x")
    with pytest.raises(OSError):
        write_step(edge, bad / "x.step")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file_not_dir", "quiet.step"]


def test_export_step_of_mixed_ght_objects(tmp_path):
    from OCP.TopAbs import TopAbs_FACE

    rng = np.random.default_rng(2)
    curve = GHTCurve(rng.normal(size=(5, 3)), 0.1, 0.2, 0.3)
    chain = CompositeCurve([GHTCurve(rng.normal(size=(4, 3))), GHTCurve(rng.normal(size=(6, 3)))], "G2", k=1.3)
    patch = GHTSurface(rng.normal(size=(4, 3, 3)), 0.5, 0.0, -0.5, 0.0, 0.3, 0.0)
    path = export_step([curve, chain, patch], tmp_path / "mixed.step")
    back = read_step(path)
    assert _valid(back)
    fmap = TopTools_IndexedMapOfShape()
    TopExp.MapShapes_s(back, TopAbs_FACE, fmap)
    assert fmap.Extent() == 1
    assert len(_edges(back)) == 1 + 2 + 4
    expected = _length(ght_shape(curve)) + _length(ght_shape(chain)) + _length(ght_face(patch))
    assert _length(back) == pytest.approx(expected, rel=1e-9)
    with pytest.raises(GHTError, match="cannot make a CAD shape"):
        ght_shape(3.0)


def test_open_chain_that_closes_geometrically_gives_a_closed_wire():
    a = GHTCurve([(0, 0), (1, 1), (2, 0)])
    b = GHTCurve([(2, 0), (1, -1), (0, 0)])
    assert ght_wire(CompositeCurve([a, b], "C0")).is_closed
    assert not ght_wire([a]).is_closed
    assert not ght_wire([a, GHTCurve([(2, 0), (1, -1), (0.5, 0)])]).is_closed


def test_adapter_errors():
    with pytest.raises(GHTError, match="dim"):
        ght_edge(GHTCurve(np.zeros((3, 4)) + np.arange(3)[:, None]))
    a = GHTCurve([(0, 0), (1, 1), (2, 0)])
    b = GHTCurve([(2.5, 0), (3, 1), (4, 0)])
    with pytest.raises(GHTError, match="gap"):
        ght_wire([a, b])
    with pytest.raises(GHTError, match="not closed"):
        ght_wire([a, GHTCurve([(2, 0), (3, 1), (4, 0)])], closed=True)
    with pytest.raises(GHTError, match="GHTSurface"):
        ght_face(a)
    with pytest.raises(GHTError, match="GHTCurve"):
        ght_wire([a, "not a curve"])


def test_write_step_refuses_what_is_not_a_shape(tmp_path):
    # a string, None or a null TopoDS_Shape reached BRepCheck_Analyzer and raised pybind11's
    # "incompatible constructor arguments" TypeError (or crashed the analyzer on a null shape)
    from OCP.TopoDS import TopoDS_Shape

    target = tmp_path / "x.step"
    for bad, what in (("not a shape", "str"), (None, "NoneType"), (TopoDS_Shape(), "null")):
        with pytest.raises(GHTError, match=rf"shape #0 .*{what}"):
            write_step(bad, target)
        with pytest.raises(GHTError, match=rf"shape #1 .*{what}"):
            write_step([ght_edge(GHTCurve([(0, 0), (1, 1), (2, 0)])), bad], target, check=False)
    assert not target.exists()
