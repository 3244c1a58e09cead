"""The cadquery tests: they run in the ``[cadquery]`` world (cadquery 2.8 on OCP 7.9, no build123d;
``.venv-cadquery``, see tests/test_install.py's CADQUERY_TESTS). This module imports only cadquery,
OCP and ght_cad, so it is collected there; the build123d worlds skip it whole."""
from __future__ import annotations

import math

import numpy as np
import pytest

cq = pytest.importorskip("cadquery")

import ght_cad.cad.cq_plugin  # noqa: E402,F401  (registers Workplane.ghtBezier / ghtCurve / developableLoft)
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402

from cad_checks import green_area as _green_area  # noqa: E402
from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.cq_plugin import developable_loft_cq  # noqa: E402
from ght_cad.cad.loft import loft_between  # noqa: E402
from ght_cad.cad.occ import read_step, write_step  # noqa: E402
from ght_cad.core.errors import GHTError, NotDevelopableError  # noqa: E402
from ght_cad.unrolling.unroll import unroll  # noqa: E402

RTOL = 1e-9  # as tests/test_unroll_faces.py
POINTS = [(0.0, 0.0), (4.0, 3.0), (8.0, 0.0)]  # as tests/test_cad_papercuts.py
CHINE = GHTCurve([[0, -700, 300], [1500, -1050, 200], [3000, -1150, 250], [4500, -950, 450]])  # as tests/test_cad_loft.py
SHEER = GHTCurve([[0, -900, 1200], [1500, -1250, 1150], [3000, -1300, 1180], [4500, -1100, 1300]])


def _valid(shape) -> bool:
    return bool(BRepCheck_Analyzer(getattr(shape, "wrapped", shape)).IsValid())


def _size(shape) -> float:
    return float(shape.BoundingBox().DiagonalLength)


# -- from tests/test_cad_curves.py ---------------------------------------------------------------
def test_cadquery_plugin_and_wrapped_objects(tmp_path):
    pts = [(1, 1.5), (2.5, 1.0), (3, 0)]
    wp = cq.Workplane("XY").moveTo(0, 0).ghtBezier(pts, mu=0.3, includeCurrent=True).close()
    solid = wp.extrude(2.0, clean=False).val()
    assert solid.isValid()
    curve = GHTCurve([(0, 0)] + pts, 0.3)
    exact_area = _green_area([curve, GHTCurve([(3, 0), (1.5, 0), (0, 0)])])
    assert solid.Volume() == pytest.approx(2.0 * exact_area, rel=1e-6)
    # local coordinates are mapped exactly to the workplane (XZ: local y -> world Z)
    e = cq.Workplane("XZ").ghtCurve(curve).val()
    mid = e.positionAt(0.5, mode="parameter")
    assert np.allclose(mid.toTuple(), [curve.evaluate(0.5)[0], 0.0, curve.evaluate(0.5)[1]], atol=1e-6)
    write_step(solid, tmp_path / "cq.step")
    assert _valid(read_step(tmp_path / "cq.step"))


def test_cadquery_plugin_refuses_curves_of_more_than_three_dimensions():
    # a 4-D curve (e.g. a dual curve of planes) handed to Workplane.ghtCurve raised numpy's
    # "could not broadcast input array from shape (4,) into shape (3,)" (a bare ValueError)
    four = GHTCurve(np.zeros((3, 4)) + np.arange(3)[:, None])
    with pytest.raises(GHTError, match=r"curve has dimension 4; .*2-D or 3-D"):
        cq.Workplane("XY").ghtCurve(four)
    with pytest.raises(GHTError, match=r"2-D or 3-D; got 4 coordinates"):
        cq.Workplane("XY").ghtBezier([(0, 0, 0, 0), (1, 1, 1, 1), (2, 0, 0, 0)])


# -- from tests/test_cad_loft.py -----------------------------------------------------------------
def test_cadquery_workplane_and_function() -> None:
    ea, eb = cq.Workplane().ghtCurve(CHINE).val(), cq.Workplane().ghtCurve(SHEER).val()
    wp = cq.Workplane("XY").add(ea).add(eb).developableLoft()
    shell = wp.val()
    assert isinstance(shell, cq.Shell) and shell.isValid()
    assert len(shell.Faces()) == 3
    # same B-rep as the OCP front end (the build123d one's core) on the bare TopoDS rails: same poles
    ref_shape = loft_between(ea.wrapped, eb.wrapped)
    ours = [np.asarray(d.poles) for d in shell.ght_bspline]
    ref = [np.asarray(d.poles) for d in ref_shape.ght_bspline]
    assert len(ours) == len(ref)
    assert all(a.shape == b.shape and np.max(np.abs(a - b)) <= 1e-9 * _size(shell) for a, b in zip(ours, ref))
    face = developable_loft_cq(cq.Edge.makeCircle(5.0), cq.Edge.makeCircle(2.0, cq.Vector(0, 0, 6)))
    assert isinstance(face, cq.Face) and face.isValid()
    assert cq.Workplane().developableLoft(ea, eb).val().isValid()
    with pytest.raises(GHTError, match="exactly two edges"):
        cq.Workplane().add(ea).developableLoft()
    with pytest.raises(GHTError, match="two rails"):
        cq.Workplane().developableLoft(ea)
    with pytest.raises(NotDevelopableError):
        developable_loft_cq(cq.Edge.makeLine(cq.Vector(0, 0, 0), cq.Vector(10, 0, 0)), cq.Edge.makeLine(cq.Vector(0, 5, 3), cq.Vector(0, 8, 10)))


# -- from tests/test_cad_papercuts.py ------------------------------------------------------------
@pytest.mark.parametrize("dtype", [np.int64, np.float32], ids=lambda d: np.dtype(d).name)
def test_cadquery_bezier_takes_numpy_points(dtype):
    exact = GHTCurve(POINTS, mu=0.25).arc_length()
    edge = cq.Workplane("XY").ghtBezier(np.array(POINTS, dtype=dtype), mu=np.float32(0.25)).val()
    assert edge.Length() == pytest.approx(exact, rel=1e-7)


def test_cadquery_loft_metadata_follows_in_place_moves():
    a = cq.Edge.makeCircle(100, angle1=0, angle2=180)
    b = cq.Edge.makeCircle(60, pnt=cq.Vector(0, 0, 150), angle1=0, angle2=180)
    shell = developable_loft_cq(a, b)
    dev = shell.ght_max_deviation
    shell.move(cq.Location(cq.Vector(0, 0, 10)))        # in place: the attributes stay on it
    assert shell.ght_max_deviation == dev
    assert getattr(shell, "ght_loft", None) is None
    z = np.vstack([d.poles.reshape(-1, 3) for d in shell.ght_bspline])[:, 2]
    assert z.min() == pytest.approx(10.0, abs=1e-9) and z.max() == pytest.approx(160.0, abs=1e-6)


# -- from tests/test_unroll_faces.py -------------------------------------------------------------
def test_cadquery_face() -> None:
    face = next(f for f in cq.Workplane().cylinder(5.0, 2.0).val().Faces() if f.geomType() == "CYLINDER")
    pat = unroll(face)
    assert pat.area == pytest.approx(2 * math.pi * 2.0 * 5.0, rel=RTOL)
