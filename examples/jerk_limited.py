"""Jerk-limited output: the resolver's rates through a stage bounding acceleration and jerk.

Shows: panda following random hand twists (piecewise constant: the resolver's rates jump
from one tick to the next), once as the resolver answers and once through
``rrc_pin.JerkLimiter`` (20 rad/s^2, 500 rad/s^3), the rates kept inside the resolver's box
of each tick; then STOP, within its stated time. Prints the largest acceleration and jerk of
each run, how far the smoothed hand is from the unsmoothed one, and the stop. Needs only
``pip install -e .``.

Run: ``python examples/jerk_limited.py``
"""

from __future__ import annotations

import os

import numpy as np
import pinocchio as pin

import rrc_pin
from rrc_pin.control.random_operator import random_commands

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
DT, ACCELERATION, JERK = 0.01, 20.0, 500.0


def run(arm: rrc_pin.Robot, commands: np.ndarray, stage: rrc_pin.JerkLimiter | None):
    """The hand's path and the rates integrated; the hand's target advanced by each twist."""
    resolver = rrc_pin.Resolver(arm, dt=DT)
    q, reference = arm.ready(), pin.SE3(arm.fk(arm.ready()))
    hands, rates = [], []
    for twist in commands:
        task = rrc_pin.FrameTask(arm.tool_frame, twist, target=reference.homogeneous, gain=5.0)
        r = resolver.solve(q, [task], qdot_prev=None if stage is None else stage.rates)
        qdot = r.qdot if stage is None else stage.step(r.qdot, r.problem.box,
                                                       arm.dof_positions(q)).qdot  # fmt: skip
        q = arm.integrate(q, qdot, DT)
        hands.append(arm.fk(q)[:3, 3])
        rates.append(qdot)
        moved = twist * DT * r.scale
        reference = pin.SE3(pin.exp3(moved[3:]) @ reference.rotation,
                            reference.translation + moved[:3])  # fmt: skip
    return np.array(hands), np.array(rates)


def bounds(rates: np.ndarray) -> str:
    """The largest acceleration and jerk of ``rates`` (per tick, from rest), in words."""
    acc = np.diff(np.vstack([np.zeros(rates.shape[1]), rates]), axis=0) / DT
    jerk = np.diff(np.vstack([np.zeros(rates.shape[1]), acc]), axis=0) / DT
    return f"largest acceleration {np.abs(acc).max():7.1f} rad/s^2, jerk {np.abs(jerk).max():8.0f}"


def main() -> None:
    """Both runs, then STOP from where the smoothed one ended."""
    arm = rrc_pin.load("panda")
    commands = random_commands(np.random.default_rng(0), 3.0 if QUICK else 10.0, DT,
                               speed=0.08, turn=0.3)  # fmt: skip
    raw_hands, raw_rates = run(arm, commands, None)
    stage = rrc_pin.JerkLimiter(arm.nv, DT, ACCELERATION, JERK, lower=arm.dof_lower,
                                upper=arm.dof_upper)  # fmt: skip
    hands, rates = run(arm, commands, stage)
    print(f"resolver alone: {bounds(raw_rates)} rad/s^3")
    print(f"jerk-limited:   {bounds(rates)} rad/s^3 (bounds {ACCELERATION}, {JERK})")
    print(f"hand from the unsmoothed hand at the same instant: largest "
          f"{1e3 * np.linalg.norm(hands - raw_hands, axis=1).max():.1f} mm")
    stage.stop()
    bound, ticks = stage.stop_time(), 0
    free = rrc_pin.Resolver(arm, dt=DT).solve(arm.ready(), np.zeros(6)).problem.box
    while np.abs(stage.rates).max() > 1e-9:
        stage.step(rates[-1], free)  # the command is ignored once stopped
        ticks += 1
    print(f"STOP from {np.abs(rates[-1]).max():.2f} rad/s: still after {ticks * DT:.2f} s "
          f"(stated bound {bound:.2f} s)")


if __name__ == "__main__":
    main()
