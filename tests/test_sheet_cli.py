"""`ght-cad unroll FILE.step --thickness T --k-factor K` and plate solids read from STEP (spec 6.1)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

pytest.importorskip("build123d")

import build123d as bd  # noqa: E402
import ezdxf  # noqa: E402

from ght_cad.cad.occ import write_step  # noqa: E402
from ght_cad.cad.sheet_solid import plate_solid, write_plate_step  # noqa: E402
from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main  # noqa: E402
from ght_cad.sheetmetal.sheet import Sheet  # noqa: E402

R, H, T, K = 240.0, 100.0, 4.0, 0.42


def _run(argv: list[str], capsys) -> tuple[int, dict, str]:
    rc = main(argv + ["--json"])
    cap = capsys.readouterr()
    return rc, json.loads(cap.out), cap.err


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("sheet_cli")
    face = next(f for f in bd.Solid.make_cylinder(R, H, angle=90).faces() if f.geom_type.name == "CYLINDER")
    write_step(face, d / "face.step")
    write_plate_step(plate_solid(face, Sheet(T, K)), d / "plate.step")
    return {"face": d / "face.step", "plate": d / "plate.step", "dir": d}


def test_face_with_thickness_and_outputs(files, capsys, tmp_path) -> None:
    dxf, png = tmp_path / "p.dxf", tmp_path / "chart.png"
    rc, res, err = _run(["unroll", str(files["face"]), "--thickness", str(T), "--k-factor", str(K),
                         "--dxf", str(dxf), "--forming-png", str(png)], capsys)
    assert rc == EXIT_OK, err
    assert res["area"] == pytest.approx(0.5 * math.pi * (R + K * T) * H, rel=1e-9)
    (sh,) = res["sheet"]
    assert sh["thickness"] == T and sh["k_factor"] == K and sh["side"] == "normal"
    arcs = [e for e in sh["edges"] if abs(e["inside"] - H) > 1e-6]
    assert [e["flat"] for e in arcs] == pytest.approx([0.5 * math.pi * (R + K * T)] * 2, rel=1e-9)
    assert sh["forming"][0]["radius_a"] == pytest.approx(R + K * T, rel=1e-9)
    doc = ezdxf.readfile(dxf)
    assert [t.dxf.text for t in doc.modelspace().query("TEXT") if t.dxf.layer == "FORMING"] == ["R241.7 A90.00deg"]
    assert png.read_bytes()[:4] == b"\x89PNG"
    # DIN k = 2K and the other side: φ (r - K T)
    rc, res, err = _run(["unroll", str(files["face"]), "--thickness", str(T), "--din-k-factor", str(2 * K),
                         "--side", "reverse"], capsys)
    assert rc == EXIT_OK, err
    assert res["area"] == pytest.approx(0.5 * math.pi * (R - K * T) * H, rel=1e-9)


def test_plate_solid_from_step(files, capsys) -> None:
    """--k-factor alone on a plate solid: its inside face with the thickness between its faces."""
    rc, res, err = _run(["unroll", str(files["plate"]), "--k-factor", str(K)], capsys)
    assert rc == EXIT_OK, err
    assert res["panels"] == 1
    assert res["plate"]["thickness"] == pytest.approx(T, rel=1e-9)
    assert res["area"] == pytest.approx(0.5 * math.pi * (R + K * T) * H, rel=1e-9)
    # the same thickness given explicitly is accepted; a different one is refused
    rc, res, err = _run(["unroll", str(files["plate"]), "--thickness", str(T)], capsys)
    assert rc == EXIT_OK, err
    assert res["area"] == pytest.approx(0.5 * math.pi * (R + 0.5 * T) * H, rel=1e-9)
    rc, res, err = _run(["unroll", str(files["plate"]), "--thickness", "3"], capsys)
    assert rc == EXIT_USAGE and "--thickness=3.0" in err and "4" in err


@pytest.mark.parametrize(
    "opts, word",
    [
        (["--thickness", "-1"], "thickness=-1.0"),
        (["--thickness", "nan"], "thickness=nan"),
        (["--thickness", "4", "--k-factor", "1.5"], "k_factor=1.5"),
        (["--thickness", "4", "--din-k-factor", "2.5"], "din_k_factor=2.5"),
        (["--thickness", "250", "--k-factor", "1"], "bending radius 240"),
        (["--thickness", "245", "--k-factor", "0.1", "--side", "reverse"], "centre of curvature"),
        (["--k-factor", "0.4"], "no thickness"),
    ],
)
def test_bad_sheet_values_exit_2_and_write_nothing(files, capsys, tmp_path, opts, word) -> None:
    dxf, png = tmp_path / "bad.dxf", tmp_path / "bad.png"
    rc = main(["unroll", str(files["face"]), *opts, "--dxf", str(dxf), "--png", str(png)])
    err = capsys.readouterr().err
    assert rc == EXIT_USAGE
    assert word in err and len(err.strip().splitlines()) == 1, err
    assert not dxf.exists() and not png.exists()


def test_sheet_flags_on_a_design_file_are_refused(capsys, tmp_path) -> None:
    from ght_cad.app.demo import default_design_text

    p = tmp_path / "d.toml"
    p.write_text(default_design_text())
    rc = main(["unroll", str(p), "--thickness", "2"])
    assert rc == EXIT_USAGE and "[sheet]" in capsys.readouterr().err
    rc = main(["unroll", str(p), "--forming-png", str(tmp_path / "c.png")])
    assert rc == EXIT_USAGE and "--forming-png needs a sheet thickness" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.parametrize("side", ["normal", "reverse"])
def test_plate_step_of_a_run_unrolls_to_the_runs_neutral_pattern(tmp_path, capsys, side) -> None:
    """`ght-cad run` with a [sheet] writes its plate to model.step with named faces; `ght-cad unroll
    model.step --k-factor K` finds the inside face by its name, so the neutral pattern is the run's
    on either side. By geometry alone (the smaller face is the inside) the material on the concave
    side measured K from the wrong face: the duct's pattern came out 2.4 % short."""
    design = (Path(__file__).resolve().parents[1] / "examples" / "design_duct.toml").read_text()
    p = tmp_path / "duct.toml"
    p.write_text(design + f'\n[sheet]\nthickness = 20\nk_factor = 0.3\nside = "{side}"\n')
    out = tmp_path / "out"
    assert main(["run", str(p), "--out", str(out)]) == EXIT_OK, capsys.readouterr().err
    run_area = json.loads((out / "report.json").read_text())["flat_pattern"]["area"]
    capsys.readouterr()
    rc, res, err = _run(["unroll", str(out / "model.step"), "--k-factor", "0.3"], capsys)
    assert rc == EXIT_OK, err
    assert res["plate"]["found_by"] == "names"
    assert res["area"] == pytest.approx(run_area, rel=1e-8)  # the STEP faces are fits (3e-7 T)
