"""Writers of a :class:`ght_cad.pattern.flat_pattern.FlatPattern`: :mod:`.dxf` (ezdxf R2010, hand-written
ASCII R12), :mod:`.svg`, :mod:`.png`. They read the pattern through its attributes only (no import
of :mod:`ght_cad.pattern.flat_pattern`); ezdxf and matplotlib are imported inside the writing functions.
"""
