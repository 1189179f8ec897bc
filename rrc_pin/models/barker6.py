"""Barker's 6-DOF PUMA-type arm (NASA TM-85685, 1983; DH table at the end of the report).

Standard DH (Barker eq. (1)), theta'_i = theta_i + offset with offsets 180, 90, 90, 180, 180, 0
deg, so that q = 0 is the initial position of Barker's figure 3. The report leaves NO, ES, SN,
WE, A3, R3 and alpha3 symbolic; the defaults are PUMA 560 values (assumed). The tool frame is
the wrist centre (frames 4, 5 and 6 coincide: r5 = r6 = 0 in the resolved-rate equations); the
``flange`` frame sits HW further along z6. Link inertial data: the PUMA 560's published values
(Corke & Armstrong-Helouvry 1994), mapped onto Barker's frames by
:mod:`rrc_pin.models.puma560_inertia`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rrc_pin.dh import DHChain, DHRow, pose, translation
from rrc_pin.models.arm_spec import ArmSpec, check_parameters
from rrc_pin.models.puma560_inertia import barker_inertials

if TYPE_CHECKING:
    from rrc_pin.solvers.closed_form.base import ClosedForm

NAME = "barker6"
JOINT_LIMITS_DEG = (160.0, 165.0, 135.0, 135.0, 105.0, 270.0)  # Barker's table, +-
OFFSETS_DEG = (180.0, 90.0, 90.0, 180.0, 180.0, 0.0)  # theta'_i - theta_i, Barker's table
VELOCITY_LIMIT = (2.0, 2.0, 2.0, 4.0, 4.0, 4.0)  # [rad/s], assumed (PUMA 560 class)
EFFORT_LIMIT = (100.0, 180.0, 90.0, 20.0, 20.0, 20.0)  # [N m], assumed
COLLISION_RADII = (0.10, 0.08, 0.06, 0.05, 0.04, 0.04)  # [m], assumed (PUMA 560 class)
READY = tuple(float(v) for v in np.deg2rad((0.0, 0.0, 90.0, 0.0, 45.0, 0.0)))  # chosen, see build

PUMA560 = {
    "no": 0.6718,  # neck-to-base [m]
    "es": 0.4318,  # elbow-to-shoulder [m]
    "sn": 0.15,  # shoulder-to-neck [m]
    "we": 0.4318,  # wrist-to-elbow [m]
    "a3": 0.0203,  # [m]
    "r3": 0.0,  # [m]
    "alpha3": np.pi / 2,  # [rad]
    "hw": 0.0563,  # hand-to-wrist [m]
}


def build(
    no: float = PUMA560["no"],
    es: float = PUMA560["es"],
    sn: float = PUMA560["sn"],
    we: float = PUMA560["we"],
    a3: float = PUMA560["a3"],
    r3: float = PUMA560["r3"],
    alpha3: float = PUMA560["alpha3"],
    hw: float = PUMA560["hw"],
    name: str = NAME,
) -> ArmSpec:
    """Barker's arm with the given geometry.

    Args:
        no: Neck-to-base length NO = r1 [m].
        es: Elbow-to-shoulder length ES = a2 [m].
        sn: Shoulder-to-neck length SN = r2 [m].
        we: Wrist-to-elbow length WE = r4 [m].
        a3: Link length a3 [m].
        r3: Offset r3 [m].
        alpha3: Twist alpha3 [rad] (90 deg nominal; Barker suggests it may differ).
        hw: Hand-to-wrist length HW [m], wrist centre to ``flange``.
        name: Catalogue name of the result (a variant should get its own).

    Returns:
        The arm's :class:`ArmSpec`.

    Raises:
        InvalidInput: A parameter is not a finite real number (named in the message).
    """
    params = check_parameters(
        {"no": no, "es": es, "sn": sn, "we": we, "a3": a3, "r3": r3, "alpha3": alpha3, "hw": hw}
    )
    no, es, sn, we, a3, r3, alpha3, hw = params.values()
    half_pi = np.pi / 2
    a = (0.0, es, a3, 0.0, 0.0, 0.0)
    alpha = (half_pi, 0.0, alpha3, half_pi, half_pi, 0.0)
    d = (no, sn, r3, we, 0.0, 0.0)
    rows = tuple(
        DHRow(a=a[i], alpha=alpha[i], d=d[i], theta=np.deg2rad(OFFSETS_DEG[i])) for i in range(6)
    )
    chain = DHChain(
        convention="standard",
        rows=rows,
        extra_frames=(("flange", pose(translation(z=hw))),),
    )
    limits = np.deg2rad(JOINT_LIMITS_DEG)
    assumed = [
        "joint velocity limits (2, 2, 2, 4, 4, 4) rad/s and efforts",
        "r6 = 0: tool frame at the wrist centre; HW moved to the `flange` frame",
        "link inertial data: PUMA 560 (Corke & Armstrong-Helouvry 1994), mirrored onto "
        "Barker's frames; link 1 mass and transverse moments, link 3 Izz raised",
        "collision capsule radii (0.10, 0.08, 0.06, 0.05, 0.04, 0.04) m along the DH offsets: "
        "PUMA 560 class link widths (the report gives none)",
        "ready pose (0, 0, 90, 0, 45, 0) deg: elbow bent 90 deg, wrist 45 deg, away from the "
        "limits and singularities (q = 0, Barker's initial position, has theta5 = 0: the "
        "wrist singular)",
    ]
    symbolic = {k: v for k, v in params.items() if not np.isclose(v, PUMA560[k])}
    if len(symbolic) < len(params):
        assumed.insert(
            0,
            "PUMA 560 values for the symbolic "
            + ", ".join(k.upper() for k in params if k not in symbolic),
        )

    def closed_form() -> ClosedForm:
        from rrc_pin.solvers.closed_form.barker import BarkerClosedForm

        return BarkerClosedForm(no=no, es=es, sn=sn, we=we, a3=a3, r3=r3, alpha3=alpha3)

    return ArmSpec(
        name=name,
        chain=chain,
        lower=tuple(-limits),
        upper=tuple(limits),
        velocity_limit=VELOCITY_LIMIT,
        effort_limit=EFFORT_LIMIT,
        source="Barker, NASA TM-85685 (1983), DH table and appendix A",
        assumed=tuple(assumed),
        named_poses={"paper_start": (0.0,) * 6, "ready": READY},
        closed_form=closed_form,
        parameters=params,
        inertials=barker_inertials(chain),
        collision_radii=COLLISION_RADII,
    )


SPEC = build()
