r"""ght metadata on kernel shapes that follows the shape when it is moved, or is dropped.

``ght_edge``/``ght_wire``/``ght_face``/``GHTBezierLine``/``developable_loft`` attach what they
certify to the shape they return: ``ght_bspline`` (the B-spline data and its certified deviation),
``ght_curve`` (the exact GHT curve), ``ght_max_deviation`` and ``ght_loft`` (the core loft). Those
describe the geometry *where it was made*; build123d's ``moved``/``located``/``rotate``/
``translate``/``mirror``/``scale``/``transform_shape`` copy the Python attributes to the copy
unchanged, and ``locate``/``move`` (build123d and cadquery) move a shape in place, so a plain
attribute would describe a curve that is no longer there.

Here the names are properties of a subclass of the shape's class (same class name, same
behaviour, nothing of build123d or cadquery is patched). When made, the shape's geometry is sampled
(9 points per edge, 3 x 3 per face, in explorer order, locations applied). When read, it is sampled
again and matched by a similarity ``x -> s R x + b`` (R orthogonal: rotations and mirrors, s > 0),
fitted to the samples (Umeyama, reflections allowed) and accepted when it reproduces every sample
to ``1e-9`` of the size:

* the same samples: the values as attached (the same objects);
* a similarity: ``ght_bspline``/``ght_curve`` are the transformed ones (exact for GHT curves,
  which are affinely invariant: poles / control points mapped), deviations scaled by s;
  ``ght_loft`` (a core object in the old placement) is dropped;
* anything else (non-uniform scale, a boolean's new geometry): every value is dropped.

A dropped value raises ``AttributeError`` (``getattr(shape, "ght_bspline", None)`` is None), as on
cadquery's own copies, which are new shapes without the attributes.
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

__all__ = ["GHT_NAMES", "certified", "certified_class", "certify", "shape_samples"]

#: the ght metadata names that follow their shape
GHT_NAMES = ("ght_bspline", "ght_curve", "ght_max_deviation", "ght_loft")
_RECORD = "_ght_record"


class _Record:
    """Values attached to a shape and the shape's samples at that moment (shared, never copied:
    build123d deep-copies a shape's ``__dict__`` into its moved copies)."""

    __slots__ = ("values", "samples")

    def __init__(self, values: dict[str, Any], samples: np.ndarray) -> None:
        self.values = values
        self.samples = samples

    def __copy__(self) -> "_Record":
        return self

    def __deepcopy__(self, memo: Any) -> "_Record":
        return self


def shape_samples(shape: Any) -> np.ndarray:
    """Points of a shape's geometry, locations applied: 9 per edge (uniform in the edge's
    parameter range), 3 x 3 per face (parameter box), edges then faces in explorer order."""
    from OCP.BRepAdaptor import BRepAdaptor_Curve, BRepAdaptor_Surface
    from OCP.BRepTools import BRepTools
    from OCP.TopAbs import TopAbs_EDGE, TopAbs_FACE
    from OCP.TopExp import TopExp_Explorer
    from ._ocp import TopoDS

    w = getattr(shape, "wrapped", shape)
    pts: list[tuple[float, float, float]] = []
    ex = TopExp_Explorer(w, TopAbs_EDGE)
    while ex.More():
        ad = BRepAdaptor_Curve(TopoDS.Edge_s(ex.Current()))
        for t in np.linspace(ad.FirstParameter(), ad.LastParameter(), 9):
            p = ad.Value(float(t))
            pts.append((p.X(), p.Y(), p.Z()))
        ex.Next()
    ex = TopExp_Explorer(w, TopAbs_FACE)
    while ex.More():
        face = TopoDS.Face_s(ex.Current())
        u0, u1, v0, v1 = BRepTools.UVBounds_s(face)
        ad = BRepAdaptor_Surface(face)
        for u in np.linspace(u0, u1, 3):
            for v in np.linspace(v0, v1, 3):
                p = ad.Value(float(u), float(v))
                pts.append((p.X(), p.Y(), p.Z()))
        ex.Next()
    return np.array(pts, dtype=float).reshape(-1, 3)


def _similarity(P: np.ndarray, Q: np.ndarray) -> tuple[float, np.ndarray, np.ndarray] | None:
    """``(s, R, b)`` with ``Q ≈ s P R^T + b`` (R orthogonal, det ±1) to 1e-9 of the size, else None.

    Least squares (Umeyama without the proper-rotation constraint): ``H = Pc^T Qc = U S V^T``,
    ``R = V U^T``, ``s = ΣS / |Pc|²``, ``b = q̄ - s R p̄``.
    """
    if P.shape != Q.shape or P.size == 0:
        return None
    size = max(float(np.ptp(P, axis=0).max()), float(np.ptp(Q, axis=0).max()), 1e-300)
    p0, q0 = P.mean(axis=0), Q.mean(axis=0)
    Pc, Qc = P - p0, Q - q0
    norm2 = float(np.sum(Pc * Pc))
    if norm2 <= (1e-12 * size) ** 2:  # a point: only a translation is seen
        s, R = 1.0, np.eye(3)
    else:
        U, S, Vt = np.linalg.svd(Pc.T @ Qc)
        R = Vt.T @ U.T
        s = float(S.sum() / norm2)
        if abs(s - 1.0) <= 1e-12:  # a rigid motion: deviations stay as certified, bit for bit
            s = 1.0
    b = q0 - s * R @ p0
    if not (s > 0 and np.abs(P @ (s * R).T + b - Q).max() <= 1e-9 * size):
        return None
    return s, R, b


def _map_points(pts: np.ndarray, s: float, R: np.ndarray, b: np.ndarray, size: float) -> np.ndarray:
    """Points (..., 2|3) mapped by ``x -> s R x + b``; 2-D points lie in z = 0 and stay 2-D when
    their images do (to 1e-13 of the size)."""
    dim = pts.shape[-1]
    lifted = np.concatenate([pts, np.zeros(pts.shape[:-1] + (3 - dim,))], axis=-1) if dim < 3 else pts
    out = lifted @ (s * R).T + b
    if dim < 3 and np.abs(out[..., dim:]).max() <= 1e-13 * max(size, 1e-300):
        return np.ascontiguousarray(out[..., :dim])
    return out


def _transformed(value: Any, s: float, R: np.ndarray, b: np.ndarray, size: float) -> Any:
    from ..surfaces.bspline import BSplineCurveData, BSplineSurfaceData
    from ..curves.curve import GHTCurve

    if isinstance(value, (list, tuple)):
        items = [_transformed(v, s, R, b, size) for v in value]
        return type(value)(items)
    if isinstance(value, (BSplineCurveData, BSplineSurfaceData)):
        dev = None if value.max_deviation is None else float(value.max_deviation) * s
        return dataclasses.replace(value, poles=_map_points(value.poles, s, R, b, size), max_deviation=dev,
                                   info=dict(value.info))
    if isinstance(value, GHTCurve):
        return value.with_control_points(_map_points(value.control_points, s, R, b, size))
    if isinstance(value, float):
        return value * s
    raise _Drop


class _Drop(Exception):
    """Internal: a value that cannot follow its shape."""


def _current(shape: Any) -> dict[str, Any]:
    """The record's values for the shape's present geometry; dropped ones are absent."""
    rec = shape.__dict__.get(_RECORD)
    if rec is None:
        return {}
    now = shape_samples(shape)
    if now.shape == rec.samples.shape and np.array_equal(now, rec.samples):
        return dict(rec.values)
    fit = _similarity(rec.samples, now)
    if fit is None:
        return {}
    size = float(np.ptp(rec.samples, axis=0).max()) if rec.samples.size else 0.0
    out = {}
    for name, value in rec.values.items():
        try:
            out[name] = _transformed(value, *fit, size)
        except _Drop:
            pass
    return out


def _property(name: str) -> property:
    def get(self: Any) -> Any:
        values = _current(self)
        if name not in values:
            raise AttributeError(
                f"{name} is not available on this {type(self).__name__}: it was never attached, or the shape "
                "was transformed after it was made in a way the value cannot follow (ght_loft follows no "
                "move; nothing follows a non-uniform scale or a new geometry)"
            )
        return values[name]

    def set_(self: Any, value: Any) -> None:
        values = _current(self)
        values[name] = value
        self.__dict__[_RECORD] = _Record(values, shape_samples(self))

    def delete(self: Any) -> None:
        values = _current(self)
        values.pop(name, None)
        self.__dict__[_RECORD] = _Record(values, shape_samples(self))

    return property(get, set_, delete, f"``{name}`` of this shape where it is now (see :mod:`ght_cad.cad.certified`).")


def certified(cls: type) -> type:
    """Class decorator: the :data:`GHT_NAMES` as properties that follow the shape (module doc)."""
    for name in GHT_NAMES:
        setattr(cls, name, _property(name))
    cls._ght_certified = True
    return cls


_CLASSES: dict[type, type] = {}


def certified_class(cls: type) -> type:
    """The subclass of ``cls`` with the certified properties (same name; one per class)."""
    if cls.__dict__.get("_ght_certified"):
        return cls
    sub = _CLASSES.get(cls)
    if sub is None:
        # a plain one-base subclass (a mixin base would make __class__ assignment refuse the layout)
        sub = certified(type(cls.__name__, (cls,), {"__module__": cls.__module__, "__qualname__": cls.__qualname__,
                                                     "__reduce_ex__": _reduce_ex}))
        _CLASSES[cls] = sub
    return sub


def _reduce_ex(self: Any, protocol: int) -> Any:
    """Pickle as the plain base class (the same-named subclass cannot be found by name) and make
    the copy certified again on load; the record travels in the instance state."""
    cls = type(self)
    base = cls.__mro__[1]
    rv = super(cls, self).__reduce_ex__(protocol)
    func, args = rv[0], tuple(rv[1])
    if args and args[0] is cls:
        args = (base,) + args[1:]
    return (_recertify, (func, args)) + tuple(rv[2:])


def _recertify(func: Any, args: tuple) -> Any:
    obj = func(*args)
    obj.__class__ = certified_class(type(obj))
    return obj


def certify(shape: Any, **values: Any) -> Any:
    """Attach ``values`` (names from :data:`GHT_NAMES`) to ``shape`` so that they follow it.

    The shape's class becomes its certified subclass (in place; the shape itself is returned).
    """
    unknown = set(values) - set(GHT_NAMES)
    if unknown:
        raise TypeError(f"unknown ght metadata {sorted(unknown)}; allowed: {GHT_NAMES}")
    shape.__class__ = certified_class(type(shape))
    shape.__dict__[_RECORD] = _Record(dict(values), shape_samples(shape))
    return shape
