r"""``ght-cad batch``: many designs (and sweep variants) in parallel processes or on a Dask cluster.

Every design goes through exactly the pipeline of ``ght-cad run``
(:func:`ght_cad.app.design.run_design`). A worker (a local process from
:class:`concurrent.futures.ProcessPoolExecutor`, or a ``dask.distributed`` worker on any machine)
runs it into a private temporary folder and sends back the report and the bytes of every file;
the calling process then writes them into ``DIR/<name>/`` through run's own staging
(:class:`ght_cad.core.outdir.OutputFolder`: a locked target, a temporary folder beside it, moved in
only when complete), so local and remote runs write the same files in the same way and a worker that dies
leaves nothing in ``DIR``. ``report.json`` and ``report.md`` are rewritten with ``out_dir`` naming
the local folder. ``DIR/batch.json`` and ``DIR/batch.md`` (plus one ``sweep-<name>.png`` per
sweep, :mod:`ght_cad.app.sweep`) hold one row per design:

* ``status``: ``ok``, ``bad input`` (an invalid design file or geometry the pipeline refuses: a
  :class:`~ght_cad.core.errors.GHTError`) or ``failed`` (an internal failure, or the worker died);
* ``error``: the one-line message for the last two;
* key figures: ``area`` (flat pattern area), ``theta_max`` (degrees, spec section 5),
  ``pattern_error`` (largest relative error of the flat pattern), ``optimization``
  (method, objective, best value and parameters) and ``best_value``;
* ``elapsed_s`` (wall time of the design in its worker), ``cpu_s`` (CPU time of the worker's
  process on it: well below ``elapsed_s`` means the worker waited for a core), ``host``, ``pid``, ``worker`` (``local`` or the Dask worker's address) and
  ``attempts``.

A local worker process that dies (killed, or a crash in the CAD kernel) breaks the process pool:
every design not finished is run again in a fresh pool (forked from this process with the run's
modules loaded, :func:`preload_run_modules`), and a design whose own process died under it for
the :data:`MAX_ATTEMPTS`-th time is reported ``failed``. The designs that were running in the
other workers (which the pool terminates) are run again without counting against them. On Dask the scheduler
reruns a task whose worker died (its ``allowed-failures``, default 3) before reporting
``KilledWorker``, which becomes ``failed``.

Exit code of :func:`run_batch`'s result: 0 all ok, 2 any bad input (none failed), 1 any failed.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import signal
import socket
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

from ..core.errors import GHTError
from ..core.workers import _dask_client, _limit_threads, _one_line, _worker_threads

__all__ = ["BatchJob", "BatchResult", "collect_jobs", "run_batch", "run_task", "MAX_ATTEMPTS", "batch_markdown",
           "map_step_faces", "preload_run_modules"]

#: How often a design may be running in a local worker process that dies before it is reported failed.
MAX_ATTEMPTS = 2

OK, BAD, FAILED = "ok", "bad input", "failed"


@dataclass
class BatchJob:
    """One design of a batch: its folder name, source file and parsed TOML data (or an input error)."""

    index: int
    name: str
    folder: str
    source: str
    data: dict[str, Any] | None = None
    error: str | None = None
    sweep: dict[str, Any] | None = None  # {"base": name, "values": {path: value}}
    #: ``--chord-tol`` for this design's DXF/SVG (None: its ``[outputs] chord_tol``, else 1e-3 mm)
    chord_tol: float | None = None

    def task(self, **extra: Any) -> dict[str, Any]:
        """The picklable task :func:`run_task` runs for this design (``extra``: e.g. ``marker``)."""
        return {"folder": self.folder, "source": self.source, "data": self.data, "chord_tol": self.chord_tol, **extra}


@dataclass
class BatchResult:
    """Outcome of :func:`run_batch`: one row per design, sweeps, exit code and summary."""

    out_dir: Path
    rows: list[dict[str, Any]]
    sweeps: list[Any] = field(default_factory=list)
    executor: str = ""
    elapsed_s: float = 0.0
    files: list[str] = field(default_factory=list)

    @property
    def exit_code(self) -> int:
        """0 all ok, 1 any failed, else 2 if any bad input."""
        st = {r["status"] for r in self.rows}
        return 1 if FAILED in st else 2 if BAD in st else 0

    def as_dict(self) -> dict[str, Any]:
        """The content of ``batch.json``."""
        count = {s: sum(r["status"] == s for r in self.rows) for s in (OK, BAD, FAILED)}
        return {
            "out_dir": str(self.out_dir),
            "executor": self.executor,
            "designs": len(self.rows),
            "succeeded": count[OK],
            "bad_input": count[BAD],
            "failed": count[FAILED],
            "exit_code": self.exit_code,
            "elapsed_s": self.elapsed_s,
            "rows": self.rows,
            "sweeps": [{"base": s.base, "source": s.source, "keys": s.keys, "mode": s.mode, "plot": s.plot,
                        "variants": [v.name for v in s.variants], "png": f"sweep-{_folder_name(s.base)}.png"}
                       for s in self.sweeps],
            "files": self.files,
        }


def _folder_name(name: str) -> str:
    """A folder name for a design name: characters other than letters, digits, ``._-`` become ``_``."""
    s = re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._")
    return s or "design"


def collect_jobs(paths: Sequence[str | os.PathLike]) -> tuple[list[BatchJob], list[Any]]:
    """Read and validate every design file; expand ``[sweep]`` tables (:func:`ght_cad.app.sweep.expand_sweep`).

    A file that cannot be read, is not TOML, has a bad ``[sweep]`` or fails validation
    (:func:`ght_cad.app.design.parse_design`) becomes a job with ``error`` set (reported ``bad
    input``); the others go on. Two designs with the same folder name: the later is refused.

    Returns:
        (jobs in input order, the expanded sweeps).
    """
    import tomllib

    from .design import parse_design
    from .sweep import expand_sweep

    jobs: list[BatchJob] = []
    sweeps: list[Any] = []
    used: dict[str, str] = {}

    def add(name: str, source: str, data: dict | None, error: str | None, sweep: dict | None = None) -> None:
        folder = _folder_name(name)
        if error is None and folder in used:
            error = (f"{source}: design name {name!r} gives the folder {folder!r}, already used by {used[folder]}; "
                     "allowed: distinct design names in one batch")
        if error is None:
            try:
                parse_design(data, source)
            except GHTError as exc:
                error = _one_line(exc)
        if error is None:
            used[folder] = source
        jobs.append(BatchJob(len(jobs), name, folder, source, data if error is None else None, error, sweep))

    for p in paths:
        src = str(p)
        stem = Path(src).stem or "design"
        try:
            text = Path(src).read_text(encoding="utf-8")
            data = tomllib.loads(text)
        except FileNotFoundError:
            add(stem, src, None, f"{src}: no such design file")
            continue
        except (OSError, UnicodeDecodeError) as exc:
            add(stem, src, None, f"{src}: cannot read the design file: {_one_line(exc)}")
            continue
        except tomllib.TOMLDecodeError as exc:
            add(stem, src, None, f"{src}: not valid TOML: {_one_line(exc)}")
            continue
        name = data.get("name") if isinstance(data.get("name"), str) else stem
        try:
            sweep = expand_sweep(data, src)
        except GHTError as exc:
            add(name, src, None, _one_line(exc))
            continue
        if sweep is None:
            add(name, src, data, None)
            continue
        sweeps.append(sweep)
        for v in sweep.variants:
            add(v.name, src, v.data, None, {"base": sweep.base, "values": v.values})
    return jobs, sweeps


def _where() -> dict[str, Any]:
    """Host, process id and worker (the Dask worker's address inside a Dask task, else ``local``)."""
    worker = "local"
    if "distributed" in sys.modules:
        try:
            from distributed import get_worker

            worker = get_worker().address
        except (ValueError, ImportError):  # not inside a Dask task
            pass
    return {"host": socket.gethostname(), "pid": os.getpid(), "worker": worker}


def run_task(task: dict[str, Any]) -> dict[str, Any]:
    """Run one design through :func:`ght_cad.app.design.run_design` into a private temporary folder.

    Runs in a worker (local process or Dask worker). ``task`` holds ``folder``, ``source``,
    ``data`` (the parsed TOML) and ``chord_tol`` (over the file's; None: the file's), optionally ``marker`` (a file written with the pid on start, so the
    caller knows which designs were running in a process that died; the temporary folder is then
    made beside it, in the caller's private folder, which the caller removes at the end).

    Returns:
        ``{"status", "error", "report", "files": {name: bytes}, "elapsed_s", "cpu_s", "host", "pid", "worker"}``.
    """
    t0, c0 = time.perf_counter(), time.process_time()
    if task.get("marker"):
        Path(task["marker"]).write_text(str(os.getpid()))
    out: dict[str, Any] = {"status": OK, "error": None, "report": None, "files": {}, **_where()}
    try:
        from .design import parse_design, run_design

        design = parse_design(task["data"], task["source"])
        # beside the marker: in the caller's private folder, removed with it even if this process is killed
        where = str(Path(task["marker"]).parent) if task.get("marker") else None
        with tempfile.TemporaryDirectory(prefix="ght-cad-batch.", dir=where) as tmp:
            folder = Path(tmp) / task["folder"]
            out["report"] = run_design(design, folder, progress=False, chord_tol=task.get("chord_tol"))
            out["files"] = {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()}
    except GHTError as exc:
        out.update(status=BAD, error=_one_line(exc))
    except Exception as exc:  # noqa: BLE001 - an internal failure of one design; the batch goes on
        out.update(status=FAILED, error=f"internal failure: {type(exc).__name__}: {_one_line(exc)}")
    out["elapsed_s"] = time.perf_counter() - t0
    out["cpu_s"] = time.process_time() - c0
    return out


def _commit(target: Path, result: dict[str, Any]) -> None:
    """Write a worker's files into ``target`` through run's staging (all files or none)."""
    import json

    from .design import FILE_NAMES, report_markdown
    from ..core.outdir import OutputFolder

    report = dict(result["report"] or {})
    report["out_dir"] = str(target)
    with OutputFolder(target) as stage:  # run's folder handling: lock, staging, manifest
        for name, data in result["files"].items():
            if name == FILE_NAMES["json"]:
                data = (json.dumps(report, indent=2) + "\n").encode("utf-8")
            elif name == FILE_NAMES["md"]:
                data = report_markdown(report).encode("utf-8")
            stage.path(name).write_bytes(data)
        stage.commit()


def _figures(report: dict[str, Any] | None) -> dict[str, Any]:
    """Key figures of a run report: area, θ_max, pattern error, optimization, best value."""
    r = report or {}
    pat = r.get("flat_pattern") or {}
    errors = pat.get("errors") or {}
    # the largest RELATIVE error: the pattern's own "max" (``angle_deg`` is an angle in degrees,
    # the metric check's difference-stencil residual, not a relative error)
    errs = [v for k, v in errors.items() if k == "max" and isinstance(v, (int, float))] or \
        [v for k, v in errors.items() if k != "angle_deg" and isinstance(v, (int, float))]
    opt = r.get("optimization")
    return {
        "area": pat.get("area"),
        "theta_max": (r.get("developability") or {}).get("theta_max"),
        "pattern_error": max(errs) if errs else None,
        "optimization": None if not opt else {k: opt.get(k) for k in ("method", "objective", "best_value",
                                                                       "best_parameters", "iterations")},
        "best_value": None if not opt else opt.get("best_value"),
    }


def _row(job: BatchJob, status: str, error: str | None, result: dict[str, Any] | None, attempts: int) -> dict[str, Any]:
    res = result or {}
    return {
        "name": job.name,
        "folder": job.folder if status == OK else None,
        "source": job.source,
        "status": status,
        "error": error,
        **_figures(res.get("report") if status == OK else None),
        "files": sorted(res.get("files") or {}) if status == OK else [],
        "elapsed_s": res.get("elapsed_s"),
        "cpu_s": res.get("cpu_s"),
        "host": res.get("host"),
        "pid": res.get("pid"),
        "worker": res.get("worker"),
        "attempts": attempts,
        "sweep": job.sweep,
    }


#: Modules a design run imports on first use (OCP through build123d, matplotlib, scipy.optimize:
#: several seconds, against well under a second per design once loaded).
_RUN_MODULES = ("ght_cad.app.design", "ght_cad.app.design.run", "ght_cad.app.design.outputs", "ght_cad.cad.occ",
                "ght_cad.cad.developable_faces", "ght_cad.curves.plotting", "ght_cad.developables.envelope",
                "ght_cad.unrolling.unroll", "scipy.optimize", "matplotlib.figure", "matplotlib.backends.backend_agg", "build123d")


def preload_run_modules() -> float:
    """Import what a design run needs (:data:`_RUN_MODULES`) into this process; returns the seconds taken.

    Called before local worker processes are forked, so they start with everything loaded (and
    share those pages) instead of each importing it on its first design; a fresh pool after a
    worker died starts warm too. A module that is not installed is skipped (the design that
    needs it reports the error).
    """
    import importlib

    t0 = time.perf_counter()
    for name in _RUN_MODULES:
        try:
            importlib.import_module(name)
        except ImportError:
            pass
    return time.perf_counter() - t0


def _local(jobs: list[BatchJob], n: int, finish: Callable[[BatchJob, dict[str, Any] | None, int, str | None], None]) -> None:
    """Run ``jobs`` in ``n`` local processes; ``finish(job, result, attempts, death)`` per design."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from concurrent.futures.process import BrokenProcessPool

    fork = sys.platform.startswith("linux")
    ctx = multiprocessing.get_context("fork" if fork else None)
    if fork:
        preload_run_modules()
    markers = Path(tempfile.mkdtemp(prefix="ght-cad-batch-markers."))
    pending = {j.index: j for j in jobs}
    attempts = {j.index: 0 for j in jobs}  # times started
    deaths = {j.index: 0 for j in jobs}  # times its own process died under it
    try:
        while pending:
            broken = False
            procs: dict[int, Any] = {}
            workers = max(1, min(n, len(pending)))
            with ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=_limit_threads,
                                     initargs=(_worker_threads(workers),)) as ex:
                futs = {}
                for j in pending.values():
                    futs[ex.submit(run_task, j.task(marker=str(markers / str(j.index))))] = j
                procs = dict(getattr(ex, "_processes", None) or {})  # pid -> Process (all started at once with fork)
                for fut in as_completed(futs):
                    j = futs[fut]
                    try:
                        res = fut.result()
                    except BrokenProcessPool:
                        broken = True
                        continue
                    attempts[j.index] += 1
                    (markers / str(j.index)).unlink(missing_ok=True)
                    del pending[j.index]
                    finish(j, res, attempts[j.index], None)
            if not broken:
                break
            started = {i: _marker_pid(markers / str(i)) for i in pending if (markers / str(i)).exists()}
            if not started:  # the pool died before running anything: no retry would help
                for i in list(pending):
                    finish(pending.pop(i), None, attempts[i], "internal failure: the worker processes could not start")
                break
            # the pool terminates (SIGTERM) its other workers when one dies: the designs running in
            # those are run again without counting; a design whose own process died counts a death
            # (if no process can be told apart, every started design counts one)
            culprits = {pid for pid, pr in procs.items() if pr.exitcode is not None and pr.exitcode != -signal.SIGTERM}
            if not culprits & set(started.values()):
                culprits = set(started.values())
            for i, pid in started.items():
                (markers / str(i)).unlink()
                attempts[i] += 1
                if pid in culprits:
                    deaths[i] += 1
                if deaths[i] >= MAX_ATTEMPTS:
                    finish(pending.pop(i), None, attempts[i],
                           f"internal failure: the worker process running it died {deaths[i]} times "
                           "(killed, out of memory or a crash in the CAD kernel)")
    finally:
        shutil.rmtree(markers, ignore_errors=True)


def _marker_pid(path: Path) -> int | None:
    """The worker pid a started design's marker file holds (None if unreadable)."""
    try:
        return int(path.read_text().strip())
    except (OSError, ValueError):
        return None


def _dask(jobs: list[BatchJob], scheduler: str,
          finish: Callable[[BatchJob, dict[str, Any] | None, int, str | None], None]) -> None:
    """Run ``jobs`` on the ``dask.distributed`` cluster at ``scheduler``."""
    from distributed import as_completed

    client = _dask_client(scheduler)
    try:
        futs = {}
        for j in jobs:
            futs[client.submit(run_task, j.task(), key=f"ght-cad-batch-{j.folder}-{os.getpid()}-{time.time_ns()}",
                               pure=False)] = j
        for fut in as_completed(list(futs)):
            j = futs[fut]
            try:
                res = fut.result()
            except Exception as exc:  # noqa: BLE001 - KilledWorker and friends: that design failed
                finish(j, None, 1, f"internal failure: the Dask task failed: {type(exc).__name__}: {_one_line(exc)}")
                continue
            finish(j, res, 1, None)
    finally:
        client.close()


def run_batch(
    paths: Sequence[str | os.PathLike],
    out_dir: str | os.PathLike,
    *,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = True,
    chord_tol: float | None = None,
) -> BatchResult:
    """Run every design (and every sweep variant) and write ``DIR/<name>/``, ``batch.json``, ``batch.md``.

    Args:
        paths: design files; a ``[sweep]`` table expands into variants (:mod:`ght_cad.app.sweep`).
        out_dir: the batch folder ``DIR``.
        jobs: local worker processes (default: the machine's cores); ignored with ``scheduler``.
        scheduler: address of a ``dask.distributed`` scheduler (``tcp://host:port``).
        progress: progress bar over designs on stderr when it is a terminal.
        chord_tol: DXF/SVG outline chord tolerance for every design, in each design's units; it
            takes precedence over a file's ``[outputs] chord_tol`` (None: that key, else 1e-3 mm).

    Returns:
        :class:`BatchResult` (``exit_code``: 0 all ok, 2 bad input, 1 failed).

    Raises:
        GHTError: no designs, ``jobs < 1``, ``chord_tol`` not > 0, ``out_dir`` is not a folder, an
            unreachable scheduler.
    """
    from ..core.outdir import StagedFiles
    from ..core.progress import Progress

    t0 = time.perf_counter()
    if not paths:
        raise GHTError("batch needs at least one design file")
    if jobs is None:
        jobs = os.cpu_count() or 1
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise GHTError(f"jobs={jobs!r}; allowed: an integer >= 1")
    if chord_tol is not None and not (isinstance(chord_tol, (int, float)) and chord_tol > 0 and math.isfinite(chord_tol)):
        raise GHTError(f"chord_tol={chord_tol!r} is not allowed; allowed: a positive length in the designs' units")
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise GHTError(f"{out} exists and is not a folder; allowed: a folder or a new path")
    job_list, sweeps = collect_jobs(paths)
    for j in job_list:
        j.chord_tol = chord_tol
    rows: dict[int, dict[str, Any]] = {}
    for j in job_list:
        if j.error is not None:
            rows[j.index] = _row(j, BAD, j.error, None, 0)
    todo = [j for j in job_list if j.error is None]
    out.mkdir(parents=True, exist_ok=True)
    bar = Progress(len(job_list), "batch", enabled=None if progress else False)
    bar.set(len(rows))

    def finish(job: BatchJob, result: dict[str, Any] | None, attempts: int, death: str | None) -> None:
        if death is not None or result is None:
            rows[job.index] = _row(job, FAILED, death or "internal failure: no result", None, attempts)
        elif result["status"] != OK:
            rows[job.index] = _row(job, result["status"], result["error"], result, attempts)
        else:
            try:
                _commit(out / job.folder, result)
                rows[job.index] = _row(job, OK, None, result, attempts)
            except GHTError as exc:
                rows[job.index] = _row(job, BAD, _one_line(exc), None, attempts)
            except OSError as exc:
                rows[job.index] = _row(job, FAILED, f"cannot write {out / job.folder}: {_one_line(exc)}", None, attempts)
        bar.update()

    with bar:
        if todo and scheduler:
            _dask(todo, scheduler, finish)
        elif todo:
            _local(todo, jobs, finish)
    executor = f"dask {scheduler}" if scheduler else f"local processes ({min(jobs, max(len(todo), 1))} jobs)"
    result = BatchResult(out, [rows[j.index] for j in job_list], sweeps, executor)
    result.elapsed_s = time.perf_counter() - t0
    _write_summary(result, StagedFiles)
    return result


def _write_summary(result: BatchResult, stage_cls: Any) -> None:
    """``batch.json``, ``batch.md`` and one ``sweep-<name>.png`` per sweep, all or nothing."""
    from .sweep import plot_sweep

    out = result.out_dir
    pngs = {s.base: out / f"sweep-{_folder_name(s.base)}.png" for s in result.sweeps}
    result.files = ["batch.json", "batch.md", *[p.name for p in pngs.values()]]
    targets = [out / "batch.json", out / "batch.md", *pngs.values()]
    stage = stage_cls(targets)
    try:
        for s in result.sweeps:
            plot_sweep(s, [r for r in result.rows if (r.get("sweep") or {}).get("base") == s.base],
                       stage.path(pngs[s.base]))
        from .commands.common import dumps

        stage.path(out / "batch.json").write_text(dumps(result.as_dict()) + "\n", encoding="utf-8")
        stage.path(out / "batch.md").write_text(batch_markdown(result), encoding="utf-8")
        stage.commit()
    finally:
        stage.cleanup()


def _fmt(x: Any, spec: str = ".6g") -> str:
    return "" if x is None else format(x, spec) if isinstance(x, (int, float)) else str(x)


def batch_markdown(result: BatchResult) -> str:
    """``batch.md``: a table with one row per design, the errors, and one table + PNG per sweep."""
    d = result.as_dict()
    lines = [f"# Batch: {d['designs']} design(s) - {d['succeeded']} ok, {d['bad_input']} bad input, {d['failed']} failed",
             "", f"Executor: {d['executor']}.", "",
             "| design | status | flat area | theta_max (deg) | pattern error | optimization | time (s) | where |",
             "|---|---|---|---|---|---|---|---|"]
    for r in result.rows:
        opt = r.get("optimization")
        opt_s = f"{opt['method']} {opt['objective']} = {_fmt(opt['best_value'])}" if opt else ""
        where = f"{r['host']} pid {r['pid']} ({r['worker']})" if r.get("host") else ""
        name = f"[{r['name']}]({r['folder']}/report.md)" if r["folder"] and "report.md" in r["files"] else r["name"]
        lines.append(f"| {name} | {r['status']} | {_fmt(r['area'], '.10g')} | {_fmt(r['theta_max'], '.3e')} | "
                     f"{_fmt(r['pattern_error'], '.2e')} | {opt_s} | {_fmt(r['elapsed_s'], '.2f')} | {where} |")
    bad = [r for r in result.rows if r["status"] != OK]
    if bad:
        lines += ["", "## Errors", ""]
        lines += [f"- **{r['name']}** ({r['source']}, {r['status']}): {r['error']}" for r in bad]
    for s, sd in zip(result.sweeps, d["sweeps"]):
        rows = [r for r in result.rows if (r.get("sweep") or {}).get("base") == s.base]
        lines += ["", f"## Sweep of {s.base} ({s.source}, {s.mode}, {len(s.variants)} variants)", "",
                  f"![{', '.join(s.plot)} against {s.keys[0]}]({sd['png']})", "",
                  "| variant | " + " | ".join(s.keys) + " | status | " + " | ".join(s.plot) + " |",
                  "|---|" + "---|" * (len(s.keys) + 1 + len(s.plot))]
        for r in rows:
            vals = r["sweep"]["values"]
            lines.append(f"| {r['name']} | " + " | ".join(_fmt(vals[k]) for k in s.keys) + f" | {r['status']} | "
                         + " | ".join(_fmt(r.get(p), '.10g') for p in s.plot) + " |")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------------------


def __getattr__(name: str) -> Any:
    """``ght_cad.app.batch.map_step_faces``: moved to :func:`ght_cad.app.design.step_input.map_step_faces`
    (issue 27: the STEP input no longer imports this module), still importable from here; imported
    on first use, so ``import ght_cad.app.batch`` does not load the design package."""
    if name == "map_step_faces":
        from .design.step_input import map_step_faces

        return map_step_faces
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
