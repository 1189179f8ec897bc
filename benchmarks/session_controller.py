"""A 10-minute simulated teleoperation session at 100 Hz on each paper arm and on panda.

Run from a checkout: ``python benchmarks/session_controller.py [--minutes 10] [--out DIR]``.
Random operator commands (``random_commands``: hand-frame twists held 0.5 s, 0.05 m/s and
0.2 rad/s per axis, 10 % pauses) drive a default ``Controller`` with the drift correction and
without it (same commands). Reported per arm: position and velocity limit excess, NaN, the
pose drift (max, and how fast it grows between resets of the reference [mm/min]), the
statuses. With ``--out`` the numbers go to ``DIR/session.json``.
"""

from __future__ import annotations

import argparse
import itertools
import json
import time
from pathlib import Path

import numpy as np

import rrc_pin
from rrc_pin.control import Controller, DriftCorrection
from rrc_pin.control.controller import REANCHOR
from rrc_pin.control.random_operator import random_commands

STARTS = {
    "barker6": np.deg2rad([20.0, 30.0, 60.0, 10.0, 40.0, 0.0]),
    "rrc_k1607": np.array([0.0, 0.5, 0.0, 1.2, 0.0, 0.6, 0.0]),
    "kr5_3r": np.array([0.0, 0.785, -0.785]),
    "panda": np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.8, 0.7]),
}


def session(name: str, minutes: float, drift: DriftCorrection | None) -> dict[str, object]:
    arm = rrc_pin.load(name)
    ctl = Controller(arm, q0=STARTS[name], drift=drift)
    commands = random_commands(np.random.default_rng(2026), 60.0 * minutes, ctl.dt)
    start = time.perf_counter()
    for twist in commands:
        ctl.step(twist)
    seconds = time.perf_counter() - start
    log = ctl.log
    q, qdot, t = log.column("q"), log.column("qdot"), log.column("t")
    d_pos, d_rot = log.column("drift_position"), log.column("drift_rotation")
    statuses, counts = np.unique(log.column("status"), return_counts=True)
    # Growth: the reference is reset to the reached pose whenever the resolver changes the
    # command's direction (damped, singular, ...), so the drift restarts from 0 there; over
    # every span without a reset longer than 10 s, the drift at its end per minute of span.
    resets = np.flatnonzero(np.isin(log.column("status"), REANCHOR))
    edges = np.concatenate([[0], resets, [len(log) - 1]])
    spans = [(a, b) for a, b in itertools.pairwise(edges) if b - a > 1000]
    growth = [d_pos[b - 1] / ((t[b - 1] - t[a]) / 60.0) for a, b in spans]
    return {
        "steps": len(log),
        "wall_seconds": seconds,
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=10.0)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    result: dict[str, dict[str, object]] = {}
    for name in STARTS:
        for label, drift in (("corrected", DriftCorrection()), ("uncorrected", None)):
            r = session(name, args.minutes, drift)
            result[f"{name}/{label}"] = r
            print(f"{name:10s} {label:11s} {r['steps']} steps in {r['wall_seconds']:.0f} s: "
                  f"excess pos {r['position_excess']:.1e} vel {r['velocity_excess']:.1e}, "
                  f"NaN {r['nan']}, drift max {r['drift_max_mm']:.3f} mm "
                  f"{r['drift_rotation_max_mrad']:.3f} mrad, final {r['drift_final_mm']:.3f} mm, "
                  f"growth {r['drift_growth_mm_per_min']} mm/min "
                  f"({r['drift_growth_spans']} spans > 10 s)", flush=True)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "session.json").write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
