"""Tables and plot of the tasks benchmark (``bench_tasks.py``), from its JSON.

:func:`readme_table` is the README's short table, :func:`docs_section` every table for
docs/benchmarks.md (``update_readme.py`` calls both through ``bench_tasks``), :func:`plot` the
PNG. Only the recorded results are read: nothing here is measured.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from script import QUICK_NOTE, is_quick
from stage_profile import profile_table
from timing import MODE_TITLES, mode_table, rounds_note, timing_chart, us

MODES = ("tight", "interleaved")
"""The modes the tasks benchmark times (:mod:`timing`)."""
WEIGHTED, STRICT, PLACO = "rrc-pin weighted", "rrc-pin strict", "PlaCo"
FLOOR = "Pinocchio + numpy + DAQP (weighted floor)"
"""Labels of the contenders the tables name."""


def _x(value: float | None) -> str:
    return "-" if value is None else f"{value:.1f}x"


def readme_table(results: dict[str, Any]) -> str:
    """The README's table: rrc-pin weighted and strict, pink's fastest backend and PlaCo, median
    and p99 in both modes, with rrc-pin's ratios (the peer's time over rrc-pin's)."""
    modes = results["modes"]
    head = "| contender |" + "".join(
        f" {MODE_TITLES[m]}: median / p99 [us] | vs pink fastest | vs PlaCo |" for m in MODES
    )
    lines = [head, "| --- |" + " ---: | ---: | ---: |" * len(MODES)]
    fastest = [modes[m]["pink_fastest"] for m in MODES]
    for label in (WEIGHTED, STRICT, "pink fastest", PLACO, FLOOR):
        name = label
        if label == "pink fastest":
            name = f"pink fastest ({', '.join((f or '-').removeprefix('pink ') for f in fastest)})"
        cells = f"| {name} |"
        for mode, pink_label in zip(MODES, fastest, strict=True):
            rows = modes[mode]["contenders"]
            row = (
                rows.get(pink_label if label == "pink fastest" else label)
                if (label != "pink fastest" or pink_label)
                else None
            )
            if row is None:
                cells += " - | - | - |"
                continue
            ours = label in (WEIGHTED, STRICT, FLOOR)
            vs_pink = (
                f"{_x(row.get('vs_baseline_median'))} / {_x(row.get('vs_baseline_p99'))}"
                if ours and "vs_baseline_median" in row
                else "-"
            )
            vs_placo = (
                f"{_x(row.get('vs_placo_median'))} / {_x(row.get('vs_placo_p99'))}"
                if ours and "vs_placo_median" in row
                else "-"
            )
            cells += f" {us(row['median_us'])} / {us(row['p99_us'])} | {vs_pink} | {vs_placo} |"
        lines.append(cells)
    lines += ["", _setup_line(results)]
    return "\n".join(lines)


def _setup_line(results: dict[str, Any]) -> str:
    s, m = results["settings"], results["machine"]
    t = results["trajectory"]
    eq = results["equivalence"]
    placo = eq["peers"].get(PLACO)
    text = (
        f"baxter ({results['nq']} joints), both grippers commanded and a posture task, "
        f"{t['steps']} steps (a bound active at {100 * t['active_fraction']:.0f}% of them), "
        f"dt = {1000 * s['dt']:g} ms; pink's costs (frame 1, posture {s['posture_cost']:g}), "
        "rrc-pin's and PlaCo's weights their squares. The weighted floor: the same costs with "
        "one Pinocchio pass, the rows stacked into one array, the normal equations and DAQP "
        "where they leave the bounds, and nothing else (no task objects, checks, fallbacks or "
        "report): what plain Python reaches on this problem. Ratios: the peer's time over "
        f"rrc-pin's or the floor's (above 1: faster), median / p99; {rounds_note(s)}."
    )
    if placo and placo["max_difference"] is not None:
        text += (
            f" Where nothing is constrained ({placo['steps']} steps), PlaCo's rates are rrc-pin "
            f"weighted's within {placo['max_difference']:.1g} rad/s (PlaCo's regularisation"
        )
        damped = placo.get("with_damping_task")
        if damped and damped["max_difference"] is not None:
            text += (
                f"; with it as rrc-pin's DampingTask({damped['weight']:g}): "
                f"{damped['max_difference']:.1g} rad/s"
            )
        text += "); pink's differ at first order in dt (a pose target, see docs/benchmarks.md)."
    info = results["placo"].get("info")
    if info:
        text += (
            f" PlaCo {info['placo']} (Pinocchio {info['pinocchio']}, {results['placo']['note']})."
        )
    else:
        text += f" {results['placo']['note']}."
    text += (
        f" Measured on {m['cpu']} ({m['cores']} cores), Pinocchio {m['pinocchio']}, "
        f"pink {m.get('pink')}"
    )
    load = results.get("load_average")
    if load:
        text += (
            f", load average {load['start'][0]:.2f} at the start, {load['end'][0]:.2f} at the end"
        )
    return text + "."


def docs_section(results: dict[str, Any]) -> str:
    """Every table of the tasks benchmark, for docs/benchmarks.md."""
    s, t = results["settings"], results["trajectory"]
    lines = [
        f"baxter ({results['nq']} joints: head pan and two 7-joint arms, fingers fixed), "
        f"frame tasks on {', '.join(f'`{f}`' for f in results['frames'])} with their own "
        f"random twists (new every {s['segment']} steps) and a posture task toward neutral "
        f"(k = {s['posture_gain']:g}/s), {t['steps']} steps recorded by {t['recorded_by']}, "
        f"dt = {1000 * s['dt']:g} ms; a bound is active in rrc-pin weighted's answer at "
        f"{100 * t['active_fraction']:.1f}% of the steps. Costs: pink's frame tasks "
        f"{s['frame_cost']:g} (position and orientation) and posture {s['posture_cost']:g}; pink "
        "squares its costs (|W (J Δq + e)|^2, W = diag(cost)), rrc-pin's and PlaCo's weights "
        f"multiply the squared residual, so they get the squares: frame {s['weights']['frame']:g},"
        f" posture {s['weights']['posture']:g}.",
        "",
    ]
    for note in results.get("notes", []):
        lines += [f"- {note}", ""]
    placo = results["placo"]
    if placo.get("info"):
        i, c = placo["info"], placo["checks"]
        lines += [
            f"PlaCo {i['placo']} on Pinocchio {i['pinocchio']}, numpy {i['numpy']}, Python "
            f"{i['python']} ({placo['note']}; "
            + (
                f"both processes pinned to CPU {placo['pinned_to_cpu']}"
                if placo["pinned_to_cpu"] is not None
                else "no pinning"
            )
            + "). Its model against rrc-pin's: task-frame poses within "
            f"{c['max_pose_difference']:.1g} m at 20 random configurations, position limits "
            f"within {c['max_position_limit_difference']:.1g} rad, velocity limits within "
            f"{c['max_velocity_limit_difference']:.1g} rad/s.",
            "",
        ]
    for mode in MODES:
        lines += mode_table(results["modes"][mode], mode, {"pink": "baseline", "PlaCo": "placo"})
    stats = results["rrc_pin"]["tight"]
    statuses = sorted({x for r in stats.values() for x in r["status"]})
    lines += [
        "How rrc-pin's steps were answered (tight loop):",
        "",
        "| contender | " + " | ".join(statuses) + " | backend share | bound active | "
        "failed attempts |",
        "| --- |" + " ---: |" * (len(statuses) + 3),
    ]
    for label, r in stats.items():
        lines.append(
            f"| {label} | "
            + " | ".join(str(r["status"].get(x, 0)) for x in statuses)
            + f" | {100 * r['backend_share']:.1f}% | {100 * r['active_fraction']:.1f}% | "
            f"{r['with_attempts']} |"
        )
    lines += ["", *_equivalence_lines(results["equivalence"])]
    for label, p in results.get("profiles", {}).items():
        lines += profile_table(p, label)
    return "\n".join(lines)


def _equivalence_lines(eq: dict[str, Any]) -> list[str]:
    lines = [
        f"Same answers where nothing is constrained ({eq['free_steps']} steps where rrc-pin "
        f"weighted's answer is the box-free optimum more than {eq['free_margin']:g} rad/s "
        "inside every bound; each peer compared at those where its own answer is too): "
        "largest and median, over the steps, of the largest joint-rate difference from "
        "rrc-pin weighted's [rad/s].",
        "",
        "| peer | steps | max difference | median difference | the same problem? |",
        "| --- | ---: | ---: | ---: | --- |",
    ]
    for label, p in eq["peers"].items():
        same = (
            ("yes, but for PlaCo's regularisation" if label == PLACO else "yes")
            if p["same_problem"]
            else ("no: a pose target (log6 error, Jlog6 rows), the same to first order in dt")
        )
        lines.append(
            f"| {label} | {p['steps']} | {_g(p['max_difference'])} | "
            f"{_g(p['median_difference'])} | {same} |"
        )
        damped = p.get("with_damping_task")
        if damped:
            lines.append(
                f"| {label} vs rrc-pin weighted + DampingTask({damped['weight']:g}) | "
                f"{p['steps']} | {_g(damped['max_difference'])} | "
                f"{_g(damped['median_difference'])} | yes: PlaCo's default regularisation "
                f"{damped['weight']:g} |Δq|^2 is this DampingTask in rates |"
            )
    conv = eq.get("pink_step_sizes", {})
    if conv.get("pink"):
        hs = conv["h"]
        lines += [
            "",
            f"pink at smaller steps h (targets moved by twist * h, posture gain k h; "
            f"{conv['steps']} of the unconstrained steps): largest joint-rate difference from "
            "rrc-pin weighted's [rad/s], and its order in h (fitted over the three largest h). "
            "With an exact backend pink's pose-target problem tends to the velocity problem as "
            "h -> 0, at first order; the others stop at their solver tolerance, which pink "
            "applies to Δq = qdot h.",
            "",
            "| pink backend | " + " | ".join(f"h = {h:g} s" for h in hs) + " | order |",
            "| --- |" + " ---: |" * (len(hs) + 1),
        ]
        for label, c in conv["pink"].items():
            order = "-" if c["order"] is None else f"{c['order']:.2f}"
            lines.append(
                f"| {label} | " + " | ".join(_g(d) for d in c["max_difference"]) + f" | {order} |"
            )
    return [*lines, ""]


def _g(value: float | None) -> str:
    return "-" if value is None else f"{value:.2g}"


def plot(results: dict[str, Any], path: Path) -> bool:
    """Median step time per contender and mode (bars), p99 as a tick; False without matplotlib."""
    rows = {mode: results["modes"][mode]["contenders"] for mode in MODES}
    title = f"{results['robot']}: two frame tasks and a posture, one step"
    note = QUICK_NOTE if is_quick(results) else None
    return timing_chart([(rows, title)], path, (8, 0.5 * len(rows[MODES[0]]) + 1.5), note=note)
