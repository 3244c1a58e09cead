"""The layer packages of issue 27: every moved module keeps its old import path, as the same object.

``ght_cad._MOVED`` lists the moves (old name relative to ``ght_cad`` -> new dotted path). One import
hook, :class:`ght_cad.core._aliases.AliasFinder` (installed first on ``sys.meta_path`` by
``ght_cad/__init__``), answers an old path with the moved module itself, and an old package's
submodule ``ght_cad.<old>.<sub>`` with ``<new>.<sub>``: both names give one module object, so
monkeypatching either name patches the module that the code uses, class identity (``isinstance``,
``except``, pickles) is unchanged and module-level caches and registries exist once; the module
keeps its new ``__name__`` and ``__spec__``. No file is left at an old path.

These tests import the old paths on purpose (the compatibility they check); code in ``ght_cad/``,
``freecad_workbench/``, ``examples/`` and the documentation's python blocks must import the new
paths (:func:`test_no_code_imports_an_old_path`).
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import json
import pickle
import re
import subprocess
import sys
from pathlib import Path

import pytest

import ght_cad
from ght_cad.core._aliases import AliasFinder
from tests.test_import_layers import from_module

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "ght_cad"
MOVED = sorted(ght_cad._MOVED.items())
FINDER = AliasFinder("ght_cad", ght_cad._MOVED)
#: Names of the facade that are also old module paths: ``from ght_cad import unroll`` is the public
#: callable (spec section 9), not an old-path import.
PUBLIC = set(ght_cad.__all__)


def run(code: str) -> list:
    """``code`` in a fresh interpreter (the repository's ``ght_cad``); its one printed JSON line."""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout)


# -- the table and the hook ------------------------------------------------------------------------

def test_the_alias_hook_is_first_on_the_meta_path() -> None:
    """First, so that a submodule of an old package name is never found again through the package's
    ``__path__`` by the path finder (it would be a second module object)."""
    (hook,) = [f for f in sys.meta_path if isinstance(f, AliasFinder)]
    assert sys.meta_path.index(hook) < min(sys.meta_path.index(f) for f in sys.meta_path
                                           if getattr(f, "__name__", "") == "PathFinder" or type(f).__name__ == "PathFinder")
    assert hook.table is ght_cad._MOVED


@pytest.mark.parametrize(("old", "new"), MOVED, ids=[o for o, _ in MOVED])
def test_every_move_names_a_module_and_leaves_no_file(old: str, new: str) -> None:
    """The new path is a real module (not itself an old path); nothing is left at the old path."""
    assert FINDER.target(f"ght_cad.{old}") == new
    assert FINDER.target(new) is None, f"{old} -> {new}, which is itself an old path"
    spec = importlib.util.find_spec(new)
    assert spec is not None and spec.origin and Path(spec.origin).is_file(), new
    rel = Path(*old.split("."))
    assert not (PACKAGE / rel.with_suffix(".py")).exists() and not list((PACKAGE / rel).glob("*.py")), (
        f"ght_cad/{rel}: a file at an old path would shadow the move {old} -> {new}")


def test_finder_maps_names_and_package_prefixes() -> None:
    finder = AliasFinder("pkg", {"a": "pkg.x.a", "b.c": "pkg.y", "loft": "pkg.dev.loft"})
    assert finder.target("pkg.a") == "pkg.x.a"
    assert finder.target("pkg.loft.rails.sub") == "pkg.dev.loft.rails.sub"
    assert finder.target("pkg.b.c.d") == "pkg.y.d" and finder.target("pkg.b") is None
    assert finder.target("pkg.ab") is None and finder.target("pkg.lofted") is None  # whole names only
    assert finder.target("other.a") is None and finder.target("pkg") is None


@pytest.mark.parametrize(("old", "new"), MOVED, ids=[o for o, _ in MOVED])
def test_old_path_is_the_same_module(old: str, new: str) -> None:
    moved = importlib.import_module(new)
    assert importlib.import_module(f"ght_cad.{old}") is moved
    assert sys.modules[f"ght_cad.{old}"] is moved and moved.__name__ == new
    assert moved.__spec__.name == new and moved.__spec__.origin == moved.__file__
    if old != "basis":  # ght_cad.basis is the stable function basis() of spec section 9
        assert getattr(ght_cad, old) is moved
    public = [n for n in vars(moved) if not n.startswith("__")]
    assert public, new
    namespace: dict[str, object] = {}
    exec(f"from ght_cad.{old} import {public[0]} as x", namespace)  # noqa: S102  (the old import statement)
    assert namespace["x"] is getattr(moved, public[0])


def test_old_path_first_keeps_the_new_name_and_spec() -> None:
    """Imported by its old path first, in a fresh interpreter: the module still names itself by its
    new path (the machinery sets ``__spec__`` to the alias spec while loading; the hook restores it)."""
    got = run(
        "import json, sys, importlib, importlib.util\n"
        "import ght_cad.flat_pattern as old\n"
        "new = sys.modules['ght_cad.pattern.flat_pattern']\n"
        "again = importlib.reload(old)\n"
        "print(json.dumps([old is new is again, old.__name__, old.__spec__.name, old.__spec__.origin == old.__file__,\n"
        "                  old.__file__.endswith('pattern/flat_pattern.py'), old.FlatPattern.__module__,\n"
        "                  importlib.util.find_spec('ght_cad.flat_pattern').name]))\n")
    assert got == [True, "ght_cad.pattern.flat_pattern", "ght_cad.pattern.flat_pattern", True, True,
                   "ght_cad.pattern.flat_pattern", "ght_cad.pattern.flat_pattern"]


def test_old_package_prefix_maps_its_submodules(monkeypatch: pytest.MonkeyPatch) -> None:
    """An old package name (here a made-up one for ``ght_cad.pattern``) maps every submodule to the
    module under the new package: one object, never loaded a second time from the package's path."""
    monkeypatch.setitem(ght_cad._MOVED, "zz_old_pattern", "ght_cad.pattern")
    for name in ("ght_cad.zz_old_pattern", "ght_cad.zz_old_pattern.model", "ght_cad.zz_old_pattern.io",
                 "ght_cad.zz_old_pattern.io.svg"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    import ght_cad.pattern.model as model
    import ght_cad.zz_old_pattern.model as old_model

    assert old_model is model and sys.modules["ght_cad.zz_old_pattern.model"] is model
    assert importlib.import_module("ght_cad.zz_old_pattern") is importlib.import_module("ght_cad.pattern")
    new_svg = importlib.import_module("ght_cad.zz_old_pattern.io.svg")  # imported by its old name first
    assert new_svg is sys.modules["ght_cad.pattern.io.svg"] and new_svg.__name__ == "ght_cad.pattern.io.svg"
    with pytest.raises(ModuleNotFoundError, match="zz_old_pattern.no_such"):
        importlib.import_module("ght_cad.zz_old_pattern.no_such")
    for name in [n for n in sys.modules if n.startswith("ght_cad.zz_old_pattern")]:
        monkeypatch.delitem(sys.modules, name)


def test_old_package_submodule_first_is_loaded_once() -> None:
    """Every submodule of a moved package, imported by its old path first in a fresh interpreter,
    is the one module of the new path (one object per file in sys.modules)."""
    packages = {old: new for old, new in MOVED if (PACKAGE.parent / Path(*new.split("."))).is_dir()}
    if not packages:
        pytest.skip("no package has moved")
    subs = sorted(f"ght_cad.{old}.{p.stem}" for old, new in packages.items()
                  for p in (PACKAGE.parent / Path(*new.split("."))).glob("[!_]*.py"))
    got = run(
        "import json, sys, importlib\n"
        f"subs = {subs!r}\n"
        "mods = [importlib.import_module(s) for s in subs]\n"
        "files = [m.__file__ for m in set(sys.modules.values()) if getattr(m, '__file__', None)]\n"
        "print(json.dumps([len(files) == len(set(files)), [m.__name__ for m in mods],\n"
        "                  [m is sys.modules[m.__name__] for m in mods]]))\n")
    assert got == [True, [FINDER.target(s) for s in subs], [True] * len(subs)]


def test_facade_basis_stays_the_function_after_importing_the_old_module_path() -> None:
    """``import ght_cad.basis`` in a fresh interpreter must not replace the function ``ght_cad.basis``.

    As before the move, ``import ght_cad.basis as b`` binds the package attribute, which is the
    function basis (spec section 9); the module is ``sys.modules["ght_cad.basis"]``.
    """
    assert run(
        "import json, sys, ght_cad, ght_cad.basis, ght_cad.curves.basis as m; import ght_cad.basis as b; "
        "from ght_cad.basis import _compact_differences; "
        "print(json.dumps([b is ght_cad.basis is m.basis, sys.modules['ght_cad.basis'] is m, "
        "_compact_differences is m._compact_differences]))") == [True, True, True]


def test_facade_unroll_is_the_callable_module_by_every_path() -> None:
    assert run(
        "import json, sys, ght_cad.unroll as a, ght_cad; from ght_cad import unroll as b; "
        "import ght_cad.unrolling.unroll as c; "
        "print(json.dumps([a is b is c is ght_cad.unroll is sys.modules['ght_cad.unroll'], callable(a), a.__name__]))"
    ) == [True, True, "ght_cad.unrolling.unroll"]


def test_monkeypatching_the_old_path_patches_the_moved_module(monkeypatch: pytest.MonkeyPatch) -> None:
    old = importlib.import_module("ght_cad._kernel")
    new = importlib.import_module("ght_cad.core._kernel")
    monkeypatch.setattr("ght_cad._kernel._ADAPTERS", {"marker": print})
    assert new._ADAPTERS == {"marker": print} and old._ADAPTERS is new._ADAPTERS
    from ght_cad.core.errors import GHTError
    from ght_cad.errors import GHTError as OldGHTError

    assert OldGHTError is GHTError


def test_pickles_and_isinstance_across_old_and_new_paths() -> None:
    """A pickle naming the old module path loads the one class; new pickles name the new path."""
    from ght_cad.core.errors import ShapeParameterError
    from ght_cad.curves.seeds import GHTSeed
    from ght_cad.seeds import GHTSeed as OldSeed

    seed = OldSeed(0.3, -0.6, 0.2)
    assert b"ght_cad.curves.seeds" in pickle.dumps(seed)
    data = pickle.dumps(seed, protocol=0)  # text opcodes: the module path can be replaced in place
    assert b"ght_cad.curves.seeds\n" in data
    back = pickle.loads(data.replace(b"ght_cad.curves.seeds\n", b"ght_cad.seeds\n"))
    assert type(back) is GHTSeed and isinstance(back, OldSeed) and (back.mu, back.nu, back.gamma) == (0.3, -0.6, 0.2)
    err = pickle.loads(pickle.dumps(ShapeParameterError("mu = 7 is outside [-1, 1]"), protocol=0).replace(
        b"ght_cad.core.errors\n", b"ght_cad.errors\n"))
    assert type(err) is ShapeParameterError and str(err) == "mu = 7 is outside [-1, 1]"


def test_python_m_old_cli_path_still_runs_the_command_line() -> None:
    """``python -m ght_cad.cli`` (runpy takes the moved module's code from the hook) runs ``main``."""
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


def test_the_alias_hook_is_stdlib_only() -> None:
    """``import ght_cad`` stays fast: the hook's module imports the standard library only."""
    tree = ast.parse((PACKAGE / "core" / "_aliases.py").read_text(encoding="utf-8"))
    roots = {a.name.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    roots |= {n.module.split(".")[0] for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module and not n.level}
    assert roots <= set(sys.stdlib_module_names) | {"__future__"}, roots


# -- no code of the repository imports an old path ---------------------------------------------------

def old_paths_in(source: str, module: str | None = None, is_pkg: bool = False) -> list[tuple[int, str]]:
    """``(line, old path)`` for every use of an old module path in python ``source``.

    ``module`` is the dotted name of the file (for relative imports; None outside the package).
    Counted: ``import ght_cad.<old>``, ``from ght_cad.<old> import x``, ``from ght_cad import
    <old>`` and ``ght_cad.<old>`` as an attribute (except the facade's public names, e.g. the
    callable ``unroll``), relative imports that land on an old path, and strings that are a dotted
    old path (``importlib.import_module("ght_cad.<old>")``, lazy tables).
    """
    package = (module if is_pkg else module.rpartition(".")[0]) if module else ""
    found: list[tuple[int, str]] = []

    def check(line: int, name: str) -> None:
        if FINDER.target(name) is not None:
            found.append((line, name))

    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            for a in node.names:
                check(node.lineno, a.name)
        elif isinstance(node, ast.ImportFrom):
            mod = from_module(node, package)
            check(node.lineno, mod)
            if mod == "ght_cad":
                for a in node.names:
                    if a.name not in PUBLIC:
                        check(node.lineno, f"ght_cad.{a.name}")
        elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "ght_cad":
            if node.attr not in PUBLIC:
                check(node.lineno, f"ght_cad.{node.attr}")
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and re.fullmatch(
                r"ght_cad(\.\w+)+", node.value):
            check(node.lineno, node.value)
    return sorted(found)


def python_files() -> list[tuple[Path, str | None, bool]]:
    """Every python file that must use the new paths: (file, module name or None, is a package)."""
    out: list[tuple[Path, str | None, bool]] = []
    for f in sorted(PACKAGE.rglob("*.py")):
        parts = list(f.relative_to(ROOT).with_suffix("").parts)
        is_pkg = parts[-1] == "__init__"
        out.append((f, ".".join(parts[:-1] if is_pkg else parts), is_pkg))
    for top in ("freecad_workbench", "examples", "bench"):
        out += [(f, None, False) for f in sorted((ROOT / top).rglob("*")) if f.suffix in (".py", ".FCMacro")]
    return out


def doc_blocks() -> list[tuple[Path, int, str]]:
    """The python blocks of the documentation: (file, first line, code)."""
    out = []
    for doc in [ROOT / "README.md", ROOT / "DEVELOPERS.md", *sorted((ROOT / "docs").rglob("*.md")),
                ROOT / "freecad_workbench" / "README.md"]:
        text = doc.read_text(encoding="utf-8")
        for m in re.finditer(r"^```python\n(.*?)^```", text, flags=re.S | re.M):
            out.append((doc, text.count("\n", 0, m.start(1)) + 1, m.group(1)))
    return out


def test_no_code_imports_an_old_path() -> None:
    """New code imports the new paths (README "Layout"); the old ones are for users' code."""
    bad = []
    for f, module, is_pkg in python_files():
        try:
            hits = old_paths_in(f.read_text(encoding="utf-8"), module, is_pkg)
        except SyntaxError:
            continue
        bad += [f"{f.relative_to(ROOT)}:{line}: {name} -> {FINDER.target(name)}" for line, name in hits]
    for doc, first, code in doc_blocks():
        try:
            hits = old_paths_in(code)
        except SyntaxError:
            continue
        bad += [f"{doc.relative_to(ROOT)}:{first + line - 1}: {name} -> {FINDER.target(name)}" for line, name in hits]
    for doc in [ROOT / "README.md", ROOT / "DEVELOPERS.md", *sorted((ROOT / "docs").rglob("*.md")),
                ROOT / "freecad_workbench" / "README.md"]:
        text = doc.read_text(encoding="utf-8")
        for m in re.finditer(r"-m (ght_cad(?:\.\w+)+)", text):
            if FINDER.target(m.group(1)) is not None:
                bad.append(f"{doc.relative_to(ROOT)}:{text.count(chr(10), 0, m.start()) + 1}: python -m {m.group(1)}")
    assert not bad, "old module paths (import the new ones, ght_cad._MOVED):\n" + "\n".join(bad)


def test_the_old_path_check_finds_each_kind_of_use() -> None:
    src = (
        "import ght_cad.curve\n"
        "from ght_cad.flat_pattern import FlatPattern\n"
        "from ght_cad import unroll, basis, plotting\n"
        "import ght_cad\n"
        "x = ght_cad.sheet.make_sheet\n"
        "y = ght_cad.GHTCurve\n"
        "def f():\n"
        "    import importlib\n"
        "    return importlib.import_module('ght_cad.cli')\n"
        "_LAZY = {'z': 'ght_cad.curves.curve', 'w': 'ght_cad.seeds'}\n"
    )
    assert old_paths_in(src) == [
        (1, "ght_cad.curve"), (2, "ght_cad.flat_pattern"), (3, "ght_cad.plotting"), (5, "ght_cad.sheet"),
        (9, "ght_cad.cli"), (10, "ght_cad.seeds")]
    # relative imports resolve against the importing module
    assert old_paths_in("from ..curve import GHTCurve\nfrom ..curves.curve import GHTCurve\n",
                        "ght_cad.cad.loft") == [(1, "ght_cad.curve")]
    assert old_paths_in("from . import errors\n", "ght_cad", True) == [(1, "ght_cad.errors")]
