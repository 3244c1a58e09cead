"""Developable surfaces (spec section 5, issue 27): one module per piece, this package imports none.

Modules: :mod:`~ght_cad.developables.envelope` (the envelope of control planes, tangent, rectifying
and composite developables and their joints, spec 5.2-5.4 and 5.6; old path
``ght_cad.developables.envelope``), :mod:`~ght_cad.developables.canal` (canal surfaces, 5.5),
:mod:`~ght_cad.developables.fit` (the certified B-spline fit of a ruled surface),
:mod:`~ght_cad.developables.jets` and :mod:`~ght_cad.developables.checks` (jets and argument
checks, which need none of the surfaces). ``envelope`` re-imports every name of ``canal``, ``fit``,
``jets`` and ``checks`` that it held before they moved.
"""
