"""The jerk-limited stage against Ruckig's velocity interface, on the same resolver rates.

Run from a checkout: ``python benchmarks/bench_smoothing.py`` (``--seed S``, ``--seconds T``;
needs ``pip install ruckig``, in the test extra). Prints, for each filter, what it gives to
the same command: a panda resolver's rates for 10 s of random hand twists (piecewise
constant, so the rates jump), followed by each filter open loop, both with the same
acceleration and jerk bounds:

- the largest acceleration and jerk of the sampled rates (finite differences per tick);
- how far the filtered rates trail the command (RMS and largest per joint) [rad/s];
- the time after a step in the command until every joint is within 1e-3 rad/s of it.

Ruckig (Berscheid & Kroeger 2021, the library MoveIt Servo uses) computes each tick a
time-optimal jerk-limited trajectory to the target rate and samples it at dt; rrc-pin's
:class:`~rrc_pin.control.smoothing.JerkLimiter` takes the acceleration that reaches the target
without overshoot, clipped into the jerk's interval. Quality only: no timing is recorded.
"""

from __future__ import annotations

import argparse

import numpy as np
import ruckig

import rrc_pin
from rrc_pin.control.random_operator import random_commands
from rrc_pin.control.smoothing import JerkLimiter

DT = 0.01
ACCELERATION = 20.0  # [rad/s^2]
JERK = 500.0  # [rad/s^3]


def resolver_rates(seed: int, seconds: float) -> tuple[np.ndarray, list]:
    """The panda resolver's rates (n, 7) for random hand twists, and each tick's box."""
    arm = rrc_pin.load("panda")
    resolver = rrc_pin.Resolver(arm, dt=DT)
    commands = random_commands(np.random.default_rng(seed), seconds, DT, speed=0.08, turn=0.3)
    q, rates, boxes = arm.ready(), [], []
    for twist in commands:
        r = resolver.solve(q, twist)
        rates.append(r.qdot)
        boxes.append(r.problem.box)
        q = arm.integrate(q, r.qdot, DT)
    return np.array(rates), boxes


def with_rrc_pin(rates: np.ndarray, boxes: list) -> np.ndarray:
    stage = JerkLimiter(rates.shape[1], DT, ACCELERATION, JERK)
    return np.array([stage.step(v, box).qdot for v, box in zip(rates, boxes, strict=True)])


def with_ruckig(rates: np.ndarray) -> np.ndarray:
    n = rates.shape[1]
    otg = ruckig.Ruckig(n, DT)
    inp, out = ruckig.InputParameter(n), ruckig.OutputParameter(n)
    inp.control_interface = ruckig.ControlInterface.Velocity
    inp.current_position = [0.0] * n
    inp.current_velocity = [0.0] * n
    inp.current_acceleration = [0.0] * n
    inp.max_acceleration = [ACCELERATION] * n
    inp.max_jerk = [JERK] * n
    inp.max_velocity = [10.0] * n
    inp.target_acceleration = [0.0] * n
    filtered = []
    for v in rates:
        inp.target_velocity = list(v)
        otg.update(inp, out)
        filtered.append(list(out.new_velocity))
        out.pass_to_input(inp)
    return np.array(filtered)


def report(name: str, command: np.ndarray, filtered: np.ndarray) -> None:
    acc = np.diff(np.vstack([np.zeros(command.shape[1]), filtered]), axis=0) / DT
    jerk = np.diff(acc, axis=0) / DT
    lag = np.abs(filtered - command)
    steps = np.flatnonzero(np.abs(np.diff(command, axis=0)).max(axis=1) > 0.05) + 1
    settle = []
    for k in steps:
        close = np.flatnonzero(lag[k:].max(axis=1) < 1e-3)
        if close.size:
            settle.append(close[0] * DT)
    print(f"{name:>8}: max |acc| {np.abs(acc).max():7.2f} rad/s^2, max |jerk| "
          f"{np.abs(jerk).max():8.1f} rad/s^3, trailing RMS {np.sqrt((lag**2).mean()):.4f} "
          f"max {lag.max():.3f} rad/s, settle median {np.median(settle):.3f} s "
          f"(max {max(settle):.3f} s, {len(settle)} steps)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args()
    rates, boxes = resolver_rates(args.seed, args.seconds)
    print(f"panda, {len(rates)} ticks of {DT} s, a_max {ACCELERATION} rad/s^2, "
          f"j_max {JERK} rad/s^3, seed {args.seed}")
    report("command", rates, rates)
    report("rrc-pin", rates, with_rrc_pin(rates, boxes))
    report("ruckig", rates, with_ruckig(rates))


if __name__ == "__main__":
    main()
