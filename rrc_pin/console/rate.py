"""Pacing a loop to a fixed rate, and the statistics of its tick periods."""

from __future__ import annotations

import threading
import time
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import finite_number

Array = npt.NDArray[np.float64]


class Rate:
    """Sleeps until the next tick of a fixed-rate schedule (absolute deadlines, no drift).

    Deadlines are ``start + k * period``: a late wake-up shortens the next sleep instead of
    shifting the schedule. A tick that starts more than one whole period late gives up the
    missed deadlines (counted in :attr:`skipped`) and restarts the schedule from now, so that
    a stall is not followed by a burst of catch-up ticks.

    Args:
        hz: Rate [1/s], > 0.
        min_sleep: Shortest sleep [s] of every tick, >= 0, even a late one: a thread under
            real-time scheduling that overran its period still leaves the core to others.
    """

    def __init__(self, hz: float, min_sleep: float = 0.0) -> None:
        self.period = 1.0 / finite_number(hz, "rate", 0.0, inclusive=False)
        self.min_sleep = finite_number(min_sleep, "min_sleep", 0.0)
        self.skipped = 0
        self._next = time.perf_counter() + self.period

    def sleep(self, stop: threading.Event | None = None) -> None:
        """Sleep until the next deadline (or until ``stop`` is set)."""
        delay = self._next - time.perf_counter()
        if delay <= 0.0:
            missed = int(-delay // self.period)
            if missed >= 1:  # more than a period late: drop the missed deadlines
                self.skipped += missed
                self._next = time.perf_counter()
        delay = max(delay, self.min_sleep)
        if delay > 0.0:
            if stop is None:
                time.sleep(delay)
            else:
                stop.wait(delay)
        self._next += self.period


class PeriodStats(NamedTuple):
    """Statistics of the measured tick periods.

    Attributes:
        n: Periods in the window.
        median: Median period [s].
        p99: 99th percentile [s].
        max: Largest [s].
    """

    n: int
    median: float
    p99: float
    max: float


class TickClock:
    """A loop's tick periods (between the starts of ticks) and work times, in ring buffers.

    :meth:`tick` and :meth:`done` are called by the loop (one thread); :meth:`stats` may be
    called from any thread (it copies the window first: a value written meanwhile is in or
    out, never torn).

    Args:
        window: How many periods are kept, >= 2.
    """

    def __init__(self, window: int = 20_000) -> None:
        if isinstance(window, bool) or not isinstance(window, int) or window < 2:
            raise InvalidInput("window", f"expected an int >= 2, got {window!r}")
        self._periods = np.zeros(window)
        self._work = np.zeros(window)
        self._count = 0
        self._done = 0
        self._last: float | None = None
        self.ticks = 0

    def tick(self, now: float | None = None) -> float:
        """Record the start of a tick at ``now`` [s] (default ``time.perf_counter()``)."""
        now = time.perf_counter() if now is None else now
        if self._last is not None:
            self._periods[self._count % len(self._periods)] = now - self._last
            self._count += 1
        self._last = now
        self.ticks += 1
        return now

    def done(self, now: float | None = None) -> None:
        """Record the end of the tick started last (its work time) at ``now`` [s]."""
        if self._last is not None:
            now = time.perf_counter() if now is None else now
            self._work[self._done % len(self._work)] = now - self._last
            self._done += 1

    def reset(self) -> None:
        """Forget the periods measured so far (e.g. once a browser has connected)."""
        self._count = self._done = 0
        self._last = None

    def periods(self) -> Array:
        """The periods in the window [s], oldest first."""
        return _window(self._periods, self._count)

    def work(self) -> Array:
        """The ticks' work times in the window [s] (start to :meth:`done`), oldest first."""
        return _window(self._work, self._done)

    def stats(self, work: bool = False) -> PeriodStats:
        """Median, 99th percentile and largest period (or ``work`` time) of the window.

        Zeros when the window is empty.
        """
        p = self.work() if work else self.periods()
        if p.size == 0:
            return PeriodStats(0, 0.0, 0.0, 0.0)
        median, p99 = np.percentile(p, [50.0, 99.0])
        return PeriodStats(int(p.size), float(median), float(p99), float(np.max(p)))


def _window(ring: Array, count: int) -> Array:
    """The last values written to ``ring`` (``count`` in all), oldest first (a copy)."""
    size = len(ring)
    if count <= size:
        head: Array = ring[:count].copy()
        return head
    k = count % size
    out: Array = np.concatenate([ring[k:], ring[:k]])
    return out
