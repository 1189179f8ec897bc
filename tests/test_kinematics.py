"""Kinematics and Layout: the frames' reach, the unit of their linear rows."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.kinematics import MIN_REACH, Kinematics, Layout, reach
from rrc_pin.robot import PIN_REFERENCE, frame_index


def test_a_floating_robots_frames_reach_at_least_its_longest_chain():
    """On the tripod's free-flyer the body frame's own chain has no length: its reach would be
    MIN_REACH (0.01 m), its linear rows 100 times its angular ones. Every frame of a floating
    robot reaches at least its longest chain (the legs', 1.99 m)."""
    tripod = rrc_pin.load("yeh_tripod")
    ids = frame_index(tripod.model)
    assert reach(tripod.model, ids["body"]) == MIN_REACH
    layout = Layout.of(tripod)
    longest = max(reach(tripod.model, i) for i in ids.values())
    assert longest == pytest.approx(1.987, abs=1e-3)
    assert layout.reach["body"] == longest
    assert all(layout.reach[f] == longest for f in tripod.tool_frames)


def test_a_fixed_robots_frames_keep_their_own_chains_length():
    panda = rrc_pin.load("panda")
    layout = Layout.of(panda)
    ids = frame_index(panda.model)
    for frame in (panda.tool_frame, "panda_link3"):
        assert layout.reach[frame] == reach(panda.model, ids[frame])
    assert layout.reach[panda.tool_frame] > layout.reach["panda_link3"] > MIN_REACH


@pytest.mark.parametrize("order", ["jacobians first", "poses first"])
def test_several_frames_jacobians_and_poses_are_pinocchios_full_pass(order, rng):
    """Two hands' Jacobians (the first by computeFrameJacobian, the second after
    computeJointJacobians) and poses of the hands and of a frame no Jacobian placed, in either
    order, equal Pinocchio's full pass: every joint's Jacobian and every frame's pose."""
    baxter = rrc_pin.load("baxter")
    layout = Layout.of(baxter)
    left, right = baxter.tool_frames
    other = "head"
    q = rng.uniform(baxter.lower, baxter.upper)
    kin = Kinematics(baxter.model, baxter.model.createData(), layout, q, q)
    jacobians = [(left, "world_aligned"), (right, "world_aligned"), (right, "local")]
    poses = [left, right, other]
    if order == "jacobians first":
        got_J = [kin.jacobian(f, ref) for f, ref in jacobians]
        got_T = [kin.pose(f) for f in poses]
    else:
        got_T = [kin.pose(f) for f in poses]
        got_J = [kin.jacobian(f, ref) for f, ref in jacobians]
    model, data = baxter.model, baxter.model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    for (frame, ref), J in zip(jacobians, got_J, strict=True):
        want = pin.getFrameJacobian(model, data, layout.frames[frame], PIN_REFERENCE[ref])
        np.testing.assert_allclose(J, want, rtol=0, atol=1e-12)
    for frame, T in zip(poses, got_T, strict=True):
        want = data.oMf[layout.frames[frame]].homogeneous
        np.testing.assert_allclose(T, want, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(kin.data.oMf[layout.frames[other]].homogeneous, got_T[2])
