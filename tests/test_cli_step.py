"""`ght-cad unroll FILE.step`: developable faces of a STEP file → one labelled panel per face.

STEP files are written into tmp_path from the project's own faces (an exact quarter cone from
control planes, a shell of two G2-joined strips) and from build123d (cylinder, cone), plus a
twisted bilinear patch that is not developable.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path

import build123d as bd
import ezdxf
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from ght_cad.surfaces.bspline import BSplineSurfaceData
from ght_cad.cad.occ import make_face, write_step
from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main
from ght_cad.app.design import unroll_step
from ght_cad.developables.envelope import CompositeDevelopable, developable_from_planes, join_developable

RTOL = 1e-9

# strips of the duct transition of examples/design_duct_two_strips.toml (planes through an apex)
STRIP_A = [[-0.996546, 0.996546, 0.0, -0.083045], [-0.99876, 0.864952, 0.49938, -0.049778],
           [-0.999133, 0.499567, 0.865275, 0.041631], [-0.986394, 0.0, 0.986394, 0.164399]]
STRIP_B = [[-0.978638, -0.169939, 0.96377, 0.205591], [-0.969645, -0.331638, 0.911168, 0.244517],
           [-0.96, -0.48, 0.831384, 0.28], [-0.941433, -0.721179, 0.605141, 0.3372],
           [-0.927967, -0.872004, 0.317383, 0.372662], [-0.923077, -0.923077, 0.0, 0.384615]]
ENDS = [[0, 0, 0, 1], [-2.5, -0.15, 0, 1]]


def _face(shape, kind):
    return next(f for f in shape.faces() if f.geom_type == kind)


def _run(argv: list[str], capsys) -> tuple[int, dict, str]:
    rc = main(argv + ["--json"])
    cap = capsys.readouterr()
    return rc, json.loads(cap.out), cap.err


def _dxf(path: Path) -> dict:
    doc = ezdxf.readfile(path)
    msp = doc.modelspace()
    outlines = [e for e in msp if e.dxftype() == "LWPOLYLINE" and e.dxf.layer == "OUTLINE"]
    assert outlines and all(e.closed for e in outlines)
    return {
        "layers": {layer.dxf.name for layer in doc.layers},
        "outlines": [np.array([(p[0], p[1]) for p in e.get_points()]) for e in outlines],
        "bends": [e for e in msp if e.dxftype() == "LINE" and e.dxf.layer == "BEND"],
        "labels": [e.dxf.text for e in msp if e.dxftype() == "TEXT"],
        "insunits": doc.header["$INSUNITS"],
    }


def test_cylinder_step_is_r_theta_by_h(tmp_path: Path, capsys) -> None:
    R, H, arc = 30.0, 50.0, 120.0
    step = tmp_path / "cyl.step"
    write_step(_face(bd.Solid.make_cylinder(R, H, angle=arc), bd.GeomType.CYLINDER), step)
    rc, out, err = _run(["unroll", str(step), "--dxf", str(tmp_path / "c.dxf"), "--rulings", "5"], capsys)
    assert rc == EXIT_OK, err
    assert out["units"] == "mm" and out["file_units"] == "mm" and out["panels"] == 1
    d = _dxf(tmp_path / "c.dxf")
    assert {"OUTLINE", "BEND", "LABELS", "MARKS"} <= d["layers"] and d["insunits"] == 4
    assert len(d["outlines"]) == 1 and len(d["bends"]) == 5 and "F1" in d["labels"]
    ext = np.sort(np.ptp(d["outlines"][0], axis=0))
    np.testing.assert_allclose(ext, np.sort([R * math.radians(arc), H]), rtol=RTOL)
    np.testing.assert_allclose(out["area"], R * math.radians(arc) * H, rtol=RTOL)


@given(st.floats(5.0, 40.0), st.floats(0.2, 0.9), st.floats(5.0, 60.0), st.floats(20.0, 350.0))
@settings(max_examples=6, deadline=None)
def test_cone_step_is_annular_sector(r2: float, ratio: float, h: float, arc: float) -> None:
    """Cone frustum faces over a parameter box, written to STEP and unrolled in cm: the annular
    sector of spec section 6 (radii ρ = r·slant/(r2 - r1), angle θ r2/ρ2), scaled by 1/10."""
    r1 = ratio * r2
    with tempfile.TemporaryDirectory() as tmp:
        step = Path(tmp) / "cone.stp"
        write_step(_face(bd.Solid.make_cone(r1, r2, h, angle=arc), bd.GeomType.CONE), step)
        res = unroll_step(step, units="cm", rulings=3)
    assert res.units == "cm" and res.file_units == "mm"
    slant = math.hypot(r2 - r1, h)
    rho2, rho1 = r2 * slant / (r2 - r1), r1 * slant / (r2 - r1)
    angle = math.radians(arc) * r2 / rho2
    np.testing.assert_allclose(res.pattern.area, 0.5 * angle * (rho2**2 - rho1**2) / 100.0, rtol=RTOL)
    # the straight sides of the sector have the slant length
    lengths = sorted(e.length_flat for e in res.pattern.panels[0].loops[0])
    assert any(math.isclose(x, slant / 10.0, rel_tol=RTOL) for x in lengths), (lengths, slant / 10)
    assert res.pattern.errors["max"] < RTOL


def test_file_units_are_the_default(tmp_path: Path, capsys) -> None:
    """A STEP file that declares metres gives a pattern in metres (DXF $INSUNITS 6)."""
    R, H, arc = 300.0, 500.0, 90.0  # mm; the model is written in metres
    step = tmp_path / "cyl_m.step"
    write_step(_face(bd.Solid.make_cylinder(R / 1e3, H / 1e3, angle=arc), bd.GeomType.CYLINDER), step, units="m")
    rc, out, err = _run(["unroll", str(step), "--dxf", str(tmp_path / "m.dxf"), "--svg", str(tmp_path / "m.svg")], capsys)
    assert rc == EXIT_OK, err
    assert out["file_units"] == "m" and out["units"] == "m"
    np.testing.assert_allclose(out["area"], R * math.radians(arc) * H / 1e6, rtol=RTOL)
    assert _dxf(tmp_path / "m.dxf")["insunits"] == 6
    assert (tmp_path / "m.svg").read_text().lstrip().startswith("<")


@pytest.mark.parametrize("units", ["in", "ft", "cm"])
def test_file_units_one_spelling(tmp_path: Path, capsys, units: str) -> None:
    """file_units is spelled like units (mm, cm, m, in, ft) whether the STEP file writes an SI unit
    ('millimetre', .CENTI. 'METRE') or a conversion-based one ('INCH', 'FOOT')."""
    step = tmp_path / f"cyl_{units}.step"
    write_step(_face(bd.Solid.make_cylinder(3.0, 5.0, angle=90.0), bd.GeomType.CYLINDER), step, units=units)
    rc, out, err = _run(["unroll", str(step)], capsys)
    assert rc == EXIT_OK, err
    assert out["file_units"] == units and out["units"] == units, out


def test_project_face_and_two_strip_shell(tmp_path: Path, capsys) -> None:
    """An exact quarter cone from control planes, and a shell of two G2-joined strips: one panel
    per face, the shared ruling marked on both panels, each panel's area = its strip's area."""
    from ght_cad.cad.developable_faces import composite_shell
    from ght_cad.unrolling.unroll import ruled_area

    quarter = developable_from_planes([[-400, 1, 0, 0.5], [-400, 1, 1, 0.5], [-400, 0, 1, 0.5]],
                                      [[0, 0, 0, 1], [-400, 0, 0, 1]], 0, 0, -1)
    write_step(quarter.to_face(), tmp_path / "q.step")
    rc, out, err = _run(["unroll", str(tmp_path / "q.step")], capsys)
    assert rc == EXIT_OK, err
    rho2 = math.hypot(400, 800)
    ang = (math.pi / 2) * 400 / rho2
    np.testing.assert_allclose(out["area"], 0.5 * ang * (rho2**2 - (rho2 / 2) ** 2), rtol=1e-7)  # fit tol 1e-7

    a = developable_from_planes(STRIP_A, ENDS, gamma=-1.0)
    b = join_developable(a, "G2", STRIP_B, mu=0.0, nu=0.0, gamma=-1.0)
    comp = CompositeDevelopable([a, b])
    write_step(composite_shell(comp), tmp_path / "duct.step")
    rc, out, err = _run(["unroll", str(tmp_path / "duct.step"), "--dxf", str(tmp_path / "d.dxf")], capsys)
    assert rc == EXIT_OK, err
    assert out["face_count"] == 2 and out["panels"] == 2
    d = _dxf(tmp_path / "d.dxf")
    assert len(d["outlines"]) == 2 and {"F1", "F2"} <= set(d["labels"])
    marks = [t for t in d["labels"] if t.startswith("E")]
    assert marks == ["E1", "E1"]  # the joint ruling, marked on both panels
    areas = sorted(f["area_flat"] for f in out["faces"])
    np.testing.assert_allclose(areas, sorted([ruled_area(a), ruled_area(b)]), rtol=1e-7)  # B-spline fit 1e-7
    for f in out["faces"]:
        assert f["developability"]["theta_max"] < 1e-3  # B-spline fit of a tolerance-1e-7 strip
        np.testing.assert_allclose(f["area_flat"], f["area_3d"], rtol=1e-12)

    # --face picks one face; a face number out of range is exit 2
    rc, out, _ = _run(["unroll", str(tmp_path / "duct.step"), "--face", "2"], capsys)
    assert rc == EXIT_OK and out["panels"] == 1 and out["faces"][0]["label"] == "F2"
    rc, out, err = _run(["unroll", str(tmp_path / "duct.step"), "--face", "3"], capsys)
    assert rc == EXIT_USAGE and "face 3 does not exist; allowed: face numbers 1..2" in out["error"]


def test_twisted_face_is_refused_then_best_effort(tmp_path: Path, capsys) -> None:
    net = np.array([[[0, 0, 0], [0, 10, 10]], [[10, 0, 0], [10, 10, 0]]], float)
    step = tmp_path / "twist.step"
    write_step([make_face(BSplineSurfaceData(net, [0, 0, 1, 1], [0, 0, 1, 1], 1, 1)),
                _face(bd.Solid.make_cylinder(3.0, 5.0, angle=90), bd.GeomType.CYLINDER)], step)
    dxf = tmp_path / "t.dxf"
    rc = main(["unroll", str(step), "--dxf", str(dxf)])
    err = capsys.readouterr().err
    assert rc == EXIT_USAGE and not dxf.exists()
    assert err.count("\n") == 1
    assert f"{step}: face 1 of 2 is not developable within tol_deg=0.01: theta_max=45 deg" in err
    assert "DD=0.75" in err and "--best-effort" in err
    rc, out, err = _run(["unroll", str(step), "--face", "2"], capsys)  # the cylinder alone is fine
    assert rc == EXIT_OK and out["faces"][0]["surface_type"] == "cylinder"
    rc, out, err = _run(["unroll", str(step), "--best-effort", "--dxf", str(dxf)], capsys)
    assert rc == EXIT_OK and dxf.exists() and out["panels"] == 2
    twisted = out["faces"][0]
    assert twisted["best_effort"] and twisted["developability"]["theta_max"] == pytest.approx(45.0, rel=1e-6)
    assert out["errors"]["area"] > 1e-3  # the distortion is reported


def test_step_input_errors(tmp_path: Path, capsys) -> None:
    rc, out, _ = _run(["unroll", str(tmp_path / "missing.step")], capsys)
    assert rc == EXIT_USAGE and "missing.step: no such STEP file" in out["error"]
    bad = tmp_path / "bad.step"
    bad.write_text("not a step file\n")
    rc, out, _ = _run(["unroll", str(bad)], capsys)
    assert rc == EXIT_USAGE and "not a readable STEP file" in out["error"]
    toml = tmp_path / "d.toml"
    toml.write_text("[surface]\nplanes = [[0,1,0,0],[0,1,1,0],[0,0,1,0]]\nboundary_planes = [[0,0,0,1],[-1,0,0,1]]\n")
    rc, out, _ = _run(["unroll", str(toml), "--face", "1"], capsys)
    assert rc == EXIT_USAGE and "--face applies to STEP input only" in out["error"]


def test_non_ruled_face_is_refused_with_its_deviation(tmp_path: Path, capsys) -> None:
    step = tmp_path / "hemisphere.step"
    write_step(bd.Sphere(3.0, arc_size1=0).faces()[0], step)
    rc, out, _ = _run(["unroll", str(step), "--png", str(tmp_path / "s.png")], capsys)
    assert rc == EXIT_USAGE and not (tmp_path / "s.png").exists()
    assert f"{step}: face 1 of 1 is not developable" in out["error"]
    # straightest isoline of a sphere: a closed parallel, deviation r / (2 pi r) = 1/(2 pi) = 0.159
    assert "it is not ruled: its straightest isolines deviate 0.159 from straight lines" in out["error"]
    # best effort: rulings from the equator to the pole (a cone, area pi r l = 18 pi / sqrt 2 against
    # 18 pi): the distortion 1 - 1/sqrt 2 = 0.293 is reported
    rc, out, _ = _run(["unroll", str(step), "--best-effort"], capsys)
    assert rc == EXIT_OK and out["errors"]["area"] == pytest.approx(1 - 2**-0.5, rel=1e-6)


def test_full_sphere_is_refused_even_with_best_effort(tmp_path: Path, capsys) -> None:
    """The meridians of a full sphere run from pole to pole: the ruled surface between the two
    boundary isolines (points) has no area (before: exit 0 and a pattern of area 7.7e-14)."""
    step = tmp_path / "sphere.step"
    write_step(bd.Sphere(3.0).faces()[0], step)
    rc, out, _ = _run(["unroll", str(step), "--best-effort", "--dxf", str(tmp_path / "s.dxf")], capsys)
    assert rc == EXIT_USAGE and not (tmp_path / "s.dxf").exists()
    assert f"{step}: face 1 of 1" in out["error"] and "run between two points" in out["error"]
    # without --best-effort the refusal must not suggest --best-effort, which cannot help here
    rc, out, _ = _run(["unroll", str(step)], capsys)
    assert rc == EXIT_USAGE and "not developable" in out["error"]
    assert "or --best-effort to flatten" not in out["error"] and "cannot flatten it either" in out["error"]
    assert out["error"].count("cannot flatten it either") == 1


def _cli_json(argv: list[str]) -> tuple[int, dict, str]:
    """Run ``python -m ght_cad.app.cli ARGV --json`` in a subprocess; stdout must be exactly one JSON object."""
    import subprocess
    import sys

    proc = subprocess.run([sys.executable, "-m", "ght_cad.app.cli", *argv, "--json"], capture_output=True, text=True,
                          timeout=300)
    return proc.returncode, _one_json(proc.stdout), proc.stderr


def _one_json(stdout: str) -> dict:
    """The one JSON object ``stdout`` must be exactly."""
    obj, end = json.JSONDecoder().raw_decode(stdout.lstrip())
    assert not stdout.lstrip()[end:].strip(), f"more than one JSON object on stdout: {stdout!r}"
    return obj


@pytest.mark.slow
def test_json_stdout_is_clean_of_kernel_console_output(tmp_path: Path, capfd) -> None:
    """OCCT prints STEP parse errors from C++ to fd 1; with --json they must end up on stderr.

    The refused file in a subprocess (the C++ output at process exit included); the good file in
    this process, its file descriptors 1 and 2 captured (``capfd``): one Python + OCP start-up
    less (issue 27)."""
    bad = tmp_path / "bad.step"
    bad.write_text("garbage\nthis is not ISO-10303-21\n")
    rc, out, err = _cli_json(["unroll", str(bad)])
    assert rc == EXIT_USAGE and out["ok"] is False and out["exit_code"] == 2
    assert "not a readable STEP file" in out["error"] and "not a readable STEP file" in err
    step = tmp_path / "cyl.step"
    write_step(_face(bd.Solid.make_cylinder(30.0, 50.0, angle=90.0), bd.GeomType.CYLINDER), step)
    capfd.readouterr()
    rc = main(["unroll", str(step), "--dxf", str(tmp_path / "c.dxf"), "--json"])
    captured = capfd.readouterr()
    out, err = _one_json(captured.out), captured.err
    assert rc == EXIT_OK and out["ok"] is True and out["panels"] == 1, err
    np.testing.assert_allclose(out["area"], 30.0 * math.pi / 2 * 50.0, rtol=RTOL)
