"""Hostile folders and files (issue 26): a planted link never redirects a write, ``--out`` on another
file system works and leaves nothing behind, a read-only ``--out`` is refused with exit 2, locks work
without ``fcntl``, hostile STEP files give exit 2 in seconds, degenerate geometry is refused at
construction.

The ``ght-cad`` runs here call :func:`ght_cad.app.cli.main` in this process (a curves-only design whose
outputs are ``report.json`` and ``report.md``: ~0.1 s a run).
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

from ght_cad.app.cli import EXIT_OK, EXIT_USAGE, main

TINY = """
[[curves]]
name = "a"
control_points = [[0, 0, 0], [1, 1, 0], [2, 0, 0]]
[outputs]
files = ["json", "md"]
figures = []
"""
#: every name a run of TINY writes into --out, and the hidden ones it writes beside and inside it
TINY_NAMES = ["report.json", "report.md", ".ght-cad-manifest.json"]


def _run(argv: list[str], capsys: pytest.CaptureFixture) -> tuple[int, str, str]:
    rc = main(argv)
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


@pytest.fixture()
def tiny(tmp_path: Path) -> Path:
    p = tmp_path / "tiny.toml"
    p.write_text(TINY)
    return p


def _victim(tmp_path: Path) -> tuple[Path, bytes]:
    v = tmp_path / "victim.txt"
    data = b"another user's file\x00\xff\n"
    v.write_bytes(data)
    return v, data


# ---------------------------------------------------------------------------------------------
# planted links
# ---------------------------------------------------------------------------------------------
def test_planted_lock_symlink_never_redirects_the_write(tiny: Path, tmp_path: Path, capsys) -> None:
    """``l/.out.ght-cad-lock`` -> victim: refused with exit 2 naming the lock file; victim byte-identical."""
    victim, data = _victim(tmp_path)
    (tmp_path / "l").mkdir()
    lock = tmp_path / "l" / ".out.ght-cad-lock"
    lock.symlink_to(victim)
    rc, out, err = _run(["run", str(tiny), "--out", str(tmp_path / "l" / "out"), "--no-progress"], capsys)
    assert rc == EXIT_USAGE and str(lock) in err and "symbolic link" in err, err
    assert len(err.strip().splitlines()) == 1, err
    assert victim.read_bytes() == data
    assert lock.is_symlink() and not (tmp_path / "l" / "out").exists()
    # a dangling link at that name is not created through either
    lock.unlink()
    lock.symlink_to(tmp_path / "would-be-created")
    rc, _, err = _run(["run", str(tiny), "--out", str(tmp_path / "l" / "out"), "--no-progress"], capsys)
    assert rc == EXIT_USAGE and not (tmp_path / "would-be-created").exists(), err


def test_planted_hard_link_at_the_lock_name_is_refused(tiny: Path, tmp_path: Path, capsys) -> None:
    victim, data = _victim(tmp_path)
    os.link(victim, tmp_path / ".out.ght-cad-lock")
    rc, _, err = _run(["run", str(tiny), "--out", str(tmp_path / "out"), "--no-progress"], capsys)
    assert rc == EXIT_USAGE and "hard links" in err, err
    assert victim.read_bytes() == data


def test_links_at_every_result_name_are_replaced_not_written_through(tiny: Path, tmp_path: Path, capsys) -> None:
    """An existing --out whose result names (report.json, report.md, the manifest) are links to a
    victim: the run succeeds, the links are replaced by the results, the victim is byte-identical."""
    victim, data = _victim(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    for n in TINY_NAMES:
        (out / n).symlink_to(victim)
    rc, _, err = _run(["run", str(tiny), "--out", str(out), "--no-progress"], capsys)
    assert rc == EXIT_OK, err
    assert victim.read_bytes() == data
    assert not (out / "report.json").is_symlink() and json.loads((out / "report.json").read_text())["name"] == "tiny"
    assert sorted(p.name for p in out.iterdir()) == ["report.json", "report.md"]


def test_single_file_output_lock_link_is_refused(tmp_path: Path, capsys) -> None:
    """``ght-cad curve --plot p.png`` with ``.p.png.ght-cad-lock`` planted as a link: exit 2, victim intact."""
    victim, data = _victim(tmp_path)
    (tmp_path / ".p.png.ght-cad-lock").symlink_to(victim)
    rc, _, err = _run(["curve", "--points", "0,0 1,1 2,0", "--plot", str(tmp_path / "p.png")], capsys)
    assert rc == EXIT_USAGE and "symbolic link" in err, err
    assert victim.read_bytes() == data and not (tmp_path / "p.png").exists()


# ---------------------------------------------------------------------------------------------
# other file systems, read-only folders, empty --out
# ---------------------------------------------------------------------------------------------
def _tmpfs_dir(tmp_path: Path) -> Path:
    """A fresh folder on another file system than ``tmp_path`` (/dev/shm), or skip."""
    shm = Path("/dev/shm")
    if not shm.is_dir() or os.stat(shm).st_dev == os.stat(tmp_path).st_dev:
        pytest.skip("no /dev/shm on another file system")
    d = shm / f"ght-cad-test-{os.getpid()}-{tmp_path.name}"
    d.mkdir()
    return d


def test_out_as_a_link_to_a_folder_on_another_file_system(tiny: Path, tmp_path: Path, capsys) -> None:
    """--out is a link to a folder on tmpfs: succeeds twice (new and existing files) with nothing left
    behind (was exit 1: EXDEV, leaving .ght-cad-manifest.json)."""
    import shutil

    far = _tmpfs_dir(tmp_path)
    try:
        link = tmp_path / "out"
        link.symlink_to(far, target_is_directory=True)
        for _ in range(2):
            rc, _, err = _run(["run", str(tiny), "--out", str(link), "--no-progress"], capsys)
            assert rc == EXIT_OK, err
            assert sorted(p.name for p in far.iterdir()) == ["report.json", "report.md"]
            assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "tiny.toml"]
    finally:
        shutil.rmtree(far, ignore_errors=True)


def _mount_tmpfs(where: Path, *options: str) -> None:
    where.mkdir()
    if os.geteuid() != 0:
        pytest.skip("mounting a tmpfs needs root")
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", ",".join(("size=4m", *options)), "tmpfs", str(where)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {r.stderr.strip()}")


def test_out_as_a_mount_point_and_read_only(tiny: Path, tmp_path: Path, capsys) -> None:
    """--out is a tmpfs mount point: succeeds, nothing left beside or inside; remounted read-only: exit 2
    naming the folder (was exit 1, EROFS), nothing written."""
    mnt = tmp_path / "mnt"
    _mount_tmpfs(mnt)
    try:
        rc, _, err = _run(["run", str(tiny), "--out", str(mnt), "--no-progress"], capsys)
        assert rc == EXIT_OK, err
        assert sorted(p.name for p in mnt.iterdir()) == ["report.json", "report.md"]
        assert sorted(p.name for p in tmp_path.iterdir()) == ["mnt", "tiny.toml"]
        subprocess.run(["mount", "-o", "remount,ro", str(mnt)], check=True)
        before = {p.name: p.read_bytes() for p in mnt.iterdir()}
        rc, _, err = _run(["run", str(tiny), "--out", str(mnt), "--no-progress"], capsys)
        assert rc == EXIT_USAGE and str(mnt) in err and "not writable" in err, err
        assert len(err.strip().splitlines()) == 1
        assert {p.name: p.read_bytes() for p in mnt.iterdir()} == before
        assert sorted(p.name for p in tmp_path.iterdir()) == ["mnt", "tiny.toml"]
    finally:
        subprocess.run(["umount", str(mnt)], capture_output=True)


def test_unwritable_out_folder_is_refused(tiny: Path, tmp_path: Path, capsys) -> None:
    """A folder of mode 0555 (for a user who is not root): exit 2 naming the folder."""
    if os.geteuid() == 0:
        pytest.skip("root writes into a 0555 folder (see the read-only mount test)")
    out = tmp_path / "out"
    out.mkdir()
    out.chmod(0o555)
    try:
        rc, _, err = _run(["run", str(tiny), "--out", str(out), "--no-progress"], capsys)
        assert rc == EXIT_USAGE and str(out) in err, err
    finally:
        out.chmod(0o755)


@pytest.mark.parametrize("argv", [["run", "{tiny}", "--out", ""], ["demo", "--out", " "],
                                  ["batch", "{tiny}", "--out", ""]])
def test_empty_out_is_refused(argv: list[str], tiny: Path, tmp_path: Path, capsys, monkeypatch) -> None:
    """``--out ""`` wrote into the current folder; now exit 2 and nothing written there."""
    monkeypatch.chdir(tmp_path)
    argv = [a.format(tiny=tiny) for a in argv]
    with pytest.raises(SystemExit) as e:  # argparse / or the command itself
        raise SystemExit(main(argv))
    err = capsys.readouterr().err
    assert e.value.code == EXIT_USAGE and "empty" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.toml"]


def test_empty_output_folder_refused_by_the_library(tmp_path: Path) -> None:
    from ght_cad.core.errors import GHTError
    from ght_cad.core.outdir import OutputFolder, StagedFiles

    with pytest.raises(GHTError, match="empty"):
        OutputFolder("")
    with pytest.raises(GHTError, match="empty"):
        StagedFiles([""])


# ---------------------------------------------------------------------------------------------
# locks without fcntl
# ---------------------------------------------------------------------------------------------
def test_without_fcntl_or_msvcrt_the_cli_says_so(tiny: Path, tmp_path: Path, capsys, monkeypatch) -> None:
    """A platform with neither lock call: exit 2 with one line saying so (not an ImportError, exit 1)."""
    import ght_cad.core.outdir as od

    monkeypatch.setattr(od, "fcntl", None)
    monkeypatch.setattr(od, "msvcrt", None)
    rc, _, err = _run(["run", str(tiny), "--out", str(tmp_path / "out"), "--no-progress"], capsys)
    assert rc == EXIT_USAGE and "neither fcntl nor msvcrt" in err and len(err.strip().splitlines()) == 1, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.toml"]


def test_outdir_imports_without_fcntl() -> None:
    """``import ght_cad.core.outdir`` where ``fcntl`` does not exist (Windows) works."""
    import sys

    code = "import sys; sys.modules['fcntl'] = None; import ght_cad.core.outdir as o; print(o.fcntl)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and r.stdout.strip() == "None", r.stderr


class _FakeMsvcrt:
    """``msvcrt.locking`` on top of ``fcntl.lockf`` of the same byte (to run the Windows branch here)."""

    LK_NBLCK = 2

    def __init__(self) -> None:
        import fcntl

        self._fcntl = fcntl
        self.calls = 0

    def locking(self, fd: int, mode: int, nbytes: int) -> None:
        assert mode == self.LK_NBLCK and nbytes == 1
        self.calls += 1
        self._fcntl.flock(fd, self._fcntl.LOCK_EX | self._fcntl.LOCK_NB)


def test_msvcrt_branch_locks(tiny: Path, tmp_path: Path, capsys, monkeypatch) -> None:
    """Without fcntl the msvcrt branch takes the locks (target and staging folder), and a second
    lock on the same target is refused as busy."""
    import ght_cad.core.outdir as od

    fake = _FakeMsvcrt()
    monkeypatch.setattr(od, "fcntl", None)
    monkeypatch.setattr(od, "msvcrt", fake)
    rc, _, err = _run(["run", str(tiny), "--out", str(tmp_path / "out"), "--no-progress"], capsys)
    assert rc == EXIT_OK and fake.calls >= 2, err
    with od.TargetLock(tmp_path / "x"):
        with pytest.raises(od.FolderBusy):
            od.TargetLock(tmp_path / "x").acquire()


# ---------------------------------------------------------------------------------------------
# hostile STEP files
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def cylinder_step(tmp_path_factory: pytest.TempPathFactory) -> bytes:
    """The bytes of a valid STEP file: a 120-degree cylinder face (R 30, H 50)."""
    bd = pytest.importorskip("build123d")
    from ght_cad.cad.occ import write_step

    solid = bd.Solid.make_cylinder(30.0, 50.0, angle=120.0)
    face = next(f for f in solid.faces() if f.geom_type == bd.GeomType.CYLINDER)
    p = tmp_path_factory.mktemp("step") / "cyl.step"
    write_step(face, p)
    return p.read_bytes()


def _points_scaled(text: str, fn) -> str:
    import re

    def sub(m: "re.Match[str]") -> str:
        return m.group(1) + ",".join(fn(float(x)) for x in m.group(2).split(",")) + ")"

    return re.sub(r"(CARTESIAN_POINT\('[^']*',\()([^)]*)\)", sub, text)


def test_step_with_an_overflowing_coordinate_exits_2_in_seconds(cylinder_step: bytes, tmp_path: Path, capsys) -> None:
    """``1.E400`` in a CARTESIAN_POINT: OCCT's TransferRoots never finished (> 150 s); now refused by the
    text scan before OCCT sees the file: exit 2, one line naming the file and the entity, < 30 s."""
    import re
    import time

    p = tmp_path / "e400.step"
    p.write_text(re.sub(r"(CARTESIAN_POINT\('[^']*',\()[^,]+", r"\g<1>1.E400", cylinder_step.decode(), count=1))
    t0 = time.perf_counter()
    rc, _, err = _run(["unroll", str(p)], capsys)
    assert time.perf_counter() - t0 < 30.0
    assert rc == EXIT_USAGE and str(p) in err and "CARTESIAN_POINT" in err and "1.E400" in err, err
    assert len(err.strip().splitlines()) == 1


def test_step_scaled_by_1e290_exits_2_without_warnings(cylinder_step: bytes, tmp_path: Path, capsys) -> None:
    """Every coordinate x 1e290: was NaN developability with two numpy overflow warnings."""
    import warnings

    p = tmp_path / "x1e290.step"
    p.write_text(_points_scaled(cylinder_step.decode(), lambda x: f"{x * 1e290:.17E}"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rc, _, err = _run(["unroll", str(p)], capsys)
    assert rc == EXIT_USAGE and "beyond" in err and "Warning" not in err, err
    assert len(err.strip().splitlines()) == 1


def test_step_scan_keeps_legal_numbers(cylinder_step: bytes, tmp_path: Path, capsys) -> None:
    """The valid file, its coordinates x 1e9 (within 1e12) and a name holding 'E99' still unroll."""
    p = tmp_path / "big.step"
    p.write_text(_points_scaled(cylinder_step.decode(), lambda x: f"{x * 1e9:.17E}").replace("''", "'PIPE12E99'", 1))
    rc, _, err = _run(["unroll", str(p)], capsys)
    assert rc == EXIT_OK, err


def test_step_scan_names_the_entity() -> None:
    from ght_cad.core.errors import GHTError
    from ght_cad.core.step_guard import check_step_numbers

    for text, token in [(b"#7=CARTESIAN_POINT('',(3E+291,0.,0.));", "#7 CARTESIAN_POINT"),
                        (b"#1=A(1.);\n#8=B_SPLINE_CURVE_WITH_KNOTS('',(-1.E+20));", "#8 B_SPLINE_CURVE_WITH_KNOTS"),
                        (b"#2=P((0.,12345678901234.5));", "#2 P")]:
        with pytest.raises(GHTError, match=token):
            check_step_numbers("f.step", text)
    for ok in (b"#1=P((1.5E+05,1.E-400,123456789012.));", b"#1=X('a1E99',(1.,2.));", b"#3=P((1.E12,-1.E+012));"):
        check_step_numbers("f.step", ok)


def test_a_directory_named_like_a_step_file(tmp_path: Path, capsys) -> None:
    (tmp_path / "x.step").mkdir()
    rc, _, err = _run(["unroll", str(tmp_path / "x.step")], capsys)
    assert rc == EXIT_USAGE and "is a directory" in err and "no such" not in err, err


# ---------------------------------------------------------------------------------------------
# degenerate geometry: refused at construction, never NaN
# ---------------------------------------------------------------------------------------------
def test_pencil_of_control_planes_is_degenerate() -> None:
    """Three planes through the z axis: every ruling would be that axis (was accepted, DD NaN)."""
    import numpy as np

    from ght_cad import developable_from_planes
    from ght_cad.core.errors import DegenerateGeometryError

    planes = [[0.0, np.sin(a), -np.cos(a), 0.0] for a in (0.1, 0.7, 1.3)]
    with pytest.raises(DegenerateGeometryError, match="pencil"):
        developable_from_planes(planes, [[0, 0, 0, 1], [-1, 0, 0, 1]])
    from ght_cad.surfaces.planes import check_control_planes

    moved = [list(p) for p in planes]
    moved[1][3] = 0.5  # the middle plane tilted out of the pencil: accepted by the pencil test
    check_control_planes(moved)


def test_curvature_where_the_tangent_vanishes_raises() -> None:
    import numpy as np

    from ght_cad import GHTCurve
    from ght_cad.core.errors import DegenerateGeometryError

    c = GHTCurve([[0, 0], [0, 0], [1, 1]])
    with pytest.raises(DegenerateGeometryError, match=r"t=0\b"):
        c.curvature([0.0, 0.5])
    assert np.isfinite(c.curvature([0.25, 0.5, 1.0])).all()
    with pytest.raises(DegenerateGeometryError):
        GHTCurve([[1, 1], [1, 1], [1, 1]]).curvature(0.5)


def test_control_points_near_1e300_are_refused_without_warnings() -> None:
    import warnings

    from ght_cad import GHTCurve
    from ght_cad.core.errors import GHTError

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(GHTError, match=r"beyond ±1e\+50"):
            GHTCurve([[0, 0], [1e300, 1], [2e300, 0]])


def test_zero_width_ruled_surface_is_degenerate_not_nan() -> None:
    from ght_cad import GHTCurve, unroll
    from ght_cad.core.errors import DegenerateGeometryError
    from ght_cad.surfaces.ruled import CurvePairRuledSurface, FunctionRuledSurface

    c = GHTCurve([[0, 0, 0], [1, 1, 0], [2, 0, 1]])
    with pytest.raises(DegenerateGeometryError, match="same curve"):
        CurvePairRuledSurface(c, c)
    s = FunctionRuledSurface(lambda u, d: c.derivative(u, d), lambda u, d: c.derivative(u, d))
    for call in (s.developability, lambda: unroll(s)):
        with pytest.raises(DegenerateGeometryError, match="zero width|zero-width"):
            call()


def test_join_with_huge_k_is_refused_naming_k() -> None:
    import warnings

    from ght_cad import GHTCurve
    from ght_cad.curves.continuity import join
    from ght_cad.core.errors import SingularJoinError

    a = GHTCurve([[0, 0, 0], [1, 1, 0], [2, 0, 0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for cont in ("G1", "G3"):
            with pytest.raises(SingularJoinError, match=r"k=1e\+300"):
                join(a, cont, [[2, 0, 0], [3, -1, 0], [4, 0, 0], [5, 1, 0]], k=1e300)


@pytest.mark.parametrize("body, key", [
    ("[[curves]]\nname='a'\ncontrol_points=[[0,0,0],[1e13,1,0],[2,0,0]]\n", "curves[0].control_points[1][0]"),
    ("[[curves]]\nname='a'\ncontrol_points=[" + ",".join(f"[{i},0,0]" for i in range(1001)) + "]\n",
     "curves[0].control_points"),
    ("[[curves]]\nname='a'\ncontrol_points=[[0,0,0],[1,1,0],[2,0,1]]\n[[curves]]\nname='b'\n"
     "control_points=[[0,0,5],[1,1,5],[2,0,6]]\n[surface]\ntype='curves'\ncurve_a='a'\ncurve_b='b'\n"
     "[unroll]\nsamples=20001\nrulings=1000\n", "unroll.samples"),
])
def test_design_limits_refused_before_allocating(body: str, key: str, tmp_path: Path, capsys) -> None:
    p = tmp_path / "d.toml"
    p.write_text(body)
    rc, _, err = _run(["run", str(p), "--out", str(tmp_path / "out"), "--no-progress"], capsys)
    assert rc == EXIT_USAGE and f"key '{key}'" in err and str(p) in err, err


def test_step_reader_crash_and_hang_in_its_worker_give_exit_2(cylinder_step: bytes, tmp_path: Path, capsys,
                                                              monkeypatch) -> None:
    """OCCT's reader runs in a forked worker: one that crashes (a mutated file made OCCT segfault) or
    runs past the limit (killed) gives exit 2 with one line, and this process lives on."""
    import signal
    import time

    import ght_cad.app.design.step_input as si

    if not hasattr(os, "fork"):
        pytest.skip("no fork: the reader runs in this process")
    p = tmp_path / "part.step"
    p.write_bytes(cylinder_step)
    monkeypatch.setattr(si, "_transfer_step", lambda path, units: os.kill(os.getpid(), signal.SIGSEGV))
    rc, _, err = _run(["unroll", str(p)], capsys)
    assert rc == EXIT_USAGE and "crashed" in err and "SIGSEGV" in err and str(p) in err, err
    monkeypatch.setattr(si, "_transfer_step", lambda path, units: time.sleep(60))
    monkeypatch.setenv("GHT_CAD_STEP_TIMEOUT", "1")
    t0 = time.perf_counter()
    rc, _, err = _run(["unroll", str(p)], capsys)
    assert rc == EXIT_USAGE and "did not finish within 1 s" in err, err
    assert time.perf_counter() - t0 < 20.0
    assert len(err.strip().splitlines()) == 1
