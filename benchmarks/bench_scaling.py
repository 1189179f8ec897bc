"""Scaling curves: batch closed-form throughput against N, resolver step time against DOF.

Run from a checkout: ``python benchmarks/bench_scaling.py --out DIR`` (``--record`` writes
``benchmarks/results/`` instead, ``--quick`` a short run); ``rrc-pin bench --only scaling``
runs it.

- **Batch against N**: for every paper arm with a closed form, ``joint_rates_batch`` on N =
  10, 100, ..., 10^6 configurations (10^4 with ``--quick``) drawn uniformly within the joint
  limits, with random commands: the time per configuration (median of the runs, and its
  p10, p90, p99), against the baseline measured in the same run, interleaved with the
  batches: a Python loop of Pinocchio + numpy calls (``computeFrameJacobian``,
  LOCAL_WORLD_ALIGNED, then ``numpy.linalg.solve`` or ``lstsq``, as in
  ``bench_closed_form.py``) on :data:`LOOP_N` configurations. "Flattens at": the smallest N
  whose time per configuration is within 20% of the curve's best.
- **Step time against DOF**: ``Resolver(arm).solve(q, twist)`` (the default: DAQP,
  direction-preserving) in a tight loop along a trajectory recorded as in
  ``bench_resolver.py`` (seeded random twists, rrc-pin tracking mode), for kr5_3r (3 joints),
  barker6 and ur5 (6), rrc_k1607, panda and xarm7 (7), and a longer chain: baxter's left
  gripper as the one FrameTask over its 15 joints (head, both arms). The baseline, timed
  interleaved with it at every step, is the unconstrained reference: one Pinocchio Jacobian
  and one small dense numpy solve (no limits; not a floor: the resolver's numerics are
  compiled kernels, not numpy's calls; the JSON keeps its ``floor_*`` keys;
  ``J J^T`` for more than 6 joints, ``J`` for 6, the position
  rows, square, for 3). This pass and the next run :data:`timing.REPEATS` rounds (one with
  ``--quick``), each from a fresh resolver or controller, combined by their medians.

- **Controller tick against DOF**: ``Controller(arm).step(twist, "world_aligned")`` (the
  teleoperation loop's tick: the same resolver plus the controller's kinematics, drift
  check, integration and log) driven by the same twists from the trajectory's start, in a
  second pass interleaved with the same reference; its ticks per second. There is no cell (a
  loop over several arms) in the library: no cell tick rate.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402
from script import arguments, make_parser, mark_quick, measure, pyplot, write  # noqa: E402
from timing import (  # noqa: E402
    REPEATS,
    combine_rounds,
    progress,
    record_trajectory,
    rounds_note,
    statistics,
)

import rrc_pin  # noqa: E402
from rrc_pin.control import Controller  # noqa: E402
from rrc_pin.robot import frame_id  # noqa: E402

SEED = 20261202
DT = 0.01
SEGMENT = 50
CLOSED_FORM_ARMS = ("barker6", "rrc_k1607", "kr5_3r")
DOF_ARMS = (
    ("kr5_3r", None),
    ("barker6", None),
    ("ur5", None),
    ("rrc_k1607", None),
    ("panda", None),
    ("xarm7", None),
    ("baxter", "left_gripper"),
)
"""(arm, tool frame or None for its default), in order of DOF."""
SIZES = (10, 100, 1_000, 10_000, 100_000, 1_000_000)
QUICK_SIZES = (10, 100, 1_000, 10_000)
LOOP_N = 300
"""Configurations of the Pinocchio + numpy loop (its time per configuration is flat in N)."""
BUDGET_S = 0.3
"""Target time of the runs at one N (at least 5 runs, at most 200)."""
FLATTEN = 1.2

Array = np.ndarray


def uniform_q(arm: Any, n: int, rng: np.random.Generator) -> Array:
    """``n`` configurations (n, nq) uniform within the limits ([-pi, pi] where unbounded)."""
    lo = np.where(np.isfinite(arm.lower), arm.lower, -np.pi)
    hi = np.where(np.isfinite(arm.upper), arm.upper, np.pi)
    return lo + (hi - lo) * rng.random((n, arm.nq))


def floor_step(arm: Any) -> Callable[[Array, Array], Array]:
    """The unconstrained reference: one Pinocchio Jacobian and one small dense solve
    (module docstring)."""
    model, data = arm.model, arm.model.createData()
    fid = frame_id(model, arm.tool_frame)
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    nq = arm.nq

    def step(q: Array, x: Array) -> Array:
        J = pin.computeFrameJacobian(model, data, q, fid, lwa)
        if nq > 6:
            return J.T @ np.linalg.solve(J @ J.T, x)
        if nq == 6:
            return np.linalg.solve(J, x)
        if nq == 3:
            return np.linalg.solve(J[:3], x[:3])
        return np.linalg.lstsq(J, x, rcond=None)[0]

    return step


def batch_curve(name: str, sizes: tuple[int, ...], rng: np.random.Generator) -> dict[str, Any]:
    """Time per configuration of ``joint_rates_batch`` at each N, and the loop baseline."""
    arm = rrc_pin.load(name)
    cf = arm.closed_form
    m = cf.task_dim
    model, data = arm.model, arm.model.createData()
    fid = frame_id(model, arm.tool_frame)
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    solve: Callable[..., Array] = (
        np.linalg.solve if m == arm.nq else (lambda J, x: np.linalg.lstsq(J, x, rcond=None)[0])
    )
    Q = uniform_q(arm, max(sizes), rng)
    X = rng.standard_normal((max(sizes), m))
    Ql, Xl = Q[:LOOP_N], X[:LOOP_N]

    def loop() -> None:
        for q, x in zip(Ql, Xl, strict=True):
            solve(pin.computeFrameJacobian(model, data, q, fid, lwa)[:m], x)

    points = []
    for n in sizes:
        Qn, Xn = Q[:n], X[:n]
        cf.joint_rates_batch(Qn, Xn)  # warm-up (workspaces of this size)
        t0 = time.perf_counter()
        cf.joint_rates_batch(Qn, Xn)
        once = time.perf_counter() - t0
        runs = int(np.clip(BUDGET_S / max(once, 1e-9), 5, 200))
        batch_us, loop_us = [], []
        for _ in range(runs):  # interleaved with the baseline, one run each
            t0 = time.perf_counter()
            cf.joint_rates_batch(Qn, Xn)
            batch_us.append((time.perf_counter() - t0) / n * 1e6)
            if len(loop_us) < 5:
                t0 = time.perf_counter()
                loop()
                loop_us.append((time.perf_counter() - t0) / LOOP_N * 1e6)
        p10, p50, p90, p99 = np.percentile(batch_us, [10, 50, 90, 99])
        loop_median = float(np.median(loop_us))
        points.append(
            {
                "n": n,
                "runs": runs,
                "per_config_us": float(p50),
                "p10_us": float(p10),
                "p90_us": float(p90),
                "p99_us": float(p99),
                "configs_per_s": float(1e6 / p50),
                "loop_per_config_us": loop_median,
                "vs_loop": loop_median / float(p50),
            }
        )
        progress(f"{name}: N = {n:,}: {p50:.3g} us per configuration ({runs} runs)")
    best = min(p["per_config_us"] for p in points)
    flat = next(p["n"] for p in points if p["per_config_us"] <= FLATTEN * best)
    return {"arm": name, "nq": arm.nq, "task_dim": m, "points": points, "flattens_at": flat}


def dof_row(name: str, tool: str | None, steps: int, rounds: int) -> dict[str, Any]:
    """Resolver step time along one trajectory, interleaved with the floor, and the
    controller's tick: ``rounds`` rounds, combined by their medians (``timing.combine_rounds``)."""
    arm = rrc_pin.load(name, tool_frame=tool) if tool else rrc_pin.load(name)
    rng = np.random.default_rng(SEED)
    Q, X = record_trajectory(arm, steps, rng, DT, SEGMENT)
    floor = floor_step(arm)
    row = combine_rounds([{name: resolver_steps(arm, Q, X, floor)} for _ in range(rounds)])[name]
    progress(
        f"{name} ({arm.nq} joints): {row['median_us']:.0f} us per step, "
        f"floor {row['floor_median_us']:.0f} us"
    )
    ticks = [{name: controller_ticks(arm, Q, X, floor)} for _ in range(rounds)]
    return {
        "arm": name,
        "tool_frame": arm.tool_frame,
        "nq": arm.nq,
        "steps": steps,
        **row,
        "controller": combine_rounds(ticks)[name],
    }


def resolver_steps(
    arm: Any, Q: Array, X: Array, floor: Callable[[Array, Array], Array]
) -> dict[str, Any]:
    """A fresh default ``Resolver`` along the trajectory, interleaved with the floor."""
    resolver = rrc_pin.Resolver(arm, dt=DT)
    resolver.solve(Q[0], X[0])  # untimed first call
    floor(Q[0], X[0])
    ours, base = np.empty(len(Q)), np.empty(len(Q))
    clock = time.perf_counter
    for k in range(len(Q)):
        t0 = clock()
        resolver.solve(Q[k], X[k])
        ours[k] = clock() - t0
        t0 = clock()
        floor(Q[k], X[k])
        base[k] = clock() - t0
    return _against_floor(statistics(ours), base)


def _against_floor(row: dict[str, float], base: Array) -> dict[str, float]:
    """``row`` with the floor's median and p99 [us] and the ratios to them."""
    f50, f99 = np.percentile(base * 1e6, [50, 99])
    row.update(
        floor_median_us=float(f50),
        floor_p99_us=float(f99),
        vs_floor_median=float(f50 / row["median_us"]),
        vs_floor_p99=float(f99 / row["p99_us"]),
    )
    return row


def controller_ticks(
    arm: Any, Q: Array, X: Array, floor: Callable[[Array, Array], Array]
) -> dict[str, Any]:
    """``Controller.step`` along the trajectory's twists from its start, interleaved with the
    floor at the trajectory's configurations."""
    ctl = Controller(arm, dt=DT, q0=Q[0])
    ctl.step(X[0], "world_aligned")  # untimed first call
    ticks, base = np.empty(len(Q)), np.empty(len(Q))
    clock = time.perf_counter
    for k in range(len(Q)):
        t0 = clock()
        ctl.step(X[k], "world_aligned")
        ticks[k] = clock() - t0
        t0 = clock()
        floor(Q[k], X[k])
        base[k] = clock() - t0
    row = _against_floor(statistics(ticks), base)
    row["ticks_per_s"] = 1e6 / row["median_us"]
    return row


def run(quick: bool) -> dict[str, Any]:
    """Both curves (module docstring)."""
    rng = np.random.default_rng(SEED)
    sizes = QUICK_SIZES if quick else SIZES
    steps = 100 if quick else 1000
    rounds = 1 if quick else REPEATS
    return {
        "settings": {
            "sizes": list(sizes),
            "loop_n": LOOP_N,
            "steps": steps,
            "dt": DT,
            "rounds": rounds,
        },
        "batch": [batch_curve(a, sizes, rng) for a in CLOSED_FORM_ARMS],
        "dof": [dof_row(a, tool, steps, rounds) for a, tool in DOF_ARMS],
    }


def readme_table(results: dict[str, Any]) -> str:
    """Not in the README: the two tables."""
    return docs_section(results)


def docs_section(results: dict[str, Any]) -> str:
    """The docs/benchmarks.md section: batch time per configuration against N, step time
    against DOF."""
    sizes = results["settings"]["sizes"]
    lines = [
        "Batch closed forms: time per configuration [us] of `joint_rates_batch` at each N "
        "(median of the runs), and the speed-up over a Python loop of Pinocchio + numpy "
        f"calls timed in the same run ({results['settings']['loop_n']} configurations).",
        "",
        "| arm | " + " | ".join(f"N = {n:,}" for n in sizes) + " | loop [us] | flattens at |",
        "| --- |" + " ---: |" * (len(sizes) + 2),
    ]
    for curve in results["batch"]:
        cells = " | ".join(
            f"{p['per_config_us']:.3g} ({_times(p['vs_loop'])})" for p in curve["points"]
        )
        loop = np.median([p["loop_per_config_us"] for p in curve["points"]])
        lines.append(f"| {curve['arm']} | {cells} | {loop:.1f} | N = {curve['flattens_at']:,} |")
    lines += [
        "",
        "Resolver step time against DOF: `Resolver(arm).solve` (default: DAQP, "
        f"direction-preserving), {results['settings']['steps']} steps of a seeded random "
        "teleoperation in a tight loop, interleaved with the unconstrained reference (one "
        "Pinocchio Jacobian and one small dense numpy solve, no limits: not a floor, the "
        f"resolver's numerics are compiled); {rounds_note(results['settings'])}.",
        "",
        "| arm | tool frame | joints | median [us] | p10 | p90 | p99 | reference median [us] | "
        "reference / resolver (median) | (p99) |",
        "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in results["dof"]:
        lines.append(
            f"| {r['arm']} | `{r['tool_frame']}` | {r['nq']} | {r['median_us']:.0f} | "
            f"{r['p10_us']:.0f} | {r['p90_us']:.0f} | {r['p99_us']:.0f} | "
            f"{r['floor_median_us']:.1f} | {r['vs_floor_median']:.2f}x | "
            f"{r['vs_floor_p99']:.2f}x |"
        )
    if all("controller" in r for r in results["dof"]):
        lines += ["", *controller_table(results)]
    return "\n".join(lines)


def controller_table(results: dict[str, Any]) -> list[str]:
    """Controller tick time against DOF (results recorded since the controller exists)."""
    lines = [
        'Controller tick against DOF: `Controller(arm).step(twist, "world_aligned")` on the '
        "same twists from the trajectory's start, in a second pass interleaved with the "
        "unconstrained reference. "
        "No cell (a loop over several arms) exists in the library: no cell tick rate.",
        "",
        "| arm | joints | tick median [us] | p10 | p90 | p99 | ticks per s (median) | "
        "reference median [us] | reference / tick (median) | (p99) |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in results["dof"]:
        c = r["controller"]
        lines.append(
            f"| {r['arm']} | {r['nq']} | {c['median_us']:.0f} | {c['p10_us']:.0f} | "
            f"{c['p90_us']:.0f} | {c['p99_us']:.0f} | {c['ticks_per_s']:,.0f} | "
            f"{c['floor_median_us']:.1f} | {c['vs_floor_median']:.2f}x | "
            f"{c['vs_floor_p99']:.2f}x |"
        )
    return lines


def _times(ratio: float) -> str:
    return f"{ratio:.0f}x" if ratio >= 10 else f"{ratio:.2g}x"


def plot(results: dict[str, Any], path: Path) -> bool:
    """Time per configuration against N (log-log) and step time against DOF; False without
    matplotlib."""
    plt = pyplot()
    if plt is None:
        return False

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    for curve in results["batch"]:
        n = [p["n"] for p in curve["points"]]
        t = [p["per_config_us"] for p in curve["points"]]
        lo = [p["per_config_us"] - p["p10_us"] for p in curve["points"]]
        hi = [p["p90_us"] - p["per_config_us"] for p in curve["points"]]
        line = left.errorbar(n, t, yerr=[lo, hi], marker="o", capsize=3, label=curve["arm"])
        loop = np.median([p["loop_per_config_us"] for p in curve["points"]])
        left.axhline(loop, ls="--", color=line[0].get_color(), lw=0.8)
    left.set(
        xscale="log",
        yscale="log",
        xlabel="N (configurations per call)",
        ylabel="time per configuration [us]",
        title="joint_rates_batch (dashed: Python loop over Pinocchio + numpy)",
    )
    left.legend()
    rows = results["dof"]
    x = np.arange(len(rows))
    med = [r["median_us"] for r in rows]
    right.bar(x - 0.2, med, 0.4, label="Resolver.solve (median)")
    right.errorbar(
        x - 0.2,
        med,
        yerr=[[m - r["p10_us"] for m, r in zip(med, rows, strict=True)],
              [r["p90_us"] - m for m, r in zip(med, rows, strict=True)]],
        fmt="none",
        color="k",
        capsize=3,
    )  # fmt: skip
    if all("controller" in r for r in rows):
        right.plot(
            x - 0.2, [r["controller"]["median_us"] for r in rows], "kD",
            label="Controller.step (median)",
        )  # fmt: skip
    right.bar(x + 0.2, [r["floor_median_us"] for r in rows], 0.4,
              label="reference: J + numpy solve, no limits (median)")  # fmt: skip
    right.set_xticks(x, [f"{r['arm']}\n{r['nq']} DOF" for r in rows], fontsize=8)
    right.set(ylabel="time per step [us]", title="step time against DOF (p10-p90 bars)")
    right.legend()
    mark_quick(fig, results)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def main(argv: list[str] | None = None) -> int:
    args = arguments(make_parser(__doc__, "scaling", "N up to 10^4, 100 steps"), argv)
    warnings.simplefilter("ignore")
    results = measure("scaling", args.quick, lambda: run(args.quick))
    write(args, "scaling", results, lambda path: plot(results, path))
    print(docs_section(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
