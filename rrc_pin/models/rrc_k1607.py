"""The 7-DOF redundant Robotics Research Corporation K-1607 (Nguyen & Zhou, NAG 5-1124, 1990).

Craig's modified DH (Nguyen eq. (2)), Table 1 in inches converted here. Tool frame: frame 7's
origin. q = 0 is the home configuration of Nguyen's figure 2. Joint position and velocity
limits are not in the report (assumed, K-1607 class). Link inertial data are not in the report
either: each link is assumed a uniform solid cylinder along its segment (:data:`LINK_MASSES`,
:data:`LINK_RADII`), physically consistent by construction.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rrc_pin.dh import DHChain, DHRow, link_transform
from rrc_pin.models.arm_spec import INCH, ArmSpec
from rrc_pin.models.inertia import LinkInertial, cylinder

if TYPE_CHECKING:
    from rrc_pin.solvers.closed_form.base import ClosedForm

NAME = "rrc_k1607"
# Nguyen Table 1: alpha_{i-1} [deg], a_{i-1} [in], d_i [in]
TABLE_1 = (
    (0.0, 0.000, 0.0),
    (-90.0, 0.000, 0.0),
    (90.0, 5.625, 27.0),
    (-90.0, 4.250, 0.0),
    (90.0, -4.250, 27.0),
    (-90.0, 3.125, 0.0),
    (90.0, -3.125, 0.0),
)
LIMITS_DEG = (170.0, 120.0, 170.0, 135.0, 170.0, 120.0, 170.0)  # assumed
VELOCITY_LIMIT = (1.0, 1.0, 1.5, 1.5, 2.0, 2.0, 2.0)  # [rad/s], assumed
EFFORT_LIMIT = (140.0, 140.0, 70.0, 70.0, 20.0, 20.0, 20.0)  # [N m], assumed
LINK_MASSES = (8.0, 5.0, 2.0, 3.5, 1.5, 1.0, 0.5)  # [kg], assumed (upper arm: 2, forearm: 4)
LINK_RADII = (0.08, 0.06, 0.06, 0.05, 0.05, 0.04, 0.04)  # [m], assumed
READY = tuple(float(v) for v in np.deg2rad((0.0, 30.0, 0.0, 90.0, 0.0, 45.0, 0.0)))  # chosen


def cylinder_links(rows: tuple[DHRow, ...]) -> tuple[LinkInertial, ...]:
    """Link i as a solid cylinder from joint i to joint i + 1 (modified DH frame i).

    The segment's far end is the origin of frame i + 1 at q = 0 (the tool for the last link,
    a stub of one diameter along z).
    """
    ends = [link_transform(row, 0.0, "modified")[:3, 3].copy() for row in rows[1:]] + [np.zeros(3)]
    return tuple(
        cylinder(mass, radius, end)
        for mass, radius, end in zip(LINK_MASSES, LINK_RADII, ends, strict=True)
    )


def build(name: str = NAME) -> ArmSpec:
    """The K-1607 of Nguyen Table 1, in SI units."""
    rows = tuple(
        DHRow(a=a_in * INCH, alpha=np.deg2rad(alpha_deg), d=d_in * INCH, theta=0.0)
        for alpha_deg, a_in, d_in in TABLE_1
    )
    limits = np.deg2rad(LIMITS_DEG)

    def closed_form() -> ClosedForm:
        from rrc_pin.solvers.closed_form.rrc_k1607 import RrcK1607ClosedForm

        return RrcK1607ClosedForm(a=tuple(row.a for row in rows), d=tuple(row.d for row in rows))

    return ArmSpec(
        name=name,
        chain=DHChain(convention="modified", rows=rows),
        lower=tuple(-limits),
        upper=tuple(limits),
        velocity_limit=VELOCITY_LIMIT,
        effort_limit=EFFORT_LIMIT,
        source="Nguyen & Zhou, NASA NAG 5-1124 (1990), Table 1 (inches)",
        assumed=(
            "joint limits +-(170, 120, 170, 135, 170, 120, 170) deg",
            "velocity limits (1, 1, 1.5, 1.5, 2, 2, 2) rad/s and efforts",
            "link inertial data: solid cylinders of masses (8, 5, 2, 3.5, 1.5, 1, 0.5) kg",
            "link radii (0.08, 0.06, 0.06, 0.05, 0.05, 0.04, 0.04) m, of the inertial cylinders "
            "and the collision capsules along the DH offsets (the report gives no widths)",
            "ready pose (0, 30, 0, 90, 0, 45, 0) deg: shoulder 30 deg, elbow 90 deg, wrist "
            "45 deg, away from the limits and singularities (the home q = 0 is stretched out, "
            "singular)",
        ),
        named_poses={"home": (0.0,) * 7, "ready": READY},
        closed_form=closed_form,
        inertials=cylinder_links(rows),
        collision_radii=LINK_RADII,
    )


SPEC = build()
