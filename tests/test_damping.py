"""Damping: only past the threshold, only for a command that cannot be met, continuous."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.errors import InvalidInput
from rrc_pin.solvers.tick.damping import MIN_THRESHOLD, Damping, damping_lambda_sq


def test_none_below_the_threshold_or_where_the_command_can_be_met() -> None:
    d = Damping(threshold=100.0)
    along = np.ones(3)
    assert d.lambda_sq(np.array([1.0, 0.5, 0.011]), 3, 0.5, along, 0.01) is None  # cond 91
    assert d.lambda_sq(np.array([1.0, 0.5, 0.001]), 3, 1.0, along, 0.01) is None  # u* = 1
    assert d.lambda_sq(np.array([1.0, 0.5, 0.001]), 0, 0.5, along, 0.01) is None  # no rank


def test_the_schedule_and_its_continuity() -> None:
    d = Damping(threshold=100.0)
    sigma = np.array([2.0, 1.0, 0.005])
    lam = d.lambda_sq(sigma, 3, 0.25, np.array([0.0, 0.0, 1e-4]), 0.01)
    assert lam is not None and lam[0] == lam[1] == 0.0
    onset = 2.0 / 100.0
    assert lam[2] == pytest.approx((1 - (0.005 / onset) ** 2) * onset**2 * 0.75, rel=1e-12)
    # the step floor: a large command along the weak direction damps more
    floor = d.lambda_sq(sigma, 3, 0.25, np.array([0.0, 0.0, 10.0]), 0.01)
    assert floor is not None and floor[2] == pytest.approx((1 - 0.0625) * 2.0 * 10 * 0.01 * 0.75)
    # continuous: zero at the onset and at u* = 1
    at = [d.lambda_sq(np.array([2.0, s]), 2, 0.25, np.ones(2), 0.01) for s in (0.02 - 1e-12, 0.02)]
    assert at[0] is not None and at[0][1] < 1e-11 and at[1] is None
    near_one = d.lambda_sq(sigma, 3, 1.0 - 1e-12, np.ones(3), 0.01)
    assert near_one is not None and near_one.max() < 1e-12


@pytest.mark.parametrize("threshold", [9.99, 0.0, -1.0, np.nan, np.inf, "100", True])
def test_bad_thresholds_are_refused(threshold: object) -> None:
    with pytest.raises(InvalidInput) as info:
        Damping(threshold=threshold)  # type: ignore[arg-type]
    assert info.value.argument == "threshold"
    assert Damping(threshold=MIN_THRESHOLD).threshold == 10.0


def lambda_sq_reference(
    sigma: np.ndarray, rank: int, scale: float, along: np.ndarray, dt: float, threshold: float
) -> np.ndarray | None:
    """The damping schedule in plain numpy (solvers/tick/damping.py's former implementation)."""
    if rank == 0 or scale >= 1.0:
        return None
    onset = float(sigma[0]) / threshold
    s = sigma[:rank]
    if float(s[-1]) >= onset:
        return None
    lam = np.zeros(sigma.size)
    weak = s < onset
    floor = np.maximum(onset * onset, float(sigma[0]) * along[:rank][weak] * dt)
    lam[:rank][weak] = (1.0 - (s[weak] / onset) ** 2) * floor * (1.0 - scale)
    return lam


def test_damping_lambda_sq_against_numpy(rng: np.random.Generator) -> None:
    for _ in range(2000):
        k = int(rng.integers(1, 8))
        sigma = np.sort(10.0 ** rng.uniform(-5, 1, k))[::-1].copy()
        rank = int(rng.integers(0, k + 1))
        scale = float(rng.choice([rng.uniform(0, 1), 1.0, 0.0]))
        along = np.abs(rng.normal(size=k)) * 10.0 ** rng.uniform(-4, 2)
        dt, threshold = float(rng.choice([0.001, 0.01, 0.05])), float(rng.uniform(10, 1e4))
        lam = np.full(k, np.nan)
        applies = damping_lambda_sq(sigma, rank, scale, along, dt, threshold, lam)
        reference = lambda_sq_reference(sigma, rank, scale, along, dt, threshold)
        assert applies == (reference is not None)
        if reference is not None:
            np.testing.assert_allclose(lam, reference, rtol=1e-14, atol=0)
