"""PUMA 560 link inertial parameters, mapped onto Barker's DH frames.

Source: the consensus values of P. Corke and B. Armstrong-Helouvry, "A search for consensus
among model parameters reported for the PUMA 560 robot", Proc. IEEE ICRA 1994, pp. 1608-1613
(masses and centres of mass from B. Armstrong, O. Khatib and J. Burdick, "The explicit dynamic
model and inertial parameters of the PUMA 560 arm", Proc. IEEE ICRA 1986), tabulated there in
the standard DH frames of Corke's PUMA 560 model (:data:`CORKE_DH`), the model also shipped as
``puma560`` with Corke's Robotics Toolbox. Principal inertias about the centre of mass, axes
of the link frame; products of inertia are zero in the source.

The mapping onto Barker's frames, stated and computed here once:

1. Barker's table with the PUMA 560 values assumed for its symbolic lengths is the *mirror
   image* of Corke's PUMA: at the upright pose, Barker's forearm offset ``a3`` lies on the
   +x side when the shoulder offset ``SN`` is on +y, Corke's on -x. No rigid motion maps one
   onto the other, so Corke's arm is reflected through its base y-z plane first
   (:data:`MIRROR`), and raised by Barker's ``NO`` (Corke's frame 0 is at the shoulder).
2. Joints then correspond as ``q_corke = SIGNS * q_barker + OFFSETS`` (every sense reversed
   by the reflection; ``q_barker = 0``, Barker's upright initial pose, is Corke's ``qr`` turned
   by 180 deg about joint 1).
3. Each link's data, given in Corke's frame i, is moved into Barker's DH frame i by the
   constant ``X_i = F_barker_i(0)^-1 F_corke_i(OFFSETS)`` and then into the URDF link frame
   by the DH row's fixed part (:func:`rrc_pin.urdf_export.split_row`). A test checks that
   ``X_i`` is the same at random configurations, which proves the correspondence.

Corke's ``SN`` is 0.15005 m against Barker's 0.15 m: the 0.05 mm difference is left in
``X_i`` (it moves link 3's centre of mass by 0.05 mm). Link 1: the source gives its mass as 0
(unknown) and only the inertia about joint 1 (0.35 kg m^2); a 1 kg mass on the axis and
transverse moments of 0.175 kg m^2 are assumed so that the body is physical (neither enters
the joint-space dynamics of a fixed-base arm). Link 3: the published principal moments (0.066,
0.086, 0.0125) kg m^2 break the triangle inequality (0.066 + 0.0125 < 0.086), which no mass
distribution can; Izz is raised to 0.020 kg m^2, the least that makes the body physical.
Rotor inertias (``Jm G^2``) and friction of the source are not part of a URDF and are left out.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.dh import DHChain, DHRow, translation
from rrc_pin.models.inertia import LinkInertial, make

HALF_PI = np.pi / 2
CORKE_DH = (  # (a [m], alpha [rad], d [m]) of Corke's standard DH PUMA 560
    (0.0, HALF_PI, 0.0),
    (0.4318, 0.0, 0.0),
    (0.0203, -HALF_PI, 0.15005),
    (0.0, HALF_PI, 0.4318),
    (0.0, -HALF_PI, 0.0),
    (0.0, 0.0, 0.0),
)
# (mass [kg], centre of mass [m], principal inertia Ixx, Iyy, Izz [kg m^2]) in Corke's frames
CORKE_LINKS = (
    (1.0, (0.0, 0.0, 0.0), (0.175, 0.35, 0.175)),  # mass and Ixx, Izz assumed (see above)
    (17.4, (-0.3638, 0.006, 0.2275), (0.13, 0.524, 0.539)),
    (4.8, (-0.0203, -0.0141, 0.070), (0.066, 0.086, 0.0200)),  # Izz raised (see above)
    (0.82, (0.0, 0.019, 0.0), (1.8e-3, 1.3e-3, 1.8e-3)),
    (0.34, (0.0, 0.0, 0.0), (0.3e-3, 0.4e-3, 0.3e-3)),
    (0.09, (0.0, 0.0, 0.032), (0.15e-3, 0.15e-3, 0.04e-3)),
)
MIRROR = np.diag([-1.0, 1.0, 1.0, 1.0])
"""Reflection through the base y-z plane (Corke's arm -> Barker's handedness)."""
SIGNS = np.full(6, -1.0)
OFFSETS = np.array([np.pi, HALF_PI, -HALF_PI, 0.0, 0.0, 0.0])
"""``q_corke = SIGNS * q_barker + OFFSETS`` [rad]."""


def corke_chain(neck: float) -> DHChain:
    """Corke's PUMA 560, mirrored and with its frame 0 at height ``neck`` [m] (Barker's NO)."""
    rows = tuple(DHRow(a=a, alpha=alpha, d=d, theta=0.0) for a, alpha, d in CORKE_DH)
    base = translation(z=neck) @ MIRROR
    return DHChain("standard", rows, base=tuple(tuple(float(x) for x in r) for r in base))


def corke_inertials() -> tuple[LinkInertial, ...]:
    """The source's six links, each in its own Corke DH frame."""
    return tuple(make(m, com, np.diag(moments)) for m, com, moments in CORKE_LINKS)


def link_to_corke(barker: DHChain) -> list[npt.NDArray[np.float64]]:
    """``X_i``: pose of Corke's frame i in Barker's DH frame i, i = 1..6, (4, 4) each.

    Args:
        barker: Barker's chain (standard DH, six joints; its first ``d`` is NO).
    """
    corke = corke_chain(barker.rows[0].d)
    F_barker = barker.frames(np.zeros(6))
    F_corke = corke.frames(OFFSETS)
    return [np.linalg.inv(F_barker[i]) @ F_corke[i] for i in range(1, 7)]


def barker_inertials(barker: DHChain) -> tuple[LinkInertial, ...]:
    """The PUMA 560 links in Barker's DH frames 1..6 (not yet the URDF link frames)."""
    return tuple(
        inertial.moved(X)
        for inertial, X in zip(corke_inertials(), link_to_corke(barker), strict=True)
    )
