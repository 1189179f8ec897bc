"""The scenarios of Nguyen & Zhou section 6, with the gains and set-ups used for the record.

- ``tracking``: the tool follows a polyline hand path (minimum-jerk segments of 1 s) and picks
  up a payload (:data:`PAYLOAD`, 2.5 kg, 5 cm out along the tool z axis) at ``change_at``; the
  report's claim is a small tracking error under a sudden change in payload. The transient is
  measured against the same run without the change: the payload deviation
  ``d(t) = |p(t) - p_nochange(t)|`` and the time after the change until ``d`` stays below
  :data:`RECOVERED` (1 mm).
- ``force``: the tool presses on a plane through its start position with a desired force of
  :data:`FORCE` (20 N) along the inward normal while moving along it. The plane is horizontal
  (normal +z) or turned by ``tilt`` about the base x axis; the task frame is the plane's
  (``R = Rx(tilt)``, z along the normal), the path's waypoints are turned with it, and the
  hybrid controller selects ``s = (0, 0, 1)`` in it. The joint-space baselines chase the same
  path pushed ``|f_d| / k_assumed`` into the plane (:data:`ASSUMED_STIFFNESS`, 1e4 N/m): a
  position-based force, right only on a surface of the assumed stiffness.

Gains (stated once, here): joint loops ``kp = 2 (a + 0.5) wn^2``, ``kv = 2 (a + 0.5) wn``
with ``wn = 20 rad/s`` and ``a`` the joint's armature [kg m^2]; computed torque ``wn^2`` and
``2 wn``. Every adaptive law starts from the same gains as its fixed counterpart and from
the holding torque (or wrench) at rest, which a real arm measures from its motor currents
before a move. Friction is on in every scenario.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.dh import rot_x
from rrc_pin.dynamics.adaptation import SerajiGains
from rrc_pin.dynamics.cartesian_adaptive import CartesianAdaptivePD
from rrc_pin.dynamics.computed_torque import ComputedTorque
from rrc_pin.dynamics.controller import Controller
from rrc_pin.dynamics.drives import drives_of
from rrc_pin.dynamics.environment import ContactPlane
from rrc_pin.dynamics.harness import Record, run
from rrc_pin.dynamics.hybrid import HybridForcePosition
from rrc_pin.dynamics.joint_adaptive import JointAdaptivePD
from rrc_pin.dynamics.pd import FixedPD
from rrc_pin.dynamics.reference import HandPath, JointTrajectory
from rrc_pin.dynamics.simulator import Simulator
from rrc_pin.errors import InvalidInput
from rrc_pin.models.inertia import LinkInertial, make
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import finite_number

Array = npt.NDArray[np.float64]
SCENARIOS = ("tracking", "force")
TRACKING_CONTROLLERS = ("fixed_pd", "computed_torque", "joint_adaptive_pd", "cartesian_adaptive_pd")
FORCE_CONTROLLERS = ("fixed_pd", "computed_torque", "hybrid_fixed", "hybrid_adaptive")
CONTROLLERS = (*TRACKING_CONTROLLERS, "hybrid_fixed", "hybrid_adaptive")
PAYLOAD = make(2.5, (0.0, 0.0, 0.05), np.diag([4e-3, 4e-3, 2e-3]))
"""The payload picked up mid-run [kg, m, kg m^2], tool frame."""
RECOVERED = 1e-3
"""Payload deviation [m] below which the tracking counts as recovered."""
FORCE = 20.0
"""Desired force [N] the tool exerts on the plane, along its inward normal."""
ASSUMED_STIFFNESS = 1e4
"""Plane stiffness [N/m] the position-based force baselines assume."""
SETTLE = 0.5
"""Time [s] after which force errors are measured (contact transient)."""
WN = 20.0
"""Natural frequency [rad/s] of the joint loops."""
START = {
    "barker6": (0.0, 0.7, 1.2, 0.0, 0.9, 0.0),
    "rrc_k1607": (0.0, 0.6, 0.0, -1.3, 0.0, 0.7, 0.0),
}
"""Initial joints [rad] of each arm: well-conditioned, the tool in front of the base."""
TRACKING_PATH = ((0.0, 0.0, 0.0), (0.1, 0.1, 0.0), (0.0, 0.15, -0.1), (0.0, 0.0, 0.0))
FORCE_PATH = ((0.0, 0.0, 0.0), (0.1, 0.0, 0.0), (-0.05, 0.05, 0.0), (0.0, 0.0, 0.0))
"""Waypoints [m] relative to the start, one per second."""
CART_KP = np.array([4000.0, 4000.0, 4000.0, 150.0, 150.0, 150.0])  # [N/m, N m/rad]
CART_KV = np.array([200.0, 200.0, 200.0, 8.0, 8.0, 8.0])  # [N s/m, N m s/rad]
CART_F_MAX = np.array([300.0, 300.0, 300.0, 30.0, 30.0, 30.0])  # [N, N m]
NULL_KP, NULL_KV = 200.0, 20.0  # [N m/rad, N m s/rad], the K-1607's self-motion hold


@dataclass(frozen=True)
class Outcome:
    """A scenario run and its numbers.

    Attributes:
        record: The run, sampled at every step.
        metrics: Named numbers (units in the names: ``_mm``, ``_N``, ``_Nm``, ``_s``).
        baseline: The same run without the payload change (``tracking`` only).
    """

    record: Record
    metrics: dict[str, float]
    baseline: Record | None = field(default=None)


def start(robot: Robot) -> Array:
    """The scenario's initial joints for ``robot`` (a catalogue arm with a set-up).

    Raises:
        InvalidInput: ``robot`` has no set-up (lists the arms that have one).
    """
    if robot.name not in START:
        raise InvalidInput("robot", f"no scenario set-up for {robot.name!r}; have {sorted(START)}")
    return np.array(START[robot.name])


def joint_gains(robot: Robot) -> tuple[Array, Array]:
    """``(kp, kv)`` of the joint loops [N m/rad, N m s/rad]."""
    scale = 2.0 * (drives_of(robot.name, robot.nq).armature + 0.5)
    return scale * WN**2, scale * WN


def holding(robot: Robot, q: Array) -> tuple[Array, Array]:
    """Torque ``g(q)`` (nq,) and the tool wrench (6,) that holds the arm at rest at ``q``."""
    g = pin.computeGeneralizedGravity(robot.model, robot.model.createData(), q)
    wrench = np.linalg.lstsq(robot.jacobian(q).T, g, rcond=None)[0]
    return np.array(g), wrench


def controller(
    name: str, robot: Robot, q0: Array, dt: float = 1e-3, task_frame: Array | None = None
) -> Controller:
    """One of :data:`CONTROLLERS`, with the gains of this module, starting at rest at ``q0``.

    ``task_frame`` (3, 3) is the hybrid controllers' (default: the base axes).

    Raises:
        InvalidInput: Unknown ``name`` (lists the choices).
    """
    check_controller(name)
    kp, kv = joint_gains(robot)
    g0, wrench0 = holding(robot, q0)
    if name == "fixed_pd":
        return FixedPD(robot, kp, kv, dt=dt)
    if name == "computed_torque":
        return ComputedTorque(robot, WN**2, 2.0 * WN, dt=dt)
    if name == "joint_adaptive_pd":
        adaptive = SerajiGains(
            kp0=kp,
            kv0=kv,
            wp=1.0,
            wv=0.2,
            alpha=(20.0 * kp, 0.0),
            beta=(20.0 * kv, 0.0),
            delta=(5.0 * kp, 0.0),
            kp_max=4.0 * kp,
            kv_max=4.0 * kv,
            f_max=robot.model.effortLimit,
        )
        return JointAdaptivePD(robot, adaptive, f0=g0, dt=dt)
    if name == "cartesian_adaptive_pd":
        return CartesianAdaptivePD(
            robot, cartesian_gains(True), null_kp=NULL_KP, null_kv=NULL_KV, f0=wrench0, dt=dt
        )
    adapt = name == "hybrid_adaptive"  # the last two: hybrid_fixed, hybrid_adaptive
    return HybridForcePosition(
        robot,
        cartesian_gains(adapt),
        force_gains(adapt),
        (0.0, 0.0, 1.0),
        task_frame=task_frame,
        null_kp=NULL_KP,
        null_kv=NULL_KV,
        f0=wrench0,
        dt=dt,
    )


def check_controller(name: str, allowed: tuple[str, ...] = CONTROLLERS) -> str:
    """``name`` if it is one of ``allowed``.

    Raises:
        InvalidInput: Naming ``controller`` and listing the choices.
    """
    if name not in allowed:
        raise InvalidInput("controller", f"unknown controller {name!r}; choose from {allowed}")
    return name


def cartesian_gains(adapt: bool) -> SerajiGains:
    """Seraji gains of the six tool axes (adaptation rates zero when not ``adapt``)."""
    rate = 200.0 if adapt else 0.0
    return SerajiGains(
        kp0=CART_KP,
        kv0=CART_KV,
        wp=1.0,
        wv=0.2,
        alpha=(rate * CART_KP, 0.0),
        beta=(rate * CART_KV, 0.0),
        delta=(5.0 * CART_KP if adapt else 0.0, 0.0),
        kp_max=4.0 * CART_KP,
        kv_max=4.0 * CART_KV,
        f_max=CART_F_MAX,
    )


def force_gains(adapt: bool) -> SerajiGains:
    """Seraji gains of the force axes: ``kp0`` 0.5 N/N, damping 400 N s/m."""
    return SerajiGains(
        kp0=0.5,
        kv0=400.0,
        wp=1.0,
        wv=0.0,
        alpha=(20.0 if adapt else 0.0, 0.0),
        delta=(50.0 if adapt else 0.0, 0.0),
        kp_max=5.0,
        kv_max=2000.0,
        f_max=100.0,
    )


def scenario(name: str, robot: Robot, controller_name: str, **options: Any) -> Outcome:
    """Run scenario ``name`` (``tracking`` or ``force``) with one controller.

    Args:
        name: One of :data:`SCENARIOS`.
        robot: A catalogue arm with a set-up (:data:`START`).
        controller_name: One of :data:`CONTROLLERS`.
        **options: Keyword arguments of :func:`tracking` or :func:`force`.

    Raises:
        InvalidInput: Unknown scenario or controller, or a bad option (named).
    """
    if name == "tracking":
        return tracking(robot, controller_name, **options)
    if name == "force":
        return force(robot, controller_name, **options)
    raise InvalidInput("scenario", f"unknown scenario {name!r}; choose from {SCENARIOS}")


def tracking(
    robot: Robot,
    controller_name: str,
    duration: float = 4.0,
    change_at: float = 2.0,
    segment: float = 1.0,
    payload: LinkInertial = PAYLOAD,
) -> Outcome:
    """Hand-path tracking with a payload picked up at ``change_at`` [s].

    Run twice, with the change and without, for the transient.

    Raises:
        InvalidInput: A bad duration or time (named), an unknown controller.
    """
    check_controller(controller_name)
    duration = finite_number(duration, "duration", 0.0, inclusive=False)
    change_at = finite_number(change_at, "change_at", 0.0, upper=duration)
    q0 = start(robot)
    path = HandPath(robot.fk(q0), np.array(TRACKING_PATH), segment)
    trajectory = JointTrajectory(robot, q0, path, duration)
    records = []
    for change in (True, False):
        ctl = controller(controller_name, robot, q0)
        sim = Simulator(robot, friction=True)
        sim.reset(q0)
        events = [(change_at, lambda s: s.set_payload(payload))] if change else []
        records.append(run(sim, ctl, trajectory, duration, events=events))
    rec, quiet = records
    metrics = {**tracking_metrics(rec), **transient(rec, quiet, change_at)}
    return Outcome(rec, metrics, quiet)


def force(
    robot: Robot,
    controller_name: str,
    stiffness: float = 1e4,
    duration: float = 3.0,
    segment: float = 1.0,
    tilt: float = 0.0,
) -> Outcome:
    """Press with :data:`FORCE` on a plane of ``stiffness`` [N/m] while moving along it.

    ``tilt`` [rad] turns the plane (and the task frame, and the path) about the base x axis.

    Raises:
        InvalidInput: A bad stiffness or duration (named), an unknown controller.
    """
    check_controller(controller_name)
    stiffness = finite_number(stiffness, "stiffness", 0.0, inclusive=False)
    duration = finite_number(duration, "duration", 0.0, inclusive=False)
    tilt = finite_number(tilt, "tilt", -np.pi / 2, upper=np.pi / 2)
    R = rot_x(tilt)[:3, :3]
    normal = R[:, 2]
    wanted = -FORCE * normal
    q0 = start(robot)
    T0 = robot.fk(q0)
    ctl = controller(controller_name, robot, q0, task_frame=R)
    path = HandPath(T0, np.array(FORCE_PATH) @ R.T, segment)
    if not isinstance(ctl, HybridForcePosition):
        # Position-based force: the path pushed into the plane (the resolver's pull on the
        # pose error takes the reference there from q0 within some 0.3 s).
        pressed = np.array(T0)
        pressed[:3, 3] += wanted / ASSUMED_STIFFNESS
        path = replace(path, start=pressed)
    trajectory = JointTrajectory(robot, q0, path, duration)
    plane = ContactPlane(T0[:3, 3], normal, stiffness)
    sim = Simulator(robot, friction=True, plane=plane)
    sim.reset(q0)
    rec = run(sim, ctl, trajectory, duration, force=lambda t: wanted)
    metrics = {**tracking_metrics(rec, R[:, :2]), **force_metrics(rec, normal)}
    return Outcome(rec, metrics)


def tracking_metrics(rec: Record, basis: Array | None = None) -> dict[str, float]:
    """Tool position error RMS and max [mm], orientation max [mrad], torque peaks [N m].

    ``basis`` (3, k): measure the position error along its columns only (default: all).
    """
    position = rec.pose_error[:, :3] if basis is None else rec.pose_error[:, :3] @ basis
    e = np.linalg.norm(position, axis=1)
    out = {
        "position_rms_mm": 1e3 * float(np.sqrt(np.mean(e**2))),
        "position_max_mm": 1e3 * float(np.max(e)),
        "orientation_max_mrad": 1e3 * float(np.max(np.linalg.norm(rec.pose_error[:, 3:], axis=1))),
        "clipped_steps": float(rec.clipped),
        "real_time_factor": rec.real_time_factor,
        "step_us": 1e6 * (rec.controller_seconds + rec.simulator_seconds),
    }
    for j, peak in enumerate(np.abs(rec.tau).max(axis=0)):
        out[f"torque_peak_{j + 1}_Nm"] = float(peak)
    return out


def transient(rec: Record, quiet: Record, change_at: float) -> dict[str, float]:
    """Payload deviation: peak [mm], mean over the second after the change [mm], recovery [s].

    The recovery time is ``inf`` when the deviation is still above :data:`RECOVERED` at the end.
    """
    after = rec.t >= change_at
    d = np.linalg.norm(rec.pose_error[:, :3] - quiet.pose_error[:, :3], axis=1)[after]
    t = rec.t[after] - change_at
    above = np.nonzero(d > RECOVERED)[0]
    if above.size == 0:
        recovery = 0.0
    elif above[-1] == d.size - 1:
        recovery = float("inf")
    else:
        recovery = float(t[above[-1] + 1])
    window = t < 1.0
    return {
        "payload_deviation_peak_mm": 1e3 * float(np.max(d)),
        "payload_deviation_mean_1s_mm": 1e3 * float(d[window].mean()),
        "payload_deviation_end_mm": 1e3 * float(d[-1]),
        "recovery_s": recovery,
    }


def force_metrics(rec: Record, normal: Array) -> dict[str, float]:
    """Force error along ``normal`` [N] (RMS, max, end) and time out of contact [s].

    Both after :data:`SETTLE`.
    """
    late = rec.t >= SETTLE
    err = (rec.force[late] - rec.force_ref[late]) @ normal
    return {
        "force_rms_N": float(np.sqrt(np.mean(err**2))),
        "force_max_N": float(np.abs(err).max()),
        "force_end_N": float(err[-1]),
        "contact_lost_s": float(np.sum(~rec.force[late].any(axis=1)) * rec.dt),
    }
