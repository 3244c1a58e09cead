"""The layer packages of issue 27: every moved module keeps its old import path, as the same object.

A module moved into ``ght_cad.core`` / ``ght_cad.curves`` / ``ght_cad.surfaces`` leaves a shim at
its old file that puts the moved module into ``sys.modules`` under the old name: both names give
one module object, so monkeypatching either name patches the module that the code uses, class
identity (``isinstance``, ``except``) is unchanged and module-level caches and registries exist
once. ``ght_cad._MOVED`` lists the moves; the shims on disk must be exactly those.
"""

from __future__ import annotations

import importlib
import json
import subprocess
import sys
from pathlib import Path

import pytest

import ght_cad

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "ght_cad"
MOVED = sorted(ght_cad._MOVED.items())


def shim_files() -> set[str]:
    """Names of the top-level modules of ``ght_cad`` that are shims of a moved module."""
    return {p.stem for p in PACKAGE.glob("*.py") if "sys.modules[__name__] = _module" in p.read_text(encoding="utf-8")}


def test_the_moves_table_matches_the_shims_on_disk() -> None:
    assert shim_files() == set(ght_cad._MOVED)
    for old, new in MOVED:
        layer_package, name = new.split(".")[1:]
        assert name == old, f"{old} -> {new}: a move keeps the module's name"
        assert (PACKAGE / layer_package / f"{name}.py").is_file(), new
        text = (PACKAGE / f"{old}.py").read_text(encoding="utf-8")
        assert f"from .{layer_package} import {name} as _module" in text and new in text, text


@pytest.mark.parametrize(("old", "new"), MOVED, ids=[o for o, _ in MOVED])
def test_old_path_is_the_same_module(old: str, new: str) -> None:
    moved = importlib.import_module(new)
    assert importlib.import_module(f"ght_cad.{old}") is moved
    assert sys.modules[f"ght_cad.{old}"] is moved and moved.__name__ == new
    if old != "basis":  # ght_cad.basis is the stable function basis() of spec section 9
        assert getattr(ght_cad, old) is moved
    public = [n for n in vars(moved) if not n.startswith("__")]
    assert public, new
    namespace: dict[str, object] = {}
    exec(f"from ght_cad.{old} import {public[0]} as x", namespace)  # noqa: S102  (the old import statement)
    assert namespace["x"] is getattr(moved, public[0])


def test_facade_basis_stays_the_function_after_importing_the_old_module_path() -> None:
    """``import ght_cad.basis`` in a fresh interpreter must not replace the function ``ght_cad.basis``.

    As before the move, ``import ght_cad.basis as b`` binds the package attribute, which is the
    function basis (spec section 9); the module is ``sys.modules["ght_cad.basis"]``.
    """
    code = (
        "import json, sys, ght_cad, ght_cad.basis, ght_cad.curves.basis as m; import ght_cad.basis as b; "
        "from ght_cad.basis import _compact_differences; "
        "print(json.dumps([b is ght_cad.basis is m.basis, sys.modules['ght_cad.basis'] is m, "
        "_compact_differences is m._compact_differences]))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=ROOT)
    assert json.loads(out.stdout) == [True, True, True]


def test_monkeypatching_the_old_path_patches_the_moved_module(monkeypatch: pytest.MonkeyPatch) -> None:
    old = importlib.import_module("ght_cad._kernel")
    new = importlib.import_module("ght_cad.core._kernel")
    monkeypatch.setattr("ght_cad._kernel._ADAPTERS", {"marker": print})
    assert new._ADAPTERS == {"marker": print} and old._ADAPTERS is new._ADAPTERS
    from ght_cad.core.errors import GHTError
    from ght_cad.errors import GHTError as OldGHTError

    assert OldGHTError is GHTError


def test_python_m_old_cli_path_still_runs_the_command_line() -> None:
    """``python -m ght_cad.cli`` (the shim run as ``__main__``) runs ``main`` as before the move."""
    if ght_cad._MOVED.get("cli") is None:
        pytest.skip("ght_cad.cli has not moved")
    for module in ("ght_cad.cli", ght_cad._MOVED["cli"]):
        out = subprocess.run([sys.executable, "-m", module, "--version"], capture_output=True, text=True, cwd=ROOT)
        assert out.returncode == 0 and out.stdout.strip() == f"ght-cad {ght_cad.__version__}", (module, out)


def test_console_entry_point_names_the_moved_cli() -> None:
    """pyproject's ``ght-cad`` entry point names the module that defines ``main``."""
    import tomllib

    target = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["scripts"]["ght-cad"]
    module, _, function = target.partition(":")
    main = getattr(importlib.import_module(module), function)
    assert callable(main) and main.__module__ == module, target
