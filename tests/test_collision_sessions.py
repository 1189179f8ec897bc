"""CollisionLimit over random-command sessions at 100 Hz, in the issue's four scenes.

Each session drives the hands toward random targets chosen to collide (the panda's own base
and links; under a table top; the other arm's hand), a new target every second, at up to
0.3 m/s. With the limit, the minimum distance over every pair stays above the safety
distance minus :data:`TOLERANCE` (the one-step linearisation bound), no joint leaves its
limits, no rate is NaN; without it, the same sessions collide (a pair in penetration).

The sessions are 8 s of simulated time (5 s without the limit) in the normal suite;
``RRC_PIN_COLLISION_MINUTES=10`` runs the issue's 10 minutes (docs/api.md records that run's
numbers; ``-s`` prints them). Each tick also measures every near pair's one-step
linearisation error: the lowest distance its rows (its closest points', its end points')
predict after the step, less the distance it reaches.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable

import numpy as np
import pytest

import rrc_pin
from rrc_pin import CollisionLimit, CollisionModel, FrameTask, JointLimits, Resolver
from rrc_pin.kinematics import Kinematics, Layout

DT = 0.01
SAFETY = 0.02
DETECTION = 0.10
GAIN = 0.5
TOLERANCE = 1e-3
"""[m] How far below the safety distance a session may go, and the largest one-step
linearisation error of a pair's row near it: the distance after a step against the row's
prediction ``d + d_dot dt``, the witness points' second-order motion over the step
(docs/api.md states the 10-minute sessions' numbers)."""
NEAR = 0.01
"""[m] The pairs within this of the safety distance are those whose one-step error is measured
(the error matters where a row is about to bind; far out, a closest point jumping across a box
is corrected by later steps)."""
SECONDS = 60.0 * float(os.environ.get("RRC_PIN_COLLISION_MINUTES", "0")) or 8.0
SPEED = 0.3


def two_pandas() -> rrc_pin.Robot:
    panda = rrc_pin.load("panda")
    facing = np.eye(4)
    facing[:3, :3] = np.diag([-1.0, -1.0, 1.0])
    facing[0, 3] = 1.0
    return rrc_pin.combine({"left": (panda, np.eye(4)), "right": (panda, facing)})


def scene(name: str) -> tuple[CollisionModel, Callable[[np.random.Generator, dict[str, np.ndarray]],
                                                          dict[str, np.ndarray]]]:  # fmt: skip
    """The collision model and the target rule: frame positions in, a target per frame out."""
    if name == "panda folding":
        cm = CollisionModel(rrc_pin.load("panda"))

        def targets(rng, hands):  # around its own base and lower links
            return {f: rng.uniform((-0.15, -0.25, 0.05), (0.25, 0.25, 0.45)) for f in hands}

    elif name == "panda table":
        cm = CollisionModel(rrc_pin.load("panda"))
        T = np.eye(4)
        T[:3, 3] = (0.55, 0.0, 0.2)
        cm.add_box(T, (0.5, 0.8, 0.04), name="table")
        cm.add_halfspace((0, 0, 1), -0.15, name="floor")  # the base on a 0.15 m plinth

        def targets(rng, hands):  # under the table top, or into the floor beside it
            return {f: rng.uniform((0.3, -0.5, -0.25), (0.8, 0.5, 0.15)) for f in hands}

    else:
        cm = CollisionModel(rrc_pin.load("baxter") if name == "baxter" else two_pandas())

        def targets(rng, hands):  # each hand to where the other is
            (fa, pa), (fb, pb) = hands.items()
            mid = 0.5 * (pa + pb) + rng.normal(0.0, 0.05, 3)
            return {fa: mid + rng.normal(0.0, 0.03, 3), fb: mid + rng.normal(0.0, 0.03, 3)}

    return cm, targets


class Session:
    """What one session measured."""

    def __init__(self) -> None:
        self.min_distance = math.inf
        self.worst_pair = ("", "")
        self.joint_excess = 0.0
        self.finite = True
        self.ticks = 0
        self.statuses: dict[str, int] = {}
        self.seconds = 0.0
        self.linearisation = 0.0


def run(name: str, seconds: float, limit: bool, seed: int = 7) -> Session:
    """One session of ``seconds`` simulated at 100 Hz (module docstring)."""
    cm, targets = scene(name)
    robot = cm.robot
    frames = list(robot.tool_frames)
    limits = [JointLimits()]
    if limit:
        limits.append(CollisionLimit(cm, SAFETY, DETECTION, GAIN))
    resolver = Resolver(robot, DT, limits=limits)
    probe = CollisionLimit(cm, SAFETY, DETECTION, GAIN) if limit else None
    layout = Layout.of(robot)
    tasks = [FrameTask(f, rows="position") for f in frames]
    rng = np.random.default_rng(seed)
    q = robot.ready()
    out = Session()
    goal: dict[str, np.ndarray] = {}
    start = time.perf_counter()
    for tick in range(round(seconds / DT)):
        hands = {f: robot.frame_pose(q, f)[:3, 3] for f in frames}
        if tick % 100 == 0:
            goal = targets(rng, hands)
        for task, f in zip(tasks, frames, strict=True):
            v = 2.0 * (goal[f] - hands[f])
            speed = float(np.linalg.norm(v))
            task.set_twist(v * min(1.0, SPEED / speed) if speed > 0 else v)
        res = resolver.solve(q, [tasks], priority="strict")
        out.statuses[res.status] = out.statuses.get(res.status, 0) + 1
        out.finite &= bool(np.isfinite(res.qdot).all())
        step = DT * np.asarray(res.qdot)
        if probe is not None:  # the one-step error of the rows near d_s
            rows = probe.constraints(Kinematics(robot.model, robot.model.createData(), layout,
                                                q, robot.to_pinocchio(q)), DT, step)  # fmt: skip
            after = cm.proximity_at(q + step, DETECTION)
            d_after = dict(zip(("|".join(p) for p in after.names), after.distance, strict=True))
            predicted: dict[str, float] = {}  # the lowest of a pair's rows (end points' too)
            for k, name in enumerate(rows.names):
                if name in d_after and rows.distance[k] <= SAFETY + NEAR:
                    d = rows.distance[k] - float(rows.G[k] @ step)
                    predicted[name] = min(predicted.get(name, math.inf), d)
            for name, d in predicted.items():
                out.linearisation = max(out.linearisation, d - d_after[name])
        q = q + step
        out.joint_excess = max(out.joint_excess, float(np.max(robot.lower - q)),
                               float(np.max(q - robot.upper)))  # fmt: skip
        prox = cm.proximity_at(q, DETECTION)
        if prox.names:
            k = int(np.argmin(prox.distance))
            if prox.distance[k] < out.min_distance:
                out.min_distance, out.worst_pair = float(prox.distance[k]), prox.names[k]
        out.ticks += 1
    out.seconds = time.perf_counter() - start
    return out


SCENES = ["panda folding", "panda table", "baxter", "two pandas"]


@pytest.mark.parametrize("name", SCENES)
def test_a_session_keeps_every_pair_apart(name):
    s = run(name, SECONDS, limit=True)
    print(f"\n{name}: {s.ticks} ticks, min distance {s.min_distance * 1e3:.2f} mm "
          f"({'|'.join(s.worst_pair)}), joint excess {s.joint_excess:.2e}, "
          f"statuses {s.statuses}, linearisation error {s.linearisation * 1e3:.3f} mm, "
          f"{s.seconds:.1f} s wall")  # fmt: skip
    assert s.finite
    assert s.joint_excess <= 1e-9
    assert s.min_distance >= SAFETY - TOLERANCE
    assert s.linearisation <= TOLERANCE
    assert s.min_distance < DETECTION  # the session did bring pairs within reach of a row


@pytest.mark.parametrize("name", SCENES)
def test_without_the_limit_the_same_session_collides(name):
    s = run(name, min(SECONDS, 5.0), limit=False)
    print(f"\n{name} without the limit: min distance {s.min_distance * 1e3:.1f} mm "
          f"({'|'.join(s.worst_pair)})")  # fmt: skip
    assert s.min_distance < 0.0
