"""Bent sheet parts built in build123d for the blank tests and bench/bench_blank.py, with their
closed-form neutral blanks.

A profile is a path in the xy plane: flat lengths ``flats[i]`` joined by circular bends
``(angle, inside_radius, turn)`` (turn +1 left / -1 right); the material lies to the right of the
path, so a left turn has the path on its inside (radius R, other side R + T) and a right turn on
its outside (R + T, other side R). The profile face is extruded by ``width`` along z.
Closed-form blank length: ``Σ flats + Σ (R + K T) A``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class Profile:
    flats: list[float]
    bends: list[tuple[float, float, int]]  # (angle rad, inside radius, turn ±1)
    thickness: float
    width: float

    def blank_length(self, k: float) -> float:
        return sum(self.flats) + sum((r + k * self.thickness) * a for a, r, _ in self.bends)

    def blank_area(self, k: float) -> float:
        return self.blank_length(k) * self.width


def _paths(p: Profile) -> tuple[list, list]:
    """Both sides of the profile as lists of pieces ('line', p0, p1) / ('arc', p0, pm, p1)."""
    T = p.thickness
    pos = np.zeros(2)
    d = np.array([1.0, 0.0])
    left, right = [], []  # left = the path itself, right = offset by T to the right

    def rperp(v: np.ndarray) -> np.ndarray:
        return np.array([v[1], -v[0]])

    for i, L in enumerate(p.flats):
        q = pos + L * d
        left.append(("line", pos.copy(), q.copy()))
        right.append(("line", pos + T * rperp(d), q + T * rperp(d)))
        pos = q
        if i < len(p.bends):
            a, R, turn = p.bends[i]
            r_path = R if turn > 0 else R + T
            n_left = -rperp(d)  # unit normal to the left
            c = pos + turn * r_path * n_left
            def rot(v: np.ndarray, ang: float) -> np.ndarray:
                cs, sn = math.cos(ang), math.sin(ang)
                return np.array([cs * v[0] - sn * v[1], sn * v[0] + cs * v[1]])
            ang = turn * a
            for side, rr in ((left, r_path), (right, r_path + (T if turn > 0 else -T))):
                v0 = (pos - c) / r_path * rr
                side.append(("arc", c + v0, c + rot(v0, 0.5 * ang), c + rot(v0, ang)))
            pos = c + rot(pos - c, ang)
            d = rot(d, ang)
    return left, right


def profile_solid(p: Profile, holes: list[tuple[float, float, float]] = ()):
    """The extruded sheet solid (build123d Solid); ``holes``: (x, y, radius) of round holes
    through a flange parallel to the xz plane... given as (flat index, position along, diameter)."""
    import build123d as bd

    left, right = _paths(p)

    def edge(piece, reverse=False):
        pts = [bd.Vector(float(x), float(y), 0.0) for x, y in piece[1:]]
        if reverse:
            pts = pts[::-1]
        if piece[0] == "line":
            return bd.Edge.make_line(pts[0], pts[1])
        return bd.Edge.make_three_point_arc(*pts)

    edges = [edge(pc) for pc in left]
    edges.append(bd.Edge.make_line(bd.Vector(*left[-1][-1], 0), bd.Vector(*right[-1][-1], 0)))
    edges += [edge(pc, True) for pc in reversed(right)]
    edges.append(bd.Edge.make_line(bd.Vector(*right[0][1], 0), bd.Vector(*left[0][1], 0)))
    face = bd.Face(bd.Wire(edges))
    solid = bd.Solid.extrude(face, bd.Vector(0, 0, p.width))
    for fi, along, dia in holes:
        piece = left[2 * fi]
        a, b = piece[1], piece[2]
        d = (b - a) / np.linalg.norm(b - a)
        c = a + along * d
        nrm = np.array([d[1], -d[0]])  # to the right: through the material
        cyl = bd.Solid.make_cylinder(dia / 2, 10 * p.thickness,
                                     bd.Plane(origin=(float(c[0] - 5 * p.thickness * nrm[0]), float(c[1] - 5 * p.thickness * nrm[1]),
                                                      p.width / 2), z_dir=(float(nrm[0]), float(nrm[1]), 0.0)))
        solid = solid - cyl
    return solid


def bracket() -> Profile:
    """The issue's L-bracket: T 2, inside R 3, flanges 40 and 25, width 50."""
    return Profile([40.0, 25.0], [(math.pi / 2, 3.0, 1)], 2.0, 50.0)


def z_profile() -> Profile:
    return Profile([30.0, 20.0, 30.0], [(math.pi / 2, 2.0, 1), (math.pi / 2, 2.0, -1)], 1.5, 40.0)


def u_channel() -> Profile:
    """U-channel with two radii (3 and 5); a 10 mm hole in its base (flat 1)."""
    return Profile([25.0, 60.0, 25.0], [(math.pi / 2, 3.0, 1), (math.pi / 2, 5.0, 1)], 2.0, 45.0)


def tray(A: float = 100.0, B: float = 80.0, T: float = 2.0, R: float = 3.0, F: float = 20.0, g: float = 4.0):
    """A tray: base A x B (thickness T), four flanges of flat height F bent up 90 deg at inside radius R,
    each side's bend and flange ``g`` shorter at both ends (corner reliefs). Returns the solid and
    ``area(K)``, the closed-form neutral blank ``A B + 2 (A + B - 4 g) ((R + K T) π/2 + F)``."""
    import build123d as bd

    def side(length: float) -> list:
        c = (0.0, T + R)

        def pt(r: float, a: float):
            return bd.Vector(c[0] + r * math.cos(a), 0, c[1] + r * math.sin(a))

        e = [bd.Edge.make_three_point_arc(pt(R, -math.pi / 2), pt(R, -math.pi / 4), pt(R, 0)),
             bd.Edge.make_line(pt(R, 0), pt(R + T, 0)),
             bd.Edge.make_three_point_arc(pt(R + T, 0), pt(R + T, -math.pi / 4), pt(R + T, -math.pi / 2)),
             bd.Edge.make_line(pt(R + T, -math.pi / 2), pt(R, -math.pi / 2))]
        bend = bd.Solid.extrude(bd.Face(bd.Wire(e)), bd.Vector(0, length, 0))
        return [bend, bd.Solid.make_box(T, length, F).translate((R, 0, T + R))]

    parts = [bd.Solid.make_box(A, B, T)]
    parts += [s.translate((A, g, 0)) for s in side(B - 2 * g)]
    parts += [s.mirror(bd.Plane.YZ).translate((0, g, 0)) for s in side(B - 2 * g)]
    parts += [s.rotate(bd.Axis.Z, 90).translate((A - g, B, 0)) for s in side(A - 2 * g)]
    parts += [s.rotate(bd.Axis.Z, 90).mirror(bd.Plane.XZ).translate((A - g, 0, 0)) for s in side(A - 2 * g)]
    solid = parts[0]
    for p in parts[1:]:
        solid = solid + p

    def area(k: float) -> float:
        return A * B + 2 * (A + B - 4 * g) * ((R + k * T) * math.pi / 2 + F)

    return solid, area


def freeform_bend(sign: int, T: float = 2.0, W: float = 40.0):
    """Straight (30) - cubic Bézier (turning 90 deg) - straight (25) profile extruded by W and
    thickened by T (``BRepOffsetAPI_MakeThickSolid.MakeThickSolidBySimple``: the other skin is the
    exact offset surface); ``sign`` -1 puts the material on the convex side (the profile is the
    inside skin), +1 on the concave side (the profile is the outside skin). Returns the solid and
    ``area(K) = (L_inside + K T π/2) W`` with ``L_inside = L`` or ``L - T π/2``."""
    import build123d as bd
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeThickSolid

    from ght_cad.cad.curves import exact_edges

    with exact_edges():
        l1 = bd.Edge.make_line((0, 0, 0), (30, 0, 0))
        sp = bd.Edge.make_bezier((30, 0, 0), (40, 0, 0), (50, 10, 0), (50, 20, 0))
        l2 = bd.Edge.make_line((50, 20, 0), (50, 45, 0))
        shell = bd.Shell([bd.Face.extrude(e, bd.Vector(0, 0, W)) for e in (l1, sp, l2)])
    mk = BRepOffsetAPI_MakeThickSolid()
    mk.MakeThickSolidBySimple(shell.wrapped, sign * T)
    mk.Build()
    L = 55.0 + bezier_length([(30, 0), (40, 0), (50, 10), (50, 20)]) - (T * math.pi / 2 if sign > 0 else 0.0)

    def area(k: float) -> float:
        return (L + k * T * math.pi / 2) * W

    return bd.Solid(mk.Shape()), area


def bezier_length(points, pieces: int = 16, order: int = 32) -> float:
    """Arc length of a plane Bézier curve by composite Gauss-Legendre quadrature of ``|c'(t)|``
    (``pieces`` x ``order`` nodes: round-off for a smooth cubic; OCCT's ``Edge.length`` of the same
    cubic is 2.4e-9 relative off)."""
    P = np.asarray(points, dtype=float)
    n = len(P) - 1
    D = n * np.diff(P, axis=0)  # the hodograph's control points
    x, w = np.polynomial.legendre.leggauss(order)
    total = 0.0
    for i in range(pieces):
        t = (i + 0.5 * (x + 1.0)) / pieces
        B = np.stack([math.comb(n - 1, j) * t ** j * (1 - t) ** (n - 1 - j) for j in range(n)], axis=1)
        total += float(np.sum(w * np.linalg.norm(B @ D, axis=1))) * 0.5 / pieces
    return total


def cone_bend(T: float = 2.0, W: float = 40.0, L1: float = 30.0, L2: float = 20.0, r1: float = 3.0, r2: float = 8.0):
    """An L whose bend is a cone segment: inside radius r1 at z = 0 growing linearly to r2 at z = W
    (axis z, semi-angle α = atan((r2 - r1)/W)); flanges in the tangent planes y = -r(z) and x = r(z);
    both z-sections drawn with thickness T / cos α so the skins lie T apart along the normals;
    ruled loft of the two sections. Returns the solid and ``area(K)``: flanges ``(L1 + L2) s`` and
    the neutral cone (radii ``r + K T cos α``, slant ``s = W / cos α``, a quarter turn about the
    axis) ``π/4 (r1 + r2 + 2 K T cos α) s``."""
    import build123d as bd

    al = math.atan((r2 - r1) / W)
    ts = T / math.cos(al)

    def section(r: float, z: float):
        def P(x: float, y: float):
            return bd.Vector(x, y, z)

        def c(rr: float, a: float):
            return P(rr * math.cos(a), rr * math.sin(a))

        ro = r + ts
        return bd.Wire([bd.Edge.make_line(P(-L1, -r), P(0, -r)),
                        bd.Edge.make_three_point_arc(c(r, -math.pi / 2), c(r, -math.pi / 4), c(r, 0)),
                        bd.Edge.make_line(P(r, 0), P(r, L2)), bd.Edge.make_line(P(r, L2), P(ro, L2)),
                        bd.Edge.make_line(P(ro, L2), P(ro, 0)),
                        bd.Edge.make_three_point_arc(c(ro, 0), c(ro, -math.pi / 4), c(ro, -math.pi / 2)),
                        bd.Edge.make_line(P(0, -ro), P(-L1, -ro)), bd.Edge.make_line(P(-L1, -ro), P(-L1, -r))])

    solid = bd.Solid.make_loft([section(r1, 0.0), section(r2, W)], ruled=True)
    s = W / math.cos(al)

    def area(k: float) -> float:
        return (L1 + L2) * s + math.pi / 4 * (r1 + r2 + 2 * k * T * math.cos(al)) * s

    return solid, area


def _bend_solid(centre, r_in: float, T: float, a0: float, a1: float, plane: str, length: float):
    """A circular bend: the annulus sector ``r_in .. r_in + T`` about ``centre`` from angle ``a0`` to
    ``a1`` in the xz plane (``plane="xz"``, extruded along +y) or the yz plane (``"yz"``, along +x)."""
    import build123d as bd

    def P(r: float, a: float):
        p, q = centre[0] + r * math.cos(a), centre[1] + r * math.sin(a)
        return bd.Vector(p, 0.0, q) if plane == "xz" else bd.Vector(0.0, p, q)

    am = 0.5 * (a0 + a1)
    ro = r_in + T
    e = [bd.Edge.make_three_point_arc(P(r_in, a0), P(r_in, am), P(r_in, a1)), bd.Edge.make_line(P(r_in, a1), P(ro, a1)),
         bd.Edge.make_three_point_arc(P(ro, a1), P(ro, am), P(ro, a0)), bd.Edge.make_line(P(ro, a0), P(r_in, a0))]
    return bd.Solid.extrude(bd.Face(bd.Wire(e)), bd.Vector(0, length, 0) if plane == "xz" else bd.Vector(length, 0, 0))


def crossed_flanges(A: float = 60.0, B: float = 50.0, T: float = 2.0, R: float = 3.0, F: float = 20.0, e: float = 15.0):
    """A base plate ``[0, A] x [0, B] x [0, T]`` with two flanges on adjacent edges: at x = A bent
    **up** 90 deg (inside radius R), at y = B bent **down** 90 deg (inside radius R); each flange's
    flat part (height F) runs ``e`` past the shared corner (the first to y = B + e, the second to
    x = A + e) while its bend covers only the plate's edge. In 3-D the flanges lie above z = T + R
    and below z = -R: the part does not intersect itself. In the flat both flanges start at the
    neutral bend allowance ``BA = (R + K T) π/2`` from the plate's edges, so for ``BA < e < BA + F``
    they overlap in the square ``[A + BA, A + e] x [B + BA, B + e]``. Returns the solid,
    ``overlap(K) = (e - BA)²`` and ``area(K) = A B + BA (A + B) + F (B + e) + F (A + e)``, the sum of
    the faces' own flat areas (plate, two bends, two flanges)."""
    import build123d as bd

    plate = bd.Solid.make_box(A, B, T)
    # up at x = A: centre (A, T + R) in xz, inside (top skin) from -90 deg to 0; flange x in [A+R, A+R+T]
    bend1 = _bend_solid((A, T + R), R, T, -math.pi / 2, 0.0, "xz", B)
    flange1 = bd.Solid.make_box(T, B + e, F).translate((A + R, 0, T + R))
    # down at y = B: centre (B, -R) in yz, inside (bottom skin) from 90 deg to 0; flange y in [B+R, B+R+T]
    bend2 = _bend_solid((B, -R), R, T, 0.0, math.pi / 2, "yz", A)
    flange2 = bd.Solid.make_box(A + e, T, F).translate((0, B + R, -R - F))
    solid = plate + bend1 + flange1 + bend2 + flange2

    def ba(k: float) -> float:
        return (R + k * T) * math.pi / 2

    def overlap(k: float) -> float:
        return max(0.0, min(e, ba(k) + F) - ba(k)) ** 2

    def area(k: float) -> float:  # the faces' own flat areas (plate, two bends, two flanges)
        return A * B + ba(k) * (A + B) + F * (B + e) + F * (A + e)

    return solid, overlap, area


def spherical_shell(R: float = 50.0, T: float = 2.0, a: float = 15.0):
    """A doubly curved sheet: the shell between the spheres of radii R and R + T about the origin,
    cut to ``|y|, |z| < a`` around +x. Its skins lie exactly T apart (along the radii), but they are
    not developable: Gaussian curvature ``1/R²`` (inside) and ``1/(R + T)²`` (outside)."""
    import build123d as bd

    shell = bd.Solid.make_sphere(R + T) - bd.Solid.make_sphere(R)
    box = bd.Solid.make_box(2 * (R + T), 2 * a, 2 * a).translate((0, -a, -a))
    return shell & box


def square_bar(T: float = 2.0, L: float = 100.0):
    """A bar of cross-section T x T and length L: each long face lies T from the opposite one, so
    both pairings (top/bottom and front/back) are sheets of thickness T: the skin is ambiguous."""
    import build123d as bd

    return bd.Solid.make_box(L, T, T)
