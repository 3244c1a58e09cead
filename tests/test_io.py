"""Atomic writes: a failed write leaves no partial file, keeps the old one, and names the target."""

from __future__ import annotations

import os

import pytest

from ght_cad.core.io import atomic_path, atomic_write, write_text_atomic


def test_success_replaces_and_leaves_no_temporary(tmp_path) -> None:
    target = tmp_path / "a.txt"
    target.write_text("old")
    write_text_atomic(target, "new")
    assert target.read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_failure_keeps_the_old_file_and_cleans_up(tmp_path) -> None:
    target = tmp_path / "a.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError, match="boom"):
        with atomic_write(target) as fh:
            fh.write("partial")
            raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_empty_output_is_an_error(tmp_path) -> None:
    target = tmp_path / "b.step"
    with pytest.raises(OSError, match=rf"cannot write {target}: the writer produced no data"):
        with atomic_path(target):
            pass
    assert not target.exists()


@pytest.mark.skipif(os.geteuid() != 0 and not os.path.isdir("/proc"), reason="needs /proc")
def test_unwritable_folder_names_the_target_not_the_temporary() -> None:
    target = "/proc/ght_cad_test/f.step"
    with pytest.raises(OSError) as exc:
        write_text_atomic(target, "x")
    msg = str(exc.value)
    assert f"cannot write {target}" in msg and ".part" not in msg


@pytest.mark.parametrize("depth", [1, 2])
def test_target_under_a_regular_file_names_that_file(tmp_path, depth: int) -> None:
    """``blocker/x.png`` (or ``blocker/sub/x.png``) where ``blocker`` is a file: NotADirectoryError
    naming the target and the file in the way (was FileExistsError/NotADirectoryError "File exists"
    without saying which path is the file); nothing is created, the file is untouched."""
    blocker = tmp_path / "blocker"
    blocker.write_text("keep\n")
    target = blocker / "sub" / "x.png" if depth == 2 else blocker / "x.png"
    with pytest.raises(NotADirectoryError) as exc:
        write_text_atomic(target, "x")
    msg = str(exc.value)
    assert f"cannot write {target}" in msg and f"{blocker} is a file, not a folder" in msg, msg
    assert blocker.read_text() == "keep\n" and sorted(p.name for p in tmp_path.iterdir()) == ["blocker"]
