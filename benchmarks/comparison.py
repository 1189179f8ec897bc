"""What the resolver and tasks benchmarks share: timing every contender in every mode, in rounds,
the ratios to PlaCo, the answers' quality, and the tables and figure of the results.

A round times fresh contenders in each mode of :mod:`timing` (tight, interleaved, 1 ms of other
work between calls) along the workload's trajectory; :data:`timing.REPEATS` rounds are
combined by their medians (:func:`timing.combine_rounds`) and each round's median and p99 kept
(the spread). Ratios (``vs_placo_*``): PlaCo's time over the contender's, taken within each
round (above 1: faster than PlaCo), each contender against the PlaCo row of its own problem
(:func:`add_placo_ratios`); ``vs_rrc_pin_*`` the same against rrc-pin's default, so that a run
without PlaCo still has its ratios.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from script import QUICK_NOTE, is_quick
from timing import (
    MODE_TITLES,
    MODES,
    Contender,
    Run,
    add_ratios,
    combine_rounds,
    progress,
    quiet_stdout,
    run_mode,
    summarise,
    timing_chart,
    us,
)

Array = np.ndarray


def time_workload(
    name: str,
    make: Callable[[], list[Contender]],
    Q: Array,
    X: Array,
    limits: tuple[Array, Array, Array],
    dt: float,
    rounds: int,
    placo_of: dict[str, str],
    rrc: str,
) -> tuple[dict[str, Any], dict[str, Run]]:
    """Every contender of ``make()`` (fresh each mode and round) in every mode, ``rounds``
    times; the modes' combined rows and the first round's tight runs (the answers judged).

    Args:
        name: The workload, for progress lines.
        make: Fresh contenders.
        Q, X: The trajectory.
        limits: (lower, upper, velocity) of the joints, for the limit excess.
        dt: Control period [s].
        rounds: Rounds of every mode.
        placo_of: Contender label to the PlaCo row its ratio takes (:func:`add_placo_ratios`).
        rrc: rrc-pin's default row (the ``vs_rrc_pin`` ratios).
    """
    per_mode: dict[str, list[dict[str, Any]]] = {mode: [] for mode in MODES}
    first: dict[str, Run] = {}
    for round_ in range(rounds):
        for mode in MODES:
            contenders = make()
            progress(f"{name}: {MODE_TITLES[mode]}, {len(contenders)} contenders, "
                     f"round {round_ + 1} of {rounds}")  # fmt: skip
            with quiet_stdout():  # C-level prints of the solvers
                runs = run_mode(mode, contenders, Q, X)
            rows = summarise(runs, Q, limits, dt)
            add_ratios(rows, rrc, "rrc_pin")
            add_placo_ratios(rows, placo_of)
            add_answered_ratios(rows, runs, placo_of)
            per_mode[mode].append(rows)
            if round_ == 0 and mode == "tight":
                first = runs
    return {mode: {"contenders": combine_rounds(per_mode[mode])} for mode in MODES}, first


def add_placo_ratios(rows: dict[str, dict[str, Any]], placo_of: dict[str, str]) -> None:
    """``vs_placo_median`` / ``_p99`` (and ``_cpu_p99``, of the calls' CPU times): the PlaCo
    row's median (p99) over each row's, in place, for the rows whose PlaCo row ran."""
    for label, row in rows.items():
        base = rows.get(placo_of.get(label, ""))
        if base is not None:
            row["vs_placo_median"] = base["median_us"] / row["median_us"]
            row["vs_placo_p99"] = base["p99_us"] / row["p99_us"]
            if "cpu_p99_us" in base and "cpu_p99_us" in row:
                row["vs_placo_cpu_p99"] = base["cpu_p99_us"] / row["cpu_p99_us"]


def add_answered_ratios(rows: dict[str, dict[str, Any]], runs: dict[str, Run],
                        placo_of: dict[str, str]) -> None:  # fmt: skip
    """Where the PlaCo row failed at some steps (PlaCo raises where its hard tasks cannot be
    met), each row's comparison on the steps both answered, in place: ``answered_steps``,
    ``answered_median_us`` (the row's median there) and ``vs_placo_answered_median`` (PlaCo's
    median there over the row's)."""
    for label, row in rows.items():
        peer = placo_of.get(label, "")
        if peer not in runs or not runs[peer].failed.any():
            continue
        run, base = runs[label], runs[peer]
        both = run.counted & base.counted & ~run.failed & ~base.failed
        row["answered_steps"] = int(both.sum())
        if both.any():
            row["answered_median_us"] = float(np.median(run.seconds[both]) * 1e6)
            row["vs_placo_answered_median"] = float(np.median(base.seconds[both])
                                                    / np.median(run.seconds[both]))  # fmt: skip


def spread(row: dict[str, Any], key: str = "median_us") -> str:
    """The rounds' range of ``key`` ("a-b"), or "" for one round."""
    values = [r[key] for r in row.get("rounds", [])]
    if len(values) < 2:
        return ""
    return f"{us(min(values))}-{us(max(values))}"


def _ratio(row: dict[str, Any], key: str) -> str:
    m, p = row.get(f"vs_{key}_median"), row.get(f"vs_{key}_p99")
    return "-" if m is None else f"{m:.2f}x / {p:.2f}x"


def timing_table(modes: dict[str, Any], order: list[str]) -> list[str]:
    """Markdown: a row per contender (in ``order``), per mode the median / p99 [us], the
    rounds' range of the median, and the ratio to PlaCo (PlaCo's time over the contender's)."""
    head = "| contender |" + "".join(
        f" {MODE_TITLES[m]}: median / p99 [us] | median's range | vs PlaCo |" for m in MODES
    )
    lines = [head, "| --- |" + " ---: | ---: | ---: |" * len(MODES)]
    for label in order:
        cells = f"| {label} |"
        for mode in MODES:
            row = modes[mode]["contenders"].get(label)
            if row is None:
                cells += " - | - | - |"
                continue
            cells += (
                f" {us(row['median_us'])} / {us(row['p99_us'])} | {spread(row) or '-'} | "
                f"{_ratio(row, 'placo')} |"
            )
        lines.append(cells)
    return lines


def excess_table(modes: dict[str, Any], order: list[str]) -> list[str]:
    """Markdown: each contender's largest limit excess and failures (tight loop)."""
    rows = modes["tight"]["contenders"]
    lines = [
        "| contender | velocity excess [rad/s] | position excess [rad] | failures | "
        "first failure |",
        "| --- | ---: | ---: | ---: | --- |",
    ]
    for label in order:
        r = rows.get(label)
        if r is None:
            continue
        error = r.get("first_error", "")[:100].replace("|", "/")
        lines.append(
            f"| {label} | {r['max_velocity_excess']:.2g} | {r['max_position_excess']:.2g} | "
            f"{r['failures']} | {f'`{error}`' if error else '-'} |"
        )
    return lines


def quality_table(quality: dict[str, Any], order: list[str]) -> list[str]:
    """Markdown: per contender the veer where the LP maximum scale is 1 (steps that veer, the
    largest), and on the too-fast segments the direction error and the share at the LP's best
    speed along the command."""
    lines = [
        "| contender | fully reachable steps | veer there: steps | largest [deg] | too-fast "
        "steps (0 < LP scale < 1) | standing still there | direction error median / p90 / max "
        "[deg] | at the LP's best | speed along the command / LP best (median) |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for label in order:
        q = quality.get(label)
        if q is None:
            continue
        fast = (
            f"{q['direction_error_median_deg']:.2g} / {q['direction_error_p90_deg']:.2g} / "
            f"{q['direction_error_max_deg']:.2g} | {100 * q['at_lp_best']:.0f}% | "
            f"{q['speed_median']:.2f}"
            if q.get("too_fast_steps")
            else "- | - | -"
        )
        lines.append(
            f"| {label} | {q['reachable_steps']} | {q['veer_steps']} | "
            f"{q['veer_max_deg']:.2g} | {q['too_fast_steps']} | {q.get('stopped_steps', 0)} | "
            f"{fast} |"
        )
    return lines


def peers_lines(status: dict[str, str]) -> list[str]:
    """One line per peer that did not run (its reason)."""
    return [f"- {peer}: {why}" for peer, why in status.items() if why != "ran"]


def plot(panels: list[tuple[dict[str, Any], str]], path: Path, results: dict[str, Any]) -> bool:
    """The timing figure: a panel per workload, a bar per contender and mode (median), the
    p99 a tick (:func:`timing.timing_chart`)."""
    shown = [({m: modes[m]["contenders"] for m in MODES}, title) for modes, title in panels]
    tallest = max(len(modes[MODES[0]]["contenders"]) for modes, _ in panels)
    note = QUICK_NOTE if is_quick(results) else None
    width = 6.5 * len(panels)
    return timing_chart(shown, path, (width, 1.0 + 0.75 * tallest), note=note)
