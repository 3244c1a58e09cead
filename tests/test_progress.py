"""ght_cad.core.progress: drawn on a TTY only, silent otherwise."""

from __future__ import annotations

import io

import numpy as np
import pytest

from ght_cad.optimize import pso
from ght_cad.core.progress import Progress, progress_enabled


class FakeTTY(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_silent_when_not_a_tty(monkeypatch):
    monkeypatch.delenv("GHT_CAD_PROGRESS", raising=False)
    s = io.StringIO()
    with Progress(10, "work", stream=s) as p:
        for _ in range(10):
            p.update()
    assert s.getvalue() == "" and p.count == 10


def test_drawn_on_a_tty(monkeypatch):
    monkeypatch.delenv("GHT_CAD_PROGRESS", raising=False)
    s = FakeTTY()
    with Progress(4, "work", stream=s, min_interval=0.0) as p:
        p.update(2)
        assert "[###############...............] 2/4  50%" in s.getvalue()
        p.update(5)      # clamped to total
    out = s.getvalue()
    assert out.startswith("\rwork [") and "4/4 100%" in out and out.endswith("\n") and p.count == 4


def test_env_override(monkeypatch):
    monkeypatch.setenv("GHT_CAD_PROGRESS", "0")
    assert not progress_enabled(FakeTTY())
    monkeypatch.setenv("GHT_CAD_PROGRESS", "1")
    assert progress_enabled(io.StringIO())


def test_optimizer_callback_adapter(monkeypatch):
    monkeypatch.delenv("GHT_CAD_PROGRESS", raising=False)
    s = FakeTTY()
    with Progress(20, "pso", stream=s, min_interval=0.0) as p:
        r = pso(lambda X: np.sum(X**2, axis=1), (-np.ones(2), np.ones(2)), pop_size=5, max_iter=20,
                seed=0, callback=p.callback)
    assert r.nit == 20 and p.count == 20 and "20/20 100%" in s.getvalue()


def test_counter_without_total_and_bad_total(monkeypatch):
    monkeypatch.delenv("GHT_CAD_PROGRESS", raising=False)
    s = FakeTTY()
    with Progress(None, "scan", stream=s, min_interval=0.0) as p:
        p.update(3)
    assert "scan 3 " in s.getvalue()
    with pytest.raises(ValueError, match="total=-1"):
        Progress(-1)
