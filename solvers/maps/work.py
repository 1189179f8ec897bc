"""The work of one Dask task of a capability map: draw, evaluate and accumulate blocks.

Runs on the workers: numpy, numba and :mod:`solvers` only (a worker process imports no
Pinocchio and no ``rrc_pin``). Memory of a task: one block's samples and rows
(``block_size x (8 n + 88)`` bytes: 2.6 MB for panda's 2^15) and its voxel table
(:class:`~rrc_pin.solvers.maps.batch.VoxelTable`), at most ``4 x (72 or 120)`` bytes per distinct
voxel of the task; both measured and returned with the result.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.maps.batch import Fields, GridArrays, Rows, Sparse, VoxelTable
from rrc_pin.solvers.maps.kinematics import ArmKinematics
from rrc_pin.solvers.maps.sampling import Plan, block_samples


@dataclass(frozen=True)
class Job:
    """What a worker needs to compute blocks (numpy data and the arm's kinematics).

    Attributes:
        kinematics: The arm's batch kinematics.
        grid: The voxel grid.
        plan: The map's blocks.
        seed: The map's seed.
        dexterity: Compute manipulability and sigma_min.
        quanta: Fixed-point quanta (2,).
        fields: The statistics' columns.
    """

    kinematics: ArmKinematics
    grid: GridArrays
    plan: Plan
    seed: int
    dexterity: bool
    quanta: npt.NDArray[np.float64]
    fields: Fields


@dataclass
class TaskResult:
    """One task's output.

    Attributes:
        blocks: The blocks computed.
        part: Their voxels' aggregates.
        seconds: Compute time on the worker [s].
        memory: Bytes of the task's buffers and table at their largest.
    """

    blocks: list[int]
    part: Sparse
    seconds: float
    memory: int


def compute_blocks(job: Job, blocks: list[int]) -> TaskResult:
    """Draw, evaluate and accumulate ``blocks`` (runs on a worker)."""
    start = time.perf_counter()
    fields = job.fields
    table = VoxelTable(len(fields.isum), len(fields.imin), capacity=2 * job.plan.block_size)
    rows = Rows.empty(job.plan.block_size, len(fields.conditions))
    peak = 0
    for b in blocks:
        Q = block_samples(job.kinematics.chain, job.seed, job.plan, b)
        out = rows.head(Q.shape[0])
        job.kinematics.block_rows(Q, job.grid, job.dexterity, job.quanta, job.plan.first(b), out)
        table.add(out)
        peak = max(peak, table.nbytes + Q.nbytes + sum(
            a.nbytes for a in (rows.keys, rows.count, rows.dirs, rows.fmax, rows.isum, rows.imin)
        ))  # fmt: skip
    return TaskResult(blocks, table.sparse(), time.perf_counter() - start, peak)
