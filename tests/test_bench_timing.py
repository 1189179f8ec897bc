"""The benchmarks' loop modes (benchmarks/timing.py): who runs when, and which calls count."""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture
def timing(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    return importlib.import_module("timing")


def loops(calls: list[tuple[str, int]]) -> dict:
    def loop(label: str):
        def tick(k: int) -> tuple[float, float]:
            calls.append((label, k))
            return float(k), float(k) + 0.5

        return tick

    return {label: loop(label) for label in ("a", "b", "c")}


def test_tight_turns_leave_out_their_first_calls(timing):
    calls: list[tuple[str, int]] = []
    ticks = 2 * timing.BLOCK + 10
    out = timing.closed_loops("tight", loops(calls), ticks, np.random.default_rng(0))
    # each loop BLOCK ticks in a row, the turns rotated every round, every tick once
    assert calls[: timing.BLOCK] == [("a", k) for k in range(timing.BLOCK)]
    assert calls[3 * timing.BLOCK][0] == "b"
    assert sorted(calls) == sorted((label, k) for label in "abc" for k in range(ticks))
    wall, cpu = out["c"]
    first = [a + i for a in range(0, ticks, timing.BLOCK) for i in range(timing.TURN_WARM_UP)]
    assert set(wall) == set(range(ticks)) - set(first)
    np.testing.assert_array_equal(cpu, wall + 0.5)


def test_interleaved_ticks_run_every_loop_once_in_drawn_orders(timing):
    calls: list[tuple[str, int]] = []
    out = timing.closed_loops("interleaved", loops(calls), 200, np.random.default_rng(1))
    orders = {tuple(label for label, _ in calls[3 * k : 3 * k + 3]) for k in range(200)}
    assert all(sorted(o) == ["a", "b", "c"] for o in orders) and len(orders) == 6
    assert [k for _, k in calls] == [k for k in range(200) for _ in range(3)]
    assert out["a"][0].tolist() == list(range(200))  # every tick counts


def test_an_unknown_mode_is_refused(timing):
    with pytest.raises(ValueError, match="unknown mode"):
        timing.closed_loops("loose", loops([]), 3, np.random.default_rng(0))
