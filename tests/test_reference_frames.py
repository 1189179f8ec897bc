"""One twist, one motion: every entry point reads ``local``, ``world_aligned`` and ``world`` alike.

The frames are Pinocchio's ``ReferenceFrame``: ``world_aligned`` the hand's velocity in base
axes, ``local`` the same in hand axes, ``world`` the spatial twist at the base origin. A twist
``[a u; b u]`` held for a time T in one of them is one exact motion of the hand (a screw about
``u`` through the hand point, in base or hand axes, or through the base origin), computed here
with Pinocchio; each entry point drives the arm with it and must end there. (An arm below six
joints commands its hand's position only, and its hand axes turn as the joints take them: its
``local`` motion is the resolver's, which the other entry points must follow.)

Entry points are drivers in :data:`ENTRY_POINTS`, ``drive(arm, twist, ref) -> final q``;
another (the console's loop) is one more function there. ``CellController.step`` is one (each
arm as a cell of one free hand); it also drives the frames only a cell has, each with one twist
in each of its frames: gsfc_dual's held object, yeh_tripod's body and a swung foot
(:data:`CELL_FRAMES`).
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
FRAMES = ("local", "world_aligned", "world")
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


def drive_cell(
    cell: rrc_pin.cells.Cell, name: str, twist: np.ndarray, ref: str, q0: np.ndarray | None = None
) -> np.ndarray:
    """``CellController.step({name: (twist, ref)})`` from ``q0``; a leg of a legged cell
    swung first."""
    ctl = rrc_pin.cells.CellController(cell, dt=DT, q0=q0)
    if cell.body is not None and name in cell.arms:
        ctl.swing(name)
    for _ in range(TICKS):
        step = ctl.step({name: (twist, ref)})
        assert step.resolution.status == "exact", step.resolution
    return ctl.q


def drive_cell_controller(arm: rrc_pin.Robot, twist: np.ndarray, ref: str) -> np.ndarray:
    """The arm as a cell of one free hand (``make_cell``: the same q)."""
    return drive_cell(rrc_pin.make_cell({"arm": (arm, np.eye(4))}, name=arm.name), "arm",
                      twist, ref)  # fmt: skip


ENTRY_POINTS: dict[str, Callable[[rrc_pin.Robot, np.ndarray, str], np.ndarray]] = {
    "Resolver.solve": drive_resolver,
    "FrameTask": drive_frame_task,
    "Controller.step": drive_controller,
    "guidance.operator": drive_guidance,
    "CellController.step": drive_cell_controller,
}
WHOLE_POSE = ("guidance.operator", "CellController.step")
"""Entry points that steer the whole pose of the hand (six-joint arms and up)."""
WORLD_WARNS = "ignore:CellController.step. ref 'world':FutureWarning"
"""The cells' 'world' meant world_aligned before (tests/test_cells_controller.py tests it)."""


def cases() -> list[tuple[str, str, str]]:
    out = []
    for name in ARMS:
        arm = rrc_pin.load(name)
        refs = FRAMES if full(arm) else ("local", "world_aligned")
        for entry in ENTRY_POINTS:
            if entry in WHOLE_POSE and not full(arm):
                continue
            out += [(name, entry, ref) for ref in refs]
    return out


@pytest.mark.filterwarnings(WORLD_WARNS)
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


CELL_FRAMES = {("gsfc_dual", "object"): FRAMES, ("yeh_tripod", "body"): FRAMES,
               ("yeh_tripod", "leg1"): (*FRAMES, "base")}  # fmt: skip
"""A cell's commands and their frames: a held object, a floating body over its feet, a foot
swung out of support (a free hand, also in its leg's base axes; refused for the others in
tests/test_cells_controller.py)."""
CELL_TWIST = np.array([0.03, 0.0, -0.04, 0.0, 0.05, -0.05])
"""[m/s, rad/s]: turning about y too, as the tripod's body sits on the base's z axis (where
:data:`TWIST` is one motion in ``world`` and ``world_aligned``)."""
TURN = np.array([0.0, 0.0, 0.0, 0.2, 0.0, 0.2])
"""[rad/s] held before (one run of ticks): the object's and the body's axes start as the
base's (where ``local`` is ``world_aligned``), turned 0.28 rad off them."""


def cell_expected(cell: rrc_pin.cells.Cell, q0: np.ndarray, name: str, ref: str) -> np.ndarray:
    """Where :data:`CELL_TWIST` held in ``ref`` from ``q0`` takes ``name``'s frame (exp6);
    ``base`` (a hand's arm base axes, at the hand) is world_aligned in the base's axes."""
    frame = name if name not in cell.arms else cell.arms[name].hand
    twist = CELL_TWIST
    if ref == "base":  # the body's axes (held still) times the arm's base placement
        R = cell.fk(q0, cell.body)[:3, :3] @ cell.arms[name].base[:3, :3]
        twist, ref = np.r_[R @ twist[:3], R @ twist[3:]], "world_aligned"
    return expected_pose(cell.fk(q0, frame), twist, ref, SECONDS)


@pytest.mark.filterwarnings(WORLD_WARNS)
@pytest.mark.parametrize(("name", "command", "ref"),
                         [(*key, ref) for key, refs in CELL_FRAMES.items() for ref in refs])
def test_the_same_twist_moves_a_cells_frame_as_pinocchio_says(name, command, ref):
    """Each frame ends where the twist held in ``ref`` takes it, and 1 cm or more from where
    the same twist held in any other of its frames would."""
    cell = rrc_pin.load(name)
    q0 = drive_cell(cell, command, TURN, "world_aligned")
    frame = command if command not in cell.arms else cell.arms[command].hand
    T0 = cell.fk(q0, frame)
    want = cell_expected(cell, q0, command, ref)
    others = [cell_expected(cell, q0, command, other)
              for other in CELL_FRAMES[name, command] if other != ref]  # fmt: skip
    assert min(np.linalg.norm(T[:3, 3] - want[:3, 3]) for T in others) > 0.01
    assert np.linalg.norm(want[:3, 3] - T0[:3, 3]) > 0.04
    got = cell.fk(drive_cell(cell, command, CELL_TWIST, ref, q0), frame)
    assert np.linalg.norm(got[:3, 3] - want[:3, 3]) < 1e-3, (got[:3, 3], want[:3, 3])
    assert np.linalg.norm(pin.log3(got[:3, :3] @ want[:3, :3].T)) < 1e-3


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
