"""Joint drives: reflected rotor inertia (armature) and friction, per arm.

A URDF carries link inertias only; the motors' reflected inertia ``Jm G^2`` and the joint
friction live here. For ``barker6`` they are the PUMA 560's published values (Corke &
Armstrong-Helouvry 1994, as in Corke's ``puma560`` model): rotor inertia ``Jm``, gear ratio
``G``, viscous ``B`` and Coulomb ``Tc`` friction at the motor, reflected to the joint as
``Jm G^2``, ``B G^2`` and ``Tc |G|`` (Coulomb: the mean of the two directions' magnitudes).
For ``rrc_k1607`` they are assumed (harmonic-drive class); other arms get none.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import as_array

_PUMA_JM = np.array([200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6])  # [kg m^2]
_PUMA_G = np.array([-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686])
_PUMA_B = np.array([1.48e-3, 0.817e-3, 1.38e-3, 71.2e-6, 82.6e-6, 36.7e-6])  # [N m s/rad]
_PUMA_TC = np.array(  # [N m], (+, -) magnitudes at the motor
    [
        (0.395, 0.435),
        (0.126, 0.071),
        (0.132, 0.105),
        (11.2e-3, 16.9e-3),
        (9.26e-3, 14.5e-3),
        (3.96e-3, 10.5e-3),
    ]
)


@dataclass(frozen=True)
class Drives:
    """Joint-side drive parameters, each (nq,) and >= 0.

    Attributes:
        armature: Reflected rotor inertia [kg m^2], added to the mass matrix diagonal.
        viscous: Viscous friction [N m s/rad].
        coulomb: Coulomb friction magnitude [N m].
    """

    armature: npt.NDArray[np.float64]
    viscous: npt.NDArray[np.float64]
    coulomb: npt.NDArray[np.float64]

    def __post_init__(self) -> None:
        size: int | None = None  # the armature's length; the others must match it
        for label in ("armature", "viscous", "coulomb"):
            values = as_array(getattr(self, label), label, (size,))
            size = values.shape[0]
            if np.any(values < 0.0):
                raise InvalidInput(label, "every entry must be >= 0")


def none(nq: int) -> Drives:
    """No armature, no friction."""
    return Drives(np.zeros(nq), np.zeros(nq), np.zeros(nq))


def drives_of(name: str, nq: int) -> Drives:
    """The drives of a catalogue arm (``barker6``, ``rrc_k1607``), else :func:`none`."""
    if name == "barker6":
        return Drives(
            armature=_PUMA_JM * _PUMA_G**2,
            viscous=_PUMA_B * _PUMA_G**2,
            coulomb=_PUMA_TC.mean(axis=1) * np.abs(_PUMA_G),
        )
    if name == "rrc_k1607":  # assumed: 1e-4 kg m^2 rotors behind 100:1 and 50:1 drives
        return Drives(
            armature=np.array([1.0, 1.0, 0.5, 0.5, 0.25, 0.25, 0.25]),
            viscous=np.array([5.0, 5.0, 3.0, 3.0, 1.0, 1.0, 1.0]),
            coulomb=np.array([5.0, 5.0, 3.0, 3.0, 1.0, 1.0, 1.0]),
        )
    return none(nq)
