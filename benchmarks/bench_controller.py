"""The teleoperation controller: its tick against a bare resolver loop, and 10-minute sessions.

Run from a checkout: ``python benchmarks/bench_controller.py --out DIR`` (``--record`` writes
``benchmarks/results/controller.json`` and ``.png``, ``--quick`` a short smoke run);
``rrc-pin bench --only controller`` runs it.

- **Tick time** (issue 8), on barker6 and panda: random operator commands
  (``random_commands``, seeded, hand frame, no pauses) drive a default ``Controller``
  (deadman, drift correction at every tick, log, resolver strategy). At every tick, in an order
  shuffled per tick (interleaved), the two contenders run at the controller's current q with
  the same command: the baseline ``Resolver.solve(q, twist, ref="local")`` with the Euler
  update ``q + qdot dt``, and ``Controller.step(twist, "local")`` (the kinematics and singular
  values of the tick, the drift check, the strategy, the same solve, ``pinocchio.integrate``,
  the record). Median, p10, p90, p99 [us] of each, the ratios (the baseline's time over the
  controller's) and the controller's overhead ``(ctl - bare) / ctl`` of the medians and of
  the p99s. One core, BLAS threads pinned to 1.
- **Sessions**: 10 simulated minutes at 100 Hz (6 s with ``--quick``) of random operator
  commands (hand-frame twists held 0.5 s, 0.05 m/s and 0.2 rad/s per axis, 10 % pauses) on
  each paper arm and on panda, with the drift correction and without it (same commands):
  position and velocity limit excess, NaN, the pose drift (max, and how fast it grows
  between resets of the reference [mm/min]), the statuses, and the time of every tick.

One benchmark rather than two: both measure the same ``Controller.step``, so one
``rrc-pin bench --record --only controller`` refreshes every controller number at once.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import itertools  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from script import QUICK_NOTE, arguments, make_parser, measure, write  # noqa: E402
from timing import (  # noqa: E402
    add_ratios,
    one_core,
    progress,
    statistics,
    stats_cells,
    timing_chart,
    us,
)

import rrc_pin  # noqa: E402
from rrc_pin.control import Controller, DriftCorrection  # noqa: E402
from rrc_pin.control.controller import REANCHOR  # noqa: E402
from rrc_pin.control.random_operator import random_commands  # noqa: E402

STARTS = {
    "barker6": np.deg2rad([20.0, 30.0, 60.0, 10.0, 40.0, 0.0]),
    "rrc_k1607": np.array([0.0, 0.5, 0.0, 1.2, 0.0, 0.6, 0.0]),
    "kr5_3r": np.array([0.0, 0.785, -0.785]),
    "panda": np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.7]),
}
"""Start of each arm (within its limits, away from singularities)."""
TICK_ARMS = ("barker6", "panda")
BARE, CONTROLLER = "Resolver.solve + Euler", "Controller.step"
STEPS, QUICK_STEPS = 3000, 200
"""Ticks per arm of the tick-time part."""
MINUTES, QUICK_MINUTES = 10.0, 0.1
"""Simulated minutes per session."""
TICK_SEED, SESSION_SEED = 7, 2026
GROWTH_SPAN = 1000
"""Ticks without a reset of the reference after which a span counts for the drift growth."""
TARGET = 0.25
"""Issue 8: the controller's overhead stays under this share of the step."""


def tick_time(name: str, steps: int) -> dict[str, Any]:
    """Both contenders over ``steps`` ticks of one session on arm ``name``, interleaved."""
    arm = rrc_pin.load(name)
    ctl = Controller(arm, q0=STARTS[name])
    bare = rrc_pin.Resolver(arm, dt=ctl.dt)
    rng = np.random.default_rng(TICK_SEED)
    commands = random_commands(rng, steps * ctl.dt, ctl.dt, pause=0.0)
    times: dict[str, list[float]] = {BARE: [], CONTROLLER: []}
    for twist in commands[:50]:  # warm-up
        bare.solve(ctl.q, twist, ref="local")
        ctl.step(twist, "local")
    for twist in commands:
        q = ctl.q.copy()
        for who in rng.permutation([BARE, CONTROLLER]):
            start = time.perf_counter()
            if who == BARE:
                r = bare.solve(q, twist, ref="local")
                _ = q + r.qdot * ctl.dt
            else:
                ctl.step(twist, "local")
            times[str(who)].append(time.perf_counter() - start)
    rows = {who: statistics(np.array(t)) for who, t in times.items()}
    add_ratios(rows, BARE)
    labels, counts = np.unique(ctl.log.column("status")[-steps:], return_counts=True)
    return {
        "arm": name,
        "nq": arm.nq,
        "steps": steps,
        "baseline": BARE,
        "contenders": rows,
        "overhead_median": 1.0 - rows[CONTROLLER]["vs_baseline_median"],
        "overhead_p99": 1.0 - rows[CONTROLLER]["vs_baseline_p99"],
        "statuses": {str(k): int(v) for k, v in zip(labels, counts, strict=True)},
    }


def session(name: str, minutes: float, corrected: bool) -> dict[str, Any]:
    """One session of random operator commands (module docstring)."""
    arm = rrc_pin.load(name)
    ctl = Controller(arm, q0=STARTS[name], drift=DriftCorrection() if corrected else None)
    commands = random_commands(np.random.default_rng(SESSION_SEED), 60.0 * minutes, ctl.dt)
    seconds = np.empty(len(commands))
    clock = time.perf_counter
    for k, twist in enumerate(commands):
        start = clock()
        ctl.step(twist, ref="local")
        seconds[k] = clock() - start
    log = ctl.log
    q, qdot, t = log.column("q"), log.column("qdot"), log.column("t")
    d_pos, d_rot = log.column("drift_position"), log.column("drift_rotation")
    statuses, counts = np.unique(log.column("status"), return_counts=True)
    # Growth: the reference is reset to the reached pose whenever the resolver changes the
    # command's direction (damped, singular, ...), so the drift restarts from 0 there; over
    # every span without a reset longer than GROWTH_SPAN ticks, the drift at its end per
    # minute of span.
    resets = np.flatnonzero(np.isin(log.column("status"), REANCHOR))
    edges = np.concatenate([[0], resets, [len(log) - 1]])
    spans = [(a, b) for a, b in itertools.pairwise(edges) if b - a > GROWTH_SPAN]
    growth = [d_pos[b - 1] / ((t[b - 1] - t[a]) / 60.0) for a, b in spans]
    return {
        "arm": name,
        "drift_correction": corrected,
        "steps": len(log),
        "minutes": minutes,
        "tick": statistics(seconds),
        "wall_seconds": float(seconds.sum()),
        "nan": bool(not (np.isfinite(q).all() and np.isfinite(qdot).all())),
        "position_excess": float(max(0.0, np.max(q - arm.upper), np.max(arm.lower - q))),
        "velocity_excess": float(max(0.0, np.max(np.abs(qdot) - arm.velocity_limit))),
        "drift_max_mm": 1e3 * float(d_pos.max()),
        "drift_rotation_max_mrad": 1e3 * float(d_rot.max()),
        "drift_growth_mm_per_min": 1e3 * float(np.median(growth)) if growth else None,
        "drift_growth_spans": len(growth),
        "drift_final_mm": 1e3 * float(d_pos[-1]),
        "statuses": {str(s): int(c) for s, c in zip(statuses, counts, strict=True)},
    }


def run(quick: bool) -> dict[str, Any]:
    """Both parts (module docstring)."""
    steps = QUICK_STEPS if quick else STEPS
    minutes = QUICK_MINUTES if quick else MINUTES
    arms = []
    with one_core([]):
        for name in TICK_ARMS:
            progress(f"controller: tick time on {name}, {steps} ticks interleaved")
            arms.append(tick_time(name, steps))
    sessions = []
    for name in STARTS:
        for corrected in (True, False):
            progress(f"controller: {minutes:g} min session on {name}, correction {corrected}")
            sessions.append(session(name, minutes, corrected))
    settings = {"steps": steps, "minutes": minutes, "dt": 0.01, "target_overhead": TARGET}
    return {"settings": settings, "arms": arms, "sessions": sessions}


def readme_table(results: dict[str, Any]) -> str:
    """The tick-time table and one line on the sessions."""
    lines = [
        "| arm | resolver + Euler median / p99 [us] | controller median / p99 [us] | "
        "overhead (median) | (p99) |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    for a in results["arms"]:
        b, c = a["contenders"][a["baseline"]], a["contenders"][CONTROLLER]
        lines.append(
            f"| {a['arm']} | {us(b['median_us'])} / {us(b['p99_us'])} | "
            f"{us(c['median_us'])} / {us(c['p99_us'])} | {100 * a['overhead_median']:.0f} % | "
            f"{100 * a['overhead_p99']:.0f} % |"
        )
    return "\n".join([*lines, "", _sessions_line(results)])


def _sessions_line(results: dict[str, Any]) -> str:
    s = results["sessions"]
    arms = sorted({r["arm"] for r in s})
    clean = all(not r["nan"] and r["position_excess"] == 0 and r["velocity_excess"] == 0 for r in s)
    worst = max((r for r in s if r["drift_correction"]), key=lambda r: r["drift_max_mm"])
    return (
        f"Sessions of {results['settings']['minutes']:g} simulated minutes at 100 Hz on "
        f"{', '.join(arms)} ({sum(r['steps'] for r in s):,} ticks): "
        + ("no NaN, no position or velocity limit excess" if clean else "**limit excess or NaN**")
        + f"; largest pose drift with the correction {worst['drift_max_mm']:.1f} mm "
        f"({worst['arm']})."
    )


def docs_section(results: dict[str, Any]) -> str:
    """The docs/benchmarks.md section: tick times, the overhead against the target, sessions."""
    target = results["settings"]["target_overhead"]
    lines = [
        f"Tick time, interleaved ({results['settings']['steps']:,} ticks per arm): the baseline "
        f"`{BARE}` and `{CONTROLLER}` at the same q with the same command; ratio: the "
        "baseline's time over the controller's; overhead: the controller's share of its own "
        "step that the bare loop does not spend.",
        "",
        "| arm | joints | contender | median [us] | p10 | p90 | p99 | vs baseline (median) | "
        "(p99) | ticks per s (median) |",
        "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for a in results["arms"]:
        for label, r in a["contenders"].items():
            lines.append(
                f"| {a['arm']} | {a['nq']} | {label} |{stats_cells(r)} "
                f"{1e6 / r['median_us']:,.0f} |"
            )
    verdicts = [
        f"{a['arm']} {100 * a['overhead_median']:.0f} % (p99 {100 * a['overhead_p99']:.0f} %)"
        for a in results["arms"]
    ]
    met = all(a["overhead_median"] < target for a in results["arms"])
    lines += [
        "",
        f"Overhead of the controller (issue 8's target: under {100 * target:.0f} % of the step): "
        + "; ".join(verdicts)
        + (": met." if met else ": **not met**."),
        "",
        _sessions_line(results),
        "",
        "| arm | drift correction | ticks | tick median [us] | p99 | NaN | position excess [rad] "
        "| velocity excess [rad/s] | drift max [mm] | [mrad] | drift at end [mm] | "
        "growth [mm/min] (spans) | statuses |",
        "| --- | --- | ---: | ---: | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    for r in results["sessions"]:
        growth = r["drift_growth_mm_per_min"]
        growth_text = "-" if growth is None else f"{growth:.2f}"
        statuses = ", ".join(f"{k} {v:,}" for k, v in r["statuses"].items())
        lines.append(
            f"| {r['arm']} | {'on' if r['drift_correction'] else 'off'} | {r['steps']:,} | "
            f"{us(r['tick']['median_us'])} | {us(r['tick']['p99_us'])} | "
            f"{'yes' if r['nan'] else 'no'} | {r['position_excess']:.2g} | "
            f"{r['velocity_excess']:.2g} | {r['drift_max_mm']:.2f} | "
            f"{r['drift_rotation_max_mrad']:.2f} | {r['drift_final_mm']:.2f} | "
            f"{growth_text} ({r['drift_growth_spans']}) | {statuses} |"
        )
    lines += [
        "",
        "Growth: the reference pose is reset to the reached pose whenever the resolver changes "
        "the command's direction (damped, singular, ...); over every span without a reset "
        f"longer than {GROWTH_SPAN / 100:g} s, the drift at its end per minute of span "
        "(median over the spans; - when no span is that long).",
    ]
    return "\n".join(lines)


def plot(results: dict[str, Any], path: Path) -> bool:
    """Tick times of both contenders per arm (median bars, p99 ticks); False without
    matplotlib."""
    panels = [
        ({"interleaved": a["contenders"]}, f"{a['arm']}: one tick of the operator's loop")
        for a in results["arms"]
    ]
    return timing_chart(panels, path, (6.5 * len(panels), 3.4),
                        {"interleaved": "interleaved, the same q and command"},
                        QUICK_NOTE if results.get("quick") else None)  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    args = arguments(make_parser(__doc__, "controller", f"{QUICK_STEPS} ticks, 6 s sessions"), argv)
    results = measure("controller", args.quick, lambda: run(args.quick))
    write(args, "controller", results, lambda path: plot(results, path))
    print(docs_section(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
