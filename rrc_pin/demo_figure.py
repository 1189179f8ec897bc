"""The demo's figure (matplotlib, the ``plot`` extra).

Joint angles against their limits, joint rates and the smallest singular value over time,
one column of panels per arm.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rrc_pin.control import TrajectoryLog
from rrc_pin.robot import Robot


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
    fig, axes = plt.subplots(3, len(sessions), figsize=(5 * len(sessions), 8), sharex="col",
                             squeeze=False)  # fmt: skip
    for col, (arm, (robot, logs)) in enumerate(sessions.items()):
        strategy, log = next(iter(logs.items()))
        t, q, qdot = log.column("t"), log.column("q"), log.column("qdot")
        span = robot.upper - robot.lower
        axes[0, col].plot(t, (q - robot.lower) / span, lw=1)
        axes[0, col].axhline(0.0, color="k", lw=0.8)
        axes[0, col].axhline(1.0, color="k", lw=0.8)
        axes[0, col].set_title(f"{arm}: {strategy}, then reverse")
        axes[1, col].plot(t, qdot / robot.velocity_limit, lw=1)
        axes[1, col].axhline(1.0, color="k", lw=0.8)
        axes[1, col].axhline(-1.0, color="k", lw=0.8)
        for name, other in logs.items():
            sigma = np.maximum(other.column("sigma_min"), 1e-6)
            axes[2, col].semilogy(other.column("t"), sigma, lw=1, label=name)
        axes[2, col].legend(fontsize=6, loc="lower right")
        axes[2, col].set_xlabel("t [s]")
        if col == 0:
            axes[0, col].set_ylabel("(q - lower) / range")
            axes[1, col].set_ylabel("qdot / velocity limit")
            axes[2, col].set_ylabel("smallest singular value")
        axes[0, col].legend(robot.joint_names, fontsize=6, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True
