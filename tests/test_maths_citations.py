"""Every "spec section X" / "spec X" / "maths X" citation resolves to a heading of docs/maths.md.

The code cites the mathematics by section number ("spec section 5.7", "spec 6.1", "spec sections
5 and 7", "spec 5.2–5.6", "(maths spec, section 1)", "maths 2.1", "section 4" ...). Those numbers
are the headings of ``docs/maths.md`` (the spec's numbering kept). This module scans the code and
the documents for citations, expands lists and ranges, and fails on any number without a
heading; it also checks that the document has the sections the code relies on, each with a
formula. The scanner itself is tested on made-up text (it must find, expand and reject).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MATHS = ROOT / "docs" / "maths.md"

#: What is scanned: the package, the FreeCAD workbench, the documents, examples, benches, tests.
SCANNED = ("ght_cad", "freecad_workbench", "docs", "examples", "bench", "tests", "README.md", "DEVELOPERS.md")
SUFFIXES = {".py", ".md", ".toml", ".txt", ".rst", ".FCMacro", ".xml", ".cfg"}
#: This file holds made-up citations to test the scanner with.
EXCLUDED = {Path(__file__).resolve()}

_NUM = r"\d{1,2}(?:\.\d{1,2})*(?![\d])(?!\.\d)"
# optional whitespace within a citation: spaces, at most one line break (docstring or comment wrap)
_WS = r"[ \t]*(?:\n[ \t]*(?:#[ \t]*)?)?"
_WS1 = r"(?:[ \t]+(?:\n[ \t]*(?:#[ \t]*)?)?|[ \t]*\n[ \t]*(?:#[ \t]*)?)"
_SEP = r"(?:,|;|and|or|&|/|–|—|-|to)"
_PREFIX = (
    rf"(?:\b(?:spec|maths)(?:\.md)?\b[,:]?{_WS}(?:\bsections?\b{_WS}|§{_WS})?"  # spec / maths [section(s)]
    rf"|\bsections?\b{_WS1}"  # bare "section 4"
    rf"|§{_WS})"
)
CITATION = re.compile(rf"(?P<prefix>{_PREFIX})(?P<list>{_NUM}(?:{_WS}{_SEP}{_WS}{_NUM})*)", re.IGNORECASE)
_LIST_ITEM = re.compile(rf"(?P<sep>{_SEP})?{_WS}(?P<num>{_NUM})", re.IGNORECASE)
HEADING = re.compile(r"^#{1,6}[ \t]+(\d+(?:\.\d+)*)\.?[ \t]", re.MULTILINE)


def _key(num: str) -> tuple[int, ...]:
    return tuple(int(p) for p in num.split("."))


def expand(number_list: str) -> list[str]:
    """Section numbers of a citation's list: "5 and 7" -> 5, 7; "5.2–5.4" -> 5.2, 5.3, 5.4."""
    out: list[str] = []
    for m in _LIST_ITEM.finditer(number_list):
        num, sep = m.group("num"), (m.group("sep") or "").lower()
        if sep in {"-", "–", "—", "to"} and out:
            lo, hi = _key(out[-1]), _key(num)
            if len(lo) == len(hi) and lo[:-1] == hi[:-1] and lo[-1] < hi[-1]:
                prefix = ".".join(str(p) for p in lo[:-1])
                out.extend(f"{prefix}.{k}" if prefix else str(k) for k in range(lo[-1] + 1, hi[-1]))
        out.append(num)
    return out


def find_citations(text: str) -> list[tuple[str, int, str]]:
    """``(section, line, matched text)`` for every cited section number in ``text``."""
    found = []
    for m in CITATION.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        for num in expand(m.group("list")):
            found.append((num, line, " ".join(m.group(0).split())))
    return found


def headings(text: str) -> set[str]:
    """The numbers of the numbered headings of a markdown text ("## 5.7 Title" -> "5.7")."""
    return set(HEADING.findall(text))


def scanned_files(root: Path = ROOT) -> list[Path]:
    files = []
    for name in SCANNED:
        p = root / name
        if p.is_file():
            files.append(p)
        elif p.is_dir():
            files.extend(f for f in sorted(p.rglob("*")) if f.is_file() and f.suffix in SUFFIXES
                         and ".venv" not in f.parts and "__pycache__" not in f.parts)
    return [f for f in files if f.resolve() not in EXCLUDED]


def unresolved(root: Path = ROOT, maths: Path = MATHS) -> tuple[list[str], int]:
    """(``"file:line: 'citation' -> X"`` for every citation without a heading, citations checked)."""
    known = headings(maths.read_text(encoding="utf-8"))
    bad, n = [], 0
    for f in scanned_files(root):
        for num, line, snippet in find_citations(f.read_text(encoding="utf-8", errors="replace")):
            n += 1
            if num not in known:
                bad.append(f"{f.relative_to(root)}:{line}: {snippet!r} -> section {num} has no heading in docs/maths.md")
    return bad, n


# -- the scanner on made-up text ---------------------------------------------------------------

@pytest.mark.parametrize(
    "text, expected",
    [
        ("as in spec section 5.7, the loft", ["5.7"]),
        ("(spec 6.1)", ["6.1"]),
        ("Spec 5.6: section 4 applied to", ["5.6", "4"]),
        ("spec sections 5 and 8", ["5", "8"]),
        ("spec sections 5, 7, 8", ["5", "7", "8"]),
        ("spec sections 8, 8.1", ["8", "8.1"]),
        ("spec 5.7, 8.1", ["5.7", "8.1"]),
        ("spec sections 1-3", ["1", "2", "3"]),
        ("spec sections 3–4", ["3", "4"]),
        ("spec 5.2–5.6", ["5.2", "5.3", "5.4", "5.5", "5.6"]),
        ("spec 1/3: c_1", ["1", "3"]),
        ("maths spec, section 1", ["1"]),
        ("see maths 2.1 and docs/maths.md section 6.3", ["2.1", "6.3"]),
        ("the fairness of spec\n    # section 7 (weighted)", ["7"]),
        ("spec 5.2, a dual curve", ["5.2"]),
        ("spec section 5, 100 rulings", ["5"]),
        ("spec 5.7.", ["5.7"]),
        ("§ 6.2", ["6.2"]),
        ("SheetSpec 2, a spec file, cross-section", []),
        ("the spec's contract", []),
    ],
)
def test_scanner_finds_and_expands(text: str, expected: list[str]) -> None:
    assert [num for num, _, _ in find_citations(text)] == expected


def test_scanner_rejects_a_citation_without_heading(tmp_path: Path) -> None:
    (tmp_path / "docs").mkdir()
    maths = tmp_path / "docs" / "maths.md"
    maths.write_text("# Maths\n\n## 1. Seeds\n\n$f_0$\n\n### 1.1 Jets\n\n## 5. Developables\n", encoding="utf-8")
    (tmp_path / "ght_cad").mkdir()
    (tmp_path / "ght_cad" / "good.py").write_text('"""Seeds (spec section 1), jets (maths 1.1), spec 5."""\n', encoding="utf-8")
    bad, n = unresolved(tmp_path, maths)
    assert (bad, n) == ([], 3)
    (tmp_path / "ght_cad" / "bad.py").write_text('"""The loft\n(spec sections 1 and\n    5.7)."""\n', encoding="utf-8")
    (tmp_path / "README.md").write_text("As in maths 2.\n", encoding="utf-8")
    bad, n = unresolved(tmp_path, maths)
    assert n == 6
    assert len(bad) == 2
    assert bad[0].startswith("ght_cad/bad.py:2: ") and "section 5.7" in bad[0]
    assert bad[1].startswith("README.md:1: ") and bad[1].endswith("section 2 has no heading in docs/maths.md")


def test_headings_are_parsed() -> None:
    text = "# Title\n## 5. Developable surfaces\n### 5.7 Loft\n#### 5.7.1 Deeper\nNot a ## 9 heading\n## 10. Last\n"
    assert headings(text) == {"5", "5.7", "5.7.1", "10"}


# -- the repository ------------------------------------------------------------------------------

def test_every_citation_resolves_to_a_heading_of_docs_maths() -> None:
    bad, n = unresolved()
    assert n >= 200, f"only {n} citations found: has the scanner stopped matching the code's forms?"
    assert not bad, f"{len(bad)} of {n} citations name no heading of docs/maths.md:\n" + "\n".join(bad)


#: Sections the code relies on, with a word their heading must contain.
REQUIRED = {
    "1": "seed", "1.1": "jet", "2": "basis", "2.1": "derivative", "3": "curve", "3.1": "tensor",
    "3.3": "b-spline", "4": "join", "5": "developable", "5.1": "dual", "5.2": "envelop",
    "5.3": "spine", "5.4": "geodesic", "5.5": "canal", "5.6": "join", "5.7": "loft", "5.8": "loft",
    "5.9": "gradient", "6": "flat", "6.1": "neutral", "6.2": "unfold", "6.3": "quadrature",
    "6.4": "face", "6.5": "check", "6.6": "plate", "7": "fairness", "8": "optimizer",
    "8.1": "gradient", "9": "names", "10": "approximat",
}


def test_docs_maths_has_the_sections_the_code_relies_on_each_with_a_formula() -> None:
    text = MATHS.read_text(encoding="utf-8")
    titles = {m.group(1): m.group(0) for m in re.finditer(r"^#{1,6}[ \t]+(\d+(?:\.\d+)*)\.?[ \t].*$", text, re.MULTILINE)}
    missing = [f"{k} ({word})" for k, word in REQUIRED.items() if k not in titles or word not in titles[k].lower()]
    assert not missing, f"docs/maths.md lacks headings: {missing}"
    # every numbered section states at least one formula ($...$) before the next heading
    parts = re.split(r"^#{1,6}[ \t]+(\d+(?:\.\d+)*)\.?[ \t].*$", text, flags=re.MULTILINE)
    without = [num for num, body in zip(parts[1::2], parts[2::2]) if "$" not in body]
    assert not without, f"sections without a formula: {without}"
    # numbering is unique
    nums = HEADING.findall(text)
    assert len(nums) == len(set(nums)), f"duplicate section numbers: {sorted(n for n in nums if nums.count(n) > 1)}"
