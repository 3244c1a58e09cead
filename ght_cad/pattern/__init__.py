"""Flat patterns below :mod:`ght_cad.flat_pattern` (issue 27): the model (:mod:`.model`: boundary
edges, panels, the distortion report), the layout and edge marks (:mod:`.layout`) and the writers
(:mod:`.io`: DXF through ezdxf and a hand-written R12 writer, SVG, PNG).

These modules import nothing above the curves layer: :class:`ght_cad.flat_pattern.FlatPattern`
(which reaches the sheet and the CAD adapters) stays in :mod:`ght_cad.flat_pattern`, and every
name moved here stays importable from there.
"""
