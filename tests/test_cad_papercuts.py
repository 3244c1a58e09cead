"""build123d/cadquery adapter papercuts (issue 25): numbers of any numpy dtype, transformed shapes'
ght metadata."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("build123d")
cq = pytest.importorskip("cadquery")

from build123d import BuildLine  # noqa: E402

from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.curves import GHTBezierLine  # noqa: E402
from ght_cad.errors import GHTError  # noqa: E402

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


@pytest.mark.parametrize("dtype", [np.int64, np.float32], ids=lambda d: np.dtype(d).name)
def test_cadquery_bezier_takes_numpy_points(dtype):
    import ght_cad.cad.cq_plugin  # noqa: F401

    exact = GHTCurve(POINTS, mu=0.25).arc_length()
    edge = cq.Workplane("XY").ghtBezier(np.array(POINTS, dtype=dtype), mu=np.float32(0.25)).val()
    assert edge.Length() == pytest.approx(exact, rel=1e-7)
