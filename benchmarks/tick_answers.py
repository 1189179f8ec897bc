"""The resolver's answers on recorded ticks of every catalogue arm and mode, to compare two codes.

A redesign of the tick must change its speed, not its answers. ``record`` drives every case
(:data:`CASES`: each catalogue arm in each mode it has, and two collision scenes) along a
trajectory of its own answers and writes the inputs and answers of every tick to a compressed
``.npz``; ``compare`` answers the same ticks, in the same order, with the code imported now,
and prints the largest differences. Run from a checkout::

    python benchmarks/tick_answers.py record answers.npz --ticks 100
    python benchmarks/tick_answers.py compare answers.npz

(with ``PYTHONPATH`` pointing at another checkout, ``record`` records that code's answers).
tests/test_tick_answers.py replays the first ticks of every case from
``tests/data/tick_answers.npz``.

Modes: ``twist`` (``Resolver(arm).solve(q, twist)``, the default), ``tracking``
(``direction_preserving=False``), ``limits`` (a margin, acceleration limits and
``qdot_prev``), ``undamped`` (``damping=None``), ``weighted`` (the hands' frame tasks and a
posture, weighted), ``strict`` (the hands, then the posture) and ``levels`` (each hand a
level, then the posture); ``table`` (panda's hand above a table, position rows, a collision
limit) and ``facing`` (two pandas' hands toward each other, strict, a collision limit).

A trajectory is cut into segments of :data:`SEGMENT` ticks of one kind (as
benchmarks/workloads.py: smooth, too fast, near a limit), each command times a size drawn
from :data:`SIZES`; a segment may start at a random configuration, at the neutral one (often
singular), or just outside a joint's range (recovering).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

import rrc_pin
from rrc_pin import (
    CollisionLimit,
    CollisionModel,
    FrameTask,
    JointLimits,
    PostureTask,
    QPOptions,
    Resolver,
)

Array = npt.NDArray[np.float64]

DT = 0.01
SEGMENT = 20
"""Ticks of one segment."""
SIZES = (1.0, 1.0, 1.0, 1e-3, 10.0, 300.0)
"""Factors on a segment's commands, drawn uniformly."""
STILL = 1e-9
"""A scale below this stands still along the command: its veer is not compared."""
LEVEL_TOL = 1e-6
"""Relative difference of a level's task error within which two answers serve it alike
(:func:`shortfall`)."""
UNHURRIED = QPOptions(time_limit=10.0)
"""The backend's time cap: far beyond any answer, so that the machine's load (which the default
cap of 50 ms turns into a fallback on a slow call) does not change the answers."""
SEED = 20261206
"""The recording's seed (every case draws from ``(SEED, its index)``)."""

Solve = Callable[[Array, Array, Array], Any]


@dataclass(frozen=True)
class Case:
    """One arm in one mode: how to build its resolver and answer a tick.

    Attributes:
        name: ``arm:mode``.
        robot: The robot.
        frames: Commanded frames (6 entries of the command each).
        make: A fresh resolver's tick: ``solve(q, command, qdot_prev) -> Resolution``.
        aim: ``aim(q) -> command`` added to every command (a collision scene's approach), or
            None.
        length: The case's ticks, in multiples of the recording's.
    """

    name: str
    robot: rrc_pin.Robot
    frames: tuple[str, ...]
    make: Callable[[], Solve]
    aim: Callable[[Array], Array] | None = None
    length: int = 1


def _twist_case(robot: rrc_pin.Robot, mode: str) -> Callable[[], Solve]:
    def make() -> Solve:
        options: dict[str, Any] = {}
        if mode == "tracking":
            options["direction_preserving"] = False
        elif mode == "undamped":
            options["damping"] = None
        elif mode == "limits":
            options["limits"] = JointLimits(margin=0.01, acceleration=40.0)
        resolver = Resolver(robot, DT, qp=UNHURRIED, **options)
        if mode == "limits":
            return lambda q, x, prev: resolver.solve(q, x, qdot_prev=prev)
        return lambda q, x, prev: resolver.solve(q, x)

    return make


def _tasks_case(robot: rrc_pin.Robot, frames: tuple[str, ...], mode: str) -> Callable[[], Solve]:
    rows = "full" if robot.nv >= 6 else "position"

    def make() -> Solve:
        resolver = Resolver(robot, DT, qp=UNHURRIED)
        hands = [FrameTask(f, rows=rows) for f in frames]
        posture = PostureTask(robot.neutral(), gain=1.0, weight=0.01)

        def solve(q: Array, x: Array, prev: Array) -> Any:
            for i, task in enumerate(hands):
                task.set_twist(x[6 * i : 6 * i + 6])
            if mode == "weighted":
                return resolver.solve(q, [*hands, posture])
            if mode == "strict":
                return resolver.solve(q, [hands, [posture]], priority="strict")
            return resolver.solve(q, [*([h] for h in hands), [posture]], priority="strict")

        return solve

    return make


def _table() -> Case:
    panda = rrc_pin.load("panda")
    cm = CollisionModel(panda)
    T = np.eye(4)
    T[:3, 3] = (0.5, 0.0, 0.2)
    cm.add_box(T, (0.6, 0.8, 0.04), name="table")

    def make() -> Solve:
        resolver = Resolver(panda, DT, qp=UNHURRIED,
                            limits=[JointLimits(), CollisionLimit(cm, 0.02, 0.1)],
                            task=FrameTask(panda.tool_frame, rows="position"))  # fmt: skip
        return lambda q, x, prev: resolver.solve(q, x)

    down = np.array([0.0, 0.0, -0.3, 0.0, 0.0, 0.0])
    return Case("panda:table", panda, (panda.tool_frame,), make, lambda q: down, 4)


def _facing() -> Case:
    panda = rrc_pin.load("panda")
    facing = np.eye(4)
    facing[:3, :3] = np.diag([-1.0, -1.0, 1.0])
    facing[0, 3] = 1.0
    robot = rrc_pin.combine({"left": (panda, np.eye(4)), "right": (panda, facing)})
    cm = CollisionModel(robot, "capsules")

    def make() -> Solve:
        resolver = Resolver(robot, DT, qp=UNHURRIED,
                            limits=[JointLimits(), CollisionLimit(cm, 0.02, 0.1)])
        hands = [FrameTask(f, rows="position") for f in robot.tool_frames]

        def solve(q: Array, x: Array, prev: Array) -> Any:
            for i, task in enumerate(hands):
                task.set_twist(x[6 * i : 6 * i + 6])
            return resolver.solve(q, [hands], priority="strict")

        return solve

    def aim(q: Array) -> Array:  # each hand toward the other at 0.3 m/s, and up (sliding)
        hands = [robot.frame_pose(q, f)[:3, 3] for f in robot.tool_frames]
        out = np.zeros(12)
        for me, other in ((0, 1), (1, 0)):
            v = 2.0 * (hands[other] - hands[me])
            v *= min(1.0, 0.3 / max(float(np.linalg.norm(v)), 1e-12))
            out[6 * me : 6 * me + 3] = v + np.array([0.0, 0.0, 0.05])
        return out

    return Case("facing_pandas:facing", robot, robot.tool_frames, make, aim, 4)


def cases() -> list[Case]:
    """Every catalogue arm in each of its modes, then the collision scenes (module docstring)."""
    out = []
    for name in rrc_pin.arms():
        robot = rrc_pin.load(name)
        if robot.tool_frame is not None:
            frames = (robot.tool_frame,)
            for mode in ("twist", "tracking", "limits", "undamped"):
                out.append(Case(f"{name}:{mode}", robot, frames, _twist_case(robot, mode)))
            for mode in ("weighted", "strict"):
                out.append(Case(f"{name}:{mode}", robot, frames, _tasks_case(robot, frames, mode)))
        else:
            frames = robot.tool_frames
            for mode in ("weighted", "strict", "levels"):
                out.append(Case(f"{name}:{mode}", robot, frames, _tasks_case(robot, frames, mode)))
    return [*out, _table(), _facing()]


def _command(rng: np.random.Generator, kind: str, frames: int) -> Array:
    if kind == "too_fast":
        parts = []
        for _ in range(frames):
            v, w = rng.normal(size=3), rng.normal(size=3)
            parts.append(np.concatenate([1.5 * v / np.linalg.norm(v), 3.0 * w / np.linalg.norm(w)]))
        return np.concatenate(parts)
    scale = (0.1, 0.15) if kind == "smooth" else (0.23, 0.35)
    return np.concatenate([np.concatenate([rng.normal(size=3) * scale[0],
                                           rng.normal(size=3) * scale[1]])
                           for _ in range(frames)])  # fmt: skip


def _segment_start(
    rng: np.random.Generator, robot: rrc_pin.Robot, q: Array, kind: str, scene: bool
) -> Array:
    lower, upper = robot.lower, robot.upper
    draw = rng.random()
    if draw < 0.15:  # a collision scene restarts from its ready pose: no start in a body
        q = robot.ready() if scene else robot.random_q(rng)
    elif draw < 0.25 and not scene:
        q = np.clip(robot.neutral(), lower, upper)
    q = q.copy()
    finite = np.flatnonzero(np.isfinite(lower) & np.isfinite(upper))
    if kind == "near_limit" and finite.size and not scene:
        for i in rng.choice(finite, size=min(3, finite.size), replace=False):
            inside = rng.uniform(0.0, 0.02)
            q[i] = upper[i] - inside if rng.random() < 0.5 else lower[i] + inside
    if rng.random() < 0.05 and finite.size and not scene:  # outside a joint's range
        i = int(rng.choice(finite))
        q[i] = upper[i] + 1e-3 if rng.random() < 0.5 else lower[i] - 1e-3
    return q


def record_case(case: Case, ticks: int, rng: np.random.Generator) -> dict[str, Any]:
    """Inputs and answers of ``ticks`` ticks of ``case`` along its own answers."""
    robot = case.robot
    solve = case.make()
    frames = len(case.frames)
    Q, X, P = (
        np.empty((ticks, robot.nq)),
        np.empty((ticks, 6 * frames)),
        np.zeros((ticks, robot.nv)),
    )
    answers: list[Any] = []
    q, prev = robot.ready(), np.zeros(robot.nv)
    kind, start, end, size = "smooth", np.zeros(6 * frames), np.zeros(6 * frames), 1.0
    for k in range(ticks):
        j = k % SEGMENT
        if j == 0:
            kind = str(rng.choice(("smooth", "too_fast", "near_limit")))
            size = float(rng.choice(SIZES))
            q = _segment_start(rng, robot, q, kind, case.aim is not None)
            start, end = _command(rng, kind, frames), _command(rng, kind, frames)
            if kind != "smooth":
                end = start
        x = size * (start + (end - start) * (j / (SEGMENT - 1)))
        if case.aim is not None:
            x = 0.1 * x + case.aim(q)
        Q[k], X[k], P[k] = q, x, prev
        r = solve(q, x, prev)
        answers.append(r)
        prev = np.array(r.qdot)
        q = np.clip(q + prev * DT, np.minimum(robot.lower, q), np.maximum(robot.upper, q))
    return {"q": Q, "command": X, "prev": P, **_answers(answers)}


def _answers(resolutions: list[Any]) -> dict[str, Any]:
    return {
        "qdot": np.array([r.qdot for r in resolutions]),
        "status": np.array([r.status for r in resolutions]),
        "method": np.array([r.method for r in resolutions]),
        "levels": np.array([",".join(r.levels) for r in resolutions]),
        "backend": np.array([r.backend for r in resolutions]),
        "scale": np.array([r.scale for r in resolutions]),
        "veer": np.array([r.veer for r in resolutions]),
        "lambda_sq": np.array([r.lambda_sq for r in resolutions]),
        "clip": np.array([r.clip for r in resolutions]),
    }


def record(path: Path, ticks: int, seed: int) -> None:
    """Record every case's ticks into ``path`` (module docstring)."""
    arrays: dict[str, Any] = {}
    names = []
    statuses: Counter[str] = Counter()
    for index, case in enumerate(cases()):
        rng = np.random.default_rng([seed, index])
        start = time.perf_counter()
        data = record_case(case, ticks * case.length, rng)
        names.append(case.name)
        statuses.update(data["status"].tolist())
        for key, value in data.items():
            arrays[f"{case.name}/{key}"] = value
        print(f"{case.name:32s} {time.perf_counter() - start:6.2f} s", flush=True)
    arrays["cases"] = np.array(names)
    np.savez_compressed(path, **arrays)
    print(f"{len(names)} cases, {sum(statuses.values())} ticks: {dict(statuses)}")


def shortfall(r: Any, recorded: Array) -> float:
    r"""How far the answer ``r`` serves its levels worse than the ``recorded`` rates (n,):
    level by level in priority order, the first whose task error :math:`\|A\dot q - b\|`
    differs by more than :data:`LEVEL_TOL` relative decides; its relative excess where r's is
    the larger, else 0 (the same or better).
    """
    for level in r.problem.levels:
        mine, theirs = (math.sqrt(sum(float(np.sum((t.A @ x - t.b) ** 2)) for t in level))
                        for x in (r.qdot, recorded))  # fmt: skip
        if abs(mine - theirs) > LEVEL_TOL * max(1.0, theirs):
            return max(0.0, (mine - theirs) / max(1.0, theirs))
    return 0.0


def replay(data: Any, case: Case, first: int | None = None) -> dict[str, Any]:
    """The answers of the code imported now to the recorded ticks of ``case`` (the first ones),
    and their :func:`shortfall` against the recorded ones (``"short"``).
    """
    solve = case.make()
    Q, X, P, old = (data[f"{case.name}/{key}"] for key in ("q", "command", "prev", "qdot"))
    k = len(Q) if first is None else min(first, len(Q))
    answers = [solve(Q[i], X[i], P[i]) for i in range(k)]
    short = [shortfall(r, old[i]) for i, r in enumerate(answers)]
    return {**_answers(answers), "short": np.array(short)}


def differences(data: Any, name: str, now: dict[str, Any]) -> dict[str, Any]:
    """The largest differences between the recorded answers of case ``name`` and ``now``."""
    k = len(now["qdot"])
    old = {key: data[f"{name}/{key}"][:k] for key in now if f"{name}/{key}" in data}
    scale = np.maximum(1.0, np.abs(old["qdot"]).max(axis=1))
    rates = np.abs(now["qdot"] - old["qdot"]).max(axis=1) / scale
    same = {key: old[key] == now[key] for key in ("status", "method", "levels")}
    kernels = old["backend"] == "" if "backend" in old else np.ones(k, dtype=bool)
    moving = np.maximum(old["scale"], now["scale"]) > STILL
    # the angle of rates standing still along the command is the rounding of a zero's
    return {
        "ticks": k,
        "rates": float(rates.max(initial=0.0)),
        "worst": int(rates.argmax()) if k else -1,
        "scale": float(np.abs(now["scale"] - old["scale"]).max(initial=0.0)),
        "veer": float(np.abs(now["veer"] - old["veer"])[moving].max(initial=0.0)),
        "differ": {key: np.flatnonzero(~s).tolist() for key, s in same.items() if not s.all()},
        "status": old["status"],
        "per_tick": rates,
        "kernels": kernels,
        "short": now["short"],
    }


def compare(path: Path, first: int | None, tolerance: float) -> int:
    """Replay ``path`` and print per case the largest differences; 1 where any exceeds."""
    data = np.load(path)
    known = {case.name: case for case in cases()}
    failures, worst, total, changed, shorter = 0, 0.0, 0, 0, [0, 0.0]
    by_source = {"kernels": [0, 0.0], "backend": [0, 0.0]}  # ticks, largest difference
    by_status: dict[str, float] = {}
    for name in data["cases"].tolist():
        found = differences(data, name, replay(data, known[name], first))
        total += found["ticks"]
        worst = max(worst, found["rates"])
        beyond = found["per_tick"] > tolerance
        changed += int(beyond.sum())
        short = found["short"][beyond]
        shorter = [shorter[0] + int((short > 0.0).sum()), max(shorter[1], short.max(initial=0.0))]
        for source, mask in (("kernels", found["kernels"]), ("backend", ~found["kernels"])):
            by_source[source][0] += int(mask.sum())
            by_source[source][1] = max(by_source[source][1],
                                       float(found["per_tick"][mask].max(initial=0.0)))  # fmt: skip
        for status, d in zip(found["status"].tolist(), found["per_tick"].tolist(), strict=True):
            by_status[status] = max(by_status.get(status, 0.0), d)
        bad = found["rates"] > tolerance or found["differ"]
        failures += bool(bad)
        if bad or found["rates"] > 1e-15:
            print(
                f"{name:32s} rates {found['rates']:.3g} (tick {found['worst']}) scale "
                f"{found['scale']:.3g} veer {found['veer']:.3g} short "
                f"{found['short'].max(initial=0.0):.3g} {found['differ'] or ''}"
            )
    print(
        f"{total} ticks, largest relative rate difference {worst:.3g}; per status "
        + ", ".join(f"{k} {v:.3g}" for k, v in sorted(by_status.items()))
    )
    print("the old tick's answers from " + ", ".join(
        f"its {k}: {n} ticks, largest {d:.3g}" for k, (n, d) in by_source.items()))
    print(f"{changed} ticks beyond {tolerance:g}: {shorter[0]} serve a level worse than the "
          f"recording (beyond {LEVEL_TOL:g} relative), by at most {shorter[1]:.3g}")
    print(f"{failures} cases beyond {tolerance:g} or with another status, method or levels")
    return 1 if failures else 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("action", choices=("record", "compare"))
    parser.add_argument("path", type=Path)
    parser.add_argument("--ticks", type=int, default=100, help="ticks per case (record)")
    parser.add_argument("--seed", type=int, default=SEED)
    parser.add_argument("--first", type=int, default=None, help="replay only the first ticks")
    parser.add_argument("--tolerance", type=float, default=1e-12)
    args = parser.parse_args(argv)
    if args.action == "record":
        record(args.path, args.ticks, args.seed)
        return 0
    return compare(args.path, args.first, args.tolerance)


if __name__ == "__main__":
    sys.exit(main())
