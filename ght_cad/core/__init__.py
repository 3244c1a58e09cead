"""The core layer (issue 27): what every other layer uses, numpy only, no geometry.

Modules: :mod:`~ght_cad.core.errors` (the exception hierarchy), :mod:`~ght_cad.core._validate`
(input checks naming the bad value), :mod:`~ght_cad.core._vec` (small vector kernels),
:mod:`~ght_cad.core._quadrature` (Gauss–Legendre), :mod:`~ght_cad.core._cache` (read-only caches),
:mod:`~ght_cad.core._lazy` (PEP 562 lazy names), :mod:`~ght_cad.core.io` (atomic files),
:mod:`~ght_cad.core.outdir` (output folders and their locks), :mod:`~ght_cad.core.progress`
(progress bar), :mod:`~ght_cad.core.step_guard` (STEP text scan), :mod:`~ght_cad.core.workers`
(worker processes), :mod:`~ght_cad.core._kernel` (the CAD kernel registry) and
:mod:`~ght_cad.core._aliases` (the import hook of the moved modules' old paths). Each moved one keeps
its old path ``ght_cad.<name>`` (the same module object). This package imports none of them:
``import ght_cad.core`` is free.
"""
