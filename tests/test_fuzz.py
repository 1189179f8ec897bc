"""Bad input at every public call site of the resolver, its tasks, options and the controller
(issue 28 item 8): every class of bad value raises only the package's error root, naming the
argument, and changes nothing. (Robot's own call sites: tests/test_robot.py.)"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import rrc_pin
from rrc_pin import (
    Controller,
    DampingTask,
    Deadman,
    DriftCorrection,
    FrameTask,
    JointLimits,
    JointTask,
    PostureTask,
    QPOptions,
    RelativeFrameTask,
    Resolver,
    RrcPinError,
)
from rrc_pin.guidance import screw_from_points, screw_from_poses

NUMBER = [np.nan, np.inf, -np.inf, "0.1", None, [0.1], {}, object(), True, 1j, np.array(["a"])]
"""Bad values where a finite number goes."""

VECTOR = [np.full(7, np.nan), np.r_[np.zeros(6), np.inf], np.zeros(6), np.zeros((7, 1)), [],
          "q", None, {}, [0.1] * 6 + [True], np.zeros(7, complex), [[0.0] * 7],
          np.array(["a"] * 7), object()]  # fmt: skip
"""Bad values where a (7,) vector goes (panda's q)."""

TWIST = [np.full(6, np.nan), np.r_[np.zeros(5), np.inf], np.zeros(5), np.ones((2, 3)), "t",
         None, {}, [0.0] * 5 + [True], np.zeros(6, complex), np.array(["a"] * 6)]  # fmt: skip
"""Bad values where a twist goes."""

NAME = [3, None, b"x", np.array("panda_hand_tcp"), ["panda_hand_tcp"], object(), 1.5]
"""Bad values where a name goes."""


@pytest.fixture(scope="module")
def panda() -> rrc_pin.Robot:
    return rrc_pin.load("panda")


def raises(call: Callable[[], Any], argument: str) -> None:
    """``call`` raises an RrcPinError naming ``argument`` (and nothing else escapes)."""
    try:
        call()
    except RrcPinError as exc:
        assert getattr(exc, "argument", None) == argument, (argument, exc)
        assert str(exc).startswith(f"{argument}: "), exc
        return
    raise AssertionError(f"no error for {argument}")


def _argument(site: str) -> str:
    """The argument a call site's error names: QPOptions' fields as ``qp.<field>``."""
    name = site.split(".")[1]
    return f"qp.{name}" if site.startswith("QPOptions.") else name


def cases() -> list[tuple[str, str, Any]]:
    """(call site, argument, bad value) of every class."""
    out: list[tuple[str, str, Any]] = []
    for value in NUMBER:
        for site in ("Resolver.dt", "solve.dt", "Controller.dt", "Controller.speed",
                     "reverse.seconds", "reverse.extra", "FrameTask.weight", "PostureTask.gain",
                     "JointTask.rate", "DampingTask.weight", "Deadman.timeout",
                     "DriftCorrection.gain", "QPOptions.time_limit", "JointLimits.margin",
                     "RelativeFrameTask.gain"):  # fmt: skip
            if not (value is None and site == "solve.dt"):  # dt=None: the default
                out.append((site, _argument(site), value))
    for value in VECTOR:
        for site in ("solve.q", "solve.qdot_prev", "Controller.q0", "Controller.q_set",
                     "PostureTask.q_ref", "rows_of.q"):  # fmt: skip
            if value is None and site in ("solve.qdot_prev", "Controller.q0"):
                continue  # None: the default
            if site == "PostureTask.q_ref" and np.shape(value) in ((6,), (7, 1), (1, 7), (0,)):
                site = "solve.posture"  # a vector of the wrong size: refused against the robot
            out.append((site, site.split(".")[1].replace("_set", "").replace("posture", "q_ref"),
                        value))  # fmt: skip
    for value in TWIST:
        for site in ("solve.twist", "step.twist", "FrameTask.twist", "set_twist.twist"):
            if not (value is None and site in ("step.twist", "FrameTask.twist")):
                out.append((site, "twist", value))
    for value in NAME:
        for site in ("solve.ref", "step.ref", "FrameTask.frame", "FrameTask.name",
                     "solve.priority", "JointTask.joint", "RelativeFrameTask.frame_a",
                     "QPOptions.backend"):  # fmt: skip
            if value is None and site in ("FrameTask.name", "solve.ref", "step.ref"):
                continue  # None: the default
            out.append((site, _argument(site), value))
    for value in (0.0, -1.0, 1e-320, 1e-7):
        out += [("Resolver.dt", "dt", value), ("Controller.dt", "dt", value)]
    for value in (0.0, -1.0, 1e308):
        out.append(("reverse.seconds", "seconds", value))
    out += [
        ("solve.command", "command", []),
        ("solve.command", "command", [[]]),
        ("solve.ref", "ref", "tool"),
        ("solve.priority", "priority", "both"),
        ("FrameTask.rows", "rows", "xyz"),
        ("FrameTask.rows", "rows", [7]),
        ("FrameTask.rows", "rows", [[0, 1]]),
        ("FrameTask.weight", "weight", [1.0, 2.0]),
        ("FrameTask.weight", "weight", -1.0),
        ("RelativeFrameTask.target", "target", np.eye(4) * 2.0),
        ("RelativeFrameTask.target", "target", np.full((4, 4), np.nan)),
        ("QPOptions.options", "qp.options", [("iter_limit", 5)]),
        ("QPOptions.options", "qp.options", {"no_such_setting": 1}),
        ("QPOptions.fallbacks", "qp.fallbacks", np.array([["scipy"]])),
        ("QPOptions.fallbacks", "qp.fallbacks", ("scipy", 3)),
        ("QPOptions.backend", "qp.backend", "gurobi"),
        ("Controller.speed", "speed", 1.5),
        ("Controller.strategy", "strategy", "nope"),
        ("Controller.deadman", "deadman", 0.2),
        ("Controller.drift", "drift", "on"),
        ("Resolver.limits", "limits", [0.1]),
        ("Resolver.damping", "damping", 0.05),
        ("Resolver.task", "task", "panda_hand_tcp"),
        ("Resolver.direction_preserving", "direction_preserving", "yes"),
        ("screw_from_points", "points_1", np.full((3, 3), np.nan)),
        ("screw_from_poses", "T1", np.eye(3)),
    ]
    return out


def call_site(site: str, value: Any, panda: rrc_pin.Robot, resolver: Resolver,
              ctl: Controller) -> Callable[[], Any]:  # fmt: skip
    """The call of ``site`` with ``value`` where its argument goes, the rest valid."""
    q = panda.ready()
    twist = np.array([0.05, 0.0, 0.0, 0.0, 0.0, 0.1])
    tool = "panda_hand_tcp"
    return {
        "Resolver.dt": lambda: Resolver(panda, dt=value),
        "Resolver.limits": lambda: Resolver(panda, limits=value),
        "Resolver.damping": lambda: Resolver(panda, damping=value),
        "Resolver.task": lambda: Resolver(panda, task=value),
        "Resolver.direction_preserving": lambda: Resolver(panda, direction_preserving=value),
        "solve.dt": lambda: resolver.solve(q, twist, dt=value),
        "solve.q": lambda: resolver.solve(value, twist),
        "solve.qdot_prev": lambda: resolver.solve(q, twist, qdot_prev=value),
        "solve.twist": lambda: resolver.solve(q, value),
        "solve.command": lambda: resolver.solve(q, value, priority="strict"),
        "solve.ref": lambda: resolver.solve(q, twist, ref=value),
        "solve.priority": lambda: resolver.solve(q, [FrameTask(tool, twist)], priority=value),
        "rows_of.q": lambda: resolver.rows_of(FrameTask(tool), value),
        "solve.posture": lambda: resolver.solve(q, [PostureTask(value)]),
        "Controller.dt": lambda: Controller(panda, dt=value),
        "Controller.q0": lambda: Controller(panda, q0=value),
        "Controller.speed": lambda: Controller(panda, speed=value),
        "Controller.strategy": lambda: Controller(panda, strategy=value),
        "Controller.deadman": lambda: Controller(panda, deadman=value),
        "Controller.drift": lambda: Controller(panda, drift=value),
        "Controller.q_set": lambda: setattr(ctl, "q", value),
        "step.twist": lambda: ctl.step(value, ref="local"),
        "step.ref": lambda: ctl.step(twist, ref=value),
        "reverse.seconds": lambda: ctl.reverse(value),
        "reverse.extra": lambda: ctl.reverse(0.01, extra=value),
        "FrameTask.frame": lambda: FrameTask(value, twist),
        "FrameTask.twist": lambda: FrameTask(tool, value),
        "FrameTask.name": lambda: FrameTask(tool, twist, name=value),
        "FrameTask.rows": lambda: FrameTask(tool, rows=value),
        "FrameTask.weight": lambda: FrameTask(tool, twist, weight=value),
        "set_twist.twist": lambda: FrameTask(tool).set_twist(value),
        "PostureTask.q_ref": lambda: PostureTask(value),
        "PostureTask.gain": lambda: PostureTask(q, gain=value),
        "JointTask.joint": lambda: JointTask(value),
        "JointTask.rate": lambda: JointTask("panda_joint1", value),
        "DampingTask.weight": lambda: DampingTask(value),
        "RelativeFrameTask.frame_a": lambda: RelativeFrameTask(value, tool),
        "RelativeFrameTask.gain": lambda: RelativeFrameTask(tool, tool, gain=value),
        "RelativeFrameTask.target": lambda: RelativeFrameTask(tool, tool, target=value),
        "Deadman.timeout": lambda: Deadman(timeout=value),
        "DriftCorrection.gain": lambda: DriftCorrection(gain=value),
        "QPOptions.time_limit": lambda: Resolver(panda, qp=QPOptions(time_limit=value)),
        "QPOptions.options": lambda: Resolver(panda, qp=QPOptions(options=value)),
        "QPOptions.fallbacks": lambda: Resolver(panda, qp=QPOptions(fallbacks=value)),
        "QPOptions.backend": lambda: Resolver(panda, qp=QPOptions(backend=value)),
        "JointLimits.margin": lambda: JointLimits(margin=value),
        "screw_from_points": lambda: screw_from_points(value, np.eye(3)),
        "screw_from_poses": lambda: screw_from_poses(value, np.eye(4)),
    }[site]


def test_every_bad_input_is_refused_by_name_and_changes_nothing(panda: rrc_pin.Robot) -> None:
    resolver = Resolver(panda, direction_preserving=False, limits=JointLimits(acceleration=20.0))
    ctl = Controller(panda)
    for _ in range(5):  # state worth keeping: warm starts, a record, a reference pose
        resolver.solve(panda.ready(), [3.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        ctl.step([0.02, 0.0, 0.0, 0.0, 0.0, 0.1], ref="local")
    before_resolver = resolver.warm_start_state()
    before_ctl = (ctl.q.copy(), ctl.t, len(ctl.log), ctl.speed, ctl.reference.copy())
    checked = 0
    for site, argument, value in cases():
        raises(call_site(site, value, panda, resolver, ctl), argument)
        checked += 1
    after = resolver.warm_start_state()
    assert before_resolver.keys() == after.keys()
    assert all(np.array_equal(before_resolver[k], after[k]) for k in after)
    assert np.array_equal(ctl.q, before_ctl[0]) and ctl.t == before_ctl[1]
    assert len(ctl.log) == before_ctl[2] and ctl.speed == before_ctl[3]
    assert np.array_equal(ctl.reference, before_ctl[4])
    assert checked > 300
