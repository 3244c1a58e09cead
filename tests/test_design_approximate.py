"""Design-file surfaces of ``type = "approximate"`` (issue 24): schema refusals, the run through the
code of ``ght-cad approximate``, STEP and inline targets, ``[sheet]`` plates.

Deviations are measured independently of the algorithm (OCCT ``BRepExtrema_DistShapeShape``
between sampled points and the faces, :func:`test_approximate.two_way`).
"""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import numpy as np
import pytest

from ght_cad.app.design import DesignError, load_design, parse_design
from ght_cad.app.cli import main

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "design_approximate_facade.toml"
BASE = tomllib.loads(EXAMPLE.read_text())
POLES = np.array(BASE["surfaces"][0]["target"]["poles"], dtype=float)


def _toml(d: dict) -> str:
    from test_fuzz_designs import to_toml

    return to_toml(d)


def _edit(table: str, **values: object) -> dict:
    """A copy of the example with keys of its surface (``table="surface"``) or of the surface's
    target (``"target"``) set, or removed where the value is None."""
    d = copy.deepcopy(BASE)
    t = d["surfaces"][0] if table == "surface" else d["surfaces"][0]["target"]
    for k, v in values.items():
        if v is None:
            t.pop(k, None)
        else:
            t[k] = v
    return d


def _variant(**surface: object) -> dict:
    return _edit("surface", **surface)


def _target(**target: object) -> dict:
    return _edit("target", **target)


GHT_NET = POLES.tolist()

BAD = [
    (_variant(tol=None), "surfaces[0].tol", "missing"),
    (_variant(tol=0), "surfaces[0].tol", "out of range"),
    (_variant(tol=-1.0), "surfaces[0].tol", "out of range"),
    (_variant(tol="x"), "surfaces[0].tol", "expected a number"),
    (_variant(tol=math.inf), "surfaces[0].tol", "not finite"),
    (_variant(max_panels=0), "surfaces[0].max_panels", r"\[1, 256\]"),
    (_variant(max_panels=100001), "surfaces[0].max_panels", r"\[1, 256\]"),
    (_variant(max_panels=1.5), "surfaces[0].max_panels", "integer"),
    (_variant(direction="w"), "surfaces[0].direction", "auto, u, v"),
    (_variant(method="fast"), "surfaces[0].method", "auto, loft, dual"),
    (_variant(method=1), "surfaces[0].method", "expected a string"),
    (_variant(foo=1), "surfaces[0].foo", "allowed keys in surfaces"),
    (_variant(target=None), "surfaces[0].target", "missing"),
    (_variant(target=3), "surfaces[0].target", "expected a table"),
    (_target(step="a.step"), "surfaces[0].target", "gives step and poles"),
    (_target(poles=None), "surfaces[0].target", "none of step, control_points, poles"),
    (_target(weight=[1]), "surfaces[0].target.weight", "allowed keys"),
    (_target(poles=[[[0, 0, 0], [1, 0, 0]], [[0, 1, 0]]]), r"surfaces[0].target.poles[1]", "has 1 rows"),
    (_target(poles=[[[0, 0, 0], [1, 0, 0], [2, 0]]] * 3), r"surfaces[0].target.poles[0][2]", "3 numbers"),
    (_target(poles=[POLES[0].tolist(), POLES[1, :2].tolist(), POLES[2].tolist()]), r"surfaces[0].target.poles[1]",
     "has 2 points"),
    (_target(knots_u=[0, 0, 1, 1]), "surfaces[0].target.knots_u", "6 non-decreasing"),
    (_target(knots_v=[0, 0, 0, 1, 0, 1]), "surfaces[0].target.knots_v", "non-decreasing"),
    (_target(degree_u=0), "surfaces[0].target.degree_u", r"\[1, 25\]"),
    (_target(weights=[[1, 1, 1], [1, -1, 1], [1, 1, 1]]), r"surfaces[0].target.weights[1][1]", "weight > 0"),
    (_target(weights=[[1, 1], [1, 1], [1, 1]]), r"surfaces[0].target.weights[0]", "3 numbers"),
    (_variant(target={"step": "x.iges"}), "surfaces[0].target.step", "STEP file"),
    (_variant(target={"step": "x.step", "face": 0}), "surfaces[0].target.face", r"\[1, 1000000\]"),
    ({**copy.deepcopy(BASE), "optimize": {"method": "pso"}}, "optimize", "fitted and optimized"),
    ({**copy.deepcopy(BASE), "surfaces": [BASE["surfaces"][0], {**BASE["surfaces"][0], "name": "b"}]},
     "surfaces[0].type", "only surface"),
]


@pytest.mark.parametrize("data, key, what", BAD, ids=[f"{k}:{w}" for _, k, w in BAD])
def test_bad_keys_and_values_name_file_and_key(data: dict, key: str, what: str) -> None:
    with pytest.raises(DesignError) as exc:
        parse_design(data, "facade.toml")
    msg = str(exc.value)
    assert msg.startswith(f"facade.toml: key '{key}'"), msg
    import re

    assert re.search(what, msg), msg
    assert "\n" not in msg


def test_two_surfaces_and_ght_target_and_deviation_figure() -> None:
    # an approximate surface next to another surface: refused, naming its type key
    two = copy.deepcopy(BASE)
    other = {"name": "plane", "type": "planes", "planes": [[0, 0, 0, 1], [-1, 0, 1, 1], [-2, 1, 0, 1]],
             "boundary_planes": [[0, 1, 0, 0], [-1, 1, 0, 0]], "normalize": False}
    two["surfaces"].append(other)
    with pytest.raises(DesignError, match=r"key 'surfaces\[0\].type'.*only surface"):
        parse_design(two, "d.toml")
    # a GHT patch target: its keys, shape parameters in [-1, 1]
    d = _target(poles=None, knots_u=None, knots_v=None, degree_u=None, degree_v=None, control_points=GHT_NET,
                gamma_u=0.5)
    spec = parse_design(d, "d.toml").surface
    assert spec.target.kind == "ght" and spec.target.shape["gamma_u"] == 0.5
    # every strip direction of the core is a value of the key (the diagonals: issue 24's saddle)
    for direction in ("auto", "u", "v", "diagonal", "antidiagonal"):
        assert parse_design(_variant(direction=direction), "d.toml").surface.direction == direction
    with pytest.raises(DesignError, match=r"key 'surfaces\[0\].target.mu_v'.*\[-1, 1\]"):
        parse_design(_target(poles=None, knots_u=None, knots_v=None, degree_u=None, degree_v=None,
                             control_points=GHT_NET, mu_v=2.0), "d.toml")
    with pytest.raises(DesignError, match=r"key 'surfaces\[0\].target.degree_u'.*allowed keys"):
        parse_design(_target(poles=None, control_points=GHT_NET), "d.toml")
    # the deviation figure belongs to approximate surfaces
    dd = {"curves": [{"name": "c", "control_points": [[0, 0], [1, 1], [2, 0]]}], "outputs": {"figures": ["deviation"]}}
    with pytest.raises(DesignError, match=r"key 'outputs.figures'.*'deviation' needs"):
        parse_design(dd, "d.toml")
    assert "deviation" not in parse_design({"curves": dd["curves"]}, "d.toml").outputs.figures
    assert "deviation" in parse_design(BASE, "d.toml").outputs.figures
    # to_dict: the approximate keys on the approximate surface only
    sd = parse_design(BASE, "d.toml").to_dict()
    assert sd["surface"]["tol"] == 2.0 and sd["surface"]["target"]["kind"] == "nurbs"


def test_inline_targets_evaluate_the_patch_and_degenerate_nets_are_refused() -> None:
    from ght_cad.app.design.approximate import approximation_target
    from ght_cad.surfaces.nurbs import NurbsSurface
    from ght_cad.surfaces.patch import GHTSurface

    spec = parse_design(BASE, "d.toml").surface
    tgt = approximation_target(spec, "d.toml")
    ref = NurbsSurface.from_poles([0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1], 2, 2, POLES)
    u, v = np.random.default_rng(1).random((2, 50))
    assert np.max(np.abs(tgt.jet(u, v, 0)[0] - ref.eval(u, v, 0)[0])) <= 1e-9
    # the quadratic Bezier patch is the GHT patch of the same net with mu = nu = 0, gamma = 1 (Bernstein)
    g = _target(poles=None, knots_u=None, knots_v=None, degree_u=None, degree_v=None, control_points=GHT_NET,
                gamma_u=1.0, gamma_v=1.0)
    gt = approximation_target(parse_design(g, "d.toml").surface, "d.toml")
    gs = GHTSurface(POLES, 0, 0, 1.0, 0, 0, 1.0)
    assert np.max(np.abs(gt.jet(u, v, 0)[0] - gs.evaluate(u, v))) <= 1e-9
    assert np.max(np.abs(gt.jet(u, v, 0)[0] - ref.eval(u, v, 0)[0])) <= 1e-9
    # every pole row the same: a curve, not a surface
    flat = _target(poles=[POLES[0].tolist()] * 3)
    with pytest.raises(DesignError, match=r"key 'surfaces\[0\].target'.*degenerate"):
        approximation_target(parse_design(flat, "d.toml").surface, "d.toml")


def test_run_refusals_exit_2_with_one_line(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    # a bad value, and a STEP target that does not exist (found at build time): exit 2, one line,
    # naming the file and the key; nothing written
    for data, key in ((_variant(direction="sideways"), "surfaces[0].direction"),
                      ({**copy.deepcopy(BASE), "surfaces": [{"type": "approximate", "tol": 1.0,
                                                             "target": {"step": "missing.step"}}]},
                       "surfaces[0].target.step")):
        path = tmp_path / "d.toml"
        path.write_text(_toml(data))
        assert main(["run", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and str(path) in err[0] and f"key '{key}'" in err[0], err
        assert not (tmp_path / "out").exists()


# ------------------------------------------------------------------------------------------------
# runs (the approximation takes seconds)
# ------------------------------------------------------------------------------------------------
def test_unmet_tolerance_exits_2_with_the_cores_best_deviation(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """``max_panels = 1`` at ``tol = 2`` (the march needs 3 strips): exit 2, one line naming the file,
    the surface and the core's best deviation reached with one panel (one build and measure of the
    one-strip covering, ~2 s; the front end's tol search of before took up to 9 more runs); it is
    the deviation of the one panel ``ght_cad.approximate`` gives at a tolerance it meets (1e-5
    relative: 6 digits printed). Nothing written."""
    import re

    from ght_cad.approximation import approximate
    from ght_cad.app.design.approximate import approximation_target

    data = _variant(max_panels=1, method="loft")
    path = tmp_path / "d.toml"
    path.write_text(_toml(data))
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(path) in err[0] and "surfaces[0]" in err[0], err
    m = re.search(r"no approximation of the target within tol=2 with at most max_panels=1 panels; "
                  r"best deviation reached ([0-9.e+-]+) with 1 panels", err[0])
    assert m, err
    spec = parse_design(data, str(path)).surfaces[0]
    one = approximate(approximation_target(spec, str(path)), 1e3, max_panels=1, method="loft")
    assert len(one.panels) == 1 and abs(one.max_deviation - float(m.group(1))) <= 1e-5 * one.max_deviation
    assert not (tmp_path / "out").exists()


def _target_face():
    """The example's target as an OCCT B-spline face (the quadratic Bezier patch of its poles)."""
    pytest.importorskip("OCP")
    from ght_cad.surfaces.bspline import BSplineSurfaceData
    from ght_cad.cad.occ import make_face

    k = np.array([0.0, 0, 0, 1, 1, 1])
    return make_face(BSplineSurfaceData(POLES, k, k, 2, 2))


@pytest.fixture(scope="module")
def facade_cli(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict]:
    """``ght-cad approximate facade.step --tol 2 --max-panels 12 --thickness 3 --k-factor 0.4`` once
    for the module (the STEP face of the example's target): (the STEP file, the output folder,
    report.json). The same panels as without the sheet (the core runs first, the plates after):
    :func:`test_example_run_through_the_code_of_ght_cad_approximate` compares them with
    ``ght-cad run``'s, :func:`test_cli_approximate_thickness` checks the plates."""
    pytest.importorskip("OCP")
    from ght_cad.cad.occ import write_step

    d = tmp_path_factory.mktemp("facade_cli")
    step = write_step(_target_face(), d / "facade.step")
    out = d / "out"
    assert main(["approximate", str(step), "--tol", "2", "--max-panels", "12", "--thickness", "3",
                 "--k-factor", "0.4", "--out", str(out)]) == 0
    return step, out, json.loads((out / "report.json").read_text())


@pytest.mark.slow
def test_example_run_through_the_code_of_ght_cad_approximate(tmp_path: Path, facade_cli) -> None:
    """The example (NURBS target inline) and the same target as a STEP face, once through
    ``ght-cad run`` (design with a STEP target, path relative to the design file) and once through
    ``ght-cad approximate`` (:func:`facade_cli`): the same panels; deviation within tol both ways by
    OCCT distances."""
    pytest.importorskip("OCP")
    from test_approximate import face_area, two_way

    from ght_cad.cad.occ import read_step, write_step
    from ght_cad.cad.unroll_faces import shape_faces

    out = tmp_path / "run"
    assert main(["run", str(EXAMPLE), "--out", str(out), "--no-progress"]) == 0
    rep = json.loads((out / "report.json").read_text())
    for name in ("model.step", "flat_pattern.dxf", "flat_pattern.svg", "deviation.png", "surface.png", "report.md"):
        assert (out / name).stat().st_size > 0, name
    ap = rep["surface"]["approximation"]
    tol = 2.0
    assert 2 <= ap["panels"] <= 12 and ap["max_deviation"] <= tol
    assert "Developable approximation" in (out / "report.md").read_text()
    shell = read_step(out / "model.step")
    faces = shape_faces(shell)
    assert len(faces) == ap["panels"] and rep["brep"]["shared_edges"] == ap["panels"] - 1
    target = _target_face()
    assert two_way(target, shell, n_target=(20, 14), n_panel=(10, 5)) <= tol * 1.001
    # seam marks on the flat pattern, flat areas = the STEP faces' areas
    assert rep["flat_pattern"]["edge_marks"] == [f"E{i}" for i in range(1, ap["panels"])]
    flat = sorted(p["area_flat"] for p in rep["flat_pattern"]["panels"])
    for a, b in zip(flat, sorted(face_area(f) for f in faces)):
        assert abs(a - b) <= 1e-6 * b
    # the same target as a face of a STEP file next to a design file; and ght-cad approximate on it
    write_step(target, tmp_path / "facade.step")
    d = copy.deepcopy(BASE)
    d["surfaces"][0]["target"] = {"step": "facade.step", "face": 1}
    d["outputs"] = {"files": ["json"], "figures": []}
    (tmp_path / "d.toml").write_text(_toml(d))
    assert main(["run", str(tmp_path / "d.toml"), "--out", str(tmp_path / "run2"), "--no-progress"]) == 0
    a2 = json.loads((tmp_path / "run2" / "report.json").read_text())["surface"]["approximation"]
    a3 = facade_cli[2]
    assert a2["panels"] == a3["panels"] and a2["max_deviation"] == a3["max_deviation"]
    assert [p["area"] for p in a2["panel_report"]] == [p["area"] for p in a3["panel_report"]]
    # the STEP face is the inline patch: the same strips to the march's resolution
    assert abs(a2["max_deviation"] - ap["max_deviation"]) <= 0.05 * tol
    # a face number past the file's faces: exit 2 naming target.face
    d["surfaces"][0]["target"]["face"] = 2
    (tmp_path / "d2.toml").write_text(_toml(d))
    assert main(["run", str(tmp_path / "d2.toml"), "--out", str(tmp_path / "run3"), "--no-progress"]) == 2


@pytest.mark.slow
def test_sheet_plates_every_panel(tmp_path: Path) -> None:
    """``[sheet]`` T = 3 mm, K = 0.4: one exact plate solid per panel in model.step; its volume is
    ``A T`` to within ``T max|H|`` (0.5 % here: ``V = T A + σ (T²/2) ∫ 2H dA``) and the closed form to
    1e-6; every flat panel is the neutral surface: its area is ``A_in + K (A_out - A_in)`` of the
    plate's inside and outside faces read back from STEP (exact for a developable: the area of an
    offset is linear in the distance), to 1e-6, and differs from the design panel's area."""
    pytest.importorskip("OCP")
    from test_approximate import face_area

    from ght_cad.cad.occ import volume
    from ght_cad.cad.sheet_solid import read_step_face_names
    from ght_cad.cad.unfold_solid import _solids
    from ght_cad.cad.unroll_faces import shape_faces

    T, K = 3.0, 0.4
    d = copy.deepcopy(BASE)
    d["sheet"] = {"thickness": T, "k_factor": K}
    d["outputs"] = {"files": ["step", "json", "dxf"], "figures": []}
    (tmp_path / "d.toml").write_text(_toml(d))
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "d.toml"), "--out", str(out), "--no-progress"]) == 0
    rep = json.loads((out / "report.json").read_text())
    n = rep["surface"]["approximation"]["panels"]
    areas = {f"P{p['index']}": p["area"] for p in rep["surface"]["approximation"]["panel_report"]}
    assert rep["plate"]["solids"] == n
    shape, names = read_step_face_names(out / "model.step")
    solids = _solids(shape)
    assert len(solids) == n
    total = sum(volume(s, eps=1e-12) for s in solids)
    area = sum(areas.values())
    assert abs(total - area * T) <= 5e-3 * area * T
    assert abs(total - rep["plate"]["volume_closed_form"]) <= 1e-6 * total
    faces = shape_faces(shape)
    by_name = {names[i]: faces[i] for i in names}
    flat = {p["label"]: p["area_flat"] for p in rep["flat_pattern"]["panels"]}
    assert sorted(flat) == sorted(areas)
    for label, a_flat in flat.items():
        a_in, a_out = face_area(by_name[f"{label}.inside"]), face_area(by_name[f"{label}.outside"])
        neutral = a_in + K * (a_out - a_in)
        assert abs(a_flat - neutral) <= 1e-6 * a_in, (label, a_flat, neutral)
        assert abs(a_flat - areas[label]) >= 50 * 1e-6 * a_in  # the neutral surface, not the panel
    assert rep["flat_pattern"]["sheet"][0]["thickness"] == T


@pytest.mark.slow
def test_cli_approximate_thickness(tmp_path: Path, facade_cli) -> None:
    """``ght-cad approximate --thickness T --k-factor K`` (:func:`facade_cli`): one plate solid per
    panel in panels.step, the flat patterns the neutral surfaces (the code the design's [sheet] runs)."""
    step, out, rep = facade_cli
    assert rep["plate"]["solids"] == rep["panels"] and rep["sheet"]["thickness"] == 3.0
    area = sum(p["area"] for p in rep["panel_report"])
    assert abs(rep["plate"]["volume"] - 3.0 * area) <= 5e-3 * 3.0 * area
    # flat areas differ from the panels' (the neutral surface at K T = 1.2 mm)
    assert all(abs(p["flat_area"] - p["area"]) > 1e-5 * p["area"] for p in rep["panel_report"])
    assert main(["approximate", str(step), "--tol", "2", "--k-factor", "0.4", "--out", str(tmp_path / "o2")]) == 2


@pytest.mark.slow
def test_ght_patch_target_through_surface_export_and_unroll(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """A GHT patch target (the net of a general cylinder z = z(y): developable) through the other
    design commands: one panel within 1e-6 of the size (issue 24: developable inputs give one panel);
    ``ght-cad surface --json`` reports it, ``export`` writes STEP/DXF/JSON, ``unroll`` the pattern."""
    pytest.importorskip("OCP")
    net = [[[600.0 * i, 400.0 * j, [0.0, 80.0, 0.0][j]] for j in range(3)] for i in range(3)]
    d = _target(poles=None, knots_u=None, knots_v=None, degree_u=None, degree_v=None, control_points=net)
    path = tmp_path / "cyl.toml"
    path.write_text(_toml(d))
    assert main(["surface", str(path), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    ap = res["surface"]["approximation"]
    assert ap["panels"] == 1 and ap["max_deviation"] <= 1e-6 * ap["size"]
    assert res["developability"]["theta_max"] <= 1e-3
    files = [tmp_path / "x.step", tmp_path / "x.dxf", tmp_path / "x.json"]
    assert main(["export", str(path), *map(str, files)]) == 0
    assert all(f.stat().st_size > 0 for f in files)
    rep = json.loads(files[2].read_text())
    assert abs(rep["flat_pattern"]["area"] - ap["total_area"]) <= 1e-6 * ap["total_area"]
    capsys.readouterr()
    assert main(["unroll", str(path), "--svg", str(tmp_path / "u.svg")]) == 0
    assert (tmp_path / "u.svg").stat().st_size > 0


@pytest.mark.slow
def test_sheet_side_is_measured_on_the_target_normal() -> None:
    """``side = "normal"`` puts every panel's material on the TARGET's normal side ``S_u × S_v``,
    whichever way the panel's own normal points (the strips of this cylinder run along u: the
    panel's ``X_u × X_v`` is ``-(S_u × S_v)``): the plate's outside face lies ``T`` along the target
    normal (to 1e-3 of T, the point's nearest target point found on a 401 × 401 grid and refined),
    and with ``side = "reverse"`` ``T`` against it."""
    pytest.importorskip("OCP")
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.BRepTools import BRepTools
    from scipy.optimize import minimize

    from ght_cad.app.design import build_surface, plate_solids
    from ght_cad.surfaces.patch import GHTSurface

    net = [[[600.0 * i, 400.0 * j, [0.0, 80.0, 0.0][j]] for j in range(3)] for i in range(3)]
    g = GHTSurface(np.array(net))
    T = 3.0
    for side, sign in (("normal", 1.0), ("reverse", -1.0)):
        d = _target(poles=None, knots_u=None, knots_v=None, degree_u=None, degree_v=None, control_points=net)
        d["sheet"] = {"thickness": T, "side": side}
        built = build_surface(parse_design(d, "d.toml"))
        plates = plate_solids(built)
        assert len(plates) == 1
        out = plates[0].outside
        ad = BRepAdaptor_Surface(out)
        u0, u1, v0, v1 = BRepTools.UVBounds_s(out)
        for fu, fv in ((0.5, 0.5), (0.3, 0.7), (0.8, 0.2)):
            P = np.array(ad.Value(u0 + fu * (u1 - u0), v0 + fv * (v1 - v0)).Coord())
            x = np.linspace(0, 1, 401)
            X, Y = np.meshgrid(x, x, indexing="ij")
            G = g.evaluate(X.ravel(), Y.ravel())
            k = int(np.argmin(np.linalg.norm(G - P, axis=1)))
            r = minimize(lambda w: float(np.sum((g.evaluate([w[0]], [w[1]])[0] - P) ** 2)), [X.ravel()[k], Y.ravel()[k]],
                         method="Nelder-Mead", options={"xatol": 1e-12, "fatol": 1e-14})
            uu, vv = r.x
            n = np.cross(g.derivative([uu], [vv], 1, 0)[0], g.derivative([uu], [vv], 0, 1)[0])
            n /= np.linalg.norm(n)
            assert abs(float((P - g.evaluate([uu], [vv])[0]) @ n) - sign * T) <= 1e-3 * T, (side, fu, fv)


def test_method_key_parsed_validated_and_passed_through(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """``method`` of an approximate surface: the choices of ``APPROX_METHODS`` (default auto; also
    the message of a bad value lists them), kept by ``to_dict``, passed to ``ght_cad.approximate``
    and recorded in the report: a developable GHT cylinder target with ``method = "loft"`` gives
    one loft panel within 1e-6 of the size, ``surface.approximation.method`` = "loft"."""
    from ght_cad.app.design.schema.constants import APPROX_METHODS

    assert parse_design(BASE, "d.toml").surface.method == "auto"
    for m in APPROX_METHODS:
        spec = parse_design(_variant(method=m), "d.toml").surface
        assert spec.method == m and parse_design(_variant(method=m), "d.toml").to_dict()["surface"]["method"] == m
    with pytest.raises(DesignError) as exc:
        parse_design(_variant(method="fast"), "d.toml")
    assert str(exc.value).startswith("d.toml: key 'surfaces[0].method'") and ", ".join(APPROX_METHODS) in str(exc.value)
    # the key does not leak into other surface types' plain-data form
    planes = {"surface": {"type": "planes", "planes": [[0, 0, 0, 1], [-1, 0, 1, 1], [-2, 1, 0, 1]],
                          "boundary_planes": [[0, 1, 0, 0], [-1, 1, 0, 0]], "normalize": False}}
    assert "method" not in parse_design(planes, "p.toml").to_dict()["surface"]
    # through the build: the method reaches the core and the report
    net = [[[600.0 * i, 400.0 * j, [0.0, 80.0, 0.0][j]] for j in range(3)] for i in range(3)]
    d = _target(poles=None, knots_u=None, knots_v=None, degree_u=None, degree_v=None, control_points=net)
    d["surfaces"][0]["method"] = "loft"
    path = tmp_path / "cyl.toml"
    path.write_text(_toml(d))
    assert main(["surface", str(path), "--json"]) == 0
    ap = json.loads(capsys.readouterr().out)["surface"]["approximation"]
    assert ap["method"] == "loft" and [p["method"] for p in ap["panel_report"]] == ["loft"] * ap["panels"]
    assert ap["panels"] == 1 and ap["max_deviation"] <= 1e-6 * ap["size"]
    from ght_cad.app.design.approximate import report_markdown

    assert "- method: loft (per strip: 1 loft)" in report_markdown(ap)
