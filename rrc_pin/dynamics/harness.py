"""The closed loop: simulator + controller + reference, stepped at the simulator's rate."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.dynamics.controller import Controller
from rrc_pin.dynamics.pose_error import pose_error
from rrc_pin.dynamics.reference import JointTrajectory
from rrc_pin.dynamics.simulator import Simulator
from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import finite_number

Array = npt.NDArray[np.float64]
Event = tuple[float, Callable[[Simulator], None]]
"""``(time [s], action)``: the action runs on the simulator before the first step at or after
that time (a payload change, a new plane)."""


@dataclass(frozen=True)
class Record:
    """One run, sampled at every step.

    Attributes:
        t: Times (N,) [s].
        q: Joint positions (N, nq) [rad].
        q_ref: Reference joint positions (N, nq) [rad].
        tau: Applied motor torques (N, nq) [N m].
        pose_error: Tool error ``[p_d - p; delta]`` (N, 6) [m, rad] against the reference.
        force: Force the tool exerts (N, 3) [N], base axes.
        force_ref: Desired force (N, 3) [N].
        clipped: Steps at which a commanded torque was saturated by the simulator.
        controller_seconds: Wall time per step [s] of the controller (mean).
        simulator_seconds: Wall time per step [s] of the simulator (mean).
        dt: The simulator's step [s].
    """

    t: Array
    q: Array
    q_ref: Array
    tau: Array
    pose_error: Array
    force: Array
    force_ref: Array
    clipped: int
    controller_seconds: float
    simulator_seconds: float
    dt: float

    @property
    def real_time_factor(self) -> float:
        """Simulated time per wall time of controller + simulator (> 1: faster than real time)."""
        return self.dt / (self.controller_seconds + self.simulator_seconds)


def run(
    sim: Simulator,
    controller: Controller,
    trajectory: JointTrajectory,
    duration: float,
    *,
    force: Callable[[float], Array] | None = None,
    events: Sequence[Event] = (),
) -> Record:
    """Run the loop from the simulator's current state for ``duration`` [s].

    Args:
        sim: The simulated arm (state, payload, plane).
        controller: The law; its period should equal ``sim.dt``.
        trajectory: Joint reference (held after its end).
        duration: Time [s] to run.
        force: Desired force the tool exerts (3,) [N] as a function of time, or None (zero).
        events: Actions on the simulator at given times.

    Returns:
        The :class:`Record`, one sample per step (before the step).

    Raises:
        InvalidInput: The controller's period differs from the simulator's step, or a bad
            ``duration``.
    """
    if abs(controller.dt - sim.dt) > 1e-12:
        raise InvalidInput(
            "controller", f"its period {controller.dt} s differs from the simulator's {sim.dt} s"
        )
    duration = finite_number(duration, "duration", 0.0, inclusive=False)
    steps = round(duration / sim.dt)
    nq = sim.robot.nq
    out = {k: np.zeros((steps, nq)) for k in ("q", "q_ref", "tau")}
    poses, ref_poses = np.zeros((steps, 4, 4)), np.zeros((steps, 4, 4))
    f, f_ref, t_out = np.zeros((steps, 3)), np.zeros((steps, 3)), np.zeros(steps)
    pending = sorted(events, key=lambda e: e[0])
    state = sim.state()
    clipped = 0
    control_time = simulation_time = 0.0
    for k in range(steps):
        while pending and pending[0][0] <= state.t + 1e-12:
            pending.pop(0)[1](sim)
        wanted = np.zeros(3) if force is None else force(state.t)
        ref = trajectory.at(state.t, wanted)
        tick = time.perf_counter()
        tau = controller.torques(state, ref)
        control_time += time.perf_counter() - tick
        t_out[k], out["q"][k], out["q_ref"][k] = state.t, state.q, ref.q
        poses[k], ref_poses[k] = sim.robot.fk(state.q), ref.pose
        f[k], f_ref[k] = state.force, wanted
        tick = time.perf_counter()
        state = sim.step(tau)
        simulation_time += time.perf_counter() - tick
        out["tau"][k] = sim.report.tau
        clipped += sim.report.clipped
    return Record(
        t=t_out,
        q=out["q"],
        q_ref=out["q_ref"],
        tau=out["tau"],
        pose_error=pose_error(poses, ref_poses),
        force=f,
        force_ref=f_ref,
        clipped=clipped,
        controller_seconds=control_time / max(steps, 1),
        simulator_seconds=simulation_time / max(steps, 1),
        dt=sim.dt,
    )
