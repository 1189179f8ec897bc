"""Progress of a map's run: blocks done, samples per second, time left; and a text bar."""

from __future__ import annotations

import sys
import time
from typing import TextIO

from rrc_pin.solvers.maps.sampling import Plan


class Progress:
    """Blocks and samples done by a run, and its rate.

    Attributes:
        total_blocks: Blocks of the map.
        done_blocks: Blocks done (resumed ones included).
        total_samples: Samples of the map.
        done_samples: Samples done (resumed ones included).
        run_samples: Samples computed by this run.
        started: ``time.perf_counter()`` at the run's start.
    """

    def __init__(self, plan: Plan, resumed: set[int] | None = None) -> None:
        resumed = resumed or set()
        self.total_blocks = plan.blocks
        self.total_samples = plan.samples
        self.done_blocks = len(resumed)
        self.done_samples = sum(plan.length(b) for b in resumed)
        self.run_samples = 0
        self.started = time.perf_counter()

    def update(self, blocks: list[int], plan: Plan) -> None:
        """Count ``blocks`` as done."""
        n = sum(plan.length(b) for b in blocks)
        self.done_blocks += len(blocks)
        self.done_samples += n
        self.run_samples += n

    @property
    def fraction(self) -> float:
        """Share of the blocks done [0, 1]."""
        return self.done_blocks / self.total_blocks if self.total_blocks else 1.0

    @property
    def rate(self) -> float:
        """Samples per second of this run so far."""
        elapsed = time.perf_counter() - self.started
        return self.run_samples / elapsed if elapsed > 0 else 0.0

    @property
    def eta(self) -> float:
        """Seconds left at the current rate (inf before the first task)."""
        left = self.total_samples - self.done_samples
        if not left:
            return 0.0
        return left / self.rate if self.rate > 0 else float("inf")


class ProgressBar:
    """A one-line text bar on a stream (stderr by default), redrawn at most every 0.2 s.

    On a terminal the line is redrawn in place; elsewhere (a log file) a line is written at
    every tenth of the work.
    """

    def __init__(self, label: str, stream: TextIO | None = None, width: int = 30) -> None:
        self.label, self.width = label, width
        self.stream = stream if stream is not None else sys.stderr
        self._last = 0.0
        self._tenth = -1
        self._tty = bool(getattr(self.stream, "isatty", lambda: False)())

    def __call__(self, p: Progress) -> None:
        """Draw ``p``."""
        now = time.perf_counter()
        final = p.done_blocks >= p.total_blocks
        if self._tty:
            if not final and now - self._last < 0.2:
                return
        else:
            tenth = int(10 * p.fraction)
            if tenth == self._tenth and not final:
                return
            self._tenth = tenth
        self._last = now
        full = int(self.width * p.fraction)
        eta = "" if final else (f", {p.eta:.0f} s left" if p.eta != float("inf") else "")
        line = (
            f"{self.label} [{'#' * full}{'.' * (self.width - full)}] {100 * p.fraction:3.0f}% "
            f"{p.done_blocks}/{p.total_blocks} blocks, {p.rate:,.0f} samples/s{eta}"
        )
        end = "\n" if final or not self._tty else ""
        self.stream.write(("\r" if self._tty else "") + line + end)
        self.stream.flush()
