"""Design files: validation (one-line errors naming file, key and allowed values; exit code 2)
and the staged runner (a failure leaves the output folder untouched)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from ght_cad.app.cli import main
from ght_cad.app.design import DesignError, load_design, parse_design, parse_design_text, run_design

# a small valid design: the exact quarter cone of the spec, no optimization (fast)
GOOD = """
name = "cone"
units = "mm"

[[curves]]
name = "c1"
control_points = [[0, 0, 0], [1, 2, 0], [3, 2, 1], [4, 0, 1]]

[[curves]]
name = "c2"
control_points = [[4, 0, 1], [5, -1, 1], [6, 0, 2]]

[[joins]]
first = "c1"
second = "c2"
continuity = "G1"

[surface]
type = "planes"
planes = [[-4, 1, 0, 0.5], [-4, 1, 1, 0.5], [-4, 0, 1, 0.5]]
boundary_planes = [[0, 0, 0, 1], [-4, 0, 0, 1]]
gamma = -1.0
normalize = false

[outputs]
files = ["step", "dxf", "json"]
figures = ["surface"]
"""


def snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    return {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in sorted(folder.iterdir())}


@pytest.fixture
def out_dir(tmp_path: Path) -> Path:
    out = tmp_path / "out"
    out.mkdir()
    (out / "model.step").write_text("previous result\n")
    (out / "notes.txt").write_text("keep me\n")
    return out


def run_cli(design_text: str, tmp_path: Path, out: Path, capsys: pytest.CaptureFixture) -> tuple[int, str, Path]:
    path = tmp_path / "broken.toml"
    path.write_text(design_text)
    rc = main(["run", str(path), "--out", str(out)])
    err = capsys.readouterr().err
    return rc, err, path


def run_refused(design_text: str, tmp_path: Path, out: Path, capsys: pytest.CaptureFixture) -> tuple[str, Path]:
    """``ght-cad run`` of a design that must be refused: exit 2, one line on stderr, ``out`` untouched
    (same names, bytes and mtimes) and no temporary folder left; returns that line and the design path."""
    before = snapshot(out)
    rc, err, path = run_cli(design_text, tmp_path, out, capsys)
    assert rc == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert snapshot(out) == before
    assert not list(tmp_path.glob(".*ght-cad-tmp"))
    return lines[0], path


def edit(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new)


BROKEN = {
    # (design text, key named in the message, allowed values named in the message)
    "missing key": (edit("planes = [[-4, 1, 0, 0.5], [-4, 1, 1, 0.5], [-4, 0, 1, 0.5]]\n", ""),
                    "surface.planes", "at least 3 arrays of 4 numbers"),
    "wrong type": (edit("gamma = -1.0", 'gamma = "round"'), "surface.gamma", "[-1, 1]"),
    "out of range": (edit("gamma = -1.0", "gamma = 1.5"), "surface.gamma", "[-1, 1]"),
    "unknown output": (edit('files = ["step", "dxf", "json"]', 'files = ["step", "stl"]'),
                       "outputs.files", "step, dxf, svg, json, md"),
    "unknown figure": (edit('figures = ["surface"]', 'figures = ["rendering"]'), "outputs.figures", "basis, curve"),
    "unknown key": (edit("normalize = false", "normalise = false"), "surface.normalise", "normalize"),
    "bad continuity": (edit('continuity = "G1"', 'continuity = "G4"'), "joins[0].continuity", "C0, C1, C2, C3, G0"),
    "unknown curve": (edit('second = "c2"', 'second = "c3"'), "joins[0].second", "c1, c2"),
    "short points": (edit("[[4, 0, 1], [5, -1, 1], [6, 0, 2]]", "[[4, 0, 1], [5, -1, 1]]"),
                     "curves[1].control_points", "at least 3"),
    "bad units": (edit('units = "mm"', 'units = "furlong"'), "units", "mm, cm, m, in, ft"),
}


def test_invalid_toml_is_one_line(tmp_path: Path, out_dir: Path, capsys) -> None:
    line, path = run_refused('name = "x\n[surface', tmp_path, out_dir, capsys)
    assert str(path) in line and "TOML" in line, line


def test_missing_design_file(tmp_path: Path, capsys) -> None:
    rc = main(["run", str(tmp_path / "nope.toml"), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "nope.toml" in err and not (tmp_path / "o").exists()


def test_new_out_folder_not_created_on_error(tmp_path: Path, capsys) -> None:
    out = tmp_path / "fresh"
    rc, _, _ = run_cli(edit("gamma = -1.0", "gamma = 2"), tmp_path, out, capsys)
    assert rc == 2 and not out.exists()


def test_degenerate_geometry_exit_2_untouched(tmp_path: Path, out_dir: Path, capsys) -> None:
    """Valid schema, impossible geometry (two equal neighbouring planes): found while computing."""
    text = edit("[[-4, 1, 0, 0.5], [-4, 1, 1, 0.5], [-4, 0, 1, 0.5]]", "[[-4, 1, 0, 0.5], [-4, 1, 0, 0.5], [-4, 0, 1, 0.5]]")
    line, path = run_refused(text, tmp_path, out_dir, capsys)
    assert str(path) in line and "'surface'" in line, line


def test_failure_after_files_were_written_leaves_out_untouched(tmp_path: Path, out_dir: Path, monkeypatch) -> None:
    """A crash in the last figure (after STEP and DXF were written) moves nothing into out."""
    import ght_cad.curves.plotting as P

    def boom(*a, **k):
        raise RuntimeError("renderer crashed")

    monkeypatch.setattr(P, "plot_surface", boom)
    before = snapshot(out_dir)
    design = parse_design_text(GOOD, "good.toml")
    with pytest.raises(RuntimeError, match="renderer crashed"):
        run_design(design, out_dir, progress=False)
    assert snapshot(out_dir) == before
    assert not list(tmp_path.glob(".*ght-cad-tmp"))


def test_good_design_runs_and_replaces_only_its_files(tmp_path: Path, out_dir: Path) -> None:
    design = parse_design_text(GOOD, "good.toml")
    report = run_design(design, out_dir, progress=False)
    names = {p.name for p in out_dir.iterdir()}
    assert names == {"model.step", "flat_pattern.dxf", "report.json", "surface.png", "notes.txt"}
    assert (out_dir / "notes.txt").read_text() == "keep me\n"
    assert (out_dir / "model.step").read_text().startswith("ISO-10303-21")
    assert json.loads((out_dir / "report.json").read_text())["name"] == "cone"
    # the joined curves achieve what was asked
    assert report["joins"][0]["achieved_G"] >= 1 and report["joins"][0]["satisfied"]
    # exact quarter cone frustum: h = 8, k = 0.5, cut at z = 0 and z = 4
    rho2 = math.hypot(4.0, 8.0)
    rho1 = rho2 / 2
    angle = (math.pi / 2) * 4.0 / rho2
    assert report["flat_pattern"]["area"] == pytest.approx(0.5 * angle * (rho2**2 - rho1**2), rel=1e-12)


def test_defaults_and_normalisation(tmp_path: Path) -> None:
    d = parse_design({"curves": [{"control_points": [[0, 0], [1, 1], [2, 0]]}]}, "x.toml")
    assert d.name == "x" and d.curves[0].name == "curve1" and d.surface is None
    # without a surface, surface outputs are dropped from the defaults, and without [optimize] the convergence plot
    assert "dxf" not in d.outputs.files and "flat_pattern" not in d.outputs.figures
    assert "convergence" not in d.outputs.figures and "curve" in d.outputs.figures


@pytest.mark.parametrize(
    "data,key",
    [
        ({}, "surface"),
        ({"surface": {"type": "cone"}}, "surface.type"),
        ({"surface": {"type": "curves", "curve_a": "a", "curve_b": "b"}}, "surface.curve_a"),
        ({"curves": [{"control_points": [[0, 0], [1, 1], [2, 0]], "mu": True}]}, "curves[0].mu"),
        ({"curves": [{"control_points": [[0, 0], [1, 1], [2, float("nan")]]}]}, "curves[0].control_points[2][1]"),
        ({"curves": [{"control_points": [[0, 0], [1, 1], [2, 0]]}], "optimize": {}}, "optimize"),
        ({"curves": [{"control_points": [[0, 0], [1, 1], [2, 0]]}], "outputs": {"figures": ["convergence"]}}, "outputs.figures"),
        ({"curves": [{"control_points": [[0, 0], [1, 1], [2, 0]]}], "extra": 1}, "extra"),
    ],
)
def test_parse_errors_name_the_key(data: dict, key: str) -> None:
    with pytest.raises(DesignError) as ei:
        parse_design(data, "f.toml")
    msg = str(ei.value)
    assert msg.startswith("f.toml: ") and f"'{key}'" in msg and "\n" not in msg


def test_optimize_block_validation() -> None:
    base = {"surface": {"planes": [[-4, 1, 0, 0.5], [-4, 1, 1, 0.5], [-4, 0, 1, 0.5]],
                        "boundary_planes": [[0, 0, 0, 1], [-4, 0, 0, 1]]}}
    d = parse_design({**base, "optimize": {"method": "PSO", "objective": "en"}}, "f.toml")
    assert (d.optimize.method, d.optimize.objective) == ("pso", "En")
    for bad, key, allowed in [
        ({"objective": "R"}, "optimize.objective", "AL, En, CVEn, weighted"),
        ({"population": 2}, "optimize.population", "[4, 500]"),
        ({"parameters": ["mu", "a.mu"]}, "optimize.parameters", "mu, nu, gamma"),
        ({"weights": [0, 0, 0]}, "optimize.weights", "not all 0"),
    ]:
        with pytest.raises(DesignError, match=rf"'{key}'.*{allowed.replace('[', '.').replace(']', '.')}"):
            parse_design({**base, "optimize": bad}, "f.toml")


@pytest.mark.parametrize("name", ["design_duct.toml", "design_hull_plate.toml", "design_hull_plate_quasi.toml",
                                  "design_duct_two_strips.toml", "design_dory_multichine.toml",
                                  "design_hopper_transition.toml"])
def test_example_designs_validate(name: str) -> None:
    d = load_design(Path(__file__).parent.parent / "examples" / name)
    assert d.surfaces and (d.surface is not None) == (len(d.surfaces) == 1)


def test_embedded_default_design_validates() -> None:
    from ght_cad.app.demo import default_design_text

    d = parse_design_text(default_design_text(), "<embedded>")
    assert d.surface.type == "planes" and d.optimize is not None and len(d.joins) == 1
    assert set(d.outputs.files) == {"step", "dxf", "svg", "json", "md"}
    assert set(d.outputs.figures) == {"basis", "curve", "curvature", "surface", "flat_pattern", "convergence"}


from hypothesis import given, settings
from hypothesis import strategies as st


@given(
    key=st.sampled_from(["mu", "nu", "gamma"]),
    value=st.one_of(
        st.floats(min_value=-1.0, max_value=1.0),
        st.floats(min_value=1.0, exclude_min=True, max_value=1e6),
        st.floats(max_value=-1.0, exclude_max=True, min_value=-1e6),
    ),
)
def test_shape_parameter_range_is_exactly_the_box(key: str, value: float) -> None:
    """Every value in [-1, 1] is accepted as given; every value outside is an error naming the key."""
    data = {"curves": [{"name": "c", "control_points": [[0, 0], [1, 1], [2, 0]], key: value}]}
    if -1.0 <= value <= 1.0:
        assert getattr(parse_design(data, "p.toml").curves[0], key) == value
    else:
        with pytest.raises(DesignError, match=rf"p\.toml: key 'curves\[0\]\.{key}': .* out of range; allowed: in \[-1, 1\]"):
            parse_design(data, "p.toml")


def test_impossible_join_names_the_join(tmp_path: Path, out_dir: Path, capsys) -> None:
    """C3 cannot be imposed on a degree-2 second segment (its c_3 is zero): exit 2, joins[0] named."""
    text = edit('continuity = "G1"', 'continuity = "C3"')
    line, path = run_refused(text, tmp_path, out_dir, capsys)
    assert str(path) in line and "'joins[0]'" in line, line


# ---------------------------------------------------------------------------------------------
# composite surfaces: several strips joined G1/G2/G3 (spec 5.6)
# ---------------------------------------------------------------------------------------------
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
TWO_STRIPS = (EXAMPLES / "design_duct_two_strips.toml").read_text()


def strips_edit(old: str, new: str) -> str:
    assert old in TWO_STRIPS, old
    return TWO_STRIPS.replace(old, new, 1)


def test_two_strip_design_end_to_end(tmp_path: Path) -> None:
    """Shell STEP valid with one shared edge, one panel per strip whose area equals the strip's
    area (independent Gauss–Legendre quadrature in 3-D) to 1e-9, joint G2 as requested."""
    import ezdxf

    from ght_cad.cad.occ import is_valid, read_step
    from ght_cad.app.design import build_surface, ruled_area, shared_edge_count

    out = tmp_path / "out"
    assert main(["run", str(EXAMPLES / "design_duct_two_strips.toml"), "--out", str(out), "--no-progress"]) == 0
    r = json.loads((out / "report.json").read_text())
    assert r["surface"]["type"] == "composite" and len(r["surface"]["strips"]) == 2
    (j,) = r["surface"]["joints"]
    assert j["requested"] == "G2" and j["achieved_G"] == 2 and j["satisfied"]
    for s in r["surface"]["strips"]:
        assert s["developability"]["theta_max"] < 1e-10
    # B-rep: one valid shell of two faces sharing the joint ruling, also after re-import
    assert r["brep"] == {**r["brep"], "valid": True, "faces": 2, "shape": "shell", "shared_edges": 1}
    shape = read_step(out / "model.step")
    assert is_valid(shape) and shared_edge_count(shape) == 1
    # pattern (issue 23): the strips meet G2, so ONE blank labelled with the design's name whose
    # flat area is the sum of the strips' 3-D areas (independent quadrature) to 1e-12; the joint
    # ruling is a bend line, no cut edge is left to mark
    from ght_cad.unrolling.unroll import ruled_area as ruled_area_adaptive

    comp = build_surface(load_design(EXAMPLES / "design_duct_two_strips.toml")).surface
    panels = r["flat_pattern"]["panels"]
    assert [p["label"] for p in panels] == ["duct-two-strips"]
    strips = sum(ruled_area_adaptive(seg) for seg in comp.segments)
    assert math.isclose(panels[0]["area_flat"], strips, rel_tol=1e-12), (panels[0], strips)
    assert math.isclose(panels[0]["area_flat"], sum(ruled_area(seg) for seg in comp.segments), rel_tol=1e-9)
    assert r["flat_pattern"]["errors"]["max"] < 1e-12
    assert r["flat_pattern"]["edge_marks"] == []
    doc = ezdxf.readfile(out / "flat_pattern.dxf")
    msp = doc.modelspace()
    outlines = [e for e in msp if e.dxftype() == "LWPOLYLINE" and e.dxf.layer == "OUTLINE"]
    assert len(outlines) == 1 and outlines[0].closed
    assert len([e for e in msp if e.dxftype() == "LINE" and e.dxf.layer == "BEND"]) == 2 * 10 + 1  # + the joint
    texts = [e.dxf.text for e in msp if e.dxftype() == "TEXT"]
    assert texts == ["duct-two-strips"]
    md = (out / "report.md").read_text()
    assert "| quarter → second-quarter | G2 | G2 | yes |" in md


def test_two_strip_design_per_surface_panels_and_joined_blank_agree(tmp_path: Path) -> None:
    """`[unroll] panels = "per-surface"` keeps one panel per strip (labelled by strip, areas = the
    strips' 3-D areas to 1e-9, the joint ruling marked E1 on both); the default blank's area is the
    sum of those panels' flat areas to 1e-12 and its outline is one simple loop whose boundary edges
    are the panels' outer edges less the joint (same lengths to 1e-12)."""
    from ght_cad.app.design import build_surface, ruled_area, unroll_surface
    from ght_cad.sheetmetal.join_panels import outline_self_overlap

    per = parse_design_text(TWO_STRIPS.replace("[unroll]\n", '[unroll]\npanels = "per-surface"\n'), "two.toml")
    assert per.unroll.panels == "per-surface" and parse_design_text(TWO_STRIPS, "two.toml").unroll.panels == "joined"
    built = build_surface(per)
    apart = unroll_surface(built)
    assert [p.label for p in apart.panels] == ["quarter", "second-quarter"]
    for p, seg in zip(apart.panels, built.surface.segments):
        assert math.isclose(p.area_flat, ruled_area(seg), rel_tol=1e-9)
    assert [t[2] for t in apart.labels].count("E1") == 2
    blank = unroll_surface(build_surface(parse_design_text(TWO_STRIPS, "two.toml")))
    (pn,) = blank.panels
    assert math.isclose(pn.area_flat, sum(p.area_flat for p in apart.panels), rel_tol=1e-12)
    assert outline_self_overlap(pn.loop_polylines()[0]) == 0
    lengths = {f"{p.label}:{e.name}": e.length_flat for p in apart.panels for e in p.loops[0]}
    joined = {e.name: e.length_flat for e in pn.loops[0]}
    assert set(joined) == set(lengths) - {"quarter:ruling u=1", "second-quarter:ruling u=0"}
    for k, v in joined.items():
        assert math.isclose(v, lengths[k], rel_tol=1e-12), k
    (j,) = pn.info["joints"]
    assert j["kind"] == "bend line" and j["tangency_deg"] < 1e-9 and j["fit"] < 1e-12


def test_unroll_panels_bad_value_exit_2(tmp_path: Path, capsys) -> None:
    f = tmp_path / "bad.toml"
    f.write_text(TWO_STRIPS.replace("[unroll]\n", '[unroll]\npanels = "one"\n'))
    assert main(["run", str(f), "--out", str(tmp_path / "o"), "--no-progress"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "unroll.panels" in err[0] and "joined, per-surface" in err[0] and "bad.toml" in err[0]
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("order, normalize", [("G1", "false"), ("G3", "false"), ("G2", "true")])
def test_requested_joint_order_is_achieved(order: str, normalize: str) -> None:
    """The measured joint order equals the requested one (generic free planes: not higher)."""
    from ght_cad.app.design import build_surface, surface_summary

    text = strips_edit('continuity = "G2"', f'continuity = "{order}"').replace("normalize = false", f"normalize = {normalize}")
    d = parse_design_text(text, "two.toml")
    assert d.surface.normalize is (normalize == "true")
    summ = surface_summary(build_surface(d))
    (j,) = summ["surface"]["joints"]
    assert j["requested"] == order and j["achieved_G"] == int(order[1]), j
    assert j["plane_angle_deg"] < 1e-10 and j["ruling_distance"] < 1e-10


STRIP_PLANES_B = TWO_STRIPS[TWO_STRIPS.index("[[surface.segments]]", TWO_STRIPS.index("quarter")):
                            TWO_STRIPS.index("[unroll]")]
BROKEN_STRIPS = {
    "no segments": (TWO_STRIPS[:TWO_STRIPS.index("[[surface.segments]]")] + TWO_STRIPS[TWO_STRIPS.index("[unroll]"):],
                    "surface.segments", "at least 2 tables"),
    "one segment": (TWO_STRIPS.replace(STRIP_PLANES_B, ""), "surface.segments", "at least 2"),
    "G0 join": (strips_edit('continuity = "G2"', 'continuity = "G0"'), "surface.segments[1].continuity", "G1, G2, G3"),
    "join on first": (strips_edit('name = "quarter"', 'name = "quarter"\ncontinuity = "G1"'),
                      "surface.segments[0].continuity", "segments[1] and later"),
    "k zero": (strips_edit("k = 1.0", "k = 0"), "surface.segments[1].k", "> 0"),
    "shape out of range": (strips_edit("mu = 0.0", "mu = -1.5"), "surface.segments[1].mu", "[-1, 1]"),
    "unknown key": (strips_edit("k = 1.0", "kk = 1.0"), "surface.segments[1].kk", "continuity, k, beta2"),
    "duplicate name": (strips_edit('name = "second-quarter"', 'name = "quarter"'), "surface.segments[1].name", "unique"),
    "curves key": (strips_edit('type = "composite"', 'type = "composite"\ncurve_a = "c1"'), "surface.curve_a",
                   "type, boundary_planes, normalize, segments"),
    "optimize": (TWO_STRIPS.replace("[unroll]", "[optimize]\nparameters = [\"third.mu\"]\n\n[unroll]"),
                 "optimize.parameters", "unknown segment 'third'"),
    "bad type": (strips_edit('type = "composite"', 'type = "strips"'), "surface.type", "planes, curves, rails, composite"),
    "type missing": (strips_edit('type = "composite"\n', ''), "surface.segments", 'only with type = "composite"'),
    "normalize type": (strips_edit("normalize = false", 'normalize = "no"'), "surface.normalize", "true or false"),
    "G3 with 3 planes": (strips_edit('continuity = "G2"', 'continuity = "G3"').replace(
        "  [-0.941433, -0.721179, 0.605141, 0.3372],\n  [-0.927967, -0.872004, 0.317383, 0.372662],\n"
        "  [-0.923077, -0.923077, 0.0, 0.384615],\n", ""), "surface.segments[1].planes", "at least 4 arrays"),
}


#: Every broken design: (design text, the key its error names, the allowed values it states);
#: the multi-strip ones prefixed "strips: ".
ALL_BROKEN = {**BROKEN, **{f"strips: {case}": v for case, v in BROKEN_STRIPS.items()}}


@pytest.mark.parametrize("case", list(ALL_BROKEN))
def test_broken_design_one_line_exit_2_untouched(case: str, tmp_path: Path, out_dir: Path, capsys) -> None:
    text, key, allowed = ALL_BROKEN[case]
    line, path = run_refused(text, tmp_path, out_dir, capsys)
    assert str(path) in line and f"'{key}'" in line and allowed in line, line


def test_unsolvable_strip_join_names_the_segment(tmp_path: Path, out_dir: Path, capsys) -> None:
    """Geometry that fails while computing (second strip's free planes parallel to each other)."""
    text = strips_edit("  [-0.927967, -0.872004, 0.317383, 0.372662],\n", "  [-0.941433, -0.721179, 0.605141, 0.3372],\n")
    line, path = run_refused(text, tmp_path, out_dir, capsys)
    assert f"{path}: key 'surface.segments[1]' (second-quarter)" in line, line


def test_step_declares_the_design_units(tmp_path) -> None:
    """A design in metres writes a STEP file that declares metres (coordinates kept as designed)."""
    import re
    from pathlib import Path

    from ght_cad.app.design import load_design, run_design

    src = Path(__file__).resolve().parents[1] / "examples" / "design_duct_two_strips.toml"
    design = load_design(src)
    assert design.units == "m"
    run_design(design, tmp_path / "out", progress=False)
    text = (tmp_path / "out" / "model.step").read_text(errors="replace")
    assert re.search(r"LENGTH_UNIT\(\) NAMED_UNIT\(\*\) SI_UNIT\(\$,\.METRE\.\)", text)


def test_hull_plate_header_describes_its_join() -> None:
    """The example's comment header names the join the file really has (sheer -> stem, G1)."""
    path = Path(__file__).resolve().parent.parent / "examples" / "design_hull_plate_quasi.toml"
    header = " ".join(ln.lstrip("# ").strip() for ln in path.read_text().splitlines() if ln.startswith("#"))
    d = load_design(path)
    assert [(j.first, j.second, j.continuity, j.k) for j in d.joins] == [("sheer", "stem", "G1", 0.8)]
    assert "sheer line continues into the stem" in header and "joined to the sheer's end with G1" in header
    assert "k = 0.8" in header and "chine is built from two segments" not in header
    # the stem really starts where the sheer ends (the join is at the sheer's end)
    sheer, stem = (next(c for c in d.curves if c.name == n) for n in ("sheer", "stem"))
    assert list(stem.control_points[0]) == list(sheer.control_points[-1])


@pytest.mark.slow
def test_planes_optimization_rejects_degenerate_candidates(tmp_path: Path, capsys) -> None:
    """AL of the quarter cone's dual curve is smallest at mu = nu = gamma = -1, where the dual curve
    is stationary at both ends and the surface cannot be built. PSO clips onto that corner; the
    candidate must get +inf (docs: candidates whose surface degenerates are rejected) so that
    `ght-cad optimize` and `ght-cad run` end with a surface that exists."""
    from ght_cad.app.design import build_surface, optimize_design

    text = Path(__file__).resolve().parents[1].joinpath("examples", "design_duct.toml").read_text()
    text += '\n[optimize]\nmethod = "pso"\nobjective = "AL"\npopulation = 8\niterations = 12\nseed = 0\n'
    design = parse_design_text(text)
    o = optimize_design(design, progress=False)
    assert math.isfinite(o.best_value) and o.best_value < o.initial_value
    build_surface(design, o.shape)               # raises if the optimum degenerated
    out = tmp_path / "run"
    path = tmp_path / "d.toml"
    path.write_text(text.replace('files = ["step", "dxf", "svg", "json", "md"]', 'files = ["json"]')
                    .replace('figures = ["basis", "surface", "flat_pattern"]', 'figures = ["surface"]'))
    assert main(["run", str(path), "--out", str(out), "--no-progress"]) == 0, capsys.readouterr().err
    rep = json.loads((out / "report.json").read_text())
    assert rep["optimization"]["best_value"] == pytest.approx(o.best_value, rel=1e-12)


def test_optimized_curve_strip_exports_the_optimized_curves(tmp_path: Path) -> None:
    """After optimizing a 'curves' strip, the curves in model.step and in the report are the strip's
    optimized boundary curves (not the file's), and a curve joined to a boundary curve is re-joined
    to the optimized one. A G2 join makes the difference visible: re-solving keeps G2."""
    from ght_cad.cad.occ import read_step
    from ght_cad.app.design import build_curves, build_surface

    text = (EXAMPLES / "design_hull_plate_quasi.toml").read_text()
    text = text.replace('continuity = "G1"\nk = 0.8', 'continuity = "G2"\nk = 0.8')
    text = text.replace("population = 16\niterations = 25", "population = 8\niterations = 6")
    text = text.replace('files = ["step", "dxf", "svg", "json", "md"]', 'files = ["step", "json"]')
    text = text.replace('figures = ["curve", "curvature", "surface", "flat_pattern", "convergence"]', 'figures = ["curve"]')
    path = tmp_path / "hull.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--no-progress"]) == 0
    r = json.loads((out / "report.json").read_text())
    shape = r["surface"]["shape_parameters"]
    curves = {c["name"]: c for c in r["curves"]}
    for side, name in (("a", "chine"), ("b", "sheer")):
        assert [curves[name][k] for k in ("mu", "nu", "gamma")] == [shape[f"{side}.{k}"] for k in ("mu", "nu", "gamma")]
    (j,) = r["joins"]
    assert (j["first"], j["second"], j["achieved_G"], j["satisfied"]) == ("sheer", "stem", 2, True)
    # the strip's boundary edges and the exported sheer/chine curves coincide (to 1e-6 mm)
    d = load_design(path)
    cv, _ = build_curves(d, shape)
    surf = build_surface(d, shape, curves=cv).surface
    t = np.linspace(0.0, 1.0, 101)
    assert np.max(np.linalg.norm(cv["sheer"].evaluate(t) - surf.b(t), axis=1)) < 1e-6
    assert np.max(np.linalg.norm(cv["chine"].evaluate(t) - surf.a(t), axis=1)) < 1e-6
    assert r["optimization"]["best_value"] == pytest.approx(surf.developability().R, rel=1e-9)
    # every curve edge in the STEP lies on one of the rebuilt curves
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from ght_cad.cad._ocp import TopoDS

    from ght_cad.cad.occ import unwrap

    pts = np.concatenate([c.evaluate(np.linspace(0, 1, 2001)) for c in cv.values()])
    exp, far = TopExp_Explorer(unwrap(read_step(out / "model.step")), TopAbs_EDGE), 0.0
    while exp.More():
        ad = BRepAdaptor_Curve(TopoDS.Edge_s(exp.Current()))
        Q = np.array([[p.X(), p.Y(), p.Z()] for p in
                      (ad.Value(float(s)) for s in np.linspace(ad.FirstParameter(), ad.LastParameter(), 7))])
        chord = (Q[-1] - Q[0]) / np.linalg.norm(Q[-1] - Q[0])
        off_line = np.linalg.norm(np.cross(Q - Q[0], chord), axis=1).max()
        if off_line > 1e-6:  # not a straight end ruling of the face: a boundary or a design curve
            far = max(far, max(float(np.min(np.linalg.norm(pts - q, axis=1))) for q in Q))
        exp.Next()
    assert far < 2.0, far  # mm; sampled nearest point, the file's curves were 23 mm / 242 mm away


def test_boundary_curve_that_is_a_join_second_is_rejoined_per_candidate() -> None:
    """The sheer (curve_b) continues a stem with G2: its first control points are re-solved by the
    join from its own shape parameters, so every candidate re-applies the join; the reported value
    is R of the strip rebuilt from build_curves(design, shape), and the join stays G2."""
    from ght_cad.app.design import build_curves, build_surface, optimize_design

    text = (EXAMPLES / "design_hull_plate_quasi.toml").read_text()
    text = text.replace('first = "sheer"\nsecond = "stem"\ncontinuity = "G1"', 'first = "stem"\nsecond = "sheer"\ncontinuity = "G2"')
    text = text.replace("[[4500, -1100, 1300], [5200, -800, 1450], [5800, -200, 1600]]",
                        "[[-1500, -700, 1000], [-800, -850, 1150], [0, -900, 1200]]")
    d = parse_design_text(text, "hull2.toml")
    o = optimize_design(d, {"iterations": 5, "population": 6}, progress=False)
    assert o.best_value < o.initial_value
    cv, joins = build_curves(d, o.shape)
    assert [(j["achieved_G"], j["satisfied"]) for j in joins] == [(2, True)]
    assert build_surface(d, o.shape, curves=cv).surface.developability().R == pytest.approx(o.best_value, rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.sampled_from([-1.0, 0.0, 1.0]) | st.floats(-1.0, 1.0), min_size=3, max_size=3))
def test_planes_objective_is_inf_exactly_when_the_surface_degenerates(x: list[float]) -> None:
    """Over the whole box of the quarter cone: the optimizer's objective is +inf iff the surface
    cannot be built, else En of the unit-normal dual curve (recomputed here with 80 nodes; En's
    integrand is smooth. AL's |U'| has a near-kink where U' almost vanishes on this design, and
    64-node Gauss–Legendre AL is only within ~1e-4 relative of the converged integral there)."""
    from ght_cad.app.design import OptimizeSpec, _objective_fn, build_surface
    from ght_cad.core.errors import GHTError
    from ght_cad.surfaces.planes import normalize_planes

    d = parse_design_text((EXAMPLES / "design_duct.toml").read_text(), "duct.toml")
    f = _objective_fn(d, {}, OptimizeSpec(objective="En", parameters=["mu", "nu", "gamma"]))
    sh = dict(zip(("mu", "nu", "gamma"), x))
    try:
        build_surface(d, sh)
    except GHTError:
        with pytest.raises(GHTError):
            f(sh)
        return
    from ght_cad import GHTCurve

    U = GHTCurve(normalize_planes(np.asarray(d.surface.planes, dtype=float)), *x)
    t, w = np.polynomial.legendre.leggauss(80)
    en = 0.5 * w @ np.sum(U.derivative(0.5 * (t + 1.0), 2) ** 2, axis=1)
    assert f(sh) == pytest.approx(en, rel=1e-9)
