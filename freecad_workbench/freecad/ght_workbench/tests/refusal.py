"""What a failed recompute shows, for the freecadcmd test modules (``fc_*``).

A feature that refuses its input must be in FreeCAD's error state (``State`` ``Invalid``, the
message as status string) and print exactly one line ``"<Label>: <message>"`` plus FreeCAD's
"Recompute failed! Please check report view." on the console (the Report view in the GUI), never
a Python traceback. :func:`console_output` captures what FreeCAD prints (its C++ console writes to
the process's file descriptors 1 and 2, not to ``sys.stdout``); :class:`RefusalAssertions` checks
all of that.
"""

from __future__ import annotations

import os
import re
import sys
import tempfile
from typing import Any, Callable

from freecad.ght_workbench import _base

RECOMPUTE_FAILED = "Recompute failed! Please check report view."
_PROGRESS = re.compile(r"^(Recompute\.*|\(\d+ %\))$")
_TRACEBACK = re.compile(r"Traceback \(most recent call last\)|^\s*File \".*\", line \d+|^<class '[\w.]+'>: ")


def console_output(fn: Callable[[], Any]) -> tuple[Any, str]:
    """``(fn(), everything FreeCAD and Python printed on stdout/stderr meanwhile)``."""
    sys.stdout.flush()
    sys.stderr.flush()
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        saved = os.dup(1), os.dup(2)
        os.dup2(tmp.fileno(), 1)
        os.dup2(tmp.fileno(), 2)
        try:
            value = fn()
            sys.stdout.flush()
            sys.stderr.flush()
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
        tmp.seek(0)
        return value, tmp.read().decode("utf-8", "replace")


def console_lines(text: str) -> list[str]:
    """The non-blank lines of ``text`` without freecadcmd's recompute progress ("Recompute......", "(50 %)")."""
    parts = (p.strip() for p in re.split(r"[\r\n\t]+", text))
    return [p for p in parts if p and not _PROGRESS.match(p)]


def report_line(obj: Any, message: str) -> str:
    """The line a feature prints for ``message``: ``"<Label>: <message>"``, the Label not repeated."""
    label = obj.Label
    return message if message.startswith((label + ":", label + ".")) else f"{label}: {message}"


class RefusalAssertions:
    """Mixin for ``unittest.TestCase``: a recompute that refuses a feature's input."""

    def assert_no_traceback(self, text: str) -> None:
        """No line of ``text`` is part of a Python traceback."""
        bad = [l for l in text.splitlines() if _TRACEBACK.search(l)]
        self.assertEqual(bad, [], text)  # type: ignore[attr-defined]

    def assert_recompute_refused(self, doc: Any, obj: Any, message: str, *, recompute: Callable[[], Any] | None = None) -> str:
        """Recompute ``doc`` (or call ``recompute``): ``obj`` fails with exactly ``message``.

        ``obj`` is in FreeCAD's error state (``State`` ``Invalid``, :func:`_base.failed`), its
        status string is ``message``, and the console shows exactly the feature's line and, after
        a document recompute, FreeCAD's "Recompute failed!" line (``obj.recompute()`` prints no
        such summary); no traceback.

        Returns:
            Everything printed during the recompute.
        """
        _, text = console_output(recompute or doc.recompute)
        self.assertTrue(_base.failed(obj), f"{obj.Label} did not fail (state {obj.State}); printed:\n{text}")  # type: ignore[attr-defined]
        self.assertIn("Invalid", obj.State)  # type: ignore[attr-defined]
        self.assertEqual(obj.getStatusString(), message)  # type: ignore[attr-defined]
        self.assert_no_traceback(text)
        expected = [report_line(obj, message)] + ([RECOMPUTE_FAILED] if recompute is None else [])
        self.assertEqual(console_lines(text), expected, text)  # type: ignore[attr-defined]
        return text

    def assert_refused_as(self, doc: Any, obj: Any, call: Callable[[], Any], pattern: str) -> str:
        """``call()`` (e.g. ``obj.Proxy.surface(obj)``) raises a ``GHTError`` matching ``pattern``;
        recomputing ``obj`` fails with exactly that message (:meth:`assert_recompute_refused`).

        Returns:
            The message.
        """
        from ght_cad.core.errors import GHTError

        with self.assertRaisesRegex(GHTError, pattern) as ctx:  # type: ignore[attr-defined]
            call()
        message = str(ctx.exception)
        obj.touch()
        self.assert_recompute_refused(doc, obj, message)
        return message

    def assert_recompute_clean(self, doc: Any, *objs: Any) -> str:
        """Recompute ``doc``: nothing printed, and none of ``objs`` failed."""
        _, text = console_output(doc.recompute)
        for o in objs:
            self.assertFalse(_base.failed(o), f"{o.Label}: {o.getStatusString()}")  # type: ignore[attr-defined]
        self.assertEqual(console_lines(text), [], text)  # type: ignore[attr-defined]
        return text
