"""The console's loop on a cell: one CellController at 1 kHz, fed only through the mailbox."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.cells.closure import ClosureBound
from rrc_pin.console import commands as cmd
from rrc_pin.console.cell_loop import NO_STRATEGY, CellLoop, loop_of
from rrc_pin.console.loop import ControlLoop
from rrc_pin.errors import InvalidInput

RATE = 1000.0
UP = np.array([0.0, 0.0, 0.02, 0.0, 0.0, 0.0])
"""A twist [m/s, rad/s]: 20 mm/s up, base axes."""


class Watch:
    """Ticks a cell loop on a clock of its period, checking the cell's safety at every tick.

    Every tick: q inside the position limits, the rates applied (the chains' correction
    included) within the velocity limits, and the closed chains within their bound (none
    lost).
    """

    def __init__(self, loop: CellLoop) -> None:
        self.loop = loop
        self.t = 0.0
        cell = loop.robot
        self.lower, self.upper = cell.lower, cell.upper
        self.limit = np.asarray(cell.velocity_limit)
        self.bound = ClosureBound()

    def run(self, ticks: int) -> None:
        loop = self.loop
        for _ in range(ticks):
            snap = loop.tick(self.t)
            self.t += loop.dt
            q = loop.ctl.q
            assert np.all(q >= self.lower - 1e-12) and np.all(q <= self.upper + 1e-12), q
            if snap.resolution is not None:
                rates = np.abs(snap.resolution.applied)
                assert np.all(rates <= self.limit * (1 + 1e-9)), (rates / self.limit).max()
            position, rotation = loop.cell_ctl.chain_error
            assert position <= self.bound.position and rotation <= self.bound.rotation
            assert snap.lost is None and loop.cell_ctl.lost is None

    def pose(self) -> np.ndarray:
        return self.loop.robot_pose()


def test_a_cell_is_driven_by_one_cell_controller_naming_what_it_commands(dual, tripod):
    """gsfc_dual commands its held object, yeh_tripod its body (the names the cell's
    controller takes); the console picks the cell's loop for a cell, the arm's for an arm."""
    for cell, names in ((dual, ("object",)), (tripod, ("body",))):
        loop = loop_of(cell, rate=RATE)
        assert isinstance(loop, CellLoop) and loop.dt == pytest.approx(1e-3, abs=1e-15)
        assert loop.hands == names and loop.snapshot.name == names[0]
        assert loop.snapshot.hand == names[0]  # the commanded frame
        assert loop.cell_ctl.dt == pytest.approx(1e-3, abs=1e-15)
        assert loop.strategies == () and loop.snapshot.strategy == NO_STRATEGY
    arm = loop_of(rrc_pin.load("panda"), rate=RATE)
    assert type(arm) is ControlLoop and arm.snapshot.name == arm.snapshot.hand


@pytest.mark.parametrize("name", ["gsfc_dual", "yeh_tripod"])
def test_the_commanded_frame_moves_at_1_khz_inside_the_limits_with_chains_held(name, request):
    cell = request.getfixturevalue("dual" if name == "gsfc_dual" else "tripod")
    loop = CellLoop(cell, rate=RATE)
    watch = Watch(loop)
    start = watch.pose()
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(UP, "world_aligned"))
    watch.run(500)  # 0.5 s at 20 mm/s: 10 mm up
    d = watch.pose()[:3, 3] - start[:3, 3]
    assert d[2] == pytest.approx(0.01, rel=0.05) and np.linalg.norm(d[:2]) < 5e-4
    snap = loop.snapshot
    assert snap.mode == "teleop" and snap.enabled and snap.resolution is not None
    assert snap.resolution.status in ("exact", "scaled")


def test_stop_holds_the_cell_at_the_next_tick_ahead_of_the_queue(dual):
    """STOP, behind other commands of the same tick, commands the cell still at that very
    tick: the object's frame moves less than 1 um over each tick after it (the targets' pull
    only), against 20 um per tick before."""
    loop = CellLoop(dual, rate=RATE)
    watch = Watch(loop)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(UP, "world_aligned"))
    watch.run(200)
    loop.mailbox.post(cmd.Velocity(2 * UP, "world_aligned"))
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Stop())  # behind commands in the same tick: the STOP wins
    ticks = loop.clock.ticks
    before = watch.pose()[:3, 3]
    watch.run(1)
    assert loop.halted == ticks
    assert np.linalg.norm(watch.pose()[:3, 3] - before) < 1e-6
    assert not loop.snapshot.enabled and not loop.operator.latched
    for _ in range(50):
        before = watch.pose()[:3, 3]
        watch.run(1)
        assert np.linalg.norm(watch.pose()[:3, 3] - before) < 1e-6


def test_a_released_deadman_fades_the_cells_command_then_holds_it(tripod):
    """The controller's deadman at 1 kHz: the command holds 0.2 s, fades over 0.3 s, then the
    body is still."""
    loop = CellLoop(tripod, rate=RATE)
    watch = Watch(loop)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(UP, "world_aligned"))
    watch.run(100)
    loop.mailbox.post(cmd.Latch(False))
    start = watch.pose()[:3, 3]
    watch.run(600)
    faded = np.linalg.norm(watch.pose()[:3, 3] - start)
    assert 0.004 < faded < 0.008  # 4 mm in 0.2 s, 3 mm at most over the fade
    still = watch.pose()[:3, 3]
    watch.run(50)
    assert np.linalg.norm(watch.pose()[:3, 3] - still) < 1e-6 and not loop.snapshot.enabled


def test_a_device_stream_moves_the_body_behind_the_deadman(tripod):
    """A device's poses stream to the body: clutched (still) while the deadman is released;
    latched, the body follows the device's 5 mm up; STOP ends the stream."""
    loop = CellLoop(tripod, rate=RATE)
    watch = Watch(loop)
    start = watch.pose()
    up = np.eye(4)
    up[2, 3] = 0.005
    for _ in range(10):
        loop.mailbox.post(cmd.Pose(up if _ % 2 else np.eye(4)))
        watch.run(10)  # the deadman released: clutched, nothing moves
    assert "body" in loop.ctl.streams and loop.snapshot.mode == "stream"
    assert np.linalg.norm(watch.pose()[:3, 3] - start[:3, 3]) < 1e-9
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Pose(np.eye(4)))
    watch.run(10)  # the device re-anchored at the body on the clutch's release
    for _ in range(50):
        loop.mailbox.post(cmd.Pose(up))
        watch.run(10)
    d = watch.pose()[:3, 3] - start[:3, 3]
    assert d[2] == pytest.approx(0.005, abs=5e-4) and np.linalg.norm(d[:2]) < 5e-4
    assert loop.snapshot.enabled
    loop.mailbox.post(cmd.Stop())
    watch.run(1)
    assert loop.ctl.streams == {}


def test_a_lost_grip_holds_the_cell_releases_the_deadman_and_is_shown(dual):
    """A bound tighter than a tick's remainder (at 100 Hz: at 1 kHz the chain stays closed to
    rounding): the cell holds at that tick and after, the operator's deadman is released, one
    notice names ``grip_lost`` and the snapshot shows it while it lasts; latched again, a
    command closes the chain and the status clears."""
    loop = CellLoop(dual, rate=100.0)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(5 * UP, "world_aligned"))
    t = 0.0
    for _ in range(20):
        loop.tick(t)
        t += loop.dt
    loop.cell_ctl.closure = ClosureBound(1e-12, 1e-12)  # tighter than a tick's remainder
    q = loop.ctl.q.copy()
    snap = loop.tick(t)
    assert snap.lost == "grip_lost" and snap.resolution.status == "grip_lost"
    np.testing.assert_array_equal(loop.ctl.q, q)
    assert not loop.operator.latched and loop.notices[-1].text.startswith("grip_lost")
    for _ in range(5):
        snap = loop.tick(t)
        np.testing.assert_array_equal(loop.ctl.q, q)
    assert snap.lost == "grip_lost"
    assert sum(n.text.startswith("grip_lost") for n in loop.notices) == 1
    open_ = max(loop.cell_ctl.chain_error)
    loop.cell_ctl.closure = ClosureBound(open_ / 4, open_ / 4)
    loop.mailbox.post(cmd.Latch(True))  # the operator commands it closed again
    loop.mailbox.post(cmd.Velocity(0.5 * UP, "world_aligned"))
    for _ in range(3):
        snap = loop.tick(t)
    assert snap.lost is None and max(loop.cell_ctl.chain_error) < open_ / 4
    assert snap.enabled and np.max(np.abs(loop.ctl.q - q)) > 0.0


def test_what_a_cell_does_not_take_is_refused_by_name(dual):
    loop = CellLoop(dual, rate=RATE)
    for c in (cmd.Strategy("jacobian_transpose"), cmd.Load("record.csv"), cmd.Hand("left")):
        loop.mailbox.post(c)
    loop.tick(0.0)
    errors = [n.text for n in loop.notices if n.level == "error"]
    assert len(errors) == 3
    assert "gsfc_dual is a cell" in errors[0] and "strategy" in errors[0]
    assert "gsfc_dual is a cell" in errors[1] and "replaying" in errors[1]
    assert "hand" in errors[2] and "object" in errors[2]
    with pytest.raises(InvalidInput, match="strategy"):
        CellLoop(dual, strategy="jacobian_transpose")
    with pytest.raises(InvalidInput, match="cell"):
        CellLoop(rrc_pin.load("panda"))


def test_a_cells_record_reverses_to_its_start_and_saves(dual, tmp_path):
    loop = CellLoop(dual, rate=RATE)
    watch = Watch(loop)
    loop.mailbox.post(cmd.Record(True))
    watch.run(1)
    start = loop.ctl.q.copy()
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(UP, "world_aligned"))
    watch.run(200)
    loop.mailbox.post(cmd.Stop())
    watch.run(1)
    replies = []
    loop.mailbox.post(cmd.Save(str(tmp_path / "cell.csv"), lambda p, e: replies.append((p, e))))
    watch.run(1)
    _finished(loop, 30.0)
    watch.run(1)
    assert replies and replies[0][1] == "" and (tmp_path / "cell.csv").stat().st_size > 0
    seconds = len(loop.ctl.log) * loop.dt - 0.002  # back to the record's first tick
    loop.mailbox.post(cmd.Reverse(seconds))
    watch.run(1)
    _finished(loop, 60.0)
    while loop._job is not None or loop._playback:
        watch.run(1)
        assert loop.snapshot.mode in ("held", "reverse")
    assert np.max(np.abs(loop.ctl.q - start)) < 1e-4
    assert loop.notices[-1].text.startswith("reversed")


def _finished(loop: CellLoop, seconds: float) -> None:
    """Wait up to ``seconds`` for the loop's job (a save, a reverse), if it is still running:
    a quick one is done and gone by the tick after it was posted."""
    job = loop._job
    if job is not None:
        job.done.wait(seconds)


def test_backend_switch_and_home_keep_the_cells_controller(dual):
    loop = CellLoop(dual, rate=RATE)
    watch = Watch(loop)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(UP, "world_aligned"))
    watch.run(50)
    other = next((b for b in loop.backends if b != "daqp"), "daqp")
    loop.mailbox.post(cmd.Backend(other))
    watch.run(50)
    assert loop.snapshot.backend == other and loop.ctl.resolver.qp.backend == other
    assert loop.ctl.resolver.options.damping is not None
    loop.mailbox.post(cmd.Home())
    watch.run(1)
    np.testing.assert_allclose(loop.ctl.q, loop.start_q, atol=1e-12)


def test_a_cell_of_free_hands_switches_the_commanded_name_and_holds_the_other():
    """Two free pandas: the controls move arm a's hand; switched to b (between ticks), a is
    held still from the next tick (under 1 um per tick) while b moves."""
    from rrc_pin.cells import make_cell

    panda = rrc_pin.load("panda")
    T = np.eye(4)
    T[1, 3] = 1.0
    loop = CellLoop(make_cell({"a": (panda, np.eye(4)), "b": (panda, T)}, name="pair"),
                    rate=RATE)  # fmt: skip
    assert loop.hands == ("a", "b")
    watch = Watch(loop)
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(UP, "world_aligned"))
    watch.run(100)
    hand_a = loop.robot.fk(loop.ctl.q, loop.cell_ctl.frame_of("a"))[:3, 3]
    loop.mailbox.post(cmd.Hand("b"))
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Velocity(UP, "world_aligned"))
    start_b = loop.robot.fk(loop.ctl.q, loop.cell_ctl.frame_of("b"))
    assert loop.snapshot.name == "a"
    watch.run(1)
    assert loop.snapshot.name == "b" and loop.snapshot.hand == loop.cell_ctl.frame_of("b")
    for _ in range(100):
        before = loop.robot.fk(loop.ctl.q, loop.cell_ctl.frame_of("a"))[:3, 3]
        watch.run(1)
        after = loop.robot.fk(loop.ctl.q, loop.cell_ctl.frame_of("a"))[:3, 3]
        assert np.linalg.norm(after - before) < 1e-6
    assert np.linalg.norm(after - hand_a) < 1e-4
    assert watch.pose()[2, 3] - start_b[2, 3] == pytest.approx(0.002, rel=0.1)


def test_the_target_gizmo_servoes_the_object(dual):
    loop = CellLoop(dual, rate=RATE)
    watch = Watch(loop)
    goal = watch.pose().copy()
    goal[2, 3] += 0.005
    loop.mailbox.post(cmd.Latch(True))
    loop.mailbox.post(cmd.Target(goal))
    watch.run(3000)  # 2/s: e^-6 of 5 mm left after 3 s
    assert loop.snapshot.mode == "target"
    assert np.linalg.norm(watch.pose()[:3, 3] - goal[:3, 3]) < 5e-5
