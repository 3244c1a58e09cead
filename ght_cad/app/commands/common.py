"""What the ``ght-cad`` subcommands share: exit codes, the usage error, JSON output, argument
parsers for points and paths, staged output files and the report text.

Moved from :mod:`ght_cad.app.cli` (issue 27; every name stays importable from there). :mod:`ght_cad.app.batch`
and :mod:`ght_cad.app.approximate_cli` take :func:`dumps` from here (not from the CLI that runs them).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path
from typing import Any, Callable, Sequence


EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_INTERRUPTED = 130
PROG = "ght-cad"


class UsageError(Exception):
    """Bad command-line input detected by a command (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose errors are one line on stderr and exit code 2.

    When the command line being parsed contains ``--json`` (set by :func:`main`), the error is
    also printed to stdout as one JSON object ``{"ok": false, "error": ..., "exit_code": 2}``.
    """

    json_errors = False

    def error(self, message: str) -> None:  # type: ignore[override]
        msg = " ".join(f"{message} (see '{self.prog} --help')".split())
        if _Parser.json_errors:
            sys.stdout.write(dumps({"ok": False, "error": f"{self.prog}: {msg}", "exit_code": EXIT_USAGE}) + "\n")
            sys.stdout.flush()
        self.exit(EXIT_USAGE, f"{self.prog}: error: {msg}\n")


def _wants_json(argv: Sequence[str]) -> bool:
    """True if ``argv`` asks for ``--json`` (argparse also accepts the prefixes ``--j``, ``--js``, ...)."""
    return any(a.startswith("--j") and "--json".startswith(a) for a in argv)


# ---------------------------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------------------------
def _json_default(o: Any) -> Any:
    try:
        import numpy as np

        if isinstance(o, np.ndarray):
            return o.tolist()
        if isinstance(o, np.generic):
            return o.item()
    except ImportError:  # pragma: no cover
        pass
    if isinstance(o, Path):
        return str(o)
    if hasattr(o, "as_dict"):
        return o.as_dict()
    return str(o)


def _clean(o: Any) -> Any:
    """Replace NaN/inf by None so the output is strict JSON."""
    if isinstance(o, float):
        return o if math.isfinite(o) else None
    if isinstance(o, dict):
        return {str(k): _clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_clean(v) for v in o]
    return o


def dumps(obj: Any) -> str:
    """Strict JSON text (numpy values converted, NaN/inf as null)."""
    return json.dumps(_clean(json.loads(json.dumps(obj, default=_json_default))), indent=2, allow_nan=False)


def _parse_floats(text: str, what: str) -> list[float]:
    try:
        vals = [float(x) for x in text.replace(",", " ").split()]
    except ValueError:
        raise UsageError(f"{what}={text!r} is not a list of numbers; write e.g. '0,0.5,-1'") from None
    return vals


def _parse_points(text: str, what: str = "--points") -> list[list[float]]:
    """Points from JSON (``[[0,0],[1,2]]``) or ``'x,y[,z] x,y[,z] ...'`` (space or ';' separated)."""
    s = text.strip()
    if s.startswith("["):
        try:
            pts = json.loads(s)
        except json.JSONDecodeError as exc:
            raise UsageError(f"{what} is not valid JSON: {exc}") from None
        if not isinstance(pts, list) or not all(isinstance(p, list) for p in pts):
            raise UsageError(f"{what} must be a JSON list of coordinate lists, e.g. [[0,0],[1,2],[3,0]]")
    else:
        groups = [g for g in s.replace(";", " ").split() if g]
        pts = []
        for g in groups:
            try:
                pts.append([float(x) for x in g.split(",")])
            except ValueError:
                raise UsageError(f"{what}: {g!r} is not a point; write points as 'x,y[,z]' separated by spaces") from None
    _check_same_dimension(pts, what)
    return pts


def _check_same_dimension(pts: list[list[float]], what: str) -> None:
    """Raise :class:`UsageError` naming the first point whose dimension differs from point 1's."""
    if not pts:
        return
    dim = len(pts[0])
    for i, pt in enumerate(pts[1:], start=2):
        if len(pt) != dim:
            raise UsageError(
                f"{what}: point {i} ({_fmt_point(pt)}) has dimension {len(pt)} but point 1 "
                f"({_fmt_point(pts[0])}) has dimension {dim}; all points need the same dimension"
            )


def _fmt_point(pt: list[Any]) -> str:
    return ",".join(f"{x:g}" if isinstance(x, (int, float)) else repr(x) for x in pt)


def _out_path(text: str) -> str:
    """``--out``'s value: an empty path is refused (it would silently mean the current folder)."""
    if not text.strip():
        raise argparse.ArgumentTypeError(f"{text!r} is an empty path; allowed: a folder or file path "
                                         "(use '.' for the current folder)")
    return text


def _check_suffix(option: str, value: str | os.PathLike | None, allowed: Sequence[str]) -> None:
    """Raise :class:`UsageError` unless ``value`` (if given) ends in one of ``allowed`` (case-insensitive)."""
    if value is None:
        return
    suf = Path(value).suffix
    if suf.lower() not in allowed:
        raise UsageError(
            f"{option} {str(value)!r}: unknown suffix {suf!r}; allowed: {', '.join(allowed)}"
        )


def _progress(total: int | None, label: str) -> Any:
    from ...core.progress import Progress

    return Progress(total, label)


def _emit(args: argparse.Namespace, result: dict[str, Any], text: Callable[[dict[str, Any]], str]) -> None:
    if getattr(args, "json", False):
        args._json_out = dumps({"ok": True, **result})  # printed by main() once stdout is restored
    else:
        print(text(result))


def _outputs_text(result: dict[str, Any]) -> str:
    lines = []
    for k, v in (result.get("outputs") or {}).items():
        lines.append(f"  {k}: {v}")
    return "\n".join(lines)


def _write_staged(outputs: Sequence[tuple[str, str | None, Callable[[Path], Any]]]) -> dict[str, str]:
    """Write the requested outputs all or nothing; returns ``{kind: path}`` in the given order.

    Each ``(kind, target, writer)`` with a target calls ``writer(temporary path)``; the files are
    staged beside their targets (:class:`ght_cad.core.outdir.StagedFiles`: locked targets, staging
    folders a later run can tell from a live one's) and moved into place only when every writer
    succeeded (a failure leaves no new file and every existing target as it was).
    """
    from ...core.outdir import StagedFiles

    wanted = [(kind, Path(target), writer) for kind, target, writer in outputs if target]
    if not wanted:
        return {}
    with StagedFiles([t for _, t, _ in wanted]) as stage:
        for _, target, writer in wanted:
            writer(stage.path(target))
        stage.commit()
    return {kind: str(target) for kind, target, _ in wanted}


def _chord_tol(args: argparse.Namespace) -> float | None:
    """``--chord-tol`` (None: the design's ``[outputs] chord_tol``, else 1e-3 mm in the pattern's unit); refused
    unless > 0 and finite. The option takes precedence over the design file's key."""
    tol = getattr(args, "chord_tol", None)
    if tol is not None and not (tol > 0 and math.isfinite(tol)):
        raise UsageError(f"--chord-tol={tol!r} is not allowed; allowed: a positive length in the pattern's units "
                         "(default 1e-3 mm)")
    return tol


def _wait_args(args: argparse.Namespace) -> dict[str, Any]:
    """``wait``/``timeout`` for :func:`ght_cad.app.design.run_design` from ``--wait``/``--wait-timeout``."""
    timeout = getattr(args, "wait_timeout", None)
    if timeout is not None and not (math.isfinite(timeout) and timeout >= 0):
        raise UsageError(f"--wait-timeout {timeout:g} is not allowed; allowed: a number of seconds >= 0")
    return {"wait": bool(getattr(args, "wait", False) or timeout is not None), "timeout": timeout}


def add_wait_options(sp: argparse.ArgumentParser) -> None:
    """``--wait`` and ``--wait-timeout`` of the commands that write an output folder (run, demo, batch)."""
    sp.add_argument("--wait", action="store_true",
                    help="if another ght-cad process writes the output folder, wait until it has finished "
                    "(default: refuse with exit code 2, naming the folder and the other process)")
    sp.add_argument("--wait-timeout", type=float, metavar="SECONDS",
                    help="wait at most this long for the output folder (implies --wait); then exit code 2")


def _report_text(r: dict[str, Any]) -> str:
    lines = [f"{r.get('name', 'design')}: results in {r.get('out_dir')}"]
    dev = r.get("developability")
    if dev:
        lines.append(
            f"  developability: DD={dev['dd']:.12f}  theta_max={dev['theta_max']:.3e} deg  R={dev['R']:.3e}"
        )
    pat = r.get("flat_pattern")
    if pat and pat.get("errors"):
        errs = ", ".join(f"{k}={v:.2e}" for k, v in pat["errors"].items() if isinstance(v, (int, float)))
        lines.append(f"  flat pattern errors: {errs}")
    opt = r.get("optimization")
    if opt:
        lines.append(
            f"  optimization ({opt.get('method')}, {opt.get('objective')}): best {opt.get('best_value'):.6g} "
            f"at {opt.get('best_parameters')}"
        )
    if r.get("elapsed_s") is not None:
        lines.append(f"  elapsed {r['elapsed_s']:.1f} s")
    files = r.get("files") or []
    if files:
        lines.append("  files: " + ", ".join(files))
    return "\n".join(lines)


_STEP = (".step", ".stp")
_PNG = (".png",)
