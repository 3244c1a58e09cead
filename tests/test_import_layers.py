"""Import direction of the layered package (issue 27): every module of ``ght_cad`` in a layer package.

Every import of every module of ``ght_cad`` and of the FreeCAD workbench is read with ``ast``
(function-local imports included: they are the ones that break the layering quietly) and resolved
to a module. Each module has a layer, lowest first:

=========  ====================================================================================
core       ``ght_cad.core``: errors, validation, small vector kernels, quadrature, caches, atomic
           files, output folders, progress, the STEP text guard, worker helpers, the kernel
           registry, the old module paths' import hook
curves     ``ght_cad.curves``: seeds, basis, curves, continuity, composites, analysis, plotting
surfaces   ``ght_cad.surfaces`` (planes, B-splines, NURBS, patches, ruled surfaces),
           ``ght_cad.pattern`` (flat patterns and their writers), ``ght_cad.developables``
           (envelope, tangent, rectifying, canal developables, joints, the rails loft),
           ``ght_cad.unrolling`` (unroll, ruled development, CAD faces) and ``ght_cad.sheetmetal``
           (sheet, plate, joined panels, blanks of bent parts)
optimize   ``ght_cad.optimize`` (optimizers, problems, Pareto, pipeline) and
           ``ght_cad.approximation`` (developable panels for a double-curved target)
kernel     CAD adapters: ``ght_cad.cad`` (OCP/build123d/cadquery)
facade     the package ``ght_cad`` itself: the public namespace re-exports every layer below it,
           the CAD adapters' ``unfold`` included (on first use, so ``import ght_cad`` loads no kernel)
workbench  the FreeCAD workbench (``ght_workbench``: FreeCAD ``Part`` adapters, features, commands):
           a front end on the public ``ght_cad`` namespace, never on the OCP adapters or ``design``
app        ``ght_cad.app`` (CLI, batch, sweeps, demo, STEP unfold, the approximate command; the
           command handlers ``app.commands`` and design files ``app.design``)
=========  ====================================================================================

The surfaces layer holds five packages, not one: ``developables``, ``unrolling`` and
``sheetmetal`` use each other's modules (no module cycle, but package-level ones, e.g. the sheet's
neutral surface in ``unrolling.unroll`` and the ruled development in ``sheetmetal.sheet``).

A module is in the layer of its first package below ``ght_cad`` (:data:`_LAYER_OF`). The old
path of a moved module (``ght_cad.curve``, an alias of the module ``ght_cad.curves.curve`` in
``ght_cad._MOVED``) counts as the module it stands for.

An import may go to the same or a lower layer. The imports that go UP today are listed below as an
explicit allow-list (:data:`ALLOWED_UPWARD`: the kernel hook, and the loft's deprecated aliases of
names that moved up to the optimize layer): a new upward import fails this
test, and so does an entry that no longer exists (remove it: the list only shrinks).

No import cycle is allowed at all, function-local imports included (:func:`test_no_import_cycle`;
the kernel hook is not an edge of it). The failure names every cycle's modules and, for each of
them, one of its imports of another module of the cycle with ``file:line``. Break a cycle the way
the three cycles of before were broken (issue 27): move what both sides use into a module below
both and import it back where it was (the STEP input's parallel faces into
``ght_cad.app.design.step_input`` and the worker helpers into ``ght_cad.core.workers``; the FreeCAD face
reader into ``ght_workbench.face_reader``; the forming rows' presentation into
``ght_cad.pattern.forming`` and the development of one ruled surface into
``ght_cad.unrolling.ruled_development``), not by hiding the import (``importlib``, strings).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import ght_cad
from ght_cad.core._aliases import AliasFinder

ROOT = Path(__file__).resolve().parents[1]
WORKBENCH = ROOT / "freecad_workbench" / "freecad"

LAYERS = ("core", "curves", "surfaces", "optimize", "kernel", "facade", "workbench", "app")

_LAYER_OF = {
    # the layer packages of issue 27; ght_cad/ holds nothing else (test_top_level_holds_only_layer_packages)
    "core": ["core"],
    "curves": ["curves"],
    "surfaces": ["surfaces", "pattern", "developables", "unrolling", "sheetmetal"],
    # the approximation fits and optimizes panels (the dual fit's μ, ν, γ through ght_cad.optimize)
    "optimize": ["optimize", "approximation"],
    "kernel": ["cad"],
    "app": ["app"],
}

#: The core's one way to the kernel layer: ``ght_cad.core._kernel.load_kernel`` imports ``ght_cad.cad``,
#: which registers its adapters with the registry (``to_face``, unrolling a CAD face, STEP output
#: and the like go through ``ght_cad.core._kernel.adapter``). It is the only upward import allowed for
#: good, and it is not an edge of the cycle check (``ght_cad.cad`` importing the registry to fill
#: it is the point of the plug-in).
KERNEL_HOOK = ("ght_cad.core._kernel", "ght_cad.cad")

#: Imports from a lower layer into a higher one that exist today: (importer, imported).
ALLOWED_UPWARD = {
    KERNEL_HOOK,
    # deprecated aliases (a DeprecationWarning on every use; they go in the next minor release):
    # LoftProblem and three more names moved from the loft to the optimize layer in issue 27
    ("ght_cad.developables.loft", "ght_cad.optimize.problems.loft"),
}



# -- reading the imports ---------------------------------------------------------------------------

def modules() -> dict[str, tuple[Path, bool]]:
    """Every module: dotted name -> (file, is a package). Workbench modules keep their import name."""
    out: dict[str, tuple[Path, bool]] = {}
    for base, top in ((ROOT, ROOT / "ght_cad"), (WORKBENCH, WORKBENCH / "ght_workbench")):
        for f in sorted(top.rglob("*.py")):
            parts = list(f.relative_to(base).with_suffix("").parts)
            is_pkg = parts[-1] == "__init__"
            if is_pkg:
                parts = parts[:-1]
            out[".".join(parts)] = (f, is_pkg)
    return out


def imports_of(source: str, name: str, is_pkg: bool, known: set[str]) -> set[str]:
    """The project modules ``source`` (module ``name``) imports, at any depth of the code.

    ``from X import y`` counts as importing ``X.y`` when that is a module, else ``X``; an import
    of a module inside a package counts as the module (not the package). Imports written as
    strings count too: ``importlib.import_module("ght_cad.x")`` and a dict whose values are all
    module paths (the tables of :func:`ght_cad.core._lazy.lazy_getattr`).
    """
    package = name if is_pkg else name.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(source)):
        targets: list[str] = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            mod = from_module(node, package)
            targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in known else mod for a in node.names]
        elif isinstance(node, ast.Call) and _callee(node) == "import_module" and node.args:
            # importlib.import_module("ght_cad.x"): an import written as a string
            if isinstance(node.args[0], ast.Constant) and isinstance(node.args[0].value, str):
                targets = [node.args[0].value]
        elif isinstance(node, ast.Dict) and node.values and all(
                isinstance(v, ast.Constant) and isinstance(v.value, str) and v.value in known for v in node.values):
            # a table of module paths imported on first use ({name: "ght_cad.x"}: core._lazy)
            targets = [v.value for v in node.values]
        for t in targets:
            if t not in known:  # an old path (ght_cad._MOVED) is the module it names now
                t = ALIASES.target(t) or t
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name:
                found.add(t)
    return found


def from_module(node: ast.ImportFrom, package: str) -> str:
    """The absolute module of ``from <module> import ...`` written in ``package`` (relative or not)."""
    if not node.level:
        return node.module or ""
    base = package.split(".")
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _callee(node: ast.Call) -> str:
    f = node.func
    return f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""


def import_graph() -> dict[str, set[str]]:
    mods = modules()
    known = set(mods)
    return {m: imports_of(f.read_text(encoding="utf-8"), m, is_pkg, known) for m, (f, is_pkg) in mods.items()}


#: Old paths of moved modules (issue 27, ``ght_cad._MOVED``): an import of one is an import of the
#: module it names now (the alias hook of ``ght_cad.core._aliases`` makes them one module object).
ALIASES = AliasFinder("ght_cad", ght_cad._MOVED)


def layer(module: str) -> str:
    """The layer of ``module``: by its first package below ``ght_cad``; an old path's is its new one's."""
    module = ALIASES.target(module) or module
    if module == "ght_cad":
        return "facade"
    if module.startswith("ght_workbench"):
        return "workbench"
    first = module.split(".")[1]
    for name, members in _LAYER_OF.items():
        if first in members:
            return name
    raise AssertionError(f"{module} has no layer: add it to _LAYER_OF in tests/test_import_layers.py")


def upward(graph: dict[str, set[str]]) -> set[tuple[str, str]]:
    return {(a, b) for a, deps in graph.items() for b in deps if LAYERS.index(layer(b)) > LAYERS.index(layer(a))}


def cycles(graph: dict[str, set[str]]) -> list[set[str]]:
    """Strongly connected components with more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[set[str]] = []
    counter = 0
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph.get(root, ()))))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter
                    counter += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(graph.get(w, ())))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = set()
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.add(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    out.append(comp)
    return out


# -- the checks on made-up code ---------------------------------------------------------------------

def test_reader_counts_function_local_and_relative_imports() -> None:
    known = {"ght_cad", "ght_cad.errors", "ght_cad.cad", "ght_cad.cad.occ", "ght_cad.design", "ght_cad.design.schema"}
    src = (
        "from .errors import GHTError\n"
        "import numpy as np\n"
        "def f():\n"
        "    from .cad import occ\n"
        "    class C:\n"
        "        def g(self):\n"
        "            import ght_cad.design.schema as s\n"
        "            from .. import something\n"
    )
    assert imports_of(src, "ght_cad.patch", False, known) == {"ght_cad.errors", "ght_cad.cad.occ", "ght_cad.design.schema"}
    assert imports_of("from ..errors import E\nfrom . import schema\n", "ght_cad.design.build", False, known) == {
        "ght_cad.errors", "ght_cad.design.schema"}
    assert imports_of("from . import schema\n", "ght_cad.design", True, known) == {"ght_cad.design.schema"}


def test_reader_counts_imports_written_as_strings() -> None:
    """``importlib.import_module("...")`` and a lazy table ``{name: "module"}`` are imports too (the
    way the facade and the loft's deprecated aliases reach their modules); a dict of other strings
    is not."""
    known = {"ght_cad", "ght_cad.cad", "ght_cad.cad.occ", "ght_cad.optimize", "ght_cad.design"}
    src = (
        "import importlib\n"
        "_T = {'a': 'ght_cad.cad.occ', 'b': 'ght_cad.optimize'}\n"
        "_U = {'a': 'ght_cad.cad.occ', 'b': 'not a module'}\n"
        "def f():\n"
        "    return importlib.import_module('ght_cad.design')\n"
    )
    assert imports_of(src, "ght_cad.loft", True, known) == {"ght_cad.cad.occ", "ght_cad.optimize", "ght_cad.design"}


def test_checks_find_an_upward_import_and_a_cycle() -> None:
    graph = {"ght_cad.curve": {"ght_cad.errors", "ght_cad.cli"}, "ght_cad.cli": {"ght_cad.curve"}, "ght_cad.errors": set()}
    assert upward(graph) == {("ght_cad.curve", "ght_cad.cli")}
    assert cycles(graph) == [{"ght_cad.curve", "ght_cad.cli"}]
    assert cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


# -- the repository ------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def graph() -> dict[str, set[str]]:
    return import_graph()


def test_every_module_has_a_layer(graph: dict[str, set[str]]) -> None:
    assert len(graph) > 60, "the module reader found too few modules"
    for m in graph:
        layer(m)


def test_top_level_holds_only_layer_packages() -> None:
    """``ght_cad/`` is the facade's ``__init__``, the package data and the layer packages of
    :data:`_LAYER_OF`, nothing else: a new module goes into the package of its layer."""
    top = ROOT / "ght_cad"
    packages = sorted(p.name for p in top.iterdir() if (p / "__init__.py").is_file())
    modules = sorted(p.name for p in top.glob("*.py") if p.name != "__init__.py")
    assert modules == [], f"modules at the top of ght_cad/ (move them into a layer package): {modules}"
    assert packages == sorted(n for members in _LAYER_OF.values() for n in members)


def test_no_new_upward_import(graph: dict[str, set[str]]) -> None:
    new = sorted(upward(graph) - ALLOWED_UPWARD)
    assert not new, (
        "imports from a lower layer into a higher one (tests/test_import_layers.py): "
        + "; ".join(f"{a} ({layer(a)}) imports {b} ({layer(b)})" for a, b in new)
    )


def test_allowed_upward_imports_still_exist(graph: dict[str, set[str]]) -> None:
    gone = sorted(ALLOWED_UPWARD - upward(graph))
    assert not gone, f"remove these from ALLOWED_UPWARD, they no longer exist: {gone}"


def without_kernel_hook(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """The graph less the :data:`KERNEL_HOOK` edge (the registry's plug-in point)."""
    return {m: deps - {KERNEL_HOOK[1]} if m == KERNEL_HOOK[0] else deps for m, deps in graph.items()}


def test_the_kernel_hook_is_one_import_in_load_kernel() -> None:
    """``ght_cad._kernel`` imports ``ght_cad.cad`` exactly once, inside ``load_kernel``."""
    mods = modules()
    path, is_pkg = mods[KERNEL_HOOK[0]]
    tree = ast.parse(path.read_text(encoding="utf-8"))

    def to_kernel(node: ast.AST) -> bool:
        return isinstance(node, (ast.Import, ast.ImportFrom)) and KERNEL_HOOK[1] in imports_of(
            ast.unparse(node), KERNEL_HOOK[0], is_pkg, set(mods))

    hooks = [n for n in ast.walk(tree) if to_kernel(n)]
    (load,) = [f for f in ast.walk(tree) if isinstance(f, ast.FunctionDef) and f.name == "load_kernel"]
    assert len(hooks) == 1 and any(n is hooks[0] for n in ast.walk(load)), (
        f"ght_cad._kernel must import ght_cad.cad once, in load_kernel; found at lines {[n.lineno for n in hooks]}")


def import_sites(module: str, targets: set[str], mods: dict[str, tuple[Path, bool]] | None = None) -> list[tuple[str, int]]:
    """The imports in ``module``'s file that import a module of ``targets``: ``(imported, line)``,
    by line (function-local ones included, the kernel hook left out as in the cycle check)."""
    mods = modules() if mods is None else mods
    path, is_pkg = mods[module]
    if module == KERNEL_HOOK[0]:
        targets = targets - {KERNEL_HOOK[1]}
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            out += [(t, node.lineno) for t in sorted(imports_of(ast.unparse(node), module, is_pkg, set(mods)) & targets)]
    return sorted(out, key=lambda s: (s[1], s[0]))


def describe_cycle(comp: set[str], mods: dict[str, tuple[Path, bool]] | None = None, root: Path = ROOT) -> str:
    """A cycle for its failure message: its modules, and per module one import of another module of
    the cycle (the first in the file) with ``file:line``."""
    mods = modules() if mods is None else mods
    lines = [f"cycle of {len(comp)} modules: {', '.join(sorted(comp))}"]
    for m in sorted(comp):
        target, line = import_sites(m, comp - {m}, mods)[0]
        path = mods[m][0]
        where = path.relative_to(root) if path.is_relative_to(root) else path
        lines.append(f"  {m} imports {target} at {where}:{line}")
    return "\n".join(lines)


def test_cycle_message_names_modules_and_import_lines(tmp_path: Path) -> None:
    """Made-up package: a imports b at the top, b imports a inside a function; c is outside the cycle."""
    pkg = tmp_path / "ght_cad"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "a.py").write_text("import math\nfrom .c import x\nfrom .b import y\n")
    (pkg / "b.py").write_text("def f():\n    from . import a\n    return a\n")
    (pkg / "c.py").write_text("x = 1\n")
    mods = {f"ght_cad.{n}": (pkg / f"{n}.py", False) for n in "abc"} | {"ght_cad": (pkg / "__init__.py", True)}
    graph = {m: imports_of(f.read_text(), m, p, set(mods)) for m, (f, p) in mods.items()}
    (comp,) = cycles(graph)
    assert comp == {"ght_cad.a", "ght_cad.b"}
    assert describe_cycle(comp, mods, tmp_path).splitlines() == [
        "cycle of 2 modules: ght_cad.a, ght_cad.b",
        f"  ght_cad.a imports ght_cad.b at {Path('ght_cad/a.py')}:3",
        f"  ght_cad.b imports ght_cad.a at {Path('ght_cad/b.py')}:2",
    ]


def test_no_import_cycle(graph: dict[str, set[str]]) -> None:
    """No import cycle at all, function-local imports included (module doc: how to break one)."""
    found = sorted(sorted(c) for c in cycles(without_kernel_hook(graph)))
    assert not found, (
        "import cycles (function-local imports count; move what both sides use into a module below both, "
        "see tests/test_import_layers.py):\n" + "\n".join(describe_cycle(set(c)) for c in found))


def test_the_freecad_workbench_never_imports_the_ocp_adapters(graph: dict[str, set[str]]) -> None:
    bad = sorted((a, b) for a, deps in graph.items() if a.startswith("ght_workbench")
                 for b in deps if b.startswith("ght_cad.cad"))
    assert not bad, f"the FreeCAD workbench imports OCP adapters: {bad}"
