"""The ght-cad command line: help texts, exit codes, --json output, single-step commands."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ght_cad.app.cli import EXIT_FAILURE, EXIT_OK, EXIT_USAGE, build_parser, main

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
COMMANDS = ["demo", "run", "curve", "surface", "optimize", "unroll", "export", "plot-basis", "batch", "approximate"]

# exact quarter cone (spec section 1), no optimization block: fast
CONE = """
name = "cone"
[surface]
planes = [[-4, 1, 0, 0.5], [-4, 1, 1, 0.5], [-4, 0, 1, 0.5]]
boundary_planes = [[0, 0, 0, 1], [-4, 0, 0, 1]]
gamma = -1.0
normalize = false
"""


def run_json(argv: list[str], capsys: pytest.CaptureFixture) -> tuple[int, dict, str]:
    rc = main(argv + ["--json"])
    cap = capsys.readouterr()
    return rc, json.loads(cap.out), cap.err


@pytest.fixture
def cone(tmp_path: Path) -> Path:
    p = tmp_path / "cone.toml"
    p.write_text(CONE)
    return p


def test_help_of_every_command_is_fast_and_light() -> None:
    """`--help` does not import matplotlib, scipy or a CAD kernel."""
    code = (
        "import sys\nfrom ght_cad.app.cli import main\n"
        f"for c in {COMMANDS!r}:\n"
        "    try:\n        main([c, '--help'])\n    except SystemExit as e:\n        assert e.code == 0, (c, e.code)\n"
        "heavy = [m for m in ('matplotlib', 'scipy', 'OCP', 'build123d', 'cadquery') if m in sys.modules]\n"
        "print('HEAVY', heavy)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert "HEAVY []" in out.stdout
    for c in COMMANDS:
        assert f"usage: ght-cad {c}" in out.stdout
    assert out.stdout.count("exit codes: 0 success, 1 internal failure, 2 bad input") == len(COMMANDS)


def test_parser_lists_every_command() -> None:
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    assert set(sub.choices) == set(COMMANDS)


@pytest.mark.parametrize("argv", [[], ["frobnicate"], ["curve", "--mu"], ["plot-basis"], ["run"], ["demo", "--bogus"]])
def test_usage_errors_exit_2(argv: list[str], capsys) -> None:
    with pytest.raises(SystemExit) as ei:
        if main(argv) == EXIT_USAGE:  # no command: help on stderr, code 2
            raise SystemExit(EXIT_USAGE)
    assert ei.value.code == EXIT_USAGE
    assert capsys.readouterr().err


def test_curve_json_and_step(tmp_path: Path, capsys) -> None:
    from ght_cad.cad.occ import is_valid, read_step

    step = tmp_path / "c.step"
    rc, res, _ = run_json(
        ["curve", "--points", "1,0 1,1 0,1", "--gamma", "-1", "--step", str(step), "--plot", str(tmp_path / "c.png")], capsys
    )
    assert rc == EXIT_OK and res["ok"] and res["degree"] == 2
    # γ = -1, μ = ν = 0 on (1,0), (1,1), (0,1) is the exact quarter unit circle
    assert res["arc_length"] == pytest.approx(3.141592653589793 / 2, rel=1e-12)
    assert res["curvature_max"] == pytest.approx(1.0, rel=1e-9)
    assert is_valid(read_step(step)) and res["bspline"]["max_deviation"] <= 1e-6
    assert (tmp_path / "c.png").stat().st_size > 1000


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["curve", "--points", "0,0 1,1"], "at least 3"),
        (["curve", "--points", "0,0 1,x 2,0"], "'1,x' is not a point"),
        (["curve", "--points", "0,0 1,1 2,0", "--nu", "1.2"], "nu=1.2"),
        (["plot-basis", "--degree", "1", "--out", "b.png"], "degree=1"),
        (["plot-basis", "--params", "0,0", "--out", "b.png"], "three numbers"),
    ],
)
def test_bad_values_one_line_exit_2(argv: list[str], needle: str, capsys, tmp_path: Path, monkeypatch) -> None:
    monkeypatch.chdir(tmp_path)
    rc, res, err = run_json(argv, capsys)
    assert rc == EXIT_USAGE and res == {"ok": False, "error": res["error"], "exit_code": 2}
    assert len(err.strip().splitlines()) == 1 and needle in err
    assert not list(tmp_path.iterdir())  # nothing written


def test_plot_basis(tmp_path: Path, capsys) -> None:
    from test_plotting import png_size

    rc, res, _ = run_json(["plot-basis", "--degree", "5", "--params", "0,0,-1", "--params", "0.5,-0.5,0.3",
                           "--derivative", "1", "--out", str(tmp_path / "b.png")], capsys)
    assert rc == 0 and res["params"] == [[0, 0, -1], [0.5, -0.5, 0.3]]
    assert png_size(tmp_path / "b.png") == tuple(res["pixels"]) == (1200, 800)


def test_surface_unroll_export_on_a_design(cone: Path, tmp_path: Path, capsys) -> None:
    import math

    import ezdxf

    from ght_cad.cad.occ import is_valid, read_step

    rc, res, _ = run_json(["surface", str(cone), "--step", str(tmp_path / "s.step")], capsys)
    assert rc == 0 and res["developability"]["dd"] == pytest.approx(1.0, abs=1e-12)
    assert is_valid(read_step(tmp_path / "s.step"))
    rc, res, _ = run_json(["unroll", str(cone), "--dxf", str(tmp_path / "p.dxf"), "--svg", str(tmp_path / "p.svg")], capsys)
    assert rc == 0 and res["errors"]["max"] < 1e-12
    ezdxf.readfile(tmp_path / "p.dxf")
    files = [str(tmp_path / n) for n in ("e.step", "e.dxf", "e.svg", "e.json", "e.png")]
    rc, res, _ = run_json(["export", str(cone), *files], capsys)
    assert rc == 0 and sorted(res["outputs"].values()) == sorted(files)
    summary = json.loads((tmp_path / "e.json").read_text())
    # quarter frustum area: (pi/2) * (r1 + r2)/2 * slant, r = 4 and 2, slant = hypot(2, 4)
    assert summary["surface"]["area_3d"] == pytest.approx(math.pi / 2 * 3 * math.hypot(2, 4), rel=1e-12)


def test_export_unknown_suffix(cone: Path, tmp_path: Path, capsys) -> None:
    rc, res, err = run_json(["export", str(cone), str(tmp_path / "x.stl")], capsys)
    assert rc == EXIT_USAGE and ".stl" in err and ".step" in err and not (tmp_path / "x.stl").exists()


def test_optimize_command(tmp_path: Path, capsys) -> None:
    rc, res, _ = run_json(["optimize", str(EXAMPLES / "design_hull_plate_quasi.toml"), "--iterations", "4",
                           "--population", "8", "--method", "gwo", "--plot", str(tmp_path / "cv.png")], capsys)
    assert rc == 0 and res["method"] == "gwo" and res["objective"] == "R"
    assert res["best_value"] <= res["initial_value"]
    assert len(res["history"]) == 5 and (tmp_path / "cv.png").exists()
    rc, res, err = run_json(["optimize", str(EXAMPLES / "design_hull_plate_quasi.toml"), "--objective", "AL"], capsys)
    assert rc == EXIT_USAGE and "'optimize.objective'" in err and "allowed: R" in err


def test_optimize_needs_a_surface(tmp_path: Path, capsys) -> None:
    p = tmp_path / "c.toml"
    p.write_text('[[curves]]\ncontrol_points = [[0, 0], [1, 1], [2, 0]]\n')
    rc, res, err = run_json(["optimize", str(p)], capsys)
    assert rc == EXIT_USAGE and "'surface'" in err


def test_internal_failure_exit_1(cone: Path, tmp_path: Path, capsys, monkeypatch) -> None:
    import ght_cad.app.design as D

    def boom(*a, **k):
        raise RuntimeError("kernel exploded")

    monkeypatch.setattr(D, "surface_summary", boom)
    rc, res, err = run_json(["surface", str(cone)], capsys)
    assert rc == EXIT_FAILURE and res["exit_code"] == 1
    assert "internal failure: RuntimeError: kernel exploded" in err and len(err.strip().splitlines()) == 1


def test_console_script_is_installed() -> None:
    exe = Path(sys.executable).with_name("ght-cad")
    if not exe.exists():
        pytest.skip("ght-cad console script not installed next to this interpreter")
    out = subprocess.run([str(exe), "--version"], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.startswith("ght-cad ")


def test_composite_design_single_step_commands(tmp_path: Path, capsys) -> None:
    """surface/unroll/optimize on a two-strip design (the G2 joint kept); its shell STEP unrolls again panel by panel."""
    design = str(EXAMPLES / "design_duct_two_strips.toml")
    rc, out, err = run_json(["surface", design, "--step", str(tmp_path / "s.step")], capsys)
    assert rc == EXIT_OK, err
    assert [s["name"] for s in out["surface"]["strips"]] == ["quarter", "second-quarter"]
    assert out["surface"]["joints"][0]["achieved_G"] == 2 and out["developability"]["theta_max"] < 1e-10
    rc, out, err = run_json(["unroll", design], capsys)
    assert rc == EXIT_OK and out["errors"]["max"] < 1e-12, err
    rc, out, err = run_json(["optimize", design, "--population", "4", "--iterations", "2", "--no-progress"], capsys)
    assert rc == EXIT_OK and out["best_value"] <= out["initial_value"] and out["joints"][0]["achieved_G"] == 2, err
    rc, out, err = run_json(["unroll", str(tmp_path / "s.step")], capsys)
    assert rc == EXIT_OK and out["face_count"] == 2 and out["panels"] == 2, err


# --- audit fixes: JSON on argparse errors, output suffixes, ragged points, all-or-nothing export ---


@pytest.mark.parametrize(
    "argv,needle",
    [
        (["optimize", "X.toml", "--method", "foo", "--json"], "invalid choice: 'foo'"),
        (["plot-basis", "--degree", "x", "--json"], "invalid int value: 'x'"),
        (["plot-basis", "--json"], "--out"),  # a required option is missing
        (["--json", "curve"], "unrecognized arguments: --json"),  # --json before the command
    ],
)
def test_parser_errors_give_one_json_object_with_json(argv: list[str], needle: str, capsys) -> None:
    with pytest.raises(SystemExit) as ei:
        main(argv)
    cap = capsys.readouterr()
    assert ei.value.code == EXIT_USAGE
    res = json.loads(cap.out)  # exactly one JSON object, nothing else on stdout
    assert res["ok"] is False and res["exit_code"] == 2 and needle in res["error"]
    assert len(cap.err.strip().splitlines()) == 1 and needle in cap.err


def test_parser_errors_without_json_keep_stdout_empty(capsys) -> None:
    with pytest.raises(SystemExit) as ei:
        main(["plot-basis", "--degree", "x"])
    cap = capsys.readouterr()
    assert ei.value.code == EXIT_USAGE and cap.out == "" and "invalid int value" in cap.err


def test_help_documents_exit_codes_and_json_errors(capsys) -> None:
    with pytest.raises(SystemExit):
        main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "0 success, 1 internal failure, 2 bad input or usage" in out and "130 interrupted" in out
    assert "With --json, stdout is exactly one JSON object, errors included" in out


@pytest.mark.parametrize(
    "argv,option,allowed",
    [
        (["unroll", "{cone}", "--dxf", "p.txt"], "--dxf", ".dxf"),
        (["unroll", "{cone}", "--svg", "p.dxf"], "--svg", ".svg"),
        (["unroll", "{cone}", "--png", "p.svg"], "--png", ".png"),
        (["plot-basis", "--out", "b.txt"], "--out", ".png"),
        (["curve", "--points", "0,0 1,1 2,0", "--step", "c.txt"], "--step", ".step, .stp"),
        (["curve", "--points", "0,0 1,1 2,0", "--plot", "c.pdf"], "--plot", ".png"),
        (["curve", "--points", "0,0 1,1 2,0", "--curvature-plot", "k"], "--curvature-plot", ".png"),
        (["surface", "{cone}", "--step", "s.igs"], "--step", ".step, .stp"),
        (["surface", "{cone}", "--plot", "s.txt"], "--plot", ".png"),
        (["optimize", "{cone}", "--plot", "o.txt"], "--plot", ".png"),
    ],
)
def test_output_suffixes_are_checked(argv: list[str], option: str, allowed: str, cone: Path, tmp_path: Path,
                                     capsys, monkeypatch) -> None:
    """A wrong output suffix is one line naming the option, the value and the allowed suffixes; nothing written."""
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    argv = [a.replace("{cone}", str(cone)) for a in argv]
    value = argv[argv.index(option) + 1]
    rc, res, err = run_json(argv, capsys)
    assert rc == EXIT_USAGE and res["exit_code"] == 2 and len(err.strip().splitlines()) == 1
    assert f"{option} {value!r}" in err and f"allowed: {allowed}" in err
    assert not list(work.iterdir())


@pytest.mark.parametrize(
    "points,needle",
    [
        ("1,0 1,1,3 0,1", "point 2 (1,1,3) has dimension 3 but point 1 (1,0) has dimension 2"),
        ("0,0,0 1,1,1 2,0", "point 3 (2,0) has dimension 2 but point 1 (0,0,0) has dimension 3"),
        ("[[1, 0], [1, 1], [0, 1, 5]]", "point 3 (0,1,5) has dimension 3 but point 1 (1,0) has dimension 2"),
    ],
)
def test_ragged_points_name_the_point(points: str, needle: str, capsys) -> None:
    rc, res, err = run_json(["curve", "--points", points], capsys)
    assert rc == EXIT_USAGE and needle in err and "all points need the same dimension" in err
    assert "inhomogeneous" not in err and len(err.strip().splitlines()) == 1


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_export_is_all_or_nothing_when_a_target_folder_is_unwritable(cone: Path, tmp_path: Path, capsys) -> None:
    """A target under a regular file (its folder cannot exist) fails before anything is written."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.step").write_text("old step\n")  # an existing target: must stay as it was
    (out / "blocker").write_text("a file, not a folder\n")
    before = _snapshot(out)
    files = [str(out / "keep.step"), str(out / "new.svg"), str(out / "blocker" / "zz.dxf")]
    rc, res, err = run_json(["export", str(cone), *files], capsys)
    assert rc == EXIT_USAGE and "zz.dxf" in res["error"] and len(err.strip().splitlines()) == 1
    assert _snapshot(out) == before and sorted(p.name for p in out.iterdir()) == ["blocker", "keep.step"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cone.toml", "out"]  # no temporaries left


def test_export_is_all_or_nothing_when_a_writer_fails(cone: Path, tmp_path: Path, capsys, monkeypatch) -> None:
    """The last writer fails after the STEP and SVG were produced: none of the targets appears."""
    import ght_cad.curves.plotting as P

    def boom(*a, **k):
        raise RuntimeError("renderer exploded")

    monkeypatch.setattr(P, "plot_surface", boom)
    (tmp_path / "a.json").write_text("{}\n")
    sub = tmp_path / "new" / "folder"  # missing folders are created for the set and removed on failure
    files = [str(tmp_path / "a.step"), str(sub / "a.svg"), str(tmp_path / "a.json"), str(tmp_path / "a.png")]
    rc, res, err = run_json(["export", str(cone), *files], capsys)
    assert rc == EXIT_FAILURE and "renderer exploded" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "cone.toml"]
    assert (tmp_path / "a.json").read_text() == "{}\n"


def test_export_success_replaces_existing_and_creates_folders(cone: Path, tmp_path: Path, capsys) -> None:
    (tmp_path / "a.json").write_text("{}\n")
    files = [str(tmp_path / "a.json"), str(tmp_path / "d" / "e" / "a.dxf"), str(tmp_path / "d" / "a.step")]
    rc, res, err = run_json(["export", str(cone), *files], capsys)
    assert rc == EXIT_OK, err
    assert json.loads((tmp_path / "a.json").read_text())["surface"]["area_3d"] > 0
    assert (tmp_path / "d" / "e" / "a.dxf").stat().st_size > 1000
    assert (tmp_path / "d" / "a.step").read_text().startswith("ISO-10303-21")
    leftovers = [p for p in tmp_path.rglob("*") if "ght-cad" in p.name]
    assert not leftovers


def test_unroll_outputs_are_all_or_nothing(tmp_path, monkeypatch) -> None:
    """A failing PNG after the DXF and SVG were written: none of the three targets appears."""
    from pathlib import Path

    import ght_cad.app.design as design_mod
    from ght_cad.app.cli import main

    duct = Path(__file__).resolve().parents[1] / "examples" / "design_duct.toml"
    dxf, svg, png = tmp_path / "p.dxf", tmp_path / "p.svg", tmp_path / "p.png"
    svg.write_text("old")

    def broken(*a, **k):
        raise RuntimeError("plot failed")

    monkeypatch.setattr(design_mod, "plot_pattern", broken)
    rc = main(["unroll", str(duct), "--dxf", str(dxf), "--svg", str(svg), "--png", str(png)])
    assert rc == 1
    assert not dxf.exists() and not png.exists() and svg.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.svg"]
    monkeypatch.undo()
    assert main(["unroll", str(duct), "--dxf", str(dxf), "--svg", str(svg), "--png", str(png)]) == 0
    assert dxf.stat().st_size > 0 and svg.read_text() != "old" and png.stat().st_size > 0


@pytest.fixture
def python_sigint_handler():
    """Python's own Ctrl-C handler during the test (the one :func:`ght_cad.app.cli._watch_sigint` wraps),
    the inherited one restored after: a pytest started in the background by a non-interactive shell
    (``pytest &``) inherits SIGINT ignored, which the CLI rightly keeps ignored (the test below then
    failed with exit 1: the kill never arrived)."""
    import signal

    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, inherited)


def test_ctrl_c_that_surfaces_as_another_error_still_exits_130(monkeypatch, capsys, python_sigint_handler) -> None:
    """A Ctrl-C that lands inside an extension's import can surface later as an ImportError of the
    half-initialized module (seen with OCP): the run still reports "interrupted", exit 130, and the
    SIGINT handler is restored afterwards."""
    import os
    import signal

    from ght_cad.app import cli

    def interrupted_import(args):
        try:
            os.kill(os.getpid(), signal.SIGINT)  # the handler raises KeyboardInterrupt here
        except KeyboardInterrupt:
            pass  # swallowed half-way, as inside a module initializer
        raise ImportError('generic_type: cannot initialize type "X": an object with that name is already defined')

    monkeypatch.setattr(cli, "cmd_plot_basis", interrupted_import)
    before = signal.getsignal(signal.SIGINT)
    assert cli.main(["plot-basis", "--out", "b.png", "--json"]) == cli.EXIT_INTERRUPTED
    assert json.loads(capsys.readouterr().out) == {"ok": False, "error": "interrupted", "exit_code": 130}
    assert signal.getsignal(signal.SIGINT) is before
    # the same ImportError without a Ctrl-C is an internal failure
    monkeypatch.setattr(cli, "cmd_plot_basis", lambda args: (_ for _ in ()).throw(ImportError("boom")))
    assert cli.main(["plot-basis", "--out", "b.png"]) == cli.EXIT_FAILURE


@pytest.mark.parametrize("command", ["run", "demo"])
def test_out_folder_under_a_file_is_bad_input_not_internal_failure(command: str, cone: Path, tmp_path: Path,
                                                                   capsys) -> None:
    """``--out blocker/sub`` where ``blocker`` is a regular file: exit 2 naming the path (was exit 1,
    "internal failure: FileExistsError"), nothing written, the file untouched."""
    (tmp_path / "blocker").write_text("a file\n")
    argv = ["run", str(cone)] if command == "run" else ["demo", "--quick"]
    rc, res, err = run_json([*argv, "--out", str(tmp_path / "blocker" / "sub" / "out")], capsys)
    assert rc == EXIT_USAGE and res["exit_code"] == EXIT_USAGE, err
    assert "blocker" in res["error"] and "internal failure" not in res["error"]
    assert len(err.strip().splitlines()) == 1
    assert (tmp_path / "blocker").read_text() == "a file\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blocker", "cone.toml"]


def test_failed_run_removes_the_folders_it_created(tmp_path: Path, capsys) -> None:
    """A run that fails (degenerate design) into ``--out new/a/b`` leaves no ``new`` folder behind."""
    bad = tmp_path / "bad.toml"
    bad.write_text(CONE.replace("[-4, 0, 1, 0.5]]", "[-4, 1, 0, 0.5]]"))  # two equal planes
    rc, res, err = run_json(["run", str(bad), "--out", str(tmp_path / "new" / "a" / "b")], capsys)
    assert rc == EXIT_USAGE, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


@pytest.mark.parametrize("argv", [
    ["curve", "--points", "1,0 1,1 0,1", "--step", "{d}/ok.step", "--plot", "{d}/ok.png",
     "--curvature-plot", "{d}/blocker/k.png"],
    ["surface", "{cone}", "--step", "{d}/ok.step", "--plot", "{d}/blocker/s.png"],
])
def test_curve_and_surface_outputs_are_all_or_nothing(argv: list[str], cone: Path, tmp_path: Path, capsys) -> None:
    """The last output of ``curve``/``surface`` cannot be written (its folder is a file): exit 2 naming
    it, and the STEP/PNG written before it do not appear (they did: ok.step, ok.png were left)."""
    d = tmp_path / "out"
    d.mkdir()
    (d / "blocker").write_text("a file\n")
    (d / "ok.step").write_text("old\n")  # an existing target keeps its content
    argv = [a.format(d=d, cone=cone) for a in argv]
    rc, res, err = run_json(argv, capsys)
    assert rc == EXIT_USAGE and "blocker" in res["error"] and "internal failure" not in res["error"], err
    assert sorted(p.name for p in d.iterdir()) == ["blocker", "ok.step"]
    assert (d / "ok.step").read_text() == "old\n" and (d / "blocker").read_text() == "a file\n"
    rc, res, err = run_json([a.replace("blocker/", "") for a in argv], capsys)  # and now it works
    assert rc == EXIT_OK, err
    assert (d / "ok.step").read_text().startswith("ISO-10303-21") and sorted(res["outputs"].values()) == sorted(
        a.replace("blocker/", "") for a in argv if a.endswith((".step", ".png")))


def test_single_png_under_a_file_is_bad_input(tmp_path: Path, capsys) -> None:
    """``plot-basis --out blocker/b.png`` with ``blocker`` a file: exit 2 naming it (was exit 1)."""
    (tmp_path / "blocker").write_text("a file\n")
    rc, res, err = run_json(["plot-basis", "--out", str(tmp_path / "blocker" / "b.png")], capsys)
    assert rc == EXIT_USAGE and "blocker is a file, not a folder" in res["error"], err
    assert "None" not in res["error"] and len(err.strip().splitlines()) == 1


def test_export_json_is_a_report_with_units_and_the_flat_pattern(tmp_path: Path, capsys) -> None:
    """``export D.toml r.json`` next to a DXF: the JSON states the units and the flat pattern's area,
    errors and edge marks, the same numbers as ``run``'s report.json (it had only surface,
    developability and curves). A strip named "Elbow" is a panel, not an edge mark (labels starting
    with "E" were all counted as edge marks). One panel per strip (`[unroll] panels = "per-surface"`;
    joined, the strips are one blank labelled with the design's name and nothing to mark)."""
    text = (EXAMPLES / "design_duct_two_strips.toml").read_text().replace('name = "quarter"', 'name = "Elbow"')
    text = text.replace("[unroll]\n", '[unroll]\npanels = "per-surface"\n')
    design = tmp_path / "two.toml"
    design.write_text(text)
    rc, res, err = run_json(["export", str(design), str(tmp_path / "p.dxf"), str(tmp_path / "r.json")], capsys)
    assert rc == EXIT_OK, err
    rep = json.loads((tmp_path / "r.json").read_text())
    assert rep["units"] == "m" and rep["name"] == "duct-two-strips"
    fp = rep["flat_pattern"]
    assert fp["edge_marks"] == ["E1"] and [p["label"] for p in fp["panels"]] == ["Elbow", "second-quarter"]
    assert fp["area"] == pytest.approx(rep["surface"]["area_3d"], rel=1e-12) and fp["errors"]["max"] < 1e-12
    rc, res, err = run_json(["run", str(design), "--out", str(tmp_path / "out")], capsys)
    assert rc == EXIT_OK, err
    run_fp = json.loads((tmp_path / "out" / "report.json").read_text())["flat_pattern"]
    assert run_fp["edge_marks"] == ["E1"] and run_fp["area"] == pytest.approx(fp["area"], rel=1e-14)


def test_run_into_a_folder_where_an_output_name_is_a_folder_changes_nothing(cone: Path, tmp_path: Path,
                                                                            capsys) -> None:
    """``--out`` holds a folder named ``report.md``: exit 2 naming it, and no file of the run is moved
    in (model.step, flat_pattern.* and report.json were moved before the rename of report.md failed)."""
    out = tmp_path / "out"
    (out / "report.md").mkdir(parents=True)
    (out / "model.step").write_text("old\n")
    rc, res, err = run_json(["run", str(cone), "--out", str(out)], capsys)
    assert rc == EXIT_USAGE and "report.md" in res["error"] and "internal failure" not in res["error"], err
    assert sorted(p.name for p in out.iterdir()) == ["model.step", "report.md"]
    assert (out / "model.step").read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cone.toml", "out"]  # no staging folder left


def test_curve_whose_control_points_coincide(tmp_path: Path, capsys) -> None:
    """All control points equal: the properties are reported (arc length 0, curvature null) without
    numpy warnings on stderr, and ``--step`` is refused with exit 2 (a zero-length STEP edge was
    written)."""
    rc, res, err = run_json(["curve", "--points", "2,3 2,3 2,3", "--plot", str(tmp_path / "c.png"),
                             "--curvature-plot", str(tmp_path / "k.png")], capsys)
    assert rc == EXIT_OK and abs(res["arc_length"]) < 1e-12 and res["curvature_max"] is None
    assert "Warning" not in err, err
    rc, res, err = run_json(["curve", "--points", "2,3 2,3 2,3", "--step", str(tmp_path / "c.step")], capsys)
    assert rc == EXIT_USAGE and "coincide" in res["error"] and len(err.strip().splitlines()) == 1, err
    assert not (tmp_path / "c.step").exists()


def test_curve_of_3000_control_points_and_a_straight_line(capsys) -> None:
    """Degree 2999 (C(n, n/2) overflows a float from n = 1030 on; it was exit 1, OverflowError):
    exit 0 with the right arc length; a straight line's curvature_max is round-off (degree 2: was 3.6e-9)."""
    x = [3.0 * i / 2999 for i in range(3000)]
    pts = " ".join(f"{a!r},{4 * a / 3!r}" for a in x)  # on the line y = 4x/3: length 5
    rc, res, err = run_json(["curve", "--points", pts, "--gamma", "0.4"], capsys)
    assert rc == EXIT_OK, err
    assert res["degree"] == 2999 and abs(res["arc_length"] - 5.0) < 1e-9, res["arc_length"]
    # round-off of P''_⊥ grows like m² 1e-16 |P| / |P'|² = 9e6 · 1e-16 · 5 / 25 ≈ 2e-10 at this degree
    assert res["curvature_max"] < 1e-9, res["curvature_max"]
    rc, res, err = run_json(["curve", "--points", "0,0 1,1 2,2"], capsys)
    assert rc == EXIT_OK and res["curvature_max"] < 1e-15, res["curvature_max"]
