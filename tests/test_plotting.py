"""PNG figures: fixed pixel sizes, atomic writes, validation, no matplotlib at core import."""

from __future__ import annotations

import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ght_cad import GHTCurve
from ght_cad.core.errors import GHTError
from ght_cad.curves.plotting import (
    SIZES,
    plot_basis,
    plot_convergence,
    plot_curvature,
    plot_curve,
    plot_flat_pattern,
    plot_surface,
)
from ght_cad.surfaces.ruled import CurvePairRuledSurface


def png_size(path: Path) -> tuple[int, int]:
    """(width, height) from the IHDR chunk of a PNG file."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG"
    assert data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def no_leftovers(folder: Path) -> None:
    assert not [p.name for p in folder.iterdir() if p.name.endswith(".part")]


def test_core_import_does_not_import_matplotlib() -> None:
    code = "import sys, ght_cad, ght_cad.curves.plotting; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("degree,derivative", [(2, 0), (5, 1), (3, 3)])
def test_plot_basis_size(tmp_path: Path, degree: int, derivative: int) -> None:
    p = plot_basis(tmp_path / "b.png", degree, [(0, 0, -1), (0.5, -0.5, 0), (1, 1, 1)], derivative=derivative)
    assert png_size(p) == SIZES["basis"] == (1200, 800)
    assert p.stat().st_size > 10_000
    no_leftovers(tmp_path)


@pytest.mark.parametrize(
    "params,match",
    [([(1.2, 0, 0)], "mu=1.2"), ([(0, 0, float("nan"))], "gamma"), ([], "empty"), ([(0, 0)], "triple")],
)
def test_plot_basis_rejects_bad_params(tmp_path: Path, params, match: str) -> None:
    with pytest.raises(GHTError, match=match):
        plot_basis(tmp_path / "b.png", 3, params)
    assert not list(tmp_path.iterdir())


def test_plot_basis_rejects_degree_1(tmp_path: Path) -> None:
    with pytest.raises(GHTError, match="degree=1"):
        plot_basis(tmp_path / "b.png", 1)


@pytest.mark.parametrize(
    "points",
    [[(0, 0), (1, 2), (3, 2), (4, 0)], [(0, 0, 0), (1, 2, 1), (3, 2, 0), (4, 0, 1)], [(0, 0, 0, 1), (1, 1, 0, 1), (2, 0, 1, 0)]],
)
def test_plot_curve_and_curvature_sizes(tmp_path: Path, points) -> None:
    c = GHTCurve(points, mu=0.3, nu=-0.2, gamma=0.1)
    assert png_size(plot_curve(c, tmp_path / "c.png")) == SIZES["curve"]
    assert png_size(plot_curve(c, tmp_path / "c2.png", show_polygon=False)) == SIZES["curve"]
    assert png_size(plot_curvature(c, tmp_path / "k.png")) == SIZES["curvature"]
    no_leftovers(tmp_path)


def test_surface_pattern_convergence_sizes(tmp_path: Path) -> None:
    c = GHTCurve([(0, 0, 0), (1, 2, 1), (3, 2, 0), (4, 0, 1)])
    s = CurvePairRuledSurface(c, c.translated([0, 0, 2]))
    assert png_size(plot_surface(s, tmp_path / "s.png")) == SIZES["surface"]
    outline = np.array([[0, 0], [3, 0], [3, 1], [0, 1]], float)
    assert png_size(plot_flat_pattern([outline], tmp_path / "f.png", rulings=[outline[:2]])) == SIZES["flat_pattern"]
    # panel names and edge marks are drawn too, and change the picture
    plain = (tmp_path / "f.png").read_bytes()
    marked = plot_flat_pattern([outline], tmp_path / "g.png", rulings=[outline[:2]],
                               labels=[(0.5, 0.5, "P1"), (0.9, 0.1, "E1")], marks=[outline[:2] + 0.05])
    assert png_size(marked) == SIZES["flat_pattern"] and marked.read_bytes() != plain
    assert png_size(plot_convergence({"pso": [3, 2, 1], "gwo": [3, 1, 0.5]}, tmp_path / "cv.png")) == SIZES["convergence"]


def test_failed_plot_keeps_existing_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A writer that dies half-way leaves the old file intact and no temporary file behind."""
    from matplotlib.figure import Figure

    target = tmp_path / "c.png"
    target.write_bytes(b"old")

    def broken_savefig(self, fname, **kw):
        Path(fname).write_bytes(b"\x89PNG half")
        raise OSError("disk full")

    monkeypatch.setattr(Figure, "savefig", broken_savefig)
    with pytest.raises(OSError, match="disk full"):
        plot_curve(GHTCurve([(0, 0), (1, 1), (2, 0)]), target)
    assert target.read_bytes() == b"old"
    no_leftovers(tmp_path)


def test_joined_curves_in_one_figure(tmp_path: Path) -> None:
    from ght_cad.curves.continuity import join

    a = GHTCurve([(0, 0, 0), (1, 2, 0), (3, 2, 1), (4, 0, 1)], gamma=-0.5)
    b = join(a, "G2", GHTCurve([(0, 0, 0), (0, 0, 0), (0, 0, 0), (7, 1, 2)], mu=0.2))
    assert png_size(plot_curve([a, b], tmp_path / "c.png")) == SIZES["curve"]
    assert png_size(plot_curvature([a, b], tmp_path / "k.png")) == SIZES["curvature"]
    with pytest.raises(GHTError, match="no curve"):
        plot_curve([], tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def test_plot_basis_refuses_a_degree_too_large_to_draw(tmp_path) -> None:
    """degree 100000 drew 800,000 matplotlib lines (the command ran for minutes); above
    MAX_PLOT_DEGREE the plot is refused naming the value and the allowed range, nothing written."""
    from ght_cad.core.errors import GHTError
    from ght_cad.curves.plotting import MAX_PLOT_DEGREE, plot_basis

    assert MAX_PLOT_DEGREE >= 20
    with pytest.raises(GHTError, match=rf"degree=100000 .*2\.\.{MAX_PLOT_DEGREE}"):
        plot_basis(tmp_path / "b.png", 100000)
    assert not list(tmp_path.iterdir())
