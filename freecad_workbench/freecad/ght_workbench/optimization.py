r"""Optimization feature: stores a shape-parameter problem and writes the optimum into the
features it drives (spec sections 5, 7, 8).

Problems (``ght_cad.optimize.problems``), chosen by ``Problem`` and the ``Targets``:

* ``Fairness``, one GHT curve target: :class:`CurveFairnessProblem`, objective
  ``w1 AL + w2 En + w3 CVEn`` with ``AL = ∫|X'|``, ``En = ∫|X''|²``, ``CVEn = ∫|X'''|²``.
* ``Fairness``, one developable-from-planes target: :class:`DualCurveFairnessProblem`, the same
  measures of the dual curve of the (normalized) control planes.
* ``Developability``, two GHT curve targets: :class:`StripProblem`, ``R = ∫(1 - n_a·n_b) du`` of the
  ruled strip between them (parameters ``a.mu ... b.gamma``).
* ``Loft``, one *Developable loft* target whose two rails are GHT curves:
  :class:`ght_cad.optimize.problems.loft.LoftProblem` over the rails' ``a.mu ... b.gamma``, objective
  ``WeightFanShare · fan share + WeightRulingFairness · ∫|d'|² + WeightRegression · (edge of
  regression penalty)`` of the exact developable loft (+inf where none exists).

Recomputing the feature only evaluates the objective at the targets' current parameters
(``CurrentValue``); :meth:`OptimizationFeature.run` (command *Run optimization*) runs PSO / GWO /
I-GWO / DE with a progress callback that can cancel, then writes the best parameters into the
targets, which recompute. A cancelled run changes nothing.
"""

from __future__ import annotations

from typing import Any, Callable

import FreeCAD as App

from ght_cad.core.errors import GHTError

from ._base import BaseCommand, FeatureProxy, ViewProviderBase, info_panel, new_feature, register_command, set_read_only

__all__ = ["OptimizationFeature", "make_optimization", "run_optimization", "PROBLEMS", "METHODS"]

PROBLEMS = ["Fairness", "Developability", "Loft"]
#: Loft objective weights: property -> LoftProblem objective name
LOFT_WEIGHTS = {"WeightFanShare": "fan_share", "WeightRulingFairness": "fairness", "WeightRegression": "regression"}
METHODS = ["hybrid", "igwo", "pso", "gwo", "de"]
_OUT = ("InitialValue", "BestValue", "CurrentValue", "Evaluations", "Status", "BestParameters")


def _kind(obj: Any) -> str:
    return getattr(getattr(obj, "Proxy", None), "Type", "")


class OptimizationFeature(FeatureProxy):
    """Proxy of an optimization (``App::FeaturePython``: no shape)."""

    Type = "GHT::Optimization"

    def setup(self, obj: Any) -> None:
        obj.addProperty("App::PropertyLinkList", "Targets", "Problem", "Driven features: one GHT curve or developable (Fairness), two GHT curves (Developability)")
        obj.addProperty("App::PropertyEnumeration", "Problem", "Problem", "Fairness (AL/En/CVEn), Developability (R of the strip between two curves) or Loft (a developable loft's fan share, ruling fairness, edge of regression)")
        obj.Problem = PROBLEMS
        obj.addProperty("App::PropertyStringList", "Free", "Problem", "Free parameter names (empty: all), e.g. mu, gamma or a.mu, b.nu")
        obj.addProperty("App::PropertyFloat", "WeightAL", "Problem", "Weight of the arc length AL = ∫|X'| (Fairness)")
        obj.addProperty("App::PropertyFloat", "WeightEn", "Problem", "Weight of the bending energy En = ∫|X''|² (Fairness)")
        obj.addProperty("App::PropertyFloat", "WeightCVEn", "Problem", "Weight of the curvature variation CVEn = ∫|X'''|² (Fairness)")
        obj.WeightEn = 1.0
        self.add_loft_weights(obj)
        obj.addProperty("App::PropertyEnumeration", "Method", "Optimizer", "hybrid (Sobol starts + L-BFGS-B, default), igwo, pso, gwo or de (scipy differential evolution)")
        obj.Method = METHODS
        obj.addProperty("App::PropertyInteger", "PopulationSize", "Optimizer", "Population size")
        obj.PopulationSize = 20
        obj.addProperty("App::PropertyInteger", "MaxIterations", "Optimizer", "Iteration budget")
        obj.MaxIterations = 40
        obj.addProperty("App::PropertyInteger", "Seed", "Optimizer", "Random seed (runs are reproducible)")
        obj.Seed = 1
        obj.addProperty("App::PropertyFloat", "InitialValue", "Result", "Objective before the last run")
        obj.addProperty("App::PropertyFloat", "BestValue", "Result", "Objective after the last run")
        obj.addProperty("App::PropertyFloat", "CurrentValue", "Result", "Objective at the targets' current parameters")
        obj.addProperty("App::PropertyInteger", "Evaluations", "Result", "Objective evaluations of the last run")
        obj.addProperty("App::PropertyString", "Status", "Result", "Outcome of the last run")
        obj.addProperty("App::PropertyStringList", "BestParameters", "Result", "name=value of the last optimum")
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        set_read_only(obj, _OUT)
        self.add_loft_weights(obj)  # files saved before the Loft problem existed
        if "Loft" not in obj.getEnumerationsOfProperty("Problem"):
            current = obj.Problem
            obj.Problem = PROBLEMS
            obj.Problem = current

    @staticmethod
    def add_loft_weights(obj: Any) -> None:
        """Add the Loft objective weights (fan share 1, the others 0) if missing."""
        tips = {
            "WeightFanShare": "Weight of the fan share of the loft's area (Loft: 0 = rulings end to end)",
            "WeightRulingFairness": "Weight of the ruling field's fairness ∫|d'|² (Loft)",
            "WeightRegression": "Weight of the edge-of-regression penalty (Loft: keeps it away from the rails)",
        }
        for prop, tip in tips.items():
            if prop not in obj.PropertiesList:
                obj.addProperty("App::PropertyFloat", prop, "Problem", tip)
                setattr(obj, prop, 1.0 if prop == "WeightFanShare" else 0.0)

    # -- problem ------------------------------------------------------------------------
    def problem(self, obj: Any) -> tuple[Any, list[tuple[Any, str, str]]]:
        """(core problem, [(target feature, property, parameter name), ...])."""
        from ght_cad.optimize.problems import CurveFairnessProblem, DualCurveFairnessProblem, StripProblem

        from .ght_curve import core_curve

        targets = list(obj.Targets)
        free = [s.strip() for s in obj.Free if s.strip()] or None
        if obj.Problem == "Developability":
            if len(targets) != 2 or any(_kind(t) != "GHT::Curve" for t in targets):
                raise GHTError(f"{obj.Label}: Developability needs exactly two GHT curve targets (the strip's boundaries)")
            prob = StripProblem(core_curve(targets[0], placed=True), core_curve(targets[1], placed=True), free=free)
            mapping = [(targets[i], p, f"{s}.{p.lower()}") for i, s in enumerate("ab") for p in ("Mu", "Nu", "Gamma")]
            return prob, mapping
        if obj.Problem == "Loft":
            return self.loft_problem(obj, targets, free)
        if len(targets) != 1:
            raise GHTError(f"{obj.Label}: Fairness needs exactly one target (a GHT curve or a developable), got {len(targets)}")
        weights = {"AL": float(obj.WeightAL), "En": float(obj.WeightEn), "CVEn": float(obj.WeightCVEn)}
        t = targets[0]
        if _kind(t) == "GHT::Curve":
            prob = CurveFairnessProblem(core_curve(t, placed=True), objective=weights, free=free)
        elif _kind(t) == "GHT::Developable":
            planes, boundary = t.Proxy.control_planes(t)
            prob = DualCurveFairnessProblem(planes, boundary, objective=weights, free=free, mu=float(t.Mu), nu=float(t.Nu), gamma=float(t.Gamma))
        else:
            raise GHTError(f"{t.Label} is a {_kind(t) or t.TypeId}; Fairness drives a GHT curve or a developable from planes")
        return prob, [(t, p, p.lower()) for p in ("Mu", "Nu", "Gamma")]

    def loft_problem(self, obj: Any, targets: list, free: Any) -> tuple[Any, list[tuple[Any, str, str]]]:
        """(:class:`ght_cad.optimize.problems.loft.LoftProblem`, mapping to the rails' Mu/Nu/Gamma) of one loft target."""
        from ght_cad.optimize.problems import LoftProblem

        from .ght_curve import core_curve

        if len(targets) != 1 or _kind(targets[0]) != "GHT::DevelopableLoft":
            raise GHTError(f"{obj.Label}: Loft needs exactly one Developable loft target, got {[t.Label for t in targets]}")
        loft = targets[0]
        rails = [getattr(loft, n)[0] if getattr(loft, n) else None for n in ("RailA", "RailB")]
        for n, r in zip(("RailA", "RailB"), rails):
            if r is None or _kind(r) != "GHT::Curve":
                raise GHTError(
                    f"{obj.Label}: {loft.Label}.{n} is {'not linked' if r is None else r.Label + ', not a GHT curve'}; "
                    "Loft optimizes the shape parameters of GHT curve rails"
                )
        weights = {name: float(getattr(obj, prop)) for prop, name in LOFT_WEIGHTS.items() if float(getattr(obj, prop)) != 0.0}
        opts = {"orientation": str(loft.Orientation), "samples": 33}
        prob = LoftProblem(core_curve(rails[0], placed=True), core_curve(rails[1], placed=True), objective=weights, free=free, loft_options=opts)
        mapping = [(rails[i], p, f"{s}.{p.lower()}") for i, s in enumerate("ab") for p in ("Mu", "Nu", "Gamma")]
        return prob, mapping

    def check_settings(self, obj: Any) -> None:
        """Refuse optimizer settings the core would refuse, naming the property.

        Raises:
            GHTError: ``MaxIterations`` < 0 or ``PopulationSize`` < 4.
        """
        if int(obj.MaxIterations) < 0:
            raise GHTError(f"{obj.Label}.MaxIterations={obj.MaxIterations} is not allowed; use an integer >= 0")
        if int(obj.PopulationSize) < 4:
            raise GHTError(f"{obj.Label}.PopulationSize={obj.PopulationSize} is not allowed; use an integer >= 4")

    def compute(self, obj: Any) -> None:
        self.check_settings(obj)
        if not obj.Targets:
            return
        prob, _ = self.problem(obj)
        obj.CurrentValue = prob.value(prob.x0)

    # -- run ------------------------------------------------------------------------------
    def run(self, obj: Any, progress: Callable[[int, int, float], bool] | None = None) -> Any:
        """Optimize and write the best parameters into the targets (then recompute).

        Args:
            progress: ``progress(iteration, max_iterations, best_value) -> cancel`` called after
                every iteration; returning True cancels (the targets are then left unchanged).

        Returns:
            The core :class:`ght_cad.optimize.OptimizeResult`.
        """
        from ght_cad.optimize import minimize

        self.check_settings(obj)
        prob, mapping = self.problem(obj)
        initial = prob.value(prob.x0)

        def callback(state: Any) -> bool:
            return bool(progress(state.nit, state.max_iter, state.fun)) if progress is not None else False

        res = minimize(
            prob, prob.bounds, method=obj.Method, pop_size=int(obj.PopulationSize), max_iter=int(obj.MaxIterations),
            seed=int(obj.Seed), x0=prob.x0, callback=callback,
        )
        obj.InitialValue = float(initial)
        obj.Evaluations = int(res.nfev)
        obj.Status = str(res.message)
        if res.message == "stopped by callback":
            obj.Status = "cancelled: targets unchanged"
            return res
        params = prob.parameters(res.x)
        if res.fun > initial:  # optimizers keep the start point, but never make it worse
            params = prob.parameters(prob.x0)
        for target, prop, name in mapping:
            setattr(target, prop, float(params[name]))
        obj.BestValue = float(min(res.fun, initial))
        obj.BestParameters = [f"{k}={v:.12g}" for k, v in params.items()]
        obj.Document.recompute()
        return res


class ViewProviderOptimization(ViewProviderBase):
    icon_name = "GHT_Optimization"
    panel_factory = staticmethod(lambda obj: info_panel(obj, ("Targets",), "Edit Problem, Method and Targets in the "
                                                       "property editor; run it with Run optimization."))

    def claimChildren(self) -> list:
        return []


def make_optimization(targets: list, problem: str = "Fairness", *, method: str = "hybrid", doc: Any = None, name: str = "Optimization", **props: Any) -> Any:
    """Create an optimization feature driving ``targets`` (see module doc); ``props`` set properties."""
    if problem not in PROBLEMS:
        raise GHTError(f"problem={problem!r} is not allowed; use one of {PROBLEMS}")
    obj = new_feature(doc or targets[0].Document, name, OptimizationFeature, ViewProviderOptimization, "App::FeaturePython")
    obj.Targets = list(targets)
    obj.Problem = problem
    obj.Method = method
    for k, v in props.items():
        setattr(obj, k, v)
    obj.Document.recompute()
    return obj


def run_optimization(obj: Any, *, gui: bool | None = None) -> Any:
    """Run ``obj``'s optimization; in the GUI with a cancellable progress dialog."""
    gui = App.GuiUp if gui is None else gui
    if not gui:
        return obj.Proxy.run(obj)
    from PySide2 import QtCore, QtWidgets

    import FreeCADGui as Gui

    dlg = QtWidgets.QProgressDialog(f"Optimizing {obj.Label} ({obj.Method})", "Cancel", 0, int(obj.MaxIterations), Gui.getMainWindow())
    dlg.setWindowTitle("GHT optimization")
    dlg.setWindowModality(QtCore.Qt.WindowModal)
    dlg.setMinimumDuration(0)

    def progress(it: int, max_it: int, best: float) -> bool:
        dlg.setMaximum(max(max_it, 1))
        dlg.setValue(min(it, max_it))
        dlg.setLabelText(f"Optimizing {obj.Label}: iteration {it}/{max_it}, best {best:.6g}")
        QtWidgets.QApplication.processEvents()
        return dlg.wasCanceled()

    try:
        return obj.Proxy.run(obj, progress)
    finally:
        dlg.close()


class CommandOptimization(BaseCommand):
    name = "GHT_Optimization"
    icon_name = "GHT_Optimization"
    menu_text = "Optimization"
    tooltip = (
        "Create an optimization of the selected features' shape parameters: one GHT curve or "
        "developable -> fairness (AL/En/CVEn weights); two GHT curves -> developability R of the "
        "strip between them; a developable loft on GHT curve rails -> fan share / ruling fairness / edge of "
        "regression of the loft. Run it with 'Run optimization'."
    )

    def IsActive(self) -> bool:
        import FreeCADGui as Gui

        return App.ActiveDocument is not None and bool(Gui.Selection.getSelection())

    def Activated(self) -> None:
        import FreeCADGui as Gui

        sel = [o for o in Gui.Selection.getSelection() if _kind(o) in ("GHT::Curve", "GHT::Developable", "GHT::DevelopableLoft")]
        if not sel:
            App.Console.PrintError("GHT optimization: select one or two GHT curves, a developable or a developable loft\n")
            return
        if _kind(sel[0]) == "GHT::DevelopableLoft":
            problem = "Loft"
        else:
            problem = "Developability" if len(sel) == 2 and all(_kind(o) == "GHT::Curve" for o in sel) else "Fairness"
        doc = App.ActiveDocument
        doc.openTransaction("Optimization")
        obj = make_optimization(sel if problem == "Developability" else sel[:1], problem, doc=doc)
        doc.commitTransaction()
        Gui.Selection.clearSelection()
        Gui.Selection.addSelection(obj)


class CommandRunOptimization(BaseCommand):
    name = "GHT_RunOptimization"
    icon_name = "GHT_RunOptimization"
    menu_text = "Run optimization"
    tooltip = "Run the selected optimization (progress dialog, Cancel keeps the targets unchanged) and write the optimum into its targets"

    def IsActive(self) -> bool:
        import FreeCADGui as Gui

        return any(_kind(o) == "GHT::Optimization" for o in Gui.Selection.getSelection())

    def Activated(self) -> None:
        import FreeCADGui as Gui

        for obj in [o for o in Gui.Selection.getSelection() if _kind(o) == "GHT::Optimization"]:
            doc = obj.Document
            doc.openTransaction("Run optimization")
            try:
                res = run_optimization(obj)
            except Exception as exc:  # bad settings/targets: nothing was changed, say why
                doc.abortTransaction()
                App.Console.PrintError(f"GHT: {obj.Label}: {exc}\n")
                continue
            doc.commitTransaction()
            App.Console.PrintMessage(f"GHT: {obj.Label}: {res}\n")


register_command(CommandOptimization())
register_command(CommandRunOptimization())
