"""Proximity per tick (rrc_pin.geometry) against computing every pair, and the hull build cost.

Run from a checkout: ``PYTHONPATH=. python benchmarks/geometry_timing.py`` (``--ticks N``,
default 2000).
Prints a Markdown table (the one docs/api.md records) and the conditions: CPU, load, versions.

Scenes (detection distance 0.10 m):

- ``panda``: one panda's self-collision;
- ``two pandas``: two pandas combined facing each other, bases 0.8 m apart on x (the second
  turned half a turn about z), their hands within reach of each other;
- ``panda + table``: one panda, a table top (a box) under its hand and a floor half-space.

Configurations: each arm's ready pose plus a uniform draw of +-0.6 rad per joint, clipped to
the limits (seeded): near the poses an operator works in, where pairs come and go within the
detection distance (uniform draws over the whole range fold the arms through themselves).

Per scene and geometry variant, per tick, interleaved (each tick calls every contender once):

- ``proximity``: ``CollisionModel.proximity(kin, data, 0.10)`` with ``kin.data`` computed
  beforehand (the resolver has it: its tasks' Jacobians), so the time is the query's own;
- ``all pairs``: the same model's active pairs all computed by coal
  (``pinocchio.updateGeometryPlacements`` + ``computeDistances``) and the rows below the
  detection distance gathered from the results in a Python loop over every pair (the naive
  query, which the issue measured at 0.68 ms for 1,296 pairs);
- ``all pairs, C++ only``: ``updateGeometryPlacements`` + ``computeDistances`` without
  reading anything back (the floor of computing every pair: no query can stop there, it
  would still have to read the results).

The ratio is the contender's time over ``proximity``'s (above 1: proximity is faster).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pinocchio as pin

import rrc_pin
from rrc_pin.geometry import CollisionModel
from rrc_pin.kinematics import Kinematics, Layout

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import machine_info

DETECTION = 0.10
SPREAD = 0.6


def scenes() -> list[tuple[str, rrc_pin.Robot, str, bool]]:
    panda = rrc_pin.load("panda")
    facing = np.eye(4)
    facing[:3, :3] = np.diag([-1.0, -1.0, 1.0])
    facing[0, 3] = 0.8
    two = rrc_pin.combine({"left": (panda, np.eye(4)), "right": (panda, facing)})
    return [
        ("panda", panda, "capsules", False),
        ("panda", panda, "hulls", False),
        ("panda", panda, "urdf", False),
        ("panda + table", panda, "capsules", True),
        ("panda + table", panda, "hulls", True),
        ("two pandas", two, "capsules", False),
        ("two pandas", two, "hulls", False),
    ]


def configurations(robot: rrc_pin.Robot, n: int, seed: int = 0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    ready = robot.ready()
    return [np.clip(ready + rng.uniform(-SPREAD, SPREAD, robot.nq), robot.lower, robot.upper)
            for _ in range(n)]  # fmt: skip


def stats(samples: list[float]) -> tuple[float, float, float]:
    a = np.array(samples) * 1e6
    return float(np.median(a)), float(np.percentile(a, 99)), float(a.mean())


def run(ticks: int) -> list[str]:
    rows = [
        "| scene | geometry | bodies | pairs | rows / tick | proximity median (p99) [us] "
        "| all pairs median (p99) [us] | ratio | all pairs, C++ only [us] | ratio |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for label, robot, variant, table in scenes():
        cm = CollisionModel(robot, variant)
        if table:
            T = np.eye(4)
            T[:3, 3] = (0.55, 0.0, 0.15)
            cm.add_box(T, (0.6, 0.8, 0.04), name="table")
            cm.add_halfspace((0, 0, 1), 0.0, name="floor")
        data = cm.create_data()
        model, pdata = robot.model, robot.model.createData()
        layout = Layout.of(robot)
        geometry = cm.scene.geometry
        gdata = geometry.createData()
        names = cm.pairs
        times: dict[str, list[float]] = {"prox": [], "all": [], "cpp": []}
        found = 0
        for q in configurations(robot, ticks):
            q_pin = robot.to_pinocchio(q)
            kin = Kinematics(model, pdata, layout, q, q_pin)
            _ = kin.data  # the resolver's tasks have computed it
            start = time.perf_counter()
            prox = cm.proximity(kin, data, DETECTION)
            times["prox"].append(time.perf_counter() - start)
            found += len(prox.names)
            start = time.perf_counter()
            pin.updateGeometryPlacements(model, pdata, geometry, gdata)
            pin.computeDistances(geometry, gdata)
            near = [(names[k], r.min_distance, r.getNearestPoint1(), r.getNearestPoint2(),
                     r.normal) for k, r in enumerate(gdata.distanceResults)
                    if r.min_distance < DETECTION]  # fmt: skip
            times["all"].append(time.perf_counter() - start)
            assert len(near) == len(prox.names)
            start = time.perf_counter()
            pin.updateGeometryPlacements(model, pdata, geometry, gdata)
            pin.computeDistances(geometry, gdata)
            times["cpp"].append(time.perf_counter() - start)
        p, a, c = stats(times["prox"]), stats(times["all"]), stats(times["cpp"])
        rows.append(
            f"| {label} | {variant} | {len(cm.bodies)} | {len(names)} | {found / ticks:.1f} | "
            f"{p[0]:.1f} ({p[1]:.0f}) | {a[0]:.1f} ({a[1]:.0f}) | {a[0] / p[0]:.1f} | "
            f"{c[0]:.1f} | {c[0] / p[0]:.2f} |"
        )
    return rows


def hull_cost() -> str:
    """The hulls' build cost, in a fresh process (nothing cached yet)."""
    code = (
        "import time, rrc_pin\n"
        "from rrc_pin.geometry import CollisionModel\n"
        "from rrc_pin.geometry.hulls import hull_statistics\n"
        "panda = rrc_pin.load('panda')\n"
        "t = time.perf_counter(); CollisionModel(panda, 'urdf'); urdf = time.perf_counter() - t\n"
        "t = time.perf_counter(); CollisionModel(panda, 'hulls'); hulls = time.perf_counter() - t\n"
        "t = time.perf_counter(); CollisionModel(panda, 'hulls'); again = time.perf_counter() - t\n"
        "s = hull_statistics()\n"
        "print(f'panda: {s.built} hulls built in {s.seconds * 1e3:.1f} ms (qhull); the model "
        "with meshes read: {urdf * 1e3:.0f} ms, then with hulls: {hulls * 1e3:.0f} ms, a second "
        "model with the hulls cached: {again * 1e3:.1f} ms')\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return out.stdout.strip()


def conditions() -> str:
    """The CPU, its load and the versions measured, in one line."""
    info = machine_info("coal")
    return (f"{info['cpu']}, {info['cores']} cores, load average {os.getloadavg()[0]:.2f}; "
            f"Python {info['python']}, Pinocchio {info['pinocchio']}, coal {info['coal']}, "
            f"numpy {info['numpy']}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ticks", type=int, default=2000)
    args = parser.parse_args()
    before = conditions()
    rows = run(args.ticks)
    print("\n".join(rows))
    print()
    print(hull_cost())
    print(f"conditions at start: {before}")
    print(f"load average at end: {os.getloadavg()[0]:.2f}; {args.ticks} ticks per scene")


if __name__ == "__main__":
    main()
