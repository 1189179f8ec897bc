"""GripLimit: two hands held together as equality rows, and how far each pair is from its
grip."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.errors import InvalidInput
from rrc_pin.limits import GripLimit, JointLimits


def test_the_grip_is_held_and_its_error_measured_in_the_first_hands_axes():
    dual = rrc_pin.load("gsfc_dual")
    a, b = dual.objects["object"].hands
    q0 = dual.ready()
    grip = np.linalg.inv(dual.fk(q0, a)) @ dual.fk(q0, b)
    limit = GripLimit([(a, b)], grips=[grip])
    resolver = rrc_pin.Resolver(dual, 0.01, limits=[JointLimits(), limit])
    q = q0 + np.random.default_rng(5).normal(size=dual.nq) * 0.01
    resolver.solve(q, [rrc_pin.FrameTask("object", [0.02, 0, 0, 0, 0, 0.1])], priority="strict")
    rel = np.linalg.inv(dual.fk(q, a)) @ dual.fk(q, b)
    want = np.concatenate([grip[:3, 3] - rel[:3, 3], pin.log3(grip[:3, :3] @ rel[:3, :3].T)])
    np.testing.assert_allclose(limit.last.error, want, atol=1e-12)
    assert limit.last.C.shape == (6, dual.nv)
    np.testing.assert_allclose(limit.last.unit[3:], 1.0)
    assert limit.last.unit[0] > 1.0  # the longer hand's chain [m]


def test_bad_grips_are_named_and_change_nothing():
    limit = GripLimit([("a", "b")])
    assert limit.last is None
    with pytest.raises(InvalidInput, match="grips: expected 1 poses, got 0"):
        limit.set_pairs([("a", "b")], [])
    with pytest.raises(InvalidInput, match=r"grips\[0\]"):
        limit.set_pairs([("a", "b")], [np.zeros((4, 4))])
    assert limit.pairs == (("a", "b"),)
