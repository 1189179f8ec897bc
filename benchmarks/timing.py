"""How the benchmarks time a contender as its users run it: loop modes, statistics, compliance.

A contender is one way of computing the joint rates of a step (a library, a backend, a set
of options), called exactly as its users call it, the whole call timed with
``time.perf_counter``, every contender in the same process. Along one recorded trajectory
(configurations ``Q`` and commands ``X``), it is timed in one of three modes:

- ``tight``: one contender at a time, every step back to back (what a micro-benchmark
  measures: caches, branch predictors and the CPU clock stay hot for that contender);
- ``interleaved``: at every step every contender is called once, in an order drawn at random
  at each step (each contender first and after each of the others by turns), so that each
  call finds the caches left by its peers (one process running several libraries);
- ``busy``: one contender at a time, and between two calls 1 ms of other work
  (:class:`OtherWork`: numpy products and Pinocchio kinematics of another model, as a
  controller does between ticks), so that each call finds its caches cooled by a tick's
  worth of other code, on a core kept busy (a sleep would let the clock drop and the process
  be descheduled: what the machine's other load does, not the controller).

In the ``tight`` and ``busy`` modes the contenders take turns of :data:`BLOCK` consecutive
steps (the order rotated at every round of turns), each going through the trajectory in
order, so that every contender samples the whole run's machine state: on a shared machine
the load of other processes drifts within seconds, and one contender timed at once over the
whole trajectory would meet a different machine than the next (measured: the medians of
identical code paths differed by up to 1.9x that way). The first calls of a turn find the
caches of the previous contender: rrc-pin's panda tick took 128 us on the first call after
2.5 ms of other work, 18 on the second, 11 on the third, 8-10 after (medians over 24 turns),
so that these calls, 2 in 250, made most of the tight mode's top 1 %. The ``tight`` mode
leaves the first :data:`TURN_WARM_UP` calls of every turn out of its statistics, for every
contender: it measures the hot loop; the other two modes measure calls with cooled caches.

Each mode starts from fresh contenders (warm starts carry from step to step within a mode,
as in a control loop) and calls each once, untimed, at the first step before timing.

A contender that raises is counted as a failure at that step and its rates taken as zero.
Compliance is measured on every answer: the largest excess of ``|qdot|`` over the velocity
limit and of ``q + qdot dt`` over the position limits (0 when there is none).
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

MODES = ("tight", "interleaved", "busy")
MODE_TITLES = {
    "tight": "tight loop",
    "interleaved": "interleaved",
    "busy": "1 ms of other work between calls",
}
OTHER_WORK = 1e-3
"""[s] The other work between two calls of the ``busy`` mode."""
BLOCK = 250
"""Steps a contender runs in one turn of the ``tight`` and ``busy`` modes."""
TURN_WARM_UP = 5
"""First calls of a ``tight`` turn left out of its statistics (module docstring)."""
REPEATS = 3
"""Rounds of every mode in a full run (``--quick``: one), each from fresh contenders: one
round's medians move by up to 2x between runs on the project's shared 2-core machine:
:func:`combine_rounds` keeps the median of the rounds, and each round's numbers (the
spread)."""


class OtherWork:
    """About ``seconds`` of other work per call: numpy products and Pinocchio kinematics.

    What a controller does between two resolver calls (state estimation, logging, another
    model's kinematics): 40 x 40 matrix products and Pinocchio's forward kinematics and
    Jacobians of its sample manipulator, repeated until ``seconds`` have passed.
    """

    def __init__(self, seconds: float = OTHER_WORK) -> None:
        import pinocchio as pin

        self.seconds = seconds
        self.model = pin.buildSampleModelManipulator()
        self.data = self.model.createData()
        rng = np.random.default_rng(0)
        self.M = rng.normal(size=(40, 40)) / 40.0
        self.q = pin.neutral(self.model)
        self._pin = pin
        self.sink = 0.0

    def __call__(self) -> None:
        pin, clock = self._pin, time.perf_counter
        end = clock() + self.seconds
        M = self.M
        while clock() < end:
            M2 = M @ M
            self.q[0] += 1e-3
            pin.computeJointJacobians(self.model, self.data, self.q)
            self.sink += float(M2[0, 0])


@dataclass
class Contender:
    """One way of computing a step's joint rates, as its users call it.

    Attributes:
        label: Name in the tables.
        call: One step ``call(q, x)`` (q (n,) [rad], x the command) returning what the library
            returns; the whole call is timed.
        rates: The joint rates (n,) [rad/s] of what ``call`` returned (not timed).
        keep: Keep what ``call`` returned (rrc-pin's Resolutions, for their statistics).
    """

    label: str
    call: Callable[[Array, Array], Any]
    rates: Callable[[Any], Array] = np.asarray
    keep: bool = False


@dataclass
class Run:
    """What one contender did in one mode.

    Attributes:
        seconds: Time of each step's call (steps,) [s].
        cpu: The calling thread's CPU time of each step's call (steps,) [s]: the wall time
            less the time the scheduler gave the core to another process.
        rates: Joint rates of each step (steps, n) [rad/s] (zero where it failed).
        failed: Steps where the call raised (steps,).
        counted: Steps whose times count in the statistics (steps,): all but the first
            :data:`TURN_WARM_UP` of each ``tight`` turn.
        kept: What the calls returned, if the contender keeps it.
        first_error: The first failure's exception (type and message), or "".
    """

    seconds: Array
    rates: Array
    failed: npt.NDArray[np.bool_]
    cpu: Array = field(default_factory=lambda: np.empty(0))
    counted: npt.NDArray[np.bool_] = field(default_factory=lambda: np.ones(0, dtype=bool))
    kept: list[Any] = field(default_factory=list)
    first_error: str = ""


def run_mode(
    mode: str,
    contenders: Sequence[Contender],
    Q: Array,
    X: Array,
    other: Callable[[], None] | None = None,
    rng: np.random.Generator | None = None,
) -> dict[str, Run]:
    """Time ``contenders`` along the trajectory ``(Q, X)`` in ``mode`` (module docstring).

    Args:
        mode: ``tight``, ``interleaved`` or ``busy``.
        contenders: Fresh contenders (their warm starts begin here).
        Q: Configurations (steps, n) [rad].
        X: Commands (steps, m).
        other: The ``busy`` mode's work between calls (default :class:`OtherWork`).
        rng: The ``interleaved`` mode's draws of the order (default seeded 0).

    Returns:
        A :class:`Run` per contender label.
    """
    steps, n = Q.shape
    runs = {
        c.label: Run(
            np.empty(steps), np.zeros((steps, n)), np.zeros(steps, dtype=bool), np.empty(steps),
            np.ones(steps, dtype=bool),
        )
        for c in contenders
    }
    for c in contenders:  # one untimed call: imports, workspaces, first-call set-up
        _step(c, Q[0], X[0])
    m = len(contenders)
    if mode == "interleaved":
        order = np.random.default_rng(0) if rng is None else rng
        for k in range(steps):
            for i in order.permutation(m):
                c = contenders[i]
                _record(runs[c.label], c, k, *_step(c, Q[k], X[k]))
        return runs
    if mode not in ("tight", "busy"):
        raise ValueError(f"unknown mode {mode!r}; expected one of {', '.join(MODES)}")
    work = (other or OtherWork()) if mode == "busy" else None
    for turn, a in enumerate(range(0, steps, BLOCK)):
        b = min(a + BLOCK, steps)
        for i in range(m):
            c = contenders[(turn + i) % m]
            run = runs[c.label]
            for k in range(a, b):
                _record(run, c, k, *_step(c, Q[k], X[k]))
                if work is not None:
                    work()
            if mode == "tight":
                run.counted[a : a + TURN_WARM_UP] = False
    return runs


def timed(call: Callable[[], Any]) -> tuple[Any, float, float]:
    """``call()``'s answer, its wall-clock seconds and the thread's CPU seconds."""
    clock, cpu = time.perf_counter, time.thread_time
    c0, t0 = cpu(), clock()
    out = call()
    t1, c1 = clock(), cpu()
    return out, t1 - t0, c1 - c0


def closed_loops(
    mode: str, loops: dict[str, Callable[[int], tuple[float, float]]], ticks: int,
    rng: np.random.Generator,
) -> dict[str, tuple[Array, Array]]:
    """Run closed loops (each its own state, advanced by ``loops[label](k)`` at tick k, which
    returns its timed call's wall-clock and CPU seconds) for ``ticks`` ticks in ``mode``:
    ``tight``, each loop :data:`BLOCK` ticks in a row, in turns rotated every round;
    ``interleaved``, every tick each loop once, in an order drawn from ``rng``.

    Returns:
        Per label the wall-clock and the CPU seconds of its ticks (ticks,), in ``tight`` mode
        without the first :data:`TURN_WARM_UP` of each turn (module docstring).
    """
    out = {label: (np.empty(ticks), np.empty(ticks)) for label in loops}
    labels = list(loops)

    def advance(label: str, k: int) -> None:
        out[label][0][k], out[label][1][k] = loops[label](k)

    if mode == "interleaved":
        for k in range(ticks):
            for i in rng.permutation(len(labels)):
                advance(labels[i], k)
        return out
    if mode != "tight":
        raise ValueError(f"unknown mode {mode!r}; expected tight or interleaved")
    for turn, a in enumerate(range(0, ticks, BLOCK)):
        for i in range(len(labels)):
            label = labels[(turn + i) % len(labels)]
            for k in range(a, min(a + BLOCK, ticks)):
                advance(label, k)
    counted = np.arange(ticks) % BLOCK >= TURN_WARM_UP
    return {label: (wall[counted], cpu[counted]) for label, (wall, cpu) in out.items()}


def _step(c: Contender, q: Array, x: Array) -> tuple[Any, float, float, str]:
    """One call of ``c``: (what it returned, seconds, CPU seconds, the error or "")."""
    clock, cpu = time.perf_counter, time.thread_time
    c0, t0 = cpu(), clock()
    try:
        out = c.call(q, x)
    except Exception as exc:  # a peer raising (pink's NoSolutionFound...) is a failed step
        t1, c1 = clock(), cpu()
        return None, t1 - t0, c1 - c0, f"{type(exc).__name__}: {exc}"[:300]
    t1, c1 = clock(), cpu()
    return out, t1 - t0, c1 - c0, ""


def _record(
    run: Run, c: Contender, k: int, out: Any, seconds: float, cpu: float, error: str
) -> None:
    run.seconds[k] = seconds
    run.cpu[k] = cpu
    if error:
        run.failed[k] = True
        run.first_error = run.first_error or error
        return
    run.rates[k] = c.rates(out)
    if c.keep:
        run.kept.append(out)


def record_trajectory(
    arm: Any, steps: int, rng: np.random.Generator, dt: float = 0.01, segment: int = 50
) -> tuple[Array, Array]:
    """Configurations (steps, nq) [rad] and twists (steps, 6) of an rrc-pin run to time the
    contenders along: ``Resolver(arm, dt, direction_preserving=False)`` (the tracking mode)
    from ``arm.random_q(rng)``, a new random twist every ``segment`` steps (linear parts
    N(0, 0.23) [m/s], angular N(0, 0.35) [rad/s] per axis), Euler steps of ``dt`` [s]."""
    import rrc_pin

    resolver = rrc_pin.Resolver(arm, dt=dt, direction_preserving=False)
    q = arm.random_q(rng)
    Q, X = np.empty((steps, arm.nq)), np.empty((steps, 6))
    twist = np.zeros(6)
    for k in range(steps):
        if k % segment == 0:
            twist = np.concatenate([rng.normal(size=3) * 0.23, rng.normal(size=3) * 0.35])
        Q[k], X[k] = q, twist
        q = q + resolver.solve(q, twist).qdot * dt
    return Q, X


def statistics(seconds: Array, cpu: Array | None = None) -> dict[str, float]:
    """Median, 10th, 90th and 99th percentiles, mean and maximum of step times [us]; with the
    calls' CPU times, their median and 99th percentile too (``cpu_median_us``, ``cpu_p99_us``:
    a call that lost its core to another process counts only its own work)."""
    us = np.asarray(seconds) * 1e6
    p10, p50, p90, p99 = np.percentile(us, [10, 50, 90, 99])
    out = {
        "median_us": float(p50),
        "p10_us": float(p10),
        "p90_us": float(p90),
        "p99_us": float(p99),
        "mean_us": float(us.mean()),
        "max_us": float(us.max()),
    }
    if cpu is not None and len(cpu):
        c50, c99 = np.percentile(np.asarray(cpu) * 1e6, [50, 99])
        out.update({"cpu_median_us": float(c50), "cpu_p99_us": float(c99)})
    return out


def compliance(
    Q: Array, rates: Array, lower: Array, upper: Array, velocity: Array, dt: float
) -> dict[str, float]:
    """Largest excess over the velocity limits [rad/s] and over the position limits after one
    Euler step ``q + qdot dt`` [rad], over all steps (0 when every answer is inside)."""
    after = Q + rates * dt
    return {
        "max_velocity_excess": float(max(0.0, (np.abs(rates) - velocity).max())),
        "max_position_excess": float(max(0.0, (after - upper).max(), (lower - after).max())),
    }


def summarise(
    runs: dict[str, Run], Q: Array, limits: tuple[Array, Array, Array], dt: float
) -> dict[str, dict[str, Any]]:
    """Statistics, compliance and failures of every contender of one mode."""
    lower, upper, velocity = limits
    out: dict[str, dict[str, Any]] = {}
    for label, run in runs.items():
        row: dict[str, Any] = statistics(run.seconds[run.counted], run.cpu[run.counted])
        row.update(compliance(Q, run.rates, lower, upper, velocity, dt))
        row["failures"] = int(run.failed.sum())
        if run.first_error:
            row["first_error"] = run.first_error
        out[label] = row
    return out


def combine_rounds(rounds: Sequence[dict[str, dict[str, Any]]]) -> dict[str, dict[str, Any]]:
    """One row per contender from its rows in several rounds of one mode.

    Each time statistic and each ratio (``vs_*``, computed within its round, so that a
    contender and its peer are compared on the same machine state) is the median over the
    rounds; the largest time, excess and error (``max*``), failures and overruns are the
    worst round's; other entries are the first round's. ``rounds`` lists each round's
    median, p99 and ratios, to show the spread.
    """
    out: dict[str, dict[str, Any]] = {}
    for label, first in rounds[0].items():
        rows = [r[label] for r in rounds]
        row: dict[str, Any] = {}
        for key, value in first.items():
            values = [r[key] for r in rows]
            if key.startswith("max") or key == "failures":
                row[key] = max(values)
            elif isinstance(value, float):
                row[key] = float(np.median(values))
            else:
                row[key] = value
        timing = [k for k in first if k in ("median_us", "p99_us") or k.startswith("vs_")]
        row["rounds"] = [{k: r[k] for k in timing} for r in rows]
        out[label] = row
    return out


def rounds_note(settings: dict[str, Any]) -> str:
    """How the rounds of a mode were combined (:func:`combine_rounds`), for the tables' notes."""
    n = settings.get("rounds", 1)
    if n == 1:
        return "one round of each mode"
    return (
        f"{n} rounds of each mode, from fresh contenders: every time and ratio is the median "
        "of the rounds' (each ratio taken within its round)"
    )


def add_ratios(rows: dict[str, dict[str, Any]], baseline: str, key: str = "baseline") -> None:
    """Add each row's ratio to the baseline row, in place: ``vs_<key>_median`` is the
    baseline's median over the row's (above 1: faster than the baseline), the same for p99."""
    base = rows[baseline]
    for row in rows.values():
        row[f"vs_{key}_median"] = base["median_us"] / row["median_us"]
        row[f"vs_{key}_p99"] = base["p99_us"] / row["p99_us"]


def fastest_of(rows: dict[str, dict[str, Any]], prefix: str) -> str | None:
    """The row whose label starts with ``prefix`` with the lowest median, or None."""
    peers = [k for k in rows if k.startswith(prefix)]
    return min(peers, key=lambda k: rows[k]["median_us"]) if peers else None


def add_peer_ratios(rows: dict[str, dict[str, Any]], prefix: str, key: str = "baseline") -> None:
    """:func:`add_ratios` to the fastest row whose label starts with ``prefix`` (if any)."""
    fastest = fastest_of(rows, prefix)
    if fastest is not None:
        add_ratios(rows, fastest, key)


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """Send file descriptor 1 to /dev/null for the duration (OSQP's C code prints "Polishing
    not needed" when nothing is active); Python's ``sys.stdout`` is flushed first. Progress
    goes to stderr, which stays open."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(devnull)
        os.close(saved)


def progress(message: str) -> None:
    """One line of progress on stderr (stdout may be silenced by :func:`quiet_stdout`)."""
    print(message, file=sys.stderr, flush=True)


@contextlib.contextmanager
def one_core(pids: list[int]) -> Iterator[int | None]:
    """Pin this process and ``pids`` to the core this process runs on; restore on exit."""
    if not hasattr(os, "sched_setaffinity"):
        yield None
        return
    saved = os.sched_getaffinity(0)
    try:
        cpu = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[36])
    except (OSError, IndexError, ValueError):
        cpu = min(saved)
    try:
        for pid in [0, *pids]:
            os.sched_setaffinity(pid, {cpu})
        yield cpu
    finally:
        os.sched_setaffinity(0, saved)


def timing_chart(
    panels: list[tuple[dict[str, dict[str, dict[str, float]]], str]],
    path: Path,
    size: tuple[float, float],
    mode_titles: dict[str, str] | None = None,
    note: str | None = None,
) -> bool:
    """Bar charts of step times to ``path``; False without matplotlib (nothing written).

    One panel per (rows by mode, title): a bar per contender and mode (its median; contenders
    sorted by the first mode's), the p99 as a tick, on a log axis whose 2s and 5s are labelled
    too. One legend for the figure, below every axis label; ``mode_titles`` names the modes
    where :data:`MODE_TITLES` does not fit (a benchmark without peers); ``note`` goes above
    the panels (a quick run's warning).
    """
    titles = {**MODE_TITLES, **(mode_titles or {})}
    try:
        import matplotlib
    except ImportError:
        return False
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    fig, axes = plt.subplots(1, len(panels), figsize=size, squeeze=False)
    for ax, (by_mode, title) in zip(axes[0], panels, strict=True):
        modes = list(by_mode)
        first = by_mode[modes[0]]
        labels = sorted(first, key=lambda k: first[k]["median_us"])
        y = np.arange(len(labels))
        width = 0.8 / len(modes)
        for i, mode in enumerate(modes):
            rows = by_mode[mode]
            offset = (i - (len(modes) - 1) / 2) * width
            median = [rows[k]["median_us"] for k in labels]
            ax.barh(y + offset, median, width, label=f"{titles[mode]} (median)")
            ax.plot([rows[k]["p99_us"] for k in labels], y + offset, "k|", markersize=7)
        ax.plot([], [], "k|", label="p99")
        ax.set_yticks(y, labels)
        ax.set_xscale("log")
        # Bars start at the decade below half the fastest median, never at an autoscaled edge
        # just below it (which made 25 us against 30 us look like a factor of four), nor at
        # the fastest's own decade (a 10.0 us median drew no bar).
        fastest = min(r["median_us"] for rows in by_mode.values() for r in rows.values())
        ax.set_xlim(left=10.0 ** np.floor(np.log10(fastest / 2.0)))
        ax.xaxis.set_minor_formatter(_twos_and_fives(ax.xaxis))
        ax.xaxis.set_major_formatter(matplotlib.ticker.FuncFormatter(lambda v, _: f"{v:g}"))
        ax.tick_params(axis="x", which="minor", labelsize=7)
        ax.invert_yaxis()
        ax.set_xlabel("step time [us] (log)")
        ax.set_title(title)
    if note:
        fig.suptitle(note, color="firebrick")
    fig.tight_layout()
    handles, names = axes[0][0].get_legend_handles_labels()
    # below the figure's axes and their labels (bbox_inches="tight" keeps it in the file)
    fig.legend(handles, names, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, 0.0),
               ncol=len(names))  # fmt: skip
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return True


def _twos_and_fives(axis: Any) -> Any:
    """A minor-tick formatter for a log ``axis``: 2, 5, 20, 50... labelled where the axis
    spans at most three decades (beyond, they would crowd the powers of ten)."""
    import matplotlib.ticker

    def label(value: float, _position: int) -> str:
        low, high = axis.get_view_interval()
        if high / max(low, 1e-300) > 1e3:
            return ""
        lead = value / 10.0 ** np.floor(np.log10(value))
        return f"{value:g}" if round(lead) in (2, 5) and abs(lead - round(lead)) < 1e-6 else ""

    return matplotlib.ticker.FuncFormatter(label)


def us(x: float) -> str:
    """A time [us] for a table: thousands separated, one decimal below 10."""
    return f"{x:,.0f}" if x >= 10 else f"{x:.1f}"


def stats_cells(row: dict[str, Any]) -> str:
    """Table cells of a row: median, p10, p90, p99 [us] and the two ratios to the baseline
    (:func:`add_ratios`), as ``" a | b | ... |"``."""
    return (
        f" {us(row['median_us'])} | {us(row['p10_us'])} | {us(row['p90_us'])} | "
        f"{us(row['p99_us'])} | {row['vs_baseline_median']:.2f}x | {row['vs_baseline_p99']:.2f}x |"
    )


def ratio(row: dict[str, Any], key: str) -> str:
    """A ratio of a contender's row for a table ("-" where there is none)."""
    value = row.get(key)
    return "-" if value is None else f"{value:.2f}x"


def mode_table(m: dict[str, Any], mode: str, baselines: dict[str, str]) -> list[str]:
    """Markdown lines of one timing mode: a row per contender by median (times, the ratios
    to each of ``baselines`` (column name: key prefix in the rows), limit excess, failures),
    then the overrun ticks and the first failures."""
    vs = "".join(f" median vs {b} | p99 vs {b} |" for b in baselines)
    lines = [
        f"**{MODE_TITLES[mode]}** (pink's fastest: {m['pink_fastest'] or '-'}"
        + (f"; mink's fastest: {m['mink_fastest']}" if m.get("mink_fastest") else "")
        + ")",
        "",
        f"| contender | median [us] | p10 | p90 | p99 | mean |{vs} max velocity excess [rad/s] "
        "| max position excess [rad] | failures |",
        "| --- |" + " ---: |" * (8 + 2 * len(baselines)),
    ]
    for label, r in sorted(m["contenders"].items(), key=lambda kv: kv[1]["median_us"]):
        ratios = "".join(
            f" {ratio(r, f'vs_{k}_median')} | {ratio(r, f'vs_{k}_p99')} |"
            for k in baselines.values()
        )
        lines.append(
            f"| {label} | {us(r['median_us'])} | {us(r['p10_us'])} | {us(r['p90_us'])} | "
            f"{us(r['p99_us'])} | {us(r['mean_us'])} |{ratios} "
            f"{r['max_velocity_excess']:.2g} | {r['max_position_excess']:.2g} | {r['failures']} |"
        )
    overruns = {k: r["overruns"] for k, r in m["contenders"].items() if r.get("overruns")}
    if overruns:
        lines += [
            "",
            "Ticks overrun (call longer than 1 ms): "
            + ", ".join(f"{k} {v}" for k, v in overruns.items()),
        ]
    errors = {k: r["first_error"] for k, r in m["contenders"].items() if "first_error" in r}
    if errors:
        lines += [
            "",
            "First failure: " + "; ".join(f"{k}: `{v[:120]}`" for k, v in errors.items()),
        ]
    return [*lines, ""]
