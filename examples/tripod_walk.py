"""Yeh's three-legged robot walks along a beam: one leg swings at a time, then the body moves.

The tripod (``rrc_pin.load("yeh_tripod")``) stands on three feet clamped to the beams. Each
cycle lifts each leg in turn (up, forward by the stride, down) while the two others carry the
body, then moves the body forward by the stride on all three feet: Yeh's gait in its
simplest form. The feet in support never slip (fixed contacts); the body advances by the
planned distance. Prints the advance and the largest slip. Needs only ``pip install -e .``.

Run: ``python examples/tripod_walk.py``
"""

from __future__ import annotations

import os

import numpy as np

import rrc_pin
from rrc_pin.cells import CellController

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
STRIDE = 0.1  # [m] each foot's step and the body's advance per cycle
LIFT = 0.05  # [m] foot clearance
SPEED = 0.1  # [m/s]
CYCLES = 1 if QUICK else 3


def move(ctl: CellController, name: str, displacement: np.ndarray) -> None:
    """Command ``name`` along ``displacement`` [m] at SPEED, then let its target settle."""
    ticks = round(np.linalg.norm(displacement) / SPEED / ctl.dt)
    twist = np.r_[displacement / (ticks * ctl.dt), np.zeros(3)]
    for _ in range(ticks):
        ctl.step({name: twist})
    for _ in range(20):
        ctl.step({name: np.zeros(6)})


def main() -> None:
    """Walk the tripod CYCLES cycles along x and print what was reached."""
    cell = rrc_pin.load("yeh_tripod")
    ctl = CellController(cell, dt=0.01)
    body0 = cell.fk(ctl.q, "body")[:3, 3]
    slip = 0.0
    for _ in range(CYCLES):
        for leg in cell.arms:
            ctl.swing(leg)
            support = {f: cell.fk(ctl.q, f)[:3, 3] for f in ctl.support}
            move(ctl, leg, np.array([0.0, 0.0, LIFT]))
            move(ctl, leg, np.array([STRIDE, 0.0, 0.0]))
            move(ctl, leg, np.array([0.0, 0.0, -LIFT]))
            ctl.land(leg)
            slip = max(slip, *(np.linalg.norm(cell.fk(ctl.q, f)[:3, 3] - p)
                               for f, p in support.items()))  # fmt: skip
        support = {f: cell.fk(ctl.q, f)[:3, 3] for f in ctl.support}
        move(ctl, "body", np.array([STRIDE, 0.0, 0.0]))
        slip = max(slip, *(np.linalg.norm(cell.fk(ctl.q, f)[:3, 3] - p)
                           for f, p in support.items()))  # fmt: skip
    advance = cell.fk(ctl.q, "body")[:3, 3] - body0
    print(f"feet in support: {', '.join(ctl.support)}")
    print(f"stride {STRIDE} m, clearance {LIFT} m, foot and body speed {SPEED} m/s")
    print(f"{CYCLES} cycles, {ctl.t:.2f} s: body advanced {advance[0]:.6f} m along the beam "
          f"(planned {CYCLES * STRIDE:.3f} m), sideways {abs(advance[1]):.2e} m; "
          f"largest slip of a foot in support {slip:.2e} m")
    assert abs(advance[0] - CYCLES * STRIDE) < 1e-3 and slip < 1e-6


if __name__ == "__main__":
    main()
