"""Unrolling (issue 27): developing ruled surfaces and CAD faces into the plane (spec section 6).

Modules: :mod:`~ght_cad.unrolling.unroll` (the stable function ``unroll`` of spec section 9; the
module itself is callable and stays ``ght_cad.unroll``), :mod:`~ght_cad.unrolling.ruled_development`
(the development of one ruled surface, shared by the face unrolling and the panel joiner) and
:mod:`~ght_cad.unrolling.face_unroll` (CAD faces through the face adapter), with the package
:mod:`~ght_cad.unrolling.faces` below it (the kernel-free pieces of a CAD face: adapter data, ruled
surface, directions, area, loops). Each keeps its old path ``ght_cad.<name>`` (the same module
object). This package imports none of them.
"""
