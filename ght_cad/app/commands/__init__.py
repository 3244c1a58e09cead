"""The handlers of the ``ght-cad`` subcommands, below :mod:`ght_cad.app.cli` (issue 27): shared helpers
(:mod:`.common`: exit codes, JSON output, argument parsing, staged output files), ``plot-basis``
and ``curve`` (:mod:`.curves`), the design-file commands (:mod:`.design`), ``unroll``
(:mod:`.unroll`), ``batch`` (:mod:`.batch`) and ``export`` (:mod:`.export`).

:mod:`ght_cad.app.cli` keeps the parser, ``main`` and the signal and stdout handling, and re-imports
every name moved here. :mod:`ght_cad.app.batch` and :mod:`ght_cad.app.approximate_cli` take ``dumps`` from
:mod:`.common`, so neither imports the CLI that runs them (the import cycle through the CLI is gone).
"""
