"""``ght-cad batch``: many design files, one output folder each.

Moved from :mod:`ght_cad.app.cli` (issue 27; every name stays importable from there).
"""

from __future__ import annotations

import argparse
import sys

from .common import _chord_tol, dumps, EXIT_OK, PROG, UsageError


def cmd_batch(args: argparse.Namespace) -> int:
    """``ght-cad batch``: :func:`ght_cad.app.batch.run_batch`; exit 0 all ok, 2 any bad input, 1 any failed."""
    from ..batch import run_batch

    if args.jobs is not None and args.scheduler:
        raise UsageError("--jobs and --scheduler exclude each other: --jobs runs local processes, "
                         "--scheduler a Dask cluster's workers")
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: allowed: an integer >= 1")
    res = run_batch(args.designs, args.out, jobs=args.jobs, scheduler=args.scheduler, progress=not args.no_progress,
                    chord_tol=_chord_tol(args))
    summary = res.as_dict()
    for r in summary["rows"]:
        if r["status"] != "ok":
            sys.stderr.write(f"{PROG}: {r['status']}: {r['name']}: {r['error']}\n")
    if getattr(args, "json", False):
        args._json_out = dumps({"ok": res.exit_code == EXIT_OK, "command": "batch", **summary})
    else:
        print(f"{summary['designs']} design(s) in {summary['out_dir']}: {summary['succeeded']} ok, "
              f"{summary['bad_input']} bad input, {summary['failed']} failed ({summary['executor']}, "
              f"{summary['elapsed_s']:.1f} s); summary: batch.json, batch.md")
    return res.exit_code
