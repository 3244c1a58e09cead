"""``ght-cad approximate`` front end (issue 24): ``--method`` recorded in report.json/.md, the core's
progress lines on stderr (as ``ght-cad run`` shows its steps: a terminal or ``GHT_CAD_PROGRESS=1``,
never with ``--no-progress``), choices from the design files' constants, and a tolerance that
``--max-panels`` cannot meet: exit 2 with one line naming the best deviation reached.

The target is the facade example's quadratic NURBS patch (1200 x 800 mm, double-curved) as a
STEP face: 4 panels at tol 2 (``--method loft``: 1.42 mm, ~7 s).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from ght_cad.app.cli import main

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "design_approximate_facade.toml"


def _poles() -> np.ndarray:
    try:
        import tomllib
    except ModuleNotFoundError:  # pragma: no cover - Python 3.10
        import tomli as tomllib  # type: ignore[no-redef]

    return np.array(tomllib.loads(EXAMPLE.read_text())["surfaces"][0]["target"]["poles"], dtype=float)


def _facade_step(tmp_path: Path) -> Path:
    pytest.importorskip("OCP")
    from ght_cad.surfaces.bspline import BSplineSurfaceData
    from ght_cad.cad.occ import make_face, write_step

    k = np.array([0.0, 0, 0, 1, 1, 1])
    return Path(write_step(make_face(BSplineSurfaceData(_poles(), k, k, 2, 2)), tmp_path / "facade.step"))


def test_choices_come_from_the_design_constants(capsys: pytest.CaptureFixture) -> None:
    """--direction and --method offer exactly APPROX_DIRECTIONS / APPROX_METHODS (what design files
    and the FreeCAD feature offer); a bad one: exit 2, one line naming the option and the choices."""
    from ght_cad.app.cli import build_parser
    from ght_cad.app.design.schema.constants import APPROX_DIRECTIONS, APPROX_METHODS

    sub = next(a for a in build_parser()._actions if a.dest == "command").choices["approximate"]
    opts = {a.dest: a for a in sub._actions}
    assert tuple(opts["direction"].choices) == APPROX_DIRECTIONS and tuple(opts["method"].choices) == APPROX_METHODS
    assert opts["method"].default == "auto"
    import ght_cad.approximation as core

    if hasattr(core, "DIRECTIONS"):  # the core's own list (the FreeCAD feature reads that one)
        assert tuple(core.DIRECTIONS) == APPROX_DIRECTIONS
    with pytest.raises(SystemExit) as ei:  # argparse's usage error: SystemExit(2)
        main(["approximate", "x.step", "--tol", "1", "--out", "o", "--method", "fast"])
    assert ei.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--method" in err[0] and all(m in err[0] for m in APPROX_METHODS), err


@pytest.mark.slow
def test_method_loft_is_recorded_and_progress_goes_to_stderr(tmp_path: Path, capsys: pytest.CaptureFixture,
                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    step = _facade_step(tmp_path)
    monkeypatch.setenv("GHT_CAD_PROGRESS", "1")  # as on a terminal
    out = tmp_path / "out"
    assert main(["approximate", str(step), "--tol", "2", "--max-panels", "12", "--method", "loft",
                 "--out", str(out)]) == 0
    cap = capsys.readouterr()
    rep = json.loads((out / "report.json").read_text())
    assert rep["method"] == "loft" and rep["max_deviation"] <= 2.0
    assert [p["method"] for p in rep["panel_report"]] == ["loft"] * rep["panels"]
    assert f"- method: loft (per strip: {rep['panels']} loft)" in (out / "report.md").read_text()
    # progress: the core's lines, each "approximate: <line> (<s> s)", on stderr only
    lines = cap.err.strip().splitlines()
    assert lines and all(re.fullmatch(r"approximate: .+ \(\d+\.\d s\)", ln) for ln in lines), lines
    assert any("direction: rulings along" in ln for ln in lines)
    assert any(f"{rep['panels']} panels, max deviation" in ln for ln in lines)
    assert "approximate:" not in cap.out and f"{rep['panels']} developable panels" in cap.out
    # --json: stdout is one object with the method; --no-progress: nothing on stderr
    assert main(["approximate", str(step), "--tol", "2", "--max-panels", "12", "--method", "loft", "--no-progress",
                 "--out", str(tmp_path / "o2"), "--json"]) == 0
    cap = capsys.readouterr()
    res = json.loads(cap.out)
    assert res["ok"] and res["method"] == "loft" and res["panels"] == rep["panels"]
    assert cap.err == ""


@pytest.mark.slow
def test_unmet_tolerance_exits_2_naming_the_best_deviation(tmp_path: Path, capsys: pytest.CaptureFixture,
                                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """One panel cannot cover the facade within 2 mm (the march needs 3 strips): exit 2, one line
    naming the file and the core's best deviation reached with one panel (the core builds and
    measures the one-strip covering once), which is the deviation of the one panel
    ``ght_cad.approximate`` gives at a tolerance it meets; nothing written, no progress with
    --no-progress. Before the core named it, the front end searched tol (9 more runs)."""
    from ght_cad.approximation import approximate
    from ght_cad.cad.approximate import step_target

    step = _facade_step(tmp_path)
    monkeypatch.setenv("GHT_CAD_PROGRESS", "1")
    out = tmp_path / "out"
    assert main(["approximate", str(step), "--tol", "2", "--max-panels", "1", "--method", "loft", "--no-progress",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    m = re.search(r"no approximation of the target within tol=2 with at most max_panels=1 panels; "
                  r"best deviation reached ([\d.e+-]+) with (\d+) panels$", err[0])
    assert m and str(step) in err[0], err
    d, n = float(m.group(1)), int(m.group(2))
    assert n == 1 and d > 2.0
    res = approximate(step_target(step, 0), 1e3, max_panels=1, method="loft")
    assert len(res.panels) == 1 and abs(res.max_deviation - d) <= 1e-5 * d
    assert not out.exists()
