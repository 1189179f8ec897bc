"""The 3R arm of the Robotics I exam (2012), like the first three joints of a KUKA KR5.

Standard DH: alpha = (90, 0, 0) deg, a = (0.2, 0.5, 0.5) m, d = 0. Tool frame: O3. Limits are
not in the exam (assumed, KR5 class).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from rrc_pin.dh import DHChain, DHRow
from rrc_pin.models.arm_spec import ArmSpec, check_parameters

if TYPE_CHECKING:
    from rrc_pin.solvers.closed_form.base import ClosedForm

NAME = "kr5_3r"


def build(a1: float = 0.2, a2: float = 0.5, a3: float = 0.5, name: str = NAME) -> ArmSpec:
    """The exam's 3R arm with link lengths ``a1``, ``a2``, ``a3`` [m].

    Raises:
        InvalidInput: A length is not a finite real number (named in the message).
    """
    a1, a2, a3 = check_parameters({"a1": a1, "a2": a2, "a3": a3}).values()
    rows = (
        DHRow(a=a1, alpha=np.pi / 2, d=0.0, theta=0.0),
        DHRow(a=a2, alpha=0.0, d=0.0, theta=0.0),
        DHRow(a=a3, alpha=0.0, d=0.0, theta=0.0),
    )
    limits = np.deg2rad((170.0, 135.0, 150.0))

    def closed_form() -> ClosedForm:
        from rrc_pin.solvers.closed_form.three_r import ThreeRClosedForm

        return ThreeRClosedForm(a1=a1, a2=a2, a3=a3)

    return ArmSpec(
        name=name,
        chain=DHChain(convention="standard", rows=rows),
        lower=tuple(-limits),
        upper=tuple(limits),
        velocity_limit=(6.5, 5.2, 6.5),
        effort_limit=(200.0, 200.0, 100.0),
        source="Robotics I exam with solution (2012), Table 1 and numerical data",
        assumed=(
            "joint limits +-170, +-135, +-150 deg",
            "velocity limits (6.5, 5.2, 6.5) rad/s and efforts (KR5 class)",
            "collision capsule radii (0.08, 0.06, 0.05) m along the DH offsets, KR5 class "
            "(the exam gives no widths)",
            "ready pose: the exam's configuration (0, 45, -45) deg",
        ),
        named_poses={"exam": (0.0, np.pi / 4, -np.pi / 4), "ready": (0.0, np.pi / 4, -np.pi / 4)},
        closed_form=closed_form,
        parameters={"a1": a1, "a2": a2, "a3": a3},
        collision_radii=(0.08, 0.06, 0.05),
    )


SPEC = build()
