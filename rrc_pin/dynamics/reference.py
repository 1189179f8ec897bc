"""Desired motion: a hand path, turned into joint references by resolved-rate integration.

The hand path is a polyline of tool positions visited by minimum-jerk segments
(``s = 10 tau^3 - 15 tau^4 + 6 tau^5``), orientation held. :class:`JointTrajectory` integrates
it with :class:`rrc_pin.Resolver` (public API) at the resolver's period, with a proportional
pull on the pose error so that the integration does not drift, and interpolates the joint
samples by a clamped cubic spline: positions, velocities and accelerations at any time, the
joint reference of Nguyen & Zhou's Fig. 11.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from scipy.interpolate import CubicSpline

from rrc_pin.dynamics.pose_error import pose_error
from rrc_pin.dynamics.state import Reference
from rrc_pin.errors import InvalidInput
from rrc_pin.resolver import Resolver
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import as_array, as_vector, finite_number

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class HandPath:
    """Tool positions ``start + offsets[k]`` visited one per ``segment`` seconds.

    Attributes:
        start: Initial tool pose (4, 4), base frame; its orientation is held.
        offsets: Waypoints (k, 3) [m] relative to the start position (the first is usually 0).
        segment: Duration [s] of each of the k - 1 minimum-jerk segments, > 0.
    """

    start: Array
    offsets: Array
    segment: float

    def __post_init__(self) -> None:
        as_array(self.start, "start", (4, 4))
        offsets = as_array(self.offsets, "offsets", (None, 3))
        if offsets.shape[0] < 2:
            raise InvalidInput("offsets", "expected at least two waypoints")
        finite_number(self.segment, "segment", 0.0, inclusive=False)

    @property
    def duration(self) -> float:
        """Time [s] to the last waypoint."""
        return self.segment * (len(self.offsets) - 1)

    def at(self, t: float) -> tuple[Array, Array]:
        """Desired pose (4, 4) and twist (6,) ``[v; w]`` (base axes) at time ``t`` [s]."""
        offsets = np.asarray(self.offsets, dtype=float)
        k = int(np.clip(t // self.segment, 0, len(offsets) - 2))
        tau = float(np.clip(t / self.segment - k, 0.0, 1.0))
        s = tau**3 * (10.0 - 15.0 * tau + 6.0 * tau**2)
        ds = 30.0 * tau**2 * (1.0 - tau) ** 2 / self.segment
        step = offsets[k + 1] - offsets[k]
        pose = np.array(self.start, dtype=float)
        pose[:3, 3] += offsets[k] + s * step
        inside = 0.0 <= t <= self.duration
        return pose, np.concatenate([step * ds * inside, np.zeros(3)])


class JointTrajectory:
    """Joint references from a hand path: resolved-rate integration, then a cubic spline.

    Args:
        robot: The arm.
        q0: Initial joints (nq,) [rad]; the path should start at ``fk(q0)``.
        path: The hand path.
        duration: Time [s] covered (the path holds its last pose after its end).
        period: Resolver period [s] (default 0.01, its default).
        pull: Gain [1/s] on the pose error added to the path's twist.

    Raises:
        InvalidInput: A bad argument (named).
    """

    def __init__(
        self,
        robot: Robot,
        q0: npt.ArrayLike,
        path: HandPath,
        duration: float,
        *,
        period: float = 0.01,
        pull: float = 10.0,
    ) -> None:
        q = as_vector(q0, "q0", robot.nq).copy()
        duration = finite_number(duration, "duration", 0.0, inclusive=False)
        period = finite_number(period, "period", 0.0, inclusive=False)
        pull = finite_number(pull, "pull", 0.0)
        resolver = Resolver(robot, dt=period)
        times = np.arange(0.0, duration + period, period)
        samples = [q]
        for t in times[:-1]:
            pose, twist = path.at(t + period)
            twist = twist + pull * pose_error(robot.fk(q), pose)
            q = q + period * resolver.solve(q, twist).qdot
            samples.append(q)
        self.robot = robot
        self.path = path
        self.duration = duration
        self.spline = CubicSpline(times, np.array(samples), axis=0, bc_type="clamped")

    def at(self, t: float, force: npt.ArrayLike | None = None) -> Reference:
        """The :class:`Reference` at time ``t`` [s] (held at the end), with ``force`` (3,) [N]."""
        t = min(max(t, 0.0), float(self.spline.x[-1]))
        q = self.spline(t)
        v = self.spline(t, 1)
        a = self.spline(t, 2)
        return Reference(
            q=q,
            v=v,
            a=a,
            pose=self.robot.fk(q),
            twist=self.robot.jacobian(q) @ v,
            force=np.zeros(3) if force is None else np.asarray(force, dtype=float),
        )
