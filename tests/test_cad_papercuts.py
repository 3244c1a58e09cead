"""build123d/cadquery adapter papercuts (issue 25): numbers of any numpy dtype, transformed shapes'
ght metadata."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("build123d")  # the cadquery papercuts are in tests/test_cq_world.py (the [cadquery] world)

from build123d import BuildLine  # noqa: E402

from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.curves import GHTBezierLine  # noqa: E402
from ght_cad.core.errors import GHTError  # noqa: E402

POINTS = [(0.0, 0.0), (4.0, 3.0), (8.0, 0.0)]
DTYPES = [np.int8, np.int16, np.int32, np.int64, np.uint8, np.float16, np.float32, np.float64]


@pytest.mark.parametrize("dtype", DTYPES, ids=lambda d: np.dtype(d).name)
def test_bezier_line_takes_numpy_points_of_any_dtype(dtype):
    """An integer numpy array used to give a zero-length curve at the origin (build123d's Vector
    reads numpy integers as nothing); every spelling must give the curve of the float points."""
    exact = GHTCurve(POINTS, mu=0.25).arc_length()
    arr = np.array(POINTS, dtype=dtype)
    spellings = {
        "one 2-D array": (arr,),
        "rows as arguments": tuple(arr),
        "scalars as tuples": tuple(tuple(row) for row in arr),  # numpy scalars, not Python numbers
        "list of rows": ([row for row in arr],),
    }
    for name, args in spellings.items():
        line = GHTBezierLine(*args, mu=0.25)
        np.testing.assert_allclose(line.ght_curve.control_points[:, :2], np.array(POINTS), atol=0, err_msg=name)
        assert line.length == pytest.approx(exact, rel=1e-7), name   # certified tol 1e-7 of the size
    with BuildLine() as bl:
        GHTBezierLine(arr, mu=0.25)
    assert sum(e.length for e in bl.line.edges()) == pytest.approx(exact, rel=1e-7)


def test_bezier_line_refuses_what_is_not_points():
    with pytest.raises(GHTError, match="point"):
        GHTBezierLine((0, 0), "ab", (1, 0))
    with pytest.raises(GHTError, match="2 or 3 coordinates"):
        GHTBezierLine((0, 0, 0, 0), (1, 1, 1, 1), (2, 0, 0, 0))


# -- transformed shapes carry transformed (or no) ght metadata -------------------------------
def _edge_points(edge, t):
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    ad = BRepAdaptor_Curve(edge.wrapped)
    return np.array([[p.X(), p.Y(), p.Z()] for p in (ad.Value(float(x)) for x in t)])


def _xyz(p):
    p = np.atleast_2d(p)
    return np.hstack([p, np.zeros((p.shape[0], 3 - p.shape[1]))])


def _moves():
    from build123d import Axis, Location, Plane

    return {
        "moved": (lambda e: e.moved(Location((3, -2, 5), (1, 1, 0), 30)), 1.0),
        "rotate": (lambda e: e.rotate(Axis.Z, 40), 1.0),
        "rotate transform": (lambda e: e.rotate(Axis.X, 25, transform=True), 1.0),
        "translate": (lambda e: e.translate((1, 2, 3)), 1.0),
        "mirror": (lambda e: e.mirror(Plane.YZ), 1.0),
        "scale": (lambda e: e.scale(2.5), 2.5),
        "located": (lambda e: e.located(Location((0, 0, 7), (0, 0, 1), 90)), 1.0),
        "Location *": (lambda e: Location((4, 0, 0), (0, 1, 0), 15) * e, 1.0),
        "locate in place": (lambda e: e.locate(Location((1, 1, 1))), 1.0),
    }


@pytest.mark.parametrize("make", ["GHTBezierLine 2-D", "ght_edge 3-D"])
def test_moved_edges_carry_their_transformed_curve_and_bspline(make):
    """A moved/rotated/mirrored/scaled ght edge used to keep the untransformed ght_bspline and
    ght_curve: now both describe the edge where it is, with the deviation scaled."""
    from ght_cad.surfaces.bspline import BSplineCurveData
    from ght_cad.cad.curves import ght_edge

    curve = (GHTCurve([(0, 0), (4, 3), (8, 0)], mu=0.3, gamma=-0.5) if make.startswith("GHTBezier")
             else GHTCurve([(0, 0, 0), (4, 3, 1), (8, 0, 2), (9, 4, 0)], mu=0.3, nu=-0.4, gamma=0.2))
    edge = GHTBezierLine(curve) if make.startswith("GHTBezier") else ght_edge(curve)
    if make.startswith("GHTBezier"):
        assert edge.ght_curve is curve
    data0 = edge.ght_bspline
    t = np.linspace(0, 1, 33)
    for name, (move, s) in _moves().items():
        work = GHTBezierLine(curve) if name == "locate in place" and make.startswith("GHTBezier") else (
            ght_edge(curve) if name == "locate in place" else edge)
        moved = move(work)
        pts = _edge_points(moved, t)                        # edge parameter = curve parameter t
        data = moved.ght_bspline
        assert isinstance(data, BSplineCurveData)
        assert data.max_deviation == pytest.approx(s * data0.max_deviation, rel=1e-12), name
        assert np.abs(_xyz(data.evaluate(t)) - pts).max() <= 1e-9 * s * 10, name     # the edge's own B-spline
        if make.startswith("GHTBezier"):
            assert np.abs(_xyz(moved.ght_curve.evaluate(t)) - pts).max() <= data.max_deviation * (1 + 1e-6), name
        if name != "locate in place":                        # the original is untouched
            assert edge.ght_bspline is data0
    assert copy_of(edge).ght_bspline is data0


def copy_of(shape):
    import copy

    return copy.copy(shape)


def test_nonuniform_scale_drops_the_metadata_and_loft_drops_its_core_object():
    from build123d import Axis, Edge, Location

    from ght_cad.cad.curves import ght_edge
    from ght_cad.cad.loft import developable_loft

    e = ght_edge(GHTCurve([(0, 0, 0), (4, 3, 1), (8, 0, 2)], mu=0.3))
    squashed = e.scale((1.0, 2.0, 0.5))
    assert getattr(squashed, "ght_bspline", None) is None
    with pytest.raises(AttributeError, match="ght_bspline"):
        squashed.ght_bspline
    inlet = Edge.make_circle(100, start_angle=0, end_angle=180)
    outlet = Edge.make_circle(60, start_angle=0, end_angle=180).moved(Location((0, 0, 150)))
    half = developable_loft(inlet, outlet)
    assert half.ght_loft is not None and half.ght_max_deviation > 0
    turned = half.rotate(Axis.Z, 90)
    assert getattr(turned, "ght_loft", None) is None                     # a core object in the old place
    assert turned.ght_max_deviation == half.ght_max_deviation
    grown = half.scale(2.0)
    assert grown.ght_max_deviation == pytest.approx(2 * half.ght_max_deviation, rel=1e-12)
    P = np.vstack([d.poles.reshape(-1, 3) for d in turned.ght_bspline])
    P0 = np.vstack([d.poles.reshape(-1, 3) for d in half.ght_bspline])
    np.testing.assert_allclose(P[:, :2], np.c_[-P0[:, 1], P0[:, 0]], atol=1e-9 * 200)


# -- exact_edges keeps build123d's clean: history, warnings, nested SkipClean ----------------
def test_exact_edges_keeps_history_and_warnings():
    """Inside the block build123d's own clean runs: the shape history of a join is merged
    (Select.NEW: 0 vertices, as outside; the replaced clean gave 2) and a failing clean warns."""
    import warnings
    from unittest.mock import patch

    from build123d import Line, Select, Solid

    from ght_cad.cad.curves import exact_edges

    def counts():
        bent = Line((0, 0), (1, 0)) + Line((1, 0), (1, 1))
        return len(bent.edges(Select.NEW)), len(bent.vertices(Select.NEW)), len(bent.vertices(Select.LAST))

    outside = counts()
    with exact_edges():
        assert counts() == outside == (0, 0, 2)
        box = Solid.make_box(1, 1, 1)
        with patch("build123d.topology.shape_core.ShapeUpgrade_UnifySameDomain") as upgrader:
            upgrader.return_value.Build.side_effect = RuntimeError("mocked failure")
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                box.clean()
        assert any("Unable to clean" in str(w.message) for w in caught)


def _bspline_edges(shape) -> int:
    from build123d import GeomType

    return sum(1 for e in shape.edges() if e.geom_type == GeomType.BSPLINE)


def test_exact_edges_survives_a_nested_skipclean():
    """A ``with SkipClean():`` inside the block used to turn cleaning (with B-spline
    concatenation) back on for the rest of it: the G2 chain's two edges became one."""
    from build123d import Box, BuildLine, BuildPart, BuildSketch, Line, Mode, SkipClean, extrude, make_face

    from ght_cad.cad.curves import GHTCompositeLine, exact_edges
    from ght_cad.curves.composite import CompositeCurve
    from ght_cad.curves.continuity import join

    a = GHTCurve([(0, 0), (10, 12), (20, 12), (30, 0)], mu=0.3)
    b = join(a, "G2", [(30, 0), (40, -10), (50, -6), (60, 0)])
    chain = CompositeCurve([a, b])
    end = b.evaluate(1.0)

    def part():
        with BuildPart() as p:
            with BuildSketch():
                with BuildLine():
                    GHTCompositeLine(chain)
                    Line(tuple(end), (60, -30))
                    Line((60, -30), (0, -30))
                    Line((0, -30), (0, 0))
                make_face()
            extrude(amount=5)
            Box(4, 4, 4, mode=Mode.SUBTRACT)        # a boolean: cleaned
        return p.part

    with exact_edges():
        kept = _bspline_edges(part())
        with SkipClean():
            pass
        after_skipclean = _bspline_edges(part())
    # two GHT edges on each cap, plus the curves where the box's faces cut the first one's surface
    assert kept == after_skipclean == 6
    assert _bspline_edges(part()) < kept            # outside the block build123d merges them


def test_ght_shapes_still_pickle_with_their_metadata():
    import pickle

    from build123d import Location

    from ght_cad.cad.curves import ght_edge, ght_face, ght_wire
    from ght_cad.surfaces.patch import GHTSurface

    c1 = GHTCurve([(0, 0), (1, 1), (2, 0)], mu=0.2)
    c2 = GHTCurve([(2, 0), (3, -1), (4, 0)])
    patch = GHTSurface([[(0, 0, 0), (1, 0, 1), (2, 0, 0)], [(0, 1, 0), (1, 1, 1), (2, 1, 0)], [(0, 2, 0), (1, 2, 1), (2, 2, 0)]])
    for shape in (ght_edge(c1), ght_wire([c1, c2]), ght_face(patch), GHTBezierLine(c1)):
        back = pickle.loads(pickle.dumps(shape))
        assert type(back).__name__ == type(shape).__name__
        a, b = shape.ght_bspline, back.ght_bspline
        for x, y in zip(a if isinstance(a, list) else [a], b if isinstance(b, list) else [b]):
            np.testing.assert_array_equal(x.poles, y.poles)
        # the copy's metadata still follows its shape: moved up by 3, 2-D data lifted to z = 3
        moved = back.moved(Location((0, 0, 3)))
        m = moved.ght_bspline[0] if isinstance(moved.ght_bspline, list) else moved.ght_bspline
        o = a[0] if isinstance(a, list) else a
        lifted = np.concatenate([o.poles, np.zeros(o.poles.shape[:-1] + (3 - o.poles.shape[-1],))], axis=-1)
        np.testing.assert_allclose(m.poles, lifted + [0.0, 0.0, 3.0], rtol=0, atol=1e-12)
