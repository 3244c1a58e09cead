"""Every python block of the README runs on its own (a fresh interpreter per block, in an empty
folder): no block may lean on names from an earlier one. Blocks that need FreeCAD are skipped.

One runner process imports numpy and build123d (third-party, about 2 s of the start of every block
that uses build123d) and forks a child per block: each child is the interpreter as a fresh one would
be after those two imports (no ght_cad module loaded, no names defined), runs its block in its own
empty folder with new globals, and exits; its exit status and stderr are the block's result. Where
``os.fork`` does not exist every block gets its own ``python -c`` as before.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCKS = re.findall(r"^```python\n(.*?)^```", (ROOT / "README.md").read_text(), flags=re.S | re.M)
FREECAD = re.compile(r"^\s*(import FreeCAD|from FreeCAD|import Part\b|import FreeCADGui)", flags=re.M)
OPTIONAL = re.compile(r"^\s*(?:import|from) (build123d|cadquery)\b", flags=re.M)

#: the runner: ``argv[1]`` a JSON list of [code, folder]; prints a JSON list of exit statuses
RUNNER = r"""
import json, os, sys, traceback
import numpy, build123d  # noqa: F401  (preloaded for every child; third-party only)
jobs = json.loads(sys.argv[1])
codes = []
for i, (code, folder) in enumerate(jobs):
    sys.stdout.flush(); sys.stderr.flush()
    pid = os.fork()
    if pid == 0:
        rc = 0
        try:
            os.chdir(folder)
            for fd, name in ((1, "stdout.txt"), (2, "stderr.txt")):
                os.dup2(os.open(name, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644), fd)
            sys.argv = ["-c"]
            exec(compile(code, "<string>", "exec"), {"__name__": "__main__", "__builtins__": __builtins__})
        except SystemExit as e:
            rc = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
        except BaseException:
            traceback.print_exc()
            rc = 1
        finally:
            sys.stdout.flush(); sys.stderr.flush()
            os._exit(rc)
    _, status = os.waitpid(pid, 0)
    codes.append(os.waitstatus_to_exitcode(status))
print(json.dumps(codes))
"""


def _skip_reason(code: str) -> str | None:
    if FREECAD.search(code):
        return "needs FreeCAD"
    for module in OPTIONAL.findall(code):
        if importlib.util.find_spec(module) is None:
            return f"could not import {module!r}"
    return None


@pytest.fixture(scope="module")
def block_runs(tmp_path_factory) -> dict[int, tuple[int, str]]:
    """``{index: (exit status, stderr)}`` of every block that can run here, each in its own folder."""
    jobs = {}
    for i, code in enumerate(BLOCKS):
        if _skip_reason(code) is None:
            jobs[i] = (code, str(tmp_path_factory.mktemp(f"readme{i}")))
    if not hasattr(os, "fork") or importlib.util.find_spec("build123d") is None:
        out = {}
        for i, (code, folder) in jobs.items():
            run = subprocess.run([sys.executable, "-c", code], cwd=folder, capture_output=True, text=True, timeout=600)
            out[i] = (run.returncode, run.stderr)
        return out
    run = subprocess.run([sys.executable, "-c", RUNNER, json.dumps(list(jobs.values()))],
                         cwd=tmp_path_factory.mktemp("readme_runner"),
                         capture_output=True, text=True, timeout=600 * max(1, len(jobs)))
    assert run.returncode == 0, run.stderr[-3000:]
    codes = json.loads(run.stdout.strip().splitlines()[-1])
    return {i: (rc, (Path(folder) / "stderr.txt").read_text()) for (i, (_, folder)), rc in zip(jobs.items(), codes)}


def test_the_readme_has_python_blocks():
    assert len(BLOCKS) >= 4


@pytest.mark.slow
@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs_standalone(index, block_runs):
    code = BLOCKS[index]
    reason = _skip_reason(code)
    if reason:
        pytest.skip(reason)
    rc, stderr = block_runs[index]
    assert rc == 0, f"README python block {index} failed:\n{code}\n{stderr[-3000:]}"
