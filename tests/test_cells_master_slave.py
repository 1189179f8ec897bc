"""MasterSlave: scaling, orientation map, clutch indexing, bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.cells import MasterSlave
from rrc_pin.errors import InvalidInput


def _pose(p, w=(0.0, 0.0, 0.0)):
    T = np.eye(4)
    T[:3, :3] = pin.exp3(np.asarray(w, dtype=float))
    T[:3, 3] = p
    return T


def test_increments_are_scaled_and_mapped():
    R = pin.exp3(np.array([0.0, 0.0, np.pi / 2]))
    ms = MasterSlave(scale=2.0, rotation=R, dt=0.01)
    assert not ms.update(_pose([0, 0, 0]), True).any()  # engaging: no jump
    twist = ms.update(_pose([0.001, 0, 0], [0.002, 0, 0]), True)
    np.testing.assert_allclose(twist[:3], 2.0 * R @ [0.1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(twist[3:], R @ [0.2, 0, 0], atol=1e-12)


def test_the_clutch_lets_the_master_recentre_without_moving_the_slave():
    ms = MasterSlave(dt=0.01)
    ms.update(_pose([0, 0, 0]), True)
    assert not ms.update(_pose([0.5, 0, 0]), False).any()  # released: re-centred far away
    assert not ms.engaged
    assert not ms.update(_pose([0.5, 0, 0]), True).any()  # engaged again: counts from here
    np.testing.assert_allclose(ms.update(_pose([0.501, 0, 0]), True)[:3], [0.1, 0, 0])


@pytest.mark.parametrize(("kwargs", "argument"), [
    ({"scale": 0.0}, "scale"), ({"rotation": np.ones((3, 3))}, "rotation"), ({"dt": -1.0}, "dt"),
])  # fmt: skip
def test_bad_settings_name_the_argument(kwargs, argument):
    with pytest.raises(InvalidInput, match=f"^{argument}"):
        MasterSlave(**kwargs)


def test_a_bad_master_pose_changes_nothing():
    ms = MasterSlave(dt=0.01)
    ms.update(_pose([0, 0, 0]), True)
    with pytest.raises(InvalidInput, match="^master"):
        ms.update(np.full((4, 4), np.nan), True)
    np.testing.assert_allclose(ms.update(_pose([0.001, 0, 0]), True)[:3], [0.1, 0, 0])
