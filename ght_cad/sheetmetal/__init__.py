"""Sheet metal (issue 27): thickness, bending and joined panels of the flat pattern (spec section 6.1).

Modules: :mod:`~ght_cad.sheetmetal.sheet` (the sheet: thickness, K-factor, the neutral surface at
``K T``, offset checks, forming rows), :mod:`~ght_cad.sheetmetal.plate` (plate solids of a ruled
surface as B-spline poles: both skins, volume), :mod:`~ght_cad.sheetmetal.join_panels` (panels
joined into one blank across smooth seams) and the package :mod:`~ght_cad.sheetmetal.blank` (one
blank per bent part: connected unfolding of a sheet solid's skin, issue 23). Each keeps its old path ``ght_cad.<name>`` (the same
module object). This package imports none of them.
"""
