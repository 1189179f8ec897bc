"""Nguyen & Zhou's control schemes against the baselines, on Pinocchio dynamics, both paper arms.

Run from a checkout: ``python benchmarks/bench_control_schemes.py --record`` writes
``benchmarks/results/control_schemes.json`` and ``control_schemes.png`` and regenerates
``docs/control_schemes.md``; ``--out DIR`` writes the JSON and PNG to DIR instead (no docs),
``--quick`` runs short scenarios (a smoke test; nothing recorded unless asked).

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
- timing: controller and simulator time per 1 kHz step (means over each run), and the
  real-time factor (simulated time / wall time of controller + simulator).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np
from machine import load_average, machine_info, source_state

import rrc_pin
from rrc_pin.dynamics import scenarios

ARMS = ("barker6", "rrc_k1607")
PLANES = ((1e3, 0.0), (1e4, 0.0), (1e5, 0.0), (1e4, 30.0))
"""(stiffness [N/m], tilt about the base x axis [deg]) of the force runs."""
RESULTS = Path(__file__).resolve().parent / "results"
DOC = Path(__file__).resolve().parents[1] / "docs" / "control_schemes.md"
START, END = "<!-- control-schemes:start -->", "<!-- control-schemes:end -->"


def bench(quick: bool) -> dict[str, Any]:
    """Every scenario, controller and arm; the traces of barker6 for the plot."""
    tracking_options = (
        {"duration": 1.0, "change_at": 0.5, "segment": 0.5} if quick else {"duration": 4.0}
    )
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
        for stiffness, tilt in PLANES:
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
    return {"rows": rows, "traces": traces}


def _brief(m: dict[str, float]) -> str:
    keys = ("position_rms_mm", "position_max_mm", "recovery_s", "force_rms_N", "real_time_factor")
    return " ".join(f"{k}={m[k]:.3g}" for k in keys if k in m)


def markdown(result: dict[str, Any]) -> str:
    """The docs section: the two tables and the timing, from a recorded result."""
    rows = result["rows"]
    lines = [
        "### Tracking with a sudden payload change (2.5 kg at t = 2 s)",
        "",
        "| arm | controller | RMS [mm] | max [mm] | orient. max [mrad] | payload dev. peak "
        "[mm] | mean 1 s [mm] | at end [mm] | recovery [s] | torque peaks [N m] |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for r in (r for r in rows if r["scenario"] == "tracking"):
        rec = "never" if r["recovery_s"] == float("inf") else f"{r['recovery_s']:.2f}"
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
    lines += [
        "",
        "### Step time at 1 kHz (controller + simulator, means over the tracking runs)",
        "",
        "| arm | controller | step [us] | real-time factor |",
        "|---|---|---:|---:|",
    ]
    for r in (r for r in rows if r["scenario"] == "tracking"):
        lines.append(
            f"| {r['arm']} | {r['controller']} | {r['step_us']:.0f} | {r['real_time_factor']:.2f} |"
        )
    m = result["machine"]
    lines += [
        "",
        f"Machine: {m['cpu']}, {m['cores']} cores (shared: load {result['load']}), Python "
        f"{m['python']}, Pinocchio {m['pinocchio']}; code {result['source']['commit']}"
        f"{' (modified)' if result['source'].get('dirty') else ''}.",
        "",
    ]
    return "\n".join(lines)


def _peaks(r: dict[str, Any]) -> str:
    peaks = [r[k] for k in sorted(k for k in r if k.startswith("torque_peak_"))]
    return ", ".join(f"{p:.0f}" if p >= 10 else f"{p:.1f}" for p in peaks)


def plot(result: dict[str, Any], path: Path) -> bool:
    """Tool error (tracking) and contact force (force, 1e4 N/m) of barker6 over time."""
    try:
        import matplotlib
    except ImportError:
        return False
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(12, 4.2))
    for key, trace in result["traces"].items():
        kind, name = key.split("/")
        if kind == "tracking":
            ax1.plot(trace["t"], trace["error_mm"], label=name)
        else:
            ax2.plot(trace["t"], trace["force_N"], label=name)
    ax1.axvline(2.0, color="grey", ls=":", lw=1)
    ax1.set(
        xlabel="t [s]",
        ylabel="tool position error [mm]",
        title="barker6: tracking, 2.5 kg picked up at 2 s",
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
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def update_doc(section: str) -> None:
    """Put ``section`` between the markers of docs/control_schemes.md."""
    text = DOC.read_text()
    head, rest = text.split(START, 1)
    _, tail = rest.split(END, 1)
    DOC.write_text(f"{head}{START}\n{section}{END}{tail}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--record", action="store_true", help="write results/ and the docs")
    parser.add_argument("--out", type=Path, help="folder for the JSON and PNG")
    parser.add_argument("--quick", action="store_true", help="short scenarios (smoke test)")
    args = parser.parse_args(argv)
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    result = bench(args.quick)
    result.update(
        machine=machine_info("scipy"),
        load=load_average(),
        source=source_state(),
        quick=args.quick,
    )
    section = markdown(result)
    print(section)
    out = RESULTS if args.record else args.out
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "control_schemes.json").write_text(json.dumps(result, indent=1) + "\n")
        drawn = plot(result, out / "control_schemes.png")
        print(f"wrote {out / 'control_schemes.json'}" + (" and the PNG" if drawn else ""))
    if args.record:
        update_doc(section)
        print(f"updated {DOC}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
