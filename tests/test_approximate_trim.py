"""Trimmed target faces (issue 24): ``ght_cad.approximate`` covers a face's whole (u, v) box, so a
face with a hole or an outline inside its surface's box is refused unless ``untrimmed=True``.

The faces are made here on one B-spline dome (300 x 200 mm, z = 0.002 (x - 150)^2 + 0.0005 (y - 100)^2; interpolated as
:func:`test_approximate.bspline_face`): a circular hole of radius 0.2 in (u, v) at the centre
(covers 0.874 of the box, 1 hole), a curved deck line ``v = 0.75 + 0.2 sin(pi u)`` as the top of
the outline (0.913) and the surface restricted to the box [0.1, 0.9]^2 (its trim is its box: 1).
The covered fraction ``face_trim`` measures (OCCT areas) is checked against an independent
midpoint integration of ``|S_u x S_v|`` over the (u, v) box with the trimmed-away part masked.
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("OCP")

from OCP.BRep import BRep_Tool  # noqa: E402
from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeWire  # noqa: E402
from OCP.BRepCheck import BRepCheck_Analyzer  # noqa: E402
from OCP.BRepLib import BRepLib  # noqa: E402
from OCP.Geom2d import Geom2d_Circle, Geom2d_Line  # noqa: E402
from OCP.Geom2dAPI import Geom2dAPI_PointsToBSpline  # noqa: E402
from OCP.gp import gp_Ax2d, gp_Dir2d, gp_Pnt2d  # noqa: E402
from OCP.ShapeFix import ShapeFix_Face  # noqa: E402

try:  # OCP 7.9
    from OCP.TColgp import TColgp_Array1OfPnt2d  # noqa: E402
except ImportError:  # OCP 8
    from OCP.collections import Array1_gp_Pnt2d as TColgp_Array1OfPnt2d  # noqa: E402

from test_approximate import bspline_face  # noqa: E402

from ght_cad.app.cli import main  # noqa: E402
from ght_cad.approximation import approximate  # noqa: E402
from ght_cad.approximation.target import TrimmedTargetError  # noqa: E402
from ght_cad.cad.approximate import face_target  # noqa: E402

HOLE = ((0.5, 0.5), 0.2)


def _deck_line(s: float) -> float:
    return 0.75 + 0.2 * math.sin(math.pi * s)


def _dome(s: float, t: float) -> tuple[float, float, float]:
    x, y = 300 * s, 200 * t
    return x, y, 0.002 * (x - 150) ** 2 + 0.0005 * (y - 100) ** 2


def _wire(surf, curves):
    mw = BRepBuilderAPI_MakeWire()
    for c, a, b in curves:
        e = BRepBuilderAPI_MakeEdge(c, surf, a, b).Edge()
        BRepLib.BuildCurves3d_s(e)
        mw.Add(e)
    return mw.Wire()


def _fixed(face):
    from build123d import Face

    fix = ShapeFix_Face(face)
    fix.Perform()
    out = Face(fix.Face())
    assert BRepCheck_Analyzer(out.wrapped).IsValid()
    return out


def holed_face(face):
    """``face`` with a circular hole (centre, radius in (u, v): :data:`HOLE`)."""
    surf = BRep_Tool.Surface_s(face.wrapped)
    c = Geom2d_Circle(gp_Ax2d(gp_Pnt2d(*HOLE[0]), gp_Dir2d(1, 0)), HOLE[1], False)  # clockwise: a hole
    mk = BRepBuilderAPI_MakeFace(face.wrapped)
    mk.Add(_wire(surf, [(c, 0.0, 2 * math.pi)]))
    return _fixed(mk.Face())


def deck_face(face):
    """``face`` (on [0, 1]^2) trimmed by the curved deck line ``v = _deck_line(u)`` at the top."""
    surf = BRep_Tool.Surface_s(face.wrapped)
    pts = TColgp_Array1OfPnt2d(1, 21)
    for i, s in enumerate(np.linspace(1, 0, 21)):
        pts.SetValue(i + 1, gp_Pnt2d(float(s), _deck_line(float(s))))
    cv = Geom2dAPI_PointsToBSpline(pts).Curve()

    def seg(p, q):
        return Geom2d_Line(gp_Pnt2d(*p), gp_Dir2d(q[0] - p[0], q[1] - p[1])), 0.0, math.dist(p, q)

    w = _wire(surf, [seg((0, 0), (1, 0)), seg((1, 0), (1, _deck_line(1))), (cv, cv.FirstParameter(), cv.LastParameter()),
                     seg((0, _deck_line(0)), (0, 0))])
    return _fixed(BRepBuilderAPI_MakeFace(surf, w, True).Face())


def box_face(face, box=(0.1, 0.9, 0.1, 0.9)):
    """The surface of ``face`` over a (u, v) box: a face whose trim is its box."""
    from build123d import Face

    return Face(BRepBuilderAPI_MakeFace(BRep_Tool.Surface_s(face.wrapped), *box, 1e-7).Face())


@pytest.fixture(scope="module")
def dome():
    return bspline_face(_dome, 8, 8)


def _integrated_fraction(target, inside) -> float:
    """``∫ |S_u x S_v|`` over the (u, v) box where ``inside(u, v)``, over the whole box (midpoint
    rule, 600 x 600): the independent check of ``face_trim``."""
    u0, u1, v0, v1 = target.bounds
    n = 600
    u = u0 + (u1 - u0) * (np.arange(n) + 0.5) / n
    v = v0 + (v1 - v0) * (np.arange(n) + 0.5) / n
    U, V = np.meshgrid(u, v, indexing="ij")
    _, Su, Sv = target.jet(U.ravel(), V.ravel(), 1)
    dA = np.linalg.norm(np.cross(Su, Sv), axis=1)
    return float(dA[inside(U.ravel(), V.ravel())].sum() / dA.sum())


def test_face_trim_measures_the_covered_fraction_and_holes(dome) -> None:
    """Hole: 0.874 of the box, 1 hole; deck line: 0.913, 0 holes (uv box cut at the line's top
    0.95); both within 2e-3 of the integration. The plain face and a face on a sub-box: 1 to 1e-9."""
    for face in (dome, box_face(dome)):
        trim = face_target(face).trim
        assert trim["holes"] == 0 and abs(trim["covered"] - 1.0) <= 1e-9, trim
    t = face_target(holed_face(dome))
    (cu, cv), r = HOLE
    ref = _integrated_fraction(t, lambda u, v: (u - cu) ** 2 + (v - cv) ** 2 >= r * r)
    assert t.trim["holes"] == 1 and abs(t.trim["covered"] - ref) <= 2e-3 and 0.85 < ref < 0.9, (t.trim, ref)
    t = face_target(deck_face(dome))
    assert t.bounds[3] == pytest.approx(0.95, abs=0.02)
    ref = _integrated_fraction(t, lambda u, v: v <= 0.75 + 0.2 * np.sin(np.pi * u))
    assert t.trim["holes"] == 0 and abs(t.trim["covered"] - ref) <= 2e-3 and 0.88 < ref < 0.95, (t.trim, ref)


def test_trimmed_faces_are_refused_naming_the_fraction(dome) -> None:
    for face, covered, holes in ((holed_face(dome), "0.87", "1 hole"), (deck_face(dome), "0.91", "0 holes")):
        with pytest.raises(TrimmedTargetError, match=rf"covers {covered}\d* of its surface's \(u, v\) box, {holes}") as ei:
            approximate(face, 2.0, method="loft")
        assert "untrimmed=True" in str(ei.value)
    with pytest.raises(Exception, match="untrimmed='yes' is not allowed"):
        approximate(dome, 2.0, untrimmed="yes")


@pytest.mark.slow
def test_untrimmed_covers_the_box_and_reports_the_fraction(dome) -> None:
    """untrimmed=True: the holed face's surface over its whole box, as the untrimmed face (same
    panels), info["trim"] records 0.874 and the hole; the box-trimmed face runs without it."""
    holed = approximate(holed_face(dome), 2.0, method="loft", untrimmed=True)
    plain = approximate(dome, 2.0, method="loft")
    trim = holed.info["trim"]
    assert trim["untrimmed"] and trim["holes"] == 1 and 0.85 < trim["covered"] < 0.9, trim
    assert plain.info["trim"]["covered"] == pytest.approx(1.0, abs=1e-9)
    assert len(holed.panels) == len(plain.panels) and holed.max_deviation == pytest.approx(plain.max_deviation, rel=1e-9)
    sub = approximate(box_face(dome), 2.0, method="loft")
    assert sub.max_deviation <= 2.0 and not sub.info["trim"]["holes"]


def test_cli_refuses_a_trimmed_face_in_one_line(dome, tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    from ght_cad.cad.occ import write_step

    step = Path(write_step(holed_face(dome), tmp_path / "holed.step"))
    assert main(["approximate", str(step), "--tol", "2", "--out", str(tmp_path / "o"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(step) in err[0] and "face 1" in err[0] and "covers 0.87" in err[0], err
    assert "--untrimmed" in err[0] and "1 hole" in err[0] and not (tmp_path / "o").exists()


@pytest.mark.slow
def test_cli_untrimmed_writes_the_fraction_to_the_report(dome, tmp_path: Path) -> None:
    from ght_cad.cad.occ import write_step

    step = Path(write_step(deck_face(dome), tmp_path / "deck.step"))
    assert main(["approximate", str(step), "--tol", "2", "--method", "loft", "--untrimmed", "--out", str(tmp_path / "o"),
                 "--no-progress"]) == 0
    rep = json.loads((tmp_path / "o" / "report.json").read_text())
    assert rep["info"]["trim"]["holes"] == 0 and 0.88 < rep["info"]["trim"]["covered"] < 0.95, rep["info"]["trim"]
    assert "untrimmed" in (tmp_path / "o" / "report.md").read_text()


def test_design_key_untrimmed(dome, tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """``untrimmed`` of an approximate surface: a bad value and a trimmed STEP face without it:
    exit 2, one line naming the file and the key (and the fraction); ``untrimmed = true`` parses."""
    from test_design_approximate import BASE, _toml

    from ght_cad.cad.occ import write_step
    from ght_cad.app.design import parse_design

    write_step(holed_face(dome), tmp_path / "holed.step")
    d = copy.deepcopy(BASE)
    d["surfaces"][0]["target"] = {"step": "holed.step", "face": 1}
    d["surfaces"][0]["tol"] = 2.0
    d["outputs"] = {"files": ["json"], "figures": []}
    for value, key, words in (("yes", "surfaces[0].untrimmed", "expected a boolean"),
                              (None, "surfaces[0].target", "covers 0.87")):
        if value is not None:
            d["surfaces"][0]["untrimmed"] = value
        path = tmp_path / "d.toml"
        path.write_text(_toml(d))
        assert main(["run", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(path) in err[0] and f"key '{key}'" in err[0] and words in err[0], err
        d["surfaces"][0].pop("untrimmed", None)
    d["surfaces"][0]["untrimmed"] = True
    spec = parse_design(d, "d.toml").surfaces[0]
    assert spec.untrimmed is True and parse_design(BASE, "d.toml").surfaces[0].untrimmed is False
    assert parse_design(d, "d.toml").to_dict()["surfaces"][0]["untrimmed"] is True


@pytest.mark.slow
def test_design_untrimmed_true_runs_and_reports_the_fraction(dome, tmp_path: Path) -> None:
    """``untrimmed = true`` on a design's approximate surface with the holed STEP face: the run
    succeeds and ``surface.approximation.trim`` records 0.874 and the hole."""
    from test_design_approximate import BASE, _toml

    from ght_cad.cad.occ import write_step

    write_step(holed_face(dome), tmp_path / "holed.step")
    d = copy.deepcopy(BASE)
    d["surfaces"][0].update(target={"step": "holed.step", "face": 1}, tol=2.0, method="loft", untrimmed=True)
    d["outputs"] = {"files": ["json"], "figures": []}
    (tmp_path / "d.toml").write_text(_toml(d))
    assert main(["run", str(tmp_path / "d.toml"), "--out", str(tmp_path / "out"), "--no-progress"]) == 0
    ap = json.loads((tmp_path / "out" / "report.json").read_text())["surface"]["approximation"]
    trim = ap["trim"]
    assert trim["untrimmed"] and trim["holes"] == 1 and 0.85 < trim["covered"] < 0.9 and ap["max_deviation"] <= 2.0, trim
