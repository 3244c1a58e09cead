"""Pareto front of (AL, En, CVEn): non-dominated archive and weighted-sum sweep."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from hypothesis.extra.numpy import arrays

from ght_cad.core.errors import GHTError
from ght_cad.optimize import igwo
from ght_cad.optimize.pareto import (
    ParetoArchive,
    crowding_distance,
    nondominated,
    pareto_front,
    simplex_weights,
)
from ght_cad.optimize.problems import default_dual_problem


def brute_nondominated(F):
    n = len(F)
    out = np.ones(n, dtype=bool)
    for i in range(n):
        for j in range(n):
            if np.all(F[j] <= F[i]) and np.any(F[j] < F[i]):
                out[i] = False
    return out


@settings(max_examples=50)
@given(arrays(float, st.tuples(st.integers(1, 25), st.integers(1, 3)), elements=st.integers(0, 5).map(float)))
def test_nondominated_matches_brute_force(F):
    assert np.array_equal(nondominated(F), brute_nondominated(F))


def test_simplex_weights_and_crowding():
    W = simplex_weights(3, 4)
    assert W.shape == (15, 3) and np.allclose(W.sum(1), 1.0) and np.all(W >= 0)
    F = np.array([[0.0, 3.0], [1.0, 2.0], [1.1, 1.9], [3.0, 0.0]])
    d = crowding_distance(F)
    assert np.isinf(d[0]) and np.isinf(d[3]) and d[1] > 0 and d[2] > 0


def test_archive_cap_keeps_extremes():
    t = np.linspace(0, 1, 50)
    F = np.column_stack([t, 1 - t])            # all mutually non-dominated
    A = ParetoArchive(2, max_size=10)
    A.add(t[:, None], F)
    assert len(A) == 10 and A.f[:, 0].min() == 0.0 and A.f[:, 0].max() == 1.0
    A.add([[2.0]], [[-1.0, -1.0]])             # dominates everything
    assert len(A) == 1 and np.array_equal(A.x, [[2.0]])
    with pytest.raises(GHTError, match="shape"):
        A.add([[0.0]], [[1.0, 2.0, 3.0]])


@pytest.mark.slow
def test_pareto_front_of_dual_fairness():
    p = default_dual_problem()
    seen_x, seen_f = [], []
    measures = p.measures

    class Spy:
        names, bounds, x0 = p.names, p.bounds, p.x0

        def measures(self, X):
            M = measures(X)
            seen_x.append(np.array(X))
            seen_f.append(M)
            return M

    res = pareto_front(Spy(), divisions=3, pop_size=10, max_iter=15, seed=0, max_size=10**6)
    F = res.f
    allf = np.concatenate(seen_f)
    assert len(res.runs) == 10 and F.shape[1] == 3 and len(F) >= 10
    # no pruning here: the front is exactly the non-dominated set of all evaluated points
    assert np.all(nondominated(F))
    assert len(F) == int(np.sum(nondominated(np.unique(np.concatenate([allf, p.measures(p.x0[None])]), axis=0))))
    for fi in F:
        assert not np.any(np.all(allf <= fi, axis=1) & np.any(allf < fi, axis=1))
    # the front reproduces its own parameters' measures
    assert np.allclose(p.measures(res.x), F, rtol=1e-12)
    # extreme points: close to the single-objective optima
    for k, name in enumerate(("AL", "En", "CVEn")):
        q = default_dual_problem(name)
        best = igwo(q, q.bounds, pop_size=10, max_iter=40, seed=3).fun
        assert F[:, k].min() <= best * (1 + 2e-3), (name, F[:, k].min(), best)
    assert "| mu | nu | gamma | AL | En | CVEn |" in res.table()


def test_pareto_front_needs_measures():
    with pytest.raises(GHTError, match="no measures"):
        pareto_front(object())


def test_front_has_no_degenerate_design():
    """Three planes of the quarter cone: AL is smallest at the corner mu = nu = gamma = -1 where the
    dual curve is stationary and no surface exists. The front (every point of it) must be buildable;
    PSO clips onto that corner, so it was the AL-extreme point of the front."""
    from ght_cad.optimize.problems import DualCurveFairnessProblem

    planes = [[-400, 1, 0, 0.5], [-400, 1, 1, 0.5], [-400, 0, 1, 0.5]]
    p = DualCurveFairnessProblem(planes, [[0, 0, 0, 1], [-400, 0, 0, 1]], gamma=-1.0)
    assert p.admissible(np.array([[-1.0, -1.0, -1.0], [0.0, 0.0, -1.0]])).tolist() == [False, True]
    res = pareto_front(p, "pso", divisions=2, pop_size=8, max_iter=10, seed=0)
    assert len(res.f) >= 3
    for x in res.x:
        p.build(x)                                  # raises for a degenerate design
    assert not np.any(np.all(np.isclose(res.x, -1.0), axis=1))
