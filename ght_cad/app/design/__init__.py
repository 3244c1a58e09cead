r"""Design files (TOML): schema, validation and the pipeline runner behind ``ght-cad run``/``demo``.

A design file describes GHT-Bézier curves (control points and shape parameters, optional joins),
one surface or several named ones (an enveloping developable from control planes, spec 5.2, a
ruled strip between two curves, the exact developable loft between two rails, spec 5.7, or a
composite of developable strips joined G1/G2/G3, spec 5.6), an optional
shape-parameter optimization (of one strip, or of every strip of a composite with its joints kept) and the
outputs to write. The schema is
documented in ``docs/design-files.md``; :func:`parse_design` validates a parsed file completely
before anything is computed, and every error is one line naming the file, the key and the
allowed values, raised as :class:`DesignError` (a :class:`~ght_cad.core.errors.GHTError`, so
``ght-cad`` exits with code 2).

:func:`run_design` computes everything into a temporary folder beside the output folder and moves
the files in only when every step succeeded, so a failure leaves the output folder untouched.

:func:`unroll_step` unrolls the developable faces of a STEP file made by any CAD tool (one panel
per face), for ``ght-cad unroll FILE.step``.

Imports numpy at module level only; scipy, matplotlib and the CAD kernel are imported inside the
functions that need them.

The package follows the pipeline, one module per stage:

* :mod:`~ght_cad.app.design.schema`: the dataclasses and :func:`parse_design` / :func:`load_design`;
* :mod:`~ght_cad.app.design.build`: curves (joins applied and measured) and the surface(s);
* :mod:`~ght_cad.app.design.objectives` and :mod:`~ght_cad.app.design.optimize`: fairness / developability
  objectives and :func:`optimize_design`;
* :mod:`~ght_cad.app.design.outputs`: B-rep, STEP, flat pattern and :func:`export_files`;
* :mod:`~ght_cad.app.design.report`: ``report.md``;
* :mod:`~ght_cad.app.design.run`: :func:`run_design`, the whole pipeline into one output folder;
* :mod:`~ght_cad.app.design.step_input`: :func:`unroll_step`.

Every name is re-exported here; import from ``ght_cad.app.design``.
"""

from __future__ import annotations

from .schema import (  # noqa: F401
    CONTINUITIES,
    CurveSpec,
    Design,
    DesignError,
    FIGURE_NAMES,
    FIGURE_OUTPUTS,
    FILE_NAMES,
    FILE_OUTPUTS,
    JoinSpec,
    METHODS,
    OptimizeSpec,
    OutputSpec,
    PLANE_OBJECTIVES,
    RAILS_OBJECTIVES,
    RAIL_ORIENTATIONS,
    SHAPE_NAMES,
    STRIP_JOINS,
    STRIP_OBJECTIVES,
    SURFACE_TYPES,
    SegmentSpec,
    SurfaceSpec,
    UNITS,
    UnrollSpec,
    default_objective,
    load_design,
    parse_design,
    parse_design_text,
    _Checker,
    _SEGMENT_KEYS,
    _TOP_KEYS,
    _composite_parameters,
    _objectives_for,
    _parse_composite,
    _parse_surface,
    _parse_surfaces,
    _range_text,
    _shape_names,
    _short,
    _tname,
    _weight_names,
)
from .objectives import (  # noqa: F401
    composite_dual_objectives,
    dual_curve_objectives,
    _fairness_value,
    _gauss_legendre,
)
from .build import (  # noqa: F401
    BuiltSurface,
    GHT_DEFINITION,
    build_curves,
    build_surface,
    build_surfaces,
    check_sheet,
    make_loft,
    ruled_area,
    sheet_part_label,
    sheet_parts,
    surface_area,
    surface_designs,
    surface_summary,
    surface_view,
    surfaces_summary,
    _CompositeView,
    _composite_summary,
    _developability_dict,
    _initial_shape,
    _is_composite,
    _is_loft,
    _joined_curves,
    _make_composite,
    _make_surface,
    _worst,
)
from .optimize import (  # noqa: F401
    CANDIDATE_LOFT_SAMPLES,
    OptimizationOutcome,
    SHEET_MARGIN,
    composite_objective,
    composite_value_and_grad,
    optimize_design,
    thickness_factor,
    _composite_before_after,
    _composite_candidate,
    _composite_joint_rows,
    _objective_fn,
    _rails_objective_fn,
)
from .outputs import (  # noqa: F401
    brep_face,
    brep_shape,
    brep_shapes,
    curve_edges,
    export_files,
    export_step,
    pattern_errors,
    pattern_report,
    plot_pattern,
    sew_shell,
    shared_edge_count,
    unroll_surface,
    plate_solids,
    design_plates,
    resolve_design_sheets,
    unroll_surfaces,
    _export_one,
    _jsonable,
    _ruled_face,
)
from .report import (  # noqa: F401
    report_markdown,
    _f,
    _strips_section,
    _surface_section,
)
from .run import (  # noqa: F401
    run_design,
    _curves_report,
    _versions,
)
from .step_input import (  # noqa: F401
    MM_PER_UNIT,
    STEP_SUFFIXES,
    StepUnroll,
    unroll_step,
    _STEP_UNIT_NAMES,
    _face_type_name,
    _read_step_in,
    _step_unit,
)

__all__ = [
    "DesignError",
    "Design",
    "CurveSpec",
    "JoinSpec",
    "SegmentSpec",
    "SurfaceSpec",
    "OptimizeSpec",
    "UnrollSpec",
    "OutputSpec",
    "FILE_OUTPUTS",
    "FIGURE_OUTPUTS",
    "load_design",
    "parse_design",
    "parse_design_text",
    "build_curves",
    "build_surface",
    "build_surfaces",
    "surface_designs",
    "surfaces_summary",
    "make_loft",
    "BuiltSurface",
    "brep_shape",
    "brep_shapes",
    "sew_shell",
    "shared_edge_count",
    "surface_view",
    "unroll_step",
    "StepUnroll",
    "MM_PER_UNIT",
    "surface_summary",
    "optimize_design",
    "unroll_surface",
    "plate_solids",
    "design_plates",
    "resolve_design_sheets",
    "unroll_surfaces",
    "pattern_errors",
    "export_step",
    "export_files",
    "plot_pattern",
    "run_design",
    "dual_curve_objectives",
    "composite_dual_objectives",
    "composite_objective",
    "composite_value_and_grad",
    "check_sheet",
    "sheet_parts",
    "thickness_factor",
    "SHEET_MARGIN",
]
