r"""Composite GHT-Bézier curves: chains of segments with a chosen continuity at every joint.

Joint ``j`` connects the end of segment ``j`` to the start of segment ``j+1`` (spec section 4).
An open chain of n segments has n-1 joints; a closed chain has n, the last (the *wrap joint*)
connecting the end of segment n-1 to the start of segment 0.

How the dependent points are resolved (from the stored user segments, every time anything
changes, so the result never depends on the edit history):

1. Segment 0 is the anchor: all its points are the user's.
2. Forward, for j = 0..n-2: segment j+1 = :func:`~ght_cad.curves.continuity.join` (segment j, continuity
   j, segment j+1), which replaces its first ``r_j + 1`` points.
3. Closed chains: the wrap joint is solved *backward*: the last ``r + 1`` points of segment n-1
   are solved from the start of segment 0 by joining the reversed curves,
   ``join(seg0.reversed(), c, seg_{n-1}.reversed(), k~, β2~, β3~).reversed()`` with the reversed
   G parameters of :func:`~ght_cad.curves.continuity.reverse_g_parameters`. This needs segment n-1 to
   have disjoint start and end point sets: degree ``>= r_{n-2} + r_{n-1} + 1`` (for a single
   closed segment, degree ``>= 2 r + 1``).

Global parameter: ``s ∈ [0, n_segments]``; segment ``j = min(floor(s), n-1)`` with local
``t = s - j``, so derivatives with respect to s equal the segments' derivatives with respect to
t. At an interior joint ``s = j`` the segment to the right (segment j) is used.
"""

from __future__ import annotations

import math
from typing import Any, Iterator, Sequence

import numpy as np

from ..core._validate import as_parameter_array, check_points
from .basis import _check_order
from .continuity import Continuity, JointReport, join, measure_continuity, reverse_g_parameters
from .curve import GHTCurve, curvature_from_derivatives
from ..core.errors import GHTError, SingularJoinError
from .seeds import make_seed, seed_names

__all__ = ["CompositeCurve"]


def _per_joint(name: str, value: Any, n_joints: int, conv) -> list:
    if isinstance(value, (str, Continuity)) or np.ndim(value) == 0:
        return [conv(value)] * n_joints
    vals = list(value)
    if len(vals) != n_joints:
        raise GHTError(
            f"{name} has {len(vals)} entries but the chain has {n_joints} joints; give one value "
            f"per joint or a single value for all"
        )
    return [conv(v) for v in vals]


def _float(name: str):
    def conv(v: Any) -> float:
        try:
            f = float(v)
        except (TypeError, ValueError):
            raise GHTError(f"{name}={v!r} is not a number") from None
        if not math.isfinite(f):
            raise GHTError(f"{name}={f} is not finite; it must be a finite real number")
        return f

    return conv


def _check_not_listed(segment: GHTCurve, index: int, others: Sequence[GHTCurve]) -> None:
    """GHTError if ``segment`` is the very object of one of ``others`` (a chain lists each once)."""
    for j, o in enumerate(others):
        if o is segment:
            raise GHTError(
                f"segments[{index}] is the same GHTCurve object as segments[{j}]; allowed: each segment once "
                "(to repeat a shape, pass a moved copy: curve.transformed(np.eye(dim), offset))"
            )


class CompositeCurve:
    r"""A chain of :class:`GHTCurve` segments with continuity C0..C3 / G0..G3 at every joint.

    Args:
        segments: at least one GHTCurve, all of the same dimension. Their dependent points (the
            first ``r+1`` points after each joint, and for closed chains the last points of the
            last segment) are overwritten by the solver; all other points are kept.
        continuity: one value for all joints or a list with one per joint (``"C0".."G3"``).
        closed: if True the end of the last segment joins the start of the first (wrap joint,
            solved backward, see the module docstring).
        k, beta2, beta3: G parameters, one value or one per joint. Used at G joints only;
            at C joints they must be 1, 0, 0 when given per joint.

    Raises:
        GHTError: empty chain, a segment listed twice, mixed dimensions, wrong list lengths, bad
            continuity.
        SingularJoinError: a joint cannot be imposed (see :func:`~ght_cad.curves.continuity.join`), or a
            closed chain's last segment has too low a degree to carry both joints.

    Example:
        >>> a = GHTCurve([(0, 0), (1, 1), (2, 0)], gamma=-1)
        >>> b = GHTCurve([(0, 0), (0, 0), (0, 0), (3, -1), (4, 0)])
        >>> cc = CompositeCurve([a, b], "G2", k=1.5)
        >>> [r.g_order for r in cc.joint_reports()]
        [2]
    """

    def __init__(
        self,
        segments: Sequence[GHTCurve],
        continuity: Any = "G2",
        closed: bool = False,
        k: Any = 1.0,
        beta2: Any = 0.0,
        beta3: Any = 0.0,
    ) -> None:
        segs = list(segments)
        if not segs:
            raise GHTError("segments is empty; a composite curve needs at least one GHTCurve segment")
        for i, s in enumerate(segs):
            if not isinstance(s, GHTCurve):
                raise GHTError(f"segments[{i}] is a {type(s).__name__}; every segment must be a GHTCurve")
            if s.dim != segs[0].dim:
                raise GHTError(
                    f"segments[{i}] has dimension {s.dim} but segments[0] has dimension {segs[0].dim}; "
                    "all segments must have the same dimension"
                )
            _check_not_listed(s, i, segs[:i])
        self._closed = bool(closed)
        nj = len(segs) if self._closed else len(segs) - 1
        self._continuity = _per_joint("continuity", continuity, nj, Continuity.parse)
        scalar_g = all(np.ndim(v) == 0 for v in (k, beta2, beta3))
        ks = _per_joint("k", k, nj, _float("k"))
        b2 = _per_joint("beta2", beta2, nj, _float("beta2"))
        b3 = _per_joint("beta3", beta3, nj, _float("beta3"))
        for j, c in enumerate(self._continuity):
            if c.geometric:
                if not ks[j] > 0:
                    raise SingularJoinError(
                        f"k={ks[j]:g} at joint {j} is not allowed: geometric continuity needs k > 0"
                    )
            elif (ks[j], b2[j], b3[j]) != (1.0, 0.0, 0.0):
                if not scalar_g:
                    raise GHTError(
                        f"joint {j} is {c.value} but k={ks[j]:g}, beta2={b2[j]:g}, beta3={b3[j]:g} were "
                        "given for it; G parameters apply to G1..G3 joints only (use 1, 0, 0)"
                    )
                ks[j], b2[j], b3[j] = 1.0, 0.0, 0.0
        self._g = list(zip(ks, b2, b3))
        self._free = segs
        self._segments: list[GHTCurve] = []
        self._resolve()

    # -- solving ----------------------------------------------------------------------------
    def _gkw(self, j: int) -> dict[str, float]:
        if not self._continuity[j].geometric:
            return {}
        k, b2, b3 = self._g[j]
        return {"k": k, "beta2": b2, "beta3": b3}

    def _resolve(self, start: int = 0) -> None:
        """Solve the dependent points of segments ``start..`` (all when start = 0 or unsolved).

        Segments before ``start`` keep their solved points. The forward pass stops early at the
        first segment after ``start`` that comes out bit-identical to its previous solution: the
        joins are deterministic functions of the predecessor and the user's points, so nothing
        downstream can change. The wrap joint of a closed chain is always re-solved. The result
        is bit-identical to a full solve.
        """
        n = len(self._free)
        old = self._segments if (start > 0 and len(self._segments) == n) else None
        segs = list(old) if old is not None else list(self._free)
        segs[0] = self._free[0] if old is None or start == 0 else segs[0]
        for j in range(max(start, 1), n):
            try:
                new = join(segs[j - 1], self._continuity[j - 1], self._free[j], **self._gkw(j - 1))
            except SingularJoinError as exc:
                raise SingularJoinError(f"joint {j - 1} (segment {j - 1} -> {j}): {exc}") from None
            if (
                old is not None
                and j > start
                and not (self._closed and j == n - 1)
                and np.array_equal(new.control_points, old[j].control_points)
            ):
                break
            segs[j] = new
        if self._closed:
            j = n - 1
            c = self._continuity[j]
            r = c.order
            last = segs[j]
            r_start = self._continuity[j - 1].order if n >= 2 else r
            if last.degree < r_start + r + 1:
                what = (
                    f"its first {r_start + 1} points for joint {j - 1}"
                    if n >= 2
                    else f"its first {r + 1} points as the target of the wrap joint"
                )
                raise SingularJoinError(
                    f"closed chain: segment {j} has degree {last.degree} but must carry {what} and its "
                    f"last {r + 1} points for the wrap joint ({c.value}); it needs degree >= {r_start + r + 1}"
                )
            kw = {}
            if c.geometric:
                kr, b2r, b3r = reverse_g_parameters(*self._g[j])
                kw = {"k": kr, "beta2": b2r, "beta3": b3r}
            try:
                back = join(segs[0].reversed(), c, last.reversed(), **kw)
            except SingularJoinError as exc:
                raise SingularJoinError(
                    f"wrap joint {j} (segment {j} -> 0, solved backward on the reversed curves): {exc}"
                ) from None
            segs[j] = GHTCurve(back.control_points[::-1], seed=last.seed)
        self._segments = segs

    # -- editing ----------------------------------------------------------------------------
    def _check_index(self, index: Any) -> int:
        n = len(self._free)
        try:
            i = int(index)
        except (TypeError, ValueError):
            raise GHTError(f"index={index!r} is not an integer; allowed segment indices are 0..{n - 1}") from None
        if i != index or not -n <= i < n:
            raise GHTError(f"index={index!r} is out of range; allowed segment indices are 0..{n - 1}")
        return i % n

    def dependent_indices(self, index: int) -> list[int]:
        """Indices of the control points of segment ``index`` that the joints determine.

        ``0..r_{index-1}`` for ``index >= 1``; plus ``m-r..m`` for the last segment of a closed
        chain (r the wrap joint's order, m the degree).

        Raises:
            GHTError: bad index.
        """
        i = self._check_index(index)
        n = len(self._free)
        m = self._free[i].degree
        dep: set[int] = set()
        if i >= 1:
            dep.update(range(self._continuity[i - 1].order + 1))
        if self._closed and i == n - 1:
            r = self._continuity[n - 1].order
            dep.update(range(m - r, m + 1))
        return sorted(dep)

    def set_shape(
        self, index: int, mu: float | None = None, nu: float | None = None, gamma: float | None = None
    ) -> None:
        """Change segment ``index``'s shape parameters and re-solve every dependent point.

        Raises:
            GHTError: bad index or shape parameter; SingularJoinError if a joint becomes singular
                (the chain is then left unchanged).
        """
        i = self._check_index(index)
        old = self._free[i]
        name = old.seed.name
        if name in ("gbt", "bernstein"):
            name = "ght"  # GBT is GHT at γ = -1, Bernstein is GHT at γ = 1
        if name not in seed_names():
            raise GHTError(
                f"segment {i} uses the unregistered seed {old.seed.name!r}; set_shape needs a registered "
                "seed family (replace the segment with set_segment instead)"
            )
        seed = make_seed(
            name,
            old.mu if mu is None else mu,
            old.nu if nu is None else nu,
            old.gamma if gamma is None else gamma,
        )
        self._replace(i, GHTCurve(old.control_points, seed=seed))

    def set_segment(self, index: int, segment: GHTCurve) -> None:
        """Replace segment ``index`` (points, degree, seed and shape parameters); re-solve."""
        i = self._check_index(index)
        if not isinstance(segment, GHTCurve):
            raise GHTError(f"segment must be a GHTCurve, got {type(segment).__name__}")
        if segment.dim != self.dim:
            raise GHTError(f"segment has dimension {segment.dim}; this chain has dimension {self.dim}")
        _check_not_listed(segment, i, [s if j != i else None for j, s in enumerate(self._free)])
        self._replace(i, segment)

    def set_control_points(self, index: int, control_points: Any) -> None:
        """Replace segment ``index``'s control points (same or different count); re-solve.

        The dependent points (:meth:`dependent_indices`) of the given array are overwritten.

        Args:
            index: segment index.
            control_points: (count, dim) array, count >= 3.

        Raises:
            GHTError: bad index, shape or dimension; SingularJoinError if a joint becomes
                impossible (the chain is then left unchanged).
        """
        i = self._check_index(index)
        pts = check_points("control_points", control_points, min_count=3)
        if pts.shape[1] != self.dim:
            raise GHTError(f"control_points has dimension {pts.shape[1]}; this chain has dimension {self.dim}")
        self._replace(i, self._free[i].with_control_points(pts))

    def set_control_point(self, index: int, i: int, point: Any) -> None:
        """Move one free control point ``i`` of segment ``index``; re-solve.

        Raises:
            GHTError: the point is determined by a joint (see :meth:`dependent_indices`).
        """
        j = self._check_index(index)
        m = self._free[j].degree
        if not (isinstance(i, (int, np.integer)) and -m - 1 <= i <= m):
            raise GHTError(f"i={i!r} is not a control point index of segment {j}; allowed 0..{m}")
        i = int(i) % (m + 1)
        if i in self.dependent_indices(j):
            raise GHTError(
                f"control point {i} of segment {j} is determined by a joint (dependent points "
                f"{self.dependent_indices(j)}); move a free point or change the joint"
            )
        pts = np.array(self._free[j].control_points)
        pts[i] = check_points("point", np.reshape(np.asarray(point, dtype=float), (1, -1)))[0]
        self.set_control_points(j, pts)

    def _replace(self, i: int, curve: GHTCurve) -> None:
        old, old_segments = self._free[i], list(self._segments)
        self._free[i] = curve
        try:
            self._resolve(start=i)
        except GHTError:
            self._free[i], self._segments = old, old_segments
            raise

    # -- attributes -------------------------------------------------------------------------
    @property
    def segments(self) -> list[GHTCurve]:
        """The solved segments (a new list; GHTCurves are immutable)."""
        return list(self._segments)

    @property
    def closed(self) -> bool:
        return self._closed

    @property
    def continuity(self) -> list[Continuity]:
        """Continuity at each joint (the last one is the wrap joint of a closed chain)."""
        return list(self._continuity)

    @property
    def g_parameters(self) -> list[tuple[float, float, float]]:
        """``(k, beta2, beta3)`` per joint (``(1, 0, 0)`` at C joints)."""
        return list(self._g)

    @property
    def n_segments(self) -> int:
        return len(self._segments)

    @property
    def n_joints(self) -> int:
        return len(self._continuity)

    @property
    def dim(self) -> int:
        return self._segments[0].dim

    def __len__(self) -> int:
        return len(self._segments)

    def __iter__(self) -> Iterator[GHTCurve]:
        return iter(list(self._segments))

    def __getitem__(self, i: int) -> GHTCurve:
        return self._segments[self._check_index(i)]

    def __repr__(self) -> str:
        kind = "closed" if self._closed else "open"
        return (
            f"CompositeCurve({self.n_segments} segments, {kind}, dim={self.dim}, "
            f"continuity=[{', '.join(c.value for c in self._continuity)}])"
        )

    def joint_segments(self, j: int) -> tuple[GHTCurve, GHTCurve]:
        """``(A, B)``: the segments meeting at joint ``j`` (A's end, B's start)."""
        if not (isinstance(j, (int, np.integer)) and 0 <= j < self.n_joints):
            raise GHTError(f"joint={j!r} is out of range; allowed joints are 0..{self.n_joints - 1}")
        n = self.n_segments
        return self._segments[j], self._segments[(j + 1) % n]

    # -- evaluation -------------------------------------------------------------------------
    def locate(self, s: Any) -> tuple[np.ndarray, np.ndarray]:
        """Map global parameters ``s ∈ [0, n]`` to (segment index j, local t = s - j).

        Raises:
            GHTError: s outside [0, n_segments] or not finite.
        """
        ss, _ = as_parameter_array(s, "s")
        n = self.n_segments
        if ss.size and (ss.min() < -1e-9 or ss.max() > n + 1e-9):
            bad = ss[(ss < -1e-9) | (ss > n + 1e-9)][0]
            raise GHTError(f"s={bad:g} is outside the parameter domain [0, {n}] of this composite curve")
        ss = np.clip(ss, 0.0, float(n))
        j = np.minimum(np.floor(ss).astype(int), n - 1)
        return j, ss - j

    def _eval(self, s: Any, order: int) -> np.ndarray:
        _, scalar = as_parameter_array(s, "s")
        j, t = self.locate(s)
        out = np.empty((t.size, self.dim))
        for idx in np.unique(j):
            mask = j == idx
            out[mask] = self._segments[idx].derivative(np.clip(t[mask], 0.0, 1.0), order)
        return out[0] if scalar else out

    def evaluate(self, s: Any) -> np.ndarray:
        """Points ``X(s) = P_j(s - j)``, ``j = min(floor(s), n-1)``, at global parameters s.

        Args:
            s: scalar or 1-D array in ``[0, n_segments]``.

        Returns:
            Array (len(s), dim), or (dim,) for scalar s.

        Raises:
            GHTError: s outside the domain or not finite.
        """
        return self._eval(s, 0)

    __call__ = evaluate

    def derivative(self, s: Any, order: int = 1) -> np.ndarray:
        """``d^r X / ds^r = P_j^(r)(s - j)`` (unit parameter intervals, so no chain-rule factor).

        Args:
            s: scalar or 1-D array in ``[0, n_segments]``; at an interior joint the right-hand
                segment is used.
            order: r = 0..3.

        Returns:
            Array (len(s), dim), or (dim,) for scalar s.

        Raises:
            GHTError: s outside the domain, bad order.
        """
        return self._eval(s, _check_order(order))

    def curvature(self, s: Any) -> np.ndarray:
        r"""Curvature ``κ = |X' × X''| / |X'|³`` at global parameters s
        (:func:`ght_cad.curves.curve.curvature_from_derivatives`: 0 to round-off on straight segments)."""
        return curvature_from_derivatives(self.derivative(s, 1), self.derivative(s, 2))

    def arc_length(self, *, rtol: float = 1e-13) -> float:
        """Total arc length ``Σ_j ∫_0^1 |P_j'(t)| dt`` (Gauss–Legendre per segment)."""
        return float(sum(seg.arc_length(rtol=rtol) for seg in self._segments))

    length = property(lambda self: self.arc_length(), doc="Total arc length.")

    def joint_reports(self, tol: float = 1e-9) -> list[JointReport]:
        """:func:`~ght_cad.curves.continuity.measure_continuity` at every joint (wrap joint last).

        Args:
            tol: relative tolerance (see measure_continuity for its definition).

        Returns:
            One :class:`~ght_cad.curves.continuity.JointReport` per joint.
        """
        return [measure_continuity(*self.joint_segments(j), tol=tol) for j in range(self.n_joints)]

    def control_polygon(self) -> np.ndarray:
        """All control points, segment after segment (shared joint points repeated)."""
        return np.vstack([seg.control_points for seg in self._segments])

    # -- construction helpers -------------------------------------------------------------------
    @classmethod
    def through_points(
        cls,
        points: Any,
        *,
        degree: int = 5,
        continuity: Any = "G2",
        closed: bool = False,
        mu: float = 0.0,
        nu: float = 0.0,
        gamma: float = 0.0,
    ) -> "CompositeCurve":
        r"""A chain whose joints pass through ``points``: segment j runs from ``Q_j`` to ``Q_{j+1}``.

        Initial segments are the cubic Hermite (Catmull–Rom, chord-scaled tangents) pieces
        sampled at ``i/degree`` as control points; then every joint is solved with
        ``continuity``. At G joints ``k_j = |Q_{j+2} - Q_{j+1}| / |Q_{j+1} - Q_j|`` (chord-length
        ratio, so the parameter speed follows the spacing) and ``β2 = β3 = 0``. Segment ends
        ``Q_{j+1}`` are kept because a segment's last point is free when ``degree > r`` (open)
        or solved to ``Q_0`` by the wrap joint (closed).

        Args:
            points: (count, dim) points, count >= 2 (>= 3 when closed); no two consecutive equal.
            degree: degree of every segment (>= the continuity order + 1; closed chains need
                ``2 r + 1``).
            continuity: one value or one per joint.
            closed: close the chain through ``Q_0`` (``count`` segments instead of ``count - 1``).
            mu, nu, gamma: shape parameters of every segment.

        Raises:
            GHTError: too few points, repeated consecutive points, too low a degree.
        """
        from ..core._validate import check_degree

        Q = check_points("points", points, min_count=3 if closed else 2)
        m = check_degree(degree)
        P = np.vstack([Q, Q[:1]]) if closed else Q
        n = len(P) - 1
        chords = np.linalg.norm(np.diff(P, axis=0), axis=1)
        if np.any(chords <= 1e-12 * max(1.0, float(np.abs(P).max()))):
            j = int(np.argmin(chords))
            raise GHTError(f"points {j} and {(j + 1) % len(Q)} coincide; consecutive points must differ")
        conts = _per_joint("continuity", continuity, n if closed else n - 1, Continuity.parse)
        need = max([c.order for c in conts] + [0]) + 1
        if closed:
            need = max(need, 2 * max(c.order for c in conts) + 1)
        if m < need:
            raise GHTError(
                f"degree={m} is too low for continuity {', '.join(sorted({c.value for c in conts}))} "
                f"{'(closed)' if closed else ''} through points; it needs degree >= {need}"
            )
        # Catmull-Rom tangents (per unit parameter of each segment), chord-scaled
        tangents = np.empty_like(P)
        for i in range(n + 1):
            if closed:
                prev, nxt = P[(i - 1) % n], P[(i + 1) % n] if i < n else P[1]
                lp, ln = chords[(i - 1) % n], chords[i % n]
            else:
                prev, nxt = P[max(i - 1, 0)], P[min(i + 1, n)]
                lp, ln = chords[max(i - 1, 0)], chords[min(i, n - 1)]
            d = (nxt - prev) / (lp + ln if 0 < i < n or closed else max(lp, ln))
            tangents[i] = d
        t = np.linspace(0.0, 1.0, m + 1)[:, None]
        h00, h10 = 2 * t**3 - 3 * t**2 + 1, t**3 - 2 * t**2 + t
        h01, h11 = -2 * t**3 + 3 * t**2, t**3 - t**2
        segs = []
        for j in range(n):
            L = chords[j]
            pts = h00 * P[j] + h10 * L * tangents[j] + h01 * P[j + 1] + h11 * L * tangents[j + 1]
            segs.append(GHTCurve(pts, mu, nu, gamma))
        nj = len(conts)
        k = [float(chords[(j + 1) % n] / chords[j]) for j in range(nj)]
        for j, c in enumerate(conts):
            if not c.geometric:
                k[j] = 1.0
        return cls(segs, conts, closed=closed, k=k, beta2=0.0, beta3=0.0)

    # -- (de)serialization ----------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        """Plain data: ``{"type", "segments": [GHTCurve.to_dict()], "continuity", "closed", "k", "beta2", "beta3"}``.

        The solved segments are stored; :meth:`from_dict` re-solves them, which reproduces the
        same points exactly (the solve only rewrites dependent points from their predecessors).
        """
        return {
            "type": "CompositeCurve",
            "segments": [seg.to_dict() for seg in self._segments],
            "continuity": [c.value for c in self._continuity],
            "closed": self._closed,
            "k": [g[0] for g in self._g],
            "beta2": [g[1] for g in self._g],
            "beta3": [g[2] for g in self._g],
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> "CompositeCurve":
        """Inverse of :meth:`to_dict`.

        Raises:
            GHTError: missing keys or invalid content.
        """
        if not isinstance(data, dict) or "segments" not in data:
            raise GHTError("composite data must be a dict with a 'segments' list (see CompositeCurve.to_dict)")
        segs = [GHTCurve.from_dict(d) for d in data["segments"]]
        return cls(
            segs,
            data.get("continuity", "C0"),
            closed=bool(data.get("closed", False)),
            k=data.get("k", 1.0),
            beta2=data.get("beta2", 0.0),
            beta3=data.get("beta3", 0.0),
        )
