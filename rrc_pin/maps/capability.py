"""``maps.capability``: the capability map of one arm's tool frame, on Dask.

Every argument is checked before anything is written or any cluster is contacted: a bad
value raises :class:`~rrc_pin.errors.InvalidInput` naming it, an output folder holding
another map's blocks :class:`~rrc_pin.errors.ForeignMap` (argument ``out``), an address
where no scheduler answers :class:`~rrc_pin.errors.SchedulerUnreachable` (``scheduler``,
within 3 s).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
from collections.abc import Callable
from dataclasses import asdict
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.errors import InvalidInput
from rrc_pin.loading import load
from rrc_pin.maps import driver
from rrc_pin.maps.blocks import BlockStore
from rrc_pin.maps.capability_map import CapabilityMap
from rrc_pin.maps.kinematics import arm_kinematics
from rrc_pin.maps.progress import Progress, ProgressBar
from rrc_pin.maps.voxels import MAX_SAMPLES, Grid, chain_grid, quanta
from rrc_pin.robot import Robot
from rrc_pin.solvers.maps.batch import MAX_KEYS, Chain, Fields
from rrc_pin.solvers.maps.kinematics import ArmKinematics
from rrc_pin.solvers.maps.sampling import BLOCK, Plan
from rrc_pin.solvers.maps.work import Job

ProgressArg = bool | Callable[[Progress], None]
"""``progress``: True (a text bar on stderr), False (none) or a callable given each update."""


def capability(
    arm: Robot | str,
    samples: int = 10**7,
    voxel: float = 0.05,
    scheduler: object = None,
    *,
    seed: int = 0,
    out: str | os.PathLike[str] | None = None,
    workers: int | None = None,
    dexterity: bool = True,
    frame: str | None = None,
    progress: ProgressArg = True,
    block_size: int = BLOCK,
    blocks_per_task: int | None = None,
    grid: Grid | None = None,
    dashboard: str | None = None,
) -> CapabilityMap:
    """The capability map of ``arm``'s tool frame: reachability, dexterity, singularities.

    Samples the joints uniformly within their limits, in blocks of ``block_size`` seeded
    ``SeedSequence(seed, spawn_key=(block,))``, evaluates each block at once (barker6 by
    its batch closed form, every other arm by the compiled chain kernel), bins the tool
    origins into voxels of ``voxel`` [m] and reduces each voxel's statistics exactly
    (:mod:`rrc_pin.maps.voxels`): the map is bit-identical whatever the workers, task sizes
    or interruptions.

    Args:
        arm: A robot, or a name or path for :func:`rrc_pin.load`.
        samples: Samples (1 to 2^32).
        voxel: Voxel edge [m], > 0 (a grid of at most 2^31 voxels).
        scheduler: None (an in-process Dask cluster of ``workers`` threads), the address of
            a ``dask.distributed`` scheduler (``"tcp://host:8786"``), or a
            ``distributed.Client``.
        seed: Seed of the samples (int >= 0).
        out: Folder for the partial results (``blocks/``, so that an interrupted run resumes
            when called again), the Zarr store (``map.zarr``) and ``summary.md``/``.json``
            (the plots: :func:`~rrc_pin.maps.plot_map`, or ``rrc-pin map``). None: memory
            only.
        workers: Threads of the in-process cluster (default: the machine's cores); refused
            with a ``scheduler``.
        dexterity: Compute manipulability and sigma_min per sample (one-sided Jacobi SVD);
            False keeps counts, directions, margins, witnesses and conditions only (faster).
        frame: The tool frame (default: the robot's; required with several).
        progress: True: a progress bar on stderr; False: none; a callable: called with a
            :class:`~rrc_pin.maps.progress.Progress` after each task.
        block_size: Samples per block (a power of two, 2^6 to 2^20); part of the map's
            definition, so fixed for a map (2^15 by default).
        blocks_per_task: Blocks per Dask task (1 to 64); default: four tasks per worker
            thread, at most 8 blocks each. Any grouping gives the same map.
        grid: The voxel grid (default: the one holding the chain's reach); used by the cell
            maps to put every arm on one grid.
        dashboard: Serve Dask's dashboard of the in-process cluster at this address
            (``"8787"`` or ``":8787"``: on 127.0.0.1; ``"0.0.0.0:8787"``: every interface;
            needs bokeh); None: no dashboard, and the cluster's HTTP servers listen on
            127.0.0.1 only, serving nothing. Refused with a ``scheduler``.

    Returns:
        The map.

    Raises:
        InvalidInput: A bad argument (named).
        ForeignMap: ``out`` holds another map's blocks.
        SchedulerUnreachable: No scheduler at the address.
        MissingExtra: dask.distributed (or zarr, with ``out``) is not installed.
    """
    robot = arm if isinstance(arm, Robot) else _load(arm)
    samples = _count(samples, "samples", 1, MAX_SAMPLES)
    voxel = _positive(voxel, "voxel")
    seed = _count(seed, "seed", 0, 2**63 - 1)
    block_size = _block_size(block_size)
    if blocks_per_task is not None:
        blocks_per_task = _count(blocks_per_task, "blocks_per_task", 1, 64)
    driver.check_scheduler(scheduler, workers, dashboard)
    if not isinstance(dexterity, bool):
        raise InvalidInput("dexterity", f"expected True or False, got {dexterity!r}")
    report = progress if callable(progress) else None
    if not callable(progress) and not isinstance(progress, bool):
        raise InvalidInput("progress", f"expected a bool or a callable, got {progress!r}")
    folder = _folder(out)
    kin = arm_kinematics(robot, frame)
    frame = frame or robot.tool_frame
    if grid is None:
        grid = chain_grid(kin.chain, voxel)
    elif grid.voxel != voxel:
        raise InvalidInput("grid", f"voxel {grid.voxel} differs from voxel={voxel}")
    if grid.size > MAX_KEYS:
        raise InvalidInput(
            "voxel", f"{voxel} m gives {grid.size:,} voxels ({grid.shape}); at most 2^31"
        )
    plan = Plan(samples, block_size)
    fields = Fields(kin.conditions)
    q = quanta(kin.chain, kin.rows)
    definition = _definition(robot, frame, kin, plan, seed, grid, dexterity, q)
    store = None
    if folder is not None:
        store = BlockStore(folder / "blocks", definition, fields, grid.size)
        store.check()
    job = Job(kin, grid.arrays, plan, seed, dexterity, q, fields)
    bar = ProgressBar(f"map {robot.name}") if progress is True else None
    with driver.connect(scheduler, workers, dashboard=dashboard) as client:
        stats, run = driver.run(job, grid.size, client, store, report or bar, blocks_per_task)
    meta = {
        **definition,
        "versions": versions(),
        "run": asdict(run),
        "samples_outside": stats.outside,
        "memory": {"worker_bytes": run.worker_memory, "driver_bytes": run.driver_memory},
    }
    result = CapabilityMap(grid, stats, kin.chain, meta)
    if folder is not None:
        write_outputs(result, folder)
    return result


def write_outputs(m: CapabilityMap, folder: Path) -> None:
    """The Zarr store and the summary (Markdown and JSON)."""
    from rrc_pin.maps.store import save_map

    save_map(m, folder / "map.zarr")
    (folder / "summary.md").write_text(m.summary_table() + "\n")
    (folder / "summary.json").write_text(json.dumps(m.summary(), indent=1) + "\n")


def versions() -> dict[str, str | None]:
    """Versions of rrc-pin and what computes a map."""
    out: dict[str, str | None] = {}
    for dist in ("rrc-pin", "numpy", "pin", "numba", "dask", "distributed", "zarr"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = None
    return out


def _definition(
    robot: Robot, frame: str | None, kin: ArmKinematics, plan: Plan, seed: int, grid: Grid,
    dexterity: bool, q: npt.NDArray[Any],
) -> dict[str, Any]:  # fmt: skip
    """What makes a map this map (the blocks' fingerprint is its hash)."""
    return {
        "arm": robot.name,
        "frame": frame,
        "method": kin.method,
        "chain_sha256": chain_digest(kin.chain),
        "nq": kin.chain.n,
        "rows": kin.rows,
        "samples": plan.samples,
        "block_size": plan.block_size,
        "seed": seed,
        "voxel": grid.voxel,
        "grid": grid.to_dict(),
        "dexterity": dexterity,
        "quanta": [float(x) for x in q],
        "conditions": list(kin.conditions),
        "tolerances": [float(x) for x in kin.tolerances],
    }


def chain_digest(chain: Chain) -> str:
    """sha256 of the chain's arrays (the arm's geometry and limits)."""
    h = hashlib.sha256()
    for a in (chain.rot, chain.trans, chain.kind, chain.lower, chain.upper, chain.bounded):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _load(arm: object) -> Robot:
    if not isinstance(arm, str):
        raise InvalidInput("arm", f"expected a Robot, a name or a path, got {arm!r}")
    return load(arm)


def _count(value: object, name: str, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InvalidInput(name, f"expected an integer, got {value!r}")
    if not lo <= value <= hi:
        raise InvalidInput(name, f"expected {lo} <= {name} <= {hi}, got {value}")
    return int(value)


def _positive(value: object, name: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InvalidInput(name, f"expected a number [m], got {value!r}")
    x = float(value)
    if not math.isfinite(x) or x <= 0.0:
        raise InvalidInput(name, f"expected a finite length > 0 [m], got {value!r}")
    return x


def _block_size(value: object) -> int:
    n = _count(value, "block_size", 2**6, 2**20)
    if n & (n - 1):
        raise InvalidInput("block_size", f"expected a power of two, got {n}")
    return n


def _folder(out: object) -> Path | None:
    if out is None:
        return None
    if not isinstance(out, (str, os.PathLike)):
        raise InvalidInput("out", f"expected a folder path, got {out!r}")
    path = Path(out)
    if path.exists() and not path.is_dir():
        raise InvalidInput("out", f"{path} exists and is not a folder")
    return path
