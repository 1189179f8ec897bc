"""Controller.step against a bare Resolver.solve loop: what the teleoperation loop costs.

Run from a checkout: ``python benchmarks/bench_controller.py --out DIR`` (``--record`` writes
``benchmarks/results/controller.json``, ``--quick`` a short smoke run).

Per arm (barker6, panda): random operator commands (``random_commands``, seeded, hand
frame) drive a default ``Controller`` (deadman, drift correction every 0.1 s, log, resolver
strategy). At every tick, in an order shuffled per tick, the two contenders run at the
controller's current q with the same command:

- bare: ``Resolver.solve(q, twist, ref="local")`` and the Euler update ``q + qdot dt``;
- controller: ``Controller.step(twist, "local")`` (the kinematics and singular values of the
  tick, the drift check, the strategy, the same solve, ``pinocchio.integrate``, the record).

Median and p99 [us] of each, and the controller's overhead ``(ctl - bare) / ctl`` of the
medians. One core, BLAS threads pinned to 1.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import machine_info, source_state
from timing import one_core, progress, statistics

import rrc_pin
from rrc_pin.control import Controller
from rrc_pin.control.random_operator import random_commands

RESULTS = Path(__file__).resolve().parent / "results"
STARTS = {
    "barker6": np.deg2rad([20.0, 30.0, 60.0, 10.0, 40.0, 0.0]),
    "panda": np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.7]),
}


def bench_arm(name: str, steps: int, seed: int) -> dict[str, object]:
    """Both contenders over ``steps`` ticks of one session on arm ``name``."""
    arm = rrc_pin.load(name)
    ctl = Controller(arm, q0=STARTS[name])
    bare = rrc_pin.Resolver(arm, dt=ctl.dt)
    rng = np.random.default_rng(seed)
    commands = random_commands(rng, steps * ctl.dt, ctl.dt, pause=0.0)
    times: dict[str, list[float]] = {"bare": [], "controller": []}
    for twist in commands[:50]:  # warm-up
        bare.solve(ctl.q, twist, ref="local")
        ctl.step(twist, "local")
    for twist in commands:
        q = ctl.q.copy()
        for who in rng.permutation(["bare", "controller"]):
            start = time.perf_counter()
            if who == "bare":
                r = bare.solve(q, twist, ref="local")
                _ = q + r.qdot * ctl.dt
            else:
                ctl.step(twist, "local")
            times[str(who)].append(time.perf_counter() - start)
    stats = {who: statistics(np.array(t)) for who, t in times.items()}
    overhead = 1.0 - stats["bare"]["median_us"] / stats["controller"]["median_us"]
    labels, counts = np.unique(ctl.log.column("status")[-steps:], return_counts=True)
    statuses = dict(zip(labels, counts, strict=True))
    return {"steps": steps, "bare": stats["bare"], "controller": stats["controller"],
            "overhead": overhead, "statuses": {str(k): int(v) for k, v in statuses.items()}}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--out", type=Path, default=None, help="folder for controller.json")
    where.add_argument("--record", action="store_true", help="write benchmarks/results/")
    parser.add_argument("--quick", action="store_true", help="a short smoke run")
    parser.add_argument("--steps", type=int, default=3000, help="ticks per arm")
    args = parser.parse_args(argv)
    steps = 200 if args.quick else args.steps
    result: dict[str, object] = {"machine": machine_info(), "source": source_state(), "arms": {}}
    with one_core([]):
        for name in STARTS:
            progress(f"controller benchmark: {name}, {steps} ticks")
            result["arms"][name] = bench_arm(name, steps, seed=7)  # type: ignore[index]
    for name, r in result["arms"].items():  # type: ignore[attr-defined]
        print(f"{name:8s} bare {r['bare']['median_us']:6.1f} / {r['bare']['p99_us']:6.1f} us   "
              f"controller {r['controller']['median_us']:6.1f} / {r['controller']['p99_us']:6.1f}"
              f" us (median / p99)   overhead {100 * r['overhead']:4.1f} % of the step")
    out = RESULTS if args.record else args.out
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "controller.json").write_text(json.dumps(result, indent=2) + "\n")
        print(f"written: {out / 'controller.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
