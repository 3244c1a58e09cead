"""STEP files declare the length unit of the model, and keep its coordinates."""

from __future__ import annotations

import re

import pytest

pytest.importorskip("build123d")

from build123d import Box  # noqa: E402
from OCP.Bnd import Bnd_Box  # noqa: E402
from OCP.BRepBndLib import BRepBndLib  # noqa: E402

from ght_cad.cad.occ import read_step, write_step  # noqa: E402
from ght_cad.core.errors import GHTError  # noqa: E402


def _extent(shape) -> tuple[float, ...]:
    box = Bnd_Box()
    BRepBndLib.Add_s(shape, box)
    lo, hi = box.CornerMin(), box.CornerMax()  # (OCP 8's Bnd_Box.Get returns a struct pybind11 cannot convert)
    return (hi.X() - lo.X(), hi.Y() - lo.Y(), hi.Z() - lo.Z())


@pytest.mark.parametrize(
    "units, declared, mm",
    [("mm", r"SI_UNIT\(\.MILLI\.,\.METRE\.\)", 1.0), ("m", r"SI_UNIT\(\$,\.METRE\.\)", 1000.0),
     ("cm", r"SI_UNIT\(\.CENTI\.,\.METRE\.\)", 10.0), ("in", r"'INCH'", 25.4)],
)
def test_declared_unit_and_coordinates(tmp_path, units: str, declared: str, mm: float) -> None:
    path = tmp_path / f"box_{units}.step"
    write_step(Box(1, 2, 3), path, units=units)
    text = path.read_text(errors="replace")
    assert re.search(declared, text), f"{units}: unit not declared"
    assert "CARTESIAN_POINT('',(-0.5,-1.,-1.5))" in text  # coordinates written as given
    # OCCT reads into millimetres: the extent scales by mm per unit
    ext = _extent(read_step(path))
    for got, want in zip(ext, (1.0 * mm, 2.0 * mm, 3.0 * mm)):
        assert got == pytest.approx(want, rel=1e-6)
    # the session default is restored: the next plain write is in mm again
    write_step(Box(1, 1, 1), tmp_path / "after.step")
    assert re.search(r"SI_UNIT\(\.MILLI\.,\.METRE\.\)", (tmp_path / "after.step").read_text(errors="replace"))


def test_unknown_unit_is_refused_and_nothing_written(tmp_path) -> None:
    with pytest.raises(GHTError, match=r"units='furlong' is not a STEP length unit; allowed: mm, cm, m, in, ft"):
        write_step(Box(1, 1, 1), tmp_path / "x.step", units="furlong")
    assert not (tmp_path / "x.step").exists()


def test_design_step_declares_the_design_units_and_reads_back_at_true_size(tmp_path) -> None:
    """``units = "ft"``: ``ght-cad export`` writes a STEP declaring feet (docs/design-files.md said
    "declares millimetres whatever units says"); unrolled from the STEP file, the pattern is in ft
    with the design pattern's area (1e-7 relative: certified B-spline face), and in mm it is that
    area times 304.8²."""
    import json
    from pathlib import Path

    from ght_cad.app.cli import main

    root = Path(__file__).resolve().parents[1]
    design = (root / "examples" / "design_duct.toml").read_text().replace('units = "mm"', 'units = "ft"')
    assert 'units = "ft"' in design
    toml = tmp_path / "duct ft.toml"
    toml.write_text(design)
    step, rep = tmp_path / "d.step", tmp_path / "r.json"
    assert main(["export", str(toml), str(step), str(rep)]) == 0
    assert "'FOOT'" in step.read_text()
    area = json.loads(rep.read_text())["flat_pattern"]["area"]
    for units, scale in (("ft", 1.0), ("mm", 304.8**2)):
        out = tmp_path / f"u_{units}.json"
        import contextlib
        import io

        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            assert main(["unroll", str(step), "--units", units, "--json"]) == 0
        res = json.loads(buf.getvalue())
        assert res["units"] == units and abs(res["area"] / (area * scale) - 1) < 1e-7, (units, res["area"], area)
    assert "declares millimetres whatever" not in (root / "docs" / "design-files.md").read_text()
