"""Tests that run inside FreeCAD (``freecadcmd -t freecad.ght_workbench.tests.<module>``).

The pytest side (``tests/test_freecad_workbench.py`` in the repository) launches them as
subprocesses; ``GHT_FC_OUT`` names a directory for files they write.
"""
