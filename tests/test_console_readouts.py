"""Readouts: joints against their limits, the singularity near, the resolver's answer."""

from __future__ import annotations

import re

import numpy as np
import pytest

import rrc_pin
from rrc_pin.console import commands as cmd
from rrc_pin.console.loop import ControlLoop
from rrc_pin.console.rate import PeriodStats
from rrc_pin.console.readouts import (
    AMBER,
    GREEN,
    RED,
    Reader,
    joint_color,
    joints_html,
    nearness,
    status_html,
)


def test_nearness_and_colours():
    assert nearness(0.0, -1.0, 1.0) == pytest.approx(0.5)
    assert nearness(0.95, -1.0, 1.0) == pytest.approx(0.025)
    assert nearness(0.3, -np.inf, np.inf) == np.inf
    assert [joint_color(f) for f in (0.01, 0.07, 0.3)] == [RED, AMBER, GREEN]


def test_joint_rows_turn_red_near_a_limit():
    arm = rrc_pin.load("barker6")
    q = np.zeros(6)
    q[3] = arm.upper[3] - 0.02 * (arm.upper[3] - arm.lower[3])  # 2 % of its range from the top
    out = joints_html(arm, q, np.zeros(6))
    near = re.findall(r'data-joint="(\w+)" data-near="(\d)"', out)
    assert near == [(f"joint{i}", "1" if i == 4 else "0") for i in range(1, 7)]


def test_barker6_names_its_wrist_singularity_and_sigma_min_falls():
    arm = rrc_pin.load("barker6")
    loop = ControlLoop(arm, rate=100.0, q0=[0.35, -0.2, 0.9, 0.17, 1e-4, 0.0])  # theta5 ~ 0
    loop.tick(0.0)
    reader = Reader(arm)
    snap = loop.snapshot
    readings = reader.read(snap, arm.fk(snap.q))
    assert readings.singularity == "wrist (S5 = 0)"
    assert readings.sigma_min < 1e-3
    away = ControlLoop(arm, rate=100.0)
    away.tick(0.0)
    assert reader.read(away.snapshot, arm.fk(away.snapshot.q)).singularity == ""


def test_commanded_and_achieved_twists_in_base_axes():
    arm = rrc_pin.load("panda")
    loop = ControlLoop(arm, rate=100.0)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Speed(0.5))
    loop.mailbox.post(cmd.Velocity(np.array([0, 0, 0.04, 0, 0, 0]), "local"))
    loop.tick(0.0)
    snap = loop.snapshot
    readings = Reader(arm).read(snap, arm.fk(snap.q))
    R = arm.fk(snap.q)[:3, :3]
    np.testing.assert_allclose(readings.commanded[:3], 0.02 * R[:, 2], atol=1e-12)
    # achieved at the tick's start q: the command at half speed, to the drift correction
    assert np.linalg.norm(readings.achieved[:3] - readings.commanded[:3]) < 2e-3


def test_status_block_names_every_field():
    arm = rrc_pin.load("barker6")
    loop = ControlLoop(arm, rate=100.0)
    loop.tick(0.0)
    snap = loop.snapshot
    out = status_html(
        snap,
        Reader(arm).read(snap, arm.fk(snap.q)),
        PeriodStats(10, 0.01, 0.012, 0.02),
        100.0,
        "saved x.csv",
    )
    fields = dict(re.findall(r'data-field="(\w+)"[^>]*>([^<]*)<', out))
    assert fields["deadman"] == "released" and fields["status"] == "exact"
    assert fields["singularity"] == "none" and fields["active"] == "none"
    assert fields["loop"] == "100 Hz: period median 10.00 ms, p99 12.00 ms"
    assert fields["notice"] == "saved x.csv"
    assert "lost" not in fields and fields["hand"] == arm.tool_frames[0]


def test_a_cells_status_names_what_is_commanded_and_a_lost_chain_in_red():
    """gsfc_dual: the hand field names the held object, the readings are its frame's (the
    commanded 20 mm/s up achieved within 1e-5 m/s); a lost grip is a red field."""
    from rrc_pin.console.cell_loop import CellLoop

    cell = rrc_pin.load("gsfc_dual")
    loop = CellLoop(cell, rate=1000.0)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(np.array([0, 0, 0.02, 0, 0, 0]), "world_aligned"))
    for k in range(5):
        snap = loop.tick(k * loop.dt)
    readings = Reader(cell).read(snap, loop.robot_pose())
    np.testing.assert_allclose(readings.achieved[:3], [0, 0, 0.02], atol=1e-5)
    stats = PeriodStats(10, 0.001, 0.0012, 0.002)
    fields = dict(re.findall(r'data-field="(\w+)"[^>]*>([^<]*)<',
                             status_html(snap, readings, stats, 1000.0)))  # fmt: skip
    assert fields["hand"] == "object" and "lost" not in fields and fields["strategy"] == "none"
    out = status_html(snap._replace(lost="grip_lost"), readings, stats, 1000.0)
    assert f'data-field="lost" style="color:{RED}">grip_lost<' in out
