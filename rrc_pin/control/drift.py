r"""Pose-drift correction: the integrated reference pose and a bounded twist toward it.

Integrating joint rates (Barker eq. (21)) moves the hand along the commanded twist only to
first order in ``dt``: over minutes the pose drifts from the one the operator commanded. The
controller keeps that commanded pose (the reference, advanced by the commanded twist every
tick) and adds, every tick, a bounded proportional twist toward it. Its orientation error is
Nguyen's: the quaternion of the orientation difference (eqs. (31)-(34)) turned into
differential rotations by eq. (37), ``2 delta s``:

.. math::

    \dot x_c = \mathrm{clip}\big(k\,[p_r - p;\ 2\,\mathrm{sign}(\delta\eta)\,\delta s]\big)

in hand axes (the controller turns it into base axes for a base-axes command), the linear
and angular parts each clipped to its bound. The quaternion is Pinocchio's (one C++ call);
``tests/test_drift.py`` shows the error is what :mod:`rrc_pin.solvers.closed_form.quaternion` gives
from eqs. (32)-(34) and (37), to 1e-12.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.solvers.checks import finite_number
from rrc_pin.solvers.spatial import Reference

Array = npt.NDArray[np.float64]


@dataclass(frozen=True)
class DriftCorrection:
    """Gain and bounds of the twist that pulls the hand back to its reference pose.

    The pose error is measured and the twist applied at every tick (``gain * dt`` < 2 keeps
    the sampled loop stable).

    Attributes:
        gain: Proportional gain [1/s], >= 0 (the error decays as ``exp(-gain t)`` when no
            bound is reached).
        max_linear: Largest correcting speed [m/s], >= 0.
        max_angular: Largest correcting angular rate [rad/s], >= 0.

    Raises:
        InvalidInput: A field that is negative or not finite, named.
    """

    gain: float = 2.0
    max_linear: float = 0.01
    max_angular: float = 0.05

    def __post_init__(self) -> None:
        for name in ("gain", "max_linear", "max_angular"):
            finite_number(getattr(self, name), name, 0.0)

    def twist(self, error: Array) -> Array:
        """Correcting twist (6,) [m/s, rad/s] from the pose error, in the error's axes.

        Args:
            error: Position error [m] and differential rotation [rad] to the reference (6,)
                (:func:`pose_error`).
        """
        a = _gain(self.gain, self.max_linear, float(np.linalg.norm(error[:3])))
        b = _gain(self.gain, self.max_angular, float(np.linalg.norm(error[3:])))
        return np.concatenate([a * error[:3], b * error[3:]])


def pose_error(pose: pin.SE3, reference: pin.SE3) -> Array:
    """``[p_ref - p; delta]`` (6,) [m, rad] in hand axes: what takes ``pose`` to ``reference``.

    ``delta`` is Nguyen's differential rotation (eq. (37)): ``2 delta s`` of the quaternion
    of the orientation difference (eqs. (31)-(34)), with the sign of ``delta eta`` (``dq``
    and ``-dq`` are one rotation). Both parts are those of ``T^-1 T_ref``, so in hand axes:
    ``R^T`` times the base-axes error of
    :func:`rrc_pin.solvers.closed_form.quaternion.differential_rotation` applied to
    ``quaternion_difference(Q{R}, Q{R_ref})`` (the quaternion of ``R_ref R^T``), and
    ``R^T (p_ref - p)``.

    Args:
        pose: Current tool pose.
        reference: Reference pose.
    """
    xyzquat = pin.SE3ToXYZQUAT(pose.actInv(reference))  # T^-1 T_ref as (p, Q)
    two = 2.0 if xyzquat[6] >= 0.0 else -2.0  # eq. (37)
    return np.concatenate([xyzquat[:3], two * xyzquat[3:6]])


def advance(reference: pin.SE3, twist: Array, dt: float, ref: Reference) -> pin.SE3:
    """The reference pose moved by a ``twist`` (6,) held constant in frame ``ref`` for ``dt`` [s].

    ``local`` (hand axes): the screw motion ``T exp(twist dt)``; ``world`` (the spatial twist
    at the base origin): the screw motion ``exp(twist dt) T``; ``world_aligned``: the origin
    moves by ``v dt`` and the axes turn by ``exp(w dt)`` about the base axes.
    """
    if ref == "local":
        moved: pin.SE3 = reference * pin.exp6(twist * dt)
        return moved
    if ref == "world":
        turned: pin.SE3 = pin.exp6(twist * dt) * reference
        return turned
    return pin.SE3(pin.exp3(twist[3:] * dt) @ reference.rotation,
                   reference.translation + twist[:3] * dt)  # fmt: skip


def _gain(gain: float, bound: float, size: float) -> float:
    """``gain``, lowered so that ``gain * size`` stays within ``bound``."""
    return gain if gain * size <= bound else bound / size
