"""FlatPattern: report, DXF/SVG/PNG export (re-read), atomic writes, helpers."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import ezdxf
import numpy as np
import pytest

from ght_cad import GHTCurve
from ght_cad.core.errors import GHTError
from ght_cad.pattern.flat_pattern import DistortionReport, FlatPattern, clip_segments, romberg_length
from ght_cad.surfaces.ruled import CurvePairRuledSurface
from ght_cad.unrolling.unroll import unroll, unroll_composite

from dxf_read import dxf_outline_areas, outline_bulges, outline_vertices, svg_outline_areas


def quarter(r: float, z: float, start: float = 0.0) -> GHTCurve:
    c, s = math.cos(start), math.sin(start)
    R = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    P = np.array([(r, 0, z), (r, r, z), (0, r, z)]) @ R.T
    return GHTCurve(P, gamma=-1)


@pytest.fixture(scope="module")
def pattern() -> FlatPattern:
    return unroll(CurvePairRuledSurface(quarter(1.0, 0.0), quarter(2.0, 1.5)), rulings=7, units="mm")


def test_errors_and_report(pattern: FlatPattern) -> None:
    e = pattern.errors
    assert set(e) == {"boundary_length", "ruling_length", "area", "angle_deg", "max"}
    assert e["max"] == max(e["boundary_length"], e["ruling_length"], e["area"])
    assert e["max"] < 1e-12
    d = pattern.report.as_dict()
    for k in ("boundary_length", "ruling_length", "area", "angle_deg", "stretch"):
        assert d[k]["rms"] <= d[k]["max"] + 1e-300
    assert len(pattern.report.boundary_names) == 4
    text = pattern.summary()
    for word in ("boundary length", "ruling length", "area", "angle", "max", "rms"):
        assert word in text


def test_dxf_reread(pattern: FlatPattern, tmp_path) -> None:
    path = pattern.export_dxf(tmp_path / "p.dxf")
    doc = ezdxf.readfile(path)
    assert not doc.audit().has_errors
    names = {layer.dxf.name for layer in doc.layers}
    assert {"OUTLINE", "BEND", "LABELS"} <= names
    assert doc.header["$INSUNITS"] == 4  # mm
    msp = doc.modelspace()
    outlines = msp.query('LWPOLYLINE[layer=="OUTLINE"]')
    assert len(outlines) == 1 and outlines[0].closed
    # a cone frustum: arc a, straight ruling, arc b, straight ruling; vertices = the corners
    pts = outline_vertices(outlines[0])
    np.testing.assert_allclose(pts, pattern.outlines[0][::256], atol=1e-12)
    bulges = outline_bulges(outlines[0])
    assert bulges[1] == bulges[3] == 0.0 and bulges[0] * bulges[2] < 0  # the arcs turn opposite ways
    (area,) = dxf_outline_areas(path)
    assert area == pytest.approx(pattern.area, rel=1e-12)
    bends = msp.query('LINE[layer=="BEND"]')
    assert len(bends) == 7
    assert all(b.dxf.linetype == "DASHED" for b in bends)
    assert doc.layers.get("BEND").dxf.linetype == "DASHED"
    assert "DASHED" in doc.linetypes
    texts = [t.dxf.text for t in msp.query('TEXT[layer=="LABELS"]')]
    assert "P1" in texts


def test_dxf_units_and_spline(tmp_path) -> None:
    pat = unroll(CurvePairRuledSurface(quarter(1.0, 0.0), quarter(2.0, 1.5)), units="in", rulings=2)  # a cone
    doc = ezdxf.readfile(pat.export_dxf(tmp_path / "s.dxf", spline=True))
    assert doc.header["$INSUNITS"] == 1
    sp = doc.modelspace().query('SPLINE[layer=="OUTLINE"]')
    assert len(sp) == 1 and sp[0].dxf.degree == 2 and not sp[0].fit_points
    # control data of the exact arcs and lines (no fit points): on the knot span of edge a, the
    # spline (ezdxf's rational evaluation) lies on the circle through three exact points of the
    # developed edge a to 1e-12 of the size; on the span of a straight ruling, on its chord
    bs = sp[0].construction_tool()
    a, ruling = pat.panels[0].loops[0][:2]
    p0, pm, p1 = a.flat_fn(np.array([0.0, 0.5, 1.0]))
    A = 2 * np.array([pm - p0, p1 - p0])
    centre = np.linalg.solve(A, [pm @ pm - p0 @ p0, p1 @ p1 - p0 @ p0])
    radius = np.linalg.norm(p0 - centre)
    size = float(np.max(np.ptp(pat.outlines[0], axis=0)))
    on_a = np.array(list(bs.points(np.linspace(0.0, 1.0, 201))))[:, :2]
    assert np.max(np.abs(np.linalg.norm(on_a - centre, axis=1) - radius)) <= 1e-12 * size
    q0, q1 = ruling.flat_fn(np.array([0.0, 1.0]))
    on_r = np.array(list(bs.points(np.linspace(1.0, 2.0, 51))))[:, :2]
    n = np.array([-(q1 - q0)[1], (q1 - q0)[0]]) / np.linalg.norm(q1 - q0)
    assert np.max(np.abs((on_r - q0) @ n)) <= 1e-12 * size
    corners = np.array([tuple(bs.point(float(k)))[:2] for k in range(4)])
    np.testing.assert_allclose(corners, pat.outlines[0][::256], atol=1e-12)


def test_svg_is_valid_xml_with_layers(pattern: FlatPattern, tmp_path) -> None:
    path = pattern.export_svg(tmp_path / "p.svg")
    root = ET.parse(path).getroot()
    ns = {"s": "http://www.w3.org/2000/svg"}
    assert root.tag.endswith("svg")
    assert root.get("width").endswith("mm")
    groups = {g.get("id"): g for g in root.findall("s:g", ns)}
    assert {"OUTLINE", "BEND", "LABELS"} <= set(groups)
    assert len(groups["OUTLINE"].findall("s:path", ns)) == 1
    assert len(groups["BEND"].findall("s:line", ns)) == 7
    assert groups["BEND"].get("stroke-dasharray")
    # the path: two lines, two arcs, closed; its area (svgelements' reading of the A commands)
    # is the pattern's
    d = groups["OUTLINE"][0].get("d")
    assert d.count("A") == 2 and d.count("L") == 2 and d.endswith("Z")
    (area,) = svg_outline_areas(path)
    assert area == pytest.approx(pattern.area, rel=1e-9)


def test_png_preview(pattern: FlatPattern, tmp_path) -> None:
    path = pattern.plot_png(tmp_path / "p.png")
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 5000


def test_failed_export_leaves_no_partial_file(pattern: FlatPattern, tmp_path, monkeypatch) -> None:
    target = tmp_path / "keep.dxf"
    target.write_text("old")

    def boom(self, *a, **k):
        raise OSError("disk full")

    monkeypatch.setattr(ezdxf.document.Drawing, "saveas", boom)
    with pytest.raises(OSError):
        pattern.export_dxf(target)
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.dxf"]


def test_romberg_length_circle() -> None:
    t = np.linspace(0.0, 2.0, 4 * 32 + 1)
    pts = np.stack([np.cos(t), np.sin(t)], axis=1)
    assert abs(romberg_length(pts) - 2.0) < 1e-11
    assert abs(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)) - 2.0) > 1e-6  # plain chords are not
    with pytest.raises(GHTError, match="4N\\+1"):
        romberg_length(pts[:-1])


def test_clip_segments_with_hole() -> None:
    square = np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float)
    hole = np.array([[1, 1], [3, 1], [3, 3], [1, 3]], float)
    segs = np.array([[[2, -1], [2, 5]], [[0.5, -1], [0.5, 5]]], float)
    out = clip_segments(segs, [square, hole])
    lengths = sorted(np.linalg.norm(s[1] - s[0]) for s in out)
    np.testing.assert_allclose(lengths, [1.0, 1.0, 4.0], atol=1e-12)


def test_bad_units() -> None:
    with pytest.raises(GHTError, match="units='yd'"):
        FlatPattern([], units="yd")


def test_report_combine() -> None:
    a = DistortionReport(np.array([1e-3]), ["x"], np.array([0.0]), np.array([1e-4]), np.array([0.1]), np.array([0.0]))
    b = DistortionReport(np.array([2e-3]), ["y"], np.array([5e-3]), np.array([1e-5]), np.array([0.2]), np.array([0.0]))
    c = DistortionReport.combine([a, b])
    d = c.as_dict()
    assert d["boundary_length"]["max"] == 2e-3
    assert d["ruling_length"]["max"] == 5e-3
    np.testing.assert_allclose(d["area"]["rms"], math.sqrt((1e-8 + 1e-10) / 2))
    assert c.max_relative_error == 5e-3


def test_composite_exports_all_panels(tmp_path) -> None:
    s1 = CurvePairRuledSurface(quarter(1.0, 0.0), quarter(1.0, 1.0))
    s2 = CurvePairRuledSurface(quarter(1.0, 0.0, math.pi / 2), quarter(1.0, 1.0, math.pi / 2))
    pat = unroll_composite([s1, s2], rulings=3)
    doc = ezdxf.readfile(pat.export_dxf(tmp_path / "c.dxf"))
    msp = doc.modelspace()
    assert len(msp.query('LWPOLYLINE[layer=="OUTLINE"]')) == 2
    texts = [t.dxf.text for t in msp.query("TEXT")]
    assert {"P1", "P2"} <= set(texts) and texts.count("E1") == 2
    assert len(msp.query('LINE[layer=="MARKS"]')) == 8
    root = ET.parse(pat.export_svg(tmp_path / "c.svg")).getroot()
    assert root.tag.endswith("svg")


def test_dxf_r12_fallback_without_ezdxf(pattern: FlatPattern, tmp_path, monkeypatch) -> None:
    """Without ezdxf (FreeCAD's Python) a plain R12 file with the same layers is written."""
    import builtins

    real_import = builtins.__import__

    def no_ezdxf(name, *args, **kwargs):
        if name == "ezdxf":
            raise ImportError("no ezdxf here")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_ezdxf)
    path = pattern.export_dxf(tmp_path / "r12.dxf")
    monkeypatch.undo()
    doc = ezdxf.readfile(path)
    assert not doc.audit().has_errors
    assert doc.dxfversion == "AC1009"
    assert {"OUTLINE", "BEND", "LABELS"} <= {layer.dxf.name for layer in doc.layers}
    assert doc.header["$INSUNITS"] == 4
    msp = doc.modelspace()
    polys = msp.query('POLYLINE[layer=="OUTLINE"]')
    assert len(polys) == 1 and polys[0].is_closed
    # the same corners (17 digits: exact) and bulges as the R2010 file, the same area
    np.testing.assert_array_equal(outline_vertices(polys[0]), pattern.outlines[0][::256])
    lw = ezdxf.readfile(pattern.export_dxf(tmp_path / "r2010.dxf")).modelspace().query("LWPOLYLINE")[0]
    np.testing.assert_array_equal(outline_bulges(polys[0]), outline_bulges(lw))
    assert dxf_outline_areas(path)[0] == pytest.approx(pattern.area, rel=1e-12)
    bends = msp.query('LINE[layer=="BEND"]')
    assert len(bends) == 7 and all(b.dxf.linetype == "DASHED" for b in bends)
    assert [t.dxf.text for t in msp.query("TEXT")] == ["P1"]


#: mm per unit, for the model units and for the SVG length units (CSS: 1in = 25.4mm)
_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4, "ft": 304.8}


def _unit_square(units: str) -> FlatPattern:
    line = lambda y: GHTCurve(np.array([(0.0, y, 0.0), (0.5, y, 0.0), (1.0, y, 0.0)]), gamma=-1)  # noqa: E731
    return unroll(CurvePairRuledSurface(line(0.0), line(1.0)), rulings=0, units=units)


def _svg_size(text: str) -> tuple[float, str, float, str, list[float]]:
    import re

    root = ET.fromstring(text)
    out = []
    for key in ("width", "height"):
        m = re.fullmatch(r"([0-9.eE+-]+)(mm|cm|in)", root.get(key))
        assert m, f"{key}={root.get(key)!r} is not an SVG length in mm, cm or in"
        out += [float(m.group(1)), m.group(2)]
    return (*out, [float(x) for x in root.get("viewBox").split()])


@pytest.mark.parametrize("units", ["mm", "cm", "m", "in", "ft"])
def test_svg_size_is_true_scale_in_a_valid_svg_unit(units: str) -> None:
    """width/height carry mm, cm or in (m → mm, ft → in) and equal the viewBox extent (model
    units) at true scale: width [mm] = viewBox width × (mm per model unit), to 1e-8."""
    pat = _unit_square(units)
    np.testing.assert_allclose(np.ptp(pat.outlines[0], axis=0), [1.0, 1.0], rtol=1e-12)
    W, wu, H, hu, vb = _svg_size(pat.svg_text(margin=0.0))
    assert wu == hu == {"m": "mm", "ft": "in"}.get(units, units)
    np.testing.assert_allclose(vb, [0.0, 0.0, 1.0, 1.0], atol=1e-9)
    np.testing.assert_allclose([W * _MM[wu], H * _MM[hu]], [_MM[units], _MM[units]], rtol=1e-8)
    # the default margin (3 % of the extent) is scaled the same way
    W, wu, H, hu, vb = _svg_size(pat.svg_text())
    np.testing.assert_allclose(vb[2:], [1.06, 1.06], rtol=1e-8)
    np.testing.assert_allclose([W * _MM[wu], H * _MM[hu]], [1.06 * _MM[units]] * 2, rtol=1e-8)


def test_svg_one_metre_is_1000mm_and_one_foot_12in() -> None:
    assert _svg_size(_unit_square("m").svg_text(margin=0.0))[:4] == (1000.0, "mm", 1000.0, "mm")
    assert _svg_size(_unit_square("ft").svg_text(margin=0.0))[:4] == (12.0, "in", 12.0, "in")


@pytest.mark.parametrize("units, mm_per_unit, scale", [("mm", 1.0, 3000.0), ("mm", 1.0, 20.0), ("m", 1000.0, 3.0),
                                                       ("in", 25.4, 100.0), ("ft", 304.8, 10.0)])
def test_svg_strokes_have_a_physical_width_at_true_scale(units: str, mm_per_unit: float, scale: float,
                                                          tmp_path) -> None:
    """Printed or cut at true scale, outline/bend/mark strokes are 0.25 mm wide and bend dashes
    1..10 mm long, whatever the part's size (the width was 1/800 of the part: 3.75 mm lines on a
    3 m panel, 7.6 mm on the 6 m demo plate)."""
    pat = unroll(CurvePairRuledSurface(quarter(scale / 3, 0.0), quarter(2 * scale / 3, scale / 2)), rulings=5,
                 units=units)
    root = ET.parse(pat.export_svg(tmp_path / "p.svg")).getroot()
    ns = {"s": "http://www.w3.org/2000/svg"}
    view_w = float(root.get("viewBox").split()[2])
    width = float(root.get("width").rstrip("minc"))
    unit = root.get("width").lstrip("0123456789.e+-")
    mm_per_user = width * {"mm": 1.0, "cm": 10.0, "in": 25.4}[unit] / view_w  # true scale: = mm_per_unit
    assert mm_per_user == pytest.approx(mm_per_unit, rel=1e-7)
    groups = {g.get("id"): g for g in root.findall("s:g", ns)}
    for layer in ("OUTLINE", "BEND", "MARKS"):
        assert float(groups[layer].get("stroke-width")) * mm_per_user == pytest.approx(0.25, rel=1e-3), layer
    dash = [float(x) * mm_per_user for x in groups["BEND"].get("stroke-dasharray").split(",")]
    assert 1.0 * (1 - 1e-5) <= dash[0] <= 10.0 * (1 + 1e-5) and dash[1] == pytest.approx(dash[0] / 2, rel=1e-5), dash


def test_edge_marks_of_a_narrow_panel_stay_inside_it() -> None:
    """A 1-unit-wide strip joined to a 15.7-unit-wide one: the edge-mark label of each panel lies
    inside that panel and its ticks and text are scaled to it (the marks were sized for the widest
    panel: the narrow strip's "E1" sat 0.94 units inward, outside its 1-unit width)."""
    from ght_cad.pattern.flat_pattern import _inside

    s1 = CurvePairRuledSurface(quarter(10.0, 0.0), quarter(10.0, 10.0))  # ends at the ruling (0, 10, z)
    b = GHTCurve([(0, 10, 0), (-0.5, 10, 0), (-1.0, 9.95, 0)])
    t = GHTCurve([(0, 10, 10), (-0.5, 10, 10), (-1.0, 9.95, 10)])
    pat = unroll_composite([s1, CurvePairRuledSurface(b, t)], rulings=3)
    for panel in pat.panels:
        loops = panel.loop_polylines()
        lo, hi = panel.bbox()
        small = float(np.min(hi - lo))
        marks = [(x, y, h) for x, y, s, h in panel.texts if s == "E1"]
        assert len(marks) == 1, panel.texts
        x, y, h = marks[0]
        assert _inside(np.array([[x, y]]), loops)[0], (panel.label, x, y, lo, hi)
        assert h <= 0.25 * small, (panel.label, h, small)
        for m in panel.marks:
            assert np.linalg.norm(m[1] - m[0]) <= 0.25 * small + 1e-12


def test_dxf_r12_labels_keep_non_ascii_text(tmp_path) -> None:
    """R12 (no ezdxf) with a label "Düse ø20": the file is pure ASCII with DXF \\U+XXXX escapes and
    reads back as the same text (it was written as UTF-8 and read as cp1252: "DÃ¼se Ã¸20")."""
    pat = unroll(CurvePairRuledSurface(quarter(1.0, 0.0), quarter(2.0, 1.5)), rulings=2, units="mm")
    x, y, _, h = pat.panels[0].texts[0]
    pat.panels[0].texts[0] = (x, y, "Düse ø20", h)
    text = pat.dxf_r12_text()
    text.encode("ascii")  # raises if not pure ASCII
    path = tmp_path / "u.dxf"
    path.write_text(text, encoding="ascii")
    doc = ezdxf.readfile(path)
    assert "Düse ø20" in [ezdxf.decode_dxf_unicode(t.dxf.text) for t in doc.modelspace().query("TEXT")]


# ---------------------------------------------------------------------------------------------
# DXF/SVG for CAM (issue 25): lines and arcs exact, other curves within the chord tolerance
# ---------------------------------------------------------------------------------------------
EXAMPLES = __import__("pathlib").Path(__file__).resolve().parent.parent / "examples"


@pytest.fixture(scope="module")
def readme_cone() -> FlatPattern:
    """The README Quickstart's exact quarter cone frustum from control planes, unrolled."""
    from ght_cad import developable_from_planes

    cone = developable_from_planes([(-400, 1, 0, 0.5), (-400, 1, 1, 0.5), (-400, 0, 1, 0.5)],
                                   [(0, 0, 0, 1), (-400, 0, 0, 1)], gamma=-1)
    return unroll(cone)


def _write(pat: FlatPattern, version: str, path, **kw):
    if version == "R12":
        path.write_text(pat.dxf_r12_text(**kw))
        return path
    return pat.export_dxf(path, **kw)


@pytest.mark.parametrize("version", ["R2010", "R12"])
def test_readme_cone_dxf_corners_arcs_and_area_exact(readme_cone: FlatPattern, version: str, tmp_path) -> None:
    """The README cone's DXF (R2010 through ezdxf, R12 by the own writer): one closed outline of 4
    vertices = the development's corners map(u, v), (u, v) in {0, 1}², to 1e-9; its two rails are
    arcs (bulges) whose radii are the slant radii ρ2 = √(400² + 800²), ρ1 = ρ2/2 to 1e-12 and the
    two rulings straight; the area measured on ezdxf's path is the annular sector's
    ½ φ (ρ2² - ρ1²), φ = (π/2) 400/ρ2, to 1e-9 (measured 1.9e-14)."""
    from dxf_read import entity_area, outline_entities

    (ent,) = outline_entities(_write(readme_cone, version, tmp_path / "cone.dxf"))
    assert ent.dxftype() == ("POLYLINE" if version == "R12" else "LWPOLYLINE") and ent.is_closed
    pts, bulges = outline_vertices(ent), outline_bulges(ent)
    corners = readme_cone.map(np.array([0.0, 1.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0, 1.0]))
    assert np.max(np.abs(pts - corners)) <= 1e-9
    rho2 = math.hypot(400.0, 800.0)
    rho1, phi = rho2 / 2, (math.pi / 2) * 400.0 / rho2
    assert bulges[1] == bulges[3] == 0.0
    for k, rho in ((0, rho2), (2, rho1)):  # edge a (z = 0, the larger circle), edge b reversed
        L = float(np.linalg.norm(pts[(k + 1) % 4] - pts[k]))
        theta = 4 * math.atan(bulges[k])
        assert abs(theta) == pytest.approx(phi, rel=1e-12)
        assert L / (2 * math.sin(abs(theta) / 2)) == pytest.approx(rho, rel=1e-12)
    exact = 0.5 * phi * (rho2**2 - rho1**2)
    assert entity_area(ent) == pytest.approx(exact, rel=1e-9)
    assert svg_outline_areas(readme_cone.svg_text())[0] == pytest.approx(exact, rel=1e-9)


@pytest.fixture(scope="module")
def hopper_pattern() -> FlatPattern:
    from ght_cad.app.design import build_surfaces, load_design, unroll_surfaces

    return unroll_surfaces(build_surfaces(load_design(EXAMPLES / "design_hopper_transition.toml")))


@pytest.mark.slow
@pytest.mark.parametrize("chord_tol", [1e-3, 0.1])
def test_hopper_outline_within_chord_tolerance(hopper_pattern: FlatPattern, chord_tol: float, tmp_path) -> None:
    """The hopper (rails loft: its rails develop to curves that are neither lines nor arcs): every
    point of every exact flat edge (4,001 per edge) lies within chord_tol of the written arcs;
    the rulings are single lines; R2010, R12 and SVG files give the exact flat area to 1e-7 at
    the default 1e-3 mm (measured 7.6e-9 with 81 segments; the former 4,096-point polyline was
    2.4e-7 short) and within chord_tol × perimeter at 0.1 mm, with fewer arcs at 0.1 than at 1e-3."""
    from dxf_read import dxf_outline_areas
    from test_outline_arcs import chain_distance

    panel = hopper_pattern.panels[0]
    (pts, bulges, kinds), = panel.loop_arcs(chord_tol)
    assert kinds == ["curve", "line", "curve", "line"]
    closed = np.concatenate([pts, pts[:1]])
    t = np.linspace(0.0, 1.0, 4001)
    for e in panel.loops[0]:
        q = e.flat_fn(t) + panel.offset
        assert chain_distance(q, closed, bulges).max() <= chord_tol, e.name
    perimeter = sum(e.length_flat for e in panel.loops[0])
    exact = hopper_pattern.area
    areas = [dxf_outline_areas(_write(hopper_pattern, v, tmp_path / f"{v}.dxf", chord_tol=chord_tol))[0]
             for v in ("R2010", "R12")]
    areas.append(svg_outline_areas(hopper_pattern.svg_text(chord_tol=chord_tol))[0])
    for a in areas:
        assert abs(a - exact) <= (1e-7 * exact if chord_tol == 1e-3 else chord_tol * perimeter)
    if chord_tol == 0.1:
        assert bulges.size < len(panel.loop_arcs(1e-3)[0][1])


@pytest.mark.slow
def test_cli_chord_tol(hopper_pattern: FlatPattern, tmp_path, capsys) -> None:
    """``ght-cad unroll DESIGN --dxf --svg --chord-tol 0.1`` (and ``export``) writes the outline of that tolerance
    (the vertices of :meth:`FlatPattern.outline_arcs`); ``--chord-tol 0`` is refused (exit 2, one
    line naming the option)."""
    from ght_cad.app.cli import main

    from dxf_read import outline_entities

    design = str(EXAMPLES / "design_hopper_transition.toml")
    assert main(["unroll", design, "--dxf", str(tmp_path / "h.dxf"), "--svg", str(tmp_path / "h.svg"),
                 "--chord-tol", "0.1"]) == 0
    (ent,) = outline_entities(tmp_path / "h.dxf")
    (pts, bulges), = hopper_pattern.outline_arcs(0.1)
    np.testing.assert_allclose(outline_bulges(ent), bulges, rtol=1e-12, atol=1e-15)
    assert svg_outline_areas(tmp_path / "h.svg")[0] == pytest.approx(
        dxf_outline_areas(tmp_path / "h.dxf")[0], rel=1e-9)
    assert main(["export", design, str(tmp_path / "e.dxf"), "--chord-tol", "0.1"]) == 0
    (ent,) = outline_entities(tmp_path / "e.dxf")
    np.testing.assert_allclose(outline_bulges(ent), bulges, rtol=1e-12, atol=1e-15)
    capsys.readouterr()
    assert main(["unroll", design, "--dxf", str(tmp_path / "z.dxf"), "--chord-tol", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--chord-tol" in err[0]
    assert not (tmp_path / "z.dxf").exists()
    with pytest.raises(GHTError, match="chord_tol"):
        hopper_pattern.svg_text(chord_tol=-1.0)
