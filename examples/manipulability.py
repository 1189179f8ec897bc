"""Keeping away from singularities: a manipulability task below the hand, a singularity limit.

Shows: panda's and rrc_k1607's hands along a path that passes near a singular configuration
(the hand path of a joint-space line through one), once with the hand alone and once with
``rrc_pin.ManipulabilityTask`` one priority level below it: the measure's minimum along the
path rises, the hand's path is the same (strict priorities). Then ``rrc_pin.SingularityLimit``
stops panda stretching out at a threshold on its smallest singular value. Needs only
``pip install -e .``.

Run: ``python examples/manipulability.py``
"""

from __future__ import annotations

import numpy as np

import rrc_pin
from rrc_pin.dexterity import dexterity
from rrc_pin.kinematics import Kinematics, Layout

DT, TICKS = 0.01, 200
NEAR_SINGULAR = {
    "panda": [1.365, -1.23, -0.752, -0.425, 1.792, 1.16, -1.016],
    "rrc_k1607": [-0.306, 0.068, -0.124, 0.408, 0.538, 1.292, 0.788],
}  # [rad] smallest singular value of the tool Jacobian below 0.002 (found by sampling)


def kinematics(arm: rrc_pin.Robot, q: np.ndarray) -> Kinematics:
    """The kinematics of ``arm`` at ``q`` (what a resolver builds each tick)."""
    _, dof, q_pin = arm.positions(q)
    return Kinematics(arm.model, arm.model.createData(), Layout.of(arm), dof, q_pin)


def crossing(arm: rrc_pin.Robot, below: list) -> tuple[float, float]:
    """The least measure along the path, and the hand's largest distance from it [m]."""
    qs = np.array(NEAR_SINGULAR[arm.name])
    Vt = np.linalg.svd(arm.jacobian(qs))[2]
    delta = Vt[:6].T @ (Vt[:6] @ np.random.default_rng(1).normal(size=7))
    delta *= 0.3 / np.linalg.norm(delta)  # 0.3 rad/s, the singular point at 1 s
    path = [qs + (k * DT - 1.0) * delta for k in range(TICKS + 1)]
    resolver, q = rrc_pin.Resolver(arm, dt=DT), path[0].copy()
    least, off = np.inf, 0.0
    for k in range(TICKS):
        hand = rrc_pin.FrameTask(arm.tool_frame, arm.jacobian(path[k]) @ delta,
                                 target=arm.fk(path[k]))  # fmt: skip
        q = arm.integrate(q, resolver.solve(q, [[hand], *below], priority="strict").qdot, DT)
        least = min(least, dexterity(kinematics(arm, q), arm.tool_frame).manipulability)
        off = max(off, float(np.linalg.norm(arm.fk(q)[:3, 3] - arm.fk(path[k + 1])[:3, 3])))
    return least, off


def main() -> None:
    """Both arms with and without the task, then the limit."""
    for name in NEAR_SINGULAR:
        arm = rrc_pin.load(name)
        alone = crossing(arm, [])
        raised = crossing(arm, [[rrc_pin.ManipulabilityTask(arm.tool_frame, gain=1.0)]])
        print(f"{name}: least manipulability {alone[0]:.2e} -> {raised[0]:.2e} with the task "
              f"below the hand; hand off its path {1e3 * alone[1]:.3f} / {1e3 * raised[1]:.3f} mm")
    arm = rrc_pin.load("panda")
    limit = rrc_pin.SingularityLimit(arm.tool_frame, threshold=0.03, detection=0.08)
    for limits in ([rrc_pin.JointLimits()], [rrc_pin.JointLimits(), limit]):
        resolver, q = rrc_pin.Resolver(arm, dt=DT, limits=limits), arm.ready()
        for _ in range(600):  # straight out at 0.15 m/s
            r = resolver.solve(q, [0.15, 0.0, 0.0, 0.0, 0.0, 0.0])
            q = arm.integrate(q, r.qdot, DT)
        sigma = dexterity(kinematics(arm, q), arm.tool_frame).sigma[-1]
        print(f"panda stretched out {'with' if len(limits) > 1 else 'without'} the limit: "
              f"smallest singular value {sigma:.4f}, last status {r.status}")


if __name__ == "__main__":
    main()
