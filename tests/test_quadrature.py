"""The one Gauss–Legendre helper and the one caching scheme of pure functions (issue 27)."""

from __future__ import annotations

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
    from ght_cad.design import _gauss_legendre

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
