"""Exact shape-parameter gradients of the composite objectives (spec 8.1): the sum over strips of
AL/En/CVEn/weighted of each strip's dual curve as built, the joins re-solved for every candidate.

Reference: 4th-order central differences ``(-f(x+2h) + 8 f(x+h) - 8 f(x-h) + f(x-2h)) / 12h``,
``h = 1e-3``, of the objective computed by the independent build path (the design's composite
rebuilt and measured by ``composite_dual_objectives``). Truncation ``~h^4 f^(5)/30`` and round-off
``~eps |f| / h`` are both below 1e-10 relative here (measured: at most 1.4e-11 on the duct); the
tolerance is 1e-8 relative to the largest gradient component. The randomized (hypothesis) checks
take the derivative along one random unit direction ``d`` per example (all components nonzero, so
every gradient component enters; 4 objective values instead of 4 per parameter):
``|g·d - D_d f| <= 1e-8 |g|``.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from ght_cad.app.design import composite_objective, composite_value_and_grad, optimize_design, parse_design_text
from ght_cad.app.design.objectives import composite_dual_objectives, composite_dual_objectives_grad

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "design_duct_two_strips_optimized.toml"
TEXT = EXAMPLE.read_text()
DUCT_NAMES = [f"{g}.{k}" for g in ("quarter", "second-quarter") for k in ("mu", "nu", "gamma")]

# a third strip, the y-mirror of the second one (still tangent to the same cone, apex (1.5, 0, 6)),
# joined G3 with k, beta2, beta3 != default (rows 0..3 re-solved) -- or G1
THIRD = """
[[surface.segments]]
name = "third"
continuity = "CONT"
KPARS
planes = [
  [-0.923077, -0.923077, 0.0, 0.384615],
  [-0.927967, -0.872004, -0.317383, 0.372662],
  [-0.941433, -0.721179, -0.605141, 0.3372],
  [-0.96, -0.48, -0.831384, 0.28],
  [-0.969645, -0.331638, -0.911168, 0.244517],
  [-0.978638, -0.169939, -0.96377, 0.205591],
]
"""
THREE_NAMES = DUCT_NAMES + ["third.mu", "third.nu", "third.gamma"]
REL = 1e-8
H = 1e-3


def three_strips(cont: str = "G3") -> str:
    kp = "k = 1.1\nbeta2 = 0.05\nbeta3 = -0.02" if cont == "G3" else "k = 0.9\nbeta2 = 0.0"
    return TEXT.split("\n[optimize]")[0] + THIRD.replace("CONT", cont).replace("KPARS", kp)


def fd4(f, x: np.ndarray, h: float = H) -> np.ndarray:
    g = np.empty(x.size)
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        g[i] = (-f(x + 2 * e) + 8 * f(x + e) - 8 * f(x - e) + f(x - 2 * e)) / (12 * h)
    return g


def direction(seed: int, n: int) -> np.ndarray:
    """A unit direction in R^n, Gaussian (fixed ``seed``): every component nonzero."""
    d = np.random.default_rng(seed).normal(size=n)
    return d / np.linalg.norm(d)


def check(design, names, x, objective, weights=(1.0, 0.0, 0.0), seed: int = 0) -> float:
    """The exact gradient against the 4th-order difference along ``direction(seed)``."""
    def f(y: np.ndarray) -> float:
        return composite_objective(design, dict(zip(names, y)), objective, weights)

    v, g = composite_value_and_grad(design, dict(zip(names, x)), names, objective, weights)
    assume(math.isfinite(v))
    x = np.asarray(x, dtype=float)
    d = direction(seed, x.size)
    ref = fd4(lambda s: f(x + s[0] * d), np.zeros(1))[0]
    assume(math.isfinite(ref))
    assert v == f(x)  # the same value as the objective the optimizer sees
    err = float(abs(g @ d - ref) / np.linalg.norm(g))
    assert err <= REL, (x, d, g, ref)
    return err


OBJECTIVES = st.sampled_from([("CVEn", (1.0, 0.0, 0.0)), ("En", (1.0, 0.0, 0.0)), ("AL", (1.0, 0.0, 0.0)),
                              ("weighted", (0.3, 2.0, 0.01))])


@pytest.mark.slow
@settings(max_examples=12, deadline=None)
@given(st.lists(st.floats(-0.99, 0.99), min_size=6, max_size=6), OBJECTIVES, st.integers(0, 2**32 - 1))
def test_duct_g2_gradient_matches_fd(x: list[float], obj, seed: int) -> None:
    """Two strips (degrees 3 and 5) joined G2 (rows 0..2 re-solved), all six parameters."""
    d = parse_design_text(TEXT, "duct.toml")
    check(d, DUCT_NAMES, x, *obj, seed=seed)


@pytest.mark.slow
@settings(max_examples=10, deadline=None)
@given(st.lists(st.floats(-0.9, 0.9), min_size=9, max_size=9), OBJECTIVES, st.sampled_from(["G3", "G1"]),
       st.integers(0, 2**32 - 1))
def test_three_strips_gradient_matches_fd(x: list[float], obj, cont: str, seed: int) -> None:
    """Three strips, G2 then G3 (k, beta2, beta3 != default) or G1: strip 3's re-solved planes depend
    on all nine parameters through the chain."""
    d = parse_design_text(three_strips(cont), "three.toml")
    check(d, THREE_NAMES, x, *obj, seed=seed)


def test_subset_of_parameters_and_fixed_values() -> None:
    """Only the second strip's names free, the first strip at the file's values: the gradient is
    the corresponding columns of the full one."""
    d = parse_design_text(TEXT, "duct.toml")
    x = np.array([0.1, -0.3, 0.2, 0.4, 0.5, -0.6])
    full = composite_value_and_grad(d, dict(zip(DUCT_NAMES, x)), DUCT_NAMES)[1]
    sub = composite_value_and_grad(d, dict(zip(DUCT_NAMES, x)), DUCT_NAMES[3:][::-1])[1]
    assert np.array_equal(sub, full[3:][::-1])


@pytest.mark.parametrize("cont", ["C1", "C2", "C3"])
def test_parametric_joins_gradient(cont: str) -> None:
    """C1..C3 joins (``T_r = U^(r)(1)``), through the developable module directly."""
    from ght_cad.developables.envelope import developable_from_planes, join_developable
    from ght_cad.app.design.build import _make_composite  # noqa: F401 (same path as the design)
    from ght_cad.developables.envelope import CompositeDevelopable

    d = parse_design_text(TEXT, "duct.toml")
    s0, s1 = d.surface.segments
    P0, P1 = np.asarray(s0.planes, float), np.asarray(s1.planes, float)
    E = d.surface.boundary_planes

    def comp(x: np.ndarray):
        a = developable_from_planes(P0, E, *x[:3])
        return CompositeDevelopable([a, join_developable(a, cont, P1, mu=x[3], nu=x[4], gamma=x[5])])

    def f(x: np.ndarray) -> float:
        return composite_dual_objectives(comp(x), "En")[0]

    x = np.array([0.2, -0.1, 0.3, -0.2, 0.4, 0.1])
    v, g = composite_dual_objectives_grad(comp(x), [(cont, 1.0, 0.0, 0.0)], "En")
    ref = fd4(f, x)
    assert v == pytest.approx(f(x), rel=1e-13)
    assert np.max(np.abs(g.ravel() - ref)) <= REL * np.max(np.abs(ref))


def test_degenerate_candidate_is_inf_with_zero_gradient() -> None:
    """A candidate the objective rejects (degree-2 strip a stationary at t = 1: nu = gamma = -1)
    gives (+inf, 0)."""
    from test_design_composite_optimize import deg2

    d = parse_design_text(deg2(), "deg2.toml")
    names = [f"{g}.{k}" for g in "ab" for k in ("mu", "nu", "gamma")]
    v, g = composite_value_and_grad(d, dict(zip(names, [0.0, -1.0, -1.0, 0.0, 0.0, 0.0])), names)
    assert v == math.inf and np.array_equal(g, np.zeros(6))


@pytest.mark.slow
def test_hybrid_uses_the_exact_gradient_with_fewer_evaluations() -> None:
    """``method = "hybrid"`` on the duct: with the exact gradient (njev > 0) it reaches the same
    optimum (to 1e-6 relative) as with finite differences, with fewer objective evaluations
    (measured: 68 + 68 gradients vs 278)."""
    d = parse_design_text(TEXT, "duct.toml")
    ex = optimize_design(d, {"method": "hybrid"}, progress=False)
    fd = optimize_design(d, {"method": "hybrid"}, progress=False, exact_gradients=False)
    assert ex.njev > 0 and fd.njev == 0
    assert ex.best_value <= fd.best_value * (1 + 1e-6)
    assert ex.best_value == pytest.approx(fd.best_value, rel=1e-6)
    assert ex.nfev < fd.nfev / 2
    assert composite_objective(d, ex.shape) == pytest.approx(ex.best_value, rel=1e-12)
