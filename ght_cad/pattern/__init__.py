"""Flat patterns (issue 27): the pattern of an unrolled surface, its layout and its writers.

Modules: :mod:`~ght_cad.pattern.flat_pattern` (:class:`FlatPattern`, the distortion measures of spec
section 6; it reaches the CAD adapters only through the kernel registry), :mod:`~ght_cad.pattern.model`
(boundary edges, panels, the distortion report), :mod:`~ght_cad.pattern.layout` (layout and edge
marks), :mod:`~ght_cad.pattern.forming` (the sheet's forming rows as presented by the pattern),
:mod:`~ght_cad.pattern.outline_arcs` (outlines as exact lines and circular arcs) and
:mod:`~ght_cad.pattern.io` (DXF through ezdxf and a hand-written R12 writer, SVG, PNG).
``flat_pattern`` and ``outline_arcs`` keep their old paths ``ght_cad.<name>`` (the same module
object), and every name moved out of :mod:`~ght_cad.pattern.flat_pattern` into ``model``, ``layout``
and ``io`` stays importable from there. This package imports none of them.
"""
