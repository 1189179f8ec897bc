"""Closed-form fast paths against Pinocchio + numpy: per-call time and batch throughput.

Run from a checkout: ``python benchmarks/bench_closed_form.py --out DIR`` (``--record``
writes ``benchmarks/results/`` instead, ``--quick`` a short smoke run; with neither ``--out``
nor ``--record`` nothing is written). ``rrc-pin bench`` runs it.

For every paper arm with a closed form (barker6, rrc_k1607, kr5_3r):

- scalar: median per-call time of ``cf.joint_rates(q, xdot)`` against
  ``pin.computeFrameJacobian(..., LOCAL_WORLD_ALIGNED)`` followed by ``numpy.linalg.solve``
  (square arms; the first three rows for kr5_3r) or ``numpy.linalg.lstsq`` (minimum norm, for
  the redundant rrc_k1607; pinv is slower still and is recorded too), and of
  ``cf.jacobian(q)`` against ``computeFrameJacobian`` alone, all timed with ``timeit`` at the
  same configurations, interleaved (the compiled kernels are called once before, so that no
  sample holds their compilation);
- batch: ``cf.joint_rates_batch`` on N = 10^5 configurations against a Python loop of the
  same Pinocchio + numpy calls, timed on a subset and scaled to N.

Every closed-form answer is also checked against the Pinocchio one at the timed
configurations (largest relative difference recorded), outside Barker's singular bands, where
the closed form damps on purpose (:func:`exact_rows`; the rows inside are counted), and with
``exact=True`` everywhere. Results: ``closed_form.json`` and ``closed_form.png`` (when
matplotlib is installed); :func:`markdown_table` renders them for the README and
docs/benchmarks.md (``update_readme.py``) and is printed at the end.
"""

from __future__ import annotations

import os
import statistics
import sys
import timeit
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from machine import machine_info, source_state
from script import arguments, make_parser, mark_quick, pyplot, write

import rrc_pin
from rrc_pin.robot import frame_id

ARMS = ("barker6", "rrc_k1607", "kr5_3r")
SEED = 20261122
BATCH_RUNS = 11
"""Interleaved runs of the batch and of the loop; the medians are recorded."""


def per_call_us(fn: Callable[[], object], number: int, repeat: int) -> list[float]:
    """``repeat`` timings of ``number`` calls of ``fn``, each as microseconds per call."""
    return [t / number * 1e6 for t in timeit.repeat(fn, number=number, repeat=repeat)]


def spread(prefix: str, samples_us: list[float]) -> dict[str, float]:
    """``<prefix>_p10_us``, ``_p90_us``, ``_p99_us`` of timing samples [us] (each sample of
    the scalar timings is the mean of ``number`` calls; of the batch, one whole run)."""
    p10, p90, p99 = np.percentile(samples_us, [10, 90, 99])
    return {
        f"{prefix}_p10_us": float(p10),
        f"{prefix}_p90_us": float(p90),
        f"{prefix}_p99_us": float(p99),
    }


def reference_solver(name: str, task_dim: int, nq: int) -> tuple[str, Callable[..., Any]]:
    """The numpy solve that the Pinocchio Jacobian is paired with, and its label."""
    if task_dim == nq:
        return "numpy.linalg.solve", np.linalg.solve
    return "numpy.linalg.lstsq", lambda J, x: np.linalg.lstsq(J, x, rcond=None)[0]


def exact_rows(cf: Any, Q: np.ndarray) -> np.ndarray:
    """Mask (N,) of the configurations where the closed form is the exact inverse."""
    if not hasattr(cf, "singularity_batch"):
        return np.ones(len(Q), dtype=bool)
    s = cf.singularity_batch(Q)
    return ~(s.arm_singular | s.wrist_singular)


def bench_arm(
    name: str, *, n_scalar: int, number: int, n_batch: int, n_loop: int
) -> dict[str, Any]:
    """Scalar and batch timings of one arm (see the module docstring)."""
    arm = rrc_pin.load(name)
    cf = arm.closed_form
    model, data = arm.model, arm.data
    fid = frame_id(model, arm.tool_frame)
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    m, nq = cf.task_dim, cf.nq
    label, solve = reference_solver(name, m, nq)
    rng = np.random.default_rng(SEED)

    def pin_rates(q: np.ndarray, x: np.ndarray) -> np.ndarray:
        return solve(pin.computeFrameJacobian(model, data, q, fid, lwa)[:m], x)

    def pin_pinv(q: np.ndarray, x: np.ndarray) -> np.ndarray:
        return np.linalg.pinv(pin.computeFrameJacobian(model, data, q, fid, lwa)[:m]) @ x

    # Scalar: the same configurations for both, timings interleaved config by config.
    Qs = np.array([arm.random_q(rng) for _ in range(n_scalar)])
    Xs = rng.standard_normal((n_scalar, m))
    cf_us: list[float] = []
    pin_us: list[float] = []
    pinv_us: list[float] = []
    jac_us: list[float] = []
    pin_jac_us: list[float] = []
    worst = 0.0
    cf.jacobian(Qs[0])  # compiled (or loaded from numba's cache) before any timing
    for q, x, exact in zip(Qs, Xs, exact_rows(cf, Qs), strict=True):
        ours, ref = cf.joint_rates(q, x), pin_rates(q, x)
        if exact:
            worst = max(worst, float(np.linalg.norm(ours - ref) / np.linalg.norm(ref)))
        cf_us += per_call_us(lambda q=q, x=x: cf.joint_rates(q, x), number, 3)
        pin_us += per_call_us(lambda q=q, x=x: pin_rates(q, x), number, 3)
        if m < nq:
            pinv_us += per_call_us(lambda q=q, x=x: pin_pinv(q, x), number, 1)
        jac_us += per_call_us(lambda q=q: cf.jacobian(q), number, 3)
        pin_jac_us += per_call_us(
            lambda q=q: pin.computeFrameJacobian(model, data, q, fid, lwa), number, 3
        )
    scalar = {
        "closed_form_us": statistics.median(cf_us),
        "pinocchio_us": statistics.median(pin_us),
        "speedup": statistics.median(pin_us) / statistics.median(cf_us),
        "pinocchio_solver": label,
        "max_relative_difference": worst,
        "samples": len(cf_us),
        "calls_per_sample": number,
        "jacobian_us": statistics.median(jac_us),
        "pinocchio_jacobian_us": statistics.median(pin_jac_us),
        "jacobian_speedup": statistics.median(pin_jac_us) / statistics.median(jac_us),
    }
    if pinv_us:
        scalar["pinocchio_pinv_us"] = statistics.median(pinv_us)
    scalar.update(spread("closed_form", cf_us))
    scalar.update(spread("pinocchio", pin_us))

    # Batch: N configurations at once against a Python loop over a subset, scaled.
    Q = np.array([arm.random_q(rng) for _ in range(n_batch)])
    X = rng.standard_normal((n_batch, m))
    cf.joint_rates_batch(Q[:1000], X[:1000])  # warm-up
    Ql, Xl = Q[:n_loop], X[:n_loop]

    def loop() -> np.ndarray:
        out = np.empty((n_loop, nq))
        for i in range(n_loop):
            out[i] = pin_rates(Ql[i], Xl[i])
        return out

    # Interleaved, so that both see the same machine load.
    batch_runs, loop_runs = [], []
    for _ in range(BATCH_RUNS):
        batch_runs += timeit.repeat(lambda: cf.joint_rates_batch(Q, X), number=1, repeat=1)
        loop_runs += timeit.repeat(loop, number=1, repeat=1)
    batch_s, loop_s = statistics.median(batch_runs), statistics.median(loop_runs)
    ours, ref = cf.joint_rates_batch(Ql, Xl), loop()
    keep = exact_rows(cf, Ql)
    err = np.linalg.norm(ours - ref, axis=1) / np.linalg.norm(ref, axis=1)
    batch_worst = float(np.max(err[keep]))
    try:  # Barker's default damps in its singular bands; exact=True is the plain inverse
        exact = cf.joint_rates_batch(Ql, Xl, exact=True)
    except TypeError:
        exact = ours
    exact_worst = float(np.max(np.linalg.norm(exact - ref, axis=1) / np.linalg.norm(ref, axis=1)))
    batch = {
        "n": n_batch,
        "closed_form_s": batch_s,
        "closed_form_per_s": n_batch / batch_s,
        "loop_n": n_loop,
        "loop_s_scaled": loop_s * n_batch / n_loop,
        "loop_per_s": n_loop / loop_s,
        "speedup": (loop_s * n_batch / n_loop) / batch_s,
        "max_relative_difference": batch_worst,
        "max_relative_difference_exact": exact_worst,
        "in_band": int(np.sum(~exact_rows(cf, Q))),
        **spread("closed_form_run", [t * 1e6 for t in batch_runs]),
        **spread("loop_run", [t * 1e6 for t in loop_runs]),
    }
    return {
        "arm": name,
        "closed_form": type(cf).__name__,
        "nq": nq,
        "task_dim": m,
        "scalar": scalar,
        "batch": batch,
    }


def markdown_table(results: dict[str, Any]) -> str:
    """The results as a Markdown table, one row per arm, then a note on how they were taken.

    Columns: the scalar closed form and Pinocchio + numpy per call [us] (medians) and their
    ratio; the closed-form Jacobian and Pinocchio's per call [us] (medians; in recordings
    that hold them); the batch closed form and the Python loop over Pinocchio + numpy
    [configurations per second] at N = 10^5, and their ratio. Every cell is a plain number.
    """
    n = results["sizes"]["n_batch"]
    jacobians = all("jacobian_us" in r["scalar"] for r in results["arms"])
    head = "| arm | scalar closed form [us] | Pinocchio + numpy [us] | speed-up | "
    if jacobians:
        head += "Jacobian: closed form [us] | Pinocchio [us] | "
    lines = [
        head + "batch [configs/s] | loop [configs/s] | speed-up |",
        "| --- |" + " ---: |" * (8 if jacobians else 6),
    ]
    solvers = []
    for r in results["arms"]:
        s, b = r["scalar"], r["batch"]
        jacobian = (
            f"{s['jacobian_us']:.2f} | {s['pinocchio_jacobian_us']:.2f} | " if jacobians else ""
        )
        lines.append(
            f"| {r['arm']} | {s['closed_form_us']:.1f} | {s['pinocchio_us']:.1f} | "
            f"{s['speedup']:.1f}x | {jacobian}{b['closed_form_per_s']:,.0f} | "
            f"{b['loop_per_s']:,.0f} | {b['speedup']:.0f}x |"
        )
        solvers.append(f"{s['pinocchio_solver']} ({r['arm']})")
    info = results["machine"]
    load = info.get("load_average")
    lines += [
        "",
        "Pinocchio + numpy: `computeFrameJacobian` (LOCAL_WORLD_ALIGNED) then "
        f"{', '.join(solvers)}. Scalar: median time per call of `joint_rates` (timeit)"
        + ("; Jacobian: `jacobian` against `computeFrameJacobian` alone. " if jacobians else ". ")
        + f"Batch: `joint_rates_batch` on N = {n:,} configurations against a Python loop of the "
        f"Pinocchio + numpy calls, interleaved in one run (medians of {BATCH_RUNS}). Measured on "
        f"{info['cpu']} ({info['cores']} cores), Python {info['python']}, numpy "
        f"{info['numpy']}, Pinocchio {info['pinocchio']}"
        + (
            f", load average {load[0]:.2f} at the start and {load[1]:.2f} at the end."
            if load
            else "."
        ),
    ]
    notes = results.get("notes", [])
    if notes:
        lines.append("")
        lines += [f"- {note}" for note in notes]
    return "\n".join(lines)


def readme_table(results: dict[str, Any]) -> str:
    """The README's table (the whole :func:`markdown_table`)."""
    return markdown_table(results)


def docs_section(results: dict[str, Any]) -> str:
    """The docs/benchmarks.md section: the table, and the agreement with Pinocchio + numpy."""
    rows = []
    for r in results["arms"]:
        b = r["batch"]
        exact = b.get("max_relative_difference_exact", b["max_relative_difference"])
        rows.append(
            f"| {r['arm']} | {r['scalar']['max_relative_difference']:.1g} | "
            f"{b['max_relative_difference']:.1g} | {exact:.1g} |"
        )
    return "\n".join(
        [
            markdown_table(results),
            "",
            "Agreement with Pinocchio + numpy (largest relative difference of the joint rates, "
            "at the timed configurations and at the loop's batch configurations). Barker's "
            "closed form damps by default in its singular bands (docs/api.md: about 3% of random "
            "configurations), where it differs from the exact inverse by design; with "
            "`exact=True` it is the exact inverse again.",
            "",
            "| arm | scalar | batch (default) | batch (exact=True) |",
            "| --- | ---: | ---: | ---: |",
            *rows,
        ]
    )


def plot(results: dict[str, Any], path: Path) -> bool:
    """Bar plot: per-call times (left) and batch throughput (right, log scale); False
    without matplotlib (nothing written)."""
    plt = pyplot()
    if plt is None:
        return False

    arms = [r["arm"] for r in results["arms"]]
    x = np.arange(len(arms))
    w = 0.38
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4.2))
    panels = (
        (
            left,
            "scalar",
            "closed_form_us",
            "pinocchio_us",
            "closed form",
            "Pinocchio J + numpy",
            "time per call [us] (median)",
            "joint_rates, one configuration",
        ),
        (
            right,
            "batch",
            "closed_form_per_s",
            "loop_per_s",
            "joint_rates_batch",
            "Python loop over Pinocchio",
            "configurations per second",
            "batch, N = 10^5",
        ),
    )
    for ax, part, ours, theirs, l1, l2, ylabel, title in panels:
        a = [r[part][ours] for r in results["arms"]]
        b = [r[part][theirs] for r in results["arms"]]
        ax.bar(x - w / 2, a, w, label=l1)
        ax.bar(x + w / 2, b, w, label=l2)
        top = max(max(a), max(b))
        for i, r in enumerate(results["arms"]):
            y = max(a[i], b[i]) * (1.6 if part == "batch" else 1.04)
            ax.text(x[i], y, f"{r[part]['speedup']:.1f}x", ha="center", va="bottom")
        if part == "batch":
            ax.set_yscale("log")
            # bars from a power of ten below the lowest, not from an autoscaled edge
            low = 10.0 ** np.floor(np.log10(min(min(a), min(b))))
            ax.set_ylim(bottom=low, top=top * 15)
        else:
            ax.set_ylim(top=top * 1.35)
        ax.set_xticks(x, arms)
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.legend(loc="upper left", fontsize=8)
    mark_quick(fig, results)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return True


def main(argv: list[str] | None = None) -> int:
    args = arguments(make_parser(__doc__, "closed_form"), argv)
    sizes = (
        {"n_scalar": 3, "number": 200, "n_batch": 5000, "n_loop": 200}
        if args.quick
        else {"n_scalar": 40, "number": 1000, "n_batch": 100_000, "n_loop": 2000}
    )
    start_load = os.getloadavg()[0]
    results: dict[str, Any] = {
        "benchmark": "closed_form",
        "schema": 2,
        "machine": machine_info(),
        "source": source_state(),
        "sizes": sizes,
        "quick": bool(args.quick),
        "arms": [],
        "notes": [],
    }
    for name in ARMS:
        try:
            cf = rrc_pin.load(name).closed_form
        except ImportError as exc:
            cf, why = None, f"{type(exc).__name__}: {exc}"
        else:
            why = "no closed form in the catalogue"
        if cf is None:
            note = f"{name}: skipped ({why})"
            print(note)
            results["notes"].append(note)
            continue
        print(f"{name}: timing ...", file=sys.stderr, flush=True)
        results["arms"].append(bench_arm(name, **sizes))
    results["machine"]["load_average"] = [start_load, os.getloadavg()[0]]  # 1-minute
    table = markdown_table(results)
    write(args, "closed_form", results, lambda path: plot(results, path))
    print(table)
    return 0


if __name__ == "__main__":
    sys.exit(main())
