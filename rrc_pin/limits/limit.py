"""What every limit is: the constraints it puts on one tick's joint rates (pink's pattern).

A limit gives, at each tick, a :class:`~rrc_pin.solvers.tick.problem.Constraints`: a box
``lb <= qdot <= ub``, inequality rows ``G qdot <= h`` and equality rows ``C qdot = d``, each
row named for the report. The resolver merges every limit's constraints into one problem
(the boxes intersected, the rows stacked) and keeps them all at every answer: exactly for the
box (in floating point), to the backend's tolerance for rows.

A user's limit is one class in one file::

    class FloorLimit(Limit):
        def __init__(self, frame: str, height: float) -> None:
            self.frame, self.height, self.name = frame, height, f"floor:{frame}"

        def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
            z = kin.pose(self.frame)[2, 3]
            g = -kin.jacobian(self.frame)[2:3]          # -z_dot <= (z - height) / dt
            return Constraints(G=g, h=np.array([(z - self.height) / dt]), names=(self.name,))
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.tick.problem import Constraints

if TYPE_CHECKING:
    from rrc_pin.kinematics import Kinematics, Layout

Array = npt.NDArray[np.float64]


class Limit(ABC):
    """A limit of a resolution: the constraints on one tick's joint rates.

    Attributes:
        name: Name in the resolution's report (its rows' names start with it).
    """

    name: str

    def check(self, layout: Layout) -> None:  # noqa: B027 - optional hook
        """Refuse a limit that does not fit the robot (when a Resolver is built).

        Raises:
            InvalidInput: What does not fit, named.
            FrameNotFound: A frame the robot does not have.
        """

    @abstractmethod
    def constraints(self, kin: Kinematics, dt: float, previous: Array) -> Constraints:
        """The constraints at the configuration of ``kin`` for a step of ``dt``.

        Args:
            kin: The tick's kinematics (q, frame Jacobians and poses).
            dt: The step [s].
            previous: The joint rates of the previous tick (nv,) [rad/s or m/s].
        """
