"""A synthetic recording of a tracked device: a hand's slow figure, noise, dropouts, jumps.

For trying a :class:`~rrc_pin.control.pose_stream.PoseStream` (and its options) on the
faults a real tracker has, seeded and repeatable.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.checks import finite_number

Array = npt.NDArray[np.float64]


class Recording(NamedTuple):
    """A device's samples.

    Attributes:
        times: Sample times (n,) [s], increasing.
        poses: The poses the tracker reported (n, 4, 4) [m] (noise, jumps).
        truth: The device's true poses at those times (n, 4, 4).
    """

    times: Array
    poses: Array
    truth: Array


class Jump(NamedTuple):
    """A tracker fault: from ``start`` [s] its poses are offset by ``offset`` (3,) [m].

    ``samples`` of them (a glitch), or every later one when None (its frame moved).
    """

    start: float
    offset: tuple[float, float, float]
    samples: int | None = None


def device_pose(t: float | Array, amplitude: float = 0.08, phase: float = 0.0) -> Array:
    """The true device pose(s) (4, 4) or (n, 4, 4) at ``t`` [s]: a slow Lissajous figure.

    Up to ``amplitude`` [m] from the origin (0.25, 0.2, 0.15 Hz on x, y, z), turning up to
    0.3 rad about z at 0.1 Hz; peak speed about 0.13 m/s for the default amplitude.
    """
    times = np.atleast_1d(np.asarray(t, dtype=np.float64))
    w = 2.0 * np.pi * times
    out = np.tile(np.eye(4), (times.size, 1, 1))
    out[:, 0, 3] = amplitude * np.sin(0.25 * w + phase)
    out[:, 1, 3] = amplitude * np.sin(0.2 * w + 0.5 + phase)
    out[:, 2, 3] = 0.5 * amplitude * np.sin(0.15 * w + phase)
    yaw = 0.3 * np.sin(0.1 * w + phase)
    out[:, 0, 0], out[:, 0, 1] = np.cos(yaw), -np.sin(yaw)
    out[:, 1, 0], out[:, 1, 1] = np.sin(yaw), np.cos(yaw)
    return out[0] if np.ndim(t) == 0 else out


def synthetic_stream(
    seconds: float,
    rate: float = 90.0,
    *,
    seed: int = 0,
    noise: float = 5e-4,
    angle_noise: float = 2e-3,
    dropouts: Sequence[tuple[float, float]] = (),
    jumps: Sequence[Jump] = (),
    phase: float = 0.0,
) -> Recording:
    """A recording of :func:`device_pose` at ``rate`` [Hz] for ``seconds`` [s].

    Args:
        seconds: Length [s] > 0.
        rate: Samples per second > 0 (a VR tracker: 90).
        seed: The noise's seed.
        noise: Standard deviation [m] of the position noise per axis.
        angle_noise: Standard deviation [rad] of the rotation noise per axis.
        dropouts: ``(start, end)`` [s] intervals without samples.
        jumps: Tracker faults (:class:`Jump`).
        phase: Phase [rad] of the figure (two hands: two phases).

    Raises:
        InvalidInput: A bad length, rate or noise, named.
    """
    seconds = finite_number(seconds, "seconds", 0.0, inclusive=False)
    rate = finite_number(rate, "rate", 0.0, inclusive=False)
    finite_number(noise, "noise", 0.0)
    finite_number(angle_noise, "angle_noise", 0.0)
    times = np.arange(0.0, seconds, 1.0 / rate)
    keep = np.ones(times.size, dtype=bool)
    for start, end in dropouts:
        keep &= ~((times >= start) & (times < end))
    times = times[keep]
    truth = device_pose(times, phase=phase).reshape(-1, 4, 4)
    rng = np.random.default_rng(seed)
    poses = truth.copy()
    poses[:, :3, 3] += rng.normal(scale=noise, size=(times.size, 3))
    for k, turn in enumerate(rng.normal(scale=angle_noise, size=(times.size, 3))):
        poses[k, :3, :3] = pin.exp3(turn) @ poses[k, :3, :3]
    for jump in jumps:
        hit = np.flatnonzero(times >= jump.start)
        if jump.samples is not None:
            hit = hit[: jump.samples]
        if len(jump.offset) != 3:
            raise InvalidInput("jumps", f"an offset is (3,) [m], got {jump.offset!r}")
        poses[hit, :3, 3] += np.asarray(jump.offset, dtype=np.float64)
    return Recording(times, poses, truth)
