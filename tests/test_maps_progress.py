"""Progress of a run and its text bar."""

from __future__ import annotations

import io

from rrc_pin.maps.progress import Progress, ProgressBar
from rrc_pin.solvers.maps.sampling import Plan


def test_progress_counts_and_bar_lines():
    plan = Plan(10 * 64 - 5, 64)
    p = Progress(plan, {0, 1})
    assert p.done_blocks == 2 and p.done_samples == 128 and p.fraction == 0.2
    stream = io.StringIO()
    bar = ProgressBar("map x", stream)
    for b in range(2, 10):
        p.update([b], plan)
        bar(p)
    assert p.done_samples == plan.samples and p.fraction == 1.0 and p.eta == 0.0
    lines = stream.getvalue().splitlines()
    assert 1 <= len(lines) <= 10 and lines[-1].startswith("map x [") and "10/10 blocks" in lines[-1]
