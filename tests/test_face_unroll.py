"""The kernel-free face unrolling core (ght_cad.face_unroll) on pure-numpy fake adapters.

Analytic surfaces whose developments are known in closed form: a cylinder, a cone, an extrusion
of a parabola (lengths, area, angles to 1e-9); trimmed boundaries (a sine-curve top edge from a
slanted cut, a round hole) and the generic quadrature path against the closed forms; refusals of
non-ruled and non-developable surfaces; the loop-chaining and finite-difference helpers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from ght_cad.core.errors import NotDevelopableError
from ght_cad.unrolling.face_unroll import (
    EdgeData,
    FaceData,
    SurfaceAdapter,
    chain_loop,
    clip_rulings_uv,
    fd_derivative,
    isoline_stats,
    ruling_direction,
    unroll_face_data,
)

RTOL = 1e-9


class Cylinder(SurfaceAdapter):
    """S(u, v) = (R cos u, R sin u, v) (OCCT's cylinder parametrization)."""

    def __init__(self, R: float, kind: str = "cylinder") -> None:
        self.R, self.kind, self.radius = R, kind, R

    def value(self, u, v):
        return np.stack([self.R * np.cos(u), self.R * np.sin(u), v], axis=1)

    def d2(self, u, v):
        R, z = self.R, np.zeros_like(u)
        return [
            self.value(u, v),
            np.stack([-R * np.sin(u), R * np.cos(u), z], axis=1),
            np.stack([z, z, z + 1.0], axis=1),
            np.stack([-R * np.cos(u), -R * np.sin(u), z], axis=1),
            np.stack([z, z, z], axis=1),
            np.stack([z, z, z], axis=1),
        ]


class Cone(SurfaceAdapter):
    """OCCT's cone: S(u, v) = (R + v sin α)(cos u, sin u, 0) + v cos α (0, 0, 1)."""

    def __init__(self, R: float, alpha: float, kind: str = "cone") -> None:
        self.R, self.alpha, self.kind, self.radius, self.semi_angle = R, alpha, kind, R, alpha

    def value(self, u, v):
        r = self.R + v * math.sin(self.alpha)
        return np.stack([r * np.cos(u), r * np.sin(u), v * math.cos(self.alpha)], axis=1)

    def d2(self, u, v):
        s, c = math.sin(self.alpha), math.cos(self.alpha)
        r, z = self.R + v * s, np.zeros_like(u)
        return [
            self.value(u, v),
            np.stack([-r * np.sin(u), r * np.cos(u), z], axis=1),
            np.stack([s * np.cos(u), s * np.sin(u), z + c], axis=1),
            np.stack([-r * np.cos(u), -r * np.sin(u), z], axis=1),
            np.stack([z, z, z], axis=1),
            np.stack([-s * np.sin(u), s * np.cos(u), z], axis=1),
        ]


class ParabolaExtrusion(SurfaceAdapter):
    """S(u, v) = (u, u², 0) + v d: a surface of linear extrusion (rulings along v)."""

    kind = "extrusion"

    def __init__(self, d=(0.0, 0.0, 1.0)) -> None:
        self.d = np.asarray(d, dtype=float)

    def value(self, u, v):
        return np.stack([u, u * u, 0 * u], axis=1) + v[:, None] * self.d

    def d2(self, u, v):
        z = np.zeros_like(u)
        return [
            self.value(u, v),
            np.stack([z + 1.0, 2 * u, z], axis=1),
            np.tile(self.d, (u.size, 1)),
            np.stack([z, z + 2.0, z], axis=1),
            np.stack([z, z, z], axis=1),
            np.stack([z, z, z], axis=1),
        ]


class EllipseExtrusion(SurfaceAdapter):
    """S(u, v) = (A cos u, B sin u, v): an elliptic cylinder, a surface of linear extrusion."""

    kind = "extrusion"

    def __init__(self, A: float, B: float) -> None:
        self.A, self.B = A, B

    def value(self, u, v):
        return np.stack([self.A * np.cos(u), self.B * np.sin(u), v], axis=1)

    def d2(self, u, v):
        z = np.zeros_like(u)
        return [
            self.value(u, v),
            np.stack([-self.A * np.sin(u), self.B * np.cos(u), z], axis=1),
            np.stack([z, z, z + 1.0], axis=1),
            np.stack([-self.A * np.cos(u), -self.B * np.sin(u), z], axis=1),
            np.stack([z, z, z], axis=1),
            np.stack([z, z, z], axis=1),
        ]


class Sphere(SurfaceAdapter):
    def value(self, u, v):
        return np.stack([np.cos(v) * np.cos(u), np.cos(v) * np.sin(u), np.sin(v)], axis=1)

    def d2(self, u, v):
        cu, su, cv, sv, z = np.cos(u), np.sin(u), np.cos(v), np.sin(v), np.zeros_like(u)
        p = self.value(u, v)
        return [
            p,
            np.stack([-cv * su, cv * cu, z], axis=1),
            np.stack([-sv * cu, -sv * su, cv], axis=1),
            np.stack([-cv * cu, -cv * su, z], axis=1),
            -p,
            np.stack([sv * su, -sv * cu, z], axis=1),
        ]


class Saddle(SurfaceAdapter):
    """The hyperbolic paraboloid S(u, v) = (u, v, u v): ruled in both directions, not developable."""

    def value(self, u, v):
        return np.stack([u, v, u * v], axis=1)

    def d2(self, u, v):
        z = np.zeros_like(u)
        return [
            self.value(u, v),
            np.stack([z + 1, z, v], axis=1),
            np.stack([z, z + 1, u], axis=1),
            np.stack([z, z, z], axis=1),
            np.stack([z, z, z], axis=1),
            np.stack([z, z, z + 1], axis=1),
        ]


def _edge(surf: SurfaceAdapter, uvf, duvf, name: str = "") -> EdgeData:
    """An edge from its pcurve; its 3-D curve is S(pcurve), its length ∫|S_u u' + S_v v'| (quad)."""

    def uv(t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        u, v = uvf(t)
        return np.broadcast_to(u, t.shape).astype(float), np.broadcast_to(v, t.shape).astype(float)

    def duv(t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        du, dv = duvf(t)
        return np.stack([np.broadcast_to(du, t.shape), np.broadcast_to(dv, t.shape)], axis=1).astype(float)

    def speed(t: float) -> float:
        u, v = uv(np.array([t]))
        d = surf.d1(u, v)
        w = duv(np.array([t]))[0]
        return float(np.linalg.norm(d[0][0] * w[0] + d[1][0] * w[1]))

    length = quad(speed, 0.0, 1.0, epsabs=0, epsrel=1e-13, limit=400)[0]
    return EdgeData(uv=uv, duv=duv, xyz=lambda t: surf.value(*uv(t)), length_3d=length, name=name)


def _box_loop(surf: SurfaceAdapter, u0: float, u1: float, v0: float, v1: float) -> list[EdgeData]:
    """The (u, v) rectangle's border, counter-clockwise."""
    du, dv = u1 - u0, v1 - v0
    return [
        _edge(surf, lambda t: (u0 + du * t, v0), lambda t: (du, 0.0), "bottom"),
        _edge(surf, lambda t: (u1, v0 + dv * t), lambda t: (0.0, dv), "right"),
        _edge(surf, lambda t: (u1 - du * t, v1), lambda t: (-du, 0.0), "top"),
        _edge(surf, lambda t: (u0, v1 - dv * t), lambda t: (0.0, -dv), "left"),
    ]


def _flat_lengths(pat) -> dict[str, float]:
    return {e.name: e.length_flat for loop in pat.panels[0].loops for e in loop}


@pytest.mark.parametrize("kind", ["cylinder", "other"])
def test_cylinder_is_rectangle(kind: str) -> None:
    """Closed form (kind "cylinder") and quadrature along the rulings (kind "other"): R Δu × H."""
    R, u1, H = 10.0, 2 * math.pi, 20.0
    surf = Cylinder(R, kind)
    pat = unroll_face_data(FaceData(surf, (0.0, u1, 0.0, H), [_box_loop(surf, 0.0, u1, 0.0, H)]), rulings=5)
    np.testing.assert_allclose(np.ptp(pat.outlines[0], axis=0), [R * u1, H], rtol=RTOL)
    assert pat.area == pytest.approx(R * u1 * H, rel=RTOL)
    assert pat.panels[0].area_3d == pytest.approx(R * u1 * H, rel=RTOL)
    L = _flat_lengths(pat)
    assert L["bottom"] == pytest.approx(R * u1, rel=RTOL) and L["top"] == pytest.approx(R * u1, rel=RTOL)
    assert L["left"] == pytest.approx(H, rel=RTOL) and L["right"] == pytest.approx(H, rel=RTOL)
    assert pat.errors["max"] < RTOL and pat.errors["angle_deg"] < 1e-7
    # right angles at the corners: the bend lines are parallel to the short sides
    b = pat.bend_lines
    assert len(b) == 5
    np.testing.assert_allclose(np.abs(b[:, 1, 1] - b[:, 0, 1]), H, rtol=RTOL)
    np.testing.assert_allclose(b[:, 1, 0] - b[:, 0, 0], 0.0, atol=RTOL * H)
    assert pat.panels[0].info["method"].startswith("cylinder" if kind == "cylinder" else "quadrature")


def _cone_sector(R: float, alpha: float, du: float, v0: float, v1: float, kind: str):
    surf = Cone(R, alpha, kind)
    return surf, unroll_face_data(FaceData(surf, (0.0, du, v0, v1), [_box_loop(surf, 0.0, du, v0, v1)]), rulings=3)


@pytest.mark.parametrize("kind", ["cone", "other"])
def test_cone_frustum_is_annular_sector(kind: str) -> None:
    """Radii = slant distances ρ = R/sin α + v from the apex, angle s Δu (2π r/ρ for a full cone)."""
    R, alpha, du, v0, v1 = 5.0, math.radians(25.0), 2 * math.pi, 0.0, 12.0
    _, pat = _cone_sector(R, alpha, du, v0, v1, kind)
    s = math.sin(alpha)
    rho0, rho1 = R / s + v0, R / s + v1
    angle = s * du
    assert angle == pytest.approx(2 * math.pi * R / rho0, rel=1e-15)
    assert pat.area == pytest.approx(0.5 * angle * (rho1**2 - rho0**2), rel=RTOL)
    L = _flat_lengths(pat)
    assert L["bottom"] == pytest.approx(angle * rho0, rel=RTOL) and L["top"] == pytest.approx(angle * rho1, rel=RTOL)
    assert L["left"] == pytest.approx(v1 - v0, rel=RTOL)
    # every outline point lies on one of the two arcs or on a radial edge through the apex image
    pts = np.concatenate([e.flat for e in pat.panels[0].loops[0]])
    left = pat.panels[0].loops[0][3].flat
    right = pat.panels[0].loops[0][1].flat
    # apex image: the intersection of the two radial edges' lines
    d1, d2 = left[-1] - left[0], right[-1] - right[0]
    A = np.array([d1, -d2]).T
    k = np.linalg.solve(A, right[0] - left[0])
    apex = left[0] + k[0] * d1
    r = np.linalg.norm(pts - apex, axis=1)
    assert r.min() == pytest.approx(rho0, rel=RTOL) and r.max() == pytest.approx(rho1, rel=RTOL)
    r1, r2 = left[0] - apex, right[-1] - apex  # the two radial edges as rays from the apex image
    assert angle < math.pi
    assert math.atan2(abs(r1[0] * r2[1] - r1[1] * r2[0]), float(r1 @ r2)) == pytest.approx(angle, rel=RTOL)
    assert pat.errors["max"] < RTOL


@settings(max_examples=12, deadline=None)
@given(
    R=st.floats(0.5, 20.0),
    alpha_deg=st.floats(5.0, 80.0),
    du=st.floats(0.3, 2 * math.pi),
    v1=st.floats(0.5, 15.0),
)
def test_cone_quadrature_equals_closed_form(R: float, alpha_deg: float, du: float, v1: float) -> None:
    """Over a parameter box: the generic ruled path (kind "other") gives the closed-form sector area
    ½ s Δu (ρ1² − ρ0²) and the same edge lengths as the closed form, to 1e-9."""
    alpha = math.radians(alpha_deg)
    _, closed = _cone_sector(R, alpha, du, 0.0, v1, "cone")
    _, quadr = _cone_sector(R, alpha, du, 0.0, v1, "other")
    s = math.sin(alpha)
    exact = 0.5 * s * du * ((R / s + v1) ** 2 - (R / s) ** 2)
    assert closed.area == pytest.approx(exact, rel=RTOL)
    assert quadr.area == pytest.approx(exact, rel=RTOL)
    for name, L in _flat_lengths(closed).items():
        assert _flat_lengths(quadr)[name] == pytest.approx(L, rel=RTOL)


def _parabola_length(a: float, b: float) -> float:
    F = lambda u: 0.5 * u * math.sqrt(1 + 4 * u * u) + 0.25 * math.asinh(2 * u)  # noqa: E731
    return F(b) - F(a)


def test_parabola_extrusion_is_rectangle() -> None:
    """(u, u², 0) + v (0, 0, 1), u ∈ [-1, 1.5], v ∈ [0, 3]: L × 3 with L the parabola's arc length."""
    surf = ParabolaExtrusion()
    pat = unroll_face_data(FaceData(surf, (-1.0, 1.5, 0.0, 3.0), [_box_loop(surf, -1.0, 1.5, 0.0, 3.0)]), rulings=4)
    L = _parabola_length(-1.0, 1.5)
    np.testing.assert_allclose(np.ptp(pat.outlines[0], axis=0), [L, 3.0], rtol=RTOL)
    assert pat.area == pytest.approx(3.0 * L, rel=RTOL)
    assert pat.panels[0].area_3d == pytest.approx(3.0 * L, rel=RTOL)
    assert pat.panels[0].info["ruling_direction"] == "v"
    assert pat.errors["max"] < RTOL


def test_closed_elliptic_extrusion_area() -> None:
    """A whole period of an extruded ellipse (analytic, no knots): the 3-D area by Green's
    theorem and the flat area both equal H × perimeter to 1e-12 (the inner Gauss panels are
    split to at most a period / 8)."""
    A, B, H = 10.0, 5.0, 15.0
    surf = EllipseExtrusion(A, B)
    tau = 2 * math.pi
    face = FaceData(surf, (0.0, tau, 0.0, H), [_box_loop(surf, 0.0, tau, 0.0, H)])
    pat = unroll_face_data(face, rulings=4)
    perimeter = quad(lambda u: math.hypot(A * math.sin(u), B * math.cos(u)), 0, tau, epsabs=0, epsrel=1e-13, limit=200)[0]
    assert pat.panels[0].area_3d == pytest.approx(H * perimeter, rel=1e-12)
    assert pat.area == pytest.approx(H * perimeter, rel=1e-12)
    assert pat.errors["max"] < 1e-12


def test_oblique_extrusion_keeps_ruling_length() -> None:
    d = np.array([0.4, 0.0, 2.0])
    surf = ParabolaExtrusion(d)
    pat = unroll_face_data(FaceData(surf, (0.0, 1.0, 0.0, 1.0), [_box_loop(surf, 0.0, 1.0, 0.0, 1.0)]), rulings=6)
    lens = np.linalg.norm(pat.bend_lines[:, 1] - pat.bend_lines[:, 0], axis=1)
    np.testing.assert_allclose(lens, np.linalg.norm(d), rtol=1e-12)
    assert pat.errors["max"] < RTOL


def _slanted_cylinder(R: float, H0: float, a: float, kind: str):
    """Cylinder cut by the plane z = H0 + (a/R) x: the top pcurve is v = H0 + a cos u."""
    surf = Cylinder(R, kind)
    tau = 2 * math.pi
    loop = [
        _edge(surf, lambda t: (tau * t, 0.0), lambda t: (tau, 0.0), "bottom"),
        _edge(surf, lambda t: (tau, (H0 + a) * t), lambda t: (0.0, H0 + a), "seam+"),
        _edge(surf, lambda t: (tau * (1 - t), H0 + a * np.cos(tau * (1 - t))),
              lambda t: (-tau, a * tau * np.sin(tau * (1 - t))), "top"),
        _edge(surf, lambda t: (0.0, (H0 + a) * (1 - t)), lambda t: (0.0, -(H0 + a)), "seam-"),
    ]
    return unroll_face_data(FaceData(surf, (0.0, tau, 0.0, H0 + a), [loop]), rulings=8)


@pytest.mark.parametrize("kind", ["cylinder", "other"])
def test_slanted_cut_top_edge_is_sine_of_ellipse_length(kind: str) -> None:
    """The top edge develops to y = H0 + a cos(x/R) (amplitude a = R tan β); its length is the
    ellipse's perimeter ∫ √(R² + a² sin² u) du, the area 2π R H0 (the cosine integrates to 0)."""
    R, H0, beta = 10.0, 20.0, math.radians(20.0)
    a = R * math.tan(beta)
    pat = _slanted_cylinder(R, H0, a, kind)
    assert pat.area == pytest.approx(2 * math.pi * R * H0, rel=RTOL)
    ellipse = quad(lambda u: math.sqrt(R * R + a * a * math.sin(u) ** 2), 0, 2 * math.pi, epsabs=0, epsrel=1e-13, limit=200)[0]
    top = next(e for e in pat.panels[0].loops[0] if e.name == "top")
    assert top.length_flat == pytest.approx(ellipse, rel=RTOL)
    assert top.length_3d == pytest.approx(ellipse, rel=1e-12)
    x, y = top.flat[:, 0] - pat.outlines[0][:, 0].min(), top.flat[:, 1] - pat.outlines[0][:, 1].min()
    np.testing.assert_allclose(y, H0 + a * np.cos(x / R), atol=RTOL * R)
    assert np.ptp(y) == pytest.approx(2 * a, rel=RTOL)
    assert pat.errors["max"] < RTOL


@pytest.mark.parametrize("kind", ["cylinder", "other"])
def test_round_hole_is_kept(kind: str) -> None:
    """A hole whose development is a circle of radius r: two loops, area R Δu H − π r², the hole's
    flat length 2π r; the rulings through the hole are split."""
    R, H, r = 4.0, 10.0, 1.5
    surf = Cylinder(R, kind)
    uc, vc = 1.2, 5.0
    tau = 2 * math.pi
    hole = [
        _edge(surf, lambda t: (uc + (r / R) * np.cos(tau * t), vc + r * np.sin(tau * t)),
              lambda t: (-(r / R) * tau * np.sin(tau * t), r * tau * np.cos(tau * t)), "hole")
    ]
    face = FaceData(surf, (0.0, 2.5, 0.0, H), [_box_loop(surf, 0.0, 2.5, 0.0, H), hole])
    pat = unroll_face_data(face, rulings=20)
    assert len(pat.outlines) == 2
    assert pat.area == pytest.approx(R * 2.5 * H - math.pi * r * r, rel=RTOL)
    assert pat.panels[0].area_3d == pytest.approx(R * 2.5 * H - math.pi * r * r, rel=RTOL)
    assert _flat_lengths(pat)["hole"] == pytest.approx(tau * r, rel=RTOL)
    assert len(pat.bend_lines) > 20
    assert pat.errors["max"] < RTOL


@pytest.mark.parametrize("kind", ["cylinder", "other"])
def test_hole_given_as_outer_wire_is_reordered(kind: str) -> None:
    """An adapter that hands out a hole as the outer wire (FreeCAD 0.20's Face.OuterWire does
    for drilled cylinders): the loop enclosing the largest (u, v) area becomes the outline, the
    area stays R Δu H − π r² (before: −R Δu H − π r², negative, and the hole drawn as outline)."""
    R, H, r = 4.0, 10.0, 1.5
    surf = Cylinder(R, kind)
    tau = 2 * math.pi
    hole = [
        _edge(surf, lambda t: (1.2 + (r / R) * np.cos(tau * t), 5.0 + r * np.sin(tau * t)),
              lambda t: (-(r / R) * tau * np.sin(tau * t), r * tau * np.cos(tau * t)), "hole")
    ]
    face = FaceData(surf, (0.0, 2.5, 0.0, H), [hole, _box_loop(surf, 0.0, 2.5, 0.0, H)])
    pat = unroll_face_data(face, rulings=4)
    exact = R * 2.5 * H - math.pi * r * r
    assert pat.area == pytest.approx(exact, rel=RTOL)
    assert pat.panels[0].area_3d == pytest.approx(exact, rel=RTOL)
    assert [e.name for e in pat.panels[0].loops[0]] == ["bottom", "right", "top", "left"]
    np.testing.assert_allclose(np.ptp(pat.outlines[0], axis=0), [R * 2.5, H], rtol=RTOL)
    assert pat.errors["max"] < RTOL
    assert pat.panels[0].info["outer_wire_reordered"] is True


def test_hole_outside_the_outer_wire_is_refused() -> None:
    """A hole pcurve shifted by a period (u + 2π, outside the face's box): refused naming the wire
    (before: a pattern with the hole drawn beside the outline, area and errors still "right")."""
    from ght_cad.core.errors import DegenerateGeometryError

    R, H, r = 4.0, 10.0, 1.5
    surf = Cylinder(R, "cylinder")
    tau = 2 * math.pi
    hole = [
        _edge(surf, lambda t: (1.2 + tau + (r / R) * np.cos(tau * t), 5.0 + r * np.sin(tau * t)),
              lambda t: (-(r / R) * tau * np.sin(tau * t), r * tau * np.cos(tau * t)), "hole")
    ]
    face = FaceData(surf, (0.0, 2.5, 0.0, H), [_box_loop(surf, 0.0, 2.5, 0.0, H), hole])
    with pytest.raises(DegenerateGeometryError, match=r"wire 2 \(a hole\) lies outside the outer wire.*0% of its points"):
        unroll_face_data(face)


def test_sphere_is_refused_naming_isolines() -> None:
    surf = Sphere()
    face = FaceData(surf, (0.0, 1.0, -0.5, 0.5), [_box_loop(surf, 0.0, 1.0, -0.5, 0.5)])
    d, info = ruling_direction(surf, face.bounds)
    assert d is None and info["deviation_u"] > 1e-3 and info["deviation_v"] > 1e-3
    with pytest.raises(NotDevelopableError, match=r"not ruled.*\(u-isolines\).*\(v-isolines\).*best_effort"):
        unroll_face_data(face)
    pat = unroll_face_data(face, best_effort=True)
    assert pat.errors["max"] > 1e-3


def test_saddle_is_refused_with_theta() -> None:
    surf = Saddle()
    face = FaceData(surf, (0.0, 1.0, 0.0, 1.0), [_box_loop(surf, 0.0, 1.0, 0.0, 1.0)])
    with pytest.raises(NotDevelopableError, match=r"theta_max=45 deg.*DD=0\.75"):
        unroll_face_data(face)
    assert unroll_face_data(face, best_effort=True).errors["area"] > 1e-3


def test_isoline_stats_of_circle_and_line() -> None:
    surf = Cylinder(3.0, "other")
    dev_v, open_v = isoline_stats(surf, (0.0, 2 * math.pi, 0.0, 5.0), "v")
    dev_u, open_u = isoline_stats(surf, (0.0, 2 * math.pi, 0.0, 5.0), "u")
    assert dev_v < 1e-15 and open_v == pytest.approx(1.0)
    assert dev_u == pytest.approx(1.0 / (64.0 * math.sin(math.pi / 32.0)), rel=1e-9) and open_u < 1e-12


def test_chain_loop_shifts_seam_and_reverses() -> None:
    """A cylinder's loop with the seam's other pcurve (2π away) and an edge given backwards."""
    P = 2 * math.pi
    ends = [
        (np.array([0.0, 0.0]), np.array([P, 0.0])),  # bottom
        (np.array([0.0, 0.0]), np.array([0.0, 5.0])),  # seam, wrong copy (u = 0 instead of 2π)
        (np.array([0.0, 5.0]), np.array([P, 5.0])),  # top, backwards
        (np.array([0.0, 5.0]), np.array([0.0, 0.0])),  # seam at u = 0
    ]
    out = chain_loop(ends, (P, 0.0), 1e-9)
    assert [r for r, _ in out] == [False, False, True, False]
    np.testing.assert_allclose([s for _, s in out], [[0, 0], [P, 0], [0, 0], [0, 0]], atol=1e-15)
    # a unit square whose first edge is given backwards: it is flipped so the second starts at its end
    sq = [((1, 0), (0, 0)), ((1, 0), (1, 1)), ((1, 1), (0, 1)), ((0, 1), (0, 0))]
    out2 = chain_loop([(np.array(a, float), np.array(b, float)) for a, b in sq], (0.0, 0.0), 1e-9)
    assert [r for r, _ in out2] == [True, False, False, False]
    assert all(not s.any() for _, s in out2)


def test_fd_derivative_respects_breaks() -> None:
    """|x - 0.3|³ + sin: C² at the break 0.3; with the break the 5-point differences are exact to
    1e-9 everywhere including the ends, without it they are not at points close to the break."""
    f = lambda t: np.stack([np.abs(t - 0.3) ** 3 * np.sign(t - 0.3) ** 0 + np.sin(3 * t), t * t], axis=1)  # noqa: E731
    df = lambda t: np.stack([3 * (t - 0.3) * np.abs(t - 0.3) + 3 * np.cos(3 * t), 2 * t], axis=1)  # noqa: E731
    t = np.array([0.0, 0.1, 0.29999, 0.3, 0.30001, 0.7, 1.0])
    np.testing.assert_allclose(fd_derivative(f, t, [0.3]), df(t), atol=1e-9)
    g = lambda t: np.stack([np.abs(t - 0.3), t], axis=1)  # noqa: E731 - a kink at 0.3
    bad = fd_derivative(g, np.array([0.30001]), [], h=1e-3)
    good = fd_derivative(g, np.array([0.30001]), [0.3], h=1e-3)
    assert abs(good[0, 0] - 1.0) < 1e-9 < abs(bad[0, 0] - 1.0)


def test_clip_rulings_uv_square_with_hole() -> None:
    """Rulings x = c of the unit square with a square hole [0.4, 0.6] x [0.3, 0.7]: outside the
    hole's shadow one whole interval, across it two; a ruling through polygon vertices (the hole's
    corners at x = 0.4) is split exactly once at each of them (half-open crossing rule)."""
    outer = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    hole = np.array([[0.4, 0.3], [0.4, 0.7], [0.6, 0.7], [0.6, 0.3]], float)
    k, y0, y1 = clip_rulings_uv([outer, hole], np.array([0.25, 0.5, 0.4]), 0.0, 1.0)
    assert k.tolist() == [0, 1, 1, 2, 2]
    np.testing.assert_allclose(y0, [0.0, 0.0, 0.7, 0.0, 0.7], atol=1e-15)
    np.testing.assert_allclose(y1, [1.0, 0.3, 1.0, 0.3, 1.0], atol=1e-15)


@given(c=st.floats(0.01, 0.99), lo=st.floats(-0.5, 0.2), hi=st.floats(0.8, 1.5))
@settings(max_examples=60, deadline=None)
def test_clip_rulings_uv_disc_chord(c: float, lo: float, hi: float) -> None:
    """A ruling x = c across a finely sampled disc of radius 1/2 about (1/2, 1/2): one interval,
    the chord y = 1/2 ± sqrt(1/4 - (c - 1/2)²) to the polyline's sagitta R (1 - cos(π/1024))
    ≈ 2.4e-6, magnified along y by R / half-chord where the ruling meets the circle at a slant,
    clamped to [lo, hi]."""
    th = np.linspace(0.0, 2 * np.pi, 1025)[:-1]
    disc = 0.5 + 0.5 * np.stack([np.cos(th), np.sin(th)], axis=1)
    k, y0, y1 = clip_rulings_uv([disc], np.array([c]), lo, hi)
    half = math.sqrt(0.25 - (c - 0.5) ** 2)
    assert k.tolist() == [0]
    tol = 0.5 * (1 - math.cos(math.pi / 1024)) * 0.5 / half * 1.01
    assert abs(y0[0] - max(0.5 - half, lo)) <= tol and abs(y1[0] - min(0.5 + half, hi)) <= tol


@given(u=st.floats(-3, 3), u_lo=st.floats(-1, 1), breaks=st.lists(st.floats(-3, 3), max_size=5),
       span=st.sampled_from([None, 0.7, 2.0, 6.0]))
@settings(max_examples=200, deadline=None)
def test_inner_nodes_of_one_u_match_the_vectorized_rule(u: float, u_lo: float, breaks: list, span) -> None:
    """The plain-float panels of one constant-u edge are the vectorized ones, bit for bit (the
    same cuts at the breaks, halves, panels no wider than span / 8, 12-point rule)."""
    from ght_cad.unrolling.face_unroll import _gauss12, _inner_nodes, _inner_nodes_at

    xg, wg = _gauss12()
    br = np.sort(np.asarray(breaks + [u], dtype=float))
    s1, _, w1, _ = _inner_nodes(np.array([u]), np.array([0.0]), u_lo, br, span, xg, wg)
    s2, w2 = _inner_nodes_at(u, u_lo, br, span)
    assert np.array_equal(s1, s2) and np.array_equal(w1, w2)
