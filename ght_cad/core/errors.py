"""Exception types raised by ght_cad.

Every error is a :class:`ValueError` subclass so that callers that only know the spec's
contract ("out-of-range input raises ValueError") keep working, while CAD code can catch the
precise condition.
"""

from __future__ import annotations

__all__ = [
    "GHTError",
    "ShapeParameterError",
    "DegenerateGeometryError",
    "EdgeOfRegressionError",
    "NotDevelopableError",
    "SingularJoinError",
    "ConversionError",
]


class GHTError(ValueError):
    """Base class of all ght_cad input and geometry errors."""


class ShapeParameterError(GHTError):
    """A shape parameter (mu, nu, gamma) is outside [-1, 1] or not finite."""


class DegenerateGeometryError(GHTError):
    """Coincident or parallel planes, zero-length tangents, collapsed control polygons."""


class EdgeOfRegressionError(DegenerateGeometryError):
    """A developable strip contains (part of) its edge of regression."""


class NotDevelopableError(GHTError):
    """A surface or face is not developable within the requested tolerance."""


class SingularJoinError(GHTError):
    """A continuity condition cannot be imposed (zero newest-point coefficient, k <= 0)."""


class ConversionError(GHTError):
    """A B-spline conversion could not reach the requested deviation."""
