"""One frame in the limits: rrc-pin, PlaCo, pink, mink and Drake side by side in one process.

Run from a checkout, in the peers' environment (docs/benchmarks.md): ``python
benchmarks/bench_resolver.py --out DIR`` (``--record`` writes ``benchmarks/results/``,
``--quick`` a short smoke run that runs without the peers that do not import, ``--steps N``
the trajectory length, ``--seed S`` a given seed instead of a fresh one). ``rrc-pin bench``
runs it. Issue 27's comparison.

Workloads: panda and rrc_k1607, the tool frame's full twist, the joint limits (velocity, and
position over one step). A trajectory per arm (:mod:`workloads`: smooth, too-fast and
near-limit segments, from a fresh seed, printed and recorded) is recorded by rrc-pin's
default; then every contender answers the same command at every recorded configuration, the
whole call timed, as its users call it:

- rrc-pin: ``Resolver(arm, dt).solve(q, twist)``, the default (DAQP, direction-preserving),
  returning its :class:`~rrc_pin.Resolution` (status, method, scale and veer decided in the
  call);
- PlaCo (:mod:`placo_peer`): a soft frame task (weight 1) with the target moved by
  ``twist * dt``, joint and velocity limits, ``solve``; a weighted least squares of the pose
  error in the limits (it trades speed and direction when the command cannot be met);
- pink and mink (quadprog): ``solve_ik`` with a FrameTask whose target is the pose moved by
  ``twist * dt``, ``ConfigurationLimit`` and ``VelocityLimit``: least squares too;
- Drake (:mod:`drake_peer`): ``DoDifferentialInverseKinematics`` with the twist as the frame's
  spatial velocity, position and velocity limits: direction-preserving, as rrc-pin's default.

Each peer's kinematics is checked against Pinocchio's first (poses and Jacobians within
1e-9). Modes (:mod:`timing`): tight, interleaved, 1 ms of other work between calls; rounds
and ratios (PlaCo's time over the contender's): :mod:`comparison`. The answers' quality
(:mod:`quality`), on the first round's tight-loop answers: the veer where the LP maximum scale
along the command is 1, the direction error and speed on the too-fast segments, the limit
excess. Then where rrc-pin's step time goes (:mod:`stage_profile`).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import sys  # noqa: E402
import warnings  # noqa: E402
from collections import Counter  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import peers  # noqa: E402
import quality  # noqa: E402
import workloads  # noqa: E402
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
from timing import (  # noqa: E402
    MODE_TITLES,
    MODES,
    REPEATS,
    Contender,
    progress,
    run_mode,
    statistics,
    us,
)

import rrc_pin  # noqa: E402

ARMS = ("panda", "rrc_k1607")
DT = 0.01
STEPS, QUICK_STEPS = 6000, 100
RRC = "rrc-pin"
PLACO = "PlaCo"
PINK = f"pink ({peers.QP_SOLVER})"
MINK = f"mink ({peers.QP_SOLVER})"
DRAKE = "Drake DiffIK"
ORDER = [RRC, PLACO, DRAKE, PINK, MINK]
"""The contenders, in the tables' order."""
OF_PEER = {PLACO: "PlaCo", PINK: "pink", MINK: "mink", DRAKE: "Drake"}
VERSIONS = ("placo", "pink", "mink", "mujoco", "pydrake", "qpsolvers", "quadprog", "daqp",
            "numba", "scipy")  # fmt: skip
"""Modules whose versions are recorded."""

Array = np.ndarray


def contenders(arm: Any, models: peers.Models, status: dict[str, str]) -> list[Contender]:
    """Fresh contenders: rrc-pin's default and every peer that imports."""
    resolver = rrc_pin.Resolver(arm, dt=DT)
    out = [Contender(RRC, resolver.solve, rates=lambda r: r.qdot, keep=True)]
    if status["PlaCo"] == "ran":
        from placo_peer import PlacoPeer

        placo = PlacoPeer(str(models.placo_urdf()), list(arm.joint_names), [arm.tool_frame], DT)
        out.append(Contender(PLACO, placo.step))
    if status["Drake"] == "ran":
        import drake_peer

        out.append(Contender(DRAKE, drake_peer.one_frame(arm, models.drake(), DT)))
    if status["pink"] == "ran":
        out.append(Contender(PINK, peers.pink_step(arm, DT)))
    if status["mink"] == "ran":
        import mink_peer

        out.append(Contender(MINK, mink_peer.mink_step(arm, DT, peers.QP_SOLVER)))
    return out


def rrc_statistics(resolutions: list[Any]) -> dict[str, Any]:
    """How rrc-pin's steps were answered: status and method counts, the backend's share, the
    steps with a failed attempt, the largest clip [rad/s]."""
    n = len(resolutions)
    return {
        "steps": n,
        "status": dict(Counter(r.status for r in resolutions).most_common()),
        "method": dict(Counter(r.method for r in resolutions).most_common()),
        "backend_share": sum(bool(r.backend) for r in resolutions) / n if n else 0.0,
        "with_attempts": sum(bool(r.attempts) for r in resolutions),
        "max_clip": float(max((r.clip for r in resolutions), default=0.0)),
    }


def bench_arm(
    name: str, steps: int, rounds: int, seed: int, status: dict[str, str]
) -> dict[str, Any]:
    """Every contender in every mode along one trajectory of arm ``name``, the answers'
    quality, rrc-pin's profile."""
    arm = rrc_pin.load(name)
    progress(f"{name}: recording {steps} steps (seed {seed})")
    recorder = rrc_pin.Resolver(arm, dt=DT)
    Q, X, kinds = workloads.record(arm, 1, steps, np.random.default_rng(seed), DT,
                                   lambda q, x: recorder.solve(q, x).qdot)  # fmt: skip
    models = peers.Models(arm)
    try:
        gaps = peers.gaps(arm, models, status)
        placo_of = {label: PLACO for label in ORDER}
        modes, first = time_workload(
            name, lambda: contenders(arm, models, status), Q, X,
            (arm.lower, arm.upper, arm.velocity_limit), DT, rounds, placo_of, RRC,
        )  # fmt: skip
    finally:
        models.close()
    progress(f"{name}: the answers' quality (LP per step)")
    J = quality.jacobians(arm, Q, [arm.tool_frame])
    ref = quality.reference(arm, Q, X, J, DT)
    unit = quality.units(arm, [arm.tool_frame])
    judged = {
        label: quality.direction(J, X, run.rates, unit, ref, kinds, run.failed)
        for label, run in first.items()
    }
    progress(f"{name}: profile of rrc-pin")
    return {
        "arm": name,
        "nq": arm.nq,
        "tool_frame": arm.tool_frame,
        "seed": seed,
        "trajectory": {
            "steps": steps,
            "recorded_by": "rrc_pin.Resolver(arm, dt) (the default)",
            "segments": dict(Counter(kinds[:: workloads.SEGMENT]).most_common()),
            "lp_scale_below_1": int((ref["lp_scale"] < 1.0 - quality.REACHABLE_TOL).sum()),
        },
        "kinematics_gaps": gaps,
        "modes": modes,
        "quality": judged,
        "damped": damped_ticks(first),
        "rrc_pin": rrc_statistics(first[RRC].kept),
        "profile": profile_default(arm, Q, X),
    }


def damped_ticks(first: dict[str, Any]) -> dict[str, Any]:
    """The steps rrc-pin answered ``damped`` (near a singularity, its costliest ticks) alone,
    from the first tight round: per contender the median and the CPU time's p99 [us] there,
    and the ratios to PlaCo's on the same steps."""
    mask = np.array([r.status == "damped" for r in first[RRC].kept])
    out: dict[str, Any] = {"steps": int(mask.sum()), "contenders": {}}
    if not mask.any():
        return out
    for label, run in first.items():
        answered = mask & ~run.failed & run.counted
        if answered.any():
            out["contenders"][label] = statistics(run.seconds[answered], run.cpu[answered])
    placo = out["contenders"].get(PLACO)
    for row in out["contenders"].values():
        if placo is not None:
            row["vs_placo_median"] = placo["median_us"] / row["median_us"]
            row["vs_placo_cpu_p99"] = placo["cpu_p99_us"] / row["cpu_p99_us"]
    return out


def profile_default(arm: Any, Q: Array, X: Array) -> dict[str, Any]:
    """rrc-pin's stage profile (:mod:`stage_profile`), with the plain tight-loop median of the
    same trajectory and the instrumentation's overhead [us]."""
    reference = rrc_pin.Resolver(arm, dt=DT)
    rates = np.array([reference.solve(q, x).qdot for q, x in zip(Q, X, strict=True)])
    plain = rrc_pin.Resolver(arm, dt=DT)
    run = run_mode("tight", [Contender(RRC, plain.solve, lambda r: r.qdot)], Q, X)
    resolver = rrc_pin.Resolver(arm, dt=DT)
    profile = profile_steps(lambda q, x: resolver.solve(q, x), resolver, Q, X, rates)
    profile["plain_median_us"] = float(np.median(run[RRC].seconds[run[RRC].counted]) * 1e6)
    profile["overhead_us"] = (
        profile["stages"]["all"]["total"]["median_us"] - profile["plain_median_us"]
    )
    return profile


def main(argv: list[str] | None = None) -> int:
    """Run the benchmark; write JSON and PNG to --out or (--record) benchmarks/results."""
    parser = make_parser(__doc__, "resolver", f"{QUICK_STEPS} steps per arm, peers optional")
    parser.add_argument("--steps", type=int, default=None, help=f"trajectory length ({STEPS})")
    parser.add_argument("--arms", nargs="+", default=list(ARMS), help="arms (panda rrc_k1607)")
    parser.add_argument("--seed", type=int, default=None, help="seed (default: a fresh one)")
    args = parser.parse_args(argv)
    steps = args.steps or (QUICK_STEPS if args.quick else STEPS)
    if steps < 2:
        parser.error("--steps: at least 2")
    if args.record and (args.quick or steps != STEPS or args.arms != list(ARMS)):
        parser.error(f"--record keeps full runs only ({STEPS} steps, every arm)")
    warnings.simplefilter("ignore")
    status = peers.availability()
    peers.check(status, args.quick)
    seed = workloads.fresh_seed() if args.seed is None else args.seed
    progress(f"seed {seed} (rerun with --seed {seed})")
    rounds = 1 if args.quick else REPEATS
    start = load_average()
    results: dict[str, Any] = {
        "benchmark": "resolver",
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
            "qp_solver_of_pink_and_mink": peers.QP_SOLVER,
        },
        "peers": status,
        "arms": [bench_arm(a, steps, rounds, seed + k, status) for k, a in enumerate(args.arms)],
    }
    results["load_average"] = {"start": start, "end": load_average()}
    write(args, "resolver", results, lambda path: plot(results, path))
    print(readme_table(results))
    return 0


# ---- rendering (update_readme.py) -------------------------------------------------------------


def readme_table(results: dict[str, Any]) -> str:
    """The README's table: per arm and contender, median / p99 in each mode and the ratio to
    PlaCo; then the answers' quality in one line per arm."""
    head = "| arm | contender |" + "".join(
        f" {MODE_TITLES[m]}: median / p99 [us] | vs PlaCo |" for m in MODES
    )
    lines = [head, "| --- | --- |" + " ---: | ---: |" * len(MODES)]
    for arm in results["arms"]:
        for label in ORDER:
            if label not in arm["modes"]["tight"]["contenders"]:
                continue
            cells = f"| {arm['arm']} | {label} |"
            for mode in MODES:
                r = arm["modes"][mode]["contenders"][label]
                ratio = (
                    f"{r['vs_placo_median']:.2f}x / {r['vs_placo_p99']:.2f}x"
                    if "vs_placo_median" in r
                    else "-"
                )
                cells += f" {us(r['median_us'])} / {us(r['p99_us'])} | {ratio} |"
            lines.append(cells)
    lines += ["", _setup_line(results)]
    for line in _quality_lines(results):
        lines += ["", line]
    return "\n".join(lines)


def _setup_line(results: dict[str, Any]) -> str:
    s, m = results["settings"], results["machine"]
    load = results.get("load_average", {})
    missing = [p for p, why in results["peers"].items() if why != "ran"]
    text = (
        f"{s['steps']} steps per arm (smooth, too-fast and near-limit segments of "
        f"{s['segment']} steps; seeds " + ", ".join(str(a["seed"]) for a in results["arms"])
        + f"), dt = {1000 * s['dt']:g} ms, every contender in one process. rrc-pin: "
        "`Resolver(arm).solve(q, twist)` (its default, the Resolution built); PlaCo: a soft "
        "frame task; pink and mink: `solve_ik` (quadprog); Drake: "
        "`DoDifferentialInverseKinematics`. vs PlaCo: PlaCo's time over the contender's, "
        f"median / p99 (above 1: faster than PlaCo); median of {s['rounds']} rounds. "
        f"Measured on {m['cpu']} ({m['cores']} cores, shared), Python {m['python']}, "
        f"Pinocchio {m['pinocchio']}, placo {m.get('placo')}, pink {m.get('pink')}, mink "
        f"{m.get('mink')}, Drake {m.get('pydrake')}"
    )
    if load:
        text += (
            f", load average {load['start'][0]:.2f} at the start, {load['end'][0]:.2f} at the end"
        )
    if missing:
        text += f"; not in this environment: {', '.join(missing)}"
    return text + "."


def _quality_lines(results: dict[str, Any]) -> list[str]:
    """Per arm, one line: each contender's veer where the LP maximum is 1 and its direction
    error on the too-fast segments."""
    out = []
    for arm in results["arms"]:
        parts = []
        for label in ORDER:
            q = arm["quality"].get(label)
            if q is None:
                continue
            fast = (
                f"; of {q['too_fast_steps']} too-fast steps, {100 * q['at_lp_best']:.0f}% at the "
                f"LP's best speed, {q['stopped_steps']} standing still, direction error "
                f"{q['direction_error_median_deg']:.2g} deg median"
                if q.get("too_fast_steps")
                else ""
            )
            parts.append(
                f"{label}: veers at {q['veer_steps']} of {q['reachable_steps']} fully reachable "
                f"steps (max {q['veer_max_deg']:.2g} deg){fast}"
            )
        out.append(f"Answers, {arm['arm']}: " + ". ".join(parts) + ".")
    return out


def docs_section(results: dict[str, Any]) -> str:
    """Every table of the benchmark, for docs/benchmarks.md."""
    s = results["settings"]
    lines = [
        f"Trajectories: {s['steps']} steps per arm, dt = {1000 * s['dt']:g} ms, segments of "
        f"{s['segment']} steps (`benchmarks/workloads.py`); {s['rounds']} rounds of each mode "
        "from fresh contenders, every time the median of the rounds' (the median's range "
        "over the rounds beside it). vs PlaCo: PlaCo's median over the contender's / the same "
        "for p99, within each round (above 1: faster than PlaCo).",
        "",
        *peers_lines(results["peers"]),
        "",
    ]
    for arm in results["arms"]:
        t = arm["trajectory"]
        segments = ", ".join(f"{v} {k}" for k, v in t["segments"].items())
        gaps = "; ".join(
            f"{peer} {max(g.values()):.1g}" for peer, g in arm.get("kinematics_gaps", {}).items()
        )
        lines += [
            f"### {arm['arm']} ({arm['nq']} joints, tool frame `{arm['tool_frame']}`)",
            "",
            f"Seed {arm['seed']}; segments: {segments}; the LP maximum scale along the command "
            f"is below 1 at {t['lp_scale_below_1']} of {t['steps']} steps. Peers' kinematics "
            f"against Pinocchio's (largest difference of poses and Jacobians): {gaps or '-'}.",
            "",
            *timing_table(arm["modes"], ORDER),
            "",
            "Answers (first round, tight loop; `benchmarks/quality.py`): the veer where the LP "
            "maximum scale along the command is 1 (steps above 1e-6 rad), the direction error "
            "where it is below 1 on the too-fast segments, the share of those steps at the LP's "
            "best speed along the command, and the speed reached against it.",
            "",
            *quality_table(arm["quality"], ORDER),
            "",
            "Limit excess and failures (tight loop, first round):",
            "",
            *excess_table(arm["modes"], ORDER),
            "",
            _routes(arm["rrc_pin"]),
            "",
            *profile_table(arm["profile"], "rrc-pin"),
        ]
    return "\n".join(lines)


def _routes(stats: dict[str, Any]) -> str:
    status = ", ".join(f"{k} {v}" for k, v in stats["status"].items())
    return (
        f"rrc-pin's answers: {status}; the backend called at "
        f"{100 * stats['backend_share']:.1f}% of the steps; {stats['with_attempts']} steps with a "
        f"failed attempt; largest clip {stats['max_clip']:.1g} rad/s."
    )


def plot(results: dict[str, Any], path: Path) -> bool:
    """Median step time per contender, mode and arm (bars), p99 as a tick."""
    panels = [(arm["modes"], f"{arm['arm']}: one frame, joint limits") for arm in results["arms"]]
    return comparison_plot(panels, path, results)


if __name__ == "__main__":
    sys.exit(main())
