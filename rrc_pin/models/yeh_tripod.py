"""Yeh's three-legged robot: three of Barker's PUMA-type arms as the legs of one body.

Barker (NASA TM-85685, 1983, Introduction): "three of these manipulators served as legs in
simulating the locomotion of a three-legged robot over structural beams" (Yeh, M.S. thesis,
Ohio State, 1981). Neither report gives the body's dimensions in the text available here:
the body below is assumed (``SPEC.assumed`` gives the reasons). The body is a free-flyer
root joint (a floating base); each leg hangs upside down from a hip at a corner of an
equilateral triangle, yawed to face outward, and its flange is its foot.
"""

from __future__ import annotations

import math

from rrc_pin.models.cell_spec import CellSpec, Mount

HIP_RADIUS = 0.35
"""[m] Distance of each hip from the body's centre (assumed, see ``SPEC.assumed``)."""
LEG_READY = (0.0, 0.0, math.pi / 2, 0.0, math.pi / 4, 0.0)
"""[rad] Each leg's ready joint positions: barker6's catalogue ready pose (wrist centre
1.08 m from the hip, 0.43 m outward), hanging down."""


def _leg(key: str, angle_deg: float) -> Mount:
    a = math.radians(angle_deg)
    return Mount(key, "barker6", (HIP_RADIUS * math.cos(a), HIP_RADIUS * math.sin(a), 0.0),
                 (math.pi, 0.0, a), "flange", LEG_READY)  # fmt: skip


SPEC = CellSpec(
    name="yeh_tripod",
    mounts=(_leg("leg1", 0.0), _leg("leg2", 120.0), _leg("leg3", 240.0)),
    source="Barker, NASA TM-85685 (1983), Introduction, after Yeh (1981): three PUMA-type "
    "arms as the legs of a robot walking over structural beams",
    assumed=(
        f"hips at the corners of an equilateral triangle, {HIP_RADIUS} m from the body's "
        "centre: the reports give no body size; with the legs' ready reach the feet stand "
        "1.45 m apart, "
        "inside each leg's reach of the others' footholds",
        "each leg mounted upside down (roll pi) and yawed so that its ready reach points "
        "away from the body",
        "foot: the leg's flange frame (Barker's hand, HW past the wrist centre), clamped to "
        "the beam in support (a full 6-DOF contact, the way a gripper holds a beam)",
        "ready pose: barker6's catalogue ready pose on every leg; the body's height puts the "
        "feet at z = 0, the top of the beams",
        "body speed limits 0.5 m/s and 1 rad/s (the free-flyer's velocity limits)",
    ),
    body="body",
    body_velocity=(0.5, 0.5, 0.5, 1.0, 1.0, 1.0),
    stand=True,
)
