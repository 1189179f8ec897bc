"""Rigid-body inertial parameters of one link, as the URDF ``<inertial>`` element holds them.

A :class:`LinkInertial` is a mass, a centre of mass and a rotational inertia about the centre
of mass, both in the axes of one frame (the URDF link frame once written). It is physically
consistent by construction: positive mass, symmetric inertia with positive principal moments
satisfying the triangle inequality ``I_a + I_b >= I_c`` (a real mass distribution's).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import as_array, finite_number

TRIANGLE_TOL = 1e-12
"""Slack [kg m^2] of the triangle inequality on the principal moments (rounding only)."""


@dataclass(frozen=True)
class LinkInertial:
    """Mass, centre of mass and inertia of a rigid link.

    Attributes:
        mass: Mass [kg], > 0.
        com: Centre of mass (3,) [m] in the reference frame.
        inertia: Rotational inertia (3, 3) [kg m^2] about the centre of mass, in the axes of
            the reference frame; symmetric, principal moments > 0 and satisfying the
            triangle inequality.

    Raises:
        InvalidInput: At construction, a value that no rigid body has (naming the field).
    """

    mass: float
    com: tuple[float, float, float]
    inertia: tuple[tuple[float, float, float], ...]

    def __post_init__(self) -> None:
        finite_number(self.mass, "mass", lower=0.0, inclusive=False)
        as_array(self.com, "com", (3,))
        inertia = as_array(self.inertia, "inertia", (3, 3))
        if not np.allclose(inertia, inertia.T, rtol=0.0, atol=1e-12):
            raise InvalidInput("inertia", "must be symmetric")
        moments = np.linalg.eigvalsh(inertia)
        if moments[0] <= 0.0:
            raise InvalidInput("inertia", f"principal moments must be > 0, got {moments}")
        if moments[0] + moments[1] < moments[2] - TRIANGLE_TOL:
            raise InvalidInput(
                "inertia", f"principal moments {moments} break the triangle inequality"
            )

    @property
    def com_array(self) -> npt.NDArray[np.float64]:
        """Centre of mass as a (3,) array [m]."""
        return np.array(self.com, dtype=float)

    @property
    def inertia_array(self) -> npt.NDArray[np.float64]:
        """Inertia about the centre of mass as a (3, 3) array [kg m^2]."""
        return np.array(self.inertia, dtype=float)

    def moved(self, T: npt.ArrayLike) -> LinkInertial:
        """The same body seen from another frame: ``T`` is the old frame's pose in the new one.

        ``com' = R com + p`` and ``I' = R I R^T``. ``R`` may be a reflection (det -1): a
        mirrored body (see :mod:`rrc_pin.models.puma560_inertia`).

        Args:
            T: (4, 4) homogeneous transform, rotation part orthogonal.
        """
        T = np.asarray(T, dtype=float)
        R, p = T[:3, :3], T[:3, 3]
        return make(self.mass, R @ self.com_array + p, R @ self.inertia_array @ R.T)


def make(mass: float, com: npt.ArrayLike, inertia: npt.ArrayLike) -> LinkInertial:
    """A :class:`LinkInertial` from arrays (symmetrised to remove rounding)."""
    c = np.asarray(com, dtype=float)
    inertia_matrix = np.asarray(inertia, dtype=float)
    inertia_matrix = (inertia_matrix + inertia_matrix.T) / 2.0
    return LinkInertial(
        mass=float(mass),
        com=(float(c[0]), float(c[1]), float(c[2])),
        inertia=tuple((float(r[0]), float(r[1]), float(r[2])) for r in inertia_matrix),
    )


def cylinder(mass: float, radius: float, end: npt.ArrayLike) -> LinkInertial:
    """A uniform solid cylinder from the frame origin to ``end`` (a sphere-like stub if short).

    ``I = m r^2 / 2`` about its axis ``u`` and ``m (3 r^2 + L^2) / 12`` across it; a segment
    shorter than ``2 radius`` is taken as a cylinder of length ``2 radius`` along z centred on
    the origin.

    Args:
        mass: Mass [kg], > 0.
        radius: Radius [m], > 0.
        end: Far end (3,) [m] of the axis, in the reference frame.
    """
    radius = finite_number(radius, "radius", lower=0.0, inclusive=False)
    end = as_array(end, "end", (3,))
    length = float(np.linalg.norm(end))
    u: npt.NDArray[np.float64]
    centre: npt.NDArray[np.float64]
    if length < 2.0 * radius:
        u, length, centre = np.array([0.0, 0.0, 1.0]), 2.0 * radius, np.zeros(3)
    else:
        u, centre = end / length, end / 2.0
    along = np.outer(u, u)
    inertia = mass * radius**2 / 2.0 * along + mass * (3.0 * radius**2 + length**2) / 12.0 * (
        np.eye(3) - along
    )
    return make(mass, centre, inertia)
