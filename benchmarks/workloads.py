"""The commands of the peers comparison: smooth, too-fast and near-limit segments.

A trajectory is recorded once per workload, from a fresh seed (printed and recorded), by
rrc-pin's default resolver integrated with Euler steps of dt; then every contender answers
the same command at every recorded configuration (never its own integration, so that every
library meets the same states). It is cut into segments of :data:`SEGMENT` steps, each of one
kind drawn at random:

- ``smooth``: the command blends linearly from one random twist to the next (linear parts
  N(0, 0.1) m/s, angular N(0, 0.15) rad/s per axis): reachable, far from the limits mostly;
- ``too_fast``: twists of random direction, 1.5 m/s and 3 rad/s, a new direction every
  :data:`FAST_EVERY` steps: beyond what the joints' velocity limits allow, so the answer can
  only be slower than the command (or veer). The directions change within the segment
  because a constant one soon drives a joint onto its limit, where no motion along it is
  left (the LP maximum scale is then 0: standing still is the answer);
- ``near_limit``: at the segment's start, three joints are moved to within 0.02 rad inside a
  position limit (upper or lower at random), then a moderate random twist (N(0, 0.23) m/s,
  N(0, 0.35) rad/s) drives on: the one-step position bounds are active.

With several frames (baxter) every frame gets its own command of the segment's kind.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

SEGMENT = 50
"""Steps of one segment."""
KINDS = ("smooth", "too_fast", "near_limit")
NEAR = 0.02
"""[rad] How far inside its limit a near-limit segment starts a joint (at most)."""
NEAR_JOINTS = 3
"""Joints put near a limit at the start of a near-limit segment."""
FAST_EVERY = 10
"""Steps between two directions of a too-fast segment."""


def fresh_seed() -> int:
    """A seed from the operating system's entropy (printed and recorded by the caller)."""
    return int(np.random.SeedSequence().entropy % (2**32))


def _twist(rng: np.random.Generator, linear: float, angular: float) -> Array:
    return np.concatenate([rng.normal(size=3) * linear, rng.normal(size=3) * angular])


def _too_fast(rng: np.random.Generator) -> Array:
    v, w = rng.normal(size=3), rng.normal(size=3)
    return np.concatenate([1.5 * v / np.linalg.norm(v), 3.0 * w / np.linalg.norm(w)])


def record(
    robot: Any,
    frames: int,
    steps: int,
    rng: np.random.Generator,
    dt: float,
    answer: Callable[[Array, Array], Array],
) -> tuple[Array, Array, list[str]]:
    """Configurations (steps, nq), commands (steps, 6 * frames) and each step's segment kind.

    Args:
        robot: The rrc-pin robot (its limits and random configurations).
        frames: Commanded frames (6 entries of the command each).
        steps: Length of the trajectory.
        rng: The workload's generator (from the printed seed).
        dt: Control period [s].
        answer: ``answer(q, x) -> rates``: the resolver that drives the recording.
    """
    q = robot.random_q(rng)
    Q, X = np.empty((steps, robot.nq)), np.empty((steps, 6 * frames))
    kinds: list[str] = []
    lower, upper = robot.lower, robot.upper
    kind, start, end = "smooth", np.zeros(6 * frames), np.zeros(6 * frames)
    for k in range(steps):
        j = k % SEGMENT
        if j == 0:
            kind = str(rng.choice(KINDS))
            if kind == "smooth":
                start = np.concatenate([_twist(rng, 0.1, 0.15) for _ in range(frames)])
                end = np.concatenate([_twist(rng, 0.1, 0.15) for _ in range(frames)])
            elif kind == "too_fast":
                start = end = np.concatenate([_too_fast(rng) for _ in range(frames)])
            else:
                start = end = np.concatenate([_twist(rng, 0.23, 0.35) for _ in range(frames)])
                finite = np.flatnonzero(np.isfinite(lower) & np.isfinite(upper))
                for i in rng.choice(finite, size=min(NEAR_JOINTS, finite.size), replace=False):
                    inside = rng.uniform(0.0, NEAR)
                    q[i] = upper[i] - inside if rng.random() < 0.5 else lower[i] + inside
        if kind == "too_fast" and j and j % FAST_EVERY == 0:
            start = end = np.concatenate([_too_fast(rng) for _ in range(frames)])
        x = start + (end - start) * (j / (SEGMENT - 1))
        Q[k], X[k] = q, x
        kinds.append(kind)
        q = np.clip(q + answer(q, x) * dt, lower, upper)
    return Q, X, kinds
