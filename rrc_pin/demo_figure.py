"""The demo's figure (matplotlib, the ``plot`` extra).

Joint angles against their limits, joint rates and the smallest singular value over time,
one column of panels per arm; a dotted line marks where the session's reverse begins.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rrc_pin.control import TrajectoryLog
from rrc_pin.robot import Robot

SIGMA_FLOOR = 1e-6
"""Where the plot floors the smallest singular value (log axis; 0 at a singularity)."""


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
