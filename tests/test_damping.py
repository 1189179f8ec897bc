"""Damping: only past the threshold, only for a command that cannot be met, continuous."""

from __future__ import annotations

import numpy as np
import pytest

from rrc_pin.solvers.errors import InvalidInput
from rrc_pin.solvers.tick.damping import MIN_THRESHOLD, Damping


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
