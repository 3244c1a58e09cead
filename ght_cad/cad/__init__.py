"""Thin adapters from ght_cad's plain data to CAD kernels (build123d/OCP and cadquery).

Importing :mod:`ght_cad` never imports this package; importing ``ght_cad.cad`` imports OCP.
"""
