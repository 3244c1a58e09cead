"""Installation: core-only environments, the STEP product name, the sdist's contents and the CAD
tests in the other OCP world (build123d 0.12 / OCP 7.9 against build123d 0.13 / OCP 8).

A core-only environment (FreeCAD's Python: numpy, scipy, matplotlib, no OCP) is simulated by
``tests/no_kernel/sitecustomize.py``, which makes importing OCP, build123d and cadquery (and with
``GHT_BLOCK_MODULES``, ezdxf) raise ``ModuleNotFoundError`` in a subprocess.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tarfile
from collections.abc import Sequence
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BLOCKER = Path(__file__).resolve().parent / "no_kernel"

# exact quarter cone (spec section 1), no optimization: the DXF/SVG/JSON need no kernel
CONE = """
name = "cone-core"
[surface]
planes = [[-4, 1, 0, 0.5], [-4, 1, 1, 0.5], [-4, 0, 1, 0.5]]
boundary_planes = [[0, 0, 0, 1], [-4, 0, 0, 1]]
gamma = -1.0
normalize = false
[outputs]
files = [{files}]
figures = ["flat_pattern"]
"""


def _core_only(argv: list[str], cwd: Path, blocked: str = "OCP,build123d,cadquery") -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(BLOCKER), str(ROOT)]), GHT_BLOCK_MODULES=blocked)
    return subprocess.run([sys.executable, "-m", "ght_cad.app.cli", *argv], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=300)


def test_blocker_really_blocks(tmp_path: Path) -> None:
    env = dict(os.environ, PYTHONPATH=str(BLOCKER), GHT_BLOCK_MODULES="OCP,build123d,cadquery,ezdxf")
    code = ("import importlib\n"
            "for m in ('OCP', 'build123d', 'cadquery', 'ezdxf', 'OCP.gp'):\n"
            "    try:\n        importlib.import_module(m)\n    except ModuleNotFoundError:\n        print('blocked', m)\n"
            "import ght_cad.cad as c; print('kernel', c.kernel_available())")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60).stdout
    assert out.split("\n")[:6] == ["blocked OCP", "blocked build123d", "blocked cadquery", "blocked ezdxf",
                                   "blocked OCP.gp", "kernel False"]


@pytest.mark.slow
@pytest.mark.parametrize("blocked", ["OCP,build123d,cadquery", "OCP,build123d,cadquery,ezdxf"])
def test_core_only_run_writes_dxf_svg_json(tmp_path: Path, blocked: str) -> None:
    design = tmp_path / "cone.toml"
    design.write_text(CONE.format(files='"dxf", "svg", "json", "md"'))
    res = _core_only(["run", str(design), "--out", str(tmp_path / "out")], tmp_path, blocked)
    assert res.returncode == 0, res.stderr
    out = tmp_path / "out"
    for name in ("flat_pattern.dxf", "flat_pattern.svg", "report.json", "report.md", "flat_pattern.png"):
        assert (out / name).stat().st_size > 0, name
    assert not (out / "model.step").exists()
    report = json.loads((out / "report.json").read_text())
    assert "ght_cad[build123d]" in report["brep"]["skipped"]
    # the exact cone's pattern: relative length/area errors at round-off without any kernel
    assert report["flat_pattern"]["area"] > 0
    dxf = (out / "flat_pattern.dxf").read_text()
    assert "SECTION" in dxf and "OUTLINE" in dxf
    assert "Not built" in (out / "report.md").read_text()


@pytest.mark.parametrize("argv", [["run", "{design}", "--out", "{out}"], ["demo", "--out", "{out}"],
                                  ["export", "{design}", "{out}.step"]])
def test_core_only_kernel_commands_exit_2_naming_the_extra(tmp_path: Path, argv: list[str]) -> None:
    design = tmp_path / "cone.toml"
    design.write_text(CONE.format(files='"step", "dxf"'))
    args = [a.format(design=design, out=tmp_path / "out") for a in argv]
    res = _core_only(args, tmp_path)
    assert res.returncode == 2, (res.returncode, res.stderr)
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "pip install 'ght_cad[build123d]'" in lines[0], res.stderr
    assert "internal failure" not in res.stderr
    assert not (tmp_path / "out" / "model.step").exists()


def test_step_product_is_named_after_the_design(tmp_path: Path) -> None:
    pytest.importorskip("build123d")  # a design run's B-rep
    from ght_cad.app.cli import main
    from ght_cad.cad.occ import read_step_products

    design = tmp_path / "cone.toml"
    design.write_text(CONE.format(files='"step"'))
    assert main(["run", str(design), "--out", str(tmp_path / "out"), "--no-progress"]) == 0
    names = read_step_products(tmp_path / "out" / "model.step")
    assert names and set(names) == {"cone-core"}
    assert "STEP translator" not in (tmp_path / "out" / "model.step").read_text()  # OCCT's default product name


def test_write_step_product_defaults_to_the_file_name(tmp_path: Path) -> None:
    pytest.importorskip("OCP")
    import numpy as np

    from ght_cad.surfaces.bspline import BSplineCurveData
    from ght_cad.cad.occ import make_edge, read_step_products, write_step

    edge = make_edge(BSplineCurveData(np.array([[0.0, 0, 0], [1, 1, 0], [2, 0, 0]]), np.array([0, 0, 0, 1, 1, 1.0]), 2))
    write_step(edge, tmp_path / "bracket-7.step")
    assert read_step_products(tmp_path / "bracket-7.step") == ["bracket-7"]
    write_step(edge, tmp_path / "x.step", product="Bracket 7")
    assert read_step_products(tmp_path / "x.step") == ["Bracket 7"]


#: what the sdist must hold for its tests to run (besides the package)
SDIST_MUST_HOLD = ["LICENSE", "README.md", "DEVELOPERS.md", "pyproject.toml", "tests/conftest.py",
                   "tests/no_kernel/sitecustomize.py", "tests/freecad_launch.py", "examples/design_duct.toml",
                   "examples/build123d_loft.py", "docs/design-files.md", "freecad_workbench/README.md",
                   "freecad_workbench/package.xml", "ght_cad/data/default_design.toml", "bench/bench_unroll.py"]


@pytest.mark.slow
def test_sdist_holds_tests_examples_docs_workbench_and_license(tmp_path: Path) -> None:
    pytest.importorskip("build")
    res = subprocess.run([sys.executable, "-m", "build", "--sdist", "--outdir", str(tmp_path), str(ROOT)],
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    (sdist,) = tmp_path.glob("ght_cad-*.tar.gz")
    with tarfile.open(sdist) as tar:
        names = {n.split("/", 1)[1] for n in tar.getnames() if "/" in n}
    missing = [n for n in SDIST_MUST_HOLD if n not in names]
    assert not missing, missing
    tracked = subprocess.run(["git", "-C", str(ROOT), "ls-files"], capture_output=True, text=True).stdout.split()
    if tracked:  # a git checkout: every tracked test, example, doc and workbench file is in the sdist
        wanted = [t for t in tracked if t.split("/")[0] in ("tests", "examples", "docs", "freecad_workbench", "ght_cad")]
        assert [t for t in wanted if t not in names] == []
    assert not any("__pycache__" in n or n.endswith(".pyc") for n in names)


#: this file's tests that go through OCP (a STEP product name); its other tests block the kernel (the
#: core-only environment) and so run the same way in every world
KERNEL_TESTS_HERE = ["tests/test_install.py::test_step_product_is_named_after_the_design",
                     "tests/test_install.py::test_write_step_product_defaults_to_the_file_name"]
#: the CAD adapter tests run again in the other build123d / OCP world. The rule: only tests whose outcome
#: can depend on the OCP/build123d/cadquery version run there, i.e. those that import a kernel: each file
#: below imports OCP or build123d at module level (without a kernel it skips as a whole), and of this file
#: only KERNEL_TESTS_HERE (its core-only tests block the kernel: repeats of the main run)
OTHER_BUILD123D_TESTS = ["tests/test_cad_curves.py", "tests/test_cad_loft.py", "tests/test_developable_faces.py",
                         "tests/test_unroll_faces.py", "tests/test_step_units.py", "tests/test_sheet_solid.py",
                         *KERNEL_TESTS_HERE]
def _readme_blocks_importing(module: str) -> list[str]:
    """The ids of tests/test_readme_snippets.py's runs of the README blocks that import ``module``
    (the blocks that import no kernel run the same way in the main world)."""
    from test_readme_snippets import BLOCKS

    return [f"tests/test_readme_snippets.py::test_readme_python_block_runs_standalone[{i}]"
            for i, code in enumerate(BLOCKS) if re.search(rf"^\s*(?:import|from) {module}\b", code, flags=re.M)]


#: the tests of the [cadquery] world (cadquery 2.8 on OCP 7.9, no build123d), run there in one pytest run
#: with no mark filter (slow ones included: in the main world, which has no cadquery, they all skip):
#: every test that imports cadquery, among them cadquery's own Workplane tests with the plugin (its sdist,
#: fetched by pip), the cadquery example (in-process and as a program), the README blocks importing
#: cadquery, and the OCP test of this file that needs no build123d
CADQUERY_TESTS = ["tests/test_cq_plugin.py", "tests/test_cq_world.py",
                  "tests/test_install.py::test_write_step_product_defaults_to_the_file_name",
                  "tests/test_examples_scripts.py::test_cadquery_script",
                  "tests/test_examples_scripts.py::test_scripts_run_as_programs[cadquery_script]",
                  "tests/test_sheet_solid.py::test_cadquery_faces_and_solids",
                  "tests/test_host_suites.py::test_cadquery_workplane_tests_with_the_plugin",
                  *_readme_blocks_importing("cadquery")]
TEST_TOOLS = ["pytest>=8", "hypothesis>=6.100", "pytest-timeout>=2.3"]


def _versions(python: Path | str) -> dict[str, str]:
    code = ("import json, importlib.metadata as m\n"
            "out = {}\n"
            "for d in ('build123d', 'cadquery', 'cadquery-ocp', 'cadquery-ocp-novtk'):\n"
            "    try:\n        out[d] = m.version(d)\n    except m.PackageNotFoundError:\n        pass\n"
            "print(json.dumps(out))")
    return json.loads(subprocess.run([str(python), "-c", code], capture_output=True, text=True, check=True).stdout)


def _uv() -> str | None:
    """uv's executable (in ``[test]``), or None."""
    try:
        import uv
    except ImportError:
        return None
    try:
        return uv.find_uv_bin()
    except FileNotFoundError:
        return None


def _pip_indexes() -> list[str]:
    """pip's configured indexes and find-links (pip.conf, ``PIP_*``) as uv options: uv reads no pip.conf.
    ``--index-strategy unsafe-best-match`` is pip's rule: the best version over all the indexes."""
    listing = subprocess.run([sys.executable, "-m", "pip", "config", "list"], capture_output=True, text=True).stdout
    options = {"index-url": "--index-url", "extra-index-url": "--extra-index-url", "find-links": "--find-links"}
    args: list[str] = []
    for line in listing.splitlines():
        key, _, value = line.partition("=")
        option = options.get(key.rsplit(".", 1)[-1])
        if option:
            args += [a for url in value.strip("'\"").split() for a in (option, url)]
    return args + ["--index-strategy", "unsafe-best-match"]


def _venv(name: str, extra: str, first: Sequence[str] = (), more: Sequence[str] = ()) -> Path:
    """``ROOT/name`` (made here and kept, so a second run only checks it): ``first`` installed (the
    world a user had), then ``pip install -e ROOT[extra] *more``, the user's command.

    With uv (in ``[test]``), uv installs ``first`` and every dependency of ``ROOT[extra]`` and ``more``
    beforehand (``-r pyproject.toml --extra``: the same requirement strings, the same indexes, pip's
    best-version rule): parallel downloads, no bytecode compiled up front (measured 12-16 s instead of
    ~80 s of pip per world). pip then resolves the same requirements against what is installed: a
    version it would not keep (a build123d outside ``[build123d]``) it would replace, and the tests'
    version assertions would see it; it builds and installs the project itself."""
    venv = ROOT / name
    python = venv / "bin" / "python"
    uv = _uv()
    if not python.exists():
        cmd = [uv, "venv", "-q", "--seed", "--python", sys.executable] if uv else [sys.executable, "-m", "venv"]
        subprocess.run([*cmd, str(venv)], check=True, timeout=300)
    pip = [str(python), "-m", "pip", "install", "-q"]
    project = [*pip, "-e", f"{ROOT}[{extra}]", *more]
    if uv:
        steps = [[uv, "pip", "install", "-q", "--python", str(python), *_pip_indexes(), *first,
                  "-r", str(ROOT / "pyproject.toml"), "--extra", extra, *more], project]
    else:
        steps = [[*pip, *first], project] if first else [project]
    for args in steps:
        res = subprocess.run(args, capture_output=True, text=True, timeout=1800)
        assert res.returncode == 0, res.stderr[-3000:]
    return python


def _pytest_in(python: Path, files: list[str], marks: str = "not slow") -> str:
    res = subprocess.run([str(python), "-m", "pytest", "-q", "-p", "no:cacheprovider", "-m", marks, "-rs", *files],
                         cwd=ROOT, capture_output=True, text=True, timeout=2400)
    tail = res.stdout[-4000:]
    assert res.returncode == 0, tail
    return tail


@pytest.mark.slow
@pytest.mark.timeout(3600)
def test_cad_tests_pass_with_the_other_build123d() -> None:
    """The suite runs on what ``[test]`` resolves to (build123d 0.13 / OCP 8 on a fresh machine);
    here the CAD adapter tests run again with the other one (0.12 / OCP 7.9), installed first and
    kept by ``pip install -e '.[test]'`` (``.venv-build123d-0.12``, one OCP distribution)."""
    here = _versions(sys.executable).get("build123d", "")
    if not here:
        pytest.skip("build123d is not installed here")
    other = "0.12" if here.startswith("0.13") else "0.13"
    python = _venv(f".venv-build123d-{other}", "test", first=[f"build123d=={other}.*"])
    there = _versions(python)
    assert there["build123d"].startswith(other) and "cadquery-ocp" not in there, there
    assert there["cadquery-ocp-novtk"].startswith("7.9" if other == "0.12" else "8."), there
    tail = _pytest_in(python, OTHER_BUILD123D_TESTS)
    assert " passed" in tail


@pytest.mark.freecad
def test_core_and_run_in_debian_freecad_python(tmp_path: Path) -> None:
    """FreeCAD's Python for real (Debian 12: /usr/bin/python3 with python3-numpy 1.24, scipy 1.10,
    matplotlib 3.6, no ezdxf, no OCP): ``ght-cad run`` writes DXF/SVG/JSON; a STEP output exits 2."""
    py = "/usr/bin/python3"
    probe = subprocess.run([py, "-s", "-c", "import numpy, scipy, matplotlib; print(numpy.__version__)"],
                           capture_output=True, text=True) if os.path.exists(py) else None
    if probe is None or probe.returncode != 0:
        pytest.skip("no Debian python3 with numpy/scipy/matplotlib (apt-get install freecad-python3)")
    env = {k: v for k, v in os.environ.items() if k not in ("VIRTUAL_ENV", "PYTHONHOME")}
    env["PYTHONPATH"] = str(ROOT)
    design = tmp_path / "cone.toml"
    design.write_text(CONE.format(files='"dxf", "svg", "json"'))
    res = subprocess.run([py, "-s", "-m", "ght_cad.app.cli", "run", str(design), "--out", str(tmp_path / "out"), "--no-progress"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    for name in ("flat_pattern.dxf", "flat_pattern.svg", "report.json"):
        assert (tmp_path / "out" / name).stat().st_size > 0, name
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert "skipped" in report["brep"] and report["flat_pattern"]["area"] > 0
    design.write_text(CONE.format(files='"step", "dxf"'))
    res = subprocess.run([py, "-s", "-m", "ght_cad.app.cli", "run", str(design), "--out", str(tmp_path / "out2")],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert res.returncode == 2 and "pip install 'ght_cad[build123d]'" in res.stderr, res.stderr
