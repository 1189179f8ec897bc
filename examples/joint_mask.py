"""A joint mask: joints held still at run time, the rest solving without them.

Shows: panda's hand driven sideways while ``Controller.mask`` freezes its wrist
(``panda_joint5`` to ``panda_joint7``) for a second, then its elbow; masked joints stay exactly
where they were (their rates 0.0, their columns out of every task and limit), the other
joints serve what they can, and ``Resolution.masked`` names the frozen ones. Then gsfc_dual
carrying its object with one shoulder frozen, through a ``CellController``. Needs only
``pip install -e .``.

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
    tool = controller.robot.tool_frame
    for k, masked in enumerate(phases):
        controller.unmask()
        if masked:
            controller.mask(masked)
        start, hand = controller.q.copy(), controller.robot.fk(controller.q, tool)[:3, 3]
        twist = [0.0, 0.05 if k % 2 == 0 else -0.05, 0.0, 0.0, 0.0, 0.0]
        for _ in range(TICKS):
            step = controller.step(twist, ref="world_aligned")
        moved = np.abs(controller.q - start)
        held = [controller.robot.joint_names.index(j) for j in masked]
        travel = np.linalg.norm(controller.robot.fk(controller.q, tool)[:3, 3] - hand)
        print(f"panda, masked {list(step.resolution.masked) or 'none'}: hand moved "
              f"{1e3 * travel:.1f} mm of {1e3 * 0.05 * TICKS * controller.dt:.0f} mm; masked "
              f"joints moved {moved[held].max(initial=0.0)} rad, the others up to "
              f"{moved.max():.3f} rad")


def cell() -> None:
    """gsfc_dual: the object carried with the right shoulder frozen."""
    controller = rrc_pin.CellController("gsfc_dual", dt=0.01)
    controller.mask(["right/joint1"])
    start = controller.q.copy()
    for _ in range(TICKS):
        step = controller.step({"object": [0.0, 0.0, 0.03, 0.0, 0.0, 0.0]})
    moved = np.abs(controller.q - start)
    names = controller.robot.joint_names
    held = [names.index(j) for j in controller.masked]
    print(f"gsfc_dual, masked {list(step.resolution.masked)}: they moved {moved[held].max()} "
          f"rad, the other joints up to {moved.max():.3f} rad; {step.resolution.status}, "
          f"scale {step.resolution.scale:.2f}")


def main() -> None:
    """The arm, then the cell."""
    arm()
    cell()


if __name__ == "__main__":
    main()
