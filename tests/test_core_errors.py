"""Bad input raises clear errors naming the value and the allowed range."""

from __future__ import annotations

import numpy as np
import pytest

from ght_cad import GHTCurve, GHTError, ShapeParameterError, basis


@pytest.mark.parametrize(
    "kwargs, pattern",
    [
        ({"mu": 1.2}, r"mu=1\.2 is outside the allowed range \[-1, 1\]"),
        ({"nu": -1.0001}, r"nu=-1\.0001 is outside the allowed range \[-1, 1\]"),
        ({"gamma": float("nan")}, r"gamma=nan is not finite; allowed range is \[-1, 1\]"),
        ({"gamma": "abc"}, r"gamma='abc' is not a number"),
    ],
)
def test_shape_parameter_out_of_range(kwargs, pattern) -> None:
    with pytest.raises(ShapeParameterError, match=pattern):
        basis([0.5], 3, **kwargs)
    with pytest.raises(ValueError, match=pattern):
        GHTCurve([[0, 0], [1, 1], [2, 0]], **kwargs)


def test_degree_too_low() -> None:
    with pytest.raises(GHTError, match=r"degree=1 is not allowed; degree must be an integer >= 2"):
        basis([0.5], 1)
    with pytest.raises(GHTError, match=r"degree=2\.5 is not an integer"):
        basis([0.5], 2.5)
    with pytest.raises(GHTError, match=r"control_points has 2 points; at least 3 are required"):
        GHTCurve([[0, 0], [1, 1]])


def test_nan_control_points() -> None:
    with pytest.raises(GHTError, match=r"control_points contains a non-finite value nan at index \(1, 0\)"):
        GHTCurve([[0, 0], [np.nan, 1], [2, 0]])
    with pytest.raises(GHTError, match=r"non-finite value inf"):
        GHTCurve([[0, 0, 0], [1, 1, 1], [2, 0, np.inf]])


@pytest.mark.parametrize(
    "points, pattern",
    [
        ([0.0, 1.0, 2.0], r"control_points must be a 2-D array of shape \(count, dim\); got shape \(3,\)"),
        (np.zeros((3, 2, 2)), r"got shape \(3, 2, 2\)"),
        ([[0, 0], [1], [2, 0]], r"control_points could not be read as an array"),
    ],
)
def test_wrong_array_shapes(points, pattern) -> None:
    with pytest.raises(GHTError, match=pattern):
        GHTCurve(points)


def test_bad_parameters_and_orders() -> None:
    c = GHTCurve([[0, 0], [1, 1], [2, 0]])
    with pytest.raises(GHTError, match=r"t=1\.5 is outside the parameter domain \[0, 1\]"):
        c.evaluate([0.2, 1.5])
    with pytest.raises(GHTError, match=r"t contains a non-finite value nan"):
        c.evaluate([np.nan])
    with pytest.raises(GHTError, match=r"derivative=4 is not allowed; analytic derivatives exist for orders 0\.\.3"):
        c.derivative(0.5, 4)
    with pytest.raises(GHTError, match=r"torsion needs a 3-D curve; this curve has dim=2"):
        c.torsion(0.5)
    with pytest.raises(GHTError, match=r"seed='nope' is not registered; known seeds: bernstein, gbt, ght"):
        GHTCurve([[0, 0], [1, 1], [2, 0]], seed="nope")


def test_seed_parameters_it_does_not_use_are_refused() -> None:
    """GBT is GHT at γ = -1 and Bernstein has no parameters: a value for them is an error, not ignored."""
    from ght_cad.curves.seeds import GHTSeed, make_seed

    with pytest.raises(GHTError, match=r"gamma=0\.5 is not used by the 'gbt' seed \(it is the GHT seed at gamma=-1\)"):
        make_seed("gbt", gamma=0.5)
    with pytest.raises(GHTError, match=r"gamma=0\.0 is not used by the 'gbt' seed"):
        GHTCurve([[0, 0], [1, 1], [2, 0]], gamma=0.0, seed="gbt")
    for k in ("mu", "nu"):
        with pytest.raises(GHTError, match=rf"{k}=0\.3 is not used by the 'bernstein' seed"):
            make_seed("bernstein", **{k: 0.3})
    with pytest.raises(GHTError, match=r"gamma=-1 is not used by the 'bernstein' seed"):
        make_seed("bernstein", gamma=-1)
    with pytest.raises(GHTError, match=r"mu=0\.2 is given beside the seed object .* which has mu=0\.5"):
        GHTCurve([[0, 0], [1, 1], [2, 0]], 0.2, seed=GHTSeed(0.5, 0.0, 0.0))
    # the values a seed fixes, or its own values, are accepted
    assert make_seed("gbt", 0.3, -0.2, -1.0).gamma == -1.0 and make_seed("gbt", 0.3).mu == 0.3
    assert make_seed("bernstein", 0.0, 0.0, 1.0).gamma == 1.0
    c = GHTCurve([[0, 0], [1, 1], [2, 0]], 0.5, seed=GHTSeed(0.5, 0.0, 0.0))
    assert (c.mu, c.nu, c.gamma) == (0.5, 0.0, 0.0)
    assert GHTCurve([[0, 0], [1, 1], [2, 0]]).gamma == 0.0  # the GHT default


def test_basis_outside_the_parameter_domain() -> None:
    """Outside [0, 1] the basis loses non-negativity: refused like GHTCurve.evaluate."""
    with pytest.raises(GHTError, match=r"t=1\.5 is outside the parameter domain \[0, 1\]"):
        basis(np.array([0.0, 1.5]), 3)
    with pytest.raises(GHTError, match=r"t=-0\.25 is outside the parameter domain"):
        basis(-0.25, 4, 0.2, 0.1, 0.0)


def test_messages_show_the_exact_bad_value_and_complex_parameters_are_named() -> None:
    """gamma=-1.0000001 printed as 'gamma=-1 is outside [-1, 1]' (':g' rounding); complex t gave a raw
    TypeError."""
    import pytest as _pytest

    from ght_cad import GHTCurve
    from ght_cad.core.errors import GHTError

    with _pytest.raises(GHTError, match=r"gamma=-1\.0000001 is outside the allowed range \[-1, 1\]"):
        GHTCurve([[0, 0], [1, 1], [2, 0]], gamma=-1.0000001)
    c = GHTCurve([[0, 0], [1, 1], [2, 0]])
    with _pytest.raises(GHTError, match=r"t=1\.0000001 is outside the parameter domain \[0, 1\]"):
        c.evaluate(1.0000001)
    with _pytest.raises(GHTError, match=r"t=\(0\.5\+1j\) is not allowed; use real numbers in \[0, 1\]"):
        c.evaluate(0.5 + 1j)
