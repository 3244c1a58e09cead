"""The core's kernel dispatch (``ght_cad.core._kernel``, issue 27): the kernel-free core reaches the CAD
adapters through a registry that ``ght_cad.cad`` fills, never through imports of its own."""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ght_cad.core import _kernel
from ght_cad.core.errors import GHTError

ROOT = Path(__file__).resolve().parents[1]
BLOCKER = Path(__file__).resolve().parent / "no_kernel"


def _run(code: str, blocked: bool = False) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    if blocked:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(BLOCKER), env.get("PYTHONPATH", "")]))
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, env=env, timeout=120)


def test_import_ght_cad_registers_nothing_and_loads_no_kernel() -> None:
    out = _run(
        "import sys, json, ght_cad, ght_cad.core._kernel as k; "
        "print(json.dumps([sorted(k.registered()), sorted(m for m in sys.modules "
        "if m.split('.')[0] in ('OCP', 'build123d', 'cadquery', 'matplotlib') or m.startswith('scipy.optimize') "
        "or m.startswith('ght_cad.cad'))]))"
    )
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout) == [[], []]


def test_asking_for_an_adapter_loads_the_adapters_but_no_kernel() -> None:
    """The registered adapters import their module (and OCP) only when called."""
    out = _run(
        "import sys, json, ght_cad.core._kernel as k; f = k.adapter('developable_face'); "
        "print(json.dumps([f.__name__, sorted(k.registered()), 'ght_cad.cad' in sys.modules, "
        "sorted(m for m in sys.modules if m.split('.')[0] in ('OCP', 'build123d', 'cadquery'))]))"
    )
    assert out.returncode == 0, out.stderr
    name, ops, cad_loaded, kernels = json.loads(out.stdout)
    assert name == "developable_face" and ops == sorted(_kernel.OPERATIONS) and cad_loaded and kernels == []


def test_unknown_operation_and_bad_adapter_are_refused() -> None:
    with pytest.raises(GHTError, match=r"kernel operation 'to_mesh' is not allowed; known operations: .*make_face"):
        _kernel.adapter("to_mesh")
    with pytest.raises(GHTError, match="kernel operation 'x' is not allowed"):
        _kernel.register_adapter("x", print)
    with pytest.raises(GHTError, match="the adapter for 'make_face' must be callable, got int"):
        _kernel.register_adapter("make_face", 3)


def test_nothing_registered_names_the_extra_to_install(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(_kernel, "_ADAPTERS", {})
    monkeypatch.setattr(_kernel, "load_kernel", lambda: None)  # a kernel layer that registers nothing
    with pytest.raises(GHTError, match=r"no CAD kernel adapter is registered for 'unroll_face' .*"
                                       r"pip install 'ght_cad\[build123d\]'"):
        _kernel.adapter("unroll_face")


def test_the_core_calls_whatever_is_registered(monkeypatch: pytest.MonkeyPatch) -> None:
    """to_face of a developable and of a patch, and the unroll of a foreign face, go through the registry."""
    from ght_cad import GHTSurface, developable_from_planes, unroll
    from ght_cad.surfaces.bspline import BSplineSurfaceData

    _kernel.load_kernel()
    calls: list[tuple[str, object]] = []
    monkeypatch.setattr(_kernel, "_ADAPTERS", dict(_kernel.registered()))
    _kernel.register_adapter("developable_face", lambda s, tol=None, **kw: calls.append(("developable_face", s)) or "F")
    _kernel.register_adapter("make_face", lambda data: calls.append(("make_face", data)) or "P")
    _kernel.register_adapter("shape_faces", lambda shape: [shape])
    _kernel.register_adapter("unroll_face", lambda face, **kw: calls.append(("unroll_face", face)) or "U")

    dev = developable_from_planes([(-1, 1, 0, 0), (-1, 1, 1, 0), (-1, 0, 1, 0)], [(0, 0, 0, 1), (-2, 0, 0, 1)], gamma=-1)
    assert dev.to_face() == "F" and calls[-1] == ("developable_face", dev)
    patch = GHTSurface([[(0, 0, 0), (1, 0, 1), (2, 0, 0)], [(0, 1, 0), (1, 1, 1), (2, 1, 0)], [(0, 2, 0), (1, 2, 1), (2, 2, 0)]])
    assert patch.to_face(tol=1e-3) == "P"
    assert isinstance(calls[-1][1], BSplineSurfaceData) and calls[-1][1].max_deviation <= 1e-3

    class ForeignFace:  # looks like a build123d face to the dispatch
        wrapped = None

    face = ForeignFace()
    assert unroll(face) == "U" and calls[-1] == ("unroll_face", face)
    assert len(calls) == 3


def test_every_adapter_names_a_function_of_ght_cad_cad() -> None:
    import ght_cad.cad as cad

    assert set(cad.ADAPTERS) == set(_kernel.OPERATIONS)
    if not cad.kernel_available():
        pytest.skip("build123d/OCP not installed: the adapter modules cannot be imported")
    for op, (module, name) in cad.ADAPTERS.items():
        assert callable(getattr(importlib.import_module(f"ght_cad.cad.{module}"), name)), op
        assert f"ght_cad.cad.{module}.{name}" in _kernel.OPERATIONS[op]


def test_without_a_kernel_to_face_raises_the_kernels_module_not_found_error() -> None:
    """As before the registry: the missing kernel module's ModuleNotFoundError, which the CLI and
    the design runs recognise (ght_cad.cad.is_missing_kernel)."""
    out = _run(
        "import json\n"
        "from ght_cad import developable_from_planes\n"
        "from ght_cad.cad import is_missing_kernel\n"
        "d = developable_from_planes([(-1, 1, 0, 0), (-1, 1, 1, 0), (-1, 0, 1, 0)], [(0, 0, 0, 1), (-2, 0, 0, 1)], gamma=-1)\n"
        "try:\n"
        "    d.to_face()\n"
        "except ModuleNotFoundError as exc:\n"
        "    print(json.dumps([exc.name.split('.')[0], is_missing_kernel(exc)]))\n",
        blocked=True,
    )
    assert out.returncode == 0, out.stderr
    top, missing = json.loads(out.stdout)
    assert top in ("OCP", "build123d", "cadquery") and missing is True


def test_registered_is_a_copy() -> None:
    reg = _kernel.registered()
    reg["make_face"] = np.sum
    assert _kernel.registered().get("make_face") is not np.sum
