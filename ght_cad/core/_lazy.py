"""Names a module gives without importing them up front (PEP 562 module ``__getattr__``)."""

from __future__ import annotations

import importlib
import warnings
from typing import Any, Callable, Mapping


def lazy_getattr(module: str, table: Mapping[str, str], namespace: dict[str, Any],
                 deprecated: bool = False) -> Callable[[str], Any]:
    """A module ``__getattr__`` that imports ``table[name]`` (a dotted module path) on first use,
    takes ``name`` from it and keeps the value in ``namespace`` (the module's ``globals()``).

    Used by the facade ``ght_cad`` (heavier modules, and the CAD adapter ``unfold``) and, with
    ``deprecated=True``, by ``ght_cad.developables.loft`` for the names that moved to
    ``ght_cad.optimize.problems.loft`` (a higher layer): each first use there warns
    (:class:`DeprecationWarning` naming the new path) and is not kept, so every use warns.

    Raises:
        AttributeError: ``name`` is not in ``table`` (as for any missing module attribute).
    """

    def __getattr__(name: str) -> Any:
        source = table.get(name)
        if source is None:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(source), name)
        if deprecated:
            warnings.warn(f"{module}.{name} moved to {source}.{name}; import it from there (the old name "
                          "goes in the next minor release)", DeprecationWarning, stacklevel=2)
        else:
            namespace[name] = value
        return value

    return __getattr__
