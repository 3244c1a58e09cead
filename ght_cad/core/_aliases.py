"""Old module paths of moved modules (issue 27): one import hook instead of a shim file per move.

:func:`install` puts an :class:`AliasFinder` at the front of :data:`sys.meta_path`. For a table
``{old: new}`` (``ght_cad._MOVED``: ``old`` relative to the package, ``new`` a full dotted path) it
answers ``import <package>.<old>`` with the module ``<new>`` itself, and ``<package>.<old>.<rest>``
with ``<new>.<rest>`` (an old *package* prefix maps every submodule). The import machinery then
keeps that one module object under both names in :data:`sys.modules`, so:

- ``import ght_cad.curve`` / ``from ght_cad.curve import GHTCurve`` give the objects of
  ``ght_cad.curves.curve``: monkeypatching either name patches the module the code uses; classes
  (``isinstance``, ``except``, pickles naming the old path), caches and registries exist once;
- the module keeps its own ``__name__``, ``__spec__``, ``__file__`` (the new path): the machinery
  sets ``__spec__`` to the alias spec while loading, :meth:`AliasLoader.exec_module` restores it;
- a submodule of an aliased package is never loaded twice: the finder runs before the path finder,
  which would otherwise find ``ght_cad.loft.rails`` again through the package's ``__path__``;
- ``python -m ght_cad.cli`` runs the moved module as ``__main__`` (runpy asks the loader for
  :meth:`AliasLoader.get_code`; the spec's ``parent`` is the new module's, so its relative imports
  resolve).

Numpy-free and cheap (stdlib ``importlib`` only): ``import ght_cad`` stays fast.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
from types import CodeType, ModuleType
from typing import Mapping, Sequence


class _AliasSpec(importlib.machinery.ModuleSpec):
    """The spec of an old name: its ``parent`` is the new module's, for ``python -m <old>``."""

    def __init__(self, name: str, loader: "AliasLoader", target: importlib.machinery.ModuleSpec) -> None:
        super().__init__(name, loader, origin=target.origin)
        self.target = target

    @property
    def parent(self) -> str:  # type: ignore[override]
        return self.target.parent or ""


class AliasLoader(importlib.abc.Loader):
    """Loads an old name as the module at its new path (imported, or taken from sys.modules)."""

    def __init__(self, target: str) -> None:
        self.target = target
        self.spec: importlib.machinery.ModuleSpec | None = None

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        module = importlib.import_module(self.target)
        self.spec = module.__spec__  # the machinery overwrites it next: exec_module puts it back
        return module

    def exec_module(self, module: ModuleType) -> None:
        # importlib._bootstrap._init_module_attrs always sets module.__spec__ to the alias spec;
        # the module stays the new path's (its __name__, __loader__, __file__ are left alone).
        module.__spec__ = self.spec

    def get_code(self, fullname: str) -> CodeType | None:
        """The new module's code (what runpy executes for ``python -m <old name>``)."""
        spec = importlib.util.find_spec(self.target)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "get_code"):
            raise ImportError(f"{fullname} is {self.target}, which has no code to run", name=fullname)
        return spec.loader.get_code(self.target)  # type: ignore[union-attr]

    def is_package(self, fullname: str) -> bool:
        spec = importlib.util.find_spec(self.target)
        return bool(spec is not None and spec.submodule_search_locations is not None)


class AliasFinder(importlib.abc.MetaPathFinder):
    """Maps ``<package>.<old>[.<rest>]`` to ``<table[old]>[.<rest>]`` (the longest old prefix wins).

    ``table`` is kept by reference: entries added later (or by a test) apply at once.
    """

    def __init__(self, package: str, table: Mapping[str, str]) -> None:
        self.package = package
        self.table = table

    def target(self, fullname: str) -> str | None:
        """The new dotted name of ``fullname``, or None if it is no old path."""
        head = self.package + "."
        if not fullname.startswith(head):
            return None
        parts = fullname[len(head):].split(".")
        for n in range(len(parts), 0, -1):
            new = self.table.get(".".join(parts[:n]))
            if new is not None:
                return ".".join([new, *parts[n:]])
        return None

    def find_spec(self, fullname: str, path: Sequence[str] | None = None,
                  target: ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        new = self.target(fullname)
        if new is None:
            return None
        found = sys.modules.get(new)
        try:
            spec = getattr(found, "__spec__", None) if found is not None else importlib.util.find_spec(new)
        except ModuleNotFoundError:  # a parent of the new path is missing
            spec = None
        if spec is None:
            return None  # no such module at the new path either: the usual ModuleNotFoundError
        return _AliasSpec(fullname, AliasLoader(new), spec)


def install(package: str, table: Mapping[str, str]) -> AliasFinder:
    """Put the alias finder of ``package`` first on :data:`sys.meta_path` (once; a second call,
    e.g. after ``importlib.reload(ght_cad)``, replaces the first finder) and return it."""
    sys.meta_path[:] = [f for f in sys.meta_path if getattr(f, "package", None) != package
                        or type(f).__name__ != AliasFinder.__name__]
    finder = AliasFinder(package, table)
    sys.meta_path.insert(0, finder)
    return finder


def alias_now(package: str, table: Mapping[str, str], old: str) -> ModuleType:
    """Register the old path ``<package>.<old>`` in sys.modules now, without setting the package
    attribute ``old`` (the facade's ``basis`` is the function ``basis``, not its module)."""
    module = importlib.import_module(table[old])
    sys.modules.setdefault(f"{package}.{old}", module)
    return module
