"""The one Gauss–Legendre helper and the one caching scheme of pure functions (issue 27)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest

from ght_cad.core._cache import readonly_cache
from ght_cad.core._quadrature import gauss_legendre, gauss_legendre_unit, leggauss


@pytest.mark.parametrize("n", [1, 3, 8, 12, 16, 24, 64])
def test_nodes_are_numpys_to_the_bit_and_shared_read_only(n: int) -> None:
    x, w = np.polynomial.legendre.leggauss(n)
    a, b = leggauss(n)
    assert a.tobytes() == x.tobytes() and b.tobytes() == w.tobytes()
    assert leggauss(n)[0] is a and not a.flags.writeable and not b.flags.writeable
    # [0, 1]: the formula t = a + h (x + 1), h = (b - a) / 2, evaluated as before the helper existed
    t, wt = gauss_legendre_unit(n)
    assert t.tobytes() == (0.0 + 0.5 * (x + 1.0)).tobytes() and wt.tobytes() == (0.5 * w).tobytes()
    assert not t.flags.writeable
    t2, w2 = gauss_legendre(n)
    assert t2.tobytes() == t.tobytes() and t2.flags.writeable  # a fresh array the caller may change


@pytest.mark.parametrize("n", [2, 5, 9])
def test_the_n_point_rule_is_exact_to_degree_2n_minus_1(n: int) -> None:
    a, b = -0.7, 2.3
    t, w = gauss_legendre(n, a, b)
    for k in range(2 * n):  # ∫_a^b t^k dt = (b^{k+1} - a^{k+1}) / (k + 1), to 1e-13 relative
        exact = (b ** (k + 1) - a ** (k + 1)) / (k + 1)
        assert float(w @ t ** k) == pytest.approx(exact, rel=1e-13, abs=1e-13)


def test_the_old_public_names_are_the_helper() -> None:
    from ght_cad.curves.curve import gauss_legendre as curve_gl
    from ght_cad.app.design import _gauss_legendre

    assert curve_gl is gauss_legendre and _gauss_legendre is gauss_legendre_unit


def test_readonly_cache_freezes_arrays_and_refuses_a_bad_size() -> None:
    calls = []

    @readonly_cache(maxsize=2)
    def f(n: int) -> tuple[np.ndarray, list[np.ndarray | None]]:
        calls.append(n)
        return np.arange(n, dtype=float), [np.ones(n), None]

    a, (b, c) = f(3)
    assert f(3)[0] is a and calls == [3]
    assert not a.flags.writeable and not b.flags.writeable and c is None
    with pytest.raises(ValueError, match="maxsize=0 is not allowed"):
        readonly_cache(0)


PACKAGE = Path(__file__).resolve().parents[1] / "ght_cad"
#: the two modules that own the Gauss–Legendre nodes and the cache decorator
OWNERS = {"core/_quadrature.py", "core/_cache.py"}
#: node constructions other than the helper's (numpy's, scipy's)
FOREIGN_NODES = re.compile(r"legendre\.leggauss|roots_legendre|fixed_quad|special\.p_roots|leggauss\s*=")



def _violations(rel: str, text: str) -> list[str]:
    """What in the module ``rel`` bypasses the helper or the cache scheme: a node construction of
    numpy/scipy, ``functools.lru_cache``/``functools.cache`` (decorator or import), a module-level
    global whose name says cache or memo."""
    bad = [f"{rel}: Gauss–Legendre nodes by {m.group(0)!r}" for m in FOREIGN_NODES.finditer(text)]
    tree = ast.parse(text, filename=rel)
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "functools"
                and node.attr in ("lru_cache", "cache")):
            bad.append(f"{rel}:{node.lineno}: functools.{node.attr}")
        if isinstance(node, ast.ImportFrom) and node.module == "functools":
            bad += [f"{rel}:{node.lineno}: from functools import {a.name}" for a in node.names
                    if a.name in ("lru_cache", "cache")]
    for stmt in tree.body:  # a global container named *cache* or *memo* (its size limits, plain numbers, may stay)
        targets = stmt.targets if isinstance(stmt, ast.Assign) else [stmt.target] if isinstance(stmt, ast.AnnAssign) else []
        if isinstance(getattr(stmt, "value", None), (ast.Constant, ast.UnaryOp, ast.BinOp)):
            continue
        bad += [f"{rel}:{stmt.lineno}: module-level cache {t.id}" for t in targets
                if isinstance(t, ast.Name) and ("cache" in t.id.lower() or "memo" in t.id.lower())]
    return bad


def test_no_other_cache_or_gauss_legendre_construction_comes_back() -> None:
    """Issue 27: one quadrature helper and one caching scheme. Outside ``core/_quadrature.py`` and
    ``core/_cache.py`` no module builds Gauss–Legendre nodes itself, caches with
    ``functools.lru_cache``/``functools.cache`` or keeps a module-level cache; per-object caches
    live on their objects (``self._cache``, as ``ght_cad.core._cache`` says)."""
    bad = [v for p in sorted(PACKAGE.rglob("*.py")) if (rel := p.relative_to(PACKAGE).as_posix()) not in OWNERS
           for v in _violations(rel, p.read_text(encoding="utf-8"))]
    assert not bad, "use ght_cad.core._quadrature / ght_cad.core._cache instead:\n" + "\n".join(bad)


def test_the_guard_sees_what_it_forbids() -> None:
    """:func:`_violations` finds each form it forbids (so the guard cannot pass by matching nothing)
    and nothing in a module on the scheme."""
    bad = (
        "import functools\nfrom functools import lru_cache\nimport numpy as np\n"
        "@functools.lru_cache(8)\ndef f(n): return np.polynomial.legendre.leggauss(n)\n"
        "@functools.cache\ndef g(n): return scipy.special.roots_legendre(n)\n"
        "_X_CACHE: dict = {}\n_jet_cache = weakref.WeakKeyDictionary()\n_BASIS_MEMO: dict = {}\n"
    )
    found = _violations("m.py", bad)
    for what in ("legendre.leggauss", "roots_legendre", "functools.lru_cache", "functools.cache",
                 "import lru_cache", "cache _X_CACHE", "cache _jet_cache", "cache _BASIS_MEMO"):
        assert any(what in v for v in found), (what, found)
    good = "from ..core._cache import readonly_cache\n_CACHE_SIZE = 8\n@readonly_cache(maxsize=_CACHE_SIZE)\ndef f(n): return n\n"
    assert _violations("m.py", good) == []
