"""Nadkarni's manipulator configuration #2 (thesis Table A2-7): three prismatic, three revolute.

Used in Illustrations 5 to 7. Lengths in thesis units taken as inches (assumed); limits and
speeds are not in the thesis (assumed).
"""

from __future__ import annotations

import numpy as np

from rrc_pin.models.arm_spec import ArmSpec
from rrc_pin.models.nadkarni import Row, chain_and_initial_pose

NAME = "nadkarni_c2"
# Table A2-7: r_i, alpha_i [deg], a_i, theta_i [deg], joint
TABLE_A2_7: tuple[Row, ...] = (
    (0.00, 90.00, 0.00, 0.00, "prismatic"),
    (25.00, 90.00, 0.00, 90.00, "prismatic"),
    (8.00, 0.00, 0.00, 180.00, "prismatic"),
    (0.00, 90.00, 0.00, 0.00, "revolute"),
    (0.00, 90.00, 0.00, 90.00, "revolute"),
    (10.00, 90.00, 0.00, 0.00, "revolute"),
    (0.00, 0.00, 1.00, 0.00, None),  # the hand frame
)
FIRST_FRAME_POINTS = (
    (25.0, 0.0, 20.0),
    (30.0, 0.0, 20.0),
    (25.0, 0.0, 10.0),
)  # Table A2-8, set five


def build(name: str = NAME) -> ArmSpec:
    """Configuration #2 in SI units, base frame = the thesis's global frame."""
    chain, q0 = chain_and_initial_pose(TABLE_A2_7, FIRST_FRAME_POINTS)
    travel = 1.0  # [m]
    return ArmSpec(
        name=name,
        chain=chain,
        lower=(-travel,) * 3 + (-np.pi,) * 3,
        upper=(travel,) * 3 + (np.pi,) * 3,
        velocity_limit=(0.5,) * 3 + (2.0,) * 3,
        effort_limit=(500.0,) * 3 + (50.0,) * 3,
        source="Nadkarni, M.S. thesis (1977), Table A2-7",
        assumed=(
            "length unit of the thesis taken as the inch",
            "prismatic travel +-1 m at 0.5 m/s, revolute +-180 deg at 2 rad/s, efforts",
            "collision radii (0.04, 0.04, 0.04, 0.03, 0.03, 0.02) m: spheres at the prismatic "
            "links' frames and the wrist, a capsule along r6 (the thesis gives no widths)",
            "ready pose: the initial configuration of Table A2-7",
        ),
        named_poses={"table_a2_7": q0, "ready": q0},
        collision_radii=(0.04, 0.04, 0.04, 0.03, 0.03, 0.02),
    )


SPEC = build()
