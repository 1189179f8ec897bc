"""MJCF models: an arm loaded from a MuJoCo file, the same kinematics as from its URDF.

Shows: ``rrc_pin.load("model.xml")`` on an MJCF (Pinocchio's MJCF parser; the tool frame
and the limits by the same rules as a URDF; MJCF gives no velocity limits, so they are
passed to ``JointLimits``). The MJCF is written by MuJoCo from the committed
``urdf/rrc_k1607.urdf`` into a temporary folder when ``mujoco`` is installed (``pip install
mujoco``), else read from the copy the tests keep (``tests/data/mjcf``). Prints the largest
difference of forward kinematics and Jacobians at random configurations, and a few ticks
solved from both. Needs ``pip install -e .`` (and optionally ``mujoco``).

Run: ``python examples/mjcf.py``
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

import rrc_pin

ROOT = Path(__file__).resolve().parents[1]


def compare(path: Path) -> None:
    """The MJCF arm against the URDF arm: kinematics, then resolved rates."""
    mjcf, urdf = rrc_pin.load(path), rrc_pin.load("rrc_k1607")
    rng = np.random.default_rng(0)
    worst = 0.0
    for _ in range(100):
        q = np.clip(urdf.random_q(rng), mjcf.lower, mjcf.upper)
        worst = max(worst, float(np.abs(mjcf.fk(q) - urdf.fk(q)).max()),
                    float(np.abs(mjcf.jacobian(q) - urdf.jacobian(q)).max()))  # fmt: skip
    print(f"{mjcf.name} from MJCF: {mjcf.nq} joints, tool frame {mjcf.tool_frame!r}; fk and "
          f"Jacobians at 100 random q within {worst:.1e} of the URDF's")
    limits = rrc_pin.JointLimits(velocity=urdf.velocity_limit)  # MJCF has none
    ours, theirs = rrc_pin.Resolver(mjcf, limits=limits), rrc_pin.Resolver(urdf)
    q, twist, gap = urdf.ready(), [0.1, -0.05, 0.02, 0.1, 0.0, -0.2], 0.0
    for _ in range(50):
        a, b = ours.solve(q, twist), theirs.solve(q, twist)
        gap = max(gap, float(np.abs(a.qdot - b.qdot).max()))
        q = q + a.qdot * 0.01
    print(f"50 ticks of a hand twist: rates within {gap:.1e} rad/s of the URDF arm's "
          f"(status {a.status})")


def main() -> None:
    """Write the MJCF with MuJoCo if it is there, else read the kept copy."""
    try:
        import mujoco
    except ImportError:
        print("mujoco is not installed: reading tests/data/mjcf/rrc_k1607.xml")
        compare(ROOT / "tests" / "data" / "mjcf" / "rrc_k1607.xml")
        return
    spec = mujoco.MjSpec.from_file(str(ROOT / "urdf" / "rrc_k1607.urdf"))
    spec.compiler.fusestatic = False  # keep the tool link: the tool frame
    spec.compile()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "rrc_k1607.xml"
        path.write_text(spec.to_xml())
        print(f"MuJoCo {mujoco.__version__} wrote the MJCF of urdf/rrc_k1607.urdf")
        compare(path)


if __name__ == "__main__":
    main()
