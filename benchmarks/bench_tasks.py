"""Two frames and a posture on baxter: rrc-pin against PlaCo, pink, mink and Drake in one process.

Run from a checkout, in the peers' environment (docs/benchmarks.md): ``python
benchmarks/bench_tasks.py --out DIR`` (``--record`` writes ``benchmarks/results/``,
``--quick`` a short smoke run that runs without the peers that do not import, ``--steps N``
the trajectory length, ``--seed S`` a given seed). ``rrc-pin bench`` runs it. Issue 27's
comparison.

The robot: ``rrc_pin.load("baxter")``, 15 joints (head pan and both 7-joint arms). Each
gripper (``left_gripper``, ``right_gripper``) follows its own command (:mod:`workloads`:
smooth, too-fast and near-limit segments, a fresh seed), a posture task pulls toward the
neutral configuration with gain k = 1/s. Limits: velocity, and position over one step. A
trajectory is recorded by rrc-pin weighted; every contender then answers the same commands
at every recorded configuration, the whole call timed.

Weighted (one least squares of the tasks' costs): frame tasks weight 1 (position and
orientation), posture 0.01 (pink's costs 1 and 0.1 squared: pink and mink square their costs):

- rrc-pin: ``solve(q, [hand_l, hand_r, posture])``, its two FrameTasks kept and their twists
  set in the call (``FrameTask.set_twist``), as every peer keeps its tasks and sets their
  targets in the call;
- PlaCo: two soft frame tasks and a soft joints task (targets ``q + k dt (q_ref - q)``),
  PlaCo's regularisation 1e-8 on top: the same problem;
- pink and mink (quadprog): FrameTasks with the targets moved by ``twist * dt`` and a
  PostureTask (gain ``k dt``); their frame error is ``log6`` of the pose difference, the same
  problem to first order in dt.

Strict (the hands first, the posture in what they leave free):

- rrc-pin: ``solve(q, [[both FrameTasks], posture], priority="strict")``: the hands with one
  common direction-preserving scale, the posture least squares in their null space;
- PlaCo: the frame tasks ``hard`` (equality constraints: when the limits cannot meet them
  exactly, PlaCo's QP fails and it raises: a failure, rates taken as zero), the joints task
  soft;
- Drake: ``DoDifferentialInverseKinematics`` on both frames' Jacobians stacked, the posture
  as its joint centering (the null-space objective): direction-preserving, one scale;
- pink and mink have no strict priority (weighted only).

Modes, rounds and ratios: :mod:`comparison` (each contender against the PlaCo row of its own
mode of priority). Answers (:mod:`quality`): weighted, the distance of the rates from the exact
optimum of the stated costs in the box (scipy's BVLS); both, the hands' 12 rows judged as one
command: the veer where the LP maximum scale along it is 1, the direction error on the
too-fast segments.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from collections import Counter  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import peers  # noqa: E402
import quality  # noqa: E402
import workloads  # noqa: E402
from bench_resolver import VERSIONS, rrc_statistics  # noqa: E402
from comparison import (  # noqa: E402
    excess_table,
    peers_lines,
    quality_table,
    time_workload,
    timing_table,
)
from comparison import plot as comparison_plot  # noqa: E402
from machine import load_average, machine_info, source_state  # noqa: E402
from script import make_parser, write  # noqa: E402
from stage_profile import profile_steps, profile_table  # noqa: E402
from timing import MODE_TITLES, MODES, REPEATS, Contender, progress, run_mode, us  # noqa: E402

import rrc_pin  # noqa: E402
from rrc_pin import FrameTask, PostureTask  # noqa: E402

ROBOT = "baxter"
DT = 0.01
STEPS, QUICK_STEPS = 6000, 100
FRAME_WEIGHT = 1.0
"""rrc-pin's and PlaCo's weight of each frame task (pink's and mink's cost: its root)."""
POSTURE_WEIGHT = 0.01
"""rrc-pin's and PlaCo's posture weight (pink's and mink's cost: 0.1)."""
POSTURE_GAIN = 1.0
"""k [1/s]: the posture asks for k (q_ref - q)."""
WEIGHTED, STRICT = "rrc-pin weighted", "rrc-pin strict"
PLACO_W, PLACO_S = "PlaCo weighted", "PlaCo strict"
PINK = f"pink weighted ({peers.QP_SOLVER})"
MINK = f"mink weighted ({peers.QP_SOLVER})"
DRAKE = "Drake DiffIK strict"
ORDER = [WEIGHTED, PLACO_W, PINK, MINK, STRICT, PLACO_S, DRAKE]
PLACO_OF = {WEIGHTED: PLACO_W, PLACO_W: PLACO_W, PINK: PLACO_W, MINK: PLACO_W,
            STRICT: PLACO_S, PLACO_S: PLACO_S, DRAKE: PLACO_S}  # fmt: skip
"""Each contender's PlaCo row (the same priority)."""

Array = np.ndarray


def _posture(robot: Any) -> PostureTask:
    return PostureTask(robot.neutral(), gain=POSTURE_GAIN, weight=POSTURE_WEIGHT)


def rrc_call(robot: Any, strict: bool) -> tuple[Any, Any]:
    """rrc-pin's step (weighted or strict), its FrameTasks' twists set in the call; and its
    Resolver."""
    hands = [FrameTask(frame, weight=FRAME_WEIGHT) for frame in robot.tool_frames]
    left, right = hands
    posture = _posture(robot)
    resolver = rrc_pin.Resolver(robot, dt=DT)

    def weighted(q: Array, x: Array) -> Any:
        left.set_twist(x[:6])
        right.set_twist(x[6:])
        return resolver.solve(q, [left, right, posture])

    def levels(q: Array, x: Array) -> Any:
        left.set_twist(x[:6])
        right.set_twist(x[6:])
        return resolver.solve(q, [hands, posture], priority="strict")

    return (levels if strict else weighted), resolver


def contenders(robot: Any, models: peers.Models, status: dict[str, str]) -> list[Contender]:
    """Fresh contenders: rrc-pin weighted and strict and every peer that imports."""
    out = [
        Contender(WEIGHTED, rrc_call(robot, False)[0], rates=lambda r: r.qdot, keep=True),
        Contender(STRICT, rrc_call(robot, True)[0], rates=lambda r: r.qdot, keep=True),
    ]
    posture = (np.sqrt(POSTURE_WEIGHT), POSTURE_GAIN, robot.neutral())
    if status["PlaCo"] == "ran":
        from placo_peer import PlacoPeer

        for label, strict in ((PLACO_W, False), (PLACO_S, True)):
            peer = PlacoPeer(
                str(models.placo_urdf()), list(robot.joint_names), list(robot.tool_frames), DT,
                FRAME_WEIGHT, POSTURE_WEIGHT, POSTURE_GAIN, robot.neutral(), strict,
            )  # fmt: skip
            out.append(Contender(label, peer.step))
    if status["pink"] == "ran":
        out.append(Contender(PINK, peers.pink_step(robot, DT, np.sqrt(FRAME_WEIGHT), posture)))
    if status["mink"] == "ran":
        import mink_peer

        step = mink_peer.mink_step(robot, DT, peers.QP_SOLVER, np.sqrt(FRAME_WEIGHT), posture)
        out.append(Contender(MINK, step))
    if status["Drake"] == "ran":
        import drake_peer

        step = drake_peer.two_frames(robot, models.drake(), DT, POSTURE_GAIN, robot.neutral())
        out.append(Contender(DRAKE, step))
    return out


def weighted_optima(robot: Any, Q: Array, X: Array, J: Array, ref: dict[str, Array]) -> Array:
    """The exact optimum of rrc-pin weighted's costs in the step's box, per step (BVLS)."""
    n = robot.nq
    weights = np.concatenate([np.full(12, FRAME_WEIGHT), np.full(n, POSTURE_WEIGHT)])
    target = robot.neutral()
    out = np.empty_like(Q)
    for k, (q, x) in enumerate(zip(Q, X, strict=True)):
        A = np.vstack([J[k], np.eye(n)])
        b = np.concatenate([x, POSTURE_GAIN * (target - q)])
        out[k] = quality.weighted_optimum(A, b, weights, ref["lb"][k], ref["ub"][k])
    return out


def profile(robot: Any, strict: bool, Q: Array, X: Array) -> dict[str, Any]:
    """Stage profile of rrc-pin weighted or strict (:mod:`stage_profile`), with its plain
    tight-loop median on the same trajectory and the instrumentation's overhead [us]."""
    call, _ = rrc_call(robot, strict)
    rates = np.array([call(q, x).qdot for q, x in zip(Q, X, strict=True)])
    plain, _ = rrc_call(robot, strict)
    run = run_mode("tight", [Contender("plain", plain, lambda r: r.qdot)], Q, X)["plain"]
    call, resolver = rrc_call(robot, strict)
    out = profile_steps(call, resolver, Q, X, rates, tasks=True)
    out["plain_median_us"] = float(np.median(run.seconds[run.counted]) * 1e6)
    out["overhead_us"] = out["stages"]["all"]["total"]["median_us"] - out["plain_median_us"]
    return out


def bench(steps: int, rounds: int, seed: int, status: dict[str, str]) -> dict[str, Any]:
    """Every contender in every mode along one baxter trajectory, the answers' quality."""
    robot = rrc_pin.load(ROBOT)
    progress(f"{ROBOT}: recording {steps} steps (seed {seed})")
    recorder, _ = rrc_call(robot, False)
    Q, X, kinds = workloads.record(robot, 2, steps, np.random.default_rng(seed), DT,
                                   lambda q, x: recorder(q, x).qdot)  # fmt: skip
    models = peers.Models(robot)
    try:
        gaps = peers.gaps(robot, models, status)
        modes, first = time_workload(
            ROBOT, lambda: contenders(robot, models, status), Q, X,
            (robot.lower, robot.upper, robot.velocity_limit), DT, rounds, PLACO_OF, WEIGHTED,
        )  # fmt: skip
    finally:
        models.close()
    progress(f"{ROBOT}: the answers' quality (LP and BVLS per step)")
    frames = list(robot.tool_frames)
    J = quality.jacobians(robot, Q, frames)
    ref = quality.reference(robot, Q, X, J, DT)
    unit = quality.units(robot, frames)
    optima = weighted_optima(robot, Q, X, J, ref)
    judged = {}
    for label, run in first.items():
        judged[label] = quality.direction(J, X, run.rates, unit, ref, kinds, run.failed)
        judged[label].update(quality.distance(run.rates, optima, run.failed))
    progress(f"{ROBOT}: profiles of rrc-pin weighted and strict")
    return {
        "robot": ROBOT,
        "nq": robot.nq,
        "frames": frames,
        "seed": seed,
        "trajectory": {
            "steps": steps,
            "recorded_by": "rrc-pin weighted",
            "segments": dict(Counter(kinds[:: workloads.SEGMENT]).most_common()),
            "lp_scale_below_1": int((ref["lp_scale"] < 1.0 - quality.REACHABLE_TOL).sum()),
        },
        "kinematics_gaps": gaps,
        "modes": modes,
        "quality": judged,
        "rrc_pin": {label: rrc_statistics(first[label].kept) for label in (WEIGHTED, STRICT)},
        "profiles": {WEIGHTED: profile(robot, False, Q, X), STRICT: profile(robot, True, Q, X)},
    }


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write JSON and PNG to --out or (--record) benchmarks/results."""
    parser = make_parser(__doc__, "tasks", f"{QUICK_STEPS} steps, peers optional")
    parser.add_argument("--steps", type=int, default=None, help=f"trajectory length ({STEPS})")
    parser.add_argument("--seed", type=int, default=None, help="seed (default: a fresh one)")
    # rrc-pin bench passes --placo-python (PlaCo's interpreter, when it ran in a worker); PlaCo
    # now runs in this process: accepted and ignored.
    parser.add_argument("--placo-python", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    steps = args.steps or (QUICK_STEPS if args.quick else STEPS)
    if steps < 2:
        parser.error("--steps: at least 2")
    if args.record and (args.quick or steps != STEPS):
        parser.error(f"--record keeps full runs only ({STEPS} steps)")
    warnings.simplefilter("ignore")
    status = peers.availability()
    peers.check(status, args.quick)
    seed = workloads.fresh_seed() if args.seed is None else args.seed
    progress(f"seed {seed} (rerun with --seed {seed})")
    rounds = 1 if args.quick else REPEATS
    start = load_average()
    results: dict[str, Any] = {
        "benchmark": "tasks",
        "schema": 3,
        "machine": machine_info(*VERSIONS),
        "source": source_state(),
        "quick": bool(args.quick),
        "settings": {
            "dt": DT,
            "steps": steps,
            "segment": workloads.SEGMENT,
            "seed": seed,
            "rounds": rounds,
            "frame_weight": FRAME_WEIGHT,
            "posture_weight": POSTURE_WEIGHT,
            "posture_gain": POSTURE_GAIN,
            "qp_solver_of_pink_and_mink": peers.QP_SOLVER,
        },
        "peers": status,
        **bench(steps, rounds, seed, status),
    }
    results["load_average"] = {"start": start, "end": load_average()}
    write(args, "tasks", results, lambda path: plot(results, path))
    print(readme_table(results))
    return 0


# ---- rendering (update_readme.py) -------------------------------------------------------------


def readme_table(results: dict[str, Any]) -> str:
    """The README's table: per contender, median / p99 in each mode and the ratio to PlaCo of
    the same priority; the setup and the answers in a few lines."""
    modes = results["modes"]
    head = "| contender |" + "".join(
        f" {MODE_TITLES[m]}: median / p99 [us] | vs PlaCo |" for m in MODES
    )
    lines = [head, "| --- |" + " ---: | ---: |" * len(MODES)]
    for label in ORDER:
        if label not in modes["tight"]["contenders"]:
            continue
        cells = f"| {label} |"
        for mode in MODES:
            r = modes[mode]["contenders"][label]
            ratio = (
                f"{r['vs_placo_median']:.2f}x / {r['vs_placo_p99']:.2f}x"
                if "vs_placo_median" in r
                else "-"
            )
            cells += f" {us(r['median_us'])} / {us(r['p99_us'])} | {ratio} |"
        lines.append(cells)
    answered = _answered_line(results)
    lines += ["", _setup_line(results), *(["", answered] if answered else []), "",
              _answers_line(results)]  # fmt: skip
    return "\n".join(lines)


def _answered_line(results: dict[str, Any]) -> str:
    """The strict rows on the steps PlaCo strict answered (it raises on the others); "" where
    it did not run or answered every step."""
    tight = results["modes"]["tight"]["contenders"]
    placo = tight.get(PLACO_S)
    if placo is None or "answered_steps" not in placo:
        return ""
    shown = [label for label in (STRICT, PLACO_S, DRAKE)
             if "answered_median_us" in tight.get(label, {})]  # fmt: skip
    parts = [f"{label} {tight[label]['answered_median_us']:.0f} us "
             f"({tight[label]['vs_placo_answered_median']:.2f}x)" for label in shown]  # fmt: skip
    return (
        f"PlaCo strict raised at {placo['failures']} of {results['settings']['steps']} steps "
        f"(its hard tasks not met within the limits); on the {placo['answered_steps']} steps "
        "it answered, tight-loop medians and PlaCo's over them: " + ", ".join(parts) + "."
    )


def _setup_line(results: dict[str, Any]) -> str:
    s, m = results["settings"], results["machine"]
    load = results.get("load_average", {})
    missing = [p for p, why in results["peers"].items() if why != "ran"]
    text = (
        f"baxter ({results['nq']} joints), both grippers commanded (smooth, too-fast and "
        f"near-limit segments, seed {results['seed']}) and a posture task, {s['steps']} steps, "
        f"dt = {1000 * s['dt']:g} ms, every contender in one process. Weighted: frame tasks "
        f"{s['frame_weight']:g}, posture {s['posture_weight']:g} (pink's and mink's costs their "
        "roots); strict: the hands first (PlaCo: hard tasks; Drake: its direction-preserving "
        "QP, the posture as its null-space objective; pink and mink have no strict mode). vs "
        "PlaCo: PlaCo's time (same priority) over the contender's, median / p99 (above 1: "
        f"faster than PlaCo); median of {s['rounds']} rounds. Measured on {m['cpu']} "
        f"({m['cores']} cores, shared), Pinocchio {m['pinocchio']}, placo {m.get('placo')}"
    )
    if load:
        text += (
            f", load average {load['start'][0]:.2f} at the start, {load['end'][0]:.2f} at the end"
        )
    if missing:
        text += f"; not in this environment: {', '.join(missing)}"
    return text + "."


def _answers_line(results: dict[str, Any]) -> str:
    parts = []
    for label in ORDER:
        q = results["quality"].get(label)
        if q is None:
            continue
        text = f"{label} {q['veer_steps']} of {q['reachable_steps']}"
        if label in (WEIGHTED, PLACO_W):
            text += f" (from the weighted optimum: at most {q['optimum_max']:.1g} rad/s)"
        parts.append(text)
    return (
        "Answers, steps that veer where the hands' LP maximum scale is 1: " + "; ".join(parts)
        + " (docs/benchmarks.md)."
    )


def docs_section(results: dict[str, Any]) -> str:
    """Every table of the benchmark, for docs/benchmarks.md."""
    s, t = results["settings"], results["trajectory"]
    segments = ", ".join(f"{v} {k}" for k, v in t["segments"].items())
    gaps = "; ".join(
        f"{peer} {max(g.values()):.1g}" for peer, g in results.get("kinematics_gaps", {}).items()
    )
    lines = [
        f"Trajectory: {s['steps']} steps, dt = {1000 * s['dt']:g} ms, seed {results['seed']}; "
        f"segments: {segments}; the hands' LP maximum scale is below 1 at "
        f"{t['lp_scale_below_1']} steps. {s['rounds']} rounds of each mode from fresh "
        "contenders, every time the median of the rounds' (the median's range beside it). vs "
        "PlaCo: PlaCo's (same priority) median over the contender's / the same for p99, within "
        "each round (above 1: faster than PlaCo). Peers' kinematics against Pinocchio's "
        f"(largest difference of poses and Jacobians): {gaps or '-'}.",
        "",
        *peers_lines(results["peers"]),
        "",
        *timing_table(results["modes"], ORDER),
        "",
        "Answers (first round, tight loop): the hands' 12 rows judged as one command (veer "
        "where its LP maximum scale is 1; direction error and speed on the too-fast segments), "
        "and the distance from the exact optimum of the weighted costs in the box (BVLS; "
        "the weighted contenders' problem: pink and mink solve it to first order in dt, the "
        "strict ones another problem).",
        "",
        *quality_table(results["quality"], ORDER),
        "",
        "| contender | from the weighted optimum: median [rad/s] | largest |",
        "| --- | ---: | ---: |",
    ]
    for label in ORDER:
        q = results["quality"].get(label)
        if q is not None:
            lines.append(f"| {label} | {q['optimum_median']:.2g} | {q['optimum_max']:.2g} |")
    lines += ["", "Limit excess and failures (tight loop, first round):", ""]
    lines += excess_table(results["modes"], ORDER)
    lines.append("")
    for label, prof in results["profiles"].items():
        lines += profile_table(prof, label)
    return "\n".join(lines)


def plot(results: dict[str, Any], path: Path) -> bool:
    """Median step time per contender and mode (bars), p99 as a tick."""
    return comparison_plot(
        [(results["modes"], "baxter: two frames and a posture")], path, results
    )


if __name__ == "__main__":
    sys.exit(main())
