"""The kernel-free pieces of unrolling a CAD face, below :mod:`ght_cad.unrolling.face_unroll` (issue 27): the
face as an adapter describes it (:mod:`.adapter`), its ruled surface (:mod:`.ruled_face`), which
isolines are straight (:mod:`.directions`), its 3-D area (:mod:`.area`) and its boundary loops in
(u, v) (:mod:`.loops`).

These modules import nothing above the surfaces they describe: the development itself
(:func:`ght_cad.unrolling.face_unroll.unroll_face_data`, which reaches
:mod:`ght_cad.unrolling.unroll` and :mod:`ght_cad.sheetmetal.sheet`) stays in
:mod:`ght_cad.unrolling.face_unroll`, and every name moved here stays importable from there. Old
path of this package: ``ght_cad.unrolling.faces``.
"""
