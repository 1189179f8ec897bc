"""CollisionLimit from starts the user did not choose: random placements from touching to 8 cm
into penetration (panda against an obstacle of a random shape, two facing pandas, a box held
by panda's hand overlapping a link), the scenes of benchmarks/collision_soak.py.

From every start: no fallback tick (never held); commanded away (the hands' twists whose exact
rates move every pair inside the safety distance apart and approach no other), the hands move
at the command from the first tick (faster than 1 cm/s, or at the command's own hand speed
where that is slower: ``collision_soak.moved_at_once``) and every pair is outside the safety
distance within the time the command needs (the deepest shortfall at its speed, and 0.1 s,
where the command could go at its speed throughout); commanded at random,
no pair inside the safety distance comes closer by more than :data:`DECREASE` in a tick; no
joint rate above its velocity limit. A fixed seed and one drawn fresh each run (named in every
failure); ``bench_collision.py --soak`` runs 200 starts.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
try:
    import collision_soak as soak
finally:
    sys.path.pop(0)

SEEDS = (11, int(np.random.SeedSequence().entropy % 2**63))
"""A fixed seed and one drawn fresh each run."""

SPEED = 0.1
"""[m/s] The away command's speed apart (the soak's is 0.05)."""

DECREASE = 2.5e-4
"""[m] The largest decrease of a pair's distance inside the safety distance over one tick,
commanded at random: the rows keep the distance to first order (rounding 1e-11 m a tick), a
capsule against a box with the rows of the box's features that may take over within the step
(:mod:`rrc_pin.solvers.collision.box_kernels`); the rest is the step's second-order motion and
coal's penetration depths of cylinders. The most over 5,600 starts of the soak, 40 ticks each:
0.154 mm (a cylinder), 0.106 mm for boxes (0.46 mm without the features' rows; a capsule
sliding along a box, quadratic in the step), 0.116 mm for two pandas' capsules (quadratic)."""

MAKERS = {"panda": soak.panda_start, "held box": soak.held_box_start,
          "two pandas": soak.two_pandas_start}  # fmt: skip


@pytest.mark.parametrize("seed", SEEDS, ids=("fixed", "fresh"))
@pytest.mark.parametrize("kind", list(MAKERS))
def test_a_start_in_penetration_never_holds_and_leaves_when_commanded_away(kind, seed):
    rng = np.random.default_rng(seed)
    tried = trials = moved = 0
    while trials < 2 and tried < 20:
        tried += 1
        start = MAKERS[kind](rng, float(rng.uniform(-0.08, 0.0)))
        if start is None:
            continue
        trials += 1
        r = soak.start_trial(start, rng, random_ticks=40, away=SPEED)
        where = f"seed {seed}, {start.label}: {r}"
        assert r.fallbacks == 0, where
        assert r.rate_over_limit <= 1.0 + 1e-12, where
        assert r.decrease <= DECREASE, where
        if r.away_ticks:  # a command takes every pair inside apart: followed from the start
            moved += 1
            assert soak.moved_at_once(r), where
        if r.away_speed >= SPEED - 1e-9 and r.away_ticks:  # at the command's speed throughout
            assert r.exit_ticks is not None and r.exit_ticks <= r.deadline, where
    assert trials == 2, f"seed {seed}: {trials} starts in {tried} draws"
