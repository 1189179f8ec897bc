"""The resolver's tick against another checkout's and PlaCo's, interleaved in one process.

On a shared, loaded machine a timing means something only against another one taken under the
same load: every step calls each contender once, in an order drawn at random, on the same
configuration and command, and the table gives medians and 99th percentiles of the wall-clock
time and of the thread's CPU time per call, and their ratios. Run from a checkout, where
PlaCo imports (docs/benchmarks.md, "The peers' environment")::

    PYTHONPATH=. .venv-peers/bin/python benchmarks/ab_tick.py --reference ../old-checkout

``--reference PATH`` imports a second rrc-pin from another checkout under its own name
(:func:`load_reference`); ``--no-placo`` leaves PlaCo out. Workloads (:data:`WORKLOADS`):
panda's and rrc_k1607's default twist tick, baxter's two hands and posture weighted and
strict (benchmarks/bench_tasks.py's), each along a trajectory of benchmarks/workloads.py from
a fresh seed (printed); the rows ``damped`` hold the ticks the reference answered ``damped``.
``--only collision9`` (``collision36``, ``collision81``, ``collision221``): the two facing
pandas of benchmarks/bench_collision.py with that many pairs, along the closed loop the
reference drives (without PlaCo).
"""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
import workloads  # noqa: E402

import rrc_pin  # noqa: E402

Array = np.ndarray
DT = 0.01
WORKLOADS = ("panda", "rrc_k1607", "baxter_weighted", "baxter_strict")


def load_reference(path: Path) -> Any:
    """The ``rrc_pin`` package of the checkout at ``path``, imported beside this one.

    Every module of it is imported while it stands in ``sys.modules`` under the name
    ``rrc_pin``, then moved aside: its functions keep their own modules (a module that imports
    another only when called would find this checkout's).
    """
    mine = {k: v for k, v in sys.modules.items() if k == "rrc_pin" or k.startswith("rrc_pin.")}
    for key in mine:
        del sys.modules[key]
    sys.path.insert(0, str(path))
    try:
        reference = importlib.import_module("rrc_pin")
        skip = ("rrc_pin.console", "rrc_pin.maps", "rrc_pin.cli", "rrc_pin.demo")
        for info in pkgutil.walk_packages(reference.__path__, "rrc_pin."):
            if not info.name.startswith(skip):
                importlib.import_module(info.name)
        for name in ("Resolver", "FrameTask", "PostureTask", "load", "combine", "CollisionModel",
                     "CollisionLimit", "JointLimits"):
            getattr(reference, name)
    finally:
        sys.path.remove(str(path))
        for key in [k for k in sys.modules if k == "rrc_pin" or k.startswith("rrc_pin.")]:
            del sys.modules[key]
        sys.modules.update(mine)
    return reference


def _tasks_solver(lib: Any, robot: Any, strict: bool) -> Callable[[Array, Array], Any]:
    """Baxter's two hands and a posture, as benchmarks/bench_tasks.py calls them."""
    resolver = lib.Resolver(robot, dt=DT)
    left, right = robot.tool_frames
    posture = lib.PostureTask(robot.neutral(), gain=1.0, weight=0.01)

    def solve(q: Array, x: Array) -> Any:
        hands = [lib.FrameTask(left, x[:6]), lib.FrameTask(right, x[6:])]
        if strict:
            return resolver.solve(q, [hands, posture], priority="strict")
        return resolver.solve(q, [*hands, posture])

    return solve


def contenders(workload: str, libs: dict[str, Any], placo: bool) -> dict[str, Callable[..., Any]]:
    """Each library's tick for ``workload``: ``tick(q, x) -> rates``."""
    arm = "baxter" if workload.startswith("baxter") else workload
    out: dict[str, Callable[..., Any]] = {}
    for label, lib in libs.items():
        robot = lib.load(arm)
        if arm == "baxter":
            out[label] = _tasks_solver(lib, robot, workload.endswith("strict"))
        else:
            out[label] = lib.Resolver(robot, dt=DT).solve
    if placo:
        from mink_peer import urdf_of
        from placo_peer import PlacoPeer, placo_urdf

        robot = rrc_pin.load(arm)
        urdf = placo_urdf(robot, urdf_of(robot), Path(tempfile.mkdtemp()))
        if arm == "baxter":
            peer = PlacoPeer(str(urdf), list(robot.joint_names), list(robot.tool_frames), DT,
                             posture_weight=0.01, posture_gain=1.0, q_ref=robot.neutral(),
                             strict=workload.endswith("strict"))  # fmt: skip
        else:
            peer = PlacoPeer(str(urdf), list(robot.joint_names), [robot.tool_frame], DT)
        out["PlaCo"] = peer.step
    return out


def collision(libs: dict[str, Any], pairs: int, steps: int) -> tuple[Any, Any, dict[str, Any]]:
    """benchmarks/bench_collision.py's cell with ``pairs`` pairs (9, 36, 81 or 221): each
    library's tick, and the states of its closed loop driven by the first library."""
    import bench_collision as bc

    k = {9: 8, 36: 6, 81: 4, 221: None}[pairs]
    ticks: dict[str, Callable[..., Any]] = {}
    robots = []
    for label, lib in libs.items():
        panda = lib.load("panda")
        facing = np.diag([-1.0, -1.0, 1.0, 1.0])
        facing[0, 3] = 1.0
        robot = lib.combine({"left": (panda, np.eye(4)), "right": (panda, facing)})
        cm = lib.CollisionModel(robot, "capsules")
        limit = lib.CollisionLimit(cm, bc.SAFETY, bc.DETECTION, 0.5, pairs=bc.pair_set(cm, k))
        resolver = lib.Resolver(robot, DT, limits=[lib.JointLimits(), limit])
        tasks = [lib.FrameTask(f, rows="position") for f in robot.tool_frames]
        ticks[label] = _collision_tick(resolver, tasks)
        robots.append(robot)
    driver, robot = next(iter(ticks.values())), robots[0]
    q, Q, X = robot.ready().copy(), [], []
    for _ in range(steps):
        v = bc.commands(robot, q)
        Q.append(q.copy())
        X.append(v)
        q = np.clip(q + DT * np.asarray(driver(q, v).qdot), robot.lower, robot.upper)
    return Q, X, ticks


def _collision_tick(resolver: Any, tasks: list[Any]) -> Callable[[Array, Any], Any]:
    """The hands' position tasks commanded ``v`` (two (3,) rates), strict, as the bench's."""
    def solve(q: Array, v: Any) -> Any:
        for task, twist in zip(tasks, v, strict=True):
            task.set_twist(twist)
        return resolver.solve(q, [tasks], priority="strict")

    return solve


def run(workload: str, libs: dict[str, Any], placo: bool, steps: int, seed: int) -> None:
    """Time every contender on one workload, interleaved, and print the table."""
    if workload.startswith("collision"):
        Q, X, ticks = collision({"driver": libs.get("reference", rrc_pin), **libs},
                                int(workload[len("collision"):]), steps)  # fmt: skip
        del ticks["driver"]
    else:
        arm = "baxter" if workload.startswith("baxter") else workload
        frames = 2 if arm == "baxter" else 1
        driver = contenders(workload, {"driver": rrc_pin}, False)["driver"]
        robot = rrc_pin.load(arm)
        rng = np.random.default_rng(seed)
        Q, X, _ = workloads.record(robot, frames, steps, rng, DT,
                                   lambda q, x: np.asarray(driver(q, x).qdot))  # fmt: skip
        ticks = contenders(workload, libs, placo)
    names = list(ticks)
    wall = {n: np.zeros(steps) for n in names}
    cpu = {n: np.zeros(steps) for n in names}
    failed = dict.fromkeys(names, 0)
    status: list[str] = []
    for name in names:  # compiled code loaded, caches warm
        try:
            ticks[name](Q[0], X[0])
        except RuntimeError:
            pass
    order = np.random.default_rng(seed + 1)
    for k in range(steps):
        q, x = Q[k], X[k]
        for name in order.permutation(names).tolist():
            tick = ticks[name]
            c0, t0 = time.thread_time_ns(), time.perf_counter_ns()
            try:
                out = tick(q, x)
            except RuntimeError:  # PlaCo's infeasible hard tasks
                out = None
                failed[name] += 1
            t1, c1 = time.perf_counter_ns(), time.thread_time_ns()
            wall[name][k], cpu[name][k] = (t1 - t0) * 1e-3, (c1 - c0) * 1e-3
            if name == ("reference" if "reference" in names else "this"):
                status.append(getattr(out, "status", ""))
    kinds = {"all": np.ones(steps, bool)}
    if "reference" in names:
        kinds["damped"] = np.array([s == "damped" for s in status])
    load = os.getloadavg()[0]
    print(f"\n{workload}: {steps} steps, seed {seed}, load {load:.1f}; failures {failed}")
    print(f"{'ticks':8s} {'contender':10s} {'n':>6s} {'median':>8s} {'p99':>8s} "
          f"{'cpu med':>8s} {'cpu p99':>8s}   ratios (median, cpu p99) to the others")  # fmt: skip
    for kind, mask in kinds.items():
        if not mask.any():
            continue
        stats = {
            n: (np.median(wall[n][mask]), np.percentile(wall[n][mask], 99),
                np.median(cpu[n][mask]), np.percentile(cpu[n][mask], 99))
            for n in names
        }  # fmt: skip
        for n in names:
            m, p, cm, cp = stats[n]
            ratios = ", ".join(f"{o} {m / stats[o][0]:.2f} / {cp / stats[o][3]:.2f}"
                               for o in names if o != n)  # fmt: skip
            print(f"{kind:8s} {n:10s} {int(mask.sum()):6d} {m:8.1f} {p:8.1f} {cm:8.1f} {cp:8.1f}"
                  f"   {ratios}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", type=Path, default=None)
    parser.add_argument("--no-placo", action="store_true")
    parser.add_argument("--steps", type=int, default=3000)
    parser.add_argument("--seed", type=int, default=None)
    parser.add_argument("--only", nargs="*", default=list(WORKLOADS))
    args = parser.parse_args()
    libs: dict[str, Any] = {"this": rrc_pin}
    if args.reference is not None:
        libs["reference"] = load_reference(args.reference)
    seed = workloads.fresh_seed() if args.seed is None else args.seed
    for workload in args.only:
        run(workload, libs, not args.no_placo, args.steps, seed)


if __name__ == "__main__":
    main()
