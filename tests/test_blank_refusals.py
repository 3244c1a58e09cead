"""Issue 23, refusals on real parts built in build123d (tests/sheet_parts.py): a blank whose
flanges overlap in the flat although the part does not intersect itself, a doubly curved
(non-developable) shell, and an ambiguous skin (a square bar). Each: exit 2 with one line naming
the faces and the measured value, nothing written; the overlap with ``--allow-split`` gives
separate panels with matching marks."""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import pytest

pytest.importorskip("build123d")

sys.path.insert(0, str(Path(__file__).parent))
from sheet_parts import crossed_flanges, spherical_shell, square_bar  # noqa: E402

import ght_cad  # noqa: E402
from ght_cad.sheetmetal.blank import BlankError  # noqa: E402
from ght_cad.cad.occ import write_step  # noqa: E402
from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main  # noqa: E402

pytestmark = pytest.mark.slow  # booleans of build123d solids, STEP round trips (~5-20 s each on a loaded machine)

K = 0.42


@pytest.fixture(scope="module")
def crossed(tmp_path_factory):
    solid, overlap, area = crossed_flanges()
    step = tmp_path_factory.mktemp("crossed") / "crossed.step"
    write_step(solid, step)
    return solid, overlap, area, step


def _run(argv, capsys):
    rc = main(argv + ["--json"])
    return rc, json.loads(capsys.readouterr().out)


def test_crossed_flanges_do_not_intersect_in_3d(crossed) -> None:
    """The part is one valid solid of the volume of its pieces (no piece overlaps another in 3-D)."""
    import build123d as bd

    solid, *_ = crossed
    A, B, T, R, F, e = 60.0, 50.0, 2.0, 3.0, 20.0, 15.0
    bend = math.pi / 4 * ((R + T) ** 2 - R ** 2)  # a quarter annulus
    want = A * B * T + bend * (A + B) + T * F * (B + e) + T * F * (A + e)
    assert solid.is_valid and len(solid.solids()) == 1
    assert abs(solid.volume / want - 1) < 1e-9, (solid.volume, want)
    del bd


def test_overlap_refused_with_faces_and_area(crossed, tmp_path: Path, capsys) -> None:
    """``ght-cad unroll part.step``: exit 2, one line naming the two flange faces and the overlap
    area (e - BA)² (BA = (R + K T) π/2 = 6.0319, e = 15: 80.4276 mm²) to 1e-7 relative (the message's
    9 digits; the area is exact for the outline polygons, whose edges are straight here); no file."""
    solid, overlap, area, step = crossed
    out = tmp_path / "x.dxf"
    rc, res = _run(["unroll", str(step), "--k-factor", str(K), "--dxf", str(out)], capsys)
    assert rc == EXIT_USAGE and not out.exists()
    msg = res["error"]
    assert "\n" not in msg and "crossed.step" in msg and "overlap" in msg, msg
    faces = re.search(r"faces (F\d+), (F\d+)", msg)
    assert faces, msg
    got = float(re.search(r"overlap area ([0-9.eE+-]+) mm\^2", msg).group(1))
    assert abs(got / overlap(K) - 1) < 1e-7, (got, overlap(K))
    # the two faces are the flanges' flat faces: planar, of 3-D area F (B + e) and F (A + e)
    from ght_cad.cad.unfold_solid import sheet_skins

    skins, _ = sheet_skins(solid)
    by = {f"F{f.number}": f for f in skins[0].faces}
    areas = sorted(by[faces.group(i)].area for i in (1, 2))
    assert areas == [pytest.approx(20.0 * 65.0, rel=1e-9), pytest.approx(20.0 * 75.0, rel=1e-9)]
    # the same through the Python API
    with pytest.raises(BlankError, match=r"overlap area 80\.42757"):
        ght_cad.unfold(solid, k_factor=K)


def test_overlap_allow_split_panels_with_marks(crossed, tmp_path: Path, capsys) -> None:
    """``--allow-split``: exit 0, one panel per skin face (plate, 2 bends, 2 flanges), the faces'
    flat area in total, every shared edge marked E<k> on exactly two panels."""
    solid, overlap, area, step = crossed
    out = tmp_path / "split.dxf"
    rc, res = _run(["unroll", str(step), "--k-factor", str(K), "--allow-split", "--dxf", str(out)], capsys)
    assert rc == EXIT_OK and out.exists(), res
    assert res["panels"] == 5
    assert abs(res["area"] / area(K) - 1) < 1e-9, (res["area"], area(K))
    res_py = ght_cad.unfold(solid, k_factor=K, allow_split=True)
    panels = res_py.pattern.panels
    assert len(panels) == 5 and abs(res_py.pattern.area / area(K) - 1) < 1e-9
    labels: dict[str, list[str]] = {}
    for p in panels:
        for t in p.texts:
            if re.fullmatch(r"E\d+", t[2]):
                labels.setdefault(t[2], []).append(p.label)
    # the 4 edges the walk placed faces across (plate-bend, bend-flange, twice)
    assert len(labels) == 4 and all(len(v) == 2 and v[0] != v[1] for v in labels.values()), labels
    assert sum(len(p.marks) for p in panels) == 4 * 2 * 4  # 4 ticks per edge per panel


def test_non_developable_shell_refused(tmp_path: Path, capsys) -> None:
    """A spherical shell segment (skins exactly T apart, one face each): ``ght-cad unroll`` exits 2
    naming the sphere face and how far its straightest isolines are from straight (a one-face skin
    goes to the per-face unroll, which measures that); ``ght_cad.unfold`` refuses naming the face
    and its Gaussian curvature 1/R² (R = 50 or 52, whichever skin) to 1e-5; no output."""
    from OCP.BRepAdaptor import BRepAdaptor_Surface
    from OCP.GeomAbs import GeomAbs_Sphere

    solid = spherical_shell()
    step = tmp_path / "shell.step"
    write_step(solid, step)
    out = tmp_path / "x.dxf"
    for extra in ([], ["--k-factor", str(K)]):
        rc, res = _run(["unroll", str(step), *extra, "--dxf", str(out)], capsys)
        assert rc == EXIT_USAGE and not out.exists()
        msg = res["error"]
        assert "\n" not in msg and "not developable" in msg, msg
        face = int(re.search(r"face (\d+) of \d+", msg).group(1))
        assert BRepAdaptor_Surface(solid.faces()[face - 1].wrapped).GetType() == GeomAbs_Sphere
        dev = float(re.search(r"deviate ([0-9.eE+-]+) from straight", msg).group(1))
        assert dev > 1e-3, msg  # allowed: 1e-9
    with pytest.raises(BlankError, match="Gaussian curvature") as info:
        ght_cad.unfold(solid)
    msg = str(info.value)
    face = int(re.search(r"face F(\d+)", msg).group(1))
    assert BRepAdaptor_Surface(solid.faces()[face - 1].wrapped).GetType() == GeomAbs_Sphere
    kg = float(re.search(r"Gaussian curvature .*? is ([0-9.eE+-]+) /mm\^2", msg).group(1))
    assert min(abs(kg * r * r - 1) for r in (50.0, 52.0)) < 1e-5, kg


def test_ambiguous_skin_refused(tmp_path: Path, capsys) -> None:
    """A square bar T x T x L: every long face lies T from its opposite one, in two pairings; exit 2
    'ambiguous skin' naming the faces of the contradiction and T (not a 'sharp edge'); no output."""
    step = tmp_path / "bar.step"
    write_step(square_bar(), step)
    out = tmp_path / "x.dxf"
    rc, res = _run(["unroll", str(step), "--dxf", str(out)], capsys)
    assert rc == EXIT_USAGE and not out.exists()
    msg = res["error"]
    assert "\n" not in msg and "ambiguous skin" in msg and "distance 2 " in msg, msg
    assert "sharp edge" not in msg
    named = set(re.findall(r"F(\d+)", msg))
    assert len(named) == 3, msg  # two opposite faces and one face sharing an edge with both
    with pytest.raises(BlankError, match="ambiguous skin"):
        ght_cad.unfold(square_bar())
