"""The pieces of :mod:`ght_cad.developable` that need none of its surfaces (issue 27): jets and
argument checks (:mod:`.jets`, :mod:`.checks`), the certified B-spline fit of a ruled surface
(:mod:`.fit`) and canal surfaces (:mod:`.canal`).

The envelope, tangent, rectifying and composite developables and their joints stay in
:mod:`ght_cad.developable` (their ``to_face`` reaches the CAD adapters); every name moved here
stays importable from there.
"""
