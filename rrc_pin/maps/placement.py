"""Base placement of a second arm: where it shares the most dexterous volume with a first.

Given the first arm's map, a work region (a box in the first map's base frame) and a set of
candidate base poses of the second arm, each placement is one Dask task: the second arm's
samples (the same seeded blocks for every placement: common random numbers, so placements
are compared on the same joint samples) are mapped with its chain placed at that pose, on
the voxels of the region only (aligned with the first map's voxels), and the task returns
the region's voxels where *both* arms are dexterous: reached with an orientation coverage of
at least ``min_coverage``. The score is their volume [m^3] (ties: the larger sum over them
of the weaker arm's best manipulability).
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.loading import load
from rrc_pin.maps import driver
from rrc_pin.maps.capability_map import CapabilityMap, popcount
from rrc_pin.maps.kinematics import chain_of, placed
from rrc_pin.maps.voxels import Grid, quanta
from rrc_pin.robot import Robot
from rrc_pin.solvers.maps.batch import BINS, Fields
from rrc_pin.solvers.maps.kinematics import ChainKinematics, task_rows
from rrc_pin.solvers.maps.sampling import BLOCK, Plan
from rrc_pin.solvers.maps.work import Job, compute_blocks

Array = npt.NDArray[np.float64]


def placements_grid(
    x: Sequence[float], y: Sequence[float], yaw: Sequence[float] = (0.0,), z: float = 0.0
) -> Array:
    """Base poses (K, 4, 4) on a grid of positions, headings and one height.

    Positions ``x``, ``y`` [m] at height ``z`` [m], headings ``yaw`` [rad] about the
    vertical, in the first map's base frame; x slowest, yaw fastest.
    """
    out = []
    for xi in x:
        for yi in y:
            for a in yaw:
                T = np.eye(4)
                c, s = np.cos(a), np.sin(a)
                T[:2, :2] = [[c, -s], [s, c]]
                T[:3, 3] = (xi, yi, z)
                out.append(T)
    return np.array(out)


@dataclass(repr=False)
class PlacementSearch:
    """Scores of the candidate placements of the second arm (its ``repr``, a summary).

    Attributes:
        placements: Candidate base poses (K, 4, 4).
        shared_volume: Volume of the region where both arms are dexterous, per placement
            (K,) [m^3].
        manipulability: Sum over those voxels of the weaker arm's best manipulability (K,).
        region: The region's voxels (:class:`Grid`).
        min_coverage: The coverage that makes a voxel dexterous.
        seconds: Wall time of the search [s].
    """

    placements: Array
    shared_volume: Array
    manipulability: Array
    region: Grid
    min_coverage: float
    seconds: float = 0.0

    def __repr__(self) -> str:
        k = self.best
        x, y, z = self.placements[k][:3, 3]
        return (
            f"PlacementSearch({len(self.placements):,} placements, best #{k} at "
            f"({x:.3f}, {y:.3f}, {z:.3f}) m: {self.shared_volume[k]:.4g} m^3 shared dexterous, "
            f"{self.seconds:.1f} s)"
        )

    @property
    def best(self) -> int:
        """Index of the best placement (largest volume, then manipulability, then first)."""
        order = np.lexsort((-np.arange(len(self.shared_volume)), self.manipulability,
                            self.shared_volume))  # fmt: skip
        return int(order[-1])

    def table(self, top: int = 10) -> str:
        """The ``top`` placements as a Markdown table."""
        order = np.lexsort((self.manipulability, self.shared_volume))[::-1][:top]
        rows = [
            "| rank | x [m] | y [m] | z [m] | yaw [deg] | shared dexterous volume [m^3] |",
            "| ---: | ---: | ---: | ---: | ---: | ---: |",
        ]
        for rank, k in enumerate(order, 1):
            T = self.placements[k]
            yaw = np.degrees(np.arctan2(T[1, 0], T[0, 0]))
            rows.append(
                f"| {rank} | {T[0, 3]:.3f} | {T[1, 3]:.3f} | {T[2, 3]:.3f} | {yaw:.0f} | "
                f"{self.shared_volume[k]:.4f} |"
            )
        return "\n".join(rows)


def region_grid(lo: npt.ArrayLike, hi: npt.ArrayLike, voxel: float) -> Grid:
    """The voxels (aligned on multiples of ``voxel``) that the box ``[lo, hi]`` [m] touches."""
    a = np.floor(np.asarray(lo, dtype=float) / voxel).astype(np.int64)
    b = np.floor(np.asarray(hi, dtype=float) / voxel).astype(np.int64)
    start = (int(a[0]), int(a[1]), int(a[2]))
    shape = (int(b[0] - a[0] + 1), int(b[1] - a[1] + 1), int(b[2] - a[2] + 1))
    return Grid(start, shape, voxel)


def score_placement(
    job: Job, first_dexterous: npt.NDArray[np.bool_], first_manip: Array,
    min_coverage: float,
) -> tuple[float, float]:  # fmt: skip
    """One placement's task: the second arm's region map, and the voxels both arms share.

    Returns:
        (voxels where both are dexterous, the sum there of the weaker best manipulability).
    """
    result = compute_blocks(job, list(range(job.plan.blocks)))
    part = result.part
    mine = popcount(part.dirs) / BINS >= min_coverage
    keys = part.keys[mine]
    both = first_dexterous[keys]
    weaker = np.minimum(first_manip[keys][both], part.fmax[mine, 0][both])
    return float(np.count_nonzero(both)), float(np.nansum(np.where(np.isfinite(weaker),
                                                                 weaker, 0.0)))


def base_placement(
    first: CapabilityMap,
    second: Robot | str,
    region: tuple[npt.ArrayLike, npt.ArrayLike],
    placements: npt.ArrayLike,
    *,
    samples: int = 2**17,
    seed: int = 0,
    min_coverage: float = 0.25,
    scheduler: object = None,
    workers: int | None = None,
    frame: str | None = None,
    block_size: int = BLOCK,
    dashboard: str | None = None,
) -> PlacementSearch:
    """Score each base pose of ``second`` by the dexterous volume it shares with ``first``.

    Args:
        first: The first arm's map (its base frame is the frame of everything here).
        second: The second arm (a robot, or a name).
        region: The work region, a box ``(lo, hi)`` (3,) each [m].
        placements: Candidate base poses of the second arm (K, 4, 4), e.g.
            :func:`placements_grid`.
        samples: Samples of the second arm per placement.
        seed: Their seed (the same samples for every placement).
        min_coverage: Orientation coverage from which a voxel counts as dexterous, (0, 1].
        scheduler: As :func:`~rrc_pin.maps.capability`; one task per placement.
        workers: As :func:`~rrc_pin.maps.capability`.
        frame: The second arm's tool frame (default: its own).
        block_size: Samples per block.
        dashboard: As :func:`~rrc_pin.maps.capability`.

    Raises:
        InvalidInput: A bad argument (named).
        SchedulerUnreachable: No scheduler at the address.
    """
    robot = second if isinstance(second, Robot) else load(str(second))
    lo, hi = (np.asarray(b, dtype=float).reshape(-1) for b in region)
    if lo.shape != (3,) or hi.shape != (3,) or not np.all(np.isfinite([lo, hi])) or np.any(
        hi < lo
    ):
        raise InvalidInput("region", f"expected a box (lo, hi), lo <= hi, (3,) each; got {region}")
    T = np.asarray(placements, dtype=float)
    if T.ndim != 3 or T.shape[1:] != (4, 4) or not np.all(np.isfinite(T)) or not len(T):
        raise InvalidInput("placements", f"expected (K, 4, 4) poses, got shape {T.shape}")
    if not 0.0 < float(min_coverage) <= 1.0:
        raise InvalidInput("min_coverage", f"expected (0, 1], got {min_coverage!r}")
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise InvalidInput("samples", f"expected an int >= 1, got {samples!r}")
    driver.check_scheduler(scheduler, workers, dashboard)
    grid = region_grid(lo, hi, first.grid.voxel)
    centres = grid.centres(np.arange(grid.size))
    q1 = first.at(centres)
    first_dexterous = (q1.samples > 0) & (q1.coverage >= min_coverage)
    first_manip = np.nan_to_num(q1.manipulability_max, nan=0.0)
    chain, _ = chain_of(robot, frame)
    rows = task_rows(chain.n)
    plan = Plan(samples, block_size)
    q = quanta(chain, rows)
    jobs = [
        Job(ChainKinematics(placed(chain, t), rows), grid.arrays, plan, seed, True, q,
                   Fields())
        for t in T
    ]  # fmt: skip
    start = time.perf_counter()
    with driver.connect(scheduler, workers, dashboard=dashboard) as client:
        futures: list[Any] = [
            client.submit(score_placement, job, first_dexterous, first_manip,
                          float(min_coverage), pure=False)
            for job in jobs
        ]  # fmt: skip
        scores = client.gather(futures)
    volume = np.array([s[0] for s in scores]) * grid.voxel**3
    manip = np.array([s[1] for s in scores])
    return PlacementSearch(T, volume, manip, grid, float(min_coverage),
                           time.perf_counter() - start)  # fmt: skip
