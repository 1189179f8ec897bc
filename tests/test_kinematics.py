"""Kinematics and Layout: the frames' reach, the unit of their linear rows."""

from __future__ import annotations

import pytest

import rrc_pin
from rrc_pin.kinematics import MIN_REACH, Layout, reach
from rrc_pin.robot import frame_index


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
