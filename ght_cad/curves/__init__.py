"""The curves layer (issue 27): GHT-Bézier seeds, bases and curves; imports only ``ght_cad.core``.

Modules: :mod:`~ght_cad.curves.seeds` (the seed functions), :mod:`~ght_cad.curves.basis` (the
GHT-Bernstein basis, spec section 2), :mod:`~ght_cad.curves.curve` (:class:`GHTCurve`),
:mod:`~ght_cad.curves.continuity` (G/C joins), :mod:`~ght_cad.curves.composite` (chains of
segments), :mod:`~ght_cad.curves.analysis` (curvature, fairness) and :mod:`~ght_cad.curves.plotting`
(matplotlib figures, imported inside the functions). Each keeps its old path ``ght_cad.<name>``
(the same module object). This package imports none of them.
"""
