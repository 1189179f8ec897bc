"""One twist of the hand, resolved within the joint limits.

Shows: ``rrc_pin.Resolver`` on panda at its ready pose. A slow hand-frame twist is followed
exactly; one twenty times faster would need joint rates beyond their limits, so the
resolver slows it down along the commanded direction (status ``scaled``) and says which
limits bind. Needs only ``pip install -e .``.

Run: ``python examples/one_twist_with_limits.py``
"""

import numpy as np

import rrc_pin

arm = rrc_pin.load("panda")
q = arm.ready()  # away from limits and singularities
resolver = rrc_pin.Resolver(arm, dt=0.01)  # joint velocity and one-step position limits

for label, twist in [
    ("slow", [0.05, 0.0, 0.0, 0.0, 0.0, 0.2]),  # [m/s, rad/s], hand axes
    ("20x faster", [1.0, 0.0, 0.0, 0.0, 0.0, 4.0]),
]:
    r = resolver.solve(q, twist, ref="local")
    achieved = arm.jacobian(q, ref="local") @ r.qdot
    print(f"{label}: status {r.status}, scale {r.scale:.3f}, method {r.method}")
    print(f"  joint rates [rad/s]   {np.round(r.qdot, 3)}")
    print(f"  of their limits       {np.round(np.abs(r.qdot) / arm.velocity_limit, 3)}")
    print(f"  twist achieved        {np.round(achieved, 4)}")
    print(f"  limits that bind      {[f'{a.joint}:{a.side}:{a.kind}' for a in r.active] or '-'}")
