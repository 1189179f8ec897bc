"""A soak over every arm rrc_pin.load knows and every installed backend (issue 18): random
twists from 1e-3 to 1e3, starts inside, on and beyond the limits. No backend answers zero
rates where another moves the arm; commands the arm can meet are met without veer; scale is
always in [0, 1] and the fraction achieved along the command."""

from __future__ import annotations

import math
import zlib

import numpy as np
import pytest

import rrc_pin
from rrc_pin import FrameTask, QPOptions, Resolver
from solvers.qp_backends import installed_backends

CASES = 80


def start(arm: rrc_pin.Robot, rng: np.random.Generator) -> np.ndarray:
    """Inside (60%), on a limit (20%) or beyond one (20%) for a few joints."""
    q = arm.random_q(rng)
    finite = np.flatnonzero(np.isfinite(arm.lower) & np.isfinite(arm.upper))
    kind = rng.random()
    for j in rng.choice(finite, size=min(2, finite.size), replace=False) if finite.size else []:
        span = arm.upper[j] - arm.lower[j]
        if kind < 0.2:
            q[j] = arm.lower[j] if rng.random() < 0.5 else arm.upper[j]
        elif kind < 0.4:
            out = rng.uniform(0, 0.1) * span
            q[j] = arm.lower[j] - out if rng.random() < 0.5 else arm.upper[j] + out
    return q


def veer(a: np.ndarray, b: np.ndarray) -> float:
    a, b = a / np.linalg.norm(a), b / np.linalg.norm(b)
    return math.degrees(2.0 * math.atan2(np.linalg.norm(a - b), np.linalg.norm(a + b)))


@pytest.mark.parametrize("name", rrc_pin.arms())
def test_soak_every_arm_every_backend(name: str) -> None:
    arm = rrc_pin.load(name)
    task = FrameTask(arm.tool_frame or arm.tool_frames[0],
                     rows="full" if arm.nq >= 6 else "position")  # fmt: skip
    resolvers = {b: Resolver(arm, task=task, qp=QPOptions(backend=b)) for b in installed_backends()}
    rng = np.random.default_rng(zlib.crc32(name.encode()))
    frozen, veers = [], []
    for _ in range(CASES):
        q = start(arm, rng)
        twist = rng.normal(size=6) * 10.0 ** rng.uniform(-3, 3)
        J = arm.jacobian(q, frame=task.frame)[list(task.selected)]
        b = twist[list(task.selected)]
        answers = {k: r.solve(q, twist) for k, r in resolvers.items()}
        moving = {k for k, r in answers.items() if np.linalg.norm(r.qdot) > 1e-6 and r.scale > 1e-6}
        for k, r in answers.items():
            step = q + r.qdot * 0.01
            inside = (q >= arm.lower) & (q <= arm.upper)
            assert np.all(np.abs(r.qdot) <= arm.velocity_limit)
            assert np.all(step[inside] >= arm.lower[inside])
            assert np.all(step[inside] <= arm.upper[inside])
            assert 0.0 <= r.scale <= 1.0
            unit = r.problem.levels[0][0].unit  # the normalised metric: linear rows / reach
            y, bn = J @ r.qdot / unit, b / unit
            along = min(1.0, max(0.0, float(y @ bn) / float(bn @ bn)))
            assert r.scale == pytest.approx(along, abs=1e-9 + 1e-9 * along)
            if moving and k not in moving and np.linalg.norm(r.qdot) <= 1e-9:
                frozen.append((k, r.status, r.attempts))
        exact = np.linalg.pinv(J) @ b
        bounds = answers["daqp"].box
        if np.all(exact >= bounds.lb) and np.all(exact <= bounds.ub) and np.any(b):
            for r in answers.values():
                veers.append(veer(J @ r.qdot, b))
    assert frozen == []  # no backend answers zero where another moves the arm
    if veers:
        assert np.percentile(veers, 90) < 0.1, np.percentile(veers, 90)
