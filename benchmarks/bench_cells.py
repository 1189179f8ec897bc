"""One tick of a multi-arm cell's controller, with and without collision constraints.

The cells: gsfc_dual and yeh_tripod.

Run from a checkout: ``python benchmarks/bench_cells.py --out DIR`` (``--record`` writes
``benchmarks/results/cells.json`` and ``.png``, ``--quick`` a short smoke run);
``rrc-pin bench --only cells`` runs it.

- **gsfc_dual** (issue 30): the held object commanded by random world-axes twists (0.15 m/s
  and 0.4 rad/s per axis, normal, each held 0.5 s), a default ``CellController`` (deadman,
  targets fed back, the grip's equality rows, the closed chain's correction, the log), at
  100 Hz. The controllers take the same commands: joint limits only, and joint limits plus
  a ``CollisionLimit`` on the cell's capsules (every pair between the two arms and the
  kinematic rules' pairs within each; default safety and detection distances). Timed in two
  modes, each from fresh controllers: tight (each controller 250 ticks in a row, by turns)
  and interleaved (at every tick each steps, in an order drawn at random: each tick finds the
  caches the others left).
- **yeh_tripod**: the body commanded by random twists (0.03 m/s, 0.1 rad/s per axis, held
  0.5 s) over its three feet in support (the contacts' equality rows and correction), the
  same controllers (the collision model: the three legs' capsules, rows over all 24 rates,
  the floating base's included).
- A third controller of each cell adds a ball to its collision model (:data:`BALLS`), in the
  way of the commanded motion, so that the collision rows bind on most ticks (the arms'
  own pairs come within the detection distance on some ticks of the dual cell's session, on
  none of the tripod's: there the collision case times the distance queries alone).

A case whose collision model cannot be built or whose limit refuses the cell is recorded in
``not_run`` with the refusal, never timed without its limit.

Per case and mode the tick's median, p10, p90, p99 [us] (``time.perf_counter`` around
``step``; the first ticks left out) and its CPU time's median and p99 (``time.thread_time``);
of the tight mode, the loop rate they give (1 / tick [Hz]), the statuses, the largest grip
error or foot slip, and with collision the ticks that had collision rows and the smallest
distance seen. One core, BLAS threads pinned to 1. As the console does before its loop
starts (docs/api.md, "Pauses of the garbage collector"), what the process holds once the
controllers are built is collected and frozen out of later collections while they run: a
full collection of the unfrozen heap (numba's compilations included) took 44-65 ms, and which
tick it lands in depends on what was built before.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import collections  # noqa: E402
import gc  # noqa: E402
import json  # noqa: E402
import sys  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from script import arguments, make_parser, mark_quick, measure, pyplot, write  # noqa: E402
from timing import closed_loops, one_core, progress, statistics, timed, us  # noqa: E402

import rrc_pin  # noqa: E402
from rrc_pin.cells import CellController  # noqa: E402
from rrc_pin.cells.closure import ClosureBound  # noqa: E402
from rrc_pin.errors import RrcPinError  # noqa: E402
from rrc_pin.solvers.tick.damping import Damping  # noqa: E402
from rrc_pin.solvers.tick.factorization import Factorization  # noqa: E402

DT = 0.01
TICKS, QUICK_TICKS = 3000, 100
"""Ticks per cell (30 s at 100 Hz; a quick run 1 s)."""
HOLD = 50
"""Ticks each random command is held (0.5 s)."""
WARM_UP = 10
"""First ticks left out of the statistics (caches, the first factorisations)."""
SEED = 2030
MODES = ("tight", "interleaved")
"""Each from fresh controllers (:func:`timing.closed_loops`)."""
SPEEDS = {
    "gsfc_dual": ("object", np.array([0.15, 0.15, 0.15, 0.4, 0.4, 0.4])),
    "yeh_tripod": ("body", np.array([0.03, 0.03, 0.03, 0.1, 0.1, 0.1])),
}
"""Cell: (the command's name, the standard deviation of each twist entry [m/s, rad/s])."""
WITHOUT, WITH, BALL = "joint limits", "joint limits + collision", "+ collision, a ball"
BALLS = {
    "gsfc_dual": ("object", [0.0, 0.0, -0.25], 0.08),
    "yeh_tripod": ("body", [0.0, 0.0, -0.6], 0.1),
}
"""Cell: the obstacle of the third case, a ball: the frame its centre is placed from at the
ready pose, the offset [m] (world axes) and its radius [m]: in the way of the commanded
motion, so that the collision rows bind on most ticks."""


def _controllers(cell: rrc_pin.Cell) -> tuple[dict[str, CellController], dict[str, Any]]:
    """The case's controllers by label, and what could not run (label: reason)."""
    out = {WITHOUT: CellController(cell, DT)}
    refused: dict[str, Any] = {}
    frame, offset, radius = BALLS[cell.name]
    for label in (WITH, BALL):
        try:
            model = rrc_pin.CollisionModel(cell, "capsules")
            if label == BALL:
                model.add_sphere(cell.fk(cell.ready(), frame)[:3, 3] + offset, radius, "ball")
            limit = rrc_pin.CollisionLimit(model)
            out[label] = CellController(cell, DT, limits=[rrc_pin.JointLimits(), limit])
        except RrcPinError as exc:
            message = str(exc).split(" (rates")[0]  # not the lists of names
            refused[label] = f"{type(exc).__name__}: {message}"
    return out, refused


class CellLoop:
    """One controller's closed loop on the cell's commands, and what it met: the statuses, the
    ticks with collision rows and the smallest distance seen."""

    def __init__(self, ctl: CellController, command: str, twists: list[np.ndarray]) -> None:
        self.ctl, self.command, self.twists = ctl, command, twists
        self.statuses: collections.Counter[str] = collections.Counter()
        self.near, self.closest = 0, np.inf
        self.limit = next((lim for lim in ctl.resolver.limits
                           if isinstance(lim, rrc_pin.CollisionLimit)), None)  # fmt: skip

    def __call__(self, k: int) -> tuple[float, float]:
        """Tick ``k``: the controller's step, timed (wall-clock and CPU seconds)."""
        commands = {self.command: self.twists[k // HOLD]}
        step, wall, cpu = timed(lambda: self.ctl.step(commands))
        self.statuses[step.resolution.status] += 1
        last = None if self.limit is None else self.limit.last
        if last is not None and len(last.names):
            self.near += 1
            self.closest = min(self.closest, float(last.distance.min()))
        return wall, cpu


def run_cell(name: str, ticks: int) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
    """Every controller of cell ``name`` over ``ticks`` ticks, tight and interleaved, each mode
    from fresh controllers (module docstring)."""
    cell = rrc_pin.load(name)
    command, speed = SPEEDS[name]
    rng = np.random.default_rng(SEED)
    order = np.random.default_rng(SEED + 1)
    twists = [rng.normal(size=6) * speed for _ in range(ticks // HOLD + 1)]
    loops, times = {}, {}
    for mode in MODES:
        controllers, refused = _controllers(cell)
        loops[mode] = {label: CellLoop(ctl, command, twists) for label, ctl in controllers.items()}
        progress(f"cells: {name}, {mode}")
        gc.collect()
        gc.freeze()  # as the console's loop (module docstring)
        try:
            times[mode] = closed_loops(mode, loops[mode], ticks, order)
        finally:
            gc.unfreeze()
    feet = {f: cell.fk(cell.ready(), f)[:3, 3] for f in cell.tool_frames} if cell.body else {}
    rows = []
    for label, loop in loops["tight"].items():
        stats = statistics(*(t[WARM_UP:] for t in times["tight"][label]))
        row: dict[str, Any] = {
            "cell": name, "limits": label, "collision": label != WITHOUT, "ticks": ticks,
            "nv": cell.nv, **stats, "rate_hz_median": 1e6 / stats["median_us"],
            "rate_hz_p99": 1e6 / stats["p99_us"], "statuses": dict(loop.statuses),
            "interleaved": statistics(*(t[WARM_UP:] for t in times["interleaved"][label])),
        }  # fmt: skip
        ctl = loop.ctl
        if cell.objects:
            row["grip_max_m"] = max(max(rec.grip.values()) for rec in ctl.log)
        if feet:
            row["slip_max_m"] = max(float(np.linalg.norm(cell.fk(ctl.q, f)[:3, 3] - p))
                                    for f, p in feet.items())  # fmt: skip
        if label != WITHOUT:
            row["collision_ticks"] = loop.near
            row["min_distance_m"] = None if loop.near == 0 else loop.closest
        rows.append(row)
        progress(f"cells: {name}, {label}: tight median {stats['median_us']:.0f} us, CPU p99 "
                 f"{stats['cpu_p99_us']:.0f} us; interleaved median "
                 f"{row['interleaved']['median_us']:.0f} us")  # fmt: skip
    not_run = [{"cell": name, "limits": label, "reason": why} for label, why in refused.items()]
    return rows, not_run


def run(quick: bool) -> dict[str, Any]:
    """Both cells (module docstring)."""
    ticks = QUICK_TICKS if quick else TICKS
    rows: list[dict[str, Any]] = []
    not_run: list[dict[str, Any]] = []
    with one_core([]):
        for name in SPEEDS:
            r, n = run_cell(name, ticks)
            rows += r
            not_run += n
    settings = {"ticks": ticks, "dt": DT, "hold_ticks": HOLD, "seed": SEED,
                "speeds": {k: v[1].tolist() for k, v in SPEEDS.items()}}  # fmt: skip
    return {"settings": settings, "rows": rows, "not_run": not_run}


def _rate(hz: float) -> str:
    return f"{hz / 1000:.1f} kHz" if hz >= 1000 else f"{hz:.0f} Hz"


def readme_table(results: dict[str, Any]) -> str:
    """One row per case: tick median / p99 and the loop rate; the cases that did not run."""
    lines = [
        "| cell | limits | tight: median / CPU p99 [us] | interleaved [us] | "
        "loop rate (median / p99) |",
        "| --- | --- | ---: | ---: | ---: |",
    ]
    for r in results["rows"]:
        mixed = r["interleaved"]
        lines.append(f"| {r['cell']} | {r['limits']} | {us(r['median_us'])} / "
                     f"{us(r['cpu_p99_us'])} | {us(mixed['median_us'])} / "
                     f"{us(mixed['cpu_p99_us'])} | {_rate(r['rate_hz_median'])} / "
                     f"{_rate(r['rate_hz_p99'])} |")  # fmt: skip
    for n in results["not_run"]:
        lines.append(f"| {n['cell']} | {n['limits']} | not run: {_reason(n)} | | |")
    s, load = results["settings"], results.get("load_average") or {}
    start, end = (load.get(k, [float("nan")])[0] for k in ("start", "end"))
    def binding(label: str) -> str:
        return ", ".join(f"{r['cell']} {r['collision_ticks']:,}" for r in results["rows"]
                         if r["limits"] == label)  # fmt: skip

    lines += [
        "",
        f"`CellController.step` at {1 / s['dt']:.0f} Hz, {s['ticks']:,} ticks a cell of random "
        f"commands held {s['hold_ticks'] * s['dt']:g} s (the held object's twist on gsfc_dual, "
        "the body's on yeh_tripod), on one core: tight (each controller of a cell "
        "250 ticks in a row, by turns; the loop rate from its wall-clock median and p99) and "
        "interleaved (every tick each controller once, in an order drawn at random). "
        f"Collision: the arms' capsules (ticks with collision rows: {binding(WITH)}), and a "
        f"ball in the way ({binding(BALL)}). Load average {start:.2f} at the start, {end:.2f} "
        "at the end (2 cores, shared).",
    ]
    return "\n".join(lines)


def _reason(n: dict[str, Any]) -> str:
    """A refusal in a few words (the floating base's, else the message)."""
    return "a floating base: CollisionLimit refuses it" if "floating" in n["reason"] else (
        n["reason"])  # fmt: skip


def docs_section(results: dict[str, Any]) -> str:
    """The docs/benchmarks.md section: every statistic, the statuses and the checks."""
    s = results["settings"]
    lines = [
        f"One tick of `CellController.step` at {1 / s['dt']:.0f} Hz, {s['ticks']:,} ticks per "
        f"cell, random commands held {s['hold_ticks'] * s['dt']:g} s (the object's on "
        "gsfc_dual, the body's on yeh_tripod), on one core: tight (each controller of a cell "
        "250 ticks in a row, by turns) and interleaved (every tick each controller once, in an "
        "order drawn at random); the statuses and checks of the tight run.",
        "",
        "| cell | rates | limits | median [us] | p10 | p90 | p99 | max | CPU p99 | "
        "interleaved median / CPU p99 | loop rate (median) | (p99) | grip max [m] | "
        "foot slip [m] | ticks with collision rows | closest [m] | statuses |",
        "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | "
        "---: | ---: | ---: | ---: | --- |",
    ]
    for r in results["rows"]:
        statuses = ", ".join(f"{k} {v:,}" for k, v in sorted(r["statuses"].items()))
        grip = f"{r['grip_max_m']:.2g}" if "grip_max_m" in r else "-"
        slip = f"{r['slip_max_m']:.2g}" if "slip_max_m" in r else "-"
        rows_ = str(r["collision_ticks"]) if "collision_ticks" in r else "-"
        closest = "-" if r.get("min_distance_m") is None else f"{r['min_distance_m']:.3f}"
        lines.append(
            f"| {r['cell']} | {r['nv']} | {r['limits']} | {us(r['median_us'])} | "
            f"{us(r['p10_us'])} | {us(r['p90_us'])} | {us(r['p99_us'])} | {us(r['max_us'])} | "
            f"{us(r['cpu_p99_us'])} | {us(r['interleaved']['median_us'])} / "
            f"{us(r['interleaved']['cpu_p99_us'])} | {_rate(r['rate_hz_median'])} | "
            f"{_rate(r['rate_hz_p99'])} | {grip} | {slip} | "
            f"{rows_} | {closest} | {statuses} |"
        )
    for n in results["not_run"]:
        lines += ["", f"Not run: {n['cell']} with {n['limits']}: {n['reason']}"]
    lines += [
        "",
        "The tick is the whole Python step: the commands checked and weighted (speed, deadman), "
        "the frames' kinematics, the tasks with their targets, the resolver (with the grip's "
        "or the contacts' equality rows and, with collision, the pairs' distances and rows), "
        "the integration and the closed chains' projection, the log's record. A loop at the "
        "rate in the p99 column misses no deadline on this machine 99 % of the time.",
    ]
    return "\n".join(lines)


def plot(results: dict[str, Any], path: Path) -> bool:
    """Median bars with p10-p90 whiskers and the p99 marked per case, on a log axis, with the
    100 Hz period; the loop rate at the median above each bar. False without matplotlib."""
    plt = pyplot()
    if plt is None:
        return False
    rows = results["rows"]
    fig, ax = plt.subplots(figsize=(9.0, 4.2))
    x = np.arange(len(rows))
    med = np.array([r["median_us"] for r in rows])
    low = med - np.array([r["p10_us"] for r in rows])
    high = np.array([r["p90_us"] for r in rows]) - med
    colors = [{WITHOUT: "tab:blue", WITH: "tab:orange", BALL: "tab:red"}[r["limits"]]
              for r in rows]  # fmt: skip
    ax.bar(x, med, color=colors, yerr=[low, high], capsize=4, label="median, p10-p90")
    ax.plot(x, [r["p99_us"] for r in rows], "k_", markersize=18, mew=2, label="p99")
    ax.plot(x, [r["interleaved"]["median_us"] for r in rows], "kv", markersize=6,
            label="median, interleaved")  # fmt: skip
    period = 1e6 * results["settings"]["dt"]
    ax.axhline(period, color="gray", ls="--", lw=1)
    ax.text(len(rows) - 0.5, period * 1.05, f"the period at {1e6 / period:.0f} Hz", ha="right",
            va="bottom", fontsize=8, color="gray")  # fmt: skip
    for i, r in enumerate(rows):
        top = max(r["p90_us"], r["p99_us"]) * 1.12  # above the p99 mark, not on it
        ax.text(i, top, _rate(r["rate_hz_median"]), ha="center", va="bottom", fontsize=8)
    ax.set_xticks(x, [f"{r['cell']}\n{r['limits']}" for r in rows], fontsize=8)
    ax.set_yscale("log")
    ax.set_ylim(min(r["p10_us"] for r in rows) * 0.5, period * 2.5)
    ax.set_ylabel("one tick [us]")
    ax.legend(fontsize=8, loc="upper left")
    title = ("CellController.step on one core, tight (bars) and interleaved; the loop rate at "
             "the tight median above each bar")
    if results["not_run"]:
        title += "\nnot run: " + "; ".join(f"{n['cell']} with {n['limits']} ({_reason(n)})"
                                           for n in results["not_run"])  # fmt: skip
    ax.set_title(title, fontsize=9)
    mark_quick(fig, results)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


# -- the soak (issue 37): the closed chains over long runs, fresh seeds -------------------

SOAK = {"gsfc_dual": (20, 5000), "yeh_tripod": (10, 3000)}
"""Cell: (fresh seeds, ticks per seed) of ``--soak``; gsfc_dual with damping and without."""
QUICK_SOAK = {"gsfc_dual": (2, 300), "yeh_tripod": (2, 300)}
SOAK_SPEED = {"gsfc_dual": 2.0, "yeh_tripod": 1.0}
"""The soak's commands are the timing's (:data:`SPEEDS`) times this: joint bounds active on
about a third of gsfc_dual's ticks; the tripod's body driven by its own (0.03 m/s, 0.1 rad/s
per axis) to where its feet cannot follow on some hundreds of ticks a seed, and near singular
poses on more (three times faster, it spends most of a run there: damped on 45-75 % of the
ticks, its body turned off the commanded axis by up to 0.05 rad in 0.5 s)."""


def check_tick(
    ctl: CellController, before: np.ndarray, step: Any, report: dict[str, Any]
) -> None:
    """Count what tick ``step`` (from ``before``) broke, into ``report`` (:func:`soak`).

    The rates applied (the resolver's and the closure's correction) inside the tick's box;
    the joints' change over the tick, ``(q_new - q_old) / dt``, inside it too (to the
    integration's rounding, 1e-9 relative) and q_new inside the position limits; the closed
    chains within their bound at every tick reported held; a tick after a lost one moves
    only when it closes the chain.
    """
    cell, r, dt = ctl.cell, step.resolution, ctl.dt
    box = r.problem.box
    model = cell.model
    if not (np.isfinite(step.q).all() and np.isfinite(r.applied).all()):
        report["nan"] += 1
        return
    report["box"] += int(np.any(r.applied < box.lb) or np.any(r.applied > box.ub))
    moved = pin.difference(model, cell.to_pinocchio(before), cell.to_pinocchio(step.q)) / dt
    slack = 1e-9 * (1.0 + np.abs(box.lb) + np.abs(box.ub))
    report["rate"] += int(np.any(moved < box.lb - slack) or np.any(moved > box.ub + slack))
    report["rate_ratio"] = max(report["rate_ratio"],
                               float(np.max(np.abs(moved) / cell.velocity_limit)))  # fmt: skip
    dof = cell.dof_positions(step.q)
    report["position"] += int(np.any(dof < cell.dof_lower) or np.any(dof > cell.dof_upper))
    report["active"] += int(np.any((r.qdot <= box.lb + 1e-9) | (r.qdot >= box.ub - 1e-9)))
    report["statuses"][r.status] += 1
    position, rotation = ctl.chain_error
    bound = ctl.closure or ClosureBound()
    level = max(position / bound.position, rotation / bound.rotation)
    closing = report.pop("_closing", None)  # the last tick moved while lost: from this level
    if closing is not None and level >= closing:
        report["opened_while_lost"] += 1
    if r.status in ("grip_lost", "contact_lost"):
        report["lost"] += 1
        report["episodes"] += int(report["_last"] not in ("grip_lost", "contact_lost"))
        if r.applied.any():  # moved while lost: it must close the chain
            report["_closing"] = level
        elif report["_last"] in ("grip_lost", "contact_lost") and not np.array_equal(
            before, step.q
        ):  # fmt: skip
            report["opened_while_lost"] += 1
    else:
        report["held_position"] = max(report["held_position"], position)
        report["held_rotation"] = max(report["held_rotation"], rotation)
    report["_last"] = r.status


def soak(name: str, seed: int, ticks: int, damping: bool, dt: float = DT) -> dict[str, Any]:
    """Random commands on cell ``name`` (the object's twist on gsfc_dual, the body's on
    yeh_tripod, each held :data:`HOLD` ticks), every tick checked (:func:`check_tick`), at
    period ``dt`` [s]; the counts.

    On the tripod also: ticks where a body command could not be followed in full far from
    singularities (the top level's condition number within the damping threshold) that were
    not ``scaled`` along the command (veer above 1e-6 rad), and the body's largest turn off
    the commanded axis over a command's 0.5 s.
    """
    cell = rrc_pin.load(name)
    ctl = CellController(cell, dt, damping=Damping() if damping else None)
    command, speed = SPEEDS[name]
    speed = speed * SOAK_SPEED[name]
    rng = np.random.default_rng(seed)
    report: dict[str, Any] = {
        "cell": name, "seed": seed, "ticks": ticks, "damping": damping, "nan": 0, "box": 0,
        "rate": 0, "rate_ratio": 0.0, "position": 0, "active": 0, "lost": 0, "episodes": 0,
        "opened_while_lost": 0, "held_position": 0.0, "held_rotation": 0.0, "not_scaled": 0,
        "far_limited": 0, "turn": 0.0, "statuses": collections.Counter(), "_last": "",
    }  # fmt: skip
    threshold = Damping().threshold
    start = cell.fk(ctl.q, "body")[:3, :3] if cell.body else None
    twist = np.zeros(6)
    for k in range(ticks):
        if k % HOLD == 0:
            if start is not None and k:
                report["turn"] = max(report["turn"], _turn(cell, ctl.q, start, twist))
                start = cell.fk(ctl.q, "body")[:3, :3]
            twist = rng.normal(size=6) * speed
        before = ctl.q
        step = ctl.step({command: twist})
        check_tick(ctl, before, step, report)
        r = step.resolution
        if cell.body and r.scale < 1.0 - 1e-9 and r.status not in ("grip_lost", "contact_lost"):
            A = r.problem.stacked[0][0]
            null = Factorization(r.problem.equalities[0]).null_basis()
            sigma = np.linalg.svd(A @ null.T, compute_uv=False)
            if sigma[0] <= threshold * sigma[-1]:  # far from singularities
                report["far_limited"] += 1
                report["not_scaled"] += int(r.status != "scaled" or r.veer > 1e-6)
    report["statuses"] = dict(report["statuses"])
    for key in [k for k in report if k.startswith("_")]:
        del report[key]
    return report


def _turn(cell: rrc_pin.Cell, q: np.ndarray, start: np.ndarray, twist: np.ndarray) -> float:
    """The body's rotation [rad] since ``start`` (3, 3) off the commanded angular velocity."""
    theta = pin.log3(cell.fk(q, "body")[:3, :3] @ start.T)
    w = twist[3:]
    if np.linalg.norm(w) > 0.0:
        w = w / np.linalg.norm(w)
        theta = theta - w * (theta @ w)
    return float(np.linalg.norm(theta))


def run_soak(quick: bool) -> dict[str, Any]:
    """Every cell's soak (:data:`SOAK`) over fresh seeds, damping on and off on gsfc_dual."""
    rows = []
    for name, (seeds, ticks) in (QUICK_SOAK if quick else SOAK).items():
        for _ in range(seeds):
            seed = int(np.random.SeedSequence().entropy % 2**63)
            for damping in (True, False) if name == "gsfc_dual" else (True,):
                rows.append(soak(name, seed, ticks, damping))
                row = rows[-1]
                progress(f"soak {name} seed {seed} damping {damping}: lost {row['lost']} "
                         f"({row['episodes']} times), held within {row['held_position']:.2e} m "
                         f"{row['held_rotation']:.2e} rad, rates {row['rate_ratio']:.4f} of "
                         f"the limits, box {row['box']} rate {row['rate']} nan {row['nan']}, "
                         f"far and limited {row['far_limited']} (not scaled "
                         f"{row['not_scaled']}), turn {row['turn']:.2e} rad")  # fmt: skip
    return {"soak": rows}


def main(argv: list[str] | None = None) -> int:
    parser = make_parser(__doc__, "cells", f"{QUICK_TICKS} ticks per cell")
    parser.add_argument("--soak", action="store_true",
                        help="the closed chains' soak instead of the timing (never recorded)")
    args = arguments(parser, argv)
    if args.soak:
        if args.record:
            parser.error("--soak is not recorded")
        results = measure("cells_soak", args.quick, lambda: run_soak(args.quick))
        if args.out is not None:
            args.out.mkdir(parents=True, exist_ok=True)
            (args.out / "cells_soak.json").write_text(json.dumps(results, indent=2) + "\n")
        return 0
    results = measure("cells", args.quick, lambda: run(args.quick))
    write(args, "cells", results, lambda path: plot(results, path))
    print(docs_section(results))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
