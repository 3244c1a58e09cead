"""The application layer (issue 27): what the ``ght-cad`` command runs.

Modules: :mod:`~ght_cad.app.cli` (the parser, ``main``: the console entry point ``ght-cad``),
:mod:`~ght_cad.app.batch` (many designs in parallel processes or on Dask),
:mod:`~ght_cad.app.sweep` (``[sweep]`` variants of a design), :mod:`~ght_cad.app.demo` (the embedded
default design), :mod:`~ght_cad.app.unfold_step` (blanks of a STEP file's bent parts),
:mod:`~ght_cad.app.approximate_cli` (the ``approximate`` command), and the packages
:mod:`~ght_cad.app.commands` (the subcommands' handlers, below ``cli``) and
:mod:`~ght_cad.app.design` (design files: schema, validation, the pipeline runner; its
``schema`` subpackage holds the file format). Each module keeps its old path
``ght_cad.<name>`` (the same module object, through ``ght_cad.core._aliases``, which also keeps
``python -m`` of the old path running the command line). This package imports none of them.
"""
