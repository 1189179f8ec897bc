r"""Pose-drift correction: the integrated reference pose and a bounded twist toward it.

Integrating joint rates (Barker eq. (21)) moves the hand along the commanded twist only to
first order in ``dt``: over minutes the pose drifts from the one the operator commanded. The
controller keeps that commanded pose (the reference, advanced by the commanded twist every
tick) and adds a bounded proportional twist toward it. Its orientation error is Nguyen's
quaternion difference, eqs. (32)-(34), turned into differential rotations by eq. (37)
(:mod:`solvers.closed_form.quaternion`):

.. math::

    \dot x_c = \mathrm{clip}\big(k\,[p_r - p;\ 2\,\delta s(Q\{R\}, Q\{R_r\})]\big)

in ``world_aligned`` axes, the linear and angular parts each clipped to its bound.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from solvers.closed_form.quaternion import (
    differential_rotation,
    quaternion_difference,
    quaternion_from_matrix,
)
from solvers.validation import finite_number

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class DriftCorrection:
    """Gain and bounds of the twist that pulls the hand back to its reference pose.

    Attributes:
        gain: Proportional gain [1/s], >= 0 (the error decays as ``exp(-gain t)`` when no
            bound is reached).
        max_linear: Largest correcting speed [m/s], >= 0.
        max_angular: Largest correcting angular rate [rad/s], >= 0.
        period: Time [s] between two measurements of the pose error, > 0; the correcting
            twist is held in between (``gain * period`` < 2 keeps the sampled loop stable).
            Measuring every tick would cost more than the rest of the controller's tick:
            Nguyen's quaternion functions take about 0.1 ms per call (measured).

    Raises:
        InvalidInput: A field that is negative or not finite, named.
    """

    gain: float = 2.0
    max_linear: float = 0.01
    max_angular: float = 0.05
    period: float = 0.1

    def __post_init__(self) -> None:
        for name in ("gain", "max_linear", "max_angular"):
            finite_number(getattr(self, name), name, 0.0, error=InvalidInput)
        finite_number(self.period, "period", 0.0, inclusive=False, error=InvalidInput)

    def twist(self, linear: Array, angular: Array) -> Array:
        """Correcting twist (6,) [m/s, rad/s], ``world_aligned``, from the pose error.

        Args:
            linear: Position error (3,) [m], reference minus current, base axes.
            angular: Differential rotation (3,) [rad] to the reference (:func:`pose_error`).
        """
        out = np.concatenate([_clip(self.gain * linear, self.max_linear),
                              _clip(self.gain * angular, self.max_angular)])  # fmt: skip
        return out


def pose_error(pose: Array, reference: Array) -> tuple[Array, Array]:
    """Position error [m] and differential rotation [rad] (Nguyen eq. (37)), base axes, (3,) each.

    The rotation error is that of ``R_ref R^T`` (Nguyen eqs. (32)-(34)): the small rotation
    about the base axes that brings the current hand axes to the reference ones.
    """
    # Both quaternions from one call on the stack: a third less time than two calls (measured).
    current, wanted = quaternion_from_matrix(np.stack([pose[:3, :3], reference[:3, :3]]))
    dq = quaternion_difference(current, wanted)
    return reference[:3, 3] - pose[:3, 3], differential_rotation(dq)


def advance(reference: Array, twist: Array, dt: float, local: bool) -> Array:
    """The reference pose (4, 4) moved by a constant ``twist`` (6,) for ``dt`` [s].

    ``local`` (hand axes): the screw motion ``T exp(twist dt)``; else ``world_aligned``: the
    origin moves by ``v dt`` and the axes turn by ``exp(w dt)`` about the base axes.
    """
    out: Array = reference.copy()
    if local:
        moved: Array = out @ pin.exp6(pin.Motion(twist[:3] * dt, twist[3:] * dt)).homogeneous
        return moved
    out[:3, 3] += twist[:3] * dt
    out[:3, :3] = pin.exp3(twist[3:] * dt) @ reference[:3, :3]
    return out


def _clip(x: Array, bound: float) -> Array:
    """``x`` scaled down to norm ``bound`` if longer."""
    n = float(np.linalg.norm(x))
    out: Array = x * (bound / n) if n > bound else x
    return out
