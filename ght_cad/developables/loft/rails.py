"""Rails of the developable loft (spec section 5.7): the :class:`Rail` protocol, adapters for
callables and curve objects (:func:`as_rail`), the reversed rail and the derivative jets the
tracing solver reads."""

from __future__ import annotations

from typing import Any, Callable, Protocol, runtime_checkable

import numpy as np

from ...core._validate import as_parameter_array
from ...curves.curve import GHTCurve
from ...core.errors import GHTError


# ----------------------------------------------------------------------------------------------
# rails
# ----------------------------------------------------------------------------------------------
@runtime_checkable
class Rail(Protocol):
    """What a rail must provide: positions and derivatives on t ∈ [0, 1], each (n, 3).

    GHTCurve objects qualify; CAD edges are wrapped in :class:`CallableRail` by the adapters.
    """

    def evaluate(self, t: Any) -> np.ndarray:  # pragma: no cover - protocol
        """Points ``r(t)``, shape (n, 3)."""

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:  # pragma: no cover - protocol
        """Derivative ``r^(order)(t)``, shape (n, 3)."""


def _fd(fun: Callable[[np.ndarray], np.ndarray], t: np.ndarray, h: float = 1e-3) -> np.ndarray:
    r"""Derivative of ``fun`` by 4th-order differences inside [0, 1].

    Central ``(-f(t+2h) + 8f(t+h) - 8f(t-h) + f(t-2h)) / 12h`` where the stencil fits in [0, 1],
    else the one-sided ``±(-25 f(t) + 48 f(t±h) - 36 f(t±2h) + 16 f(t±3h) - 3 f(t±4h)) / 12h``.
    """
    out = np.empty((t.size, 3))
    lo = t < 2 * h
    hi = (t > 1 - 2 * h) & ~lo
    mid = ~(lo | hi)
    if mid.any():
        x = t[mid]
        out[mid] = (-fun(x + 2 * h) + 8 * fun(x + h) - 8 * fun(x - h) + fun(x - 2 * h)) / (12 * h)
    for mask, sgn in ((lo, 1.0), (hi, -1.0)):
        if mask.any():
            x = t[mask]
            hh = sgn * h
            out[mask] = (-25 * fun(x) + 48 * fun(x + hh) - 36 * fun(x + 2 * hh) + 16 * fun(x + 3 * hh)
                         - 3 * fun(x + 4 * hh)) / (12 * hh)
    return out


def _as_points(value: Any, n: int, what: str) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.size != 3 * n:
        raise GHTError(f"{what} returned an array of shape {arr.shape}; expected ({n}, 3)")
    return arr.reshape(n, 3)


class CallableRail:
    r"""A rail from plain callables ``position(t)``, ``first(t)`` (and optionally ``second(t)``).

    Each callable takes a 1-D array of parameters in [0, 1] and returns an (n, 3) array. Higher
    derivatives that are not given are computed by 4th-order finite differences of the highest
    given one (step 1e-3 in t, error about 1e-12 of the curve size for a smooth edge), which is
    what the CAD adapters use for edges whose kernel gives only two derivatives.

    Args:
        position: ``t -> r(t)``.
        first: ``t -> r'(t)``.
        second: ``t -> r''(t)`` or None.
        name: label used in error messages.
    """

    def __init__(
        self,
        position: Callable[[np.ndarray], Any],
        first: Callable[[np.ndarray], Any],
        second: Callable[[np.ndarray], Any] | None = None,
        *,
        name: str = "rail",
    ) -> None:
        for nm, f in (("position", position), ("first", first), ("second", second)):
            if f is not None and not callable(f):
                raise GHTError(f"CallableRail {nm} must be callable, got {type(f).__name__}")
        self._f = [position, first, second]
        self.name = name

    def _call(self, r: int, t: np.ndarray) -> np.ndarray:
        return _as_points(self._f[r](t), t.size, f"{self.name} derivative {r}")

    def _deriv(self, t: np.ndarray, r: int) -> np.ndarray:
        if r < len(self._f) and self._f[r] is not None:
            return self._call(r, t)
        return _fd(lambda x: self._deriv(x, r - 1), t)

    def evaluate(self, t: Any) -> np.ndarray:
        """Points ``r(t)``, shape (n, 3)."""
        return self.derivative(t, 0)

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        """``r^(order)(t)`` for order 0..3 (given callables or finite differences of them)."""
        if order not in (0, 1, 2, 3):
            raise GHTError(f"order={order!r} is not allowed; rails give derivatives of order 0..3")
        tt, _ = as_parameter_array(t, "t")
        return self._deriv(tt, order)

    def __repr__(self) -> str:
        return f"CallableRail(name={self.name!r})"


class _ObjectRail:
    """Adapter for any object with ``evaluate(t)`` and ``derivative(t, order)`` (GHTCurve too).

    Orders the object refuses are computed by finite differences of the highest it gives.
    """

    def __init__(self, obj: Any, name: str) -> None:
        self.obj = obj
        self.name = name
        self._max_order = 3

    def _call(self, t: np.ndarray, r: int) -> np.ndarray:
        if r == 0:
            return _as_points(self.obj.evaluate(t), t.size, f"{self.name}.evaluate")
        return _as_points(self.obj.derivative(t, r), t.size, f"{self.name}.derivative(order={r})")

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        tt, _ = as_parameter_array(t, "t")
        if order <= self._max_order:
            try:
                return self._call(tt, order)
            except (NotImplementedError, TypeError, ValueError) as exc:
                if order <= 1 or isinstance(exc, GHTError) and "order" not in str(exc):
                    raise
                self._max_order = order - 1
        return _fd(lambda x: self.derivative(x, order - 1), tt)

    def evaluate(self, t: Any) -> np.ndarray:
        return self.derivative(t, 0)

    def jet(self, t: np.ndarray, k: int) -> list[np.ndarray]:
        """``[r, r', ..., r^(k)]`` at t; one pass for a GHTCurve (:meth:`GHTCurve.derivatives`)."""
        if isinstance(self.obj, GHTCurve) and k <= 3:
            return self.obj.derivatives(t, k)
        return [self.derivative(t, r) for r in range(k + 1)]

    def __repr__(self) -> str:
        return f"{self.name}={self.obj!r}"


def as_rail(obj: Any, name: str = "rail") -> Any:
    """A rail object (``evaluate`` and ``derivative(t, order)`` of orders 0..3) for ``obj``.

    Args:
        obj: a 3-D :class:`~ght_cad.curves.curve.GHTCurve`, a :class:`CallableRail`, or any object with
            ``evaluate(t) -> (n, 3)`` and ``derivative(t, order=1) -> (n, 3)`` on [0, 1]. CAD
            edges (build123d/OCP, FreeCAD ``Part.Edge``) are wrapped by the adapters
            (``ght_cad.cad``, ``freecad_workbench``) into a :class:`CallableRail`.
        name: label used in error messages ("rail_a", "rail_b").

    Raises:
        GHTError: an object without those methods, or a GHTCurve that is not 3-D.
    """
    if isinstance(obj, (CallableRail, _ObjectRail)):
        return obj
    if isinstance(obj, GHTCurve):
        if obj.dim != 3:
            raise GHTError(f"{name} is a GHTCurve of dimension {obj.dim}; a rail must be a 3-D curve")
        return _ObjectRail(obj, name)
    if callable(getattr(obj, "evaluate", None)) and callable(getattr(obj, "derivative", None)):
        return _ObjectRail(obj, name)
    raise GHTError(
        f"{name} is a {type(obj).__name__}; a rail is a 3-D GHTCurve, a CallableRail(position, first, "
        "second=None) or an object with evaluate(t) and derivative(t, order) on [0, 1] (CAD edges: use "
        "the build123d/FreeCAD loft adapters, which wrap them)"
    )


class _Reversed:
    """``r~(s) = r(1 - s)``: derivatives of order k get the sign ``(-1)^k``."""

    def __init__(self, rail: Any) -> None:
        self.rail = rail
        self.name = getattr(rail, "name", "rail") + " (reversed)"

    def derivative(self, t: Any, order: int = 1) -> np.ndarray:
        tt, _ = as_parameter_array(t, "t")
        return (-1.0) ** order * self.rail.derivative(1.0 - tt, order)

    def evaluate(self, t: Any) -> np.ndarray:
        return self.derivative(t, 0)

    def jet(self, t: np.ndarray, k: int) -> list[np.ndarray]:
        return [(-1.0) ** r * x for r, x in enumerate(_jet(self.rail, 1.0 - np.asarray(t, float), k))]


def _jet(rail: Any, t: np.ndarray, k: int) -> list[np.ndarray]:
    """``[r, r', ..., r^(k)]`` at t (the rail's one-pass ``jet`` where it has one)."""
    fast = getattr(rail, "jet", None)
    if fast is not None:
        return fast(t, k)
    return [rail.derivative(t, r) for r in range(k + 1)]


def _det(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """Row-wise ``det(x, y, z) = x · (y × z)`` of (n, 3) arrays (explicit: np.cross is slow on small arrays)."""
    return (x[:, 0] * (y[:, 1] * z[:, 2] - y[:, 2] * z[:, 1])
            + x[:, 1] * (y[:, 2] * z[:, 0] - y[:, 0] * z[:, 2])
            + x[:, 2] * (y[:, 0] * z[:, 1] - y[:, 1] * z[:, 0]))

