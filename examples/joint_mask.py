"""A joint mask: joints held still at run time, the rest solving without them.

Shows: panda's hand driven along a circle while ``Controller.mask`` freezes its wrist
(``panda_joint5`` to ``panda_joint7``) for a second, then its elbow; masked joints stay exactly
where they were (their rates 0.0, their columns out of every task and limit), the other
joints serve what they can, and ``Resolution.masked`` names the frozen ones. Then the same on
gsfc_dual's right arm through a ``CellController``. Needs only ``pip install -e .``.

Run: ``python examples/joint_mask.py``
"""

from __future__ import annotations

import os

import numpy as np

import rrc_pin

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
TICKS = 50 if QUICK else 100  # per phase, at 100 Hz


def arm() -> None:
    """Panda: free, wrist masked, elbow masked, free again."""
    controller = rrc_pin.Controller("panda", dt=0.01)
    phases = [(), ("panda_joint5", "panda_joint6", "panda_joint7"), ("panda_joint4",), ()]
    for masked in phases:
        controller.unmask()
        if masked:
            controller.mask(masked)
        start = controller.q.copy()
        worst = 0.0
        for k in range(TICKS):
            angle = 2.0 * np.pi * k / TICKS
            step = controller.step([0.05 * np.cos(angle), 0.05 * np.sin(angle), 0.0, 0, 0, 0])
            worst = max(worst, 1.0 - step.resolution.scale)
        moved = np.abs(controller.q - start)
        held = [controller.robot.joint_names.index(j) for j in masked]
        print(f"panda masked {list(step.resolution.masked) or 'none'}: masked joints moved "
              f"{moved[held].max(initial=0.0):.1f} rad, the others up to {moved.max():.3f} rad; "
              f"command scaled down by at most {100 * worst:.0f}%")


def cell() -> None:
    """gsfc_dual: the right arm's shoulder masked while both hands move."""
    controller = rrc_pin.CellController("gsfc_dual", dt=0.01)
    controller.mask(["right/joint1", "right/joint2"])
    start = controller.q.copy()
    for _ in range(TICKS):
        step = controller.step({"left/tool": [0.0, 0.03, 0.0, 0, 0, 0],
                                "right/tool": [0.0, -0.03, 0.0, 0, 0, 0]})  # fmt: skip
    moved = np.abs(controller.q - start)
    names = controller.robot.joint_names
    held = [names.index(j) for j in controller.masked]
    print(f"gsfc_dual masked {list(step.resolution.masked)}: they moved {moved[held].max():.1f} "
          f"rad, the other joints up to {moved.max():.3f} rad")


def main() -> None:
    """The arm, then the cell."""
    arm()
    cell()


if __name__ == "__main__":
    main()
