"""The one interface of every control scheme: state and reference in, motor torques out."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Literal

import numpy as np
import numpy.typing as npt

from rrc_pin.dynamics.state import Reference, State
from rrc_pin.errors import InvalidInput
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import as_vector, finite_number, real_array

Array = npt.NDArray[np.float64]


class Controller(ABC):
    """A control law at a fixed rate, saturated at the motors' torque limits.

    Subclasses write :meth:`law`; :meth:`torques` clips its answer to ``torque_limit``, and
    answers zero torque (counted in :attr:`faults`) should the law ever
    produce a non-finite number, so that no NaN reaches the motors.

    Args:
        robot: The controlled arm (its nominal model: no payload, no armature).
        dt: Control period [s], > 0 (the integrals of the adaptive laws use it).
        torque_limit: Motor torque limits (nq,) [N m]; default the URDF's efforts.

    Raises:
        InvalidInput: A bad argument (named).
    """

    name = "controller"

    def __init__(
        self, robot: Robot, dt: float = 1e-3, torque_limit: npt.ArrayLike | None = None
    ) -> None:
        self.robot = robot
        self.dt = finite_number(dt, "dt", 0.0, inclusive=False)
        limit = robot.model.effortLimit if torque_limit is None else torque_limit
        self.torque_limit = as_vector(limit, "torque_limit", robot.nq)
        if np.any(self.torque_limit <= 0.0):
            raise InvalidInput("torque_limit", "every limit must be > 0")
        self.faults = 0

    @abstractmethod
    def law(self, state: State, ref: Reference) -> Array:
        """Unsaturated motor torques (nq,) [N m] for ``state`` chasing ``ref``."""

    def reset(self) -> None:
        """Forget adapted values and integrals (a fixed-gain law has none)."""
        self.faults = 0

    def torques(self, state: State, ref: Reference) -> Array:
        """Motor torques (nq,) [N m], each within its limit, never NaN."""
        tau = self.law(state, ref)
        if not np.all(np.isfinite(tau)):
            self.faults += 1
            return np.zeros(self.robot.nq)
        return np.clip(tau, -self.torque_limit, self.torque_limit)


def gains(
    value: npt.ArrayLike,
    name: str,
    size: int,
    *,
    sign: Literal["positive", "nonnegative", "any"] = "positive",
    infinite: bool = False,
) -> Array:
    """A gain as a (size,) float array; a scalar is broadcast.

    Args:
        value: Scalar or (size,) values.
        name: Argument name for the error.
        size: Number of axes.
        sign: ``positive`` (> 0), ``nonnegative`` (>= 0) or ``any``.
        infinite: Whether +-inf is accepted (a bound); NaN never is.

    Raises:
        InvalidInput: Wrong shape, NaN, inf (unless allowed) or a wrong sign, naming ``name``.
    """
    arr = real_array(value, name, f"expected a number or {size} numbers")
    if arr.ndim == 0:
        arr = np.full(size, float(arr))
    if arr.shape != (size,):
        raise InvalidInput(name, f"expected a number or shape ({size},), got {arr.shape}")
    if np.any(np.isnan(arr)) or (not infinite and not np.all(np.isfinite(arr))):
        raise InvalidInput(name, f"expected finite numbers, got {arr}")
    if (sign == "positive" and np.any(arr <= 0.0)) or (sign == "nonnegative" and np.any(arr < 0.0)):
        raise InvalidInput(
            name, f"every entry must be {'> 0' if sign == 'positive' else '>= 0'}, got {arr}"
        )
    out: Array = arr.copy()
    return out
