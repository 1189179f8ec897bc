"""The jerk stage's compiled kernels against the numpy expressions they are written from."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.smoothing_kernels import braked, jerk_step

SEEDS = [7, int(np.random.SeedSequence().entropy % 2**63)]


def jerk_step_reference(v, a, target, dt, a_max, j_max):
    e = target - v
    wanted = np.sign(e) * j_max * (np.sqrt(dt * dt + 2.0 * np.abs(e) / j_max) - dt)
    step = np.clip(np.clip(wanted, a - j_max * dt, a + j_max * dt), -a_max, a_max)
    return v + step * dt


def braked_reference(command, position, lower, upper, brake, lead):
    out = command.copy()
    for distance, sign in ((upper - position, 1.0), (position - lower, -1.0)):
        d = np.maximum(distance, 0.0)
        fastest = -brake * lead + np.sqrt((brake * lead) ** 2 + 2.0 * brake * d)
        out = np.minimum(out, fastest) if sign > 0 else np.maximum(out, -fastest)
    return out


@pytest.mark.parametrize("seed", SEEDS, ids=["fixed", "fresh"])
def test_the_kernels_are_the_numpy_expressions(seed):
    """Random rates, accelerations, targets (some equal to the rate: e = 0), bounds, positions
    (some beyond a limit, some limits infinite): the kernels' answers equal numpy's to 1e-12."""
    rng = np.random.default_rng(seed)
    for _ in range(200):
        n = int(rng.integers(1, 16))
        v, a = rng.normal(size=n) * 2.0, rng.normal(size=n) * 10.0
        target = np.where(rng.random(n) < 0.2, v, rng.normal(size=n) * 2.0)
        a_max, j_max = rng.uniform(1.0, 50.0, n), rng.uniform(10.0, 1000.0, n)
        dt = float(rng.uniform(1e-3, 2e-2))
        out = np.empty(n)
        jerk_step(v, a, target, dt, a_max, j_max, out)
        np.testing.assert_allclose(out, jerk_step_reference(v, a, target, dt, a_max, j_max),
                                   rtol=0, atol=1e-12, err_msg=f"seed {seed}")  # fmt: skip
        lower, upper = -rng.uniform(0.5, 3.0, n), rng.uniform(0.5, 3.0, n)
        lower[rng.random(n) < 0.2], upper[rng.random(n) < 0.2] = -np.inf, np.inf
        position = rng.uniform(-3.5, 3.5, n)
        brake, lead = 0.5 * a_max, a_max / j_max + 2.0 * dt
        braked(v, position, lower, upper, brake, lead, out)
        want = braked_reference(v, position, lower, upper, brake, lead)
        np.testing.assert_allclose(out, want, rtol=0, atol=1e-12, err_msg=f"seed {seed}")
