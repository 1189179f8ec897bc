"""Pacing and tick statistics."""

from __future__ import annotations

import time

import numpy as np
import pytest

from rrc_pin.console.rate import Rate, TickClock
from rrc_pin.errors import InvalidInput


def test_rate_keeps_absolute_deadlines():
    rate = Rate(200.0)
    start = time.perf_counter()
    for _ in range(40):
        rate.sleep()
    elapsed = time.perf_counter() - start
    assert 0.19 <= elapsed < 1.0  # 40 periods of 5 ms, however late each wake-up (a loaded
    # machine's stall adds to it)
    assert rate.period == 0.005


def test_a_stall_skips_the_missed_deadlines_instead_of_bursting():
    rate = Rate(1000.0)
    rate.sleep()
    time.sleep(0.02)  # 20 periods late
    rate.sleep()
    assert rate.skipped >= 15
    start = time.perf_counter()
    for _ in range(5):
        rate.sleep()
    assert time.perf_counter() - start >= 0.004  # paced again, not five at once


def test_tick_clock_periods_and_window():
    clock = TickClock(window=4)
    assert clock.stats().n == 0
    for k, t in enumerate([0.0, 1.0, 3.0, 6.0, 10.0, 15.0, 21.0]):
        clock.tick(t)
        assert clock.ticks == k + 1
    np.testing.assert_array_equal(clock.periods(), [3.0, 4.0, 5.0, 6.0])  # the last four
    stats = clock.stats()
    assert (stats.n, stats.median, stats.max) == (4, 4.5, 6.0)
    clock.reset()
    assert clock.stats().n == 0


def test_bad_rates_and_windows_are_refused():
    with pytest.raises(InvalidInput, match="rate"):
        Rate(0.0)
    with pytest.raises(InvalidInput, match="window"):
        TickClock(1)


def test_tick_clock_work_times():
    clock = TickClock(window=8)
    for start in (0.0, 1.0, 2.0):
        clock.tick(start)
        clock.done(start + 0.25)
    np.testing.assert_array_equal(clock.work(), [0.25, 0.25, 0.25])
    assert clock.stats(work=True).median == 0.25


def test_a_late_tick_still_sleeps_its_minimum():
    rate = Rate(1000.0, min_sleep=0.002)
    time.sleep(0.005)  # late
    start = time.perf_counter()
    rate.sleep()
    assert time.perf_counter() - start >= 0.0019
