"""Host hygiene: build123d's and cadquery's own tests give the same outcome per test with ght_cad's
adapters imported, and build123d's clean/history/algebra tests also inside ``exact_edges()``.

The host tests come from the source release matching the installed version (``pip download
<pkg>==<version> --no-deps --no-binary :all:`` into a cache folder at test time; nothing of them is
in this repository). Without network (or with ``GHT_CAD_HOST_SUITES=off``) the tests skip. Cache:
``$GHT_CAD_HOST_CACHE`` or ``~/.cache/ght_cad/host-suites``.

cadquery 2.8's sdist ships its test modules without ``tests/__init__.py`` (their ``BaseTest`` and
``toTuple``): :data:`CQ_TESTS_INIT` is our own stand-in for the two names test_workplanes uses.
"""

from __future__ import annotations

import importlib.metadata
import json
import os
import subprocess
import sys
import tarfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow

HERE = Path(__file__).resolve().parent
PLUGINS = HERE / "host_suites"

BUILD123D_MODULES = ["tests/test_direct_api/test_clean_method.py", "tests/test_direct_api/test_history.py",
                     "tests/test_algebra.py"]
CADQUERY_MODULES = ["tests/test_workplanes.py"]

CQ_TESTS_INIT = '''"""ght_cad's stand-in for the helpers cadquery's test modules import (not in its sdist)."""
import unittest


def toTuple(v):
    return tuple(v.toTuple()) if hasattr(v, "toTuple") else tuple(v)


class BaseTest(unittest.TestCase):
    def assertTupleAlmostEquals(self, expected, actual, places, msg=None):
        for i, j in zip(actual, expected):
            self.assertAlmostEqual(i, j, places, msg=msg)
'''


def _cache() -> Path:
    return Path(os.environ.get("GHT_CAD_HOST_CACHE", Path.home() / ".cache" / "ght_cad" / "host-suites"))


def host_tests(package: str) -> Path:
    """The folder holding ``<package>``'s source release (its ``tests/`` extracted), or skip."""
    if os.environ.get("GHT_CAD_HOST_SUITES") == "off":
        pytest.skip("GHT_CAD_HOST_SUITES=off")
    pytest.importorskip(package)
    version = importlib.metadata.version(package)
    root = _cache() / f"{package}-{version}"
    done = root / ".extracted"
    if not done.exists():
        root.mkdir(parents=True, exist_ok=True)
        sdists = list(root.glob(f"{package}-{version}.tar.gz"))
        if not sdists:
            try:
                out = subprocess.run(
                    [sys.executable, "-m", "pip", "download", f"{package}=={version}", "--no-deps",
                     "--no-binary", ":all:", "-q", "-d", str(root)],
                    capture_output=True, text=True, timeout=600,
                )
            except subprocess.TimeoutExpired:
                pytest.skip(f"pip download {package}=={version} timed out (offline?)")
            sdists = list(root.glob(f"{package}-{version}.tar.gz"))
            if out.returncode != 0 or not sdists:
                pytest.skip(f"cannot download the {package} {version} source release (offline?): {out.stderr.strip()[-300:]}")
        with tarfile.open(sdists[0]) as tar:
            members = [m for m in tar.getmembers() if "/tests/" in m.name and m.isreg()]
            tar.extractall(root, members=members, filter="data")
        src = root / f"{package}-{version}"
        if package == "cadquery" and not (src / "tests" / "__init__.py").exists():
            (src / "tests" / "__init__.py").write_text(CQ_TESTS_INIT)
        done.write_text(version)
    src = root / f"{package}-{version}"
    if not (src / "tests").is_dir():
        pytest.skip(f"the {package} {version} source release has no tests/")
    return src


def outcomes(src: Path, modules: list[str], plugins: list[str | None], tmp: Path) -> list[dict[str, str]]:
    """Per session (one per entry of ``plugins``: None = plain) and test id: passed, failed, error or
    skipped. All sessions run one after the other in one fresh interpreter
    (``host_suites/run_sessions.py``: the host is imported once); a plain session must come first
    and runs before anything of ght_cad is imported."""
    xmls = [tmp / f"{plugin or 'plain'}.xml" for plugin in plugins]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(PLUGINS), str(src)]))
    args = [sys.executable, str(PLUGINS / "run_sessions.py"), json.dumps([[str(x), p] for x, p in zip(xmls, plugins)]),
            "-q", "-p", "no:cacheprovider", "-p", "no:randomly", "--rootdir", str(src), "-o", "addopts=", "-W", "default"]
    run = subprocess.run(args + [str(src / m) for m in modules], cwd=src, env=env, capture_output=True, text=True,
                         timeout=1800)
    results = []
    for xml, plugin in zip(xmls, plugins):
        if not xml.exists():
            raise AssertionError(f"pytest did not run ({plugin}): {run.stdout[-1500:]} {run.stderr[-1500:]}")
        out: dict[str, str] = {}
        for case in ET.parse(xml).getroot().iter("testcase"):
            kinds = {c.tag for c in case}
            out[f"{case.get('classname')}::{case.get('name')}"] = (
                "failed" if "failure" in kinds else "error" if "error" in kinds else "skipped" if "skipped" in kinds else "passed")
        results.append(out)
    return results


def _differences(base: dict[str, str], other: dict[str, str]) -> list[str]:
    return [f"{k}: {base.get(k)} -> {other.get(k)}" for k in sorted(set(base) | set(other)) if base.get(k) != other.get(k)]


def test_build123d_clean_history_algebra_tests_inside_exact_edges_and_with_the_plugin(tmp_path):
    """Same outcome per test: plain, with ght_cad's adapters imported, and every test inside
    ``exact_edges()`` (history merged, "Unable to clean" warned, nested SkipClean respected)."""
    src = host_tests("build123d")
    plugins = ["ght_plugin_imported", "ght_plugin_exact_edges"]
    base, *others = outcomes(src, BUILD123D_MODULES, [None, *plugins], tmp_path)
    assert len(base) >= 100, sorted(base)[:5]
    for plugin, other in zip(plugins, others):
        assert _differences(base, other) == [], plugin


def test_cadquery_workplane_tests_with_the_plugin(tmp_path):
    src = host_tests("cadquery")
    base, other = outcomes(src, CADQUERY_MODULES, [None, "ght_plugin_imported"], tmp_path)
    assert len(base) >= 15 and list(base.values()).count("passed") >= 15, base
    assert _differences(base, other) == []
