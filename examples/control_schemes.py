"""Nguyen & Zhou's control schemes on Pinocchio's dynamics.

Shows: ``rrc_pin.dynamics``. Barker's arm follows a hand path at 1 kHz and picks up a 2.5 kg
payload half way; fixed-gain PD and computed torque (on the nominal model) against the
adaptive PD of Nguyen & Zhou (joint space, Fig. 11; Cartesian, Fig. 12). Prints each
controller's tracking error and how far the payload pushed the hand. Needs only
``pip install -e .``.

Run: ``python examples/control_schemes.py``
"""

import os

import rrc_pin
from rrc_pin.dynamics import scenarios

QUICK = os.environ.get("RRC_PIN_EXAMPLES_QUICK") == "1"
duration = 0.1 if QUICK else 4.0  # [s] of simulated time, the payload at half of it

arm = rrc_pin.load("barker6")
print(f"barker6, {duration:g} s, {scenarios.PAYLOAD.mass:g} kg picked up at {duration / 2:g} s")
print(f"{'controller':24s} {'RMS [mm]':>9s} {'max [mm]':>9s} {'payload peak [mm]':>18s}  recovery")
for name in scenarios.TRACKING_CONTROLLERS:
    m = scenarios.tracking(arm, name, duration=duration, change_at=duration / 2,
                           segment=min(1.0, duration / 2)).metrics  # fmt: skip
    recovery = (f"within 1 mm after {m['recovery_s']:.2f} s" if m["recovery_s"] != float("inf")
                else f"not within the run's last {duration / 2:g} s")  # fmt: skip
    print(f"{name:24s} {m['position_rms_mm']:9.2f} {m['position_max_mm']:9.2f} "
          f"{m['payload_deviation_peak_mm']:18.2f}  {recovery}")
