"""Frame changes of twists and Jacobians, checked against Pinocchio's own frames."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.solvers.errors import InvalidInput
from rrc_pin.solvers.spatial import (
    REFERENCES,
    check_reference,
    from_world_aligned,
    to_world_aligned,
)


@pytest.mark.parametrize("ref", REFERENCES)
def test_conversion_reproduces_pinocchio_frames(rng, ref):
    arm = rrc_pin.load("panda")
    for _ in range(100):
        q = arm.random_q(rng)
        T = arm.fk(q)
        J = from_world_aligned(arm.jacobian(q), T[:3, :3], T[:3, 3], ref)
        np.testing.assert_allclose(J, arm.jacobian(q, ref), atol=1e-12)
        twist = rng.normal(size=6)
        R, p = T[:3, :3], T[:3, 3]
        # the inverse change: the rotation transposed and the position negated
        back = from_world_aligned(from_world_aligned(twist, R, p, ref), R.T, -p, ref)
        np.testing.assert_allclose(back, twist, atol=1e-12)


def test_unknown_reference_lists_the_valid_ones():
    with pytest.raises(InvalidInput, match="^ref: expected one of world_aligned, local, world"):
        check_reference("base")


@pytest.mark.parametrize("ref", REFERENCES)
def test_to_world_aligned_is_the_twist_of_the_same_rates(rng, ref):
    """A twist of rates expressed in ``ref`` comes back as their world_aligned twist."""
    arm = rrc_pin.load("panda")
    for _ in range(50):
        q, qdot = arm.random_q(rng), rng.normal(size=arm.nv)
        T = arm.fk(q)
        twist = to_world_aligned(arm.jacobian(q, ref) @ qdot, T[:3, :3], T[:3, 3], ref)
        np.testing.assert_allclose(twist, arm.jacobian(q) @ qdot, atol=1e-12)
