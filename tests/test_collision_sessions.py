"""CollisionLimit over random-command sessions at 100 Hz, in the issue's four scenes
(benchmarks/collision_soak.py: the hands driven toward random targets chosen to collide).

With the limit, the minimum distance over every pair stays above the safety distance minus
:data:`TOLERANCE` (the one-step linearisation bound), no joint leaves its limits or exceeds its
velocity limit, no rate is NaN and no tick falls back (each one named with its reasons
otherwise); without it, the same sessions collide (a pair in penetration). The hands' positions
alone with a fixed seed, and their full twists turning at random with a fresh one.

The sessions are 8 s of simulated time (5 s without the limit) in the normal suite;
``RRC_PIN_COLLISION_MINUTES=10`` runs the issue's 10 minutes (docs/api.md records those runs'
numbers; ``-s`` prints them; ``bench_collision.py --soak`` runs them too).
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
try:
    import collision_soak as soak
finally:
    sys.path.pop(0)

TOLERANCE = 1e-3
"""[m] How far below the safety distance a session may go, and the largest one-step
linearisation error of a pair's row near it: the distance after a step against the row's
prediction ``d + d_dot dt``, the witness points' second-order motion over the step
(docs/api.md states the 10-minute sessions' numbers)."""
SECONDS = 60.0 * float(os.environ.get("RRC_PIN_COLLISION_MINUTES", "0")) or 8.0
FRESH = int(np.random.SeedSequence().entropy % 2**63)
"""The turning sessions' seed, drawn fresh each run (named in every failure)."""


@pytest.mark.parametrize("turn", [False, True], ids=("positions", "turning"))
@pytest.mark.parametrize("name", soak.SCENES)
def test_a_session_keeps_every_pair_apart(name, turn):
    seed = FRESH if turn else 7
    start = time.perf_counter()
    s = soak.session(name, SECONDS, seed, turn=turn)
    where = f"{name}, seed {seed}"
    print(f"\n{where}{' turning' if turn else ''}: {s.ticks} ticks, min distance "
          f"{s.min_distance * 1e3:.2f} mm ({'|'.join(s.worst_pair)}), joint excess "
          f"{s.joint_excess:.2e}, rates {s.rate_over_limit:.4f} of their limits, statuses "
          f"{s.statuses}, linearisation error {s.linearisation * 1e3:.3f} mm, fallback ticks "
          f"{s.fallbacks}, {time.perf_counter() - start:.1f} s wall")  # fmt: skip
    assert s.finite, where
    assert not s.fallbacks, f"{where}: {s.fallbacks}"
    assert s.joint_excess <= 1e-9, where
    assert s.rate_over_limit <= 1.0 + 1e-12, where
    assert s.min_distance >= soak.SAFETY - TOLERANCE, where
    assert s.linearisation <= TOLERANCE, where
    assert s.min_distance < soak.DETECTION, where  # the session brought pairs within reach


@pytest.mark.parametrize("name", soak.SCENES)
def test_without_the_limit_the_same_session_collides(name):
    s = soak.session(name, min(SECONDS, 5.0), 7, limit=False, measure_steps=False)
    print(f"\n{name} without the limit: min distance {s.min_distance * 1e3:.1f} mm "
          f"({'|'.join(s.worst_pair)})")  # fmt: skip
    assert s.min_distance < 0.0
