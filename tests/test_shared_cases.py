"""The design files in ``../shared/cases/design-files/`` (inputs that broke ``ght-cad run``, issue 26):
each gives exit 0 with valid output, or exit 2 with ONE line on stderr naming the file and the key and
no warning before it. Skipped only when that folder is absent (a checkout without the shared cases).

Each file is run through :func:`ght_cad.app.cli.main` in this process (stdout/stderr captured; Python
warnings recorded as errors would be, so a numpy RuntimeWarning before the line fails the test).
"""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

import pytest

from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main

CASES = Path(__file__).resolve().parents[1] / ".." / "shared" / "cases" / "design-files"
FILES = sorted(CASES.glob("*.toml")) if CASES.is_dir() else []

#: what each known file must give (a file added later is held to "0 or 2")
EXPECTED = {
    "sheet_with_straight_rail.toml": EXIT_OK,  # legal plated design with a straight rail
    "curves_identical_rails_optimize.toml": EXIT_OK,  # the optimizer moves the rails apart
    "rails_loft_to_straight_rail.toml": EXIT_OK,  # legal loft to a straight rail
    "join_k_1e300.toml": EXIT_USAGE,  # k = 1e300 overflows the joined curve
    "curves_identical_rails.toml": EXIT_USAGE,  # a zero-width strip
}


@pytest.mark.slow
@pytest.mark.skipif(not FILES, reason="../shared/cases/design-files is absent")
@pytest.mark.parametrize("case", FILES, ids=lambda p: p.name)
def test_shared_design_case(case: Path, tmp_path: Path, capsys) -> None:
    out = tmp_path / "out"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rc = main(["run", str(case), "--out", str(out), "--no-progress"])
    cap = capsys.readouterr()
    assert not [w for w in caught if issubclass(w.category, (RuntimeWarning, UserWarning))], \
        [str(w.message) for w in caught]
    assert rc in (EXIT_OK, EXIT_USAGE), cap.err
    if case.name in EXPECTED:
        assert rc == EXPECTED[case.name], cap.err
    if rc == EXIT_USAGE:
        lines = cap.err.strip().splitlines()
        assert len(lines) == 1, cap.err
        assert str(case) in lines[0] and re.search(r"key '[^']+'", lines[0]), lines[0]
        assert "internal failure" not in lines[0] and "nan" not in lines[0].lower()
        assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == []
    else:
        report = json.loads((out / "report.json").read_text())
        assert sorted(report["files"]) == sorted(p.name for p in out.iterdir())
        assert "Warning" not in cap.err
        text = (out / "report.md").read_text()
        assert "None" not in text and not re.search(r"\bnan\b", text, re.IGNORECASE)
        dev = report.get("developability")
        if dev:
            assert all(v is not None for v in dev.values()), dev
