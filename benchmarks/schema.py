"""The shape every benchmark's JSON must have (tests/test_bench_schema.py checks it).

:func:`problems` lists what is missing or malformed in one result file, as sentences naming
the key; an empty list means the file follows the schema. Common to every file: the
benchmark's name, the machine (CPU, cores, Python, numpy, Pinocchio), the code measured (a
hash of the sources). Timing benchmarks: per case the median, p10, p90 and p99 [us] and at
least one ratio to a baseline measured in the same run (``vs_<baseline>_median`` and
``_p99``); the closed forms: both timings with their spread and the speed-ups; the study:
an error and a fitted order per quantity; the controller: its tick rows, and per session the
tick times, NaN, limit excess and drift; the control schemes: the scenarios' errors and the
step-time rows; the cells: per cell a tick without and with collision constraints (or the
refusal), each with its statistics and loop rate. ``schema`` 2 (written by the closed-form
benchmark since it records the spread of its timings) also requires the closed forms' p10,
p90, p99; files without the key are version 1. The resolver and tasks benchmarks
(``schema`` 3, the peers side by side in one process): each peer's status is ``ran`` (its
rows present in every mode) or "not in this environment..." (no row of it), every peer ran
in a full run, each peer's kinematics within :data:`GAP_TOL` of Pinocchio's, and every
contender's answers judged (``quality``).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

KNOWN = (
    "closed_form", "resolver", "tasks", "study", "scaling", "controller", "control_schemes", "maps",
    "collision", "collision_soak", "cells",
)
CELLS = ("gsfc_dual", "yeh_tripod")
"""The cells the cell benchmark times (issue 30)."""
MACHINE = ("cpu", "cores", "python", "numpy", "pinocchio")
STATS = ("median_us", "p10_us", "p90_us", "p99_us")
GAP_TOL = 1e-9
"""Largest difference of a peer's kinematics from Pinocchio's accepted beside its rows."""
PEERS = {"PlaCo": "PlaCo", "pink": "pink", "mink": "mink", "Drake": "Drake"}
"""Peer: the start of its rows' labels."""
NOT_HERE = "not in this environment"
QUALITY = ("reachable_steps", "veer_steps", "veer_max_deg", "too_fast_steps")
"""What every contender's answers report (benchmarks/quality.py)."""


def problems(results: dict[str, Any]) -> list[str]:
    """What does not follow the schema in one benchmark's JSON (empty: all follows)."""
    out = []
    name = results.get("benchmark")
    if name not in KNOWN:
        return [f"benchmark: expected one of {KNOWN}, got {name!r}"]
    machine = results.get("machine", {})
    out += [f"machine.{k}: missing" for k in MACHINE if machine.get(k) in (None, "")]
    if not results.get("source", {}).get("source_sha256"):
        out.append("source.source_sha256: missing")
    check = {
        "closed_form": _closed_form,
        "resolver": _resolver,
        "tasks": _tasks,
        "study": _study,
        "scaling": _scaling,
        "controller": _controller,
        "control_schemes": _control_schemes,
        "maps": _maps,
        "collision": _collision,
        "collision_soak": _collision_soak,
        "cells": _cells,
    }[name]
    out += list(check(results))
    return out


def _positive(value: Any) -> bool:
    return isinstance(value, (int, float)) and math.isfinite(value) and value > 0


def _rows(where: str, mode: dict[str, Any]) -> Iterator[str]:
    rows = mode.get("contenders") or {}
    if not rows:
        yield f"{where}.contenders: empty"
    for label, row in rows.items():
        for key in STATS:
            if not _positive(row.get(key)):
                yield f"{where}.{label}.{key}: expected a positive time"
        if not any(k.startswith("vs_") and k.endswith("_median") for k in row):
            yield f"{where}.{label}: no ratio to a baseline (vs_<baseline>_median)"


def _closed_form(results: dict[str, Any]) -> Iterator[str]:
    arms = results.get("arms") or []
    if not arms:
        yield "arms: empty"
    for arm in arms:
        where = f"arms.{arm.get('arm')}"
        scalar, batch = arm.get("scalar", {}), arm.get("batch", {})
        for key in ("closed_form_us", "pinocchio_us", "speedup"):
            if not _positive(scalar.get(key)):
                yield f"{where}.scalar.{key}: expected a positive number"
        for who in ("closed_form", "pinocchio") if results.get("schema", 1) >= 2 else ():
            for p in ("p10", "p90", "p99"):
                if not _positive(scalar.get(f"{who}_{p}_us")):
                    yield f"{where}.scalar.{who}_{p}_us: expected a positive time"
        for key in ("n", "closed_form_per_s", "loop_per_s", "speedup"):
            if not _positive(batch.get(key)):
                yield f"{where}.batch.{key}: expected a positive number"


def _resolver(results: dict[str, Any]) -> Iterator[str]:
    arms = results.get("arms") or []
    if not arms:
        yield "arms: empty"
    for arm in arms:
        yield from _comparison(f"arms.{arm.get('arm')}", arm, results)


def _tasks(results: dict[str, Any]) -> Iterator[str]:
    yield from _comparison("tasks", results, results)


def _comparison(where: str, part: dict[str, Any], results: dict[str, Any]) -> Iterator[str]:
    """One workload of the peers comparison: its rows, its peers' status and kinematics, the
    answers' quality."""
    modes = part.get("modes") or {}
    if not modes:
        yield f"{where}.modes: empty"
    for mode, m in modes.items():
        yield from _rows(f"{where}.modes.{mode}", m)
    status = results.get("peers")
    if not isinstance(status, dict) or set(status) != set(PEERS):
        yield f"peers: expected the status of {', '.join(PEERS)}"
        return
    for peer, prefix in PEERS.items():
        ran = status[peer] == "ran"
        if not ran and not str(status[peer]).startswith(NOT_HERE):
            yield f"peers.{peer}: expected 'ran' or '{NOT_HERE}: ...', got {status[peer]!r}"
        if not ran and not results.get("quick"):
            yield f"peers.{peer}: a full run needs every peer ({status[peer]})"
        for mode, m in modes.items():
            rows = [k for k in m.get("contenders", {}) if k.startswith(prefix)]
            if ran and not rows:
                yield f"{where}.modes.{mode}: {peer} ran but has no row"
            if not ran and rows:
                yield f"{where}.modes.{mode}: rows of {peer}, which did not run: {rows}"
        gap = (part.get("kinematics_gaps") or {}).get(peer)
        if ran and prefix != "pink" and not (gap and max(gap.values()) <= GAP_TOL):
            yield f"{where}.kinematics_gaps.{peer}: missing or above {GAP_TOL}"
    judged = part.get("quality") or {}
    for label in (modes.get("tight") or {}).get("contenders", {}):
        for key in QUALITY:
            if not _finite(judged.get(label, {}).get(key)):
                yield f"{where}.quality.{label}.{key}: expected a number"


def _within(value: Any, tol: float) -> bool:
    return value is None or (_finite(value) and value <= tol)


def _study(results: dict[str, Any]) -> Iterator[str]:
    dts = results.get("dts") or []
    if len(dts) < 2:
        yield "dts: expected at least two sampling times"
    errors, orders = results.get("errors") or {}, results.get("orders") or {}
    if not errors:
        yield "errors: empty"
    for key, values in errors.items():
        if len(values) != len(dts) or not all(
            isinstance(v, (int, float)) and math.isfinite(v) and v >= 0 for v in values
        ):
            yield f"errors.{key}: expected {len(dts)} finite errors >= 0"
        if not isinstance(orders.get(key), (int, float)):
            yield f"orders.{key}: missing"
    if "trajectory" not in results:
        yield "trajectory: missing"


def _scaling(results: dict[str, Any]) -> Iterator[str]:
    batch = results.get("batch") or []
    if not batch:
        yield "batch: empty"
    for curve in batch:
        where = f"batch.{curve.get('arm')}"
        points = curve.get("points") or []
        if not points:
            yield f"{where}.points: empty"
        for point in points:
            for key in ("n", "per_config_us", "p10_us", "p90_us", "p99_us", "vs_loop"):
                if not _positive(point.get(key)):
                    yield f"{where}.n={point.get('n')}.{key}: expected a positive number"
    dof = results.get("dof") or []
    if not dof:
        yield "dof: empty"
    for row in dof:
        for key in (*STATS, "floor_median_us", "vs_floor_median"):
            if not _positive(row.get(key)):
                yield f"dof.{row.get('arm')}.{key}: expected a positive number"
        ctl = row.get("controller")  # recorded since the controller exists (issue 8)
        for key in (*STATS, "floor_median_us", "vs_floor_median") if ctl is not None else ():
            if not _positive(ctl.get(key)):
                yield f"dof.{row.get('arm')}.controller.{key}: expected a positive number"


def _controller(results: dict[str, Any]) -> Iterator[str]:
    arms = results.get("arms") or []
    if not arms:
        yield "arms: empty"
    for arm in arms:
        where = f"arms.{arm.get('arm')}"
        yield from _rows(where, arm)
        for key in ("overhead_median", "overhead_p99"):
            if not _finite(arm.get(key)):
                yield f"{where}.{key}: expected a number"
    sessions = results.get("sessions") or []
    if not sessions:
        yield "sessions: empty"
    for s in sessions:
        where = f"sessions.{s.get('arm')}.{'on' if s.get('drift_correction') else 'off'}"
        for key in STATS:
            if not _positive(s.get("tick", {}).get(key)):
                yield f"{where}.tick.{key}: expected a positive time"
        if not isinstance(s.get("nan"), bool):
            yield f"{where}.nan: expected true or false"
        for key in ("position_excess", "velocity_excess", "drift_max_mm", "drift_final_mm"):
            if not (_finite(s.get(key)) and s[key] >= 0):
                yield f"{where}.{key}: expected a finite number >= 0"
        if not _positive(s.get("steps")):
            yield f"{where}.steps: expected a positive number"


def _control_schemes(results: dict[str, Any]) -> Iterator[str]:
    rows = results.get("rows") or []
    if not rows:
        yield "rows: empty"
    for r in rows:
        where = f"rows.{r.get('arm')}.{r.get('scenario')}.{r.get('controller')}"
        for key in ("position_rms_mm", "position_max_mm") + (
            ("force_rms_N",) if r.get("scenario") == "force" else ()
        ):
            if not (_finite(r.get(key)) and r[key] >= 0):
                yield f"{where}.{key}: expected a finite number >= 0"
    timing = results.get("timing") or []
    if not timing:
        yield "timing: empty"
    for arm in timing:
        yield from _rows(f"timing.{arm.get('arm')}", arm)


def _maps(results: dict[str, Any]) -> Iterator[str]:
    cases = results.get("cases") or []
    if not cases:
        yield "cases: empty"
    for c in cases:
        where = f"cases.{c.get('label')}"
        for key in ("per_core_per_s", "wall_per_s", "pinocchio_loop_per_s", "vs_pinocchio_loop"):
            if not _positive(c.get(key)):
                yield f"{where}.{key}: expected a positive number"
    scaling = results.get("scaling") or {}
    for key in ("one_worker_s", "two_workers_s", "speedup"):
        if not _positive(scaling.get(key)):
            yield f"scaling.{key}: expected a positive number"
    projection = results.get("projection") or {}
    if not projection or not all(
        _positive(v) for k, v in projection.items() if k not in ("assumes", "samples", "cores")
    ):
        yield "projection: expected positive times"
    for key in ("one_point_us", "batch_us_per_point"):
        if not _positive((results.get("query") or {}).get(key)):
            yield f"query.{key}: expected a positive time"
    confirmed = (results.get("audit") or {}).get("confirmed")
    if not (_finite(confirmed) and 0.0 <= confirmed <= 1.0):
        yield "audit.confirmed: expected a share in [0, 1]"


def _collision(results: dict[str, Any]) -> Iterator[str]:
    rows = results.get("rows") or []
    if not rows:
        yield "rows: empty"
    for r in rows:
        where = f"rows.{r.get('contender')}.{r.get('pairs')}"
        if not _positive(r.get("pairs")):
            yield f"{where}.pairs: expected a positive number"
        for mode in ("tight", "interleaved"):
            stats = (r.get("modes") or {}).get(mode) or {}
            for key in ("median_us", "cpu_p99_us"):
                if not _positive(stats.get(key)):
                    yield f"{where}.modes.{mode}.{key}: expected a positive number"
        if not isinstance(r.get("min_distance_m"), (int, float)):
            yield f"{where}.min_distance_m: expected a number"


def _collision_soak(results: dict[str, Any]) -> Iterator[str]:
    """The starts (each with its fallback count) and the sessions (each with its ticks,
    statuses and fallback ticks), and the summary's counts."""
    if not results.get("starts"):
        yield "starts: empty"
    for k, r in enumerate(results.get("starts") or []):
        if not (isinstance(r.get("fallbacks"), int) and r["fallbacks"] >= 0):
            yield f"starts.{k}.fallbacks: expected a count"
    if not results.get("sessions"):
        yield "sessions: empty"
    for s in results.get("sessions") or []:
        where = f"sessions.{s.get('scene')}.{s.get('turning')}"
        if not _positive(s.get("ticks")):
            yield f"{where}.ticks: expected a positive number"
        if not s.get("statuses"):
            yield f"{where}.statuses: empty"
        if not (isinstance(s.get("fallback_ticks"), int) and s["fallback_ticks"] >= 0):
            yield f"{where}.fallback_ticks: expected a count"
    summary = results.get("summary") or {}
    for key in ("starts", "locked", "session_fallback_ticks"):
        if not (isinstance(summary.get(key), int) and summary[key] >= 0):
            yield f"summary.{key}: expected a count"


def _cells(results: dict[str, Any]) -> Iterator[str]:
    """Per cell a tick without and with collision constraints (or the refusal, said)."""
    rows = results.get("rows") or []
    not_run = results.get("not_run")
    if not isinstance(not_run, list):
        yield "not_run: expected a list (empty when every case ran)"
        not_run = []
    for n in not_run:
        if not (isinstance(n.get("reason"), str) and n["reason"]):
            yield f"not_run.{n.get('cell')}.{n.get('limits')}.reason: expected the refusal"
    for cell in CELLS:
        mine = [r for r in rows if r.get("cell") == cell]
        if not any(r.get("collision") is False for r in mine):
            yield f"rows.{cell}: no tick without collision constraints"
        if not any(r.get("collision") is True for r in mine) and not any(
            n.get("cell") == cell for n in not_run
        ):
            yield f"rows.{cell}: no tick with collision constraints, and no reason in not_run"
    for r in rows:
        where = f"rows.{r.get('cell')}.{r.get('limits')}"
        for key in (*STATS, "cpu_p99_us", "rate_hz_median", "rate_hz_p99", "ticks"):
            if not _positive(r.get(key)):
                yield f"{where}.{key}: expected a positive number"
        for key in ("median_us", "cpu_p99_us"):
            if not _positive((r.get("interleaved") or {}).get(key)):
                yield f"{where}.interleaved.{key}: expected a positive number"
        if not isinstance(r.get("collision"), bool):
            yield f"{where}.collision: expected true or false"
        if not r.get("statuses"):
            yield f"{where}.statuses: empty"
        if r.get("collision") is True:
            if not (isinstance(r.get("collision_ticks"), int) and r["collision_ticks"] >= 0):
                yield f"{where}.collision_ticks: expected a count"
            distance = r.get("min_distance_m")
            if not (distance is None or _finite(distance)):
                yield f"{where}.min_distance_m: expected a number or null (no rows)"


def _finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def main(argv: list[str] | None = None) -> int:
    """``python benchmarks/schema.py DIR``: check every ``*.json`` of a results folder; exit
    code 1 (and one line per problem) if one does not follow the schema."""
    import argparse
    import json
    from pathlib import Path

    parser = argparse.ArgumentParser(description=main.__doc__)
    parser.add_argument("folder", type=Path)
    args = parser.parse_args(argv)
    files = sorted(args.folder.glob("*.json"))
    bad = 0
    for path in files:
        for problem in problems(json.loads(path.read_text())):
            print(f"{path.name}: {problem}")
            bad += 1
    print(f"{len(files)} result files, {bad} problems")
    return 1 if bad or not files else 0


if __name__ == "__main__":
    raise SystemExit(main())
