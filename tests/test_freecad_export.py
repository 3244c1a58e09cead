"""The workbench's named STEP export, run inside Debian's FreeCAD and read back with OCP here.

``freecadcmd -t freecad.ght_workbench.tests.fc_export`` writes one STEP file holding a GHT curve,
a composite curve, a developable (Label "Platte Ä"), a joined developable shell, a flat pattern
(Label with quotes) and a box. This side reads it with OCP 7.9's XCAF reader
(``STEPCAFControl_Reader`` + ``XCAFDoc_ShapeTool`` + ``TDataStd_Name``), independently of
FreeCAD: the root product is named after the document and each component refers to a product
named by the feature's Label.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from freecad_launch import run_fc_unittest

pytestmark = pytest.mark.freecad


def _xcaf_tree(path: Path) -> tuple[list[str], list[str]]:
    """(names of the free shapes, names of the products the root's components refer to)."""
    from OCP.IFSelect import IFSelect_RetDone
    from OCP.STEPCAFControl import STEPCAFControl_Reader
    from OCP.TCollection import TCollection_ExtendedString
    from OCP.TDataStd import TDataStd_Name
    from OCP.TDF import TDF_Label

    from ght_cad.cad._ocp import TDF_LabelSequence
    from OCP.TDocStd import TDocStd_Document
    from OCP.XCAFDoc import XCAFDoc_DocumentTool

    doc = TDocStd_Document(TCollection_ExtendedString("XmlOcaf"))
    reader = STEPCAFControl_Reader()
    reader.SetNameMode(True)
    assert reader.ReadFile(str(path)) == IFSelect_RetDone
    assert reader.Transfer(doc)
    tool = XCAFDoc_DocumentTool.ShapeTool_s(doc.Main())

    def name(label: TDF_Label) -> str | None:
        attr = TDataStd_Name()
        return attr.Get().ToExtString() if label.FindAttribute(TDataStd_Name.GetID_s(), attr) else None

    free = TDF_LabelSequence()
    tool.GetFreeShapes(free)
    roots = [free.Value(i) for i in range(1, free.Length() + 1)]
    parts = []
    for root in roots:
        comps = TDF_LabelSequence()
        tool.GetComponents_s(root, comps)
        for i in range(1, comps.Length() + 1):
            ref = TDF_Label()
            assert tool.GetReferredShape_s(comps.Value(i), ref)
            parts.append(name(ref))
    return [name(r) for r in roots], parts


def test_named_step_export_inside_freecadcmd(tmp_path: Path) -> None:
    run_fc_unittest("freecad.ght_workbench.tests.fc_export", tmp_path, min_tests=4)
    expected = json.loads((tmp_path / "export_named.json").read_text(encoding="utf-8"))
    roots, parts = _xcaf_tree(tmp_path / "export_named.step")
    assert roots == [expected["root"]]
    assert sorted(parts) == sorted(expected["labels"])
    assert "Platte Ä" in parts and "Zuschnitt \"1\" 'A'" in parts
    # one object alone: it is the root product itself
    single = sorted(tmp_path.glob("export_Developable*.step"))
    assert single, sorted(p.name for p in tmp_path.iterdir())
    assert _xcaf_tree(single[0]) == (["Platte Ä"], [])
