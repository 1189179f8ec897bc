"""``rrc-pin demo``: a scripted teleoperation session on the paper arms, every strategy.

Each paper arm (``barker6``, ``rrc_k1607``, ``kr5_3r``) is driven by the same kind of operator
script: hand-frame commands (Barker eq. (20)) that turn the wrist through theta5 = 0
(Barker's arm), cross the base axis, reach out to the stretched arm and back (the other
arms: reach, then cross), roll the hand against a joint limit, let go (the deadman fades the
command), and reverse the last two seconds (Barker's evacuation). The script runs once per
applicable singularity strategy; a summary table is printed, the trajectories are written
as CSV, the table as ``summary.csv`` and a figure as ``session.png`` (needs matplotlib, the
``plot`` extra) into the output folder: ``--out``, or a new folder under the system's
temporary directory (never the working directory), printed.

rrc_k1607 and kr5_3r start at their ready pose (:meth:`rrc_pin.Robot.ready`); barker6 starts
next to its wrist singularity, which its script turns through first.
"""

from __future__ import annotations

import csv
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import NamedTuple, cast

import numpy as np
import numpy.typing as npt

from rrc_pin.control import Controller, TrajectoryLog
from rrc_pin.control.strategies import make_strategy
from rrc_pin.control.strategies.barker_arm import compile_closed_form
from rrc_pin.limits import JointLimits
from rrc_pin.loading import load
from rrc_pin.robot import Robot
from rrc_pin.solvers.closed_form.barker import BarkerClosedForm
from rrc_pin.solvers.compiled import numba_config
from rrc_pin.solvers.tick.tick import compile_stages

Array = npt.NDArray[np.float64]
DT = 0.01  # [s], control period
MARGIN = 0.02  # [rad], kept from every joint limit
REVERSE = 2.0  # [s], the evacuation at the end
Command = Callable[[Controller], Array]
"""A segment's hand-frame twist, chosen from the state at the segment's start."""


class Segment(NamedTuple):
    """One line of the operator's script: a hand-frame twist held for ``seconds``."""

    label: str
    command: Command | None  # None: the operator lets go
    seconds: float


class Session(NamedTuple):
    """An arm's script, its start (None: the arm's ready pose) and its strategies."""

    arm: str
    q0: tuple[float, ...] | None
    segments: tuple[Segment, ...]
    strategies: tuple[str, ...]


class Row(NamedTuple):
    """One line of the summary table (the numbers of one session's log)."""

    arm: str
    strategy: str
    steps: int
    drift_mm: float | None  # None: not measured (the strategy chooses the rates)
    margin_rad: float
    rate: float
    statuses: str
    singularities: str


def to_hand(ctl: Controller, linear: Array, angular: Array | None = None) -> Array:
    """A twist given in base axes, expressed in the hand frame (what the operator sends)."""
    R = ctl.robot.fk(ctl.q)[:3, :3]
    w = np.zeros(3) if angular is None else angular
    return np.concatenate([R.T @ linear, R.T @ w])


def reach(speed: float) -> Command:
    """Along the line from the arm's shoulder (its second joint) to the hand, [m/s]."""

    def command(ctl: Controller) -> Array:
        robot = ctl.robot
        d = robot.fk(ctl.q)[:3, 3] - robot.fk(ctl.q, shoulder_frame(robot))[:3, 3]
        return to_hand(ctl, speed * d / np.linalg.norm(d))

    return command


def toward_axis(speed: float) -> Command:
    """Horizontally toward the base's z axis (the shoulder singularity lies on it), [m/s]."""

    def command(ctl: Controller) -> Array:
        p = ctl.robot.fk(ctl.q)[:3, 3]
        horizontal = np.array([-p[0], -p[1], 0.0])
        return to_hand(ctl, speed * horizontal / np.linalg.norm(horizontal))

    return command


def sideways(speed: float) -> Command:
    """Horizontally around the base's z axis (turning joint 1 toward its limit), [m/s]."""

    def command(ctl: Controller) -> Array:
        p = ctl.robot.fk(ctl.q)[:3, 3]
        around = np.array([-p[1], p[0], 0.0])
        return to_hand(ctl, speed * around / np.linalg.norm(around))

    return command


def fixed(twist: list[float]) -> Command:
    """The same hand-frame twist whatever the state."""
    return lambda ctl: np.array(twist, dtype=np.float64)


def shoulder_frame(robot: Robot) -> str:
    """The frame of the second joint (the shoulder of the paper arms)."""
    return str(robot.model.frames[robot.model.getFrameId(robot.joint_names[1])].name)


ACROSS = Segment("across the base axis", toward_axis(0.15), 4.0)
REACH = (
    Segment("reach out to the stretched arm", reach(0.15), 2.5),
    Segment("back in", reach(-0.15), 1.5),
)
LET_GO = Segment("let go (deadman)", None, 0.5)
SESSIONS = (
    Session("barker6", (0.35, -0.2, 0.9, 0.17, 0.20, 0.0),
            (Segment("wrist through theta5 = 0", fixed([0, 0, 0, 0, -0.8, 0]), 1.0), ACROSS, *REACH,
             Segment("roll against joint 6's limit", fixed([0, 0, 0, 0, 0, 2.0]), 3.0),
             LET_GO),
            ("resolver", "slowdown", "generalized_inverse", "freezing", "auxiliary_hand",
             "wrist_choice", "uncoupled")),
    Session("rrc_k1607", None,
            (*REACH, ACROSS,
             Segment("roll against joint 7's limit", fixed([0, 0, 0, 0, 0, 2.0]), 3.0), LET_GO),
            ("resolver", "slowdown")),
    Session("kr5_3r", None,
            (*REACH, ACROSS, Segment("sideways against joint 1's limit", sideways(0.5), 6.0),
             LET_GO),
            ("resolver", "slowdown")),
)  # fmt: skip


def run_session(session: Session, strategy: str, quick: bool) -> TrajectoryLog:
    """The script of ``session`` under ``strategy``; the controller's log."""
    robot = load(session.arm)
    ctl = Controller(robot, DT, session.q0, strategy=strategy,
                     limits=JointLimits(margin=MARGIN))  # fmt: skip
    scale = 0.3 if quick else 1.0
    for segment in session.segments:
        twist = None if segment.command is None else segment.command(ctl)
        for _ in range(round(scale * segment.seconds / DT)):
            ctl.step(twist, "local")  # re-sent every tick; None: let go, the command ages
    ctl.reverse(min(scale * REVERSE, len(ctl.log) * DT))
    return ctl.log


def summarise(arm: str, strategy: str, log: TrajectoryLog, robot: Robot) -> Row:
    """The summary row of one session's log (no drift where the strategy chooses the rates)."""
    q = np.asarray(log.column("q"), dtype=np.float64)
    qdot = np.asarray(log.column("qdot"), dtype=np.float64)
    drift = np.asarray(log.column("drift_position"), dtype=np.float64)
    margin = float(np.min(np.minimum(q - robot.lower, robot.upper - q)))
    statuses = Counter(str(s) for s in log.column("status"))
    met = sorted({name for s in log.column("singularity") if s for name in str(s).split("+")})
    measured = not make_strategy(strategy).chooses_rates
    return Row(
        arm, strategy, len(log), 1e3 * float(np.max(drift)) if measured else None, margin,
        float(np.max(np.abs(qdot) / robot.velocity_limit)),
        " ".join(f"{k} {n}" for k, n in statuses.most_common()),
        "; ".join(met[:3]) + (f"; +{len(met) - 3} more" if len(met) > 3 else ""),
    )  # fmt: skip


HEADER = ("arm", "strategy", "steps", "max drift [mm]", "min margin [rad]", "max |qdot|/limit",
          "statuses", "singularities met")  # fmt: skip


NOT_MEASURED = "-"
"""What the table prints for a drift that is not measured (summary.csv: an empty cell)."""


def drift_text(row: Row) -> str:
    """The drift as printed: four decimals [mm], or :data:`NOT_MEASURED`."""
    return NOT_MEASURED if row.drift_mm is None else f"{row.drift_mm:.4f}"


def print_table(rows: list[Row]) -> None:
    """The summary table."""
    print(f"{HEADER[0]:10s} {HEADER[1]:20s} {HEADER[2]:>6s} {HEADER[3]:>14s} {HEADER[4]:>16s} "
          f"{HEADER[5]:>16s}  {HEADER[6]} | {HEADER[7]}")  # fmt: skip
    for r in rows:
        print(f"{r.arm:10s} {r.strategy:20s} {r.steps:6d} {drift_text(r):>14s} "
              f"{r.margin_rad:16.6f} {r.rate:16.4f}  {r.statuses} | "
              f"{r.singularities or '-'}")  # fmt: skip


def write_summary(rows: list[Row], path: Path) -> None:
    """The table as CSV, numbers as printed; a drift not measured is an empty cell."""
    with path.open("w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(HEADER)
        for r in rows:
            drift = "" if r.drift_mm is None else f"{r.drift_mm:.4f}"
            writer.writerow([r.arm, r.strategy, r.steps, drift, f"{r.margin_rad:.6f}",
                             f"{r.rate:.4f}", r.statuses, r.singularities])  # fmt: skip


def default_out() -> Path:
    """A new folder ``rrc-pin-demo-*`` under the system's temporary directory (created)."""
    return Path(tempfile.mkdtemp(prefix=f"rrc-pin-demo-{time.strftime('%Y%m%d-%H%M%S')}-"))


def compile_beside() -> None:
    """Compile, or load from numba's cache, the default tick's two longest stages
    (:func:`~rrc_pin.solvers.tick.tick.compile_stages`), then Barker's kernels
    (:func:`compile_closed_form`): :func:`compiling_beside`'s work."""  # noqa: D205, D209
    compile_stages()
    compile_closed_form(cast(BarkerClosedForm, load("barker6").closed_form))


def compiling_beside() -> subprocess.Popen[bytes] | None:
    """A second process that compiles into numba's cache (:func:`compile_beside`).

    On a fresh install the first session's controller compiles the resolver's tick, then
    Barker's kernels: the second process compiles, on another core meanwhile, two stages of
    the tick before that compilation reaches them, then Barker's kernels, and the controller
    loads them from the cache. Where they are cached already it loads them and exits. None
    where no process can be started, or nothing is compiled (``NUMBA_DISABLE_JIT=1``).
    """
    if numba_config.DISABLE_JIT:
        return None
    try:
        return subprocess.Popen(
            [sys.executable, "-c", "from rrc_pin.demo import compile_beside; compile_beside()"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
    except OSError:
        return None


def teleoperation(out: Path | None = None, quick: bool = False) -> int:
    """The scripted sessions, the table, the CSV files and the figure; the exit code."""
    beside = compiling_beside()
    try:
        return _teleoperation(out, quick)
    finally:
        if beside is not None:
            beside.wait()


def _teleoperation(out: Path | None, quick: bool) -> int:
    """:func:`teleoperation`'s sessions, table, files and figure."""
    out = default_out() if out is None else out
    out.mkdir(parents=True, exist_ok=True)
    runs = [(s, name) for s in SESSIONS for name in s.strategies]
    print(f"== Teleoperation sessions, dt = {DT * 1e3:g} ms, margin {MARGIN} rad from every "
          f"limit{' (quick)' if quick else ''}: {len(runs)} runs -> {out}\n")  # fmt: skip
    rows: list[Row] = []
    logs: dict[str, dict[str, TrajectoryLog]] = {}
    for k, (session, strategy) in enumerate(runs, 1):
        start = time.perf_counter()
        log = run_session(session, strategy, quick)
        log.save(out / f"{session.arm}-{strategy}.csv")
        rows.append(summarise(session.arm, strategy, log, load(session.arm)))
        if strategy in ("resolver", "slowdown"):
            logs.setdefault(session.arm, {})[strategy] = log
        print(f"[{k:2d}/{len(runs)}] {session.arm} / {strategy}: {len(log)} ticks in "
              f"{time.perf_counter() - start:.1f} s", flush=True)  # fmt: skip
    print()
    print_table(rows)
    write_summary(rows, out / "summary.csv")
    from rrc_pin.demo_figure import draw

    figure = draw({arm: (load(arm), by) for arm, by in logs.items()}, out / "session.png")
    for session in SESSIONS:
        labels = ", ".join(s.label for s in session.segments)
        print(f"\n{session.arm}: {labels}, then reverse {REVERSE:g} s.", end="")
    print("\n\ndrift: distance from the commanded pose (corrected at every tick); '-': not "
          "measured: Barker's\nstrategies choose the rates themselves and leave that pose "
          "(summary.csv leaves the cell empty);\nmargin: closest approach to a joint limit; "
          "statuses: how the resolver answered.")
    print(f"\nwritten to {out}: {len(runs)} trajectories (CSV), summary.csv"
          + (", session.png" if figure else "; session.png skipped: matplotlib is not "
             "installed (pip install -e '.[plot]')"))  # fmt: skip
    return 0


def kinematics_tour(names: Sequence[str]) -> None:
    """Print, per arm and tool frame, its position and Jacobian conditioning at its ready pose.

    Every arm is loaded before anything is printed (a name that does not load prints
    nothing); the arm column holds the robot's name (a URDF's robot, not its path), and the
    columns are as wide as their widest cell.

    Raises:
        RrcPinError: A name that :func:`rrc_pin.load` refuses.
    """
    robots = [load(name) for name in names]
    rows = [("arm", "dof", "pose", "tool frame", "position [m]", "cond(J)")]
    for arm in robots:
        q = arm.ready()
        for frame in arm.tool_frames:
            position = np.array2string(arm.fk(q, frame)[:3, 3], precision=4, suppress_small=True)
            cond = np.linalg.cond(arm.jacobian(q, frame=frame))
            rows.append((arm.name, str(arm.nq), "ready", frame, position, f"{cond:.2e}"))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    right = (False, True, False, False, True, True)
    for r in rows:
        cells = [c.rjust(w) if k else c.ljust(w) for c, w, k in zip(r, widths, right, strict=True)]
        print("  ".join(cells).rstrip())


def run_demo(arm: str | None = None, out: Path | None = None, quick: bool = False) -> int:
    """The teleoperation sessions, or (``arm``) the kinematics row of one arm; the exit code."""
    if arm:
        kinematics_tour([arm])
        return 0
    return teleoperation(out, quick)
