"""OCCT collection classes under their OCP 7.9 names, on OCP 7.9 and OCP 8 alike.

OCP 8 (OCCT 8, build123d 0.13) dropped the ``TColgp``/``TColStd``/``TopTools``/``TDF`` typedef
modules' collection classes: the same NCollection templates are bound once in
``OCP.collections`` under template names (``TColgp_Array1OfPnt`` is ``Array1_gp_Pnt``,
``TopTools_IndexedMapOfShape`` is ``IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher``, ...), and
the downcasts ``TopoDS.Edge_s`` & co. became ``TopoDS.Edge`` & co.
The adapters import these names from here; the classes are the same (same methods, 1-based).
"""

from __future__ import annotations

try:  # OCP 7.9
    from OCP.TColgp import TColgp_Array1OfPnt, TColgp_Array2OfPnt
    from OCP.TColStd import TColStd_Array1OfInteger, TColStd_Array1OfReal, TColStd_SequenceOfAsciiString
    from OCP.TDF import TDF_LabelSequence
    from OCP.TopTools import TopTools_IndexedDataMapOfShapeListOfShape, TopTools_IndexedMapOfShape
except ImportError:  # OCP 8
    from OCP.collections import Array1_double as TColStd_Array1OfReal
    from OCP.collections import Array1_gp_Pnt as TColgp_Array1OfPnt
    from OCP.collections import Array1_int as TColStd_Array1OfInteger
    from OCP.collections import Array2_gp_Pnt as TColgp_Array2OfPnt
    from OCP.collections import IndexedDataMap_TopoDS_Shape_List_TopoDS_Shape_TopTools_ShapeMapHasher as \
        TopTools_IndexedDataMapOfShapeListOfShape
    from OCP.collections import IndexedMap_TopoDS_Shape_TopTools_ShapeMapHasher as TopTools_IndexedMapOfShape
    from OCP.collections import Sequence_TCollection_AsciiString as TColStd_SequenceOfAsciiString
    from OCP.collections import Sequence_TDF_Label as TDF_LabelSequence

from OCP.TopoDS import TopoDS as _TopoDS

if hasattr(_TopoDS, "Edge_s"):  # OCP 7.9: TopoDS is a class of static methods
    TopoDS = _TopoDS
else:  # OCP 8: TopoDS is a namespace of free functions without the `_s` suffix

    class TopoDS:  # type: ignore[no-redef]
        """``TopoDS.Edge_s`` & co. (the OCP 7.9 names) on OCP 8's ``TopoDS.Edge`` & co."""

        Vertex_s = staticmethod(_TopoDS.Vertex)
        Edge_s = staticmethod(_TopoDS.Edge)
        Wire_s = staticmethod(_TopoDS.Wire)
        Face_s = staticmethod(_TopoDS.Face)
        Shell_s = staticmethod(_TopoDS.Shell)
        Solid_s = staticmethod(_TopoDS.Solid)
        CompSolid_s = staticmethod(_TopoDS.CompSolid)
        Compound_s = staticmethod(_TopoDS.Compound)


__all__ = [
    "TopoDS",
    "TColgp_Array1OfPnt",
    "TColgp_Array2OfPnt",
    "TColStd_Array1OfInteger",
    "TColStd_Array1OfReal",
    "TColStd_SequenceOfAsciiString",
    "TDF_LabelSequence",
    "TopTools_IndexedDataMapOfShapeListOfShape",
    "TopTools_IndexedMapOfShape",
]
