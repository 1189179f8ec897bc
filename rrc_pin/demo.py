"""``rrc-pin demo``: a short tour of the arms, their kinematics and the closed-form fast paths."""

from __future__ import annotations

import numpy as np

from rrc_pin import models
from rrc_pin.loading import load


def kinematics_tour(names: list[str]) -> None:
    """Print, per arm, the tool pose and Jacobian conditioning at a named pose."""
    print(f"{'arm':12s} {'dof':>3s} {'pose':12s} {'tool position [m]':>28s} {'cond(J)':>9s}")
    for name in names:
        arm = load(name)
        spec = models.CATALOGUE.get(name)
        pose_name, q = next(iter(spec.named_poses.items())) if spec else ("neutral", arm.neutral())
        p = arm.fk(q)[:3, 3]
        cond = np.linalg.cond(arm.jacobian(q))
        position = np.array2string(p, precision=4, suppress_small=True)
        print(f"{name:12s} {arm.nq:3d} {pose_name:12s} {position:>28s} {cond:9.2e}")


def run_demo(arm: str | None = None) -> int:
    """Run the tour (all paper arms plus panda, or one ``arm``); return the exit code."""
    names = [arm] if arm else [*models.CATALOGUE, "panda"]
    print("rrc-pin demo: forward kinematics and Jacobians (Pinocchio)\n")
    kinematics_tour(names)
    return 0
