"""Capability maps: samples per second per core, the 1 -> 2 worker speed-up, a 10^9-sample
projection, query latency and an IK audit of 1,000 voxels.

Run from a checkout: ``python benchmarks/bench_maps.py --out DIR`` (``--record`` writes
``benchmarks/results/maps.json`` and ``.png``, ``--quick`` a smoke run of a few seconds);
``rrc-pin bench --only maps`` runs it. Needs the maps extra (dask[distributed], zarr).

- **Per-core rate**: the work of a map's tasks on one thread (``rrc_pin.solvers.maps.work.
  compute_blocks``: draw the blocks' samples, evaluate them, accumulate them into voxels),
  on 2^18 samples (8 blocks of 2^15) per case, the cases interleaved in a shuffled order
  for :data:`ROUNDS` rounds; the median round is recorded with the range. Timed as the
  thread's CPU time (``time.thread_time``: samples per CPU-second, what a core does when the
  process has it; the machine is shared, and wall time counts the time other processes hold
  the core too); the wall-clock rate is recorded beside it (``wall_per_s``).
  Cases: barker6 by its batch closed form and by the compiled chain, panda by the chain;
  each with the reach statistics only (count, 54 direction bins, joint-limit margin,
  witness; barker6 also its conditions 32, 33, S5) and with the dexterity statistics too
  (the task Jacobian's singular values per sample: manipulability and sigma_min).
- **The reference** the issue measured: Pinocchio in a Python loop (``forwardKinematics`` +
  ``updateFramePlacement`` of the tool; with dexterity also ``computeFrameJacobian`` and
  ``numpy.linalg.svd``), same arms, same samples, interleaved with the rest.
- **1 -> 2 workers**: the wall time of ``maps.capability(panda, 2^20, 5 cm)`` with 1 and
  with 2 worker threads of the in-process cluster (the driver's loop: tasks, merges; no
  cluster start-up), interleaved for the rounds; the machine has 2 cores shared with others.
  Beside it, the control: ``numpy.sin`` over 2^21 angles, twice on one thread against once
  on each of two threads, what the machine gives two threads of plain numerics.
- **Projection**: a 10^9-sample map on 64 cores at the measured per-core rate, assuming the
  tasks scale linearly (each task is independent; the driver's merge of a sparse result
  costs about 1 % of the task's compute at 5 cm, measured in the scaling run).
- **Query latency**: ``map.at`` for one point (median of 2,000 calls) and for 10^5 points.
- **Audit**: 1,000 seeded random reached voxels of the panda map (7 joints) confirmed by
  resolved-rate IK through ``rrc_pin.Resolver`` (10 with ``--quick``).
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import random  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import load_average  # noqa: E402
from script import arguments, make_parser, measure, pyplot, write  # noqa: E402
from timing import progress  # noqa: E402

import rrc_pin  # noqa: E402
from rrc_pin import maps  # noqa: E402
from rrc_pin.maps.kinematics import arm_kinematics, chain_of  # noqa: E402
from rrc_pin.maps.voxels import chain_grid, quanta  # noqa: E402
from rrc_pin.robot import frame_id  # noqa: E402
from rrc_pin.solvers.maps.batch import Fields  # noqa: E402
from rrc_pin.solvers.maps.kinematics import ChainKinematics, task_rows  # noqa: E402
from rrc_pin.solvers.maps.sampling import Plan, block_samples  # noqa: E402
from rrc_pin.solvers.maps.work import Job, compute_blocks  # noqa: E402

ROUNDS = 5
"""Interleaved rounds of the per-core cases and of the scaling runs (full mode)."""
SAMPLES, QUICK_SAMPLES = 2**18, 2**15
"""Samples per per-core case and round."""
LOOP, QUICK_LOOP = 20_000, 2_000
"""Samples of the Pinocchio loop (FK only); a fifth of that with the SVD."""
SCALE, QUICK_SCALE = 2**20, 2**16
"""Samples of the 1 -> 2 worker runs."""
AUDIT, QUICK_AUDIT = 1000, 10
"""Voxels of the IK audit."""
PROJECT = {"samples": 10**9, "cores": 64}
VOXEL = 0.05
CASES = (
    ("barker6", "closed_form", False),
    ("barker6", "closed_form", True),
    ("barker6", "chain", False),
    ("barker6", "chain", True),
    ("panda", "chain", False),
    ("panda", "chain", True),
)
"""(arm, evaluation, dexterity) of the per-core cases."""


def case_label(arm: str, method: str, dexterity: bool) -> str:
    what = "reach + dexterity" if dexterity else "reach"
    how = "batch closed form" if method == "closed_form" else "compiled chain"
    return f"{arm} / {how} / {what}"


def make_job(arm: str, method: str, dexterity: bool, samples: int) -> Job:
    robot = rrc_pin.load(arm)
    kin = arm_kinematics(robot)
    if method == "chain" and kin.method != "chain":
        chain, _ = chain_of(robot)
        kin = ChainKinematics(chain, task_rows(chain.n))
    grid = chain_grid(kin.chain, VOXEL)
    plan = Plan(samples)
    return Job(kin, grid.arrays, plan, 1, dexterity, quanta(kin.chain, kin.rows),
               Fields(kin.conditions))  # fmt: skip


def pinocchio_loop(arm: str, n: int, dexterity: bool) -> float:
    """Samples per second of Pinocchio in a Python loop (the issue's reference)."""
    robot = rrc_pin.load(arm)
    chain, _ = chain_of(robot)
    Q = block_samples(chain, 1, Plan(n, 2**15), 0) if n <= 2**15 else np.concatenate(
        [block_samples(chain, 1, Plan(n, 2**15), b) for b in range(Plan(n, 2**15).blocks)]
    )
    model, data = robot.model, robot.model.createData()
    fid = frame_id(model, robot.tool_frame)
    ref = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    start = time.thread_time()
    for q in Q:
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacement(model, data, fid)
        if dexterity:
            J = pin.computeFrameJacobian(model, data, q, fid, ref)
            np.linalg.svd(J, compute_uv=False)
    return n / (time.thread_time() - start)


def per_core(quick: bool) -> dict[str, Any]:
    """The per-core rates of every case and of the Pinocchio loops, interleaved by round."""
    samples = QUICK_SAMPLES if quick else SAMPLES
    loop = QUICK_LOOP if quick else LOOP
    rounds = 1 if quick else ROUNDS
    jobs = {c: make_job(*c, samples) for c in CASES}
    for job in jobs.values():  # compile, or load the compiled kernels, untimed
        compute_blocks(job, [0])
    refs = [(arm, dex) for arm in ("barker6", "panda") for dex in (False, True)]
    rates: dict[Any, list[float]] = {c: [] for c in (*CASES, *refs)}
    walls: dict[Any, list[float]] = {c: [] for c in CASES}
    loads = []
    order = list(rates)
    rng = random.Random(7)
    for r in range(rounds):
        rng.shuffle(order)
        loads.append(load_average()[0])
        for c in order:
            if len(c) == 3:
                job = jobs[c]
                cpu = time.thread_time()
                result = compute_blocks(job, list(range(job.plan.blocks)))
                rates[c].append(samples / (time.thread_time() - cpu))
                walls[c].append(samples / result.seconds)
            else:
                arm, dex = c
                rates[c].append(pinocchio_loop(arm, loop // 5 if dex else loop, dex))
        progress(f"maps: per-core round {r + 1}/{rounds} done")
    out = []
    for arm, method, dex in CASES:
        ref = rates[(arm, dex)]
        row = {
            "arm": arm,
            "method": method,
            "dexterity": dex,
            "label": case_label(arm, method, dex),
            "samples": samples,
            "per_core_per_s": statistics.median(rates[(arm, method, dex)]),
            "per_core_min": min(rates[(arm, method, dex)]),
            "per_core_max": max(rates[(arm, method, dex)]),
            "rounds": rates[(arm, method, dex)],
            "wall_per_s": statistics.median(walls[(arm, method, dex)]),
            "pinocchio_loop_per_s": statistics.median(ref),
        }
        row["vs_pinocchio_loop"] = row["per_core_per_s"] / row["pinocchio_loop_per_s"]
        out.append(row)
    loops = [
        {"arm": arm, "dexterity": dex, "per_s": statistics.median(rates[(arm, dex)]),
         "rounds": rates[(arm, dex)], "samples": loop // 5 if dex else loop}
        for arm, dex in refs
    ]  # fmt: skip
    return {"cases": out, "pinocchio_loop": loops, "round_loads": loads}


def control_speedup(rounds: int) -> list[float]:
    """What the machine gives two threads of plain numerics: ``numpy.sin`` over 2^21
    angles (it releases the GIL) on one thread twice, then on two threads at once."""
    import threading

    x = np.random.default_rng(0).uniform(-3.0, 3.0, 2**21)

    def work() -> None:
        for _ in range(4):
            np.sin(x)

    out = []
    for _ in range(rounds):
        t = time.perf_counter()
        work()
        work()
        one = time.perf_counter() - t
        threads = [threading.Thread(target=work) for _ in range(2)]
        t = time.perf_counter()
        for th in threads:
            th.start()
        for th in threads:
            th.join()
        out.append(one / (time.perf_counter() - t))
    return out


def scaling(quick: bool) -> tuple[dict[str, Any], maps.CapabilityMap]:
    """Wall time of one map with 1 and 2 worker threads, interleaved."""
    samples = QUICK_SCALE if quick else SCALE
    rounds = 1 if quick else ROUNDS
    control = control_speedup(rounds)
    walls: dict[int, list[float]] = {1: [], 2: []}
    computes: dict[int, list[float]] = {1: [], 2: []}
    last = None
    for r in range(rounds):
        for workers in (1, 2) if r % 2 == 0 else (2, 1):
            m = maps.capability("panda", samples, VOXEL, workers=workers, seed=r,
                                dexterity=False, progress=False)  # fmt: skip
            walls[workers].append(m.meta["run"]["wall_seconds"])
            computes[workers].append(m.meta["run"]["compute_seconds"])
            last = m
        progress(f"maps: scaling round {r + 1}/{rounds} done")
    one, two = statistics.median(walls[1]), statistics.median(walls[2])
    speedups = [a / b for a, b in zip(walls[1], walls[2], strict=True)]
    assert last is not None
    return {
        "arm": "panda",
        "samples": samples,
        "voxel": VOXEL,
        "dexterity": False,
        "one_worker_s": one,
        "two_workers_s": two,
        "speedup": statistics.median(speedups),
        "speedup_min": min(speedups),
        "speedup_max": max(speedups),
        "control_speedup": statistics.median(control),
        "control_rounds": control,
        "rounds": {"1": walls[1], "2": walls[2]},
        "compute_s": {"1": computes[1], "2": computes[2]},
        "memory": last.meta["memory"],
        "tasks": last.meta["run"]["tasks"],
    }, last


def queries(m: maps.CapabilityMap, quick: bool) -> dict[str, Any]:
    rng = np.random.default_rng(3)
    point = m.grid.centres(np.flatnonzero(m.reached)[:1])[0]
    m.at(point)
    calls = 200 if quick else 2000
    times = []
    for _ in range(calls):
        t = time.perf_counter()
        m.at(point)
        times.append(time.perf_counter() - t)
    P = rng.uniform(-1.0, 1.0, size=(100_000, 3))
    batch = []
    for _ in range(3 if quick else 7):
        t = time.perf_counter()
        m.at(P)
        batch.append(time.perf_counter() - t)
    return {
        "one_point_us": 1e6 * statistics.median(times),
        "one_point_p99_us": 1e6 * float(np.percentile(times, 99)),
        "batch_points": len(P),
        "batch_ms": 1e3 * statistics.median(batch),
        "batch_us_per_point": 1e6 * statistics.median(batch) / len(P),
    }


def store_size(m: maps.CapabilityMap) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        path = maps.save_map(m, Path(tmp) / "map.zarr")
        size = sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
    return {"zarr_bytes": size, "grid_voxels": m.grid.size,
            "voxels_reached": int(np.count_nonzero(m.reached))}  # fmt: skip


def run(quick: bool) -> dict[str, Any]:
    rates = per_core(quick)
    scale, m = scaling(quick)
    progress("maps: queries, store, audit ...")
    q = queries(m, quick)
    projection = {**PROJECT, "assumes": "linear scaling over the cores at the per-core rate"}
    for row in rates["cases"]:
        key = f"{row['arm']}/{row['method']}/{'dexterity' if row['dexterity'] else 'reach'}"
        projection[key] = PROJECT["samples"] / (PROJECT["cores"] * row["per_core_per_s"])
    audit_map = maps.capability("panda", 2**16 if quick else 2**20, VOXEL, seed=5,
                                dexterity=False, progress=False)  # fmt: skip
    n = QUICK_AUDIT if quick else AUDIT
    report = maps.audit(audit_map, rrc_pin.load("panda"), n, seed=11)
    audit = {
        "arm": "panda", "joints": 7, "map_samples": int(audit_map.meta["samples"]),
        "voxels": int(report.keys.size), "confirmed": report.confirmed,
        "failures": report.failures.tolist(), "seconds": report.seconds,
        "steps": report.steps_total, "starts_max": int(report.starts.max()),
    }  # fmt: skip
    return {
        "sizes": {
            "per_core_samples": QUICK_SAMPLES if quick else SAMPLES,
            "rounds": 1 if quick else ROUNDS,
            "voxel": VOXEL,
        },
        **rates,
        "scaling": scale,
        "projection": projection,
        "query": q,
        "store": store_size(m),
        "audit": audit,
    }


# -- rendering ----------------------------------------------------------------------------


def _rate(x: float) -> str:
    return f"{x / 1e6:.2f} M" if x >= 1e6 else f"{x / 1e3:.0f} k"


def readme_table(results: dict[str, Any]) -> str:
    rows = [
        "| arm | evaluation | statistics | samples/s/core | vs Pinocchio loop | "
        "10^9 samples on 64 cores |",
        "| --- | --- | --- | ---: | ---: | ---: |",
    ]
    for c in results["cases"]:
        key = f"{c['arm']}/{c['method']}/{'dexterity' if c['dexterity'] else 'reach'}"
        how = "batch closed form" if c["method"] == "closed_form" else "compiled chain"
        what = "reach + dexterity" if c["dexterity"] else "reach"
        rows.append(
            f"| {c['arm']} | {how} | {what} | {_rate(c['per_core_per_s'])} "
            f"| {c['vs_pinocchio_loop']:.1f}x | {results['projection'][key]:.0f} s |"
        )
    s, q, a = results["scaling"], results["query"], results["audit"]
    load = results["load_average"]
    rows += [
        "",
        "Reach: count, orientation coverage (54 direction bins), joint-limit margin, witness "
        "(barker6 also its conditions 32, 33, S5); dexterity adds the task Jacobian's singular "
        "values per sample (manipulability, sigma_min). Per core: samples per CPU-second of one "
        f"thread, median of {results['sizes']['rounds']} interleaved rounds (wall-clock rates "
        "in docs/benchmarks.md). 1 -> 2 workers "
        f"(panda, {s['samples']:,} samples, reach): {s['one_worker_s']:.2f} s -> "
        f"{s['two_workers_s']:.2f} s, {s['speedup']:.2f}x (rounds {s['speedup_min']:.2f}-"
        f"{s['speedup_max']:.2f}x; numpy's sin on two threads at the same time: "
        f"{s.get('control_speedup', float('nan')):.2f}x). Query `map.at`: "
        f"{q['one_point_us']:.0f} us a point, "
        f"{q['batch_us_per_point']:.2f} us a point in batches of {q['batch_points']:,}. IK "
        f"audit (panda, 7 joints): {100 * a['confirmed']:.1f} % of {a['voxels']} voxels "
        f"confirmed ({a['seconds']:.0f} s). Load average {load['start'][0]:.2f} at the start, "
        f"{load['end'][0]:.2f} at the end (2 cores, shared).",
    ]
    return "\n".join(rows)


def docs_section(results: dict[str, Any]) -> str:
    lines = [readme_table(results), ""]
    lines += ["Every round (samples per CPU-second of the thread), and the wall-clock rate:", "",
              "| case | rounds | min | max | wall clock (median) |",
              "| --- | --- | ---: | ---: | ---: |"]  # fmt: skip
    for c in results["cases"]:
        lines.append(
            f"| {c['label']} | {', '.join(_rate(x) for x in c['rounds'])} | "
            f"{_rate(c['per_core_min'])} | {_rate(c['per_core_max'])} | "
            f"{_rate(c['wall_per_s'])} |"
        )
    for ref in results["pinocchio_loop"]:
        lines.append(
            f"| Pinocchio loop, {ref['arm']}{' + J + SVD' if ref['dexterity'] else ''} | "
            f"{', '.join(_rate(x) for x in ref['rounds'])} | {_rate(min(ref['rounds']))} | "
            f"{_rate(max(ref['rounds']))} | - |"
        )
    s, st = results["scaling"], results["store"]
    lines += [
        "",
        f"Load average (1 min) at the start of each round: "
        f"{', '.join(f'{x:.2f}' for x in results['round_loads'])}.",
        "",
        f"1 -> 2 workers, wall times per round [s]: 1 worker "
        f"{', '.join(f'{x:.2f}' for x in s['rounds']['1'])}; 2 workers "
        f"{', '.join(f'{x:.2f}' for x in s['rounds']['2'])} ({s['tasks']} tasks). Memory: "
        f"{s['memory']['worker_bytes'] / 1e6:.1f} MB per worker thread (a task's buffers and "
        f"voxel table at their largest), {s['memory']['driver_bytes'] / 1e6:.1f} MB on the "
        f"driver (the grid's dense statistics). The Zarr store of that map: "
        f"{st['zarr_bytes'] / 1e3:.0f} kB for {st['voxels_reached']:,} voxels reached of "
        f"{st['grid_voxels']:,}.",
    ]
    return "\n".join(lines)


def plot(results: dict[str, Any], path: Path) -> bool:
    plt = pyplot()
    if plt is None:
        return False
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.2), width_ratios=[2.2, 1])
    cases = results["cases"]
    y = np.arange(len(cases))
    left.barh(y + 0.2, [c["per_core_per_s"] for c in cases], 0.4, label="rrc_pin.maps")
    left.barh(y - 0.2, [c["pinocchio_loop_per_s"] for c in cases], 0.4,
              label="Pinocchio in a Python loop: FK (reach), FK + J + SVD (dexterity)")  # fmt: skip
    for i, c in enumerate(cases):
        left.text(c["per_core_per_s"] * 1.1, i + 0.2, f"{c['vs_pinocchio_loop']:.1f}x",
                  va="center", fontsize=8)  # fmt: skip
    left.set_yticks(y, [c["label"] for c in cases], fontsize=8)
    left.set_xscale("log")
    left.set_xlabel("samples per CPU-second of one thread (median of the rounds)")
    left.axvline(1e6, color="grey", ls=":", lw=1)
    left.text(1e6, len(cases) - 0.6, " 10^6 / s", color="grey", fontsize=8, va="top")
    left.set_xlim(right=4e6)
    left.legend(loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=2, fontsize=8)
    left.set_title("Per-core rate of a map's work (draw, evaluate, accumulate)")
    s = results["scaling"]
    right.bar(["1 worker", "2 workers"], [s["one_worker_s"], s["two_workers_s"]])
    right.set_ylabel("wall time [s] (median of the rounds)")
    right.set_title(
        f"1 -> 2 workers, panda, {s['samples']:,} samples:\n{s['speedup']:.2f}x (numpy's sin "
        f"on 2 threads: {s.get('control_speedup', float('nan')):.2f}x)", fontsize=10
    )
    load = results["load_average"]
    fig.suptitle(f"Capability maps, 2 shared cores, load average {load['start'][0]:.2f} -> "
                 f"{load['end'][0]:.2f}")  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def main(argv: list[str] | None = None) -> int:
    args = arguments(make_parser(__doc__, "maps", "smoke run of a few seconds"), argv)
    results = measure("maps", args.quick, lambda: run(args.quick), "numba", "dask",
                      "distributed", "zarr")  # fmt: skip
    write(args, "maps", results, lambda path: plot(results, path))
    print(readme_table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
