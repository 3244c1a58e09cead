"""The application layer (issue 27): what the ``ght-cad`` command runs.

Modules: :mod:`~ght_cad.app.cli` (the parser, ``main``: the console entry point ``ght-cad``),
:mod:`~ght_cad.app.batch` (many designs in parallel processes or on Dask),
:mod:`~ght_cad.app.sweep` (``[sweep]`` variants of a design), :mod:`~ght_cad.app.demo` (the embedded
default design), :mod:`~ght_cad.app.unfold_step` (blanks of a STEP file's bent parts) and
:mod:`~ght_cad.app.approximate_cli` (the ``approximate`` command). The app's packages
(``ght_cad.commands``, ``ght_cad.design``) stay top-level. Each module keeps its old path
``ght_cad.<name>`` (the same module object, through ``ght_cad.core._aliases``, which also keeps
``python -m`` of the old path running the command line). This package imports none of them.
"""
