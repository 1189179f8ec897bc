r"""The centre of mass of one tick and its Jacobian, from the tick's kinematics.

:math:`c = \sum_i m_i c_i / \sum_i m_i` over every body of the model [m], in the base frame
(the world, for a robot on a floating base), and :math:`J_c` (3, nv) with
:math:`\dot c = J_c \dot q` (Pinocchio's ``jacobianCenterOfMass``, on the joint Jacobians
the tick computed already: nothing is recomputed at another configuration).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.kinematics import Kinematics

Array = npt.NDArray[np.float64]


class CenterOfMass(NamedTuple):
    """The centre of mass at one configuration.

    Attributes:
        position: (3,) [m] in the base frame.
        jacobian: (3, nv) [m/rad or 1]: its velocity per joint rate.
    """

    position: Array
    jacobian: Array


def center_of_mass(kin: Kinematics) -> CenterOfMass:
    """The centre of mass and its Jacobian at the configuration of ``kin``."""
    data = kin.data  # every joint's placement and Jacobian at q
    J = np.array(pin.jacobianCenterOfMass(kin.model, data, True))
    return CenterOfMass(np.array(data.com[0]), J)


def check_mass(model: pin.Model) -> None:
    """Refuse a model without mass (no centre of mass to speak of).

    Raises:
        InvalidInput: Naming ``robot``: every body's mass is zero.
    """
    if not sum(inertia.mass for inertia in model.inertias) > 0.0:
        raise InvalidInput("robot", "its model has no mass: no centre of mass (give the URDF "
                           "<inertial> elements)")  # fmt: skip
