"""GSFC's dual-arm telerobot testbed: two RRC K-1607 slave arms (Nguyen & Zhou 1990, sec. 2).

The report says the testbed is "a pair of mini-master controllers and a pair of slave arms,
each of which is a redundant manipulator possessing 7 DOFs", without their placement: the
spacing and the ready pose below are assumed (``SPEC.assumed`` gives the reasons).
"""

from __future__ import annotations

from rrc_pin.models.cell_spec import CellSpec, HeldObject, Mount

SPACING = 0.9
"""[m] Distance between the two shoulders (assumed, see ``SPEC.assumed``)."""
INWARD = 0.25
"""[rad] Joint 1 of each arm turned toward the other in the ready pose (assumed)."""

UPRIGHT = (0.0, 0.0, 0.0)
"""Both bases upright, facing +x (roll, pitch, yaw [rad]; assumed)."""

_ARM_READY = (0.0, 0.5235987755982988, 0.0, 1.5707963267948966, 0.0, 0.7853981633974483, 0.0)


def _ready(yaw: float) -> tuple[float, ...]:
    return (yaw, *_ARM_READY[1:])


SPEC = CellSpec(
    name="gsfc_dual",
    mounts=(
        Mount("left", "rrc_k1607", (0.0, SPACING / 2, 0.0), UPRIGHT, "tool", _ready(-INWARD)),
        Mount("right", "rrc_k1607", (0.0, -SPACING / 2, 0.0), UPRIGHT, "tool", _ready(INWARD)),
    ),
    source="Nguyen & Zhou, NASA grant NAG 5-1124 report (1990), section 2: the GSFC dual-arm "
    "telerobot testbed (two RRC K-1607 slave arms, two 6-DOF Kraft mini-master hand controllers)",
    assumed=(
        f"shoulder spacing {SPACING} m along y, both bases upright facing +x: the report gives "
        "no placement; with the arm's 1.245 m reach at its ready pose this spacing makes the "
        "two workspaces overlap over about 1.5 m in front of the pair, where a shared object "
        "is held",
        f"ready pose: each arm's catalogue ready pose with joint 1 turned {INWARD} rad toward "
        "the other, so that the hands are 0.28 m apart in front of the pair (an object that "
        "size held between them)",
        "object frame 'object' midway between the hands in the ready pose, base axes",
    ),
    objects=(HeldObject("object", ("left", "right")),),
)
