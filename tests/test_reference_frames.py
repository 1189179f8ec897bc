"""One twist, one motion: every entry point reads ``local``, ``world_aligned`` and ``world`` alike.

The frames are Pinocchio's ``ReferenceFrame``: ``world_aligned`` the hand's velocity in base
axes, ``local`` the same in hand axes, ``world`` the spatial twist at the base origin. A twist
``[a u; b u]`` held for a time T in one of them is one exact motion of the hand (a screw about
``u`` through the hand point, in base or hand axes, or through the base origin), computed here
with Pinocchio; each entry point drives the arm with it and must end there. (An arm below six
joints commands its hand's position only, and its hand axes turn as the joints take them: its
``local`` motion is the resolver's, which the other entry points must follow.)

Entry points are drivers in :data:`ENTRY_POINTS`, ``drive(arm, twist, ref) -> final q``;
another (the cells' controller, the console's loop) is one more function there.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin import guidance

DT = 0.01
TICKS = 100
SECONDS = DT * TICKS
TWIST = np.array([0.0, 0.0, -0.05, 0.0, 0.0, -0.05])
"""[m/s, rad/s]: down along z while turning about it (``v`` parallel to ``w``: one screw)."""
POSITION_ONLY = np.array([0.0, 0.0, -0.05, 0.0, 0.0, 0.0])
"""The command of an arm below six joints (its task is the hand's position)."""


def single_tool_arms() -> list[str]:
    """Every arm of the catalogue with one tool frame (``rrc_pin.arms()``)."""
    return [name for name in rrc_pin.arms() if rrc_pin.load(name).tool_frame is not None]


ARMS = single_tool_arms()


def full(arm: rrc_pin.Robot) -> bool:
    return arm.nv >= 6


def expected_pose(T0: np.ndarray, twist: np.ndarray, ref: str, seconds: float) -> np.ndarray:
    """The hand pose after ``twist`` is held in ``ref`` for ``seconds`` (Pinocchio's exp6)."""
    motion = pin.exp6(pin.Motion(twist * seconds))
    start = pin.SE3(T0)
    if ref == "local":
        return (start * motion).homogeneous
    if ref == "world":
        return (motion * start).homogeneous
    moved = pin.SE3(pin.exp3(twist[3:] * seconds) @ T0[:3, :3], T0[:3, 3] + twist[:3] * seconds)
    return moved.homogeneous


def drive_resolver(arm: rrc_pin.Robot, twist: np.ndarray, ref: str) -> np.ndarray:
    resolver = rrc_pin.Resolver(arm, dt=DT)
    q = arm.ready()
    for _ in range(TICKS):
        r = resolver.solve(q, twist, ref=ref)
        assert r.status == "exact", r
        q = arm.integrate(q, r.qdot, DT)
    return q


def drive_frame_task(arm: rrc_pin.Robot, twist: np.ndarray, ref: str) -> np.ndarray:
    resolver = rrc_pin.Resolver(arm, dt=DT)
    rows = "full" if full(arm) else "position"
    q = arm.ready()
    for _ in range(TICKS):
        task = rrc_pin.FrameTask(arm.tool_frame, twist, ref=ref, rows=rows)
        r = resolver.solve(q, [task])
        assert r.status == "exact", r
        q = arm.integrate(q, r.qdot, DT)
    return q


def drive_controller(arm: rrc_pin.Robot, twist: np.ndarray, ref: str) -> np.ndarray:
    ctl = rrc_pin.Controller(arm, dt=DT)
    for _ in range(TICKS):
        step = ctl.step(twist, ref=ref)
        assert step.resolution.status == "exact", step.resolution
    return ctl.q


def drive_guidance(arm: rrc_pin.Robot, twist: np.ndarray, ref: str) -> np.ndarray:
    """Type IV: the twist's screw as one operator command, through a Resolver."""
    speed, rate = float(np.linalg.norm(twist[:3])), float(np.linalg.norm(twist[3:]))
    axis = twist[:3] / speed
    steps = 20
    command = guidance.Command(axis, speed * SECONDS, rate * SECONDS * np.sign(axis @ twist[3:]),
                               ref=ref)  # fmt: skip
    (path,) = guidance.operator(arm, arm.ready(), [command], steps,
                                solver=rrc_pin.Resolver(arm, dt=SECONDS / steps))  # fmt: skip
    return path.q[-1]


ENTRY_POINTS: dict[str, Callable[[rrc_pin.Robot, np.ndarray, str], np.ndarray]] = {
    "Resolver.solve": drive_resolver,
    "FrameTask": drive_frame_task,
    "Controller.step": drive_controller,
    "guidance.operator": drive_guidance,
}


def cases() -> list[tuple[str, str, str]]:
    out = []
    for name in ARMS:
        arm = rrc_pin.load(name)
        refs = ("local", "world_aligned", "world") if full(arm) else ("local", "world_aligned")
        for entry in ENTRY_POINTS:
            if entry == "guidance.operator" and not full(arm):
                continue  # guidance steers the whole pose of the hand
            out += [(name, entry, ref) for ref in refs]
    return out


@pytest.mark.parametrize(("name", "entry", "ref"), cases())
def test_the_same_twist_moves_the_hand_the_same_way_through_every_entry_point(name, entry, ref):
    arm = rrc_pin.load(name)
    twist = TWIST if full(arm) else POSITION_ONLY
    T0 = arm.fk(arm.ready())
    if full(arm) or ref == "world_aligned":
        want = expected_pose(T0, twist, ref, SECONDS)
    else:  # hand axes that turn as the position-only task lets them: the resolver's motion
        want = arm.fk(drive_resolver(arm, twist, ref))
    got = arm.fk(ENTRY_POINTS[entry](arm, twist, ref))
    moved = np.linalg.norm(want[:3, 3] - T0[:3, 3])
    assert moved > 0.04  # at least the twist's own 0.05 m: every case moves the hand
    # first-order integration of 100 ticks (20 guidance steps): well under a millimetre
    assert np.linalg.norm(got[:3, 3] - want[:3, 3]) < 1e-3, (got[:3, 3], want[:3, 3])
    if full(arm):
        turn = np.linalg.norm(pin.log3(got[:3, :3] @ want[:3, :3].T))
        assert turn < 1e-3


def test_panda_moves_down_through_the_resolver_and_the_controller_by_default():
    """The issue's case: 100 ticks of [0, 0, -0.05, 0, 0, 0] moved the hand -0.050 m with
    ``Resolver.solve`` and +0.050 m with ``Controller.step`` (its default was ``local``)."""
    arm = rrc_pin.load("panda")
    twist = np.array([0.0, 0.0, -0.05, 0.0, 0.0, 0.0])
    z0 = arm.fk(arm.ready())[2, 3]
    resolver, q = rrc_pin.Resolver(arm, dt=DT), arm.ready()
    for _ in range(TICKS):
        q = arm.integrate(q, resolver.solve(q, twist).qdot, DT)
    ctl = rrc_pin.Controller(arm, dt=DT)
    with pytest.warns(FutureWarning, match="default was 'local'"):
        ctl.step(twist)
    for _ in range(TICKS - 1):
        ctl.step(twist)
    for final in (q, ctl.q):
        assert abs(arm.fk(final)[2, 3] - z0 - -0.05) < 1e-4


def test_the_controller_keeps_the_old_keyword_for_one_release():
    arm = rrc_pin.load("panda")
    old, new = rrc_pin.Controller(arm, dt=DT), rrc_pin.Controller(arm, dt=DT)
    with pytest.warns(DeprecationWarning, match=r"Controller.step\(frame=\) is deprecated"):
        a = old.step(TWIST, frame="local")
    b = new.step(TWIST, ref="local")
    np.testing.assert_array_equal(a.q, b.q)
    with pytest.raises(rrc_pin.InvalidInput, match="^frame:"), pytest.warns(DeprecationWarning):
        old.step(TWIST, ref="local", frame="local")


def test_a_world_twist_is_refused_where_the_task_is_the_position_only():
    ctl = rrc_pin.Controller("kr5_3r", dt=DT)
    with pytest.raises(rrc_pin.InvalidInput, match="^ref: kr5_3r is commanded in position"):
        ctl.step(POSITION_ONLY, ref="world")
    assert ctl.t == 0.0
