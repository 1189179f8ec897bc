"""Nguyen & Zhou's control schemes against the baselines, on Pinocchio dynamics, both paper arms.

Run from a checkout: ``python benchmarks/bench_control_schemes.py --out DIR`` writes
``control_schemes.json`` and ``control_schemes.png`` to DIR (``--record``: to
``benchmarks/results/``; ``--quick``: short scenarios, a smoke test); ``rrc-pin bench --only
control_schemes`` runs it, and ``benchmarks/update_readme.py`` renders the tables into
``docs/control_schemes.md`` (scenarios) and ``docs/benchmarks.md`` (step time).

For barker6 and rrc_k1607 (scenarios and gains in :mod:`rrc_pin.dynamics.scenarios`):

- ``tracking``: fixed-gain PD (+ nominal gravity), computed torque (RNEA, nominal model),
  joint-space adaptive PD (Fig. 11), Cartesian adaptive PD (Fig. 12) on a 3 s hand path with
  a 2.5 kg payload picked up at 2 s; tracking RMS and max error, orientation error, torque
  peaks, and the payload transient (deviation from the same run without the change, time to
  stay within 1 mm);
- ``force``: position-based force with the two baselines (the path pushed 2 mm into the plane,
  right for 1e4 N/m only), hybrid control with fixed gains and with adapted gains (Fig. 13),
  20 N into horizontal planes of 1e3, 1e4 and 1e5 N/m and into a 1e4 N/m plane tilted by
  30 deg about the base x axis, while moving along them;
- step time: every controller with its own simulator (friction on, no plane) following the
  tracking path's joint reference, interleaved: at every 1 kHz tick each controller + simulator
  step runs once, in an order shuffled per tick; median, p10, p90, p99 [us] of the step
  (``torques`` then ``Simulator.step``; the reference is computed untimed), the ratio to the
  fixed-gain PD's step (its time over the controller's) and the real-time factor (1 ms over
  the median step). BLAS threads pinned to 1.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402
from script import QUICK_NOTE, arguments, make_parser, measure, pyplot, write  # noqa: E402
from timing import add_ratios, progress, statistics, stats_cells  # noqa: E402

import rrc_pin  # noqa: E402
from rrc_pin.dynamics import scenarios  # noqa: E402
from rrc_pin.dynamics.reference import HandPath, JointTrajectory  # noqa: E402
from rrc_pin.dynamics.simulator import Simulator  # noqa: E402

ARMS = ("barker6", "rrc_k1607")
PLANES = ((1e3, 0.0), (1e4, 0.0), (1e5, 0.0), (1e4, 30.0))
"""(stiffness [N/m], tilt about the base x axis [deg]) of the force runs."""
QUICK_PLANES = ((1e4, 0.0),)
BASELINE = "fixed_pd"
"""The step-time baseline: the simplest law in the same harness."""
STEPS, QUICK_STEPS = 3000, 300
"""1 kHz ticks of the step-time part, per arm."""
TRACKING = {"duration": 4.0, "change_at": 2.0, "segment": 1.0}
QUICK_TRACKING = {"duration": 1.0, "change_at": 0.5, "segment": 0.5}
"""The tracking scenario's times [s]: run, payload picked up, path segment (recorded in the
JSON's settings; results recorded before they were have the full run's)."""


def tracking_settings(result: dict[str, Any]) -> dict[str, float]:
    """The tracking run's times [s] and payload [kg] of a result (older JSON: the full run's)."""
    settings = result["settings"].get("tracking", TRACKING)
    return {"payload_kg": scenarios.PAYLOAD.mass, **settings}


def recovery_text(row: dict[str, Any], settings: dict[str, float]) -> str:
    """The recovery time [s], or "> T" where the deviation was still above 1 mm at the end
    (T: the run's time after the change, the longest recovery it can see)."""
    if row["recovery_s"] == float("inf"):
        return f"> {settings['duration'] - settings['change_at']:.2f}"
    return f"{row['recovery_s']:.2f}"


def bench(quick: bool) -> dict[str, Any]:
    """Every scenario, controller and arm; the traces of barker6 for the plot."""
    tracking_options = QUICK_TRACKING if quick else TRACKING
    force_options = {"duration": 1.0} if quick else {"duration": 3.0}
    rows: list[dict[str, Any]] = []
    traces: dict[str, Any] = {}
    for arm_name in ARMS:
        arm = rrc_pin.load(arm_name)
        for name in scenarios.TRACKING_CONTROLLERS:
            outcome = scenarios.tracking(arm, name, **tracking_options)
            rows.append(
                {"arm": arm_name, "scenario": "tracking", "controller": name, **outcome.metrics}
            )
            print(f"{arm_name:10s} tracking  {name:22s} {_brief(outcome.metrics)}", flush=True)
            if arm_name == "barker6":
                rec = outcome.record
                traces[f"tracking/{name}"] = {
                    "t": rec.t[::10].tolist(),
                    "error_mm": (1e3 * np.linalg.norm(rec.pose_error[::10, :3], axis=1)).tolist(),
                }
        for stiffness, tilt in QUICK_PLANES if quick else PLANES:
            for name in scenarios.FORCE_CONTROLLERS:
                outcome = scenarios.force(
                    arm, name, stiffness=stiffness, tilt=np.deg2rad(tilt), **force_options
                )
                rows.append(
                    {
                        "arm": arm_name,
                        "scenario": "force",
                        "stiffness": stiffness,
                        "tilt_deg": tilt,
                        "controller": name,
                        **outcome.metrics,
                    }
                )
                print(
                    f"{arm_name:10s} force {stiffness:7.0e} {tilt:2.0f} deg {name:18s} "
                    f"{_brief(outcome.metrics)}",
                    flush=True,
                )
                if arm_name == "barker6" and stiffness == 1e4 and tilt == 0.0:
                    rec = outcome.record
                    traces[f"force/{name}"] = {
                        "t": rec.t[::10].tolist(),
                        "force_N": (-rec.force[::10, 2]).tolist(),
                    }
    return {"rows": rows, "traces": traces, "tracking": tracking_options}


def _brief(m: dict[str, float]) -> str:
    keys = ("position_rms_mm", "position_max_mm", "recovery_s", "force_rms_N", "real_time_factor")
    return " ".join(
        f"{k}={m[k]:.3g}" if m[k] != float("inf") else f"{k}=not within the run"
        for k in keys
        if k in m
    )


def markdown(result: dict[str, Any]) -> str:
    """The docs section: the two tables and the timing, from a recorded result."""
    rows = result["rows"]
    tracking = tracking_settings(result)
    lines = [
        f"### Tracking with a sudden payload change ({tracking['payload_kg']:g} kg at "
        f"t = {tracking['change_at']:g} s of {tracking['duration']:g} s)",
        "",
    ]
    if result.get("quick"):
        lines += [
            "**Quick run (a smoke test, not a result):** the scenarios are shortened; a "
            "recovery longer than the little time left after the change cannot be seen.",
            "",
        ]
    lines += [
        "Recovery: the time from the change until the payload deviation stays within 1 mm; "
        f"> {tracking['duration'] - tracking['change_at']:g}: still above it when the run ends.",
        "",
        "| arm | controller | RMS [mm] | max [mm] | orient. max [mrad] | payload dev. peak "
        "[mm] | mean 1 s [mm] | at end [mm] | recovery [s] | torque peaks [N m] |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for r in (r for r in rows if r["scenario"] == "tracking"):
        rec = recovery_text(r, tracking)
        lines.append(
            f"| {r['arm']} | {r['controller']} | {r['position_rms_mm']:.2f} | "
            f"{r['position_max_mm']:.2f} | {r['orientation_max_mrad']:.1f} | "
            f"{r['payload_deviation_peak_mm']:.2f} | {r['payload_deviation_mean_1s_mm']:.2f} | "
            f"{r['payload_deviation_end_mm']:.2f} | {rec} | {_peaks(r)} |"
        )
    lines += [
        "",
        "### Force regulation (20 N into the plane) while moving along it",
        "",
        "Force errors along the plane's normal after 0.5 s of settling; in-plane tracking error "
        "over the run. Tilt: the plane turned about the base x axis (0: horizontal).",
        "",
        "| arm | stiffness [N/m] | tilt [deg] | controller | force RMS [N] | force max [N] | "
        "out of contact [s] | in-plane RMS [mm] | in-plane max [mm] | torque peaks [N m] |",
        "|---|---:|---:|---|---:|---:|---:|---:|---:|---|",
    ]
    for r in (r for r in rows if r["scenario"] == "force"):
        lines.append(
            f"| {r['arm']} | {r['stiffness']:.0e} | {r['tilt_deg']:.0f} | {r['controller']} | "
            f"{r['force_rms_N']:.2f} | "
            f"{r['force_max_N']:.2f} | {r['contact_lost_s']:.3f} | {r['position_rms_mm']:.2f} | "
            f"{r['position_max_mm']:.2f} | {_peaks(r)} |"
        )
    lines += ["", "### Step time at 1 kHz (controller + simulator, interleaved)", ""]
    lines += [step_table(result), "", machine_line(result), ""]
    return "\n".join(lines)


def step_table(result: dict[str, Any]) -> str:
    """The step times of every controller + simulator, with the ratio to the baseline."""
    lines = [
        f"{result['settings']['steps']:,} ticks of the tracking path per arm, every controller "
        "with its own simulator, interleaved; ratio: the fixed-gain PD's step time over the "
        "controller's; real-time factor: 1 ms over the median step.",
        "",
        "| arm | controller | median [us] | p10 | p90 | p99 | vs fixed_pd (median) | (p99) | "
        "real-time factor (median) |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for arm in result["timing"]:
        for name, r in arm["contenders"].items():
            lines.append(f"| {arm['arm']} | {name} |{stats_cells(r)} {1e3 / r['median_us']:.1f} |")
    return "\n".join(lines)


def machine_line(result: dict[str, Any]) -> str:
    """Where and on what code the result was recorded."""
    m, source = result["machine"], result["source"]
    return (
        f"Machine: {m['cpu']}, {m['cores']} cores (shared: load "
        f"{result['load_average']['start']}), Python {m['python']}, Pinocchio "
        f"{m['pinocchio']}; code {source['commit']}"
        f"{' (modified)' if source.get('uncommitted_changes') else ''}."
    )


def readme_table(result: dict[str, Any]) -> str:
    """Not in the README (update_readme.DOCS_ONLY): the step-time table."""
    return step_table(result)


def docs_section(result: dict[str, Any]) -> str:
    """The docs/benchmarks.md section: the step times; the scenarios' tables are in
    docs/control_schemes.md (:func:`markdown`, rendered from the same JSON)."""
    return (
        "The scenarios (tracking with a payload change, force regulation on planes of several "
        "stiffnesses) and their tables: [control_schemes.md](control_schemes.md), generated "
        "from the same JSON. Step time:\n\n" + step_table(result)
    )


def step_time(arm_name: str, steps: int) -> dict[str, Any]:
    """Every controller + simulator step along the tracking path's reference, interleaved."""
    arm = rrc_pin.load(arm_name)
    q0 = scenarios.start(arm)
    path = HandPath(arm.fk(q0), np.array(scenarios.TRACKING_PATH), 1.0)
    trajectory = JointTrajectory(arm, q0, path, steps * 1e-3)
    loops = {}
    for name in scenarios.CONTROLLERS:
        sim = Simulator(arm, friction=True)
        sim.reset(q0)
        loops[name] = (scenarios.controller(name, arm, q0), sim, [sim.state()])
    times: dict[str, list[float]] = {name: [] for name in loops}
    rng = np.random.default_rng(0)
    clock = time.perf_counter
    wanted = np.zeros(3)
    for _ in range(steps):
        for name in rng.permutation(list(loops)):
            ctl, sim, state = loops[name]
            ref = trajectory.at(state[0].t, wanted)
            start = clock()
            tau = ctl.torques(state[0], ref)
            state[0] = sim.step(tau)
            times[name].append(clock() - start)
    rows = {name: statistics(np.array(t)) for name, t in times.items()}
    add_ratios(rows, BASELINE)
    progress(
        f"{arm_name}: step time "
        + ", ".join(f"{k} {r['median_us']:.0f} us" for k, r in rows.items())
    )
    return {"arm": arm_name, "steps": steps, "baseline": BASELINE, "contenders": rows}


def _peaks(r: dict[str, Any]) -> str:
    peaks = [r[k] for k in sorted(k for k in r if k.startswith("torque_peak_"))]
    return ", ".join(f"{p:.0f}" if p >= 10 else f"{p:.1f}" for p in peaks)


def plot(result: dict[str, Any], path: Path) -> bool:
    """Tool error (tracking) and contact force (force, 1e4 N/m) of barker6 over time."""
    plt = pyplot()
    if plt is None:
        return False
    tracking = tracking_settings(result)
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.6 if result.get("quick") else 4.2))
    for key, trace in result["traces"].items():
        kind, name = key.split("/")
        if kind == "tracking":
            ax1.plot(trace["t"], trace["error_mm"], label=name)
        else:
            ax2.plot(trace["t"], trace["force_N"], label=name)
    ax1.axvline(tracking["change_at"], color="grey", ls=":", lw=1)
    ax1.annotate(f"+{tracking['payload_kg']:g} kg", (tracking["change_at"], 1.0),
                 xycoords=("data", "axes fraction"), xytext=(3, -12),
                 textcoords="offset points", fontsize=8, color="grey")  # fmt: skip
    ax1.set(
        xlabel="t [s]",
        ylabel="tool position error [mm]",
        title=f"barker6: tracking, {tracking['payload_kg']:g} kg picked up at "
        f"{tracking['change_at']:g} s",
    )
    ax2.axhline(20.0, color="grey", ls=":", lw=1)
    ax2.set(
        xlabel="t [s]",
        ylabel="pressing force [N]",
        title="barker6: 20 N on a 1e4 N/m plane while moving",
    )
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    if result.get("quick"):
        fig.suptitle(f"{QUICK_NOTE}: {tracking['duration']:g} s of tracking, 1 s of force",
                     color="firebrick")  # fmt: skip
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def _run(quick: bool, steps: int) -> dict[str, Any]:
    """The scenarios, then the step time; the tracking times go into the settings."""
    scenes = bench(quick)
    settings = {"steps": steps, "baseline": BASELINE, "tracking": scenes.pop("tracking")}
    return {"settings": settings, **scenes, "timing": [step_time(arm, steps) for arm in ARMS]}


def main(argv: list[str] | None = None) -> int:
    args = arguments(make_parser(__doc__, "control_schemes", "short scenarios (smoke test)"), argv)
    steps = QUICK_STEPS if args.quick else STEPS
    result = measure(
        "control_schemes",
        args.quick,
        lambda: _run(args.quick, steps),
        "scipy",
    )
    write(args, "control_schemes", result, lambda path: plot(result, path), indent=1)
    print(markdown(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
