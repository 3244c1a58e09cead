"""The surfaces layer's base modules (issue 27); they import only ``ght_cad.core`` and ``ght_cad.curves``.

Modules: :mod:`~ght_cad.surfaces.planes` (plane algebra), :mod:`~ght_cad.surfaces.bspline`
(certified B-spline conversion and fits), :mod:`~ght_cad.surfaces.nurbs` (kernel-free NURBS
evaluation), :mod:`~ght_cad.surfaces.patch` (:class:`GHTSurface`) and
:mod:`~ght_cad.surfaces.ruled` (ruled surfaces). Each keeps its old path ``ght_cad.<name>`` (the
same module object). The rest of the surfaces layer is in its own packages:
:mod:`ght_cad.pattern`, :mod:`ght_cad.developables`, :mod:`ght_cad.unrolling`,
:mod:`ght_cad.sheetmetal`. This package imports none of them.
"""
