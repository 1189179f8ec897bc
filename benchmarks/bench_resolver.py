"""The resolver against pink's ``solve_ik``: step time and limit compliance, one run.

Run from a checkout: ``/work/venv/bin/python benchmarks/bench_resolver.py`` (``--quick``
for a short smoke run that writes nothing; ``--steps N`` to change the trajectory length).

For rrc_k1607 and panda, one trajectory of joint configurations is recorded first: from a
seeded random start, piecewise-constant random twists (new every 50 steps, about 0.4 m/s
and 0.6 rad/s) are resolved by rrc-pin (native OSQP) and integrated with dt = 10 ms, so that
position and velocity limits become active along the way. Then, at every recorded
configuration q_k with its twist, every contender computes joint rates once, the contenders
interleaved step by step so that they share the machine's state (warm starts carry from
step to step as in a control loop). A step's time is the whole call:

- rrc-pin: ``Resolver.solve(q, twist)`` (Pinocchio Jacobian, bounds, factorisation, QP,
  record); native warm-started OSQP, each qpsolvers backend, the direction-preserving
  default, and OSQP without the shortcuts (box-free optimum, guessed active set: every
  step through the backend). With the shortcuts the backend answers only the steps whose
  active set changed (about 1%), so the backends differ mostly in the tail;
- pink (``pink.solve_ik``): ``configuration.update(q)``, the FrameTask target set to the pose
  moved by ``twist * dt``, ``solve_ik(..., limits=[ConfigurationLimit(gain=1),
  VelocityLimit])`` with every qpsolvers backend pink accepts. pink raises when its QP has no
  solution (counted as a failure, rates taken as zero).

Compliance of every answer: the largest excess of ``|qdot|`` over the velocity limit and of
``q + qdot dt`` over the position limits. BLAS threads are pinned to one (set before numpy
is imported) so that the tiny matrix products do not pay for thread hand-offs; both
libraries run under the same setting. Results go to ``benchmarks/results/resolver.json`` and
``resolver.png``; :func:`markdown_table` renders them and is printed at the end.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import contextlib  # noqa: E402
import json  # noqa: E402
import logging  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Callable, Iterator  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402
from machine import machine_info  # noqa: E402

import rrc_pin  # noqa: E402
from rrc_pin.resolver import Resolver  # noqa: E402
from solvers.qp_backends import installed_backends  # noqa: E402

ARMS = ("rrc_k1607", "panda")
RESULTS = Path(__file__).resolve().parent / "results"
SEED = 20261122
DT = 0.01
SEGMENT = 50


def record_trajectory(
    arm: Any, steps: int, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Configurations (steps, nq) and twists (steps, 6) of one rrc-pin run (module docstring)."""
    resolver = Resolver(arm, dt=DT, direction_preserving=False)
    q = arm.random_q(rng)
    Q = np.empty((steps, arm.nq))
    X = np.empty((steps, 6))
    twist = np.zeros(6)
    for k in range(steps):
        if k % SEGMENT == 0:
            twist = np.concatenate([rng.normal(size=3) * 0.23, rng.normal(size=3) * 0.35])
        Q[k], X[k] = q, twist
        q = q + resolver.solve(q, twist).qdot * DT
    return Q, X


def rrc_contenders(arm: Any) -> dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """rrc-pin resolvers under test, by label."""
    out: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {}

    def make(**kwargs: Any) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
        resolver = Resolver(arm, dt=DT, **kwargs)
        return lambda q, x: resolver.solve(q, x).qdot

    out["rrc-pin osqp (native, warm)"] = make(backend="osqp", direction_preserving=False)
    out["rrc-pin osqp, no shortcut"] = make(
        backend="osqp", direction_preserving=False, shortcut=False
    )
    out["rrc-pin osqp, direction-preserving"] = make(backend="osqp", direction_preserving=True)
    for name in installed_backends():
        if name != "osqp":
            out[f"rrc-pin {name}"] = make(backend=name, direction_preserving=False)
    return out


def pink_contenders(arm: Any) -> dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """pink.solve_ik with every qpsolvers backend, on the same task and limits."""
    try:
        import pink
        import qpsolvers
        from pink.limits import ConfigurationLimit, VelocityLimit
        from pink.tasks import FrameTask
    except ImportError:
        return {}
    logging.getLogger().setLevel(logging.ERROR)  # pink logs every near-limit configuration
    model = arm.model
    out: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {}
    for solver in qpsolvers.available_solvers:
        configuration = pink.Configuration(model, model.createData(), arm.neutral())
        task = FrameTask(arm.tool_frame, position_cost=1.0, orientation_cost=1.0)
        limits = [ConfigurationLimit(model, config_limit_gain=1.0), VelocityLimit(model)]

        def step(
            q: np.ndarray,
            x: np.ndarray,
            configuration: Any = configuration,
            task: Any = task,
            limits: Any = limits,
            solver: str = solver,
        ) -> np.ndarray:
            configuration.update(q)
            T = configuration.get_transform_frame_to_world(arm.tool_frame)
            target = pin.SE3(pin.exp3(x[3:] * DT) @ T.rotation, T.translation + x[:3] * DT)
            task.set_target(target)
            return pink.solve_ik(
                configuration, [task], DT, solver=solver, limits=limits, safety_break=False
            )

        out[f"pink {solver}"] = step
    return out


def bench_arm(name: str, steps: int) -> dict[str, Any]:
    """Time and compliance of every contender along one trajectory of arm ``name``."""
    arm = rrc_pin.load(name)
    rng = np.random.default_rng(SEED)
    Q, X = record_trajectory(arm, steps, rng)
    contenders = {**rrc_contenders(arm), **pink_contenders(arm)}
    with _quiet_stdout():  # OSQP's C code prints "Polishing not needed" when nothing is active
        rows = _run(arm, Q, X, contenders, rng)
    ours = rows["rrc-pin osqp (native, warm)"]
    pinks = {k: v for k, v in rows.items() if k.startswith("pink")}
    active, routes = _routes(arm, Q, X)
    summary: dict[str, Any] = {"steps": steps, "active_limit_fraction": active, "routes": routes}
    if pinks:
        fastest = min(pinks, key=lambda k: pinks[k]["median_us"])
        summary.update(
            pink_fastest=fastest,
            speedup_median=pinks[fastest]["median_us"] / ours["median_us"],
            speedup_p99=pinks[fastest]["p99_us"] / ours["p99_us"],
        )
    return {"arm": name, "nq": arm.nq, "summary": summary, "contenders": rows}


def _run(
    arm: Any,
    Q: np.ndarray,
    X: np.ndarray,
    contenders: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]],
    rng: np.random.Generator,
) -> dict[str, dict[str, Any]]:
    """Every contender at every step (shuffled order): times and limit excesses."""
    times: dict[str, list[float]] = {label: [] for label in contenders}
    v_excess = dict.fromkeys(contenders, 0.0)
    q_excess = dict.fromkeys(contenders, 0.0)
    failures = dict.fromkeys(contenders, 0)
    v_max, lower, upper = arm.velocity_limit, arm.lower, arm.upper
    clock = time.perf_counter
    order = list(contenders)
    for q, x in zip(Q, X, strict=True):
        rng.shuffle(order)  # no contender always runs first, after another one's cache misses
        for label in order:
            t0 = clock()
            try:
                qdot = contenders[label](q, x)
            except Exception:  # pink raises NoSolutionFound (and others) on failure
                qdot = np.zeros(arm.nq)
                failures[label] += 1
            times[label].append(clock() - t0)
            step = q + qdot * DT
            v_excess[label] = max(v_excess[label], float(np.max(np.abs(qdot) - v_max)))
            q_excess[label] = max(
                q_excess[label], float(np.max(step - upper)), float(np.max(lower - step))
            )
    out = {}
    for label in contenders:
        t = np.array(times[label]) * 1e6
        out[label] = {
            "median_us": float(np.median(t)),
            "p99_us": float(np.percentile(t, 99)),
            "mean_us": float(np.mean(t)),
            "max_velocity_excess": v_excess[label],
            "max_position_excess": q_excess[label],
            "failures": failures[label],
        }
    return out


@contextlib.contextmanager
def _quiet_stdout() -> Iterator[None]:
    """Send file descriptor 1 (C-level prints) to /dev/null for the duration."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        os.dup2(saved, 1)
        os.close(devnull)
        os.close(saved)


def _routes(arm: Any, Q: np.ndarray, X: np.ndarray) -> tuple[float, dict[str, int]]:
    """Fraction of the steps with a bound active in rrc-pin's answer, and how the main
    contender's steps were answered (status counts: box-free optimum, guessed active set,
    backend)."""
    resolver = Resolver(arm, dt=DT, direction_preserving=False)
    hits = 0
    routes: dict[str, int] = {}
    for q, x in zip(Q, X, strict=True):
        r = resolver.solve(q, x)
        hits += bool(r.active)
        route = "backend" if r.backend else r.status
        routes[route] = routes.get(route, 0) + 1
    return hits / len(Q), routes


def markdown_table(results: dict[str, Any]) -> str:
    """Markdown table of a results dictionary (as written to resolver.json).

    Per arm: median and 99th percentile of every contender's step time, and both as a
    ratio against pink's fastest backend (its median over the contender's median, and the
    same for the 99th percentile: above 1, faster than pink); then the limit compliance.
    """
    lines = []
    for arm in results["arms"]:
        s = arm["summary"]
        head = (
            f"**{arm['arm']}** ({arm['nq']} joints, {s['steps']} steps, a bound active at "
            f"{100 * s['active_limit_fraction']:.0f}% of them)"
        )
        pink = arm["contenders"].get(s.get("pink_fastest", ""))
        if pink is not None:
            head += (
                f": rrc-pin (native OSQP) is {s['speedup_median']:.1f}x faster than "
                f"{s['pink_fastest']} at the median, {s['speedup_p99']:.1f}x at the 99th percentile"
            )
        routes = s.get("routes")
        if routes:
            total = sum(routes.values())
            head += "; its steps answered by: " + ", ".join(
                f"{name} {100 * count / total:.1f}%"
                for name, count in sorted(routes.items(), key=lambda kv: -kv[1])
            )
        lines += [
            head,
            "",
            "| contender | median [us] | p99 [us] | median vs pink fastest | "
            "p99 vs pink fastest | max velocity excess [rad/s] | max position excess [rad] "
            "| failures |",
            "|---|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for label, r in sorted(arm["contenders"].items(), key=lambda kv: kv[1]["median_us"]):
            ratios = ("-", "-")
            if pink is not None:
                ratios = (
                    f"{pink['median_us'] / r['median_us']:.2f}x",
                    f"{pink['p99_us'] / r['p99_us']:.2f}x",
                )
            lines.append(
                f"| {label} | {r['median_us']:.0f} | {r['p99_us']:.0f} | {ratios[0]} | "
                f"{ratios[1]} | {r['max_velocity_excess']:.2g} | "
                f"{r['max_position_excess']:.2g} | {r['failures']} |"
            )
        lines.append("")
    return "\n".join(lines)


def plot(results: dict[str, Any], path: Path) -> None:
    """Bar chart of median and p99 step times per contender and arm."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    arms = results["arms"]
    fig, axes = plt.subplots(1, len(arms), figsize=(7 * len(arms), 5), squeeze=False)
    for ax, arm in zip(axes[0], arms, strict=True):
        items = sorted(arm["contenders"].items(), key=lambda kv: kv[1]["median_us"])
        labels = [k for k, _ in items]
        med = [v["median_us"] for _, v in items]
        p99 = [v["p99_us"] for _, v in items]
        y = np.arange(len(labels))
        ax.barh(y - 0.2, med, 0.4, label="median")
        ax.barh(y + 0.2, p99, 0.4, label="99th percentile")
        ax.set_yticks(y, labels)
        ax.set_xscale("log")
        ax.set_xlim(left=50.0)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.invert_yaxis()
        ax.set_xlabel("step time [us] (log)")
        ax.set_title(f"{arm['arm']}: one resolved-rate step")
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv: list[str] | None = None) -> None:
    """Run the benchmark, write JSON and PNG (unless --quick), print the table."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="short run, writes nothing")
    parser.add_argument("--steps", type=int, default=2000, help="trajectory length")
    args = parser.parse_args(argv)
    steps = 100 if args.quick else args.steps
    warnings.simplefilter("ignore")
    results = {
        "machine": {
            **machine_info("osqp", "qpsolvers", "pink"),
            "blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"),
        },
        "dt": DT,
        "arms": [bench_arm(a, steps) for a in ARMS],
    }
    if not args.quick:
        RESULTS.mkdir(parents=True, exist_ok=True)
        (RESULTS / "resolver.json").write_text(json.dumps(results, indent=2) + "\n")
        plot(results, RESULTS / "resolver.png")
    print(markdown_table(results))


if __name__ == "__main__":
    main()
