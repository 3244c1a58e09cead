"""Diagonal strips of the developable approximation (issue 24): the diagonal frame's map and jets,
the conjugate strip estimate, the direction choice and the accepted direction values. Kernel-free
(analytic targets); the OCCT acceptance case is tests/test_approximate_saddle.py."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ght_cad.approximation import (DIRECTIONS, SurfaceTarget, _choose_direction, _DiagonalFrame, _estimate,
                                   _estimate_curvature, _march, approximate, make_frame, strip_uv)
from ght_cad.core.errors import GHTError

L = 2000.0


def saddle_target() -> SurfaceTarget:
    """``z = x y / L``, x, y in [-500, 500], parametrized by x and y (asymptotic parameter lines)."""

    def jet(u, v, order):
        z = np.zeros_like(u)
        o = np.ones_like(u)
        out = [np.stack([u, v, u * v / L], 1), np.stack([o, z, v / L], 1), np.stack([z, o, u / L], 1)]
        if order >= 2:
            out += [np.zeros((u.size, 3)), np.zeros((u.size, 3)), np.stack([z, z, o / L], 1)]
        return out

    return SurfaceTarget(jet, (-500.0, 500.0, -500.0, 500.0), "saddle")


def wavy_target() -> SurfaceTarget:
    """A generic smooth graph on a non-square, off-origin box (every jet term nonzero)."""

    def jet(u, v, order):
        s, c = np.sin(u + 0.3 * v), np.cos(u + 0.3 * v)
        w = np.exp(0.5 * v)
        z = np.zeros_like(u)
        o = np.ones_like(u)
        f = s * w + u * v * v
        fu = c * w + v * v
        fv = 0.3 * c * w + 0.5 * s * w + 2 * u * v
        out = [np.stack([u + 0.1 * v * v, v, f], 1), np.stack([o, z, fu], 1), np.stack([0.2 * v, o, fv], 1)]
        if order >= 2:
            fuu = -s * w
            fvv = -0.09 * s * w + 0.3 * c * w + 0.25 * s * w + 2 * u
            fuv = -0.3 * s * w + 0.5 * c * w + 2 * v
            out += [np.stack([z, z, fuu], 1), np.stack([0.2 * o, z, fvv], 1), np.stack([z, z, fuv], 1)]
        return out

    return SurfaceTarget(jet, (0.3, 1.7, -0.5, 0.8), "wavy")


def sphere_cap_target(radius: float = 1000.0, polar_deg: float = 60.0) -> SurfaceTarget:
    """Spherical cap in longitude u (a full turn) and latitude v (principal parameter lines)."""

    def jet(u, v, order):
        cu, su, cv, sv = np.cos(u), np.sin(u), np.cos(v), np.sin(v)
        R = radius
        out = [R * np.stack([cv * cu, cv * su, sv], 1), R * np.stack([-cv * su, cv * cu, 0 * u], 1),
               R * np.stack([-sv * cu, -sv * su, cv], 1)]
        if order >= 2:
            out += [R * np.stack([-cv * cu, -cv * su, 0 * u], 1), R * np.stack([-cv * cu, -cv * su, -sv], 1),
                    R * np.stack([sv * su, -sv * cu, 0 * u], 1)]
        return out

    return SurfaceTarget(jet, (0.0, 2 * math.pi, math.pi / 2 - math.radians(polar_deg), math.pi / 2), "cap")


def cylinder_target() -> SurfaceTarget:
    """Half a cylinder of radius 300 (developable: one strip), u the angle, v along the axis."""

    def jet(u, v, order):
        c, s, z = np.cos(u), np.sin(u), np.zeros_like(u)
        out = [np.stack([300 * c, 300 * s, v], 1), np.stack([-300 * s, 300 * c, z], 1), np.stack([z, z, z + 1], 1)]
        if order >= 2:
            out += [np.stack([-300 * c, -300 * s, z], 1), np.zeros((u.size, 3)), np.zeros((u.size, 3))]
        return out

    return SurfaceTarget(jet, (0.0, math.pi, 0.0, 500.0), "cylinder")


@pytest.mark.parametrize("direction", ["diagonal", "antidiagonal"])
def test_diagonal_map_seams_and_corners(direction):
    b = (0.3, 1.7, -0.5, 0.8)
    x = np.linspace(0, 1, 11)
    sign = 1.0 if direction == "diagonal" else -1.0
    for y in np.linspace(0, 1, 17):
        u, v = strip_uv(direction, b, x, np.full(x.size, y))
        un, vn = (u - b[0]) / (b[1] - b[0]), (v - b[2]) / (b[3] - b[2])
        # the seam at y is the isoline u_n ± v_n = 2 y (- 1) clipped to the box, ends on its edges
        target = 2 * y if direction == "diagonal" else 2 * y - 1
        assert np.allclose(un + sign * vn, target, atol=1e-12)
        assert np.all((un >= -1e-12) & (un <= 1 + 1e-12) & (vn >= -1e-12) & (vn <= 1 + 1e-12))
        ends = [min(un[k], 1 - un[k], vn[k], 1 - vn[k]) for k in (0, -1)]
        assert max(ends) <= 1e-12
    # y = 0 and y = 1: single points, the box corners
    for y, corner in ((0.0, (0, 0) if sign > 0 else (0, 1)), (1.0, (1, 1) if sign > 0 else (1, 0))):
        u, v = strip_uv(direction, (0.0, 1.0, 0.0, 1.0), x, np.full(x.size, y))
        assert np.allclose(u, corner[0], atol=1e-12) and np.allclose(v, corner[1], atol=1e-12)
    # continuous at the kink y = 1/2 (the full diagonal through the other two corners)
    for eps in (1e-9, -1e-9):
        u0, v0 = strip_uv(direction, b, x, np.full(x.size, 0.5))
        u1, v1 = strip_uv(direction, b, x, np.full(x.size, 0.5 + eps))
        assert np.max(np.abs(u1 - u0)) + np.max(np.abs(v1 - v0)) <= 1e-8


@pytest.mark.parametrize("direction", ["diagonal", "antidiagonal"])
def test_diagonal_frame_jets_match_finite_differences(direction):
    fr = make_frame(wavy_target(), direction)
    assert isinstance(fr, _DiagonalFrame) and fr.breaks() == (0.5,)
    rng = np.random.default_rng(7)
    # off the kink y = 1/2 (the y-derivatives jump there) and the point seams
    x = rng.uniform(0.02, 0.98, 40)
    y = np.concatenate([rng.uniform(0.03, 0.47, 20), rng.uniform(0.53, 0.97, 20)])
    S, Sx, Sy, Sxx, Syy, Sxy = fr.jet(x, y, 2)
    h = 1e-5

    def P(a, b):
        return fr.jet(a, b, 0)[0]

    def D1(a, b, k):
        return fr.jet(a, b, 1)[k]

    scale = np.max(np.abs(S))
    fd = {
        "S_x": ((P(x + h, y) - P(x - h, y)) / (2 * h), Sx),
        "S_y": ((P(x, y + h) - P(x, y - h)) / (2 * h), Sy),
        "S_xx": ((D1(x + h, y, 1) - D1(x - h, y, 1)) / (2 * h), Sxx),
        "S_yy": ((D1(x, y + h, 2) - D1(x, y - h, 2)) / (2 * h), Syy),
        "S_xy": ((D1(x, y + h, 1) - D1(x, y - h, 1)) / (2 * h), Sxy),
        "S_yx": ((D1(x + h, y, 2) - D1(x - h, y, 2)) / (2 * h), Sxy),
    }
    for name, (num, exact) in fd.items():
        err = np.max(np.abs(num - exact)) / max(np.max(np.abs(exact)), scale)
        assert err <= 1e-6, (name, err)
    # the frame's uv is the map of strip_uv, and the positions are the target's there
    u, v = fr.uv(x, y)
    assert np.allclose(fr.t.jet(u, v, 0)[0], S, rtol=0, atol=1e-12 * scale)


def test_conjugate_estimate_saddle_and_cap():
    tol = 2.0
    sad = saddle_target()
    est = {d: _estimate(make_frame(sad, d), tol) for d in ("u", "v", "diagonal", "antidiagonal")}
    # along the principal directions |κ| <= 1/L: the 1414 mm diagonal needs about
    # sqrt(2 |L_xy| / (16 tol)) ~ 5.6 strips (|L_xy| = 500 mm in the unit square's coordinates)
    for d in ("diagonal", "antidiagonal"):
        assert 4.0 <= est[d] <= 6.0, est
    # the parameter lines are asymptotic: the strips would need rulings along the seams
    for d in ("u", "v"):
        assert est[d] >= 10 * est["diagonal"], est
    # the curvature-only estimate sees (almost) nothing along u and v: why the saddle failed before
    assert _estimate_curvature(make_frame(sad, "u"), tol) <= 1e-6
    # both diagonals tie on the symmetric saddle: "diagonal", whatever the rounding
    assert abs(est["diagonal"] - est["antidiagonal"]) <= 1e-9 * est["diagonal"]
    assert all(_choose_direction(sad, t)[0] == "diagonal" for t in (0.5, 1.0, 2.0, 4.0))
    # the cap in longitude/latitude (principal lines, L_xy = 0): the conjugate estimate is the
    # curvature one (1 % for the two quadratures), rulings along the meridians, no diagonals tried
    cap = sphere_cap_target()
    for d in ("u", "v"):
        a, b = _estimate(make_frame(cap, d), 1.0), _estimate_curvature(make_frame(cap, d), 1.0)
        assert abs(a - b) <= 0.01 * b, (d, a, b)
    choice, est = _choose_direction(cap, 1.0)
    assert choice == "v" and set(est) == {"u", "v"}
    # a developable: 0 along its rulings; seams along the rulings bound planar strips (L_yy)
    cyl = cylinder_target()
    est = {d: _estimate(make_frame(cyl, d), 1.0) for d in ("u", "v")}
    assert est["v"] <= 1e-6 and est["u"] >= 5.0, est
    assert _choose_direction(cyl, 1.0)[0] == "v"


@pytest.mark.slow
def test_diagonal_march_has_a_seam_on_the_kink():
    fr = make_frame(saddle_target(), "diagonal")
    ys = _march(fr, 2.0, 0.9, 30, 1e-6)
    assert ys[0] == 0.0 and ys[-1] == 1.0 and 0.5 in ys
    assert np.all(np.diff(ys) > 0)
    assert 4 <= len(ys) - 1 <= 16


def test_direction_values_everywhere():
    import argparse

    from ght_cad.app.approximate_cli import add_parser
    from ght_cad.app.design.schema.constants import APPROX_DIRECTIONS

    assert DIRECTIONS == ("auto", "u", "v", "diagonal", "antidiagonal")
    assert APPROX_DIRECTIONS == DIRECTIONS
    parser = argparse.ArgumentParser()
    add_parser(parser.add_subparsers(), lambda sp: None)
    args = parser.parse_args(["approximate", "x.step", "--tol", "1", "--out", "o", "--direction", "antidiagonal"])
    assert args.direction == "antidiagonal"
    with pytest.raises(GHTError, match=r"direction='w' is not allowed; use one of 'auto', 'u', 'v', 'diagonal', "
                                       r"'antidiagonal'"):
        approximate(saddle_target(), 1.0, direction="w")
    with pytest.raises(ValueError, match="direction='w'"):
        make_frame(saddle_target(), "w")


def test_no_developable_between_the_seams_is_a_ght_error(monkeypatch):
    import ght_cad.approximation as A
    from ght_cad.core.errors import NotDevelopableError

    def refuse(frame, a, b):
        raise NotDevelopableError("F has no zero between the rails")

    monkeypatch.setattr(A, "_build_panel", refuse)
    with pytest.raises(GHTError) as err:
        approximate(cylinder_target(), 5.0, method="loft", max_panels=4)
    assert type(err.value) is GHTError  # not the loft's NotDevelopableError
    msg = str(err.value)
    assert "best deviation reached: none" in msg and "NotDevelopableError: F has no zero" in msg
    assert "max_panels=4" in msg and "tol=5" in msg


def test_plain_frame_refuses_the_diagonal_directions():
    from ght_cad.approximation import _Frame

    with pytest.raises(ValueError, match="make_frame"):
        _Frame(saddle_target(), "diagonal")
    assert type(make_frame(saddle_target(), "u")) is _Frame


@pytest.mark.slow
def test_small_saddle_end_to_end_without_a_kernel(tmp_path):
    """A 300 mm saddle z = x y / L in its own parameters at tol 0.5 (measured: 4 panels, 0.461,
    ~8 s): diagonal strips, cones at the two corners, seams shared, the sheets of the panels on the
    target's normal side, the deviation plot."""
    from ght_cad.approximation import ConeStrip
    from ght_cad.app.design.approximate import panel_sheets, plot_deviation
    from ght_cad.sheetmetal.sheet import Sheet

    def jet(u, v, order):
        return saddle_target()._jet(u, v, order)

    tgt = SurfaceTarget(jet, (-150.0, 150.0, -150.0, 150.0), "small saddle")
    res = approximate(tgt, 0.5)
    assert res.direction == "diagonal" and 2 <= len(res.panels) <= 6
    assert res.max_deviation <= 0.5
    assert isinstance(res.panels[0].exact, ConeStrip) and isinstance(res.panels[-1].exact, ConeStrip)
    assert any(abs(p.y1 - 0.5) <= 1e-12 for p in res.panels)
    # every cone apex is its box corner: (-150, -150) and (150, 150) (up to the seam offsets, < tol)
    for p, corner in ((res.panels[0], (-150.0, -150.0)), (res.panels[-1], (150.0, 150.0))):
        apex = p.exact.b(np.array([0.5]))[0]
        assert np.hypot(apex[0] - corner[0], apex[1] - corner[1]) <= 0.5
    # neighbours share their seam: a rail of each exported face, to 1e-6 of the size (points of one
    # projected onto the other by Gauss-Newton from the nearest of 4001 samples)
    lam = np.linspace(0, 1, 41)
    dense = np.linspace(0, 1, 4001)

    def gap(P, rail):
        C = rail(dense)
        t = dense[np.argmin(np.linalg.norm(C[None, :, :] - P[:, None, :], axis=2), axis=1)]
        for _ in range(6):
            c, c1 = rail(t), rail(t, 1)
            t = np.clip(t - np.sum((c - P) * c1, 1) / np.maximum(np.sum(c1 * c1, 1), 1e-300), 0, 1)  # apex: c1 = 0
        return float(np.max(np.linalg.norm(rail(t) - P, axis=1)))

    for p, q in zip(res.panels[:-1], res.panels[1:]):
        best = min(gap(ra(lam), rb) for ra in (p.surface.a, p.surface.b) for rb in (q.surface.a, q.surface.b))
        assert best <= 1e-6 * res.size, best
    # the sheets: material on the target's normal side at every sampled point of every panel
    sheets = panel_sheets(res, tgt, Sheet(2.0))
    for p, sh in zip(res.panels, sheets):
        part = p.exact
        for lm in (0.2, 0.5, 0.8):
            la = np.array([lm])
            a, b = part.a(la)[0], part.b(la)[0]
            for w in (0.25, 0.75):
                X = a + w * (b - a)
                Xl = part.a(la, 1)[0] + w * (part.b(la, 1)[0] - part.a(la, 1)[0])
                n_panel = np.cross(Xl, b - a)
                n_target = np.array([-X[1] / L, -X[0] / L, 1.0])
                assert (n_panel @ n_target > 0) == (sh.side == "normal")
    png = plot_deviation(res, tmp_path / "dev.png")
    assert png.stat().st_size > 1000
