"""Collision-constrained steps of a two-arm cell: rrc-pin's CollisionLimit, mink's
CollisionAvoidanceLimit and pink's SelfCollisionBarrier, side by side in one process.

Run with the peers' environment from a checkout:
``PYTHONPATH=. .venv-peers/bin/python benchmarks/bench_collision.py --out DIR`` (``--record``
writes ``benchmarks/results/collision.{json,png}``; ``--quick`` a short smoke run).

``--soak`` (rrc-pin alone, any environment) runs the held-out soak of benchmarks/collision_soak.py
instead: 200 random starts in penetration and each scene's 10-minute sessions (``--quick``: 12
starts, 10 s), written as ``collision_soak.{json,png}``.

The cell: two pandas facing each other 1.0 m apart (``rrc_pin.combine``), capsule geometry
(:class:`rrc_pin.CollisionModel`); for mink the same joint tree and capsules written as MJCF
(:mod:`collision_peers`; MuJoCo's ``mj_geomDistance`` equals coal's distance to 1e-15 on them).
Each hand is commanded toward the other (0.3 m/s at most, position rows) plus a tangential
0.05 m/s along +z, so that the hands meet and then have to slide. Every contender runs its own
closed loop (its own q, integrated at 100 Hz) on the same commands, in two modes, each from
fresh contenders: tight (each contender 250 ticks in a row, by turns: caches and branch
predictors hot for it) and interleaved (every tick each contender once, in an order drawn at
random: each step finds the caches its peers left; after pink's milliseconds of step a tick of
ours finds little of its code and data there).

Pair sets (the number of pairs each library checks): the inter-arm pairs between links from
``panda_link<K>`` to the fingers for K = 8 (hand and fingers), 6, 4, then every pair of the
cell (224, self-collision included).

Per contender, pair set and mode: the step's time (median and the other percentiles, wall clock and
the thread's CPU time; one call from q and the command to the joint rates, distances included); per
contender and pair set, of its tight loop: the minimum distance over every pair of the cell reached
(coal, the same capsules), the tangential progress while constrained (the hands' mean +z speed over
the commanded 0.05 m/s, on ticks where a pair is closer than twice the safety distance), and the
largest joint-rate jump at a tick where a pair enters the detection distance.
Settings: safety 0.02 m, detection 0.10 m; rrc-pin's gain 0.5 m/s; mink's gain 0.85 (its
default) with the same distances; pink's barrier gain 1, d_min 0.02, every pair of the set.
"""

from __future__ import annotations

import math
import os
import sys
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np
import pinocchio as pin
from collision_peers import mjcf
from collision_soak import soak
from script import arguments, make_parser, mark_quick, measure, pyplot, write
from timing import BLOCK, closed_loops, progress, statistics, timed

import rrc_pin
from rrc_pin import CollisionLimit, CollisionModel, FrameTask, JointLimits, Resolver

DT = 0.01
SAFETY, DETECTION = 0.02, 0.10
SPEED, SLIDE = 0.3, 0.05
LINKS = (8, 6, 4, None)
MODES = ("tight", "interleaved")
SEED = 2026
"""Of the interleaved mode's orders."""
WARM_UP = 10
"""First ticks of each loop left out of the statistics (first calls' set-up)."""


def cell() -> tuple[rrc_pin.Robot, CollisionModel]:
    panda = rrc_pin.load("panda")
    facing = np.eye(4)
    facing[:3, :3] = np.diag([-1.0, -1.0, 1.0])
    facing[0, 3] = 1.0
    robot = rrc_pin.combine({"left": (panda, np.eye(4)), "right": (panda, facing)})
    return robot, CollisionModel(robot, "capsules")


def link_number(body: str) -> int:
    name = body.split("/")[-1]
    if name.startswith("panda_link"):
        return int(name[len("panda_link")].rstrip("_"))
    return 8  # hand, fingers


def pair_set(cm: CollisionModel, k: int | None) -> list[tuple[str, str]]:
    if k is None:
        return list(cm.pairs)
    return [(a, b) for a, b in cm.pairs if a.split("/")[0] != b.split("/")[0]
            and link_number(a) >= k and link_number(b) >= k]  # fmt: skip


def commands(robot: rrc_pin.Robot, q: np.ndarray) -> list[np.ndarray]:
    hands = [robot.frame_pose(q, f)[:3, 3] for f in robot.tool_frames]
    out = []
    for me, other in ((0, 1), (1, 0)):
        v = 2.0 * (hands[other] - hands[me])
        v *= min(1.0, SPEED / max(float(np.linalg.norm(v)), 1e-12))
        out.append(v + np.array([0.0, 0.0, SLIDE]))
    return out


class Rrc:
    label = "rrc-pin CollisionLimit"

    def __init__(self, robot, cm, pairs):
        limit = CollisionLimit(cm, SAFETY, DETECTION, 0.5, pairs=pairs)
        self.resolver = Resolver(robot, DT, limits=[JointLimits(), limit])
        self.tasks = [FrameTask(f, rows="position") for f in robot.tool_frames]
        self.limit_times: list[float] = []  # the limit's own share: distances and rows
        self.limit_rows: list[int] = []
        constraints = limit.constraints

        def timed(*args):
            start = time.perf_counter()
            out = constraints(*args)
            self.limit_times.append(time.perf_counter() - start)
            self.limit_rows.append(0 if out.h is None else out.h.size)
            return out

        limit.constraints = timed

    def step(self, q, v):
        for task, twist in zip(self.tasks, v, strict=True):
            task.set_twist(twist)
        return np.array(self.resolver.solve(q, [self.tasks], priority="strict").qdot)


class Mink:
    label = "mink CollisionAvoidanceLimit"

    def __init__(self, robot, cm, pairs):
        import mink
        import mujoco

        self.mink = mink
        self.model = mujoco.MjModel.from_xml_string(mjcf(robot, cm.scene.geometry,
                                                         robot.tool_frames))  # fmt: skip
        self.conf = mink.Configuration(self.model)
        self.tasks = [mink.FrameTask(f, "site", position_cost=1.0, orientation_cost=0.0)
                      for f in robot.tool_frames]  # fmt: skip
        velocity = {robot.model.names[j]: float(robot.velocity_limit[j - 1])
                    for j in range(1, robot.model.njoints)}  # fmt: skip
        self.limits = [
            mink.ConfigurationLimit(self.model), mink.VelocityLimit(self.model, velocity),
            mink.CollisionAvoidanceLimit(self.model, [([a], [b]) for a, b in pairs], 0.85,
                                         SAFETY, DETECTION),
        ]  # fmt: skip

    def step(self, q, v):
        self.conf.update(q)
        for task, twist in zip(self.tasks, v, strict=True):
            T = self.conf.get_transform_frame_to_world(task.frame_name, "site")
            target = self.mink.SE3.from_rotation_and_translation(
                T.rotation(), T.translation() + twist * DT)
            task.set_target(target)
        return self.mink.solve_ik(self.conf, self.tasks, DT, "daqp", 1e-3, limits=self.limits)


class Pink:
    label = "pink SelfCollisionBarrier"

    def __init__(self, robot, cm, pairs):
        import pink
        from pink.barriers import SelfCollisionBarrier

        self.pink, self.robot = pink, robot
        geometry = pin.GeometryModel()
        for obj in cm.scene.geometry.geometryObjects:
            geometry.addGeometryObject(obj)
        for a, b in pairs:
            geometry.addCollisionPair(pin.CollisionPair(geometry.getGeometryId(a),
                                                        geometry.getGeometryId(b)))  # fmt: skip
        self.geometry = geometry
        self.data = robot.model.createData()
        self.gdata = pin.GeometryData(geometry)
        self.tasks = [pink.tasks.FrameTask(f, position_cost=1.0, orientation_cost=0.0)
                      for f in robot.tool_frames]  # fmt: skip
        self.barriers = [SelfCollisionBarrier(len(pairs), gain=1.0, d_min=SAFETY)]

    def step(self, q, v):
        conf = self.pink.Configuration(self.robot.model, self.data, q, copy_data=False,
                                       collision_model=self.geometry,
                                       collision_data=self.gdata)  # fmt: skip
        for task, twist in zip(self.tasks, v, strict=True):
            T = conf.get_transform_frame_to_world(task.frame).copy()
            T.translation = T.translation + twist * DT
            task.set_target(T)
        return self.pink.solve_ik(conf, self.tasks, DT, "daqp", barriers=self.barriers,
                                  safety_break=False)  # fmt: skip


class Loop:
    """One contender's closed loop on the cell (its own q, integrated at 100 Hz), and what it
    reached: the minimum distance, the tangential progress while constrained, the largest
    joint-rate jump where a pair enters the detection distance."""

    def __init__(self, contender: Any, robot: rrc_pin.Robot, cm: CollisionModel) -> None:
        self.contender, self.robot, self.cm = contender, robot, cm
        self.q = robot.ready().copy()
        self.minimum, self.jump = np.inf, 0.0
        self.progress: list[float] = []
        self.last: tuple[Any, int] = (None, 0)

    def __call__(self, k: int) -> tuple[float, float]:
        """Tick ``k``: the contender's step timed (wall-clock and CPU seconds), then its
        integration and what it reached."""
        robot, q = self.robot, self.q
        v = commands(robot, q)
        qdot, wall, cpu = timed(lambda: self.contender.step(q, v))
        qdot = np.nan_to_num(np.asarray(qdot, dtype=float))
        hands_before = [robot.frame_pose(q, f)[2, 3] for f in robot.tool_frames]
        self.q = q = np.clip(q + DT * qdot, robot.lower, robot.upper)
        prox = self.cm.proximity_at(q, DETECTION)
        near = len(prox.names)
        if near:
            d = float(prox.distance.min())
            self.minimum = min(self.minimum, d)
            if d < 2 * SAFETY:
                hands = [robot.frame_pose(q, f)[2, 3] for f in robot.tool_frames]
                self.progress.append(np.mean(np.subtract(hands, hands_before)) / DT / SLIDE)
        previous, count = self.last
        if previous is not None and near > count:
            self.jump = max(self.jump, float(np.abs(qdot - previous).max()))
        self.last = (qdot, near)
        return wall, cpu


def run(ticks: int) -> dict[str, Any]:
    """Every contender on every pair set, in both modes (module docstring)."""
    robot, cm = cell()
    rows = []
    order = np.random.default_rng(SEED)
    for k in LINKS:
        pairs = pair_set(cm, k)
        modes, loops = {}, {}
        for mode in MODES:
            loops[mode] = {c.label: Loop(c, robot, cm)
                           for c in (kind(robot, cm, pairs) for kind in (Rrc, Mink, Pink))}
            progress(f"{len(pairs)} pairs: {mode}")
            modes[mode] = closed_loops(mode, loops[mode], ticks, order)  # fmt: skip
        for label, loop in loops["tight"].items():
            c = loop.contender
            share = {}
            if isinstance(c, Rrc):
                share = {"limit_median_us": float(np.median(c.limit_times[WARM_UP:]) * 1e6),
                         "limit_rows_median": float(np.median(c.limit_rows[WARM_UP:]))}  # fmt: skip
            rows.append({
                "contender": label, "pairs": len(pairs),
                "modes": {mode: statistics(*(t[WARM_UP:] for t in modes[mode][label]))
                          for mode in MODES},
                "min_distance_m": float(loop.minimum),
                "tangential_progress": float(np.mean(loop.progress)) if loop.progress else None,
                "constrained_ticks": len(loop.progress),
                "largest_activation_jump": loop.jump, **share,
            })  # fmt: skip
            progress(str(rows[-1]))
    return {"settings": {"ticks": ticks, "dt": DT, "safety": SAFETY, "detection": DETECTION,
                         "speed": SPEED, "slide": SLIDE, "modes": list(MODES)},
            "rows": rows}  # fmt: skip


def _table(results: dict[str, Any], full: bool) -> str:
    """One row per pair set: each contender's median / CPU p99 step, tight and interleaved,
    and its minimum distance."""
    rows = results["rows"]
    labels = list(dict.fromkeys(r["contender"] for r in rows))
    sets = sorted({r["pairs"] for r in rows})
    head = "| pairs | " + " | ".join(
        f"{label}, tight [us] | interleaved [us] | min [mm]" for label in labels)
    rule = "| ---: |" + " ---: | ---: | ---: |" * len(labels) + (" ---: |" if full else "")
    lines = [head + (" | rrc-pin limit's share [us] (rows) |" if full else " |"), rule]
    for n in sets:
        by = {r["contender"]: r for r in rows if r["pairs"] == n}
        cells = [" | ".join(f"{m['median_us']:,.0f} / {m['cpu_p99_us']:,.0f}"
                            for m in (by[lb]["modes"][mode] for mode in MODES))
                 + f" | {_millimetres(by[lb]['min_distance_m'])}" for lb in labels]  # fmt: skip
        line = f"| {n} | " + " | ".join(cells) + " |"
        ours = by.get(Rrc.label, {})
        if full and "limit_median_us" in ours:
            line += f" {ours['limit_median_us']:,.0f} ({ours['limit_rows_median']:.0f}) |"
        elif full:
            line += " - |"
        lines.append(line)
    load = results.get("load_average", {})
    start, end = (load.get(k, [float("nan")])[0] for k in ("start", "end"))
    s = results["settings"]
    never = "" if all(math.isfinite(r["min_distance_m"]) for r in rows) else (
        f" min -: no pair came within the detection distance ({s['detection'] * 1e3:.0f} mm).")
    lines += ["", "Step time: the wall-clock median / the CPU time's p99. "
              f"Safety {s['safety'] * 1e3:.0f} mm, {s['ticks']:,} ticks a pair set and "
              f"mode, one process: tight (each contender {BLOCK} ticks in a row, by turns) and "
              "interleaved (every tick each contender once, in an order drawn at random: each "
              "finds the caches its peers left); load average "
              f"{start:.1f} at the start, {end:.1f} at the end (2 cores).{never}"]  # fmt: skip
    return "\n".join(lines)


def _millimetres(distance: float) -> str:
    """A minimum distance [m] in mm, or ``-`` where no pair came near (infinite)."""
    return f"{distance * 1e3:.1f}" if math.isfinite(distance) else "-"


def readme_table(results: dict[str, Any]) -> str:
    """The README's collision table: step time and minimum distance per pair set."""
    return _table(results, full=False)


def docs_section(results: dict[str, Any]) -> str:
    """docs/benchmarks.md: the table with the limit's share, tangential progress and jumps."""
    lines = [_table(results, full=True), "",
             "| contender | pairs | tangential progress | constrained ticks | "
             "largest activation jump [rad/s] |",
             "| --- | ---: | ---: | ---: | ---: |"]  # fmt: skip
    for r in results["rows"]:
        progress = r["tangential_progress"]
        shown = "-" if progress is None else f"{progress:.2f}"
        jump = r["largest_activation_jump"]
        lines.append(f"| {r['contender']} | {r['pairs']} | {shown} | "
                     f"{r['constrained_ticks']} | {jump:.2f} |")  # fmt: skip
    return "\n".join(lines)


def plot(results: dict[str, Any], path: Path) -> bool:
    plt = pyplot()
    if plt is None:
        return False
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    labels = sorted({r["contender"] for r in results["rows"]})
    for label in labels:
        rows = sorted((r for r in results["rows"] if r["contender"] == label),
                      key=lambda r: r["pairs"])  # fmt: skip
        x = [r["pairs"] for r in rows]
        line = ax[0].plot(x, [r["modes"]["tight"]["median_us"] for r in rows], "o-",
                          label=f"{label}, tight")[0]  # fmt: skip
        ax[0].plot(x, [r["modes"]["interleaved"]["median_us"] for r in rows], "^:",
                   color=line.get_color(), label=f"{label}, interleaved")  # fmt: skip
        if all("limit_median_us" in r for r in rows):
            ax[0].plot(x, [r["limit_median_us"] for r in rows], "s--", color=line.get_color(),
                       label=f"{label}: the limit's share")  # fmt: skip
        near = [(n, r["min_distance_m"] * 1e3) for n, r in zip(x, rows, strict=True)
                if math.isfinite(r["min_distance_m"])]  # fmt: skip
        never = [n for n, r in zip(x, rows, strict=True) if not math.isfinite(r["min_distance_m"])]
        note = f" (no pair within {DETECTION * 1e3:.0f} mm at {never} pairs: not drawn)"
        ax[1].plot([n for n, _ in near], [d for _, d in near], "o-", color=line.get_color(),
                   label=label + (note if never else ""))  # fmt: skip
    ax[0].set(xscale="log", yscale="log", xlabel="pairs", ylabel="step median [us]")
    ax[1].axhline(SAFETY * 1e3, color="gray", ls="--", label="safety distance")
    ax[1].set(xscale="log", xlabel="pairs", ylabel="minimum distance [mm]")
    ax[0].legend(fontsize=8)
    ax[1].legend(fontsize=7)
    mark_quick(fig, results)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def plot_soak(results: dict[str, Any], path: Path) -> bool:
    """The soak: each start's ticks to leave the safety distance against the command's time,
    and each session's nearest pair."""
    plt = pyplot()
    if plt is None:
        return False
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    for kind in sorted({r["kind"] for r in results["starts"]}):
        rows = [r for r in results["starts"] if r["kind"] == kind and r["exit_ticks"] is not None]
        ax[0].plot([r["deadline"] * DT for r in rows], [r["exit_ticks"] * DT for r in rows], "o",
                   ms=3, label=kind)  # fmt: skip
    top = max([r["deadline"] * DT for r in results["starts"]] + [0.1])
    ax[0].plot([0, top], [0, top], color="gray", ls="--", label="the command's time")
    ax[0].set(xlabel="the command's time to leave [s]", ylabel="out of the safety distance [s]")
    ax[0].legend(fontsize=8)
    sessions = results["sessions"]
    labels = [f"{s['scene']}{' (turning)' if s['turning'] else ''}" for s in sessions]
    ax[1].barh(labels, [s["min_distance_m"] * 1e3 for s in sessions])
    ax[1].axvline(SAFETY * 1e3, color="gray", ls="--")
    ax[1].set(xlabel="minimum distance [mm]", xlim=(SAFETY * 1e3 - 2, SAFETY * 1e3 + 1))
    for k, s in enumerate(sessions):
        ax[1].text(SAFETY * 1e3 - 1.9, k, f"{s['fallback_ticks']} fallback ticks", va="center",
                   fontsize=7, color="white")  # fmt: skip
    mark_quick(fig, results)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def main(argv: list[str] | None = None) -> None:
    parser = make_parser(__doc__, "collision")
    parser.add_argument("--ticks", type=int, default=None, help="ticks per pair set")
    parser.add_argument("--soak", action="store_true", help="the held-out soak, not the peers")
    args = arguments(parser, argv)
    if args.soak:
        starts, minutes = (12, 10 / 60) if args.quick else (200, 10.0)
        soaked = measure("collision_soak", args.quick, lambda: soak(starts, minutes, 0, progress),
                         "coal")  # fmt: skip
        print(soaked["summary"])
        write(args, "collision_soak", soaked, lambda p: plot_soak(soaked, p))
        return
    ticks = args.ticks or (60 if args.quick else 1000)
    results = measure("collision", args.quick, lambda: run(ticks), "mink", "mujoco", "pink",
                      "coal")  # fmt: skip
    for r in results["rows"]:
        print(r)
    write(args, "collision", results, lambda p: plot(results, p))


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    main()
