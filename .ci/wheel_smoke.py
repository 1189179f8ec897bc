"""Smoke set of an installed wheel, run by .ci/wheel as a user who cannot write site-packages.

Checks that the package imported is the wheel's (not a checkout's), that its site-packages
really refuses writes, that the numerics compile and cache outside it (numba's user-wide cache)
and that the entry points answer: the resolver, the controller, a cell, the errors.
"""

from __future__ import annotations

import os
import sysconfig
from pathlib import Path

import numpy as np

import rrc_pin

site = Path(sysconfig.get_paths()["purelib"]).resolve()
package = Path(rrc_pin.__file__).resolve().parent
assert package.is_relative_to(site), f"rrc_pin imported from {package}, not {site}"
assert (package / "solvers" / "tick" / "pipeline.py").is_file()
assert not (package / "solvers").is_symlink()
try:
    (package / "probe.txt").write_text("")
except PermissionError:
    pass
else:
    raise SystemExit(f"{package} is writable: the read-only check would prove nothing")

arm = rrc_pin.load("panda")
twist = np.array([0.0, 0.0, -0.05, 0.0, 0.0, 0.0])
r = rrc_pin.Resolver(arm, dt=0.01).solve(arm.ready(), twist)
assert r.status == "exact", r
ctl = rrc_pin.Controller(arm, dt=0.01)
for _ in range(100):
    ctl.step(twist, ref="world_aligned")
moved = arm.fk(ctl.q)[2, 3] - arm.fk(arm.ready())[2, 3]
assert abs(moved + 0.05) < 1e-3, moved

dual = rrc_pin.Controller("gsfc_dual", dt=0.01)
for _ in range(20):
    step = dual.step({"object": [0.05, 0.0, 0.0, 0.0, 0.0, 0.1]})
assert step.resolution.status == "exact" and dual.log[-1].grip["object"] < 1e-9

try:
    rrc_pin.load("")
except rrc_pin.errors.InvalidInput as exc:
    assert str(exc).startswith("name_or_path: "), exc
else:
    raise SystemExit("load('') was not refused")

cache = Path(os.environ.get("NUMBA_CACHE_DIR") or Path.home() / ".cache" / "numba")
cached = list(cache.rglob("*.nbi"))
assert cached, f"numba cached nothing in {cache}"
assert not list(package.rglob("*.nbi")), "numba wrote into the read-only site-packages"
print(f"wheel smoke: rrc_pin {package}, read-only; panda moved {moved:+.4f} m; gsfc_dual "
      f"{step.resolution.status}; {len(cached)} compiled kernels cached in {cache}")
