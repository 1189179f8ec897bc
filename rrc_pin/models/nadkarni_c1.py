"""Nadkarni's manipulator configuration #1 (thesis Table A2-2): six revolute joints and a hand.

Used in Illustrations 2 and 4. Lengths in thesis units taken as inches (assumed); limits and
speeds are not in the thesis (assumed).
"""

from __future__ import annotations

import numpy as np

from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.models.nadkarni import Row, chain_and_initial_pose

NAME = "nadkarni_c1"
# Table A2-2: r_i, alpha_i [deg], a_i, theta_i [deg], joint
TABLE_A2_2: tuple[Row, ...] = (
    (0.00, 90.00, 0.00, 70.00, "revolute"),
    (0.00, -90.00, 0.375, 80.00, "revolute"),
    (12.20, 90.00, 0.375, 40.00, "revolute"),
    (0.00, -90.00, 0.00, 0.00, "revolute"),
    (9.50, 90.00, 0.00, 60.00, "revolute"),
    (0.00, 0.00, 5.90, 30.00, "revolute"),
    (0.00, 0.00, 1.00, 0.00, None),  # the hand frame
)
FIRST_FRAME_POINTS = ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))  # Table A2-3, set five
READY = tuple(float(v) for v in np.deg2rad((0.0, -60.0, 0.0, 90.0, 0.0, 0.0)))  # chosen


def build(name: str = NAME) -> ArmSpec:
    """Configuration #1 in SI units, base frame = the thesis's global frame."""
    chain, q0 = chain_and_initial_pose(TABLE_A2_2, FIRST_FRAME_POINTS)
    return ArmSpec(
        name=name,
        chain=chain,
        lower=(-np.pi,) * 6,
        upper=(np.pi,) * 6,
        velocity_limit=(2.0,) * 6,
        effort_limit=(50.0,) * 6,
        source="Nadkarni, M.S. thesis (1977), Table A2-2",
        assumed=(
            "length unit of the thesis taken as the inch",
            "joint limits +-180 deg, velocity limits 2 rad/s, efforts",
            "collision capsule radii (0.04, 0.04, 0.03, 0.03, 0.025, 0.02) m along the DH "
            "offsets (the thesis gives no widths)",
            "ready pose (0, -60, 0, 90, 0, 0) deg, away from the limits and singularities "
            "(the initial configuration of Table A2-2 is singular: Illustration 4 escapes "
            "from it)",
        ),
        named_poses={"table_a2_2": q0, "ready": READY},
        collision_radii=(0.04, 0.04, 0.03, 0.03, 0.025, 0.02),
    )


SPEC = build()
