"""Launching Debian's FreeCAD (freecadcmd, the GUI under Xvfb) from pytest: shared by the workbench tests."""

from __future__ import annotations

import os
import signal
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
WB = REPO / "freecad_workbench"


def freecad_env(tmp_path: Path, pythonpath: bool = True) -> dict[str, str]:
    """Environment for a FreeCAD process: its own HOME in ``tmp_path``, no venv variables, and
    (with ``pythonpath``) the workbench and this process's ght_cad on PYTHONPATH."""
    env = dict(os.environ)
    home = tmp_path / "home"
    home.mkdir(exist_ok=True)
    env["HOME"] = str(home)  # FreeCAD's user config goes here, not into the real home
    env["GHT_FC_OUT"] = str(tmp_path)
    env.pop("PYTHONHOME", None)
    env.pop("VIRTUAL_ENV", None)
    if pythonpath:
        # the very ght_cad this pytest process imports, so both sides run the same core code
        import ght_cad

        core = Path(ght_cad.__file__).resolve().parents[1]
        env["PYTHONPATH"] = os.pathsep.join(dict.fromkeys([str(WB), str(core), str(REPO)]))
    else:
        env.pop("PYTHONPATH", None)
    return env


def xvfb_run(*cmd: str) -> list[str]:
    """``xvfb-run`` for a FreeCAD GUI run on a virtual screen. ``-a`` looks for a free display from
    the ``-n`` given before it (xvfb-run reads its options in order); each pytest-xdist worker starts its search at its own number (99, 119, ...), so two GUI
    tests started at the same moment by two workers never race for the same display's lock."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    index = int(worker[2:]) if worker[2:].isdigit() else 0
    return ["xvfb-run", "-n", str(99 + 20 * index), "-a", "-s", "-screen 0 1280x1024x24", *cmd]


def run_process(cmd: list[str], env: dict[str, str], cwd: Path, timeout: float) -> subprocess.CompletedProcess:
    """Run in a new session; on timeout kill the whole process group (FreeCAD, Xvfb) and fail."""
    proc = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        pytest.fail(f"{cmd[0]} timed out after {timeout} s:\n{(out + err)[-4000:]}")
    return subprocess.CompletedProcess(cmd, proc.returncode, out, err)


def summary(proc: subprocess.CompletedProcess) -> str:
    """The last 80 non-blank output lines of a FreeCAD run, for assertion messages."""
    lines = [l for l in (proc.stdout + proc.stderr).splitlines() if l.strip() and not l.startswith("  #")]
    return "\n".join(lines[-80:])


def assert_no_traceback(out: str) -> None:
    """No Python traceback in a FreeCAD run's output: the workbench reports refused input (a failed
    recompute) as one line, and a deliberately provoked one is captured inside the test."""
    lines = [l for l in out.splitlines() if "Traceback (most recent call last)" in l or l.startswith("<class '")]
    assert not lines, f"{len(lines)} traceback line(s) in FreeCAD's output:\n" + "\n".join(out.splitlines()[-80:])


def run_fc_unittest(module: str, tmp_path: Path, min_tests: int, timeout: float = 120) -> str:
    """Run ``freecadcmd -t module`` and assert it ran at least ``min_tests`` tests, all OK and none
    skipped, and printed no Python traceback (:func:`assert_no_traceback`); return its whole output
    (stdout + stderr)."""
    import re

    from conftest import freecadcmd_or_skip

    exe = freecadcmd_or_skip()
    proc = run_process([exe, "-t", module], freecad_env(tmp_path), tmp_path, timeout)
    out = proc.stdout + proc.stderr
    assert proc.returncode == 0, summary(proc)
    ran = re.search(r"Ran (\d+) tests?", out)
    assert ran and int(ran.group(1)) >= min_tests, summary(proc)
    assert re.search(r"^OK\s*$", out, re.M) and not re.search(r"^FAILED \(", out, re.M), summary(proc)
    assert "skipped=" not in out, summary(proc)
    assert_no_traceback(out)
    return out
