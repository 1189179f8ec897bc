"""A teleoperation session: the controller, its log, and the way back.

Shows: ``rrc_pin.Controller`` on panda (it starts at the arm's ready pose), hand-frame
commands every tick at 100 Hz, the deadman fading a command that is no longer sent, the
trajectory log (saved to CSV in a temporary folder, never in the working directory) and
``reverse``, which retraces the last second. Prints what the log says. Needs only
``pip install -e .``; with matplotlib (``pip install -e ".[plot]"``) it also draws the joint
rates to a PNG in that folder.

Run: ``python examples/teleoperation.py``
"""

import os
import tempfile
from pathlib import Path

import numpy as np

import rrc_pin

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"  # shorter session (the tests)
seconds = 0.5 if QUICK else 3.0

ctl = rrc_pin.Controller("panda", dt=0.01, strategy="slowdown")
start = ctl.q
for k in range(round(seconds / ctl.dt)):
    # forward and turning for the first half, then up; hand axes [m/s, rad/s]
    twist = [0.05, 0.0, 0.0, 0.0, 0.0, 0.3] if k < seconds / ctl.dt / 2 else [0, 0, 0.05, 0, 0, 0]
    ctl.step(twist, ref="local")
for _ in range(round(0.6 / ctl.dt)):
    ctl.step()  # no new command: the deadman fades the last one after 0.2 s

log = ctl.log
print(f"{len(log)} ticks, {log.column('t')[-1]:.2f} s")
names, counts = np.unique(log.column("status"), return_counts=True)
print("statuses: " + ", ".join(f"{n} {c}" for n, c in zip(names, counts, strict=True)))
print(f"largest drift from the commanded pose: {1e3 * log.column('drift_position').max():.3f} mm")
print(f"hand speed at the end (deadman): {np.linalg.norm(log.column('achieved')[-1][:3]):.4f} m/s")

back = ctl.reverse(seconds=1.0)  # Barker's evacuation: retrace the last second
print(f"reverse: {back.steps} ticks, reached {back.reached}, error {back.error:.2e} rad")

out = Path(tempfile.mkdtemp(prefix="rrc-pin-teleoperation-"))
log.save(out / "session.csv")
print(f"log written to {out / 'session.csv'} (joints moved {np.abs(ctl.q - start).max():.3f} rad)")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib not installed: no figure (pip install -e '.[plot]')")
else:
    t = log.column("t")
    fig, ax = plt.subplots(figsize=(8, 3.2))
    ax.plot(t, log.column("qdot") / ctl.robot.velocity_limit, lw=1, label=ctl.robot.joint_names)
    reverse = t[list(log.column("mode")).index("reverse")]
    ax.axvline(reverse, color="grey", ls=":", lw=1)
    ax.annotate("reverse", (reverse, 1.0), xycoords=("data", "axes fraction"), xytext=(3, -12),
                textcoords="offset points", fontsize=8, color="grey")  # fmt: skip
    ax.set(xlabel="t [s]", ylabel="qdot / velocity limit",
           title="panda: commands, let go (deadman), then reverse")  # fmt: skip
    ax.legend(fontsize=6, loc="center left", bbox_to_anchor=(1.0, 0.5))
    fig.tight_layout()
    fig.savefig(out / "rates.png", dpi=100)
    print(f"figure written to {out / 'rates.png'}")
