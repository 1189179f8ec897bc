"""Nguyen & Zhou section 5 on the RRC K-1607: how the sampling time spoils velocity conversions.

The numerics of the study (``bench_study.py`` records, plots and renders them). The report
does not print its test trajectories; this study states its own (:data:`TRAJECTORY`): every
joint moves as ``theta_i(t) = theta0_i + A_i sin(2 pi t / T_i + phi_i)``, known in closed
form, so the joint rates ``thetadot(t)`` are exact and every error below comes from sampling.
With the samples ``t_k = k dt`` (``dt`` the sampling time):

- **Part 1** (report figs 4-5): the tool frame's Cartesian velocity from differenced forward
  kinematics, ``v_k = (p(t_k) - p(t_{k-1})) / dt`` and ``w_k = delta_k / dt`` with
  ``delta_k`` the differential rotation of ``R(t_k) R(t_{k-1})^T`` read off the skew part of
  Nguyen eq. (35)-(36) (corrected, docs/errata.md), against the Jacobian's
  ``J(theta(t_k)) thetadot(t_k)`` (world-aligned, rows ``[v; w]``). A backward difference
  is the derivative at ``t_k - dt/2``, so the error is first order:
  ``e ~ (dt / 2) max |pddot|``. The centred comparison (Jacobian at ``t_k - dt/2``) is
  recorded too: second order.
- **Part 2** (figs 6-7): the joint rates from the Jacobian pseudo-inverse,
  ``J^+(theta(t_k)) xdot``, against ``thetadot(t_k)``, for ``xdot`` the Jacobian's own
  Cartesian velocity (the conversion alone) and the differenced one of Part 1 (what a sampled
  controller sees). The pseudo-inverse returns the minimum-norm rates: it drops the
  self-motion ``(I - J^+ J) thetadot`` of a 7-joint arm whatever ``dt`` is; the
  sampling adds Part 1's error mapped by ``J^+`` (first order).
- **Part 3** (figs 9-10): the quaternion of the orientation difference ``R(t_k)
  R(t_{k-1})^T`` from those of the two orientations (Nguyen eqs. (33)-(34)) and the
  differential rotation ``delta = 2 delta s`` (eq. (37)), as a rate ``delta / dt``, against
  the Jacobian's ``w``; and the quaternion components ``delta s`` themselves against the
  Jacobian's ``w dt / 2``.

Every error is the largest absolute value over the trajectory, in SI units and (for the
report's comparison) inches; :func:`fitted_order` fits ``log e = p log dt + c``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

import rrc_pin
from rrc_pin.solvers.closed_form.quaternion import (
    differential_rotation,
    quaternion_difference,
    quaternion_from_matrix,
)

Array = npt.NDArray[np.float64]
INCH = 0.0254
"""One inch [m] (the report's unit of length)."""
ARM = "rrc_k1607"
SAMPLING_TIMES = (0.001, 0.01, 0.1)
"""The report's sampling times [s] (it plots 10 and 100 ms)."""


@dataclass(frozen=True)
class Trajectory:
    """Test joint trajectories ``theta_i(t) = theta0_i + A_i sin(2 pi t / T_i + phi_i)``.

    Attributes:
        theta0: Centre (7,) [rad].
        amplitude: ``A`` (7,) [rad].
        period: ``T`` (7,) [s].
        phase: ``phi`` (7,) [rad].
        duration: Length of the run [s].
        speed: Time scale: the trajectory ``theta(speed t)`` (2 is twice as fast).
    """

    theta0: tuple[float, ...]
    amplitude: tuple[float, ...]
    period: tuple[float, ...]
    phase: tuple[float, ...]
    duration: float
    speed: float = 1.0

    def q(self, t: Array) -> Array:
        """Joint positions (N, 7) at times ``t`` (N,) [s]."""
        arg = self._arg(t)
        return np.asarray(self.theta0) + np.asarray(self.amplitude) * np.sin(arg)

    def qdot(self, t: Array) -> Array:
        """Exact joint rates (N, 7) [rad/s]."""
        w = 2.0 * np.pi * self.speed / np.asarray(self.period)
        return np.asarray(self.amplitude) * w * np.cos(self._arg(t))

    def scaled(self, speed: float) -> Trajectory:
        """The same path run ``speed`` times faster (so in ``duration / speed`` seconds)."""
        return Trajectory(
            self.theta0,
            self.amplitude,
            self.period,
            self.phase,
            self.duration * self.speed / speed,
            speed,
        )

    def _arg(self, t: Array) -> Array:
        t = np.asarray(t, dtype=float)[:, None]
        return 2.0 * np.pi * self.speed * t / np.asarray(self.period) + np.asarray(self.phase)


TRAJECTORY = Trajectory(
    theta0=(0.0, 0.6, 0.0, 1.0, 0.0, 0.8, 0.0),
    amplitude=(0.6, 0.4, 0.5, 0.4, 0.6, 0.5, 0.8),
    period=(8.0, 6.0, 7.0, 5.0, 4.0, 4.5, 3.0),
    phase=(0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0),
    duration=10.0,
)
"""The study's test trajectory: every joint a sine, periods 3-8 s, amplitudes 0.4-0.8 rad
(peak joint rates 0.3-1.7 rad/s), around an elbow-bent posture away from singularities."""


@dataclass
class Sampled:
    """One trajectory sampled at one sampling time: errors per sample, rows ``t_1 ... t_K``.

    Attributes:
        dt: Sampling time [s].
        t: Sample times (K,) [s].
        v_jac: Jacobian linear velocity (K, 3) [m/s]; ``w_jac`` angular (K, 3) [rad/s].
        v_diff: Differenced FK (K, 3) [m/s]; ``w_diff`` from eq. (35) (K, 3) [rad/s].
        v_mid: Jacobian linear velocity at ``t - dt/2`` (K, 3) [m/s]; ``w_mid`` angular.
        qdot: Exact joint rates (K, 7); ``qdot_pinv_jac`` ``J^+ J qdot``;
            ``qdot_pinv_diff`` ``J^+`` of the differenced velocity [rad/s].
        w_quat: ``2 delta s / dt`` (eqs. (33)-(34), (37)) (K, 3) [rad/s].
        ds_quat: ``delta s`` (K, 3); ``ds_jac`` ``w_jac dt / 2`` (K, 3) (dimensionless).
    """

    dt: float
    t: Array
    v_jac: Array
    w_jac: Array
    v_diff: Array
    w_diff: Array
    v_mid: Array
    w_mid: Array
    qdot: Array
    qdot_pinv_jac: Array
    qdot_pinv_diff: Array
    w_quat: Array
    ds_quat: Array
    ds_jac: Array
    errors: dict[str, float] = field(default_factory=dict)


ERRORS = {
    "v_x": ("Part 1", "x velocity, differenced FK - Jacobian", "m/s"),
    "v": ("Part 1", "linear velocity (norm)", "m/s"),
    "w_x": ("Part 1", "x angular velocity, eq. (35) - Jacobian", "rad/s"),
    "w": ("Part 1", "angular velocity (norm)", "rad/s"),
    "v_mid": ("Part 1", "linear velocity (norm), Jacobian at t - dt/2", "m/s"),
    "w_mid": ("Part 1", "angular velocity (norm), Jacobian at t - dt/2", "rad/s"),
    "qdot1_pinv_jac": ("Part 2", "joint 1 rate, J^+ of the Jacobian's velocity", "rad/s"),
    "qdot_pinv_jac": ("Part 2", "joint rates (norm), J^+ of the Jacobian's velocity", "rad/s"),
    "qdot1_pinv_diff": ("Part 2", "joint 1 rate, J^+ of differenced FK", "rad/s"),
    "qdot_pinv_diff": ("Part 2", "joint rates (norm), J^+ of differenced FK", "rad/s"),
    "qdot_sampling": ("Part 2", "joint rates (norm), J^+ (differenced - Jacobian)", "rad/s"),
    "w_quat": ("Part 3", "rotation rate (norm), 2 delta s / dt - Jacobian", "rad/s"),
    "ds_beta": ("Part 3", "delta beta - w_x dt / 2", "1"),
    "ds_gamma": ("Part 3", "delta gamma - w_y dt / 2", "1"),
}
"""Error name: (part, what, unit). Each is the largest absolute value over the run."""


def sample(arm: Any, trajectory: Trajectory, dt: float) -> Sampled:
    """Run Parts 1-3 of the study on ``trajectory`` sampled every ``dt`` seconds.

    Args:
        arm: The robot (``rrc_pin.load("rrc_k1607")``).
        trajectory: The test joint trajectories.
        dt: Sampling time [s], at most a tenth of the duration.

    Returns:
        The per-sample velocities and the largest errors (:data:`ERRORS`) in ``errors``.
    """
    if not (np.isfinite(dt) and 0.0 < dt <= trajectory.duration / 10.0):
        raise ValueError(f"dt: expected 0 < dt <= duration / 10, got {dt!r}")
    n = round(trajectory.duration / dt)
    times = np.arange(n + 1) * dt
    Q = trajectory.q(times)
    poses = np.array([arm.fk(q) for q in Q])
    p, R = poses[:, :3, 3], poses[:, :3, :3]
    t = times[1:]
    qdot = trajectory.qdot(t)
    J = np.array([arm.jacobian(q) for q in Q[1:]])
    xdot = np.einsum("kij,kj->ki", J, qdot)
    mid = t - dt / 2.0
    J_mid = np.array([arm.jacobian(q) for q in trajectory.q(mid)])
    xdot_mid = np.einsum("kij,kj->ki", J_mid, trajectory.qdot(mid))
    # Part 1: differenced FK; differential rotation from the skew part of R_k R_{k-1}^T
    # (Nguyen eqs. (35)-(36) corrected: dR ~ I + delta^x).
    v_diff = np.diff(p, axis=0) / dt
    dR = np.einsum("kij,klj->kil", R[1:], R[:-1])
    skew = 0.5 * (dR - np.transpose(dR, (0, 2, 1)))
    w_diff = np.stack([skew[:, 2, 1], skew[:, 0, 2], skew[:, 1, 0]], axis=1) / dt
    # Part 2: the pseudo-inverse back to joint rates.
    J_pinv = np.linalg.pinv(J)
    qdot_pinv_jac = np.einsum("kij,kj->ki", J_pinv, xdot)
    qdot_pinv_diff = np.einsum("kij,kj->ki", J_pinv, np.hstack([v_diff, w_diff]))
    # Part 3: the quaternion of the orientation difference, eqs. (33)-(34), and eq. (37).
    quats = quaternion_from_matrix(R)
    dq = quaternion_difference(quats[:-1], quats[1:])
    dq *= np.where(dq[:, :1] < 0.0, -1.0, 1.0)  # the short way round
    w_quat = differential_rotation(dq) / dt
    out = Sampled(
        dt=dt,
        t=t,
        v_jac=xdot[:, :3],
        w_jac=xdot[:, 3:],
        v_diff=v_diff,
        w_diff=w_diff,
        v_mid=xdot_mid[:, :3],
        w_mid=xdot_mid[:, 3:],
        qdot=qdot,
        qdot_pinv_jac=qdot_pinv_jac,
        qdot_pinv_diff=qdot_pinv_diff,
        w_quat=w_quat,
        ds_quat=dq[:, 1:],
        ds_jac=xdot[:, 3:] * dt / 2.0,
    )
    out.errors = largest_errors(out)
    return out


def largest_errors(s: Sampled) -> dict[str, float]:
    """The largest absolute errors of one sampled run, keyed as :data:`ERRORS`."""

    def top(x: Array) -> float:
        return float(np.max(np.abs(x)))

    def top_norm(x: Array) -> float:
        return float(np.max(np.linalg.norm(x, axis=1)))

    return {
        "v_x": top(s.v_diff[:, 0] - s.v_jac[:, 0]),
        "v": top_norm(s.v_diff - s.v_jac),
        "w_x": top(s.w_diff[:, 0] - s.w_jac[:, 0]),
        "w": top_norm(s.w_diff - s.w_jac),
        "v_mid": top_norm(s.v_diff - s.v_mid),
        "w_mid": top_norm(s.w_diff - s.w_mid),
        "qdot1_pinv_jac": top(s.qdot_pinv_jac[:, 0] - s.qdot[:, 0]),
        "qdot_pinv_jac": top_norm(s.qdot_pinv_jac - s.qdot),
        "qdot1_pinv_diff": top(s.qdot_pinv_diff[:, 0] - s.qdot[:, 0]),
        "qdot_pinv_diff": top_norm(s.qdot_pinv_diff - s.qdot),
        "qdot_sampling": top_norm(s.qdot_pinv_diff - s.qdot_pinv_jac),
        "w_quat": top_norm(s.w_quat - s.w_jac),
        "ds_beta": top(s.ds_quat[:, 0] - s.ds_jac[:, 0]),
        "ds_gamma": top(s.ds_quat[:, 1] - s.ds_jac[:, 1]),
    }


def fitted_order(dts: Sequence[float], errors: Sequence[float]) -> float:
    """Slope ``p`` of the least-squares line ``log e = p log dt + c`` (``e ~ dt^p``).

    An error that does not depend on ``dt`` fits ``p ~ 0``; a zero error (exact to
    round-off everywhere) is floored at 1e-300 so that the fit stays finite.
    """
    x = np.log(np.asarray(dts, dtype=float))
    y = np.log(np.maximum(np.asarray(errors, dtype=float), 1e-300))
    slope = np.polyfit(x, y, 1)[0]
    return float(slope)


def trajectory_bounds(arm: Any, trajectory: Trajectory, dt: float = 0.001) -> dict[str, float]:
    """Peaks of the tool's speed and acceleration along ``trajectory`` (finely sampled).

    Returns:
        ``speed`` [m/s], ``accel`` [m/s^2] (both of the tool origin; ``accel_x`` the
        largest x component), ``omega`` [rad/s],
        ``qdot`` (largest joint rate) [rad/s], ``tool_frequency`` = accel / speed [rad/s]
        and the smallest singular value of ``J`` along the run (``sigma_min``).
    """
    times = np.arange(round(trajectory.duration / dt) + 1) * dt
    Q = trajectory.q(times)
    J = np.array([arm.jacobian(q) for q in Q])
    xdot = np.einsum("kij,kj->ki", J, trajectory.qdot(times))
    v = xdot[:, :3]
    a = np.gradient(v, dt, axis=0)
    speed = float(np.max(np.linalg.norm(v, axis=1)))
    accel = float(np.max(np.linalg.norm(a, axis=1)))
    return {
        "speed": speed,
        "accel": accel,
        "accel_x": float(np.max(np.abs(a[:, 0]))),
        "omega": float(np.max(np.linalg.norm(xdot[:, 3:], axis=1))),
        "qdot": float(np.max(np.abs(trajectory.qdot(times)))),
        "tool_frequency": accel / speed,
        "sigma_min": float(np.min(np.linalg.svd(J, compute_uv=False)[:, -1])),
    }


def longest_period(accel: float, tolerance: float) -> float:
    """Longest sampling time [s] whose backward-difference velocity error stays under
    ``tolerance`` [m/s]: ``(dt / 2) accel <= tolerance``, ``accel`` the peak [m/s^2]."""
    return 2.0 * tolerance / accel


def study(
    trajectory: Trajectory = TRAJECTORY,
    dts: Sequence[float] = SAMPLING_TIMES,
    speeds: Sequence[float] = (0.5, 1.0, 2.0),
    arm: Any = None,
) -> dict[str, Any]:
    """The whole study: errors per ``dt``, fitted orders, criterion (JSON-ready but ``runs``).

    Args:
        trajectory: Test trajectory (default :data:`TRAJECTORY`).
        dts: Sampling times [s] (at least two).
        speeds: Time scales of the trajectory for the criterion table (errors at each ``dt``).
        arm: The robot; default ``rrc_pin.load("rrc_k1607")``.

    Returns:
        ``errors`` (name -> largest error per dt), ``orders`` (:func:`fitted_order`),
        ``bounds`` (:func:`trajectory_bounds`), ``by_speed`` (one row per time scale:
        ``time_scale``, its bounds and the errors ``v_x``, ``v``, ``w`` per dt), the
        trajectory, and ``runs`` (dt -> :class:`Sampled`, not JSON).
    """
    arm = arm if arm is not None else rrc_pin.load(ARM)
    runs = {dt: sample(arm, trajectory, dt) for dt in dts}
    errors = {name: [runs[dt].errors[name] for dt in dts] for name in ERRORS}
    orders = {name: fitted_order(dts, errors[name]) for name in ERRORS}
    by_speed = []
    for speed in speeds:
        traj = trajectory.scaled(speed)
        bounds = trajectory_bounds(arm, traj)
        errs = {dt: sample(arm, traj, dt).errors for dt in dts}
        by_speed.append(
            {
                "time_scale": speed,
                **bounds,
                "v_x": [errs[dt]["v_x"] for dt in dts],
                "v": [errs[dt]["v"] for dt in dts],
                "w": [errs[dt]["w"] for dt in dts],
            }
        )
    return {
        "arm": ARM,
        "trajectory": {
            "theta0": list(trajectory.theta0),
            "amplitude": list(trajectory.amplitude),
            "period": list(trajectory.period),
            "phase": list(trajectory.phase),
            "duration": trajectory.duration,
        },
        "dts": list(dts),
        "errors": errors,
        "orders": orders,
        "bounds": trajectory_bounds(arm, trajectory),
        "by_speed": by_speed,
        "runs": runs,
    }
