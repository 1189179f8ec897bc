"""The teleoperation controller (issue 8): frames, one-step order, reverse, sessions, deadman,
speed override, margins, bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from device_replay import DT, SECONDS, Replay

import rrc_pin
from rrc_pin.control import Controller, Deadman, DriftCorrection
from rrc_pin.control.controller import _checked_twist, active_codes
from rrc_pin.control.random_operator import random_commands
from rrc_pin.control.smoothing import SmoothingOptions
from rrc_pin.control.strategies import Decision, ResolverOnly, Situation, Strategy
from rrc_pin.control.strategies.base import KEEP

BARKER_Q0 = np.deg2rad([20.0, 30.0, 60.0, 10.0, 40.0, 0.0])
PANDA_Q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.7])
START = {"barker6": BARKER_Q0, "panda": PANDA_Q0}


def start(name: str) -> np.ndarray:
    arm = rrc_pin.load(name)
    return START.get(name, arm.neutral())


@pytest.fixture(scope="module")
def barker():
    return rrc_pin.load("barker6")


@pytest.fixture(scope="module")
def panda():
    return rrc_pin.load("panda")


def test_a_hand_frame_command_moves_the_tool_as_the_same_command_in_base_axes(barker):
    twist = np.array([0.05, -0.02, 0.03, 0.2, -0.1, 0.3])
    local = Controller(barker, q0=BARKER_Q0, drift=None)  # one command, its two spellings
    base = Controller(barker, q0=BARKER_Q0, drift=None)
    for _ in range(20):
        R = barker.fk(base.q)[:3, :3]
        local.step(twist, "local")
        base.step(np.concatenate([R @ twist[:3], R @ twist[3:]]), "world_aligned")
        assert np.max(np.abs(local.q - base.q)) < 1e-12


@pytest.mark.parametrize("name", ["barker6", "panda"])
def test_one_step_follows_the_twist_to_second_order_in_dt(name):
    """Euler's step (Barker eq. (21)) leaves O(dt^2) of pose error: halving dt quarters it."""
    arm = rrc_pin.load(name)
    twist = np.array([0.05, -0.03, 0.04, 0.3, -0.2, 0.25])
    T0 = arm.fk(start(name))
    errors = []
    dts = [8e-3, 4e-3, 2e-3, 1e-3]
    for dt in dts:
        ctl = Controller(arm, dt=dt, q0=start(name), drift=None)
        step = ctl.step(twist, "local")
        assert step.resolution.status == "exact" and not step.resolution.active
        wanted = T0 @ pin.exp6(pin.Motion(twist[:3] * dt, twist[3:] * dt)).homogeneous
        reached = arm.fk(step.q)
        errors.append(np.linalg.norm(pin.log6(np.linalg.inv(wanted) @ reached).vector))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.1), orders


@pytest.mark.parametrize("name", ["barker6", "rrc_k1607", "kr5_3r", "panda"])
def test_reverse_returns_to_the_recorded_start(name, rng):
    arm = rrc_pin.load(name)
    ctl = Controller(arm, q0=start(name))
    q_start = ctl.q.copy()
    for twist in random_commands(rng, 2.0, ctl.dt, speed=0.03, turn=0.1, pause=0.0):
        ctl.step(twist, ref="local")
    assert not any(ctl.log.column("active"))  # no limit intervened
    moved = np.max(np.abs(ctl.q - q_start))
    result = ctl.reverse(2.0)
    assert moved > 0.05
    assert result.reached and result.steps == 200
    assert np.max(np.abs(ctl.q - q_start)) <= 1e-9
    assert set(ctl.log.column("mode")[-200:]) == {"reverse"}


def test_reverse_keeps_the_limits_when_they_intervene(panda):
    """Acceleration limits make the turn-around slower: more ticks, no excess, same start."""
    limits = rrc_pin.JointLimits(acceleration=20.0)
    ctl = Controller(panda, q0=PANDA_Q0, limits=limits)
    for _ in range(100):
        ctl.step([0.1, 0.0, 0.0, 0.0, 0.0, 0.5], ref="local")
    result = ctl.reverse(1.0)
    qdot = ctl.log.column("qdot")[-result.steps:]
    assert result.steps > 100
    assert np.all(np.abs(np.diff(qdot, axis=0)) <= 20.0 * ctl.dt * (1 + 1e-9) + 1e-12)
    assert result.reached and np.max(np.abs(ctl.q - PANDA_Q0)) <= 1e-9


@pytest.mark.parametrize("name", ["barker6", "rrc_k1607", "kr5_3r", "panda"])
def test_a_simulated_session_stays_in_the_limits_with_bounded_drift(name):
    """20 s at 100 Hz of random operator commands (benchmarks/bench_controller.py: 10 min)."""
    arm = rrc_pin.load(name)
    ctl = Controller(arm, q0=start(name))
    for twist in random_commands(np.random.default_rng(1), 20.0, ctl.dt):
        ctl.step(twist, ref="local")
    q, qdot = ctl.log.column("q"), ctl.log.column("qdot")
    assert np.isfinite(q).all() and np.isfinite(qdot).all()
    assert np.all(q >= arm.lower - 1e-12) and np.all(q <= arm.upper + 1e-12)
    assert np.all(np.abs(qdot) <= arm.velocity_limit * (1 + 1e-9))
    # Measured every tick: kr5_3r 1.2 mm (a 0.1 s sampling showed 0.48 mm of its 1.4 mm
    # peak), rrc_k1607 0.36 mm, barker6 and panda 0.25 mm.
    assert ctl.log.column("drift_position").max() < 2e-3  # [m]
    assert ctl.log.column("drift_rotation").max() < 3e-3  # [rad]


def test_drift_grows_without_the_correction_and_stays_small_with_it(barker):
    drift = {}
    for correction in (DriftCorrection(), None):
        ctl = Controller(barker, q0=BARKER_Q0, drift=correction)
        for twist in random_commands(np.random.default_rng(1), 8.0, ctl.dt):
            ctl.step(twist, ref="local")
        drift[correction is None] = ctl.log.column("drift_position")
    assert drift[False].max() < 0.5 * drift[True].max()
    assert drift[False][-100:].mean() < 0.2 * drift[True][-100:].mean()
    assert drift[True][-100:].max() > drift[True][:100].max()  # grows without correction


def test_deadman_fades_an_old_command_smoothly_to_zero(panda):
    deadman = Deadman(timeout=0.1, fade=0.2)
    ctl = Controller(panda, q0=PANDA_Q0, deadman=deadman, drift=None)
    first = ctl.step([0.05, 0.0, 0.0, 0.0, 0.0, 0.0], ref="local").resolution.qdot
    speeds = [np.linalg.norm(ctl.step().resolution.qdot) for _ in range(40)]
    ages = ctl.dt * np.arange(1, 41)
    factors = np.array([deadman.factor(a) for a in ages])
    # The rates follow the factor (the Jacobian changes little over 0.4 s).
    assert np.allclose(speeds, factors * np.linalg.norm(first), rtol=0.05, atol=1e-12)
    assert factors[9] == 1.0 and 0.0 < factors[15] < 1.0 and speeds[-1] == 0.0
    assert np.max(np.abs(np.diff(factors))) < 0.1  # no jump


def test_speed_override_scales_the_command(panda):
    full = Controller(panda, q0=PANDA_Q0)
    half = Controller(panda, q0=PANDA_Q0, speed=0.5)
    twist = [0.05, 0.02, 0.0, 0.0, 0.1, 0.0]
    assert np.allclose(half.step(twist, ref="local").resolution.qdot,
                       0.5 * full.step(twist, ref="local").resolution.qdot, atol=1e-12)
    half.speed = 0.0
    assert np.all(half.step(twist, ref="local").resolution.qdot == 0.0)


def test_joint_limit_margins_are_kept(panda):
    margin = 0.1
    ctl = Controller(panda, q0=PANDA_Q0, limits=rrc_pin.JointLimits(margin=margin))
    for _ in range(300):  # rotate the hand about its z axis far beyond joint 7's range
        ctl.step([0.0, 0.0, 0.0, 0.0, 0.0, 2.0], ref="local")
    q = ctl.log.column("q")
    assert np.all(q >= panda.lower + margin - 1e-12) and np.all(q <= panda.upper - margin + 1e-12)
    assert abs(ctl.q[6] - (panda.upper[6] - margin)) < 1e-9 or abs(
        ctl.q[6] - (panda.lower[6] + margin)) < 1e-9
    assert any("panda_joint7" in a for a in ctl.log.column("active"))


@pytest.mark.parametrize(
    ("call", "argument"),
    [
        (lambda c: c.step([0.0, 0.0, np.nan, 0.0, 0.0, 0.0], ref="local"), "twist"),
        # float (6,) arrays, checked on Python floats (Controller's fast path)
        (lambda c: c.step(np.array([0.0, 0.0, np.nan, 0.0, 0.0, 0.0]), ref="local"), "twist"),
        (lambda c: c.step(np.array([0.0, np.inf, 0.0, 0.0, 0.0, 0.0]), ref="local"), "twist"),
        (lambda c: c.step(np.array([np.inf, -np.inf, 0.0, 0.0, 0.0, 0.0]), ref="local"), "twist"),
        (lambda c: c.step(np.zeros((6, 1))), "twist"),
        (lambda c: c.step([0.0, 0.0, 0.1], ref="local"), "twist"),
        (lambda c: c.step([0.1, 0, 0, 0, 0, 0], ref="tool"), "ref"),
        (lambda c: c.step([0.1, 0, 0, 0, 0, 0], ref="base"), "ref"),
        (lambda c: c.step(None, ref="hand"), "ref"),
        (lambda c: c.reverse(10.0), "seconds"),
        (lambda c: c.reverse(-1.0), "seconds"),
        (lambda c: setattr(c, "speed", 1.5), "speed"),
        (lambda c: setattr(c, "speed", float("nan")), "speed"),
        (lambda c: setattr(c, "q", [0.0] * 6), "q"),
        (lambda c: setattr(c, "q", [np.nan] * 7), "q"),
    ],
)
def test_bad_input_names_the_argument_and_changes_nothing(panda, call, argument):
    ctl = Controller(panda, q0=PANDA_Q0)
    for _ in range(5):
        ctl.step([0.01, 0.0, 0.0, 0.0, 0.0, 0.0], ref="local")
    q, t, n, reference = ctl.q.copy(), ctl.t, len(ctl.log), ctl.reference
    with pytest.raises(rrc_pin.InvalidInput) as info:
        call(ctl)
    assert info.value.argument == argument and argument in str(info.value)
    assert np.array_equal(ctl.q, q) and ctl.t == t and len(ctl.log) == n
    assert np.array_equal(ctl.reference, reference) and ctl.speed == 1.0


@pytest.mark.parametrize(
    ("kwargs", "argument"),
    [
        ({"dt": 0.0}, "dt"),
        ({"dt": -0.01}, "dt"),
        ({"strategy": "magic"}, "strategy"),
        ({"strategy": 3}, "strategy"),
        ({"q0": [0.0] * 3}, "q0"),
        ({"speed": -0.1}, "speed"),
        ({"deadman": 0.2}, "deadman"),
        ({"strategy": "generalized_inverse"}, "strategy"),  # panda has no Barker closed form
    ],
)
def test_bad_construction_names_the_argument(panda, kwargs, argument):
    with pytest.raises(rrc_pin.InvalidInput) as info:
        Controller(panda, **kwargs)
    assert info.value.argument == argument


def test_a_float_array_command_is_kept_as_a_copy_and_judged_like_any_other(panda):
    """The twist is kept as a copy (the caller's array may be reused); finite entries whose
    sum overflows are accepted, integers too."""
    reused = Controller(panda, q0=PANDA_Q0)
    fresh = Controller(panda, q0=PANDA_Q0)
    buffer = np.array([0.02, -0.01, 0.0, 0.0, 0.1, 0.0])
    reused.step(buffer, ref="local")
    fresh.step(buffer.copy(), ref="local")
    buffer[:] = 5.0  # the caller's buffer changes after the call: the held command does not
    for _ in range(3):
        assert np.array_equal(reused.step().q, fresh.step().q)
    huge = np.array([1e308, 1e308, 0.0, 0.0, 0.0, 0.0])  # finite, its sum is not
    kept = _checked_twist(huge)
    assert np.array_equal(kept, huge) and kept is not huge
    ints = Controller(panda, q0=PANDA_Q0)
    assert np.array_equal(ints.step(np.array([0, 0, 0, 0, 0, 0]), ref="local").q, PANDA_Q0)


def test_q_is_read_only_and_set_checked_the_tick_resolves_as_solve_does(panda):
    """The controller holds q read-only (the log and every Step share it), takes a new one
    through the checked setter, and resolves its own q and checked command without checking
    them again: the same rates as the public ``Resolver.solve`` on the same arguments."""
    ctl = Controller(panda, q0=PANDA_Q0, drift=None)
    start = PANDA_Q0 + 0.05
    ctl.q = start
    start[0] = 1.0  # the caller's array is copied
    with pytest.raises(ValueError):
        ctl.q[0] = 0.0
    twist = np.array([0.05, -0.02, 0.03, 0.1, 0.0, -0.2])
    step = ctl.step(twist, ref="local")
    with pytest.raises(ValueError):
        step.q[0] = 0.0
    expected = rrc_pin.Resolver(panda).solve(PANDA_Q0 + 0.05, twist, ref="local")
    np.testing.assert_array_equal(step.resolution.qdot, expected.qdot)
    assert step.resolution.tasks[0].commanded.tolist() == twist.tolist()


def test_the_resolvers_strategy_is_skipped_as_its_decision_would_keep_the_command(panda):
    """``ResolverOnly.passive``: the controller builds no Situation for it; a strategy that
    decides KEEP through the ordinary path moves the arm identically."""

    class Keep(Strategy):
        def decide(self, situation: Situation) -> Decision:
            assert situation.q.shape == (7,)
            return KEEP

    assert ResolverOnly.passive and not Keep.passive
    rng = np.random.default_rng(5)
    passive = Controller(panda, q0=PANDA_Q0)
    ordinary = Controller(panda, q0=PANDA_Q0, strategy=Keep())
    for twist in random_commands(rng, 0.3, 0.01, hold=0.05):
        assert np.array_equal(passive.step(twist, ref="local").q,
                              ordinary.step(twist, ref="local").q)
    assert np.array_equal(passive.log.column("drift_position"),
                          ordinary.log.column("drift_position"))  # fmt: skip


def test_a_robot_with_two_hands_is_refused():
    with pytest.raises(rrc_pin.InvalidInput, match="several tool frames") as info:
        Controller("baxter")
    assert info.value.argument == "robot"


def test_records_name_the_singularity_met(barker):
    ctl = Controller(barker, q0=np.deg2rad([20.0, 30.0, 60.0, 10.0, 3.0, 0.0]))
    for _ in range(15):
        ctl.step([0.0, 0.0, 0.0, 0.0, -0.5, 0.0], ref="local")  # theta5 towards and through 0
    labels = set(ctl.log.column("singularity"))
    assert "wrist (S5 = 0)" in labels


def test_the_default_start_is_the_ready_pose():
    """Issue 33 item 2: Controller(panda) started on joint 4's limit, with a recovering tick."""
    ctl = Controller(rrc_pin.load("panda"))
    np.testing.assert_array_equal(ctl.q, ctl.robot.ready())
    for _ in range(3):
        _, r = ctl.step([0.02, 0.0, 0.0, 0.0, 0.0, 0.0], ref="world_aligned")
        assert r.status == "exact"


def test_a_mask_holds_its_joints_through_the_loop_and_unmask_releases_them() -> None:
    """Controller.mask between ticks: the masked joints exactly still through the drift
    correction and the integration, the hand still served by the others; a bad name refused
    by name with the mask unchanged; unmask lets them move again."""
    ctl = Controller("panda", 0.01)
    ctl.mask(["panda_joint1", "panda_joint4"])
    with pytest.raises(rrc_pin.InvalidInput, match="joints"):
        ctl.mask("panda_joint8")
    assert ctl.masked == ("panda_joint1", "panda_joint4")
    start = ctl.q.copy()
    for _ in range(60):
        step = ctl.step([0.0, 0.0, 0.05, 0.0, 0.0, 0.0], ref="world_aligned")
        assert step.resolution.masked == ctl.masked
        assert ctl.q[0] == start[0] and ctl.q[3] == start[3]
    assert np.abs(ctl.q - start).max() > 0.01
    ctl.unmask()
    assert ctl.masked == ()
    before = ctl.q.copy()
    ctl.step([0.0, 0.0, 0.05, 0.0, 0.0, 0.0], ref="world_aligned")
    assert ctl.q[0] != before[0] or ctl.q[3] != before[3]


# -- pose streams and the jerk stage (issue 41) ------------------------------------------------


def replayed(ctl: Controller, replays: dict[str, Replay]) -> list[rrc_pin.control.loop.Step]:
    """SECONDS of each recording fed into the controller's streams as its clock passes them."""
    steps = []
    for k in range(round(SECONDS / DT)):
        for frame, replay in replays.items():
            replay.feed(k * DT, ctl.robot.fk(ctl.q, frame))
        steps.append(ctl.step())
    return steps


@pytest.mark.parametrize("seed", [1, "fresh"])
def test_a_recorded_stream_drives_the_hand_through_its_faults(panda, seed):
    """ctl.stream() on panda: a 90 Hz recording (0.5 mm and 2 mrad noise, dropouts of 0.15 and
    0.4 s, a three-sample glitch 0.25 m off, the tracker's frame moved by (0, 0.2, 0.05) m, the
    clutch pressed 1 s) into a 100 Hz Controller.step(): the hand follows the clean target
    0.10 s behind (1/k) within 3 mm (RMS 1.5 mm) outside 0.5 s after each fault, both jumps
    rejected, the moved frame and the clutch's release re-anchored with no step in the target
    or the hand's motion (measured 0.10 s, 2.1 mm, RMS 0.92 mm; at most 2.4 mm over 20 other
    noise seeds)."""
    seed = int(np.random.SeedSequence().entropy % 2**63) if seed == "fresh" else seed
    ctl = Controller(panda, dt=DT)
    stream = ctl.stream()
    assert ctl.streams == {panda.tool_frame: stream}
    replay = Replay(stream, seed=seed)
    steps = replayed(ctl, {panda.tool_frame: replay})
    lag, worst, rms = replay.lag_and_error()
    assert 0.05 <= lag <= 0.12 and worst < 3e-3 and rms < 1.5e-3, (seed, lag, worst, rms)
    replay.check_faults()
    assert all(s.resolution.status == "exact" for s in steps)
    with pytest.raises(rrc_pin.InvalidInput, match="twist: panda_hand_tcp follows its pose"):
        ctl.step([0.01, 0, 0, 0, 0, 0], ref="world_aligned")
    ctl.close_stream()
    held = ctl.step().resolution  # the stream's last twist does not age on: it holds
    assert np.abs(held.qdot).max() < 1e-9 and ctl.streams == {}
    moved = ctl.step([0.01, 0, 0, 0, 0, 0], ref="world_aligned").resolution  # twists again
    assert moved.status == "exact" and np.abs(moved.qdot).max() > 1e-3
    with pytest.raises(rrc_pin.InvalidInput, match="name: 'panda_hand_tcp' has no stream"):
        ctl.close_stream()
    with pytest.raises(rrc_pin.InvalidInput, match="name: expected a frame of panda"):
        ctl.stream("nowhere")


def test_two_hands_of_baxter_in_one_controller_each_on_its_own_stream():
    """baxter loaded with its left hand as the tool frame, the right hand streamed as a second
    frame of the same Controller (one top level, one common scale): each hand follows its own
    recording (other seeds, the figure's phase apart) as panda's did."""
    baxter = rrc_pin.load("baxter", tool_frame="left_gripper")
    ctl = Controller(baxter, dt=DT)
    replays = {"left_gripper": Replay(ctl.stream(), seed=2),
               "right_gripper": Replay(ctl.stream("right_gripper"), seed=3, phase=1.0)}  # fmt: skip
    replayed(ctl, replays)
    for frame, replay in replays.items():
        lag, worst, rms = replay.lag_and_error()
        assert 0.05 <= lag <= 0.12 and worst < 3e-3 and rms < 1.5e-3, (frame, lag, worst, rms)
        replay.check_faults()


def jerk_session(arm, seed: int, smoothing: SmoothingOptions):
    """10 s of random hand twists (piecewise constant): the steps and the stage's reports."""
    ctl = Controller(arm, dt=DT, smoothing=smoothing)
    steps, reports = [], []
    for twist in random_commands(np.random.default_rng(seed), 10.0, DT, speed=0.08, turn=0.3):
        steps.append(ctl.step(twist, ref="world_aligned"))
        reports.append(ctl.smoothed)
    return ctl, steps, reports


@pytest.mark.parametrize("seed", [0, 4, "fresh"])
def test_the_jerk_stage_bounds_acceleration_and_jerk_inside_the_limits_and_stops_in_time(
    panda, seed
):
    """Controller(smoothing=SmoothingOptions(20, 500)) under random hand twists whose raw
    rates change up to 3.2 rad/s a tick: every tick's rate change within a_max dt, its change
    within j_max dt^2 (1e-9), inside the tick's box (the resolver's position and velocity
    limits, exact), the box never winning; ``smoothed.changed`` set where the stage ramped;
    then STOP (``smoothing.stop()``) from where the session ended, every rate below
    1e-9 within ``stop_time()`` as stated at the stop, the commands still coming."""
    seed = int(np.random.SeedSequence().entropy % 2**63) if seed == "fresh" else seed
    smoothing = SmoothingOptions(20.0, 500.0)
    ctl, steps, reports = jerk_session(panda, seed, smoothing)
    rates = np.array([s.resolution.qdot for s in steps])
    acceleration = np.diff(np.vstack([np.zeros(panda.nv), rates]), axis=0) / DT
    jerk = np.diff(np.vstack([np.zeros(panda.nv), acceleration]), axis=0) / DT
    assert np.abs(acceleration).max() <= 20.0 + 1e-9, seed
    assert np.abs(jerk).max() <= 500.0 + 1e-7, seed  # (1e-9 of the rates over dt^2)
    for s, report in zip(steps, reports, strict=True):
        box = s.resolution.box
        assert (box.lb <= s.resolution.qdot).all() and (s.resolution.qdot <= box.ub).all(), seed
        assert not report.clipped.any(), seed
        assert (np.abs(s.resolution.qdot) <= panda.velocity_limit).all(), seed
        assert (panda.lower <= s.q).all() and (s.q <= panda.upper).all(), seed
    assert any(r.changed.any() for r in reports), seed  # (a session may start with a zero)
    stage = ctl.smoothing
    stage.stop()
    stated, ticks = stage.stop_time(), 0
    while np.abs(stage.rates).max() > 1e-9:
        ctl.step([0.05, 0.0, 0.0, 0.0, 0.0, 0.3], ref="world_aligned")
        ticks += 1
        assert ticks * DT <= stated + 1e-9, (seed, ticks, stated)


def test_with_the_jerk_stage_the_streamed_hand_keeps_to_the_unsmoothed_path(panda):
    """The stream replay of the test above with and without the stage (20 rad/s^2, 500
    rad/s^3): the hands within 2 cm of each other at every tick (measured 17.5 mm, as the
    0.4 s dropout ends and the hand catches up), 0.5 mm at the median (0.09 mm); the raw
    rates change up to 1.5 rad/s a tick, the smoothed ones 0.2."""
    hands = {}
    for smoothing in (None, SmoothingOptions(20.0, 500.0)):
        ctl = Controller(panda, dt=DT, smoothing=smoothing)
        steps = replayed(ctl, {panda.tool_frame: Replay(ctl.stream(), seed=1)})
        hands[smoothing is None] = np.array([panda.fk(s.q)[:3, 3] for s in steps])
        rates = np.array([s.resolution.qdot for s in steps])
        change = np.abs(np.diff(rates, axis=0)).max()
        assert change > 1.0 if smoothing is None else change <= 0.2 + 1e-9, change
    apart = np.linalg.norm(hands[True] - hands[False], axis=1)
    assert apart.max() < 0.02 and np.median(apart) < 5e-4, (apart.max(), np.median(apart))


def test_the_step_report_says_when_the_stage_changed_the_rates(panda):
    """A constant twist from rest: the stage ramps the rates (``smoothed.changed``, the
    acceleration at its bound) for the first ticks, then passes the resolver's own (to 1e-6)."""
    ctl = Controller(panda, dt=DT, smoothing=SmoothingOptions(20.0, 500.0))
    changed = []
    for _ in range(100):
        ctl.step([0.05, 0.02, 0.0, 0.0, 0.0, 0.2], ref="world_aligned")
        changed.append(bool(ctl.smoothed.changed.any()))
    assert changed[:3] == [True] * 3 and not any(changed[50:]), changed
    assert ctl.smoothed.qdot is not ctl.smoothing.rates  # a copy: the report stays


def test_a_bad_smoothing_is_refused_by_name(panda):
    with pytest.raises(rrc_pin.InvalidInput, match="smoothing: expected SmoothingOptions"):
        Controller(panda, smoothing=20.0)  # type: ignore[arg-type]
    with pytest.raises(rrc_pin.InvalidInput, match="jerk"):
        SmoothingOptions(20.0, -1.0)
    with pytest.raises(rrc_pin.InvalidInput, match="acceleration"):
        Controller(panda, smoothing=SmoothingOptions([1.0, 2.0], 500.0))


def test_active_codes_against_numpy() -> None:
    """The bounds a tick's rates touch, as the log keys their text: the kernel's codes are
    numpy's ``low (1 + kind[0]) + 4 high (1 + kind[1])``."""
    rng = np.random.default_rng(20261206)
    for _ in range(200):
        n = int(rng.integers(1, 9))
        lb, ub = -rng.uniform(0.0, 2.0, n), rng.uniform(0.0, 2.0, n)
        qdot = np.where(rng.random(n) < 0.3, lb, np.where(rng.random(n) < 0.3, ub,
                                                          rng.uniform(lb, ub)))  # fmt: skip
        lb[rng.random(n) < 0.1] = 0.0
        ub[lb == 0.0] = 0.0
        qdot[lb == 0.0] = 0.0
        kind = rng.integers(0, 4, (2, n)).astype(np.int8)
        codes = np.empty(n, np.int8)
        touched = active_codes(qdot, lb, ub, kind, codes)
        low = (qdot - lb <= 1e-9).astype(np.int8)
        high = (ub - qdot <= 1e-9).astype(np.int8)
        want = low * (1 + kind[0]) + 4 * high * (1 + kind[1])
        np.testing.assert_array_equal(codes, want)
        assert touched == bool(want.any())
