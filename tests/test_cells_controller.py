"""CellController: the dual cell's object session, the tripod's contacts, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

import rrc_pin
from rrc_pin.cells.controller import CellController
from rrc_pin.errors import InvalidInput
from rrc_pin.solvers.tick.pipeline import scale_and_veer

GRIP_BOUND = 1e-5
"""[m] The grip's bound over a session: one tick's second-order integration remainder after
the projection (measured: at most 4.9e-6 m over 1,000 random ticks at 100 Hz, median 1.5e-9
m; 7.7 mm after 10 s with the projection off)."""
SPEED = np.array([0.15, 0.15, 0.15, 0.4, 0.4, 0.4])


@pytest.fixture(scope="module")
def dual():
    return rrc_pin.load("gsfc_dual")


@pytest.fixture(scope="module")
def tripod():
    return rrc_pin.load("yeh_tripod")


def _session(cell, coupled, ticks=1000, seed=0):
    ctl = CellController(cell, 0.01, coupled=coupled)
    rng = np.random.default_rng(seed)
    out = []
    for k in range(ticks):
        if k % 50 == 0:
            twist = rng.normal(size=6) * SPEED
        out.append(ctl.step({"object": twist}).resolution)
    return ctl, out


@pytest.fixture(scope="module")
def coupled_session(dual):
    return _session(dual, True)


def test_the_grip_holds_within_its_bound_while_limits_bind(coupled_session):
    ctl, resolutions = coupled_session
    limited = sum(1 for r in resolutions if r.active)
    assert limited > 200, limited  # limits hit often
    assert sum(r.status != "exact" for r in resolutions) > 200  # scaled or damped often
    grip = max(rec.grip["object"] for rec in ctl.log)
    assert grip < GRIP_BOUND, grip


def test_the_object_follows_its_target_without_drift(coupled_session):
    ctl, _ = coupled_session
    errors = [rec.errors["object"] for rec in ctl.log]
    assert max(errors) < 5e-3, max(errors)  # while scaled or damped, the target waits
    assert errors[-1] < 1e-4, errors[-1]


def test_both_hands_report_the_same_scale(coupled_session, dual):
    """Each hand's achieved twist is its commanded one (the object's, through the grasp) times
    the one common scale."""
    ctl, resolutions = coupled_session
    checked = 0
    for rec, r in zip(ctl.log, resolutions, strict=True):
        if r.status != "scaled":
            continue
        level = r.problem.levels[0][0]  # the object's task: b = feed-forward + feedback
        T_obj = dual.fk(rec.q, "object")
        scales = []
        for hand in dual.objects["object"].hands:
            T = dual.fk(rec.q, hand)
            v, w = level.b[:3], level.b[3:]
            b_hand = np.concatenate([v + np.cross(w, T[:3, 3] - T_obj[:3, 3]), w])
            achieved = dual.jacobian(rec.q, "world_aligned", hand) @ r.qdot
            scale, veer = scale_and_veer(achieved, b_hand)
            assert veer < 1e-6
            scales.append(scale)
        assert scales[0] == pytest.approx(scales[1], abs=1e-7)
        assert scales[0] == pytest.approx(r.scale, abs=1e-6)
        checked += 1
    assert checked > 50


def test_coupling_off_breaks_the_grip(dual):
    ctl, _ = _session(dual, False, ticks=400)
    grip = max(rec.grip["object"] for rec in ctl.log)
    assert grip > 1000 * GRIP_BOUND, grip


def test_the_common_scale_is_the_lp_maximum(dual):
    """max s: A qdot = s b, C qdot = 0 (grip), lb <= qdot <= ub, by scipy's LP."""
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(40):
        ctl = CellController(dual, 0.01, q0=dual.random_q(rng), damping=None)
        r = ctl.step({"object": rng.normal(size=6) * 3 * SPEED}).resolution
        if r.status != "scaled":
            continue
        p = r.problem
        A, b = p.levels[0][0].A, p.levels[0][0].b
        C = p.equalities[0]
        n = dual.nv
        # variables (qdot, s): maximise s
        A_eq = np.vstack([np.hstack([A, -b[:, None]]), np.hstack([C, np.zeros((len(C), 1))])])
        res = linprog(np.r_[np.zeros(n), -1.0], A_eq=A_eq, b_eq=np.zeros(len(A_eq)),
                      bounds=[*zip(p.box.lb, p.box.ub, strict=True), (0.0, 1.0)],
                      method="highs")  # fmt: skip
        assert res.status == 0
        assert r.scale == pytest.approx(res.x[-1], abs=1e-6)
        checked += 1
    assert checked >= 5, checked


def test_feet_in_support_stay_while_the_body_moves(tripod):
    ctl = CellController(tripod, 0.01)
    feet = {f: tripod.fk(ctl.q, f) for f in tripod.tool_frames}
    body0 = tripod.fk(ctl.q, "body")[:3, 3]
    for _ in range(100):  # 1 s
        ctl.step({"body": [0.05, 0.02, -0.03, 0.05, 0.0, 0.1]})
    slip = max(np.linalg.norm(tripod.fk(ctl.q, f)[:3, 3] - T[:3, 3]) for f, T in feet.items())
    moved = np.linalg.norm(tripod.fk(ctl.q, "body")[:3, 3] - body0)
    assert moved > 0.05
    assert slip < 1e-6 * 1.0, slip  # per second of body motion


def test_a_body_command_that_needs_a_slip_is_scaled(tripod):
    ctl = CellController(tripod, 0.01)
    feet = {f: tripod.fk(ctl.q, f) for f in tripod.tool_frames}
    statuses = [ctl.step({"body": [0.0, 0.0, 0.3, 0, 0, 0]}).resolution for _ in range(120)]
    assert any(r.status == "scaled" and r.scale < 0.5 for r in statuses)
    slip = max(np.linalg.norm(tripod.fk(ctl.q, f)[:3, 3] - T[:3, 3]) for f, T in feet.items())
    assert slip < 1e-6, slip


def test_a_swinging_leg_moves_while_two_feet_carry_the_body(tripod):
    ctl = CellController(tripod, 0.01)
    ctl.swing("leg1")
    assert "leg1" in ctl.commandable()
    feet = {f: tripod.fk(ctl.q, f) for f in ("leg2/flange", "leg3/flange")}
    start = tripod.fk(ctl.q, "leg1/flange")[:3, 3]
    for _ in range(50):
        ctl.step({"leg1": [0.0, 0.0, 0.1, 0, 0, 0]})
    assert tripod.fk(ctl.q, "leg1/flange")[2, 3] - start[2] == pytest.approx(0.05, abs=1e-3)
    slip = max(np.linalg.norm(tripod.fk(ctl.q, f)[:3, 3] - T[:3, 3]) for f, T in feet.items())
    assert slip < 1e-6
    ctl.land("leg1")
    assert "leg1" not in ctl.commandable()


@pytest.mark.parametrize(
    ("commands", "match"),
    [
        ({"middle": np.zeros(6)}, "commands: 'middle' is not commandable.*commandable: object"),
        ({"left": np.zeros(6)}, "left's hand holds 'object'"),
        ({"object": [0, 0, np.nan, 0, 0, 0]}, r"commands\['object'\]"),
        ({"object": np.zeros(5)}, r"commands\['object'\]"),
        ({"object": (np.zeros(6), "hand")}, r"commands\['object'\]: ref 'hand'"),
    ],
)
def test_bad_commands_raise_naming_the_argument_and_change_nothing(dual, commands, match):
    ctl = CellController(dual, 0.01)
    ctl.step({"object": [0.01, 0, 0, 0, 0, 0]})
    q, t, n, target = ctl.q.copy(), ctl.t, len(ctl.log), ctl.target("object")
    with pytest.raises(InvalidInput, match=match):
        ctl.step(commands)
    assert ctl.t == t and len(ctl.log) == n
    np.testing.assert_array_equal(ctl.q, q)
    np.testing.assert_array_equal(ctl.target("object"), target)


def test_a_foot_in_support_cannot_be_commanded(tripod):
    ctl = CellController(tripod, 0.01)
    with pytest.raises(InvalidInput, match=r"foot is in support: swing\('leg2'\) first"):
        ctl.step({"leg2": np.zeros(6)})


def test_free_hands_take_world_local_and_base_axes(dual):
    """With no object held, each hand follows its own command in the frame named."""
    cell = rrc_pin.cells.make_cell(
        {k: (a.robot, a.base) for k, a in dual.arms.items()}, name="free",
        ready={k: dual.ready()[a.q] for k, a in dual.arms.items()},
    )  # fmt: skip
    twist = np.array([0.02, -0.01, 0.03, 0.0, 0.1, 0.0])
    for ref in ("world", "local", "base"):
        ctl = CellController(cell, 0.01, q0=cell.ready())
        T0 = cell.fk(ctl.q, "left/tool")
        r = ctl.step({"left": (twist, ref), "right": np.zeros(6)}).resolution
        R = {"world": np.eye(3), "local": T0[:3, :3], "base": cell.arms["left"].base[:3, :3]}[ref]
        achieved = cell.jacobian(ctl.log[-1].q, "world_aligned", "left/tool") @ r.qdot
        np.testing.assert_allclose(achieved, np.r_[R @ twist[:3], R @ twist[3:]], atol=1e-9)


@pytest.mark.parametrize(("name", "command"), [("object", [0.05, 0.0, 0.02, 0.0, 0.0, 0.1]),
                                               ("body", [0.02, 0.0, 0.01, 0.0, 0.0, 0.1])])
def test_reverse_retraces_the_record(dual, tripod, name, command):
    """One tick per recorded configuration (the projection's offsets passed, ``passing``),
    perhaps one more to reach the start to rounding; the feet kept in support."""
    cell = dual if name == "object" else tripod
    ctl = CellController(cell, 0.01)
    start = ctl.q.copy()
    feet = {f: cell.fk(ctl.q, f) for f in ctl.support}
    for _ in range(30):
        ctl.step({name: command})
    done = ctl.reverse(0.3)
    assert done.steps in (30, 31) and done.reached and done.error < 1e-9, done  # +1: the start
    np.testing.assert_allclose(ctl.q, start, atol=1e-9)
    assert all(rec.mode == "reverse" for rec in ctl.log.records[30:])
    slip = max((np.linalg.norm(cell.fk(ctl.q, f)[:3, 3] - T[:3, 3]) for f, T in feet.items()),
               default=0.0)  # fmt: skip
    assert slip < 1e-9, slip
    with pytest.raises(InvalidInput, match="seconds: asked to reverse"):
        ctl.reverse(10.0)


def test_controller_of_a_cell_is_the_cells_loop(dual):
    """rrc_pin.Controller(cell) makes the cell's controller, on the same loop as one arm's."""
    for robot in (dual, "gsfc_dual"):
        ctl = rrc_pin.Controller(robot, 0.01, gain=5.0)
        assert type(ctl) is CellController and ctl.gain == 5.0
        assert isinstance(ctl, rrc_pin.control.Loop)
        assert isinstance(rrc_pin.Controller("panda"), rrc_pin.control.Loop)
    ctl.speed = 0.5
    ctl.step({"object": [0.02, 0.0, 0.0, 0.0, 0.0, 0.0]})
    assert ctl.log[-1].scale == pytest.approx(1.0)
    with pytest.raises(TypeError, match="strategy"):  # one arm's keyword
        rrc_pin.Controller(dual, strategy="slowdown")


def test_the_speed_override_scales_every_command(dual):
    full, half = CellController(dual, 0.01, damping=None), CellController(dual, 0.01, damping=None)
    half.speed = 0.5
    twist = [0.02, 0.01, 0.0, 0.0, 0.0, 0.05]
    a, b = full.step({"object": twist}), half.step({"object": twist})
    np.testing.assert_allclose(b.resolution.qdot, 0.5 * a.resolution.qdot, atol=1e-9)
    with pytest.raises(InvalidInput, match="speed"):
        half.speed = 1.5
    assert half.speed == 0.5


def test_a_robot_with_several_tool_frames_that_is_no_cell_names_tool_frame_and_cells(dual):
    arm = rrc_pin.load("kr5_3r")
    both = rrc_pin.combine({"a": (arm, np.eye(4)), "b": (arm, np.eye(4))})
    with pytest.raises(InvalidInput, match=r"robot: .*tool_frame=.*make_cell"):
        rrc_pin.Controller(both)


def test_the_deadman_stops_a_stale_command(dual):
    ctl = CellController(dual, 0.01)
    ctl.step({"object": [0.05, 0, 0, 0, 0, 0]})
    for _ in range(60):  # 0.6 s > timeout 0.2 + fade 0.3
        r = ctl.step().resolution
    assert np.abs(r.qdot).max() < 1e-3


def test_the_log_saves_as_csv(dual, tmp_path):
    ctl = CellController(dual, 0.01)
    for _ in range(3):
        ctl.step({"object": [0.01, 0, 0, 0, 0, 0]})
    text = ctl.save(tmp_path / "cell.csv").read_text().splitlines()
    assert len(text) == 4 and text[0].startswith("t,mode,status,scale,levels,error:object")
    with pytest.raises(InvalidInput, match="path: expected a .csv"):
        ctl.save(tmp_path / "cell.npz")
    with pytest.raises(InvalidInput, match="path: cannot write"):
        ctl.save(tmp_path / "missing" / "cell.csv")


@pytest.mark.parametrize("collision", [True, False])
def test_collision_limits_hold_on_a_floating_cell(tripod, collision):
    """A CollisionLimit on the tripod's capsules (a floating base): the swinging foot, lifted
    toward a ball 0.15 m above it, stops at the safety distance (0.02 m, to 1e-5 m); without
    the limit it goes into the ball. The feet in support do not slip either way."""
    model = rrc_pin.CollisionModel(tripod, "capsules")
    ball = model.add_sphere(tripod.fk(tripod.ready(), "leg1/flange")[:3, 3] + [0.0, 0.0, 0.15],
                            0.05)  # fmt: skip
    limit = rrc_pin.CollisionLimit(model)
    ctl = CellController(tripod, 0.01, limits=[rrc_pin.JointLimits(), limit] if collision
                         else None)  # fmt: skip
    ctl.swing("leg1")
    feet = {f: tripod.fk(ctl.q, f)[:3, 3] for f in ("leg2/flange", "leg3/flange")}
    closest = np.inf
    for _ in range(150):  # 1.5 s at 0.1 m/s: 0.15 m up
        ctl.step({"leg1": [0.0, 0.0, 0.1, 0.0, 0.0, 0.0]})
        prox = model.proximity_at(ctl.q, 0.3)
        closest = min([closest, *[d for n, d in zip(prox.names, prox.distance, strict=True)
                                  if ball in n]])  # fmt: skip
    if collision:
        assert closest == pytest.approx(limit.safety, abs=1e-5), closest
    else:
        assert closest < -0.05, closest
    slip = max(np.linalg.norm(tripod.fk(ctl.q, f)[:3, 3] - p) for f, p in feet.items())
    assert slip < 1e-9, slip


def test_setting_q_moves_the_targets_and_anchors_there(tripod):
    """q set from outside (a new start): the feet in support are anchored where they are
    then, and a tick without command stays there (no pull back to the old pose)."""
    ctl = CellController(tripod, 0.01)
    q = ctl.q.copy()
    q[2] -= 0.02  # the body 2 cm lower, the feet through the floor: anchored there
    ctl.q = q
    with pytest.raises(InvalidInput, match="q: "):
        ctl.q = np.zeros(3)
    np.testing.assert_array_equal(ctl.q, q)
    np.testing.assert_allclose(ctl.target("body"), tripod.fk(q, "body"), atol=1e-15)
    for _ in range(10):
        ctl.step()
    np.testing.assert_allclose(ctl.q, q, atol=1e-9)
