"""What a controller reads: the measured :class:`State` and the desired :class:`Reference`."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class State:
    """What the arm's sensors report at one instant.

    Attributes:
        t: Time [s].
        q: Joint positions (nq,) [rad].
        v: Joint velocities (nq,) [rad/s].
        force: Force the tool exerts on the environment (3,) [N], base axes (a wrist
            force sensor's reading; zero in free space).
    """

    t: float
    q: Array
    v: Array
    force: Array = field(default_factory=lambda: np.zeros(3))


@dataclass(frozen=True)
class Reference:
    """What the arm should do at one instant: joint and tool motion, and a contact force.

    The tool pose and twist are those of the joint reference (``fk(q)`` and ``J(q) v``), so
    that joint-space and Cartesian controllers chase the same motion.

    Attributes:
        q: Desired joint positions (nq,) [rad].
        v: Desired joint velocities (nq,) [rad/s].
        a: Desired joint accelerations (nq,) [rad/s^2].
        pose: Desired tool pose (4, 4) in the base frame [m].
        twist: Desired tool twist (6,) ``[v; w]`` in ``world_aligned`` axes [m/s, rad/s].
        force: Desired force the tool exerts on the environment (3,) [N], base axes.
    """

    q: Array
    v: Array
    a: Array
    pose: Array
    twist: Array
    force: Array = field(default_factory=lambda: np.zeros(3))
