r"""build123d / OCP front end of the exact developable loft between two rails (spec section 5.7).

:func:`developable_loft` takes two rails as CAD edges (build123d or cadquery ``Edge``/``Wire``,
OCP ``TopoDS_Edge``/``TopoDS_Wire``, any curve type: B-spline, circle, ellipse, line, ...) or
:class:`~ght_cad.curves.curve.GHTCurve` objects, runs the core :func:`ght_cad.developables.loft.developable_loft`
(the branch ``F(t, s) = det(a'(t), b'(s), b(s) - a(t)) = 0`` traced to round-off, fans at the
rail ends) and returns its B-rep: one B-spline face per segment (main part and fans, degree 1
across the rulings, the boundary curves fitted together so pole pair ``i`` spans one ruling:
:meth:`ght_cad.developables.loft.DevelopableLoft.bspline_data`) sewn along the joint rulings into one
``Shell`` (a single ``Face`` when the loft has one segment).

Edges become rails through :class:`OCPCurveRail`: ``r(t) = C(p(t))`` with the edge's parameter
``p(t) = p_0 + t (p_1 - p_0)`` (``p(t) = p_1 - t (p_1 - p_0)`` for a reversed edge, so the rail
runs from the edge's start vertex to its end vertex), ``r^(k)(t) = (±(p_1 - p_0))^k C^(k)(p)``
from OCCT's exact ``BRepAdaptor_Curve.DN`` (``BRepAdaptor_CompCurve`` for a wire of several
G1-joined edges).

Accuracy (certified, not assumed): every face's edges on the rails lie within its fit's
``max_deviation`` (<= ``tol``, default ``1e-7 ×`` the segment size) of the exact rails at matched
parameters; joint rulings are exact end poles of both faces, so sewing (tolerance ``1e-6 ×`` size)
turns them into shared edges; θ of every face, measured from OCCT normals, is below 1e-3°.

Builder mode: inside ``BuildPart`` the faces are added to the builder's pending faces (as
build123d's ``add`` does with faces), e.g. for ``thicken``; ``mode=Mode.PRIVATE`` adds nothing.
Algebra mode: the returned shape is a plain build123d ``Shell``/``Face``. The core loft (report,
``unroll``, ``sigma``) is attached as ``shape.ght_loft`` and the B-spline data as
``shape.ght_bspline``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from OCP.BRepAdaptor import BRepAdaptor_CompCurve, BRepAdaptor_Curve
from OCP.BRepBuilderAPI import BRepBuilderAPI_Sewing
from OCP.TopAbs import TopAbs_EDGE, TopAbs_REVERSED
from OCP.TopExp import TopExp_Explorer
from OCP.TopoDS import TopoDS_Edge, TopoDS_Shape, TopoDS_Wire
from ._ocp import TopoDS

from ..core._validate import as_parameter_array
from ..curves.curve import GHTCurve
from ..core.errors import ConversionError, GHTError
from .developable_faces import sew_shell
from .occ import is_valid, make_face, shape_class, unwrap

__all__ = ["OCPCurveRail", "rail_of", "developable_loft", "loft_shape", "LOFT_OPTIONS"]

#: keyword options passed on to the core :func:`ght_cad.developables.loft.developable_loft`
LOFT_OPTIONS = ("orientation", "branch", "max_step", "step_tol", "samples", "boundary_samples")


class OCPCurveRail:
    r"""A rail ``r(t)``, t ∈ [0, 1], on an OCP edge or wire (any curve type).

    ``r(t) = C(p(t))``, ``p(t) = p_0 + t (p_1 - p_0)`` on the edge's parameter range (reversed
    edges run from ``p_1`` to ``p_0``), derivatives ``r^(k)(t) = (dp/dt)^k C^(k)(p(t))`` for
    k = 1..3, the edge's location included. Lines, circles, ellipses, Bézier and (rational)
    B-spline curves are evaluated in closed form with numpy on the adaptor's placed geometry
    (``O + R(cos p X + sin p Y)``, ``C = A/w`` with ``C^(k) = (A^(k) - Σ_j binom(k,j) w^(j)
    C^(k-j)) / w``; the core evaluates millions of points); other curve types call OCCT's
    ``BRepAdaptor_Curve.DN`` point by point. A wire of
    several edges is one curve through ``BRepAdaptor_CompCurve`` (its parameter is the sum of the
    edges' ranges; the edges should meet G1, else the loft finds no smooth branch across a kink).

    Args:
        shape: ``TopoDS_Edge``/``TopoDS_Wire`` or a build123d/cadquery ``Edge``/``Wire``.
        name: label used in error messages.

    Raises:
        GHTError: not an edge or wire, a degenerated edge, or an unbounded parameter range.
    """

    def __init__(self, shape: Any, name: str = "rail") -> None:
        raw = unwrap(shape)
        self.name = name
        if not isinstance(raw, TopoDS_Shape) or raw.IsNull():
            raise GHTError(f"{name} is a {type(shape).__name__}; expected an edge or a wire")
        edges = []
        exp = TopExp_Explorer(raw, TopAbs_EDGE)
        while exp.More():
            edges.append(TopoDS.Edge_s(exp.Current()))
            exp.Next()
        if isinstance(raw, TopoDS_Wire) or raw.ShapeType().name == "TopAbs_WIRE":
            wire = TopoDS.Wire_s(raw)
            if len(edges) == 1:
                raw = edges[0]
            else:
                self._curve: Any = BRepAdaptor_CompCurve(wire)
                self._reversed = False
        elif not (isinstance(raw, TopoDS_Edge) or raw.ShapeType().name == "TopAbs_EDGE"):
            raise GHTError(f"{name} is a {raw.ShapeType().name[7:].lower()}; a rail is an edge or a wire")
        if raw.ShapeType().name == "TopAbs_EDGE":
            edge = TopoDS.Edge_s(raw)
            from OCP.BRep import BRep_Tool

            if BRep_Tool.Degenerated_s(edge):
                raise GHTError(f"{name} is a degenerated edge (a point); a rail must be a curve")
            self._curve = BRepAdaptor_Curve(edge)
            self._reversed = edge.Orientation() == TopAbs_REVERSED
        p0, p1 = float(self._curve.FirstParameter()), float(self._curve.LastParameter())
        if not (math.isfinite(p0) and math.isfinite(p1) and p1 > p0):
            raise GHTError(f"{name} has the parameter range [{p0:g}, {p1:g}]; a rail needs a bounded edge")
        self.p_range = (p0, p1)
        self._exact = self._closed_form()

    def _closed_form(self) -> Any:
        """``f(p, k) -> C^(k)(p)`` (vectorized numpy, exact) for lines, circles, ellipses, Bézier
        and B-spline curves (rational too) in the edge's own parameter; None for other types
        (then OCCT's ``DN`` is called point by point)."""
        from OCP.GeomAbs import GeomAbs_BezierCurve, GeomAbs_BSplineCurve, GeomAbs_Circle, GeomAbs_Ellipse, GeomAbs_Line

        c = self._curve
        kind = c.GetType()

        def xyz(v: Any) -> np.ndarray:
            return np.array([v.X(), v.Y(), v.Z()])

        if kind == GeomAbs_Line:
            ln = c.Line()
            o, d = xyz(ln.Location()), xyz(ln.Direction())
            return lambda p, k: o + p[:, None] * d if k == 0 else (np.tile(d, (p.size, 1)) if k == 1 else np.zeros((p.size, 3)))
        if kind in (GeomAbs_Circle, GeomAbs_Ellipse):
            if kind == GeomAbs_Circle:
                g = c.Circle()
                ra = rb = g.Radius()
            else:
                g = c.Ellipse()
                ra, rb = g.MajorRadius(), g.MinorRadius()
            ax = g.Position()
            o, x, y = xyz(ax.Location()), ra * xyz(ax.XDirection()), rb * xyz(ax.YDirection())
            # d^k/dp^k (cos p, sin p) = (cos(p + kπ/2), sin(p + kπ/2))
            return lambda p, k: (o if k == 0 else 0.0) + np.cos(p + k * np.pi / 2)[:, None] * x + np.sin(p + k * np.pi / 2)[:, None] * y
        if kind not in (GeomAbs_BSplineCurve, GeomAbs_BezierCurve):
            return None
        from scipy.interpolate import BSpline

        g = c.BSpline() if kind == GeomAbs_BSplineCurve else c.Bezier()
        if kind == GeomAbs_BSplineCurve and g.IsPeriodic():
            g = g.Copy()  # OCP hands back the Geom_BSplineCurve; never modify the edge's own curve
            g.SetNotPeriodic()
        n = g.NbPoles()
        poles = np.array([xyz(g.Pole(i)) for i in range(1, n + 1)])
        w = np.array([g.Weight(i) for i in range(1, n + 1)]) if g.IsRational() else np.ones(n)
        if kind == GeomAbs_BSplineCurve:
            knots = np.array([g.KnotSequence().Value(i) for i in range(1, g.KnotSequence().Length() + 1)])
        else:
            knots = np.r_[np.zeros(n), np.ones(n)]
        deg = g.Degree()
        lo, hi = knots[deg], knots[-deg - 1]
        p0, p1 = self.p_range
        if p0 < lo - 1e-12 * (hi - lo) or p1 > hi + 1e-12 * (hi - lo):
            return None
        sp = BSpline(knots, np.column_stack([poles * w[:, None], w]), deg, extrapolate=False)

        def f(p: np.ndarray, k: int) -> np.ndarray:
            # C = A / w: C^(k) = (A^(k) - Σ_{j=1..k} binom(k, j) w^(j) C^(k-j)) / w
            q = np.clip(p, lo, hi)
            H = [sp(q, j) for j in range(k + 1)]
            W = [h[:, 3:] for h in H]
            C: list[np.ndarray] = []
            for r in range(k + 1):
                acc = H[r][:, :3].copy()
                for j in range(1, r + 1):
                    acc -= math.comb(r, j) * W[j] * C[r - j]
                C.append(acc / W[0])
            return C[k]

        return f

    def _param(self, t: np.ndarray) -> tuple[np.ndarray, float]:
        p0, p1 = self.p_range
        if self._reversed:
            return p1 - t * (p1 - p0), -(p1 - p0)
        return p0 + t * (p1 - p0), p1 - p0

    def evaluate(self, t: Any) -> np.ndarray:
        """Points ``r(t)``, shape (n, 3)."""
        return self.derivative(t, 0)

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        """``r^(order)(t) = (dp/dt)^order C^(order)(p(t))`` for order 0..3, shape (n, 3)."""
        if isinstance(order, bool) or order not in (0, 1, 2, 3):
            raise GHTError(f"order={order!r} is not allowed; an edge rail gives derivatives of order 0..3")
        tt, _ = as_parameter_array(t, "t")
        p, dp = self._param(tt)
        if self._exact is not None:
            return self._exact(p, order) * dp**order
        c = self._curve
        out = np.empty((tt.size, 3))
        if order == 0:
            for i, x in enumerate(p.tolist()):
                q = c.Value(x)
                out[i] = (q.X(), q.Y(), q.Z())
            return out
        k = dp**order
        for i, x in enumerate(p.tolist()):
            v = c.DN(x, order)
            out[i] = (v.X() * k, v.Y() * k, v.Z() * k)
        return out

    def __repr__(self) -> str:
        return f"OCPCurveRail({self.name}, p in [{self.p_range[0]:g}, {self.p_range[1]:g}]{', reversed' if self._reversed else ''})"


def rail_of(obj: Any, name: str = "rail") -> Any:
    """The core rail for a CAD edge/wire (:class:`OCPCurveRail`) or a ght_cad rail (as it is).

    Args:
        obj: build123d/cadquery ``Edge``/``Wire``, OCP ``TopoDS_Edge``/``TopoDS_Wire``, a 3-D
            :class:`~ght_cad.curves.curve.GHTCurve` (exact, no kernel in between), a
            :class:`ght_cad.developables.loft.CallableRail` or any object with ``evaluate``/``derivative``.

    Raises:
        GHTError: anything else (a face, a solid, a number, ...).
    """
    if isinstance(obj, GHTCurve):
        return obj
    raw = unwrap(obj)
    if isinstance(raw, TopoDS_Shape):
        return OCPCurveRail(raw, name)
    if callable(getattr(obj, "evaluate", None)) and callable(getattr(obj, "derivative", None)):
        return obj
    raise GHTError(
        f"{name} is a {type(obj).__name__}; a rail is a build123d/cadquery Edge or Wire, an OCP "
        "TopoDS_Edge/TopoDS_Wire, a 3-D GHTCurve or an object with evaluate(t) and derivative(t, order)"
    )


def _segment_size(loft: Any) -> float:
    pts = np.vstack([loft.a(np.linspace(0, 1, 65)), loft.b(np.linspace(0, 1, 65))])
    return float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))) or 1.0


def loft_shape(loft: Any, *, tol: float | None = None, degree: int = 5, sew_tol: float | None = None) -> Any:
    r"""The B-rep of a core :class:`ght_cad.developables.loft.DevelopableLoft`: one valid B-spline face per
    segment (:meth:`~ght_cad.developables.loft.DevelopableLoft.bspline_data`) sewn into one ``Shell``, or the
    single ``Face`` of a one-segment loft.

    A loft whose first and last rulings coincide (two closed rails, e.g. the circles of a cone)
    is sewn along that ruling too: the shell (or the single face, with a seam edge) is then
    closed around. Shared edges: ``len(segments) - 1`` joint rulings (+1 when closed around).

    Args:
        loft: the core loft.
        tol: fit tolerance per face (default ``1e-7 ×`` the segment size).
        degree: B-spline degree along the rulings' directrix.
        sew_tol: sewing tolerance (default ``1e-6 ×`` the loft size).

    Returns:
        build123d ``Shell`` or ``Face`` with ``.ght_loft`` (the core loft), ``.ght_bspline`` (list
        of BSplineSurfaceData) and ``.ght_max_deviation`` (the certified rail tolerance).

    Raises:
        ConversionError: a face or the sewn shell fails ``BRepCheck_Analyzer``, or sewing did not
            give one shell with the expected shared rulings.
    """
    datas = loft.bspline_data(tol=tol, degree=degree)
    faces = [make_face(d) for d in datas]
    for i, (f, sg) in enumerate(zip(faces, loft.segments)):
        if not is_valid(f):
            raise ConversionError(f"the B-spline face of loft segment {i} ({sg.kind}) is not a valid B-rep")
    size = _segment_size(loft)
    first = np.vstack([loft.a(np.array([0.0])), loft.b(np.array([0.0]))])
    last = np.vstack([loft.a(np.array([1.0])), loft.b(np.array([1.0]))])
    stol = float(sew_tol) if sew_tol is not None else 1e-6 * size
    if not (math.isfinite(stol) and stol > 0):
        raise GHTError(f"sew_tol={sew_tol!r} is not allowed; it must be a finite length > 0")
    closed = float(np.max(np.linalg.norm(first - last, axis=1))) <= stol
    if len(faces) == 1 and not closed:
        shape: Any = faces[0]
    else:
        if len(faces) == 1:
            sewing = BRepBuilderAPI_Sewing(stol)
            sewing.Add(faces[0].wrapped)
            sewing.Perform()
            sewn = sewing.SewedShape()
            if sewn.ShapeType().name != "TopAbs_FACE" or not is_valid(sewn):
                raise ConversionError("sewing the closed one-segment loft did not give one valid face with a seam")
            shape = shape_class("Face")(TopoDS.Face_s(sewn))
        else:
            shape = sew_shell(faces, stol, len(faces) - 1 + (1 if closed else 0))
    from .certified import certify

    return certify(shape, ght_loft=loft, ght_bspline=datas,
                   ght_max_deviation=max(float(d.max_deviation or 0.0) for d in datas))


def developable_loft(
    edge_a: Any,
    edge_b: Any,
    *,
    tol: float | None = None,
    degree: int = 5,
    sew_tol: float | None = None,
    mode: Any = None,
    **options: Any,
) -> Any:
    r"""The exact developable loft between two edges as a build123d ``Shell`` (or ``Face``).

    The rulings ``a(t)–b(σ(t))`` satisfy ``det(a'(t), b'(σ), b(σ) - a(t)) = 0`` to round-off
    (spec 5.7, :func:`ght_cad.developables.loft.developable_loft`); fans (cones with apex at a rail end)
    complete the loft so both rails are covered over their whole length. See the module doc for
    the rail adapter and the B-rep (:func:`loft_shape`).

    Args:
        edge_a, edge_b: rails: build123d/cadquery ``Edge``/``Wire``, OCP ``TopoDS_Edge``/
            ``TopoDS_Wire`` (any curve type) or 3-D :class:`~ght_cad.curves.curve.GHTCurve`.
        tol, degree, sew_tol: see :func:`loft_shape`.
        mode: builder combination mode inside ``BuildPart`` (default ``Mode.ADD``: faces join
            the pending faces; ``Mode.PRIVATE``: nothing is added).
        **options: core options ``orientation``, ``branch``, ``max_step``, ``step_tol``,
            ``samples``, ``boundary_samples`` (:func:`ght_cad.developables.loft.developable_loft`).

    Returns:
        ``Shell`` (several segments, or closed around) or ``Face``, with ``.ght_loft``.

    Raises:
        NotDevelopableError: no developable joins the rails over their whole length (e.g. two
            skew lines); DegenerateGeometryError: coincident/coplanar rails; GHTError: bad rails
            or options, or a builder that cannot take faces (BuildLine, BuildSketch).
    """
    from build123d import BuildPart, Mode
    from build123d.build_common import Builder

    mode = Mode.ADD if mode is None else mode
    context = Builder._get_context("developable_loft")
    if context is not None and mode != Mode.PRIVATE and not isinstance(context, BuildPart):
        raise GHTError(
            f"developable_loft inside {type(context).__name__}: a loft is a 3-D surface; use it in BuildPart "
            "(its faces join the pending faces) or outside any builder"
        )
    shape = loft_between(edge_a, edge_b, tol=tol, degree=degree, sew_tol=sew_tol, **options)
    if context is not None and mode != Mode.PRIVATE:
        context._add_to_context(*shape.faces(), mode=mode)
    return shape


def loft_between(edge_a: Any, edge_b: Any, *, tol: float | None = None, degree: int = 5,
                 sew_tol: float | None = None, **options: Any) -> Any:
    """:func:`developable_loft` outside any builder, without importing build123d's builders (the
    cadquery plugin's path): the rails read by :func:`rail_of`, the core loft, :func:`loft_shape`.

    Raises:
        GHTError: an unknown option (and everything :func:`developable_loft` raises).
    """
    from ..developables.loft import developable_loft as core_loft

    unknown = sorted(set(options) - set(LOFT_OPTIONS))
    if unknown:
        raise GHTError(f"unknown loft option(s) {unknown}; allowed: tol, degree, sew_tol, mode, {', '.join(LOFT_OPTIONS)}")
    loft = core_loft(rail_of(edge_a, "rail_a"), rail_of(edge_b, "rail_b"), **options)
    return loft_shape(loft, tol=tol, degree=degree, sew_tol=sew_tol)
