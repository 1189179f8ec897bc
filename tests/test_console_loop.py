"""The control loop: commands in through the mailbox, the controller stepped, state out."""

from __future__ import annotations

import time

import numpy as np
import pytest

import rrc_pin
from rrc_pin.console import commands as cmd
from rrc_pin.console.loop import ControlLoop, start_pose
from rrc_pin.control.synthetic_stream import device_pose, synthetic_stream
from rrc_pin.errors import InvalidInput


@pytest.fixture(scope="module")
def barker6():
    return rrc_pin.load("barker6")


@pytest.fixture(scope="module")
def panda():
    return rrc_pin.load("panda")


def run(loop: ControlLoop, ticks: int, t0: float = 0.0) -> float:
    """Tick ``ticks`` times on a clock of the loop's period; returns the next time."""
    t = t0
    for _ in range(ticks):
        loop.tick(t)
        t += loop.dt
    return t


def moved(loop: ControlLoop, ticks: int, *commands: cmd.Command) -> np.ndarray:
    """The hand's displacement [m] (base axes) over ``ticks`` ticks after ``commands``."""
    before = loop.robot_pose()[:3, 3]
    for c in commands:
        loop.mailbox.post(c)
    run(loop, ticks)
    return loop.robot_pose()[:3, 3] - before


def along(d: np.ndarray, axis: np.ndarray) -> float:
    return float(d @ axis / np.linalg.norm(d))


@pytest.mark.parametrize("name", ["barker6", "panda"])
def test_the_hand_moves_along_the_commanded_axis(name, request):
    loop = ControlLoop(request.getfixturevalue(name), rate=100.0)
    R = loop.robot_pose()[:3, :3]
    d = moved(loop, 50, cmd.Latch(True), cmd.Velocity(np.array([0, 0, 0.04, 0, 0, 0]), "local"))
    assert along(d, R[:, 2]) > 0.999  # hand z
    assert np.linalg.norm(d) == pytest.approx(0.02, rel=0.05)  # 0.04 m/s for 0.5 s
    d = moved(loop, 50, cmd.Velocity(np.array([0, -0.04, 0, 0, 0, 0]), "world_aligned"))
    assert along(d, np.array([0.0, -1.0, 0.0])) > 0.999  # base -y
    snap = loop.snapshot
    assert snap.enabled and snap.mode == "teleop" and snap.resolution is not None


def test_released_deadman_fades_the_command_and_stop_is_immediate(barker6):
    loop = ControlLoop(barker6, rate=100.0)
    assert loop.halted == -1
    moved(loop, 20, cmd.Latch(True), cmd.Velocity(np.array([0.04, 0, 0, 0, 0, 0])))
    d = moved(loop, 100, cmd.Latch(False))  # the controller's deadman: 0.2 s, then a 0.3 s fade
    assert 0.004 < np.linalg.norm(d) < 0.02
    assert np.linalg.norm(moved(loop, 10)) < 1e-9 and not loop.snapshot.enabled
    moved(loop, 20, cmd.Latch(True), cmd.Velocity(np.array([0.04, 0, 0, 0, 0, 0])))
    loop.clock.tick()
    loop.mailbox.post(cmd.Latch(True))  # before the STOP in the same tick: the STOP wins
    loop.mailbox.post(cmd.Stop())
    loop.tick(10.0)  # a zero command at once: only the drift correction's pull remains
    assert loop.halted == loop.clock.ticks == 1
    assert (
        np.linalg.norm(loop.ctl.robot.jacobian(loop.ctl.q)[:3] @ loop.snapshot.resolution.qdot)
        < 1e-3
    )
    assert loop.snapshot.stops == 1 and not loop.snapshot.latched


def test_record_reverse_retraces_to_where_the_record_started(panda):
    loop = ControlLoop(panda, rate=100.0)
    loop.mailbox.post(cmd.Record(True))
    run(loop, 1)
    start = loop.ctl.q.copy()
    moved(loop, 60, cmd.Latch(True), cmd.Velocity(np.array([0.05, 0.02, 0, 0, 0, 0.2])))
    loop.mailbox.post(cmd.Reverse(0.61))
    t = run(loop, 1)
    deadline = time.perf_counter() + 10.0
    while loop.snapshot.mode == "held" and time.perf_counter() < deadline:  # the worker
        time.sleep(0.005)
        t = run(loop, 1, t)
    modes = [loop.snapshot.mode]
    for _ in range(80):
        modes.append(loop.tick(t).mode)
        t += loop.dt
    assert modes.count("reverse") == 61
    assert np.max(np.abs(loop.ctl.q - start)) < 1e-9
    assert loop.snapshot.q is loop.ctl.q
    assert any("reversed" in n.text for n in loop.notices)


def test_reverse_and_save_need_a_record(barker6):
    loop = ControlLoop(barker6, rate=100.0)
    loop.mailbox.post(cmd.Reverse(1.0))
    loop.mailbox.post(cmd.Save("x.csv"))
    run(loop, 1)
    assert [n.level for n in loop.notices] == ["error", "error"]
    loop.mailbox.post(cmd.Record(True))
    run(loop, 5)
    loop.mailbox.post(cmd.Reverse(1.0))
    run(loop, 1)
    assert "the record holds" in loop.notices[-1].text


def test_save_then_load_replays_the_recorded_commands(barker6, tmp_path):
    loop = ControlLoop(barker6, rate=100.0)
    loop.mailbox.post(cmd.Record(True))
    run(loop, 1)
    moved(
        loop,
        40,
        cmd.Latch(True),
        cmd.Velocity(np.array([0.03, 0, -0.02, 0.1, 0, 0]), "world_aligned"),
    )
    moved(loop, 1, cmd.Latch(False))
    recorded = np.array(loop.ctl.log.column("q"))
    replies = []
    for suffix in (".csv", ".npz"):
        loop.mailbox.post(
            cmd.Save(str(tmp_path / f"run{suffix}"), lambda p, e: replies.append((p, e)))
        )
        t = run(loop, 1)
        while loop.snapshot.mode == "held":
            time.sleep(0.005)
            t = run(loop, 1, t)
        assert replies[-1] == (tmp_path / f"run{suffix}", "")
    loop.mailbox.post(cmd.Record(False))
    loop.mailbox.post(cmd.Load(str(tmp_path / "run.npz")))
    t = run(loop, 1)
    while loop.snapshot.mode == "held":
        time.sleep(0.005)
        t = run(loop, 1, t)
    replayed = [loop.ctl.q.copy()]
    while loop.snapshot.mode == "replay" or len(replayed) == 1:
        loop.tick(t)
        t += loop.dt
        replayed.append(loop.ctl.q.copy())
    replayed = np.array(replayed[: len(recorded)])
    np.testing.assert_allclose(replayed, recorded, atol=1e-6)  # teleop ticks, rounding apart
    assert "replay done" in loop.notices[-1].text


def test_load_refuses_another_arms_record(barker6, panda, tmp_path):
    other = ControlLoop(panda, rate=100.0)
    other.mailbox.post(cmd.Record(True))
    run(other, 3)
    other.ctl.log.save(tmp_path / "panda.csv")
    loop = ControlLoop(barker6, rate=100.0)
    loop.mailbox.post(cmd.Load(str(tmp_path / "panda.csv")))
    t = run(loop, 1)
    while loop.snapshot.mode == "held":
        time.sleep(0.005)
        t = run(loop, 1, t)
    assert "load failed" in loop.notices[-1].text and "panda_joint1" in loop.notices[-1].text
    assert loop.snapshot.mode == "teleop"


def test_strategies_and_backends_switch_or_are_refused_with_a_notice(barker6, panda):
    loop = ControlLoop(panda, rate=100.0)
    assert loop.strategies == ("resolver", "slowdown")
    loop.mailbox.post(cmd.Strategy("freezing"))
    loop.mailbox.post(cmd.Backend("no-such-qp"))
    loop.mailbox.post(cmd.Backend("osqp"))
    loop.mailbox.post(cmd.Strategy("slowdown"))
    run(loop, 1)
    assert [n.level for n in loop.notices] == ["error", "error"]
    assert (loop.snapshot.backend, loop.snapshot.strategy) == ("osqp", "slowdown")
    assert loop.ctl.resolver.qp.backend == "osqp"
    d = moved(
        loop, 20, cmd.Latch(True), cmd.Velocity(np.array([0, 0, 0.04, 0, 0, 0]), "world_aligned")
    )
    assert along(d, np.array([0.0, 0.0, 1.0])) > 0.999
    barker = ControlLoop(barker6, rate=100.0, strategy="freezing")
    assert "freezing" in barker.strategies and barker.ctl.strategy.name == "freezing"
    with pytest.raises(InvalidInput, match="strategy"):
        ControlLoop(panda, strategy="freezing_nope")
    with pytest.raises(InvalidInput, match="robot"):
        ControlLoop("panda")
    with pytest.raises(InvalidInput, match="priority"):
        ControlLoop(panda, priority=1.5)
    with pytest.raises(InvalidInput, match="rate"):
        ControlLoop(panda, rate=float("nan"))


def test_a_robot_with_two_hands_commands_the_chosen_one():
    baxter = rrc_pin.load("baxter")
    loop = ControlLoop(baxter, rate=100.0)
    assert loop.hands == ("left_gripper", "right_gripper")
    right = baxter.fk(loop.ctl.q, "right_gripper")[:3, 3]
    loop.mailbox.post(cmd.Hand("right_gripper"))
    run(loop, 1)
    assert loop.snapshot.hand == "right_gripper"
    moved(loop, 30, cmd.Latch(True), cmd.Velocity(np.array([0, 0, 0.04, 0, 0, 0]), "world_aligned"))
    d = baxter.fk(loop.ctl.q, "right_gripper")[:3, 3] - right
    assert along(d, np.array([0.0, 0.0, 1.0])) > 0.999
    loop.mailbox.post(cmd.Record(True))
    loop.mailbox.post(cmd.Hand("left_gripper"))
    loop.mailbox.post(cmd.Hand("head"))
    run(loop, 1)
    assert "while recording" in loop.notices[-2].text and "hand" in loop.notices[-1].text


def test_a_failing_tick_stops_the_arm_and_the_loop_goes_on(barker6, monkeypatch):
    loop = ControlLoop(barker6, rate=200.0)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(np.array([0.02, 0, 0, 0, 0, 0])))
    real = loop.ctl.step
    calls = []

    def flaky(*args, **kwargs):
        calls.append(1)
        if len(calls) == 5:
            raise RuntimeError("a bug in a tick")
        return real(*args, **kwargs)

    monkeypatch.setattr(loop.ctl, "step", flaky)
    loop.start()
    time.sleep(0.3)
    loop.stop()
    assert not loop.alive
    assert loop.errors == 1 and "a bug in a tick" in loop.notices[-1].text
    assert len(calls) > 20 and loop.clock.ticks > 20
    assert loop.operator.stops == 1 and not loop.snapshot.enabled
    assert np.all(np.isfinite(loop.ctl.q))


def test_a_full_record_holds_the_arm(barker6):
    loop = ControlLoop(barker6, rate=100.0, record_limit=0.1)
    loop.mailbox.post(cmd.Record(True))
    moved(loop, 15, cmd.Latch(True), cmd.Velocity(np.array([0.02, 0, 0, 0, 0, 0])))
    q = loop.ctl.q
    run(loop, 5)
    assert loop.ctl.q is q and loop.snapshot.mode == "held"
    assert "record full" in loop.notices[-1].text
    loop.mailbox.post(cmd.Record(False))
    moved(loop, 5, cmd.Latch(True), cmd.Velocity(np.array([0.02, 0, 0, 0, 0, 0])))
    assert loop.snapshot.mode == "teleop" and len(loop.ctl.log) == 0


def test_home_puts_the_arm_back_at_its_start(barker6):
    loop = ControlLoop(barker6, rate=100.0)
    moved(loop, 20, cmd.Latch(True), cmd.Velocity(np.array([0.02, 0, 0, 0, 0, 0.1])))
    loop.mailbox.post(cmd.Home())
    run(loop, 1)
    np.testing.assert_allclose(loop.ctl.q, loop.start_q)
    assert loop.snapshot.stops == 1


@pytest.mark.parametrize("name", ["barker6", "rrc_k1607", "kr5_3r", "panda", "ur5", "kinova"])
def test_start_pose_is_inside_the_limits(name):
    robot = rrc_pin.load(name)
    q = start_pose(robot)
    assert np.all(q >= robot.lower) and np.all(q <= robot.upper)
    J = robot.jacobian(q)[: 6 if robot.nq >= 6 else 3]
    assert np.linalg.svd(J, compute_uv=False)[-1] > 0.02  # away from singularities


def test_a_realtime_loop_runs_under_fifo_or_says_why_not(barker6):
    loop = ControlLoop(barker6, rate=500.0, realtime=True)
    loop.start()
    time.sleep(0.2)
    loop.stop()
    refused = [n for n in loop.notices if "real-time scheduling refused" in n.text]
    assert loop.scheduling == "SCHED_FIFO 10" or (refused and loop.scheduling != "not started")
    assert loop.clock.ticks > 20


def test_a_record_is_full_at_the_logs_capacity_too(barker6):
    loop = ControlLoop(barker6, rate=100.0)  # record_limit 120 s: the log's ring is shorter
    loop.ctl.log.capacity = 10
    loop.mailbox.post(cmd.Record(True))
    moved(loop, 15, cmd.Latch(True), cmd.Velocity(np.array([0.02, 0, 0, 0, 0, 0])))
    assert loop.snapshot.mode == "held" and "record full (0.1 s)" in loop.notices[-1].text


def stream_into(loop: ControlLoop, recording, ticks: int, t0: float, clutch=lambda t: False):
    """Post the recording's samples due by each tick as Pose commands, then tick; the hand's
    positions and the stream's targets of the clean device 0.1 s before (NaN: no stream)."""
    hands, expected, k = [], [], int(np.searchsorted(recording.times, t0))
    for i in range(ticks):
        t = t0 + i * loop.dt
        while k < len(recording.times) and recording.times[k] <= t + 1e-9:
            loop.mailbox.post(cmd.Pose(recording.poses[k], clutch(t)))
            k += 1
        loop.tick(t)
        stream = loop.ctl.streams.get(loop.snapshot.hand)
        hands.append(loop.robot_pose()[:3, 3])
        clean = device_pose(max(t - 0.1, 0.0))
        expected.append(np.full(3, np.nan) if stream is None else stream.target_for(clean)[:3, 3])
    return np.array(hands), np.array(expected)


def test_a_device_pose_stream_drives_the_hand_behind_the_deadman_and_stop(panda):
    """Pose commands at 90 Hz (0.5 mm noise) into the 100 Hz loop, the deadman latched: the
    hand follows the device 0.1 s behind within 3 mm (measured 1.6 mm); the deadman released
    holds it (clutched: still to 1e-4 m once it has reached its target) and latched again it
    follows on with no step; the device's clutch holds it likewise; STOP ends the stream and
    stops the arm, and the next sample opens a new stream where the hand is (no jump); an
    empty pose ends it."""
    loop = ControlLoop(panda, rate=100.0)
    recording = synthetic_stream(8.0, 90.0, seed=3)
    loop.mailbox.post(cmd.Latch(True))
    hands, expected = stream_into(loop, recording, 200, 0.0)
    error = np.linalg.norm(hands - expected, axis=1)[50:]
    assert error.max() < 3e-3 and loop.snapshot.mode == "stream" and loop.snapshot.enabled
    loop.mailbox.post(cmd.Latch(False))
    hands, _ = stream_into(loop, recording, 100, 2.0)
    assert np.ptp(hands[50:], axis=0).max() < 1e-4 and not loop.snapshot.enabled
    loop.mailbox.post(cmd.Latch(True))
    hands, _ = stream_into(loop, recording, 100, 3.0)
    steps = np.linalg.norm(np.diff(hands, axis=0), axis=1)
    assert steps.max() < 0.5 * loop.dt  # under 0.5 m/s (the stream's clamp): no jump
    hands, _ = stream_into(loop, recording, 100, 4.0, clutch=lambda t: t >= 4.0)
    assert np.ptp(hands[50:], axis=0).max() < 1e-4
    loop.mailbox.post(cmd.Stop())
    loop.tick(5.0)
    assert loop.ctl.streams == {} and loop.snapshot.stops == 1
    held = loop.robot_pose()[:3, 3]
    loop.mailbox.post(cmd.Latch(True))
    hands, _ = stream_into(loop, recording, 50, 5.01)
    assert np.linalg.norm(hands[0] - held) < 1e-9  # from where it stopped, with no jump
    assert np.linalg.norm(np.diff(hands, axis=0), axis=1).max() < 0.5 * loop.dt
    loop.mailbox.post(cmd.Pose(None))
    loop.tick(5.6)
    assert loop.ctl.streams == {} and loop.snapshot.mode == "teleop"
