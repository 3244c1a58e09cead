"""The loft and the optimization problems as packages (issue 27): every name the old modules
``ght_cad/loft.py`` and ``ght_cad/optimize/problems.py`` gave is still given, and is the same object
as in its new home; the names that moved up to the optimize layer load only on first use."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: ``ght_cad.loft``'s ``__all__`` and public constants before the split (loft.py, 2,128 lines)
OLD_LOFT = ["Rail", "CallableRail", "as_rail", "developable_loft", "DevelopableLoft", "LoftSegment", "LoftReport",
            "loft_function", "plot_loft_sign", "LoftProblem", "LOFT_OBJECTIVES", "LoftGradientFallback",
            "loft_measures_and_gradients", "CORNER_TOL", "CORNER_RADIUS", "MIN_FAN"]
#: ``ght_cad.optimize.problems``' ``__all__`` before the split (problems.py, 1,049 lines), and the
#: names other modules import from it
OLD_PROBLEMS = ["ght_seed_jets", "population_basis", "PopulationBasis", "Problem", "StripProblem", "FairnessProblem",
                "DualCurveFairnessProblem", "CurveFairnessProblem", "InterpolationFairnessProblem",
                "FAIRNESS_MEASURES", "EnvelopeStrip", "default_strip_problem", "default_dual_problem",
                "default_interpolation_problem", "wave_strip_problem", "cone_strip_problem", "CurveParameterJets",
                "SHAPE_NAMES"]


#: the names of OLD_LOFT that moved to the optimize layer: deprecated aliases on ght_cad.loft
DEPRECATED_LOFT = ["LoftProblem", "LOFT_OBJECTIVES", "LoftGradientFallback", "loft_measures_and_gradients"]


@pytest.mark.parametrize("name", OLD_LOFT)
def test_ght_cad_loft_keeps_its_names(name: str) -> None:
    import ght_cad.loft as loft

    if name in DEPRECATED_LOFT:
        with pytest.warns(DeprecationWarning, match=f"moved to ght_cad.optimize.problems.loft.{name}"):
            value = getattr(loft, name)
    else:
        value = getattr(loft, name)
    if callable(value):  # classes and functions: defined in the package or in the loft problem's module
        assert value.__module__.startswith(("ght_cad.developables.loft.", "ght_cad.optimize.problems.loft")), value.__module__


@pytest.mark.parametrize("name", OLD_PROBLEMS)
def test_ght_cad_optimize_problems_keeps_its_names(name: str) -> None:
    import ght_cad.optimize.problems as problems

    assert getattr(problems, name) is not None


def test_moved_loft_names_are_deprecated_aliases_of_the_optimize_ones() -> None:
    """``ght_cad.loft.LoftProblem`` and the other three moved names are the optimize layer's objects,
    loaded on use with a DeprecationWarning naming the new path (every use: the alias is not kept);
    neither ``import ght_cad.loft`` nor ``from ght_cad.loft import *`` imports the optimize layer."""
    code = (
        "import sys, json, warnings, ght_cad.loft as L\n"
        "before = 'ght_cad.optimize' in sys.modules\n"
        "from ght_cad.loft import *\n"
        "star = 'ght_cad.optimize' in sys.modules\n"
        "import ght_cad.optimize.problems as P\n"
        "names = ('LoftProblem', 'LOFT_OBJECTIVES', 'LoftGradientFallback', 'loft_measures_and_gradients')\n"
        "msgs = []\n"
        "same = []\n"
        "for n in names + names[:1]:\n"
        "    with warnings.catch_warnings(record=True) as w:\n"
        "        warnings.simplefilter('always')\n"
        "        same.append(getattr(L, n) is getattr(P, n))\n"
        "    msgs.append([(x.category.__name__, str(x.message)) for x in w])\n"
        "print(json.dumps([before, star, same, msgs, sorted(L.__all__) == sorted(set(L.__all__))]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    before, star, same, msgs, unique = json.loads(out.stdout)
    assert before is False and star is False, "importing ght_cad.loft must not import the optimize layer"
    assert same == [True] * 5 and unique
    names = ("LoftProblem", "LOFT_OBJECTIVES", "LoftGradientFallback", "loft_measures_and_gradients", "LoftProblem")
    for name, m in zip(names, msgs):
        assert m == [["DeprecationWarning", f"ght_cad.developables.loft.{name} moved to ght_cad.optimize.problems.loft.{name}; "
                      "import it from there (the old name goes in the next minor release)"]], m


def test_unknown_name_is_an_attribute_error() -> None:
    import ght_cad.loft as loft

    with pytest.raises(AttributeError, match="module 'ght_cad.developables.loft' has no attribute 'LoftSolver'"):
        loft.LoftSolver  # noqa: B018
