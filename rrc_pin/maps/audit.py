"""Reachability confirmed by inverse kinematics: resolved-rate IK through the resolver.

To confirm a voxel, the tool origin is driven into the voxel's cube from a start
configuration by the project's own resolver, ``Resolver(arm, dt).solve(q, twist)`` in a
loop, each step integrated ``q += qdot dt`` (Barker eq. 21). The command at each step is
the linear velocity ``v = gain (t - p) / dt`` toward the nearest point ``t`` of the cube
shrunk by :data:`INSET` of its edge (zero once inside), with, on arms whose resolver task
is the full twist, the angular velocity that the least-norm joint rates of ``v`` produce
(``w = J_w J_v^+ v``): the orientation is left free. The command is scaled down until those
least-norm rates fit the velocity limits (the resolver would scale it anyway; fitting, its
exact rates answer without a QP). A start that stops getting closer (:data:`STALL_STEPS`)
gives way to the next. The resolver keeps every joint within
its position and velocity limits at every step (its one-step bounds), so a voxel reached
this way is reachable *with the limits*. A voxel is confirmed when a start reaches it within
``max_steps``; the starts are drawn uniformly within the limits (seeded), never from the
map's own samples.

- :func:`audit`: a seeded random choice of voxels the map reports reached, each to be
  confirmed (a sampled voxel that IK cannot reach would be a mapping error).
- :func:`refine`: the voxels at the map's boundary that no sample reached (6-neighbours of
  reached ones), tried by IK: those reached extend the map's reachable set.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.maps.capability_map import CapabilityMap
from rrc_pin.resolver import Resolver
from rrc_pin.robot import Robot
from rrc_pin.solvers.checks import integer
from rrc_pin.solvers.maps.kinematics import task_rows

Array = npt.NDArray[np.float64]

INSET = 0.1
"""The target is the cube shrunk by this share of its edge on each side."""
DT = 0.05
"""[s] Integration step of the IK loop."""
GAIN = 0.5
"""Share of the error commanded per step."""
MAX_COUNT = 1_000_000
"""The most voxels, starts or steps per start an audit takes (more would run for days)."""
STALL_STEPS = 20
"""A start is abandoned after this many steps without getting :data:`STALL_M` closer."""
STALL_M = 1e-4
"""[m] Progress that counts."""
SHOWN = 5
"""Failures a report's ``repr`` lists (the rest: :attr:`AuditReport.failures`)."""


@dataclass(repr=False)
class AuditReport:
    """What IK found for each voxel tried (its ``repr``, a one-line summary).

    Attributes:
        keys: The voxels tried (k,).
        reached: Whether IK brought the tool origin into each (k,).
        starts: Starts used per voxel (k,) (the last one succeeded where reached).
        steps: Resolver steps of the last start (k,).
        distance: Final distance from the tool origin to the cube (k,) [m] (0: inside).
        seconds: Wall time [s].
        steps_total: Resolver steps over every voxel and start.
    """

    keys: npt.NDArray[np.int64]
    reached: npt.NDArray[np.bool_]
    starts: npt.NDArray[np.int64]
    steps: npt.NDArray[np.int64]
    distance: Array
    seconds: float
    steps_total: int

    @property
    def confirmed(self) -> float:
        """Share of the voxels reached by IK."""
        return float(self.reached.mean()) if self.reached.size else 1.0

    @property
    def failures(self) -> npt.NDArray[np.int64]:
        """The voxels IK did not reach."""
        out: npt.NDArray[np.int64] = self.keys[~self.reached]
        return out

    def __repr__(self) -> str:
        n, failed = int(self.keys.size), self.failures.tolist()
        shown = ", ".join(map(str, failed[:SHOWN])) + (", ..." if len(failed) > SHOWN else "")
        starts = f"{self.starts.mean():.1f} mean, {np.max(self.starts)} most" if n else "none"
        return (
            f"AuditReport({n:,} voxels tried, {n - len(failed):,} reached "
            f"({self.confirmed:.1%}), failures [{shown}], starts {starts}, "
            f"{self.steps_total:,} resolver steps, {self.seconds:.1f} s)"
        )


def _robot(m: CapabilityMap, robot: Robot) -> tuple[Robot, npt.NDArray[np.int64]]:
    if not isinstance(robot, Robot) or robot.tool_frame is None:
        raise InvalidInput("robot", "expected the Robot of the map, with one tool frame")
    if robot.tool_frame != m.meta.get("frame") or robot.nq != m.chain.n:
        raise InvalidInput(
            "robot", f"{robot.name} ({robot.tool_frame}) is not the arm of this map "
            f"({m.meta.get('arm')}, {m.meta.get('frame')})"
        )  # fmt: skip
    return robot, np.arange(robot.nq)


def reach_box(
    resolver: Resolver,
    robot: Robot,
    lo: Array,
    hi: Array,
    starts: Array,
    max_steps: int,
) -> tuple[bool, int, int, float, int]:
    """Drive the tool origin into the box ``[lo, hi]`` [m] from each start in turn.

    Returns:
        (reached, starts used, steps of the last start, final distance [m], steps in all).
    """
    inset = INSET * (hi - lo)
    tlo, thi = lo + inset, hi - inset
    full = task_rows(robot.nq) == 6  # the resolver's default task: full twist from 6 joints
    total = 0
    distance = float("inf")
    steps = 0
    for s, q0 in enumerate(starts, 1):
        q = q0.copy()
        best, since = float("inf"), 0
        for steps in range(max_steps + 1):
            p = robot.fk(q)[:3, 3]
            outside = np.maximum(lo - p, 0.0) + np.maximum(p - hi, 0.0)
            distance = float(np.linalg.norm(outside))
            if distance == 0.0:
                return True, s, steps, 0.0, total + steps
            best, since = (distance, 0) if distance < best - STALL_M else (best, since + 1)
            if steps == max_steps or since >= STALL_STEPS:  # stuck: the next start
                break
            v = GAIN * (np.clip(p, tlo, thi) - p) / DT
            J = robot.jacobian(q)
            rates = np.linalg.lstsq(J[:3], v, rcond=None)[0]
            over = float(np.max(np.abs(rates) / robot.velocity_limit))
            if over > 1.0:  # a command whose least-norm rates fit the velocity limits
                v, rates = v / over, rates / over
            twist = np.zeros(6)
            twist[:3] = v
            if full:
                twist[3:] = J[3:] @ rates
            q = q + resolver.solve(q, twist).qdot * DT
        total += steps
    return False, len(starts), steps, distance, total


def _map(m: CapabilityMap) -> None:
    """Refuse anything but a map.

    Raises:
        InvalidInput: Naming ``m``.
    """
    if not isinstance(m, CapabilityMap):
        raise InvalidInput("m", f"expected a CapabilityMap, got {type(m).__name__}")


def _try_arguments(starts: int, max_steps: int) -> None:
    """Refuse starts and steps that are not counts in [1, MAX_COUNT].

    Raises:
        InvalidInput: Naming ``starts`` or ``max_steps``.
    """
    integer(starts, "starts", 1, MAX_COUNT)
    integer(max_steps, "max_steps", 1, MAX_COUNT)


def _try(
    m: CapabilityMap, robot: Robot, keys: npt.NDArray[np.int64], seed: int, starts: int,
    max_steps: int,
) -> AuditReport:  # fmt: skip
    robot, _ = _robot(m, robot)
    rng = np.random.default_rng(seed)
    resolver = Resolver(robot, dt=DT)
    v = m.grid.voxel
    lows = (np.stack(np.unravel_index(keys, m.grid.shape), axis=1) + m.grid.start) * v
    n = keys.size
    reached = np.zeros(n, bool)
    used, steps, total = np.zeros(n, np.int64), np.zeros(n, np.int64), 0
    distance = np.zeros(n)
    t0 = time.perf_counter()
    for i in range(n):
        q0 = np.array([robot.random_q(rng) for _ in range(starts)])
        ok, used[i], steps[i], distance[i], spent = reach_box(
            resolver, robot, lows[i], lows[i] + v, q0, max_steps
        )
        reached[i] = ok
        total += spent
    return AuditReport(keys, reached, used, steps, distance, time.perf_counter() - t0, total)


def audit(
    m: CapabilityMap,
    robot: Robot,
    voxels: int = 1000,
    *,
    seed: int = 0,
    starts: int = 32,
    max_steps: int = 150,
) -> AuditReport:
    """Confirm by IK a seeded random choice of ``voxels`` voxels the map reports reached.

    Args:
        m: The map.
        robot: Its arm (the robot whose tool frame was mapped).
        voxels: Voxels to audit (all reached ones if fewer).
        seed: Seed of the choice and of the IK starts.
        starts: Start configurations per voxel at most.
        max_steps: Resolver steps per start at most.

    Raises:
        InvalidInput: ``robot`` is not the map's arm; bad ``voxels``, ``starts``,
            ``max_steps``.
    """
    _map(m)
    voxels = integer(voxels, "voxels", 1, MAX_COUNT)
    seed = integer(seed, "seed", 0)
    _try_arguments(starts, max_steps)
    reached = np.flatnonzero(m.reached)
    rng = np.random.default_rng(seed)
    keys = np.sort(rng.choice(reached, size=min(voxels, reached.size), replace=False))
    return _try(m, robot, keys, seed + 1, starts, max_steps)


def boundary(m: CapabilityMap) -> npt.NDArray[np.int64]:
    """Voxels not reached whose face neighbour (6-neighbourhood) is reached (keys)."""
    cube = m.reached.reshape(m.grid.shape)
    near = np.zeros_like(cube)
    for axis in range(3):
        for shift in (1, -1):
            near |= np.roll(cube, shift, axis=axis) & _valid(cube.shape, axis, shift)
    out: npt.NDArray[np.int64] = np.flatnonzero(near & ~cube)
    return out


def _valid(shape: tuple[int, ...], axis: int, shift: int) -> npt.NDArray[np.bool_]:
    """Mask of the cells whose rolled value came from inside the grid (no wrap-around)."""
    mask = np.ones(shape, bool)
    index = [slice(None)] * 3
    index[axis] = slice(0, 1) if shift == 1 else slice(-1, None)
    mask[tuple(index)] = False
    return mask


def refine(
    m: CapabilityMap,
    robot: Robot,
    limit: int | None = None,
    *,
    seed: int = 0,
    starts: int = 4,
    max_steps: int = 150,
) -> AuditReport:
    """Try by IK the boundary voxels no sample reached (at most ``limit``, a seeded choice).

    Those :attr:`AuditReport.reached` are reachable with the limits though unsampled.

    Raises:
        InvalidInput: As :func:`audit`.
    """
    _map(m)
    seed = integer(seed, "seed", 0)
    _try_arguments(starts, max_steps)
    keys = boundary(m)
    if limit is not None:
        limit = integer(limit, "limit", 1, MAX_COUNT)
        if keys.size > limit:
            keys = np.sort(np.random.default_rng(seed).choice(keys, size=limit, replace=False))
    return _try(m, robot, keys, seed + 1, starts, max_steps)
