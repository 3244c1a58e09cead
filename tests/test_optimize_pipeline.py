"""Pipeline (problem -> optimized object -> B-rep, STEP, flat pattern, plot), comparison table."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from ght_cad.core.errors import GHTError
from ght_cad.optimize import igwo, pso
from ght_cad.optimize.compare import budget_sweep, compare, format_table
from ght_cad.optimize.pipeline import optimize_design
from ght_cad.optimize.plots import plot_convergence, plot_pareto
from ght_cad.optimize.problems import default_dual_problem, default_interpolation_problem, default_strip_problem

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_dual_problem_to_step_and_flat_pattern(tmp_path):
    p = default_dual_problem("CVEn")
    d = optimize_design(p, pop_size=10, max_iter=20, seed=0, out_dir=tmp_path, stem="duct")
    assert d.after["CVEn"] < d.before["CVEn"] and d.after["theta_max"] < 1e-9
    assert set(d.files) == {"step", "dxf", "png", "json"}
    from ght_cad.cad.occ import is_valid, read_step

    assert is_valid(d.shape) and is_valid(read_step(d.files["step"]))
    assert d.files["dxf"].read_bytes()[:200].count(b"SECTION") >= 1
    assert d.files["png"].read_bytes()[:8] == PNG
    data = json.loads(d.files["json"].read_text())
    assert data["parameters"] == d.parameters and data["after"]["CVEn"] == pytest.approx(d.result.fun)
    # the flat pattern of an exactly developable surface has round-off distortion only
    assert d.flat.errors["max"] < 1e-9
    assert not d.notes
    assert list(tmp_path.glob("*.part")) == []      # atomic writes leave no temporaries


def test_strip_pipeline_best_effort_flat_pattern():
    d = optimize_design(default_strip_problem(), pop_size=12, max_iter=30, seed=0, cad=False)
    assert d.after["theta_max"] < 0.2 * d.before["theta_max"]
    assert d.shape is None and d.files == {}
    assert d.flat is not None and d.flat.errors["max"] < 1e-4
    assert any("best_effort" in n for n in d.notes)
    assert "| theta_max |" in d.summary()


def test_curve_pipeline_gives_an_edge(tmp_path):
    d = optimize_design(default_interpolation_problem(), pop_size=8, max_iter=10, seed=0, out_dir=tmp_path, plot=False)
    assert d.shape is not None and d.flat is None and "step" in d.files and "png" not in d.files
    assert any("curve" in n for n in d.notes)


def test_pipeline_callback_stops_and_bad_stem():
    d = optimize_design(default_dual_problem(), pop_size=8, max_iter=100, seed=0, cad=False, flat=False,
                        callback=lambda s: s.nit >= 2)
    assert d.result.nit == 2 and d.result.message == "stopped by callback"
    with pytest.raises(GHTError, match="stem='a/b'"):
        optimize_design(default_dual_problem(), stem="a/b")


def test_compare_table_and_target():
    sphere = lambda X: np.sum((X - 0.3) ** 2, axis=1)  # noqa: E731
    rows = compare({"sphere": (sphere, (-np.ones(3), np.ones(3)))}, ("pso", "igwo", "de"), seeds=(0, 1, 2),
                   pop_size=8, max_iter=30)
    assert [r.method for r in rows] == ["pso", "igwo", "de"]
    for r in rows:
        assert r.best <= r.median <= r.worst and len(r.runs) == 3
        # target = f_best + 1e-3 (f_init - f_best) with f_best the best of all runs
        assert r.target >= min(q.best for q in rows)
        if r.reached:
            hits = [run.nfev_to_reach(r.target) for run in r.runs]
            assert all(h is None or run.history[list(run.history_nfev).index(h)] <= r.target
                       for h, run in zip(hits, r.runs))
    de = rows[-1]
    assert de.ratio == pytest.approx(1.0)
    md = format_table(rows)
    assert md.splitlines()[0].startswith("| problem | method | best") and len(md.splitlines()) == 5
    assert "sphere" in format_table(rows, "text")
    with pytest.raises(GHTError, match="fmt='html'"):
        format_table(rows, "html")
    with pytest.raises(GHTError, match="'nelder'"):
        compare({"s": (sphere, (-np.ones(2), np.ones(2)))}, ("nelder",))


def test_budget_sweep_takes_the_best_grid_point():
    sphere = lambda X: np.sum((X - 0.3) ** 2, axis=1)  # noqa: E731
    b = (-np.ones(2), np.ones(2))
    sw = budget_sweep(sphere, b, "pso", 1e-4, pop_sizes=(6, 10), max_iters=(5, 40), seeds=(0, 1, 2))
    assert set(sw.table) == {(6, 5), (6, 40), (10, 5), (10, 40)}
    assert sw.nfev == min(sw.table.values()) and sw.table[(sw.pop_size, sw.max_iter)] == sw.nfev
    # one grid point recomputed by hand: median over seeds of the first hit (inf if never)
    hits = []
    for s in (0, 1, 2):
        h = pso(sphere, b, pop_size=10, max_iter=40, seed=s).nfev_to_reach(1e-4)
        hits.append(math.inf if h is None else h)
    assert sw.table[(10, 40)] == float(np.median(hits))
    # 5 iterations of 6 particles (36 evaluations) cannot reach 1e-4 on all seeds; 40 iterations can
    assert sw.table[(6, 5)] == sw.table[(10, 5)] == math.inf and math.isfinite(sw.nfev) and sw.max_iter == 40
    never = budget_sweep(sphere, b, "igwo", -1.0, pop_sizes=(6,), max_iters=(5,), seeds=(0,))
    assert never.nfev == math.inf and never.pop_size is None
    with pytest.raises(GHTError, match="'nelder'"):
        budget_sweep(sphere, b, "nelder", 0.0)
    with pytest.raises(GHTError, match="at least one"):
        budget_sweep(sphere, b, "pso", 0.0, pop_sizes=())


@pytest.mark.slow
def test_plots_are_png(tmp_path):
    f = lambda X: np.sum(X**2, axis=1)  # noqa: E731
    runs = [igwo(f, (-np.ones(2), np.ones(2)), pop_size=6, max_iter=10, seed=s) for s in range(3)]
    runs.append(pso(f, (-np.ones(2), np.ones(2)), pop_size=6, max_iter=10, seed=0))
    out = plot_convergence(runs, tmp_path / "c.png", x="nit")
    assert out.read_bytes()[:8] == PNG
    from ght_cad.optimize.pareto import pareto_front

    front = pareto_front(default_dual_problem(), divisions=1, pop_size=6, max_iter=5, seed=0)
    assert plot_pareto(front, tmp_path / "p.png").read_bytes()[:8] == PNG
    with pytest.raises(GHTError, match="x='time'"):
        plot_convergence(runs, tmp_path / "d.png", x="time")
    assert not (tmp_path / "d.png").exists()


def test_degenerate_box_corner_is_rejected_and_never_crashes_the_build():
    """Three control planes of the exact quarter cone: at mu = nu = gamma = -1 the dual curve is
    stationary at both ends (U'(0) = U'(1) = 0) and the surface cannot be built, yet its AL is the
    smallest in the box. PSO clips onto that corner; the objective must reject it (+inf) so that the
    optimized design is one whose surface exists."""
    from ght_cad.optimize.problems import DualCurveFairnessProblem

    planes = [[-400, 1, 0, 0.5], [-400, 1, 1, 0.5], [-400, 0, 1, 0.5]]
    p = DualCurveFairnessProblem(planes, [[0, 0, 0, 1], [-400, 0, 0, 1]], objective="AL", gamma=-1.0)
    assert p(np.array([[-1.0, -1.0, -1.0]]))[0] == math.inf
    assert math.isfinite(p.value(p.x0))
    d = optimize_design(p, "pso", pop_size=8, max_iter=15, seed=0, cad=False, flat=False, plot=False)
    assert math.isfinite(d.result.fun) and d.result.fun < p.value(p.x0)
    assert d.after["theta_max"] < 1e-9          # the built surface exists and is developable
    # without boundary planes there is no surface to check: the corner keeps its finite value
    free = DualCurveFairnessProblem(planes, objective="AL", gamma=-1.0)
    assert free(np.array([[-1.0, -1.0, -1.0]]))[0] == pytest.approx(1.2649110640673535, rel=1e-9)


def test_degenerate_base_design_is_reported_not_a_crash(tmp_path):
    """The base design mu = nu = gamma = -1 of three planes cannot be built (stationary dual curve):
    the run still optimizes, 'before' holds NaN with a note, and the JSON file is strict JSON
    (NaN/inf written as null)."""
    from ght_cad.optimize.problems import DualCurveFairnessProblem

    planes = [[-400, 1, 0, 0.5], [-400, 1, 1, 0.5], [-400, 0, 1, 0.5]]
    p = DualCurveFairnessProblem(planes, [[0, 0, 0, 1], [-400, 0, 0, 1]], objective="CVEn",
                                 mu=-1.0, nu=-1.0, gamma=-1.0)
    assert p.value(p.x0) == math.inf
    d = optimize_design(p, "igwo", pop_size=6, max_iter=5, seed=0, cad=False, flat=False, plot=False,
                        out_dir=tmp_path)
    assert math.isfinite(d.result.fun) and d.after["theta_max"] < 1e-9
    assert set(d.before) == set(d.after) and all(math.isnan(v) for v in d.before.values())
    assert any("base design" in n for n in d.notes)

    def strict(c):
        raise ValueError(f"non-standard JSON constant {c}")

    data = json.loads(d.files["json"].read_text(), parse_constant=strict)
    assert data["before"]["CVEn"] is None and data["after"]["CVEn"] == pytest.approx(d.result.fun)


def test_no_finite_value_is_a_clear_error():
    """An objective that is +inf everywhere: the pipeline says so instead of building, meshing and
    unrolling the midpoint of the box as if it were a result."""
    p = default_strip_problem()
    p.evaluate_full = lambda F: np.full(len(F), np.inf)
    with pytest.raises(GHTError, match="no parameters with a finite objective in 15 evaluations"):
        optimize_design(p, "pso", pop_size=5, max_iter=2, seed=0, plot=False)


def test_strip_that_cannot_be_unrolled_keeps_the_result(tmp_path):
    """A strip between a curve and itself with other shape parameters: the two boundary curves meet
    at both ends, R is finite but the unroll refuses the pinched strip. The optimization result is
    returned with a note (no crash after the optimization), the other files are written."""
    from ght_cad import GHTCurve
    from ght_cad.optimize.problems import StripProblem

    A = GHTCurve([[0, 0, 0], [1, 1, 0], [2, 0, 1], [3, 1, 1.0]])
    d = optimize_design(StripProblem(A, A), "pso", pop_size=5, max_iter=3, seed=0, cad=False, out_dir=tmp_path)
    assert math.isfinite(d.result.fun) and d.flat is None
    assert any(n.startswith("flat pattern failed") for n in d.notes), d.notes
    assert set(d.files) == {"png", "json"}
    assert json.loads(d.files["json"].read_text())["notes"] == d.notes


def test_out_dir_that_is_a_file_is_refused_before_the_run(tmp_path):
    f = tmp_path / "file.txt"
    f.write_text("keep")
    calls = []
    with pytest.raises(GHTError, match="out_dir=.*is a file"):
        optimize_design(default_dual_problem("CVEn"), pop_size=5, max_iter=2, out_dir=f,
                        callback=lambda s: calls.append(s.nit))
    assert calls == [] and f.read_text() == "keep"


def test_compare_variants_and_gradient_cost():
    """Variants by label (hybrid with finite differences) and exact gradients charged at grad_cost."""
    from ght_cad.optimize import hybrid
    from ght_cad.optimize.problems import default_dual_problem

    p = default_dual_problem("En", check_surface=False)
    fd = {"hybrid-fd": lambda f, b, *, pop_size, max_iter, seed, x0: hybrid(lambda X: f(X), b, seed=seed)}
    rows = compare({"dual": (p, p.bounds)}, ("hybrid", "hybrid-fd", "de"), seeds=(0, 1), pop_size=10, max_iter=20,
                   variants=fd, grad_cost={"dual": 3.0})
    h, hf, de = rows
    assert h.grad_cost == 3.0 and all(run.njev > 0 for run in h.runs) and all(run.njev == 0 for run in hf.runs)
    for run in h.runs:  # the count to target includes 3 evaluations per gradient
        n = run.nfev_to_reach(h.target, 3.0)
        k = int(np.nonzero(run.history <= h.target)[0][0])
        assert n == run.history_nfev[k] + 3.0 * run.history_njev[k] > run.nfev_to_reach(h.target)
    assert h.nfev_to_target == float(np.median([run.nfev_to_reach(h.target, 3.0) for run in h.runs]))
