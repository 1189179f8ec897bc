"""Readouts: what the operator reads beside the arm, computed from a loop's snapshot.

Barker's operators lost track of the wrist angles against their limits and met large rates
near singularities; the console shows, at the view's rate:

- every joint's angle on a bar spanning its range, red within :data:`NEAR` of a limit
  (amber within twice that), and its rate on a bar against its velocity limit;
- the smallest singular value of the commanded hand's task Jacobian and the singularity near
  (:class:`~rrc_pin.control.singularity.SingularityLabel`: Barker's named conditions on
  ``barker6``, the weak joint and direction elsewhere);
- the resolver's status, method and scale, and the active limits by name;
- a cell's commanded name (its object, its body, a free hand) and, while a closed chain is
  open beyond its bound, ``grip_lost`` or ``contact_lost`` in red (the cell holds).

The numbers come from :func:`read` (the kinematics at the snapshot's q, in the caller's thread:
the loop does not pay for them); the HTML from :func:`joints_html` and :func:`status_html`.
"""

from __future__ import annotations

import html
import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.console.rate import PeriodStats
from rrc_pin.console.snapshot import Snapshot
from rrc_pin.control.singularity import SingularityLabel
from rrc_pin.robot import Robot

Array = npt.NDArray[np.float64]
NEAR = 0.05
"""A joint is drawn red within this fraction of its range from a limit (amber within twice)."""
RED, AMBER, GREEN, GREY = "#d62728", "#ff9f1c", "#2ca02c", "#9aa0a6"


class Readings(NamedTuple):
    """The kinematic readouts at a snapshot.

    Attributes:
        sigma_min: Smallest singular value of the task Jacobian (task rows of the commanded
            hand's, world_aligned) [m/s or rad/s per rad/s].
        singularity: The singularity near, "" if none.
        commanded: The operator's twist in base axes (6,) [m/s, rad/s], or None (released).
        achieved: The twist the rates produce, ``J qdot``, base axes (6,), or None (no step).
        qdot: Joint rates of the tick (nq,) [rad/s], zeros when there was no step.
        pose: The commanded hand's pose (4, 4) [m].
    """

    sigma_min: float
    singularity: str
    commanded: Array | None
    achieved: Array | None
    qdot: Array
    pose: Array


class Reader:
    """Computes :class:`Readings` for one robot (one thread: it keeps a singularity labeller).

    Args:
        robot: The robot the loop drives (any number of tool frames).
    """

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        self.rows = list(range(6)) if robot.nq >= 6 else [0, 1, 2]  # the controller's task rows
        self.label = SingularityLabel(_one_hand(robot, robot.tool_frames[0]))
        self._labels = {robot.tool_frames[0]: self.label}

    def read(self, snapshot: Snapshot, pose: Array) -> Readings:
        """The readings at ``snapshot`` (its q and resolution), ``pose`` its hand's pose."""
        q, hand = snapshot.q, snapshot.hand
        J = self.robot.jacobian(q, "world_aligned", frame=hand)
        J_task = J[self.rows]
        sv: Array = np.asarray(np.linalg.svd(J_task, compute_uv=False), np.float64)
        if hand not in self._labels:
            self._labels[hand] = SingularityLabel(_one_hand(self.robot, hand))
        singularity = self._labels[hand](q, J_task, sv)
        r = snapshot.resolution
        qdot = np.zeros(self.robot.nq) if r is None else np.asarray(r.qdot, np.float64)
        achieved = None if r is None else J @ qdot
        commanded = snapshot.twist
        if commanded is not None:
            commanded = commanded * snapshot.speed
            if snapshot.frame == "local":
                R = pose[:3, :3]
                commanded = np.concatenate([R @ commanded[:3], R @ commanded[3:]])
        return Readings(float(sv[-1]), singularity, commanded, achieved, qdot, pose)


def _one_hand(robot: Robot, hand: str) -> Robot:
    """``robot`` as an arm of tool frame ``hand`` (the closed form knows its hand only)."""
    if robot.tool_frame == hand:
        return robot
    return Robot(robot.model, hand, name=robot.name, source=robot.source, spec=robot.spec)


def nearness(q: float, lower: float, upper: float) -> float:
    """Distance of ``q`` from the nearer limit as a fraction of the range (inf: no range)."""
    if not (math.isfinite(lower) and math.isfinite(upper)) or upper <= lower:
        return math.inf
    return min(q - lower, upper - q) / (upper - lower)


def joint_color(fraction: float) -> str:
    """The bar's colour at ``fraction`` of the range from the nearer limit."""
    if fraction < NEAR:
        return RED
    if fraction < 2 * NEAR:
        return AMBER
    return GREEN


def joints_html(robot: Robot, q: Array, qdot: Array) -> str:
    """One row per joint: name, angle [deg] (or [mm]), a bar in its range, the rate's bar.

    Rows carry ``data-joint`` (its name) and ``data-near`` (``1`` when red), for tests and
    styling.
    """
    rows = []
    for i, name in enumerate(robot.joint_names):
        lo, hi, v = float(robot.lower[i]), float(robot.upper[i]), float(robot.velocity_limit[i])
        near = nearness(float(q[i]), lo, hi)
        color = GREY if math.isinf(near) else joint_color(near)
        where = 50.0 if math.isinf(near) else 100.0 * (q[i] - lo) / (hi - lo)
        rate = 0.0 if not math.isfinite(v) or v <= 0 else min(1.0, abs(float(qdot[i])) / v)
        rate_color = RED if rate > 0.95 else (AMBER if rate > 0.8 else "#5b8def")
        rows.append(
            f'<div class="rrc-joint" data-joint="{html.escape(name)}" '
            f'data-near="{int(color == RED)}" style="display:flex;align-items:center;'
            f'gap:4px;font:11px monospace;margin:1px 0">'
            f'<span style="width:9em;overflow:hidden;white-space:nowrap">{html.escape(name)}</span>'
            f'<span style="width:4.5em;text-align:right">{math.degrees(q[i]):7.1f}&deg;</span>'
            f'<span style="position:relative;flex:1;height:9px;background:#e8e8e8;'
            f'border-radius:2px"><span style="position:absolute;left:{where:.1f}%;top:-2px;'
            f'width:4px;height:13px;margin-left:-2px;background:{color}"></span></span>'
            f'<span style="width:3em;height:9px;background:#e8e8e8;position:relative">'
            f'<span style="position:absolute;left:0;top:0;height:9px;width:{100 * rate:.0f}%;'
            f'background:{rate_color}"></span></span></div>'
        )  # fmt: skip
    return "".join(rows)


def active_names(snapshot: Snapshot) -> list[str]:
    """The active limits of the snapshot's resolution, ``joint:side:kind``."""
    r = snapshot.resolution
    if r is None:
        return []
    return [f"{a.name or a.joint}:{a.side}:{a.kind}" for a in r.active]


def status_html(snapshot: Snapshot, readings: Readings, stats: PeriodStats, rate: float,
                note: str = "", scheduling: str = "") -> str:  # fmt: skip
    """The status block: deadman, mode, resolver, singularity, loop rate, last notice.

    Values carry ``data-field`` attributes, for tests.
    """
    r = snapshot.resolution
    fields = [
        ("deadman", "held" if snapshot.enabled else "released"),
        ("mode", snapshot.mode),
        ("hand", snapshot.name or snapshot.hand),
        *([("lost", snapshot.lost)] if snapshot.lost is not None else []),
        ("status", "-" if r is None else r.status),
        ("method", "-" if r is None else r.method),
        ("scale", "-" if r is None else f"{r.scale:.3f}"),
        ("active", ", ".join(active_names(snapshot)) or "none"),
        ("sigma_min", f"{readings.sigma_min:.4f}"),
        ("singularity", readings.singularity or "none"),
        ("speed", f"{100 * snapshot.speed:.0f} %"),
        ("strategy", snapshot.strategy),
        ("backend", snapshot.backend),
        ("record", f"{snapshot.recorded:.1f} s" if snapshot.recording else "off"),
        ("loop", f"{rate:g} Hz: period median {1e3 * stats.median:.2f} ms, "
                 f"p99 {1e3 * stats.p99:.2f} ms{f', {scheduling}' if scheduling else ''}"),
        ("t", f"{snapshot.t:.2f} s, tick {snapshot.tick}"),
        ("notice", note or "-"),
    ]  # fmt: skip
    alert = {"singularity": bool(readings.singularity), "active": bool(active_names(snapshot)),
             "deadman": not snapshot.enabled, "lost": True}  # fmt: skip
    rows = [
        f'<div style="font:11px monospace;margin:1px 0"><b>{k}</b>: '
        f'<span data-field="{k}" style="color:{RED if alert.get(k) else "inherit"}">'
        f"{html.escape(v)}</span></div>"
        for k, v in fields
    ]
    return "".join(rows)
