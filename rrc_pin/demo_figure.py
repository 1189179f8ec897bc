"""The demo's figures (matplotlib, the ``plot`` extra).

One arm's session (:func:`draw`): joint angles against their limits, joint rates and the
smallest singular value over time, one column of panels per arm; a dotted line marks where
the session's reverse begins. A cell's session (:func:`draw_cell`): the base's pose (the
floating body's, or the held object's), the joint angles and the closed chains' error, each in
its own panel with its unit.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from rrc_pin.cells.cell_log import STATUSES
from rrc_pin.cells.controller import LOST
from rrc_pin.control import TrajectoryLog
from rrc_pin.robot import Robot

if TYPE_CHECKING:
    from rrc_pin.cells import CellController

SIGMA_FLOOR = 1e-6
"""Where the plot floors the smallest singular value (log axis; 0 at a singularity)."""
CHAIN_FLOOR = 1e-12
"""Where the cell figure floors the closed chains' errors (log axis; 0 at the start)."""


def draw(sessions: dict[str, tuple[Robot, dict[str, TrajectoryLog]]], path: Path) -> bool:
    """Write the figure to ``path``; False (nothing written) when matplotlib is absent.

    Per arm: the joints of its first strategy's log (angles, rates), and the smallest
    singular value under every strategy given.
    """
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    fig, axes = plt.subplots(3, len(sessions), figsize=(5 * len(sessions), 8.5), sharex="col",
                             squeeze=False)  # fmt: skip
    for col, (arm, (robot, logs)) in enumerate(sessions.items()):
        strategy, log = next(iter(logs.items()))
        t, q, qdot = log.column("t"), log.column("q"), log.column("qdot")
        span = robot.upper - robot.lower
        axes[0, col].plot(t, (q - robot.lower) / span, lw=1, label=robot.joint_names)
        axes[0, col].axhline(0.0, color="k", lw=0.8)
        axes[0, col].axhline(1.0, color="k", lw=0.8)
        axes[0, col].set_ylim(-0.05, 1.05)
        axes[0, col].set_title(f"{arm}: joints under '{strategy}'")
        axes[0, col].legend(fontsize=6, loc="lower center", ncol=len(robot.joint_names),
                            columnspacing=0.8, handlelength=1.2)  # fmt: skip
        axes[1, col].plot(t, qdot / robot.velocity_limit, lw=1)
        axes[1, col].axhline(1.0, color="k", lw=0.8)
        axes[1, col].axhline(-1.0, color="k", lw=0.8)
        axes[1, col].set_ylim(-1.15, 1.15)
        for name, other in logs.items():
            sigma = np.maximum(other.column("sigma_min"), SIGMA_FLOOR)
            axes[2, col].semilogy(other.column("t"), sigma, lw=1, label=name)
        axes[2, col].set_ylim(SIGMA_FLOOR / 2, 2.0)
        axes[2, col].legend(fontsize=6, loc="lower right", title="strategy", title_fontsize=6)
        axes[2, col].set_xlabel("t [s]")
        mode = log.column("mode")
        if "reverse" in set(mode):  # where the evacuation starts
            start = float(t[list(mode).index("reverse")])
            for row in range(3):
                axes[row, col].axvline(start, color="grey", ls=":", lw=1)
            axes[1, col].annotate("reverse", (start, 1.15), xytext=(3, -10),
                                  textcoords="offset points", fontsize=7, color="grey")  # fmt: skip
        if col == 0:
            axes[0, col].set_ylabel("(q - lower) / range")
            axes[1, col].set_ylabel("qdot / velocity limit")
            axes[2, col].set_ylabel(f"smallest singular value\n(floored at {SIGMA_FLOOR:g})")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def draw_cell(ctl: CellController, path: Path) -> bool:
    """Write a cell session's figure to ``path``; False (nothing written) without matplotlib.

    Four panels over time: the base's position [m] and orientation (roll, pitch, yaw [rad]:
    the floating body's, or the first held object's for a fixed cell), the joint angles
    [rad] (the arms' joints, by name) and the closed chains' largest position [m] and rotation
    [rad] error at each tick's start against the cell's bound, ticks with a chain lost shaded.
    """
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    cell, log = ctl.cell, ctl.log
    t, q = log.column("t"), log.column("q")
    frame = cell.body or next(iter(cell.objects), None)
    fig, axes = plt.subplots(4, 1, figsize=(10, 10), sharex=True)
    if frame is not None:
        poses = [cell.fk(x, frame) for x in q]
        start = poses[0][:3, 3] if poses else np.zeros(3)
        axes[0].plot(t, [T[:3, 3] - start for T in poses], lw=1, label=["x", "y", "z"])
        axes[1].plot(t, [pin.rpy.matrixToRpy(T[:3, :3]) for T in poses], lw=1,
                     label=["roll", "pitch", "yaw"])  # fmt: skip
        what = "body" if cell.body else f"held object '{frame}'"
        at = ", ".join(f"{x:.3f}" for x in start)
        axes[0].set_title(f"{cell.name}: {what} position from its start ({at}) m, the cell's "
                          "axes", fontsize=9)  # fmt: skip
        axes[1].set_title(f"{what} orientation: roll, pitch, yaw about the cell's axes",
                          fontsize=9)  # fmt: skip
        for ax in axes[:2]:
            low, high = ax.get_ylim()
            ax.set_ylim(min(low, -0.01), max(high, 0.01))  # rounding's wiggles read flat
            ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    axes[0].set_ylabel("position [m]")
    axes[1].set_ylabel("angle [rad]")
    joints = cell.actuated
    names = [n for n, a in zip(cell.dof_names, joints, strict=True) if a]
    dof = np.array([cell.dof_positions(x)[joints] for x in q])
    axes[2].plot(t, dof, lw=0.8, label=names)
    axes[2].set_ylabel("joint angle [rad]")
    axes[2].set_title(f"joint angles ({len(names)} joints)", fontsize=9)
    axes[2].legend(fontsize=5, loc="upper left", bbox_to_anchor=(1.0, 1.0),
                   ncol=1 + len(names) // 13)  # fmt: skip
    _chains(axes[3], ctl, t)
    axes[3].set_xlabel("t [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


def _chains(ax: Any, ctl: CellController, t: npt.NDArray[np.float64]) -> None:
    """The closed chains' error panel: position and rotation against the bound, lost shaded."""
    chain = np.maximum(ctl.log.column("chain"), CHAIN_FLOOR)
    what = "grip" if ctl.cell.objects else "feet in support"
    ax.semilogy(t, chain[:, 0], lw=1, color="tab:blue", label="position [m]")
    ax.semilogy(t, chain[:, 1], lw=1, color="tab:orange", label="rotation [rad]")
    if ctl.closure is not None:
        ax.axhline(ctl.closure.position, color="tab:blue", ls="--", lw=0.8,
                   label=f"bound {ctl.closure.position:g} m")  # fmt: skip
        ax.axhline(ctl.closure.rotation, color="tab:orange", ls=":", lw=0.8,
                   label=f"bound {ctl.closure.rotation:g} rad")  # fmt: skip
    lost = np.isin(ctl.log.column("status"), [STATUSES.index(s) for s in LOST])
    if lost.any():
        ax.fill_between(t, CHAIN_FLOOR, 1.0, where=lost, color="tab:red", alpha=0.2,
                        label="chain lost: the cell held still")  # fmt: skip
    ax.set_ylim(CHAIN_FLOOR / 2, 1e-3)
    ax.set_ylabel("error at the tick's start")
    ax.set_title(f"closed chains ({what}): largest error to the grasp or the anchors (floored "
                 f"at {CHAIN_FLOOR:g})", fontsize=9)  # fmt: skip
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
