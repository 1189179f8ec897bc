"""The Dask driver: blocks to tasks, tasks to workers, results merged and written as they come.

- **Scheduler.** ``None``: an in-process cluster of one worker of ``workers`` threads (no
  set-up; the compiled kernels release the GIL, so the threads run side by side), talking
  in-process (no socket); an address (``tcp://host:8786``): that cluster, connected with a
  short timeout (an address where no scheduler answers fails in :data:`CONNECT_TIMEOUT`
  seconds with :class:`~rrc_pin.errors.SchedulerUnreachable`); or a ``distributed.Client``
  already open.
- **Sockets.** The in-process scheduler and worker each start an HTTP server (distributed
  always does, whatever ``dashboard_address``): both listen on :data:`LOOPBACK` at a free
  port and serve nothing (no routes), unless the caller asks for the dashboard
  (``dashboard="host:port"``; a port alone or ``":port"`` is on 127.0.0.1 too; an address
  of every interface only when named, ``"0.0.0.0:8787"``).
- **Tasks.** Runs of consecutive blocks (at most :data:`MAX_BLOCKS_PER_TASK`); each task
  draws its blocks' samples, evaluates them and accumulates them into a hash table of voxels
  on the worker, and ships only the voxels it reached (a sparse result). At most two tasks
  per worker thread are in flight, so the results waiting on the driver stay bounded too.
- **Memory per worker thread**, whatever the samples (:mod:`rrc_pin.solvers.maps.work`): one
  block's samples and rows (``block_size x (8 n + 88)`` bytes, 2.6 MB for panda's 2^15)
  plus the task's voxel table, at most ``4 x 72`` bytes (120 for barker6) per distinct voxel
  of the task, itself at most ``min(voxels of the grid, samples of the task)``: with the
  default 8 blocks a task, under 80 MB (130 MB for barker6) in the worst case, 10-30 MB for
  panda at 5 cm. Measured per task and recorded (``meta["memory"]``).
- **Driver.** Dense statistics of the grid (:class:`~rrc_pin.maps.voxels.VoxelStats`); each
  result is merged as it arrives and, with an output folder, written as a part at once; every
  :data:`FOLD_PARTS` parts are folded into one file (:mod:`rrc_pin.maps.blocks`), and the
  last ones at the end.
- **Interruption.** Any exception (Ctrl-C included) cancels the tasks in flight and leaves
  what completed on disk; the same call resumes.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

from rrc_pin.errors import InvalidInput, MissingExtra, SchedulerUnreachable
from rrc_pin.maps.blocks import BlockStore
from rrc_pin.maps.progress import Progress
from rrc_pin.maps.voxels import VoxelStats
from rrc_pin.solvers.maps.work import Job, TaskResult, compute_blocks

LOOPBACK = "127.0.0.1"
"""Where the servers of an in-process cluster listen, unless the caller names a host."""
CONNECT_TIMEOUT = 3.0
"""[s] How long to wait for a scheduler at an address."""
MAX_BLOCKS_PER_TASK = 8
"""Blocks per task at most (2^18 samples at the default block size)."""
FOLD_PARTS = 32
"""Parts folded into one file (so a damaged fold costs at most this many tasks again)."""


def _distributed() -> Any:
    try:
        import distributed
    except ImportError as exc:
        raise MissingExtra("maps", ["dask[distributed]"]) from exc
    return distributed


def check_scheduler(scheduler: object, workers: int | None, dashboard: object = None) -> None:
    """Refuse a bad scheduler argument, or workers or a dashboard beside a remote scheduler.

    Raises:
        InvalidInput: Naming ``scheduler``, ``workers`` or ``dashboard``.
    """
    if scheduler is not None:
        if isinstance(scheduler, str):
            if not scheduler.strip() or any(c.isspace() for c in scheduler):
                raise InvalidInput("scheduler", f"expected an address, got {scheduler!r}")
        elif type(scheduler).__name__ != "Client":
            raise InvalidInput(
                "scheduler",
                f"expected None, an address such as 'tcp://host:8786' or a distributed.Client, "
                f"got {scheduler!r}",
            )
        if workers is not None:
            raise InvalidInput(
                "workers", "sets the local scheduler's threads; a cluster has its own workers"
            )
        if dashboard is not None:
            raise InvalidInput("dashboard", "a cluster serves its own dashboard")
    elif workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, int) or workers < 1
    ):
        raise InvalidInput("workers", f"expected an int >= 1, got {workers!r}")
    if dashboard is not None:
        dashboard_address(dashboard)


def dashboard_address(dashboard: object) -> str:
    """``host:port`` of the dashboard asked for: ``"8787"`` and ``":8787"`` on :data:`LOOPBACK`.

    Raises:
        InvalidInput: Naming ``dashboard``: not a string ``[host]:port``, port 0 to 65535.
    """
    text = dashboard if isinstance(dashboard, str) else ""
    host, _, port = text.rpartition(":")
    if not port.isdigit() or int(port) > 65535 or any(c.isspace() or c == "/" for c in host):
        raise InvalidInput(
            "dashboard", f"expected an address 'host:port' or a port, got {dashboard!r}"
        )
    return f"{host or LOOPBACK}:{int(port)}"


@contextlib.contextmanager
def connect(
    scheduler: object,
    workers: int | None,
    timeout: float = CONNECT_TIMEOUT,
    dashboard: str | None = None,
) -> Iterator[Any]:
    """A ``distributed.Client`` for ``scheduler`` (see the module docstring), closed after.

    Raises:
        SchedulerUnreachable: No scheduler answered at the address within ``timeout``.
        MissingExtra: dask.distributed is not installed.
    """
    distributed = _distributed()
    if scheduler is None:
        with local_cluster(workers, dashboard) as cluster, distributed.Client(cluster) as client:
            yield client
        return
    if not isinstance(scheduler, str):  # a Client the caller owns
        yield scheduler
        return
    try:
        client = distributed.Client(scheduler, timeout=timeout)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerUnreachable(scheduler, " ".join(str(exc).split())) from exc
    try:
        yield client
    finally:
        client.close()


def local_cluster(workers: int | None, dashboard: str | None = None) -> Any:
    """The in-process cluster: one worker of ``workers`` threads (default: the cores).

    A ``distributed.SpecCluster`` of one ``Scheduler`` and one ``Worker`` (what
    ``LocalCluster(processes=False)`` builds, but with the HTTP servers' addresses and the
    dashboard set apart: ``LocalCluster`` ties the worker's dashboard to its address, and
    binds every interface when given none).
    """
    import logging
    import os

    import dask

    distributed = _distributed()
    loopback = f"{LOOPBACK}:0"
    threads = workers if workers is not None else (os.cpu_count() or 1)
    config: dict[str, Any] = {"distributed.worker.http.routes": []}
    if dashboard is None:
        config["distributed.scheduler.http.routes"] = []
    inproc = {"protocol": "inproc://", "dashboard": False, "dashboard_address": loopback}
    scheduler = {**inproc}
    if dashboard is not None:
        scheduler.update(dashboard=True, dashboard_address=dashboard_address(dashboard))
    with dask.config.set(config):  # read as the servers start, inside the constructor
        return distributed.SpecCluster(
            scheduler={"cls": distributed.Scheduler, "options": scheduler},
            workers={0: {"cls": distributed.Worker, "options": {**inproc, "nthreads": threads}}},
            silence_logs=logging.WARNING,
        )


@dataclass
class RunReport:
    """What a run did.

    Attributes:
        blocks_resumed: Blocks found on disk and not computed again.
        blocks_computed: Blocks computed by this run.
        tasks: Tasks run.
        wall_seconds: Wall time of the computation [s].
        compute_seconds: Sum of the tasks' compute times on their workers [s].
        threads: Worker threads of the cluster.
        worker_memory: Largest buffers + table of one task [bytes].
        driver_memory: The driver's dense statistics [bytes].
        damaged: Files of the output folder's blocks found damaged or missing, repaired
            (their blocks computed again).
    """

    blocks_resumed: int = 0
    blocks_computed: int = 0
    tasks: int = 0
    wall_seconds: float = 0.0
    compute_seconds: float = 0.0
    threads: int = 0
    worker_memory: int = 0
    driver_memory: int = 0
    damaged: list[str] = field(default_factory=list)


def run(
    job: Job,
    size: int,
    client: Any,
    store: BlockStore | None,
    progress: Callable[[Progress], None] | None = None,
    per_task: int | None = None,
) -> tuple[VoxelStats, RunReport]:
    """Compute every block of ``job`` not already in ``store`` on ``client``'s cluster.

    Args:
        job: The map's work.
        size: Voxels of the grid.
        client: A ``distributed.Client``.
        store: The partial results (read to resume, written as tasks complete), or None.
        progress: Called after each task with the run's :class:`Progress`.
        per_task: Blocks per task; default: enough tasks for four per thread, at most
            :data:`MAX_BLOCKS_PER_TASK`.

    Returns:
        The statistics of every block, and the run's report.
    """
    distributed = _distributed()
    if store is not None:
        stats, done = store.load()
    else:
        stats, done = VoxelStats.empty(size, job.fields), set()
    report = RunReport(blocks_resumed=len(done), driver_memory=stats.nbytes,
                       damaged=list(store.damaged) if store is not None else [])  # fmt: skip
    todo = [b for b in range(job.plan.blocks) if b not in done]
    report.threads = threads = max(sum(client.nthreads().values()), 1)
    if per_task is None:
        per_task = min(max(-(-len(todo) // (4 * threads)), 1), MAX_BLOCKS_PER_TASK)
    tasks = job.plan.tasks(todo, per_task)
    tracker = Progress(job.plan, done)
    start = time.perf_counter()
    shared = client.scatter(job, broadcast=True, hash=False) if tasks else None
    pending = iter(tasks)
    window = distributed.as_completed()
    in_flight: set[Any] = set()

    def submit() -> None:
        blocks = next(pending, None)
        if blocks is not None:
            future = client.submit(compute_blocks, shared, blocks, pure=False)
            in_flight.add(future)
            window.add(future)

    since_fold = 0
    try:
        for _ in range(2 * threads):
            submit()
        for future in window:
            result: TaskResult = future.result()
            in_flight.discard(future)
            future.release()
            stats.merge(result.part)
            done.update(result.blocks)
            if store is not None:
                store.write_part(result.blocks, result.part)
                since_fold += 1
                if since_fold >= FOLD_PARTS:
                    store.fold()
                    since_fold = 0
            report.tasks += 1
            report.blocks_computed += len(result.blocks)
            report.compute_seconds += result.seconds
            report.worker_memory = max(report.worker_memory, result.memory)
            tracker.update(result.blocks, job.plan)
            if progress is not None:
                progress(tracker)
            submit()
    except BaseException:
        client.cancel(list(in_flight))
        raise
    if store is not None:
        store.fold()
    report.wall_seconds = time.perf_counter() - start
    return stats, report
