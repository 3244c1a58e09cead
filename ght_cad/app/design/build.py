r"""Building a validated design: its GHT curves (joins applied and measured) and its surface.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Sequence

import numpy as np

from ...core.errors import GHTError
from .objectives import dual_curve_objectives
from .schema import SHAPE_NAMES, Design, DesignError, SurfaceSpec


GHT_DEFINITION = (
    "GHT seed (this project's definition, spec section 1): f0 = (1-w)(1-s)(1-mu s) + w(1-t)^2, "
    "f2 = (1-w)(1-c)(1-nu c) + w t^2, f1 = 1 - f0 - f2, s = sin(pi t/2), c = cos(pi t/2), "
    "w = (1+gamma)/2; degree m: b_i,m = B_i,m-2 f0 + B_i-1,m-2 f1 + B_i-2,m-2 f2"
)


def build_curves(design: Design, shape: dict[str, float] | None = None) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """GHT curves of the design with its joins applied, and a measured report per join.

    Joins are applied in file order: ``second`` gets its first ``r+1`` control points re-solved
    (:func:`ght_cad.curves.continuity.join`) so that the joint ``first(1) → second(0)`` has the requested
    continuity; :func:`ght_cad.curves.continuity.measure_continuity` then measures it independently.

    Args:
        design: a validated design.
        shape: for a ``curves`` or ``rails`` surface, strip shape parameters ``{"a.mu", ..., "b.gamma"}`` (any
            subset) that replace the file's ``mu, nu, gamma`` of ``curve_a`` / ``curve_b``
            *before* the joins, so that joined curves follow them (as after an optimization).

    Returns:
        ``({name: GHTCurve}, [join report dicts])``.
    """
    return _joined_curves(design, shape, measure=True)


def _joined_curves(design: Design, shape: dict[str, float] | None, *, measure: bool) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """:func:`build_curves`; ``measure=False`` skips the join reports (optimizer candidates)."""
    from ...curves.curve import GHTCurve

    side_of: dict[str, str] = {}
    if shape and design.surface is not None and design.surface.type in ("curves", "rails"):
        side_of = {str(design.surface.curve_a): "a", str(design.surface.curve_b): "b"}
    curves: dict[str, Any] = {}
    for c in design.curves:
        sh = {"mu": c.mu, "nu": c.nu, "gamma": c.gamma}
        if c.name in side_of:
            sh.update({k: float(shape[f"{side_of[c.name]}.{k}"]) for k in SHAPE_NAMES  # type: ignore[index]
                       if f"{side_of[c.name]}.{k}" in shape})  # type: ignore[operator]
        curves[c.name] = GHTCurve(c.control_points, sh["mu"], sh["nu"], sh["gamma"])
    reports = []
    for i, j in enumerate(design.joins):
        from ...curves.continuity import join, measure_continuity

        a, b = curves[j.first], curves[j.second]
        if a.dim != b.dim:
            raise DesignError(
                f"{design.source}: key 'joins': curves {j.first!r} (dim {a.dim}) and {j.second!r} (dim {b.dim}) "
                "have different dimensions; allowed: curves of the same dimension"
            )
        geometric = j.continuity.startswith("G")
        kw = {"k": j.k, "beta2": j.beta2, "beta3": j.beta3} if geometric else {}
        try:
            curves[j.second] = join(a, j.continuity, b, **kw)
        except DesignError:
            raise
        except GHTError as exc:
            raise type(exc)(f"{design.source}: key 'joins[{i}]': {' '.join(str(exc).split())}") from None
        if not measure:
            continue
        rep = measure_continuity(a, curves[j.second])
        reports.append(
            {
                "first": j.first,
                "second": j.second,
                "requested": j.continuity,
                "achieved_C": int(rep.c_order),
                "achieved_G": int(rep.g_order),
                "satisfied": bool(rep.satisfies(j.continuity)),
                "c_residuals": [float(x) for x in rep.c_residuals],
                "g_residuals": [float(x) for x in rep.g_residuals],
                "tol": float(rep.tol),
            }
        )
    return curves, reports


@dataclass
class BuiltSurface:
    """A design's surface with the shape parameters it was built with."""

    design: Design
    surface: Any
    curves: dict[str, Any]
    shape: dict[str, float]
    #: ``design.sheet`` is this surface's own sheet of a ``[[surfaces]]`` design (side on its own
    #: normal, overrides applied: :func:`ght_cad.app.design.shell_sheet.apply_sheets`)
    sheet_resolved: bool = False


def _initial_shape(design: Design, curves: dict[str, Any]) -> dict[str, float]:
    spec = design.surface
    assert spec is not None
    if spec.type == "planes":
        return {"mu": spec.mu, "nu": spec.nu, "gamma": spec.gamma}
    if spec.type == "approximate":  # no shape parameters of its own (ght_cad.approximate fits them)
        return {}
    if spec.type == "composite":
        return {f"{g.name}.{k}": float(getattr(g, k)) for g in spec.segments or [] for k in SHAPE_NAMES}
    out = {}
    for side, cname in (("a", spec.curve_a), ("b", spec.curve_b)):
        c = curves[cname]
        out.update({f"{side}.mu": c.mu, f"{side}.nu": c.nu, f"{side}.gamma": c.gamma})
    return out


def _make_surface(design: Design, curves: dict[str, Any], shape: dict[str, float]) -> Any:
    spec = design.surface
    assert spec is not None
    if spec.type == "planes":
        from ...developables.envelope import developable_from_planes

        return developable_from_planes(
            spec.planes, spec.boundary_planes, shape["mu"], shape["nu"], shape["gamma"], normalize=spec.normalize
        )
    if spec.type == "composite":
        return _make_composite(design, shape)
    if spec.type == "approximate":
        from .approximate import build_approximation

        return build_approximation(spec, design.source)
    ca = curves[spec.curve_a].with_shape(shape["a.mu"], shape["a.nu"], shape["a.gamma"])
    cb = curves[spec.curve_b].with_shape(shape["b.mu"], shape["b.nu"], shape["b.gamma"])
    if spec.type == "rails":
        return make_loft(spec, ca, cb)
    from ...surfaces.ruled import CurvePairRuledSurface

    return CurvePairRuledSurface(ca, cb)


def make_loft(spec: SurfaceSpec, rail_a: Any, rail_b: Any, **options: Any) -> Any:
    r"""The exact developable loft of a ``rails`` surface (:func:`ght_cad.developable_loft`, spec 5.7):
    the rulings ``a(t)–b(σ(t))`` solve ``det(a'(t), b'(s), b(s) - a(t)) = 0``, fans at the rail ends.

    Raises:
        NotDevelopableError: no developable joins the rails over their whole length (the loft
            core's message).
    """
    from ...developables.loft import developable_loft

    return developable_loft(rail_a, rail_b, orientation=spec.orientation, **options)


def _make_composite(design: Design, shape: dict[str, float]) -> Any:
    r"""Strips of a ``composite`` surface: strip 0 from its planes, strip i joined to strip i-1.

    Join (spec 5.6): the 4-D dual curves meet with ``V(0) = U(1)`` and G1 ``V' = k U'``,
    G2 ``V'' = k² U'' + β2 U'``, G3 ``V''' = k³ U''' + 3kβ2 U'' + β3 U'``
    (:func:`ght_cad.developables.envelope.join_developable`); all strips share the boundary planes, so
    consecutive strips share their joint ruling segment.

    Raises:
        GHTError: a join that cannot be solved or a degenerate strip, naming the segment.
    """
    from ...developables.envelope import CompositeDevelopable, developable_from_planes, join_developable
    from ...surfaces.planes import normalize_planes

    spec = design.surface
    assert spec is not None and spec.segments
    segs: list[Any] = []
    for i, g in enumerate(spec.segments):
        P = np.asarray(g.planes, dtype=float)
        if spec.normalize:
            P = normalize_planes(P)
        sh = {k: shape[f"{g.name}.{k}"] for k in SHAPE_NAMES}
        try:
            if i == 0:
                segs.append(developable_from_planes(P, spec.boundary_planes, sh["mu"], sh["nu"], sh["gamma"]))
            else:
                segs.append(join_developable(segs[-1], g.continuity or "G1", P, mu=sh["mu"], nu=sh["nu"],
                                             gamma=sh["gamma"], k=g.k, beta2=g.beta2, beta3=g.beta3))
        except GHTError as exc:
            raise type(exc)(f"{design.source}: key '{spec.key}.segments[{i}]' ({g.name}): {' '.join(str(exc).split())}") from None
    try:
        comp = CompositeDevelopable(segs)
    except GHTError as exc:
        raise type(exc)(f"{design.source}: key '{spec.key}.segments': {' '.join(str(exc).split())}") from None
    return comp


def _is_composite(surface: Any) -> bool:
    return hasattr(surface, "segments") and hasattr(surface, "joints")


def sheet_parts(surface: Any) -> list[Any]:
    """The ruled surfaces a ``[sheet]`` is checked on and thickened: every strip of a composite,
    every panel of an approximation (its exact developable), else the surface itself (a
    developable loft as a whole, fans included)."""
    if _is_approximation(surface):
        return list(surface.parts)
    return list(surface.segments) if _is_composite(surface) else [surface]


def _is_approximation(surface: Any) -> bool:
    from .approximate import is_approximation

    return is_approximation(surface)


def sheet_part_label(design: Design, i: int) -> str:
    """Name of part ``i`` (0-based) of the design's plate in messages: ``"<design name> part <i+1>"``."""
    return f"{design.name} part {i + 1}"


def inside_radius(surface: Any, side: str, thickness: float, *, samples: int = 513) -> float:
    r"""The smallest inside bending radius of a sheet on the surface (spec 6.1).

    Over :func:`sheet_parts`, at ``samples`` rulings and both ruling ends (the grid of
    :func:`ght_cad.sheetmetal.sheet.check_offset`): the design surface has the signed bending radius
    ``ρ_0 = (X_u·e)/ω`` (:func:`ght_cad.sheetmetal.sheet.bending_radius`), the other skin ``ρ_0 + σ T``
    (``σ = +1`` for ``side="normal"``, -1 for ``"reverse"``), and the inside radius of the bend is
    the smaller one, ``R = min(|ρ_0|, |ρ_0 + σ T|)``; apex ends (a stationary boundary, the point of
    a cone or fan) are skipped as in ``check_offset``. ``inf`` for a flat surface.
    """
    from ...surfaces.ruled import SINGULAR_NORMAL_TOL
    from ...sheetmetal.sheet import bending_radius

    sigma = 1.0 if side == "normal" else -1.0
    u = np.linspace(0.0, 1.0, samples)
    uu, vv = np.concatenate([u, u]), np.concatenate([np.zeros_like(u), np.ones_like(u)])
    best = math.inf
    for part in sheet_parts(surface):
        rho = bending_radius(part, uu, vv)
        g = np.linalg.norm(part.ruling(u), axis=1)
        tang = np.concatenate([np.linalg.norm(part.a(u, 1), axis=1), np.linalg.norm(part.b(u, 1), axis=1)])
        rho = np.where(tang <= SINGULAR_NORMAL_TOL * np.concatenate([g, g]), np.inf, rho)
        fin = np.isfinite(rho)
        if fin.any():
            r = np.minimum(np.abs(rho[fin]), np.abs(rho[fin] + sigma * thickness))
            best = min(best, float(r.min()))
    return best


def table_k_factor(sheet: Any, surface: Any) -> Any:
    r"""The ``[sheet]`` with its ``k_factor_table`` read at the surface's ``R / T``.

    ``K = table(R / T)``, ``R`` the smallest inside bending radius (:func:`inside_radius`: the
    tightest bend, where K matters most; ``R = inf`` on a flat surface, the table's last row);
    the sheet unchanged when it has no table or ``T = 0``.

    Args:
        sheet: a :class:`ght_cad.app.design.schema.SheetSpec`; surface: the built surface.

    Returns:
        The SheetSpec with ``k_factor = table(R/T)`` and ``k_factor_ratio = R/T``.
    """
    if sheet is None or sheet.k_factor_table is None or sheet.thickness <= 0:
        return sheet
    R = inside_radius(surface, sheet.side, sheet.thickness)
    return replace(sheet, k_factor=float(sheet.k_factor_table(R, sheet.thickness)), k_factor_ratio=R / sheet.thickness)


def check_sheet(design: Design, surface: Any, *, sheet: Any = None, samples: int = 513) -> float:
    r"""The sheet check the run applies to a built surface (spec 6.1), on every part.

    For each part of :func:`sheet_parts` :func:`ght_cad.sheetmetal.sheet.check_offset` (the rule the plate
    solid and the flat pattern of ``ght-cad run`` apply, with their default ``samples = 513``
    rulings, both ends of each): refused when the neutral offset reaches a bending radius,
    ``|K T| >= |ρ_0|``, when the material reaches a centre of curvature, ``ρ_0 (ρ_0 + σ T) <= 0``, or
    when the material lies on the concave side of an apex (``ρ_0 = 0``: a cone point, a loft fan).

    Args:
        design: the design (its ``[sheet]`` and its name for the messages).
        surface: the design's built surface (``BuiltSurface.surface``).
        sheet: a :class:`ght_cad.sheetmetal.sheet.Sheet` to check instead of the design's (the optimizer
            passes the sheet with its margin); None: the design's ``[sheet]``.
        samples: rulings per part (>= 2).

    Returns:
        The smallest bending radius ``min |ρ_0|`` over all parts (``inf`` when flat, or when there
        is no sheet or ``T = 0``: nothing to check).

    Raises:
        SheetError: the first part the sheet cannot be made on (the message names the part, the
            ruling, its radius and the bound; ``constraint``, ``radius``, ``limit`` as attributes).
    """
    from ...sheetmetal.sheet import check_offset

    if sheet is None:
        if design.sheet is None:
            return math.inf
        sheet = design.sheet.to_sheet()
    if sheet.is_zero:
        return math.inf
    parts = sheet_parts(surface)
    # an approximation's panels: each with its side on the target's normal (ApproximatedSurface.part_sheets)
    sheets = surface.part_sheets(sheet) if _is_approximation(surface) else [sheet] * len(parts)
    return min(check_offset(part, sh, f"surface {sheet_part_label(design, i)!r}", samples=samples)
               for i, (part, sh) in enumerate(zip(parts, sheets)))


def _developability_dict(surface: Any) -> dict[str, float]:
    """Developability degree of a surface; for a composite the worst strip per quantity
    (θ_max and residual max, θ_rms as the root mean square over strips, DD min, R summed); for an
    approximation the worst panel likewise."""
    if _is_approximation(surface):
        return _worst([p.developability().as_dict() for p in surface.parts])
    if not _is_composite(surface):
        return surface.developability().as_dict()
    return _worst([d.as_dict() for d in surface.developability()])


class _CompositeView:
    """A composite surface seen as one ruled strip for plots: ``grid`` and ``theta`` by strip."""

    def __init__(self, composite: Any) -> None:
        self.segments = list(getattr(composite, "segments", composite))

    def _split(self, n: int) -> list[int]:
        k = len(self.segments)
        return [max(2, n // k + (1 if i < n % k else 0)) for i in range(k)]

    def grid(self, nu: int, nv: int) -> np.ndarray:
        return np.concatenate([s.grid(m, nv) for s, m in zip(self.segments, self._split(int(nu)))], axis=0)

    def theta(self, u: Any) -> np.ndarray:
        n = int(np.size(u))
        return np.concatenate([np.asarray(s.theta(np.linspace(0.0, 1.0, m)), dtype=float)
                               for s, m in zip(self.segments, self._split(n))])


class _StackedView:
    """Several surfaces in one plot: their grids side by side across the rulings (``v``), so
    surfaces that follow each other through a shared rail (keel–chine, chine–sheer) meet along it;
    ``theta`` is the largest of the surfaces' at each ``u``."""

    def __init__(self, parts: Sequence[Any]) -> None:
        self.parts = list(parts)

    def grid(self, nu: int, nv: int) -> np.ndarray:
        return np.concatenate([p.grid(nu, nv) for p in self.parts], axis=1)

    def theta(self, u: Any) -> np.ndarray:
        return np.max([np.asarray(p.theta(u), dtype=float) for p in self.parts], axis=0)


def surface_designs(design: Design) -> list[Design]:
    """One single-surface design per surface of ``design`` (for a ``[surface]`` design: itself).

    The surface of entry ``i`` of ``[[surfaces]]`` is built, measured and unrolled exactly as the
    same table given as ``[surface]`` (its name is the design name of the sub-design, so panels and
    plots are labelled with it); errors name ``surfaces[i]``.
    """
    if design.surface is not None and design.surfaces == [design.surface] and design.surface.name is None:
        return [design]
    return [replace(design, name=str(spec.name), surface=spec, surfaces=[spec], optimize=design.optimize)
            for spec in design.surfaces]


def build_surfaces(design: Design, curves: dict[str, Any] | None = None) -> list["BuiltSurface"]:
    """Every surface of the design built with the file's shape parameters (:func:`build_surface`).

    Raises:
        GHTError: a surface that cannot be built; the message names ``surfaces[i]`` and the surface
            (or ``surface``).
    """
    if curves is None:
        curves, _ = build_curves(design)
    return [build_surface(sub, curves=curves) for sub in surface_designs(design)]


def surface_view(built: "BuiltSurface | Sequence[BuiltSurface]") -> Any:
    """What :func:`ght_cad.curves.plotting.plot_surface` draws: the surface, all strips of a composite, or
    for several built surfaces all of them."""
    if isinstance(built, (list, tuple)):
        if len(built) == 1:
            return surface_view(built[0])
        return _StackedView([surface_view(b) for b in built])
    if _is_approximation(built.surface):  # panels side by side across the rulings, sharing their seams
        return _StackedView(built.surface.parts)
    return _CompositeView(built.surface) if _is_composite(built.surface) else built.surface


def build_surface(design: Design, shape: dict[str, float] | None = None,
                  curves: dict[str, Any] | None = None) -> BuiltSurface:
    """Build the design's surface with its own (or the given) shape parameters.

    Raises:
        DesignError: the design has no [surface] table.
        GHTError: degenerate geometry (parallel planes, edge of regression inside the strip, ...).
    """
    if design.surface is None:
        if design.surfaces:
            raise DesignError(f"{design.source}: key 'surfaces': this works on one surface and the design has "
                              f"{len(design.surfaces)} [[surfaces]]; allowed: ght-cad run, export or unroll "
                              "(every surface), or a design with one surface")
        raise DesignError(f"{design.source}: key 'surface': missing; this command needs a [surface] table")
    if curves is None:
        curves, _ = build_curves(design)
    sh = dict(_initial_shape(design, curves))
    if shape:
        sh.update(shape)
    try:
        surf = _make_surface(design, curves, sh)
    except DesignError:
        raise
    except GHTError as exc:
        spec = design.surface
        msg = " ".join(str(exc).split())
        what = f" (surface {spec.name!r})" if spec.name is not None else ""
        if msg.startswith(f"{design.source}: key '{spec.key}"):  # already names the file and key (a strip)
            if not what:
                raise
            raise type(exc)(msg + what) from None
        raise type(exc)(f"{design.source}: key '{spec.key}'{what}: {msg}") from None
    if design.sheet is not None and design.sheet.k_factor_table is not None:
        design = replace(design, sheet=table_k_factor(design.sheet, surf))  # K by this surface's R/T
    return BuiltSurface(design, surf, curves, sh)


def _is_loft(surface: Any) -> bool:
    return hasattr(surface, "segments") and hasattr(surface, "report") and hasattr(surface, "breakpoints")


def surface_area(surface: Any) -> float:
    """3-D area: of a loft the sum over its segments (:meth:`DevelopableLoft.area`), else :func:`ruled_area`."""
    return float(surface.area()) if _is_loft(surface) else ruled_area(surface)


def ruled_area(surface: Any, nodes: int = 64) -> float:
    r"""Area ``∫_0^1 ∫_0^1 |X_u × X_v| dv du`` of a ruled surface (Gauss–Legendre, both directions)."""
    from ...curves.curve import gauss_legendre

    t, w = gauss_legendre(nodes)
    v, wv = gauss_legendre(16)
    U = np.repeat(t, v.size)
    V = np.tile(v, t.size)
    xu, xv = surface.partials(U, V)
    dens = np.linalg.norm(np.cross(xu, xv), axis=1)
    return float(np.sum(dens * np.repeat(w, v.size) * np.tile(wv, t.size)))


def surface_summary(built: BuiltSurface) -> dict[str, Any]:
    """Developability degree (θ_max, θ_rms, DD, R), area and shape parameters of a built surface.

    A composite surface also gets ``surface.strips`` (per strip: name, shape parameters, area,
    ruling lengths, developability) and ``surface.joints`` (per joint: requested continuity, the
    order measured by :func:`ght_cad.developables.envelope.measure_developable_joint`, its residuals, the
    angle between the end tangent planes and the ruling distance); ``developability`` is then the
    worst strip's (see ``_developability_dict``).
    """
    s = built.surface
    if _is_composite(s):
        return _composite_summary(built)
    if _is_approximation(s):
        return _approximation_summary(built)
    dev = s.developability()
    out: dict[str, Any] = {
        "surface": {
            "type": built.design.surface.type if built.design.surface else None,
            "shape_parameters": dict(built.shape),
            "area_3d": surface_area(s),
            "ruling_length_min": float(np.min(s.ruling_lengths(np.linspace(0, 1, 257)))),
            "ruling_length_max": float(np.max(s.ruling_lengths(np.linspace(0, 1, 257)))),
        },
        "developability": dev.as_dict(),
    }
    spec = built.design.surface
    if spec is not None and spec.type == "planes":
        out["surface"]["control_planes"] = np.asarray(s.planes).tolist()
        out["surface"]["boundary_planes"] = np.asarray(s.boundary_planes).tolist()
        out["surface"]["normalized"] = bool(spec.normalize)
        out["surface"]["edge_of_regression"] = "outside the strip (checked on construction)"
    if _is_loft(s):
        loft = s.report.as_dict()
        loft["fairness"] = float(s.fairness())
        loft["curve_a"], loft["curve_b"] = spec.curve_a, spec.curve_b
        out["surface"]["loft"] = loft
    return out


def _approximation_summary(built: BuiltSurface) -> dict[str, Any]:
    """``report["surface"]`` and ``report["developability"]`` of an ``approximate`` surface: area,
    ruling lengths, the worst panel's developability and ``surface.approximation``
    (:func:`ght_cad.app.design.approximate.approximation_report`: per panel max deviation out/in,
    θ_max, area; the panel count and largest deviation)."""
    from .approximate import approximation_report

    s = built.surface
    u = np.linspace(0, 1, 257)
    lengths = np.concatenate([np.asarray(p.ruling_lengths(u), dtype=float) for p in s.parts])
    res = approximation_report(s.result, name=built.design.name, method=s.method, info=False)
    return {
        "surface": {
            "type": "approximate",
            "shape_parameters": {},
            "area_3d": float(res["total_area"]),
            "ruling_length_min": float(lengths.min()),
            "ruling_length_max": float(lengths.max()),
            "approximation": res,
        },
        "developability": _developability_dict(s),
    }


def surfaces_summary(builts: Sequence[BuiltSurface]) -> dict[str, Any]:
    """:func:`surface_summary` of a single surface; for several, ``surfaces`` (per surface: its name
    and summary) and ``developability``, the worst surface's per quantity (θ_max and residual max,
    θ_rms as the root mean square over surfaces, DD min, R summed)."""
    if len(builts) == 1:
        return surface_summary(builts[0])
    rows = [{"name": b.design.name, **surface_summary(b)} for b in builts]
    return {"surfaces": rows, "developability": _worst([r["developability"] for r in rows])}


def _worst(ds: Sequence[dict[str, float]]) -> dict[str, float]:
    """Per quantity the worst of several developability dicts (θ_max, θ_rms, DD, R, residual_max)."""
    return {
        "theta_max": max(d["theta_max"] for d in ds),
        "theta_rms": float(math.sqrt(sum(d["theta_rms"] ** 2 for d in ds) / len(ds))),
        "dd": min(d["dd"] for d in ds),
        "R": float(sum(d["R"] for d in ds)),
        "residual_max": max(d["residual_max"] for d in ds),
    }


def _composite_summary(built: BuiltSurface) -> dict[str, Any]:
    from ...unrolling.unroll import ruled_area as exact_area

    comp = built.surface
    spec = built.design.surface
    assert spec is not None and spec.segments
    u = np.linspace(0, 1, 257)
    strips = []
    for g, seg, dev in zip(spec.segments, comp.segments, comp.developability()):
        L = seg.ruling_lengths(u)
        strips.append({
            "name": g.name,
            "shape_parameters": {k: float(built.shape.get(f"{g.name}.{k}", getattr(g, k))) for k in SHAPE_NAMES},
            "control_planes": np.asarray(seg.planes).tolist(),
            "dual_curve_fairness": dual_curve_objectives(seg.dual_curve),
            "area_3d": exact_area(seg),
            "ruling_length_min": float(np.min(L)),
            "ruling_length_max": float(np.max(L)),
            "developability": dev.as_dict(),
        })
    joints = []
    for i, (g, rep) in enumerate(zip(spec.segments[1:], comp.joints())):
        joints.append({
            "first": spec.segments[i].name,
            "second": g.name,
            "requested": g.continuity,
            "k": g.k,
            "beta2": g.beta2,
            "beta3": g.beta3,
            "achieved_G": int(rep.order),
            "satisfied": bool(rep.satisfies(g.continuity or "G1")),
            "residuals": [float(r) for r in rep.residuals],
            "plane_angle_deg": float(rep.plane_angle),
            "ruling_distance": float(rep.ruling_distance),
            "tol": float(rep.tol),
        })
    return {
        "surface": {
            "type": "composite",
            "shape_parameters": dict(built.shape),
            "area_3d": float(sum(x["area_3d"] for x in strips)),
            "ruling_length_min": min(x["ruling_length_min"] for x in strips),
            "ruling_length_max": max(x["ruling_length_max"] for x in strips),
            "boundary_planes": np.asarray(comp.segments[0].boundary_planes).tolist(),
            "normalized": bool(spec.normalize),
            "strips": strips,
            "joints": joints,
        },
        "developability": _developability_dict(comp),
    }
