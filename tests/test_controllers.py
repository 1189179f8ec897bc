"""Control schemes in closed loop on short runs: tracking, payload recovery, force, refusals."""

from __future__ import annotations

import numpy as np
import pytest

import rrc_pin
from rrc_pin.dynamics import (
    ComputedTorque,
    Controller,
    FixedPD,
    HandPath,
    JointTrajectory,
    SerajiGains,
    SerajiLaw,
    Simulator,
    run,
)
from rrc_pin.dynamics.hybrid import HybridForcePosition
from rrc_pin.dynamics.scenarios import (
    PAYLOAD,
    TRACKING_CONTROLLERS,
    cartesian_gains,
    controller,
    force,
    force_gains,
    scenario,
    start,
)
from rrc_pin.errors import InvalidInput


@pytest.fixture(scope="module", params=("barker6", "rrc_k1607"))
def arm(request):
    return rrc_pin.load(request.param)


@pytest.fixture(scope="module")
def barker():
    return rrc_pin.load("barker6")


def short_move(robot, seconds: float = 0.25):
    """2 cm along x and y in ``seconds`` (peak tool speed 0.21 m/s at 0.25 s)."""
    q0 = start(robot)
    path = HandPath(robot.fk(q0), np.array([[0.0, 0.0, 0.0], [0.02, 0.02, 0.0]]), seconds)
    return q0, JointTrajectory(robot, q0, path, seconds)


@pytest.mark.parametrize("name", TRACKING_CONTROLLERS)
def test_each_controller_tracks_a_short_move_within_limits(arm, name):
    """Tool error below 20 mm on a 2.8 cm move in 0.25 s, friction on; no NaN; in limits.

    Measured peaks [mm]: barker6 fixed PD 17.8, computed torque 12.8, joint adaptive 10.7,
    Cartesian adaptive 14.8; rrc_k1607 12.3, 3.3, 8.6, 3.4. The PUMA's Coulomb friction
    (26 N m at joint 1) over a 1 kN m/rad loop alone is 25 mrad, some 17 mm at the tool.
    """
    q0, trajectory = short_move(arm)
    sim = Simulator(arm, friction=True)
    sim.reset(q0)
    ctl = controller(name, arm, q0)
    rec = run(sim, ctl, trajectory, 0.25)
    error = np.linalg.norm(rec.pose_error[:, :3], axis=1)
    assert np.all(np.isfinite(rec.q)) and np.all(np.isfinite(rec.tau))
    assert error.max() < 20e-3
    assert np.all(np.abs(rec.tau) <= arm.model.effortLimit + 1e-12)
    assert ctl.faults == 0


def test_computed_torque_with_the_exact_model_tracks_to_the_integrator(barker):
    """No payload, no friction: RNEA of the controller cancels ABA of the simulator.

    What remains is the first-order integrator's: the error halves with the step
    (measured 2.5e-4 rad at 1 ms on this move, against some 0.05 rad for fixed PD).
    """
    q0, trajectory = short_move(barker)
    worst = []
    for dt in (1e-3, 5e-4):
        sim = Simulator(barker, dt)
        sim.reset(q0)
        rec = run(sim, ComputedTorque(barker, 400.0, 40.0, dt=dt), trajectory, 0.25)
        worst.append(np.abs(rec.q - rec.q_ref).max())
    assert worst[0] < 5e-4  # [rad]
    assert 1.7 < worst[0] / worst[1] < 2.3


def test_adaptive_controllers_recover_from_a_payload_that_fixed_pd_cannot(barker):
    """2.5 kg picked up at 20 ms while holding still (friction on), 0.8 s.

    Measured end errors: fixed PD 8.0 mm (a steady sag), joint adaptive 1.6 mm, Cartesian
    adaptive 0.8 mm, and still falling.
    """
    q0 = start(barker)
    hold = JointTrajectory(barker, q0, HandPath(barker.fk(q0), np.zeros((2, 3)), 0.1), 0.1)
    end = {}
    for name in ("fixed_pd", "joint_adaptive_pd", "cartesian_adaptive_pd"):
        sim = Simulator(barker, friction=True)
        sim.reset(q0)
        rec = run(
            sim,
            controller(name, barker, q0),
            hold,
            0.8,
            events=[(0.02, lambda s: s.set_payload(PAYLOAD))],
        )
        end[name] = np.linalg.norm(rec.pose_error[-1, :3])
    assert end["fixed_pd"] > 5e-3
    assert end["joint_adaptive_pd"] < 0.3 * end["fixed_pd"]
    assert end["cartesian_adaptive_pd"] < 0.3 * end["fixed_pd"]


@pytest.mark.parametrize(("stiffness", "tilt"), [(1e3, 0.0), (1e5, np.deg2rad(30.0))])
def test_hybrid_holds_the_force_along_the_normal_while_tracking_in_the_plane(
    barker, stiffness, tilt
):
    """20 N into a horizontal 1e3 N/m plane and a 1e5 N/m plane tilted by 30 deg, 0.8 s.

    Bounds: force error below 3 N after the 0.5 s settling (measured below 1.5 N), in-plane
    error below 30 mm (measured below 15 mm), contact kept.
    """
    outcome = force(barker, "hybrid_adaptive", stiffness=stiffness, duration=0.8, tilt=tilt)
    m = outcome.metrics
    assert m["force_max_N"] < 3.0
    assert m["contact_lost_s"] == 0.0
    assert m["position_max_mm"] < 30.0
    assert np.all(np.abs(outcome.record.tau) <= barker.model.effortLimit + 1e-12)


class _Broken(Controller):
    def law(self, state, ref):
        return np.full(self.robot.nq, np.nan)


def test_a_non_finite_law_never_reaches_the_motors(barker):
    q0, trajectory = short_move(barker)
    ctl = _Broken(barker)
    tau = ctl.torques(Simulator(barker).reset(q0), trajectory.at(0.0))
    assert np.array_equal(tau, np.zeros(barker.nq)) and ctl.faults == 1


def test_seraji_gains_grow_while_the_error_persists():
    law = SerajiLaw(
        SerajiGains(kp0=1.0, kv0=1.0, alpha=(10.0, 0.0), delta=(5.0, 0.0), kp_max=3.0), 1, 0.01
    )
    for _ in range(100):
        law.update(np.array([0.5]), np.array([0.0]))
    assert law.kp[0] == pytest.approx(3.0)  # 1 + 10 * 0.25 * 1 s, clipped at kp_max
    assert law.f[0] == pytest.approx(2.5)  # 5 * 0.5 * 1 s
    law.reset()
    assert law.kp[0] == 1.0 and law.f[0] == 0.0


@pytest.mark.parametrize(
    ("build", "argument"),
    [
        (lambda r: FixedPD(r, kp=-1.0, kv=1.0), "kp"),
        (lambda r: FixedPD(r, kp=1.0, kv=np.ones(3)), "kv"),
        (lambda r: ComputedTorque(r, kp=np.nan, kv=1.0), "kp"),
        (lambda r: SerajiLaw(SerajiGains(kp0=1.0, kv0=1.0, alpha=(-1.0, 0.0)), 6, 1e-3), "alpha"),
        (lambda r: SerajiLaw(SerajiGains(kp0=0.0, kv0=1.0), 6, 1e-3), "kp0"),
        (lambda r: SerajiLaw(SerajiGains(kp0=1.0, kv0=1.0, kp_max=0.0), 6, 1e-3), "kp_max"),
        (
            lambda r: HybridForcePosition(r, cartesian_gains(True), force_gains(True), [0, 0, 0.5]),
            "selection",
        ),
        (
            lambda r: HybridForcePosition(r, cartesian_gains(True), force_gains(True), [0, 1]),
            "selection",
        ),
        (
            lambda r: HybridForcePosition(
                r, cartesian_gains(True), force_gains(True), [0, 0, 1], task_frame=2 * np.eye(3)
            ),
            "task_frame",
        ),
        (lambda r: scenario("juggling", r, "fixed_pd"), "scenario"),
        (lambda r: scenario("tracking", r, "bang_bang"), "controller"),
        (lambda r: force(r, "hybrid_adaptive", stiffness=-1.0), "stiffness"),
    ],
)
def test_bad_gains_selection_and_names_are_refused_by_name(barker, build, argument):
    with pytest.raises(InvalidInput, match=argument):
        build(barker)


def test_the_tracking_scenario_measures_the_payload_transient(barker):
    """A 0.3 s run with the payload at 0.1 s: the deviation from the quiet run is measured."""
    outcome = scenario("tracking", barker, "fixed_pd", duration=0.3, change_at=0.1, segment=0.3)
    m = outcome.metrics
    assert outcome.baseline is not None
    assert m["payload_deviation_peak_mm"] > 1.0  # 2.5 kg sags a fixed-gain loop
    assert m["recovery_s"] == float("inf")  # and it stays sagged
    assert all(np.isfinite(v) for k, v in m.items() if k != "recovery_s")


def test_the_loop_refuses_a_controller_at_another_rate(barker):
    _, trajectory = short_move(barker)
    with pytest.raises(InvalidInput, match="controller"):
        run(Simulator(barker), FixedPD(barker, 100.0, 10.0, dt=2e-3), trajectory, 0.1)


def test_hybrid_splits_the_wrench_along_the_task_frame(barker, rng):
    """At the reference, at rest: the wrench is the force loop's, on the force axes only.

    Task frame turned by a random rotation, S = diag(1, 0, 1): ``F = R S (f_d + kp0 (f_d -
    f))`` in task axes (no position error, no speed), checked through ``J^T`` (square J).
    """
    import pinocchio as pin

    from rrc_pin.dynamics import Reference, State

    q0 = start(barker)
    R = pin.exp3(rng.normal(size=3))
    s = np.array([1.0, 0.0, 1.0])
    ctl = HybridForcePosition(barker, cartesian_gains(False), force_gains(False), s, task_frame=R)
    f_d, f = rng.normal(size=3) * 10, rng.normal(size=3) * 10
    ref = Reference(q0, np.zeros(6), np.zeros(6), barker.fk(q0), np.zeros(6), f_d)
    tau = ctl.law(State(0.0, q0, np.zeros(6), f), ref)
    wrench = np.linalg.solve(barker.jacobian(q0).T, tau)
    expected = R @ (s * (R.T @ f_d + 0.5 * (R.T @ (f_d - f))))
    assert np.allclose(wrench[:3], expected, atol=1e-9)
    assert np.allclose(wrench[3:], 0.0, atol=1e-9)
