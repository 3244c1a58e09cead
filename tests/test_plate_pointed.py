"""Pointed ends (spec 5.7 + 6.1): a `type = "rails"` loft whose rails meet at an end (a bow where
the chine meets the sheer) has a zero-length end ruling. The loft near that corner, the limit
normal and bending radius there, the neutral-surface flat pattern, the sheet check and the plate
solid (no end wall at the point).

Tolerances: as tests/test_plate_fans.py (fit certified to ``3e-7 T``: face points within
``1e-6 T`` of their exact points, inside also within ``1e-6 size``; volume against the closed form
to ``1e-6``); flat pattern errors (exact 1-D quadrature) ``<= 1e-9``, measured ~1e-15.
"""

from __future__ import annotations

import functools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

pytest.importorskip("OCP")

from OCP.BRep import BRep_Tool  # noqa: E402

from ght_cad import GHTCurve  # noqa: E402
from ght_cad.cad.occ import is_valid  # noqa: E402
from ght_cad.cad.sheet_solid import plate_faces, plate_solid, read_step_face_names, write_plate_step  # noqa: E402
from ght_cad.core.errors import NotDevelopableError  # noqa: E402
from ght_cad.developables.loft import developable_loft  # noqa: E402
from ght_cad.sheetmetal.plate import plate_volume  # noqa: E402
from ght_cad.sheetmetal.sheet import Sheet, SheetError, bending_radius, check_offset, ruling_normal  # noqa: E402
from ght_cad.unrolling.unroll import unroll  # noqa: E402
from tests.test_plate_fans import _size, check_inside_outside, check_outside_at_thickness  # noqa: E402

SHEER = np.array([[0, -900, 1200], [1500, -1000, 1250], [3000, -700, 1350], [4200, 0, 1500]], float)
CHINE = np.array([[0, -700, 300], [1500, -800, 350], [3000, -500, 700], [4200, 0, 1500]], float)
BOW_TOML = Path(__file__).resolve().parent.parent / "examples" / "design_bow_plate.toml"


def bow(both: bool = False, chine: np.ndarray | None = None, sheer: np.ndarray | None = None):
    """The bow loft (rails meeting at u = 1; at both ends with ``both``). The loft of the module's
    own rails is built once per ``both`` and shared (the tests only read it)."""
    if chine is None and sheer is None:
        return _bow(bool(both))
    return _make_bow(both, chine, sheer)


@functools.lru_cache(maxsize=2)
def _bow(both: bool):
    return _make_bow(both, None, None)


def _make_bow(both: bool, chine: np.ndarray | None, sheer: np.ndarray | None):
    c = (CHINE if chine is None else chine).copy()
    s = (SHEER if sheer is None else sheer).copy()
    if both:  # the rails meet at both ends (a lens-shaped panel)
        c[0] = s[0] = [0.0, -800.0, 700.0]
    return developable_loft(GHTCurve(c), GHTCurve(s))




def check_pointed_plate(loft, sheet: Sheet) -> dict:
    """Valid solid, no end wall at a point, inside on S, outside at T, volume = closed form."""
    T = sheet.thickness
    plate = plate_solid(loft, sheet)
    assert is_valid(plate.solid)
    pointed = plate.data.pointed
    g = loft.ruling_lengths(np.array([0.0, 1.0]))
    assert pointed == (bool(g[0] == 0), bool(g[1] == 0))
    assert len(plate.edges) == 4 - sum(pointed)
    assert [n for n, _ in plate.named_faces()][:2] == ["inside", "outside"]
    size = _size(loft)
    lam = np.linspace(0.0, 1.0, 41)
    vv = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    U, V = np.repeat(lam, vv.size), np.tile(vv, lam.size)
    check_inside_outside(plate, loft, sheet, U, V, size)
    # outside at distance T from the inside face's surface, independently of the parametrization
    keep = (V > 0) & (V < 1) & (U > 0) & (U < 1)
    check_outside_at_thickness(plate, U[keep], V[keep], T)
    Vc = plate_volume(loft, sheet)
    assert abs(plate.volume / Vc - 1) <= 1e-6
    return {"plate": plate, "V": plate.volume, "Vc": Vc}


# -- the loft and the limit normal at the point --------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("both", [False, True])
def test_pointed_loft_is_exact_and_its_pattern_too(both: bool) -> None:
    loft = bow(both)
    g = loft.ruling_lengths(np.array([0.0, 1.0]))
    assert g[1] == 0.0 and (g[0] == 0.0) == both
    # the branch near the corner: the ruling direction is smooth (no eps/|g| noise), the
    # developability residual at round-off
    e = np.array([1e-2, 1e-4, 1e-6, 1e-8, 1e-10])
    n = ruling_normal(loft, 1.0 - e, 0)[0]
    n_end, n1_end = (x[0] for x in ruling_normal(loft, np.array([1.0]), 1))
    # |n(1) - n(1 - e)| / e -> |n'(1)|: the n'' term (measured 0.35 e) plus the difference's
    # round-off (eps/e: measured 1.7e-6 at e = 1e-10); noise of eps/|g| would be ~1e-4 there
    slope = np.linalg.norm(n - n_end, axis=1) / e
    assert np.all(np.abs(slope / np.linalg.norm(n1_end) - 1) <= 0.5 * e + 1e-15 / e)
    assert loft.report.theta_max_deg <= 1e-9
    pat = unroll(loft, rulings=8)
    assert pat.errors["max"] <= 1e-9
    assert pat.errors["boundary_length"] <= 1e-12  # measured 4e-16 (2.8e-9 before the corner fix)


def test_limit_normal_and_radius_at_the_point() -> None:
    loft = bow()
    # the normal, its derivative and the bending radius tend to their values at the point
    e = np.array([1e-3, 1e-4, 1e-5, 1e-6])
    n, n1 = ruling_normal(loft, 1.0 - e, 1)
    (n0,), (n10,) = ruling_normal(loft, np.array([1.0]), 1)
    assert np.all(np.linalg.norm(n - n0, axis=1) <= 1.0 * e)  # |n'| = 0.715
    assert np.linalg.norm(n1[-1] - n10) <= 1e-5 * np.linalg.norm(n10)
    assert np.all(np.linalg.norm(n1 - n10, axis=1) <= 5.0 * e * np.linalg.norm(n10) + 1e-6 * np.linalg.norm(n10))
    r_end = bending_radius(loft, np.array([1.0, 1.0]), np.array([0.0, 1.0]))
    assert r_end[0] == pytest.approx(r_end[1], rel=1e-12)  # a zero ruling: both ends are the point
    r = bending_radius(loft, 1.0 - e, np.full(e.size, 0.5))
    assert np.all(np.abs(r / r_end[0] - 1) <= 30.0 * e)
    # the normal is the ruled-surface normal's limit from inside: X_u x X_v at u = 1 - 1e-7
    u = np.array([1.0 - 1e-7])
    xu = loft.a(u, 1) + 0.5 * loft.ruling(u, 1)
    m = np.cross(xu, loft.ruling(u))[0]
    assert np.dot(m / np.linalg.norm(m), n0) > 1 - 1e-12


def test_too_thick_is_refused_at_the_point_with_the_radius() -> None:
    loft = bow()
    r_end = float(abs(bending_radius(loft, np.array([1.0]), np.array([0.5]))[0]))
    rmin = check_offset(loft, Sheet(4.0, 0.44))
    assert rmin <= r_end * (1 + 1e-12)
    # a neutral offset beyond the smallest radius: refused naming the ruling and the radius
    K = 1.0
    T = 1.001 * rmin / K
    with pytest.raises(SheetError, match=r"reaches the bending radius .* of the ruling at u=") as exc:
        check_offset(loft, Sheet(T, K))
    assert exc.value.constraint in ("radius", "centre") and exc.value.radius == pytest.approx(rmin, rel=1e-9)
    # just below the radius: accepted (the point is regular, not refused spuriously)
    assert check_offset(loft, Sheet(0.999 * rmin / K, K)) == rmin


def test_tangent_rails_at_the_point_are_refused() -> None:
    # a ruled surface whose boundaries meet tangentially at u = 1: c' x g' = 0 there
    from ght_cad.surfaces.ruled import CurvePairRuledSurface

    a = GHTCurve(np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]], float))
    b = GHTCurve(np.array([[0, 1, 0.2], [1, 1, 0.1], [2, 0, 0], [3, 0, 0]], float))  # same end tangent
    surf = CurvePairRuledSurface(a, b)
    if np.linalg.norm(np.cross(surf.a(np.array([1.0]), 1), surf.b(np.array([1.0]), 1))) > 1e-9:
        pytest.skip("the test rails are not tangent at the point")
    with pytest.raises(SheetError, match="meet tangentially"):
        ruling_normal(surf, np.array([1.0]))


# -- the plate ------------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("both, T, side", [(False, 4.0, "normal"), (False, 4.0, "reverse"), (False, 60.0, "normal"),
                                           (True, 4.0, "normal"), (True, 20.0, "reverse")])
def test_plate_of_a_pointed_loft(both: bool, T: float, side: str) -> None:
    out = check_pointed_plate(bow(both), Sheet(T, 0.44, side))
    names = [n for n, _ in out["plate"].named_faces()]
    assert names == ["inside", "outside"] + [f"edge{i + 1}" for i in range(2 if both else 3)]
    # the inside face ends in a degenerate (point) edge at each pointed end
    from OCP.TopAbs import TopAbs_EDGE
    from OCP.TopExp import TopExp_Explorer
    from ght_cad.cad._ocp import TopoDS

    ex, deg = TopExp_Explorer(out["plate"].inside, TopAbs_EDGE), 0
    while ex.More():
        deg += BRep_Tool.Degenerated_s(TopoDS.Edge_s(ex.Current()))
        ex.Next()
    assert deg == (2 if both else 1)


@pytest.mark.slow
@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
@given(dy1=st.floats(-200.0, 200.0), dz2=st.floats(-200.0, 200.0), dz0=st.floats(-300.0, 300.0),
       both=st.booleans(), T=st.floats(0.5, 60.0), side=st.sampled_from(["normal", "reverse"]))
def test_every_accepted_pointed_plate_is_exact(dy1, dz2, dz0, both, T, side) -> None:
    """Bow rails moved in a box (chine's second point, sheer's third point height, sheer start
    height), one or both ends pointed, any T and side: a refusal is the sheet check's (before
    OCCT); every accepted plate is valid, on the design surface and at distance T."""
    chine, sheer = CHINE.copy(), SHEER.copy()
    chine[1, 1] += dy1
    sheer[2, 2] += dz2
    sheer[0, 2] += dz0
    try:
        loft = bow(both, chine, sheer)
    except NotDevelopableError:
        assume(False)
    sheet = Sheet(T, 0.44, side)
    try:
        check_offset(loft, sheet)
    except SheetError as exc:
        assert exc.constraint in ("apex", "radius", "centre")
        event(f"refused: {exc.constraint}")
        return
    event(f"accepted: {side}, both={both}")
    check_pointed_plate(loft, sheet)


def test_pointed_plate_step_names_and_readers(tmp_path) -> None:
    loft = bow()
    plate = plate_solid(loft, Sheet(4.0, 0.44))
    path = write_plate_step(plate, tmp_path / "bow.step")
    shape, names = read_step_face_names(path)
    assert sorted(names.values()) == ["edge1", "edge2", "edge3", "inside", "outside"]
    pf = plate_faces(shape, names)
    assert pf is not None and pf.how == "names"
    assert pf.thickness == pytest.approx(4.0, rel=1e-6)


# -- the design run --------------------------------------------------------------------------------
@pytest.mark.slow
def test_run_bow_plate_with_a_sheet(tmp_path, capsys) -> None:
    from ght_cad.app.cli import main

    out = tmp_path / "out"
    assert main(["run", str(BOW_TOML), "--out", str(out)]) == 0
    rep = json.loads((out / "report.json").read_text())
    plate = rep["plate"]
    assert plate["valid"] and plate["solids"] == 1
    assert abs(plate["volume"] / plate["volume_closed_form"] - 1) <= 1e-6
    errs = rep["flat_pattern"]["errors"]
    assert errs["max"] <= 1e-9
    sh = rep["flat_pattern"]["sheet"][0]
    assert math.isfinite(sh["min_bending_radius"])
    assert all(math.isfinite(r["radius_a"]) and math.isfinite(r["radius_b"]) for r in sh["forming"])


@pytest.mark.slow
def test_run_plated_skiff_with_a_pointed_side_panel(tmp_path, capsys) -> None:
    """Two surfaces, the side loft pointed at the bow, one [sheet] (examples/design_skiff_plated.toml):
    the shell orientation asks the pointed loft for a, a', a'' on parameters near and far from the
    corner in turn (cached derivative lists of different lengths once broke the split: IndexError)."""
    from ght_cad.app.cli import main

    out = tmp_path / "out"
    path = Path(__file__).resolve().parents[1] / "examples" / "design_skiff_plated.toml"
    assert main(["run", str(path), "--out", str(out)]) == 0, capsys.readouterr().err
    rep = json.loads((out / "report.json").read_text())
    assert rep["flat_pattern"]["errors"]["max"] <= 1e-12
    plate = rep["plate"]
    assert plate["valid"] and plate["solids"] == 2
    assert [r["surface"] for r in plate["surfaces"]] == ["bottom", "side"]
    assert abs(plate["volume"] / plate["volume_closed_form"] - 1.0) <= 1e-6
    (joint,) = plate["joints"]  # the chine; the side panel's zero ruling at the bow has no direction
    assert joint["surfaces"] == ["bottom", "side"] and joint["kind"] in ("gap", "overlap", "mixed (gap, overlap)")
    assert all(math.isfinite(joint[k]) for k in ("outside_edge_distance_max", "fold_angle_deg_max"))


@pytest.mark.slow
def test_unroll_step_of_a_plain_pointed_loft(tmp_path, capsys) -> None:
    """The skiff without its sheet written to STEP and read back (``ght-cad unroll model.step``):
    its side face comes to a point at the bow, where the B-spline's end poles differ by rounding
    (a ruling of 2e-13 on 500 mm). That ruling's normals are noise and are skipped like an exact
    zero ruling (θ_max 4.4° there refused the face before); the face unrolls with the fit's
    distortion (errors max <= 1e-7, measured 5e-9), the ruling lengths measured against a floor
    of 1e-6 of the longest ruling."""
    from ght_cad.app.cli import main

    text = (Path(__file__).resolve().parents[1] / "examples" / "design_skiff_plated.toml").read_text()
    start = text.index("\n[sheet]\n")
    text = text[:start + 1] + text[text.index("\n[unroll]\n") + 1:]
    text = text.replace('figures = ["surface", "flat_pattern"]', "figures = []")
    design = tmp_path / "skiff_plain.toml"
    design.write_text(text)
    out = tmp_path / "out"
    assert main(["run", str(design), "--out", str(out)]) == 0, capsys.readouterr().err
    capsys.readouterr()
    assert main(["unroll", str(out / "model.step"), "--json"]) == 0, capsys.readouterr().err
    rep = json.loads(capsys.readouterr().out)
    assert rep["errors"]["max"] <= 1e-7
    assert rep["panels"] == 5


def test_theta_skips_a_ruling_that_is_rounding_noise() -> None:
    """θ at a ruling shorter than SINGULAR_NORMAL_TOL of the boundary speeds is NaN (skipped), as
    at an exact zero ruling; a short but real ruling (1e-6 of the speeds) keeps its θ."""
    from ght_cad.surfaces.ruled import _theta

    a1 = np.array([[100.0, 0.0, 0.0]] * 3)
    b1 = np.array([[90.0, 5.0, 0.0]] * 3)
    g = np.array([[0.0, 1e-13, 2e-13], [0.0, 0.0, 0.0], [0.0, 1e-4, 0.0]])
    th, dot = _theta(a1, b1, g)
    assert np.isnan(th[0]) and np.isnan(th[1]) and np.isnan(dot[0])
    assert th[2] == pytest.approx(0.0, abs=1e-9)
