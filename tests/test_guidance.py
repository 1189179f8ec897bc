"""Guidance Types I-IV on any arm: goal reached, path property of each type, joint limits held,
the second-order correction's order, the velocity analysis, screw joints, bad input."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import rrc_pin
from rrc_pin.dh import DHChain, DHRow
from rrc_pin.errors import InvalidInput
from rrc_pin.guidance import (
    Command,
    ThesisSolver,
    general,
    general_axes,
    joint_rates,
    operator,
    screw_from_poses,
    screw_motion,
    screw_twist,
    straight_line,
    straight_line_points,
)
from rrc_pin.models import CATALOGUE

ARMS = ["barker6", "rrc_k1607", "panda"]


@pytest.fixture(scope="module")
def arms():
    return {name: rrc_pin.load(name) for name in ARMS}


C2 = 2.0
"""First-order error of one step, at most C2 |step|^2 (step: the norm of its twist, m and rad
together) for these arms (reach about 1 m) at well-conditioned starts: measured up to 0.43."""


def pose_error(A, B):
    """Size of the WORLD twist from pose B to pose A: [m] and [rad] together."""
    return float(np.linalg.norm(pin.log6(pin.SE3(A) * pin.SE3(B).inverse()).vector))


def start_and_goal(arm, rng, size=0.25):
    """A well-conditioned start inside the limits (margin 0.3 rad) and the hand pose of a
    nearby configuration."""
    lower, upper = arm.lower + 0.3, arm.upper - 0.3
    q0 = lower + rng.uniform(size=arm.nq) * (upper - lower)
    while np.linalg.cond(arm.jacobian(q0, ref="world_aligned")) > 50:
        q0 = lower + rng.uniform(size=arm.nq) * (upper - lower)
    q1 = np.clip(q0 + rng.uniform(-size, size, arm.nq), arm.lower, arm.upper)
    return q0, arm.fk(q1)


def within_limits(arm, Q):
    return np.all(Q >= arm.lower - 1e-9) and np.all(Q <= arm.upper + 1e-9)


@pytest.mark.parametrize("name", ARMS)
def test_type_ii_moves_the_hand_on_its_screw_and_reaches_the_goal(arms, name, rng):
    arm = arms[name]
    q0, goal = start_and_goal(arm, rng)
    k = 20
    path = screw_motion(arm, q0, goal, k, solver=rrc_pin.Resolver(arm, dt=1.0))
    xi = screw_twist(screw_from_poses(arm.fk(q0), goal))
    step = np.linalg.norm(xi) / k
    # on the screw: pose i is exp(i xi / k) T0 up to the first-order error of i steps
    for i, T in enumerate(path.hand):
        planned = (pin.exp6(pin.Motion(xi * i / k)) * pin.SE3(path.hand[0])).homogeneous
        assert pose_error(planned, T) <= C2 * i * step**2 + 1e-12, (i, pose_error(planned, T))
    assert pose_error(goal, path.hand[-1]) <= C2 * k * step**2
    assert within_limits(arm, path.q) and np.all(path.scale > 1.0 - 1e-9)
    relocated = screw_motion(arm, q0, goal, k, relocate=True, solver=rrc_pin.Resolver(arm, dt=1.0))
    assert pose_error(goal, relocated.hand[-1]) <= C2 * step**2  # one step's error


@pytest.mark.parametrize("name", ARMS)
def test_type_iii_keeps_the_hand_point_on_its_line(arms, name, rng):
    arm = arms[name]
    q0, goal = start_and_goal(arm, rng)
    k = 20
    path = straight_line(arm, q0, goal, k, solver=rrc_pin.Resolver(arm, dt=1.0))
    a, b = path.hand[0][:3, 3], goal[:3, 3]
    line = (b - a) / np.linalg.norm(b - a)
    step = np.linalg.norm(screw_twist(screw_from_poses(path.hand[0], goal))) / k
    for T in path.hand:
        off = T[:3, 3] - a - ((T[:3, 3] - a) @ line) * line
        assert np.linalg.norm(off) <= C2 * step**2  # the first-order error of one step
    assert pose_error(goal, path.hand[-1]) <= C2 * step**2
    assert within_limits(arm, path.q)


@pytest.mark.parametrize("name", ARMS)
def test_type_iv_commands_in_base_and_hand_axes(arms, name, rng):
    arm = arms[name]
    q0, _ = start_and_goal(arm, rng)
    T0 = arm.fk(q0)
    commands = [
        Command((0.0, 0.0, 1.0), 0.05, np.radians(-20.0), "world_aligned"),
        Command((1.0, 0.0, 0.0), -0.03, np.radians(10.0), "local"),
    ]
    k = 10
    paths = operator(arm, q0, commands, k, solver=rrc_pin.Resolver(arm, dt=1.0),
                     correction="newton")  # fmt: skip
    first = pin.exp6(pin.Motion(np.r_[0, 0, 0.05, 0, 0, np.radians(-20)]))
    about_hand = pin.SE3(np.eye(3), T0[:3, 3])
    T1 = (about_hand * first * about_hand.inverse() * pin.SE3(T0)).homogeneous
    np.testing.assert_allclose(paths[0].hand[-1], T1, atol=1e-9)
    x = T1[:3, 0]
    second = (
        pin.SE3(np.eye(3), T1[:3, 3])
        * pin.exp6(pin.Motion(np.r_[-0.03 * x, np.radians(10.0) * x]))
        * pin.SE3(np.eye(3), -T1[:3, 3])
    )
    np.testing.assert_allclose(paths[1].hand[-1], (second * pin.SE3(T1)).homogeneous, atol=1e-9)
    assert all(within_limits(arm, p.q) for p in paths)


def test_a_world_command_turns_about_an_axis_through_the_base_origin(arms):
    """``world``: the spatial twist at the base origin, as Pinocchio's WORLD frame."""
    arm = arms["panda"]
    q0 = arm.ready()
    (path,) = operator(arm, q0, [Command((0.0, 0.0, 1.0), 0.02, 0.2, "world")], 10,
                       solver=rrc_pin.Resolver(arm, dt=1.0), correction="newton")  # fmt: skip
    moved = pin.exp6(pin.Motion(np.r_[0.0, 0.0, 0.02, 0.0, 0.0, 0.2])) * pin.SE3(arm.fk(q0))
    np.testing.assert_allclose(path.hand[-1], moved.homogeneous, atol=1e-9)


def test_the_thesis_frame_names_still_work_for_one_release_with_a_warning():
    with pytest.warns(DeprecationWarning, match="'global' is deprecated.*'world_aligned'"):
        old = Command((0.0, 0.0, 1.0), 0.05, 0.1, "global")
    assert old.ref == "world_aligned"
    with pytest.warns(DeprecationWarning) as caught:
        hand = Command((0.0, 0.0, 1.0), 0.05, 0.1, frame="hand")
    assert [str(w.message).split(" is ")[0] for w in caught] == [
        "guidance.Command(frame=)", "guidance.Command ref 'hand'"]
    assert hand.ref == "local" and hand == Command((0.0, 0.0, 1.0), 0.05, 0.1, "local")
    with pytest.warns(DeprecationWarning, match=r"Command.frame is deprecated"):
        assert hand.frame == "local"


@pytest.mark.parametrize("name", ARMS)
def test_type_i_reaches_the_goal_with_straight_hand_point(arms, name, rng):
    arm = arms[name]
    q0, goal = start_and_goal(arm, rng)
    path = general(arm, q0, goal, 15, solver=rrc_pin.Resolver(arm, dt=1.0), correction="newton")
    assert pose_error(goal, path.hand[-1]) < 1e-9
    a, b = path.hand[0][:3, 3], goal[:3, 3]
    for i, T in enumerate(path.hand):  # Example 4: the hand point on the line, k equal parts
        np.testing.assert_allclose(T[:3, 3], a + i / 15 * (b - a), atol=1e-9)
    assert within_limits(arm, path.q)


def test_resolver_holds_the_joint_limits_where_the_goal_needs_more(arms):
    arm = arms["panda"]
    q0 = arm.neutral()
    q0[3] = arm.upper[3] - 0.05
    q_far = q0.copy()
    q_far[3] = arm.upper[3] + 0.4  # past the limit
    goal = arm.fk(q_far)
    path = screw_motion(arm, q0, goal, 10, relocate=True, solver=rrc_pin.Resolver(arm, dt=1.0))
    assert within_limits(arm, path.q)
    assert np.any(path.scale < 1.0)
    thesis = screw_motion(arm, q0, goal, 10, relocate=True)  # the thesis's solve knows no limits
    assert not within_limits(arm, thesis.q)


def test_type_i_examples_1_to_3_fixed_axes(arms, rng):
    """Example 1: a turn about z through the hand point leaves the point in place (first order);
    Example 3 adds a translation along x."""
    arm = arms["barker6"]
    q0, _ = start_and_goal(arm, rng)
    T0 = arm.fk(q0)
    k = 10
    path = general_axes(arm, q0, ((0, 0, 1), 0.4), ((1, 0, 0), 0.0), k, correction="newton")
    np.testing.assert_allclose(path.hand[-1][:3, 3], T0[:3, 3], atol=1e-9)
    np.testing.assert_allclose(path.hand[-1][:3, :3], pin.exp3(np.r_[0, 0, 0.4]) @ T0[:3, :3],
                               atol=1e-9)  # fmt: skip
    path = general_axes(arm, q0, ((0, 0, 2), 0.4), ((3, 0, 0), 0.05), k)
    step = np.hypot(0.4, 0.05) / k
    assert np.linalg.norm(path.hand[-1][:3, 3] - T0[:3, 3] - [0.05, 0, 0]) <= C2 * k * step**2


def test_second_order_correction_order_on_random_cases(arms, rng):
    """Type II, the screw located once: the first-order end error halves when k doubles
    (order 1/k); Newton's is at rounding level. Eq. (5-5) as printed, without the cross terms
    between joints, stays of order 1/k on a 6R arm (docs/errata.md)."""
    arm = arms["barker6"]
    ratios = {"none": [], "eq5_5": []}
    for _ in range(3):
        q0, goal = start_and_goal(arm, rng)
        for correction in ratios:
            e10 = pose_error(goal, screw_motion(arm, q0, goal, 10, correction=correction).hand[-1])
            e20 = pose_error(goal, screw_motion(arm, q0, goal, 20, correction=correction).hand[-1])
            ratios[correction].append(e10 / e20)
        newton = screw_motion(arm, q0, goal, 10, correction="newton")
        assert pose_error(goal, newton.hand[-1]) < 1e-12
    assert np.all(np.abs(np.array(ratios["none"]) - 2.0) < 0.2)
    assert np.all(np.abs(np.array(ratios["eq5_5"]) - 2.0) < 0.2)  # not 4: first order


def test_eq_5_5_is_second_order_for_one_revolute_joint():
    """Configuration #2 (three prismatic joints, then the revolute joints): where only joint 4
    turns there are no cross terms, and eq. (5-5) is second order: the end error falls 4x when
    k doubles, against 2x without it."""
    arm = CATALOGUE["nadkarni_c2"].chain
    q0 = np.asarray(CATALOGUE["nadkarni_c2"].named_poses["table_a2_7"])
    command = Command((0.0, 0.0, 1.0), 0.1, np.radians(-30.0))
    T0 = arm.fk(q0)
    screw = pin.SE3(np.eye(3), T0[:3, 3]) * pin.exp6(pin.Motion(np.r_[0, 0, 0.1, 0, 0, -np.pi / 6]))
    target = (screw * pin.SE3(np.eye(3), -T0[:3, 3]) * pin.SE3(T0)).translation
    errors = {}
    for correction in ("none", "eq5_5"):
        for k in (10, 20):
            end = operator(arm, q0, [command], k, correction=correction)[0].hand[-1]
            errors[correction, k] = np.linalg.norm(end[:3, 3] - target)
    assert errors["none", 10] / errors["none", 20] == pytest.approx(2.0, abs=0.2)
    assert errors["eq5_5", 10] < errors["none", 10] / 20
    assert errors["eq5_5", 10] / errors["eq5_5", 20] == pytest.approx(4.0, abs=0.4)


def test_velocity_analysis_eqs_5_1_to_5_4(arms, rng):
    """Rates from the step's increments (5-3), (5-4) are J^-1 of the hand's twist at that speed."""
    arm = arms["rrc_k1607"]
    q0, goal = start_and_goal(arm, rng)
    path = screw_motion(arm, q0, goal, 10)
    xi = screw_twist(screw_from_poses(arm.fk(q0), goal)) / 10
    dtheta = np.linalg.norm(xi[3:])
    rates = joint_rates(path.q[1] - path.q[0], dtheta, 0.5)
    expected = np.linalg.lstsq(arm.jacobian(q0, ref="world"), xi / dtheta * 0.5, rcond=None)[0]
    np.testing.assert_allclose(rates, expected, atol=1e-12)
    # a pure translation: delta r and |V_H| in place of delta theta and |W_H|
    np.testing.assert_allclose(joint_rates([0.01, -0.02], 0.01, 0.2), [0.2, -0.4])
    with pytest.raises(InvalidInput, match="^hand_step:"):
        joint_rates([0.1], 0.0, 1.0)
    with pytest.raises(InvalidInput, match="^increments:"):
        joint_rates([np.nan], 0.1, 1.0)


def test_screw_joints_with_the_thesis_solver():
    """A chain with a screw joint (pitch 0.01 m/rad), not expressible in URDF: the thesis's
    solve on the DH chain's Jacobian reaches the goal."""
    rows = (
        DHRow(a=0.0, alpha=np.pi / 2, d=0.3, theta=0.0, kind="screw", pitch=0.01),
        DHRow(a=0.4, alpha=0.0, d=0.0, theta=0.0),
        DHRow(a=0.3, alpha=np.pi / 2, d=0.0, theta=0.0),
        DHRow(a=0.0, alpha=-np.pi / 2, d=0.2, theta=0.0),
        DHRow(a=0.0, alpha=np.pi / 2, d=0.0, theta=0.0),
        DHRow(a=0.0, alpha=0.0, d=0.1, theta=0.0, kind="prismatic"),
    )
    arm = DHChain("nadkarni", rows)
    q0 = np.array([0.2, 0.4, -0.6, 0.3, 0.7, 0.05])
    goal = arm.fk(q0 + np.array([0.1, -0.1, 0.1, 0.05, -0.1, 0.02]))
    path = screw_motion(arm, q0, goal, 10, correction="newton")
    assert pose_error(goal, path.hand[-1]) < 1e-10
    assert path.escapes == ()


def test_singularity_escape():
    """At a singular start the thesis solver gives the joints its increments first."""
    arm = rrc_pin.load("barker6")
    q0 = np.array([0.3, -0.4, 0.5, 0.2, 0.0, 0.1])  # wrist singular (theta5 = 0)
    goal = arm.fk(q0 + 0.1)
    solver = ThesisSolver(singular_cond=1e4)
    assert np.linalg.cond(arm.jacobian(q0, ref="world")) > 1e4
    path = screw_motion(arm, q0, goal, 10, relocate=True, solver=solver, correction="newton")
    assert path.escapes == (0,)
    np.testing.assert_allclose(path.q[0], q0 + 0.05 * np.array([-1, 1, -1, 1, -1, 1]))
    assert np.isfinite(path.q).all() and pose_error(goal, path.hand[-1]) < 1e-9


def test_bad_input_names_the_argument(arms):
    arm = arms["barker6"]
    q0 = arm.neutral()
    goal = arm.fk(q0)
    for steps in (0, -1, 2.5, True):
        with pytest.raises(InvalidInput, match="^steps:"):
            screw_motion(arm, q0, goal, steps)
    with pytest.raises(InvalidInput, match="^goal:"):
        general(arm, q0, np.full((4, 4), np.nan), 5)
    with pytest.raises(InvalidInput, match="^q0:"):
        straight_line(arm, q0[:3], goal, 5)
    with pytest.raises(InvalidInput, match="^q0:"):
        screw_motion(arm, np.full(6, np.inf), goal, 5)
    with pytest.raises(InvalidInput, match="^solver:"):
        screw_motion(arm, q0, goal, 5, solver="lstsq")
    with pytest.raises(InvalidInput, match="^correction:"):
        screw_motion(arm, q0, goal, 5, correction="third")
    points = [[0, 0, 0], [0, 0, 1], [1, 0, 0]]
    with pytest.raises(InvalidInput, match="^spacing:"):
        straight_line_points(arm, q0, points, 5, spacing=0.0)
    with pytest.raises(InvalidInput, match="^goal_points:"):
        straight_line_points(arm, q0, [[0, 0, 0], [0, 0, 1], [0, 0, 2]], 5, spacing=0.1)
    with pytest.raises(InvalidInput, match=r"^commands\[0\]\.ref:"):
        operator(arm, q0, [Command((0, 0, 1), 0.1, 0.1, "tool")], 5)
    with pytest.raises(InvalidInput, match=r"^commands\[1\]\.axis:"):
        operator(arm, q0, [Command((0, 0, 1), 0.1, 0.1), Command((0, 0, 0), 0.1, 0.1)], 5)
    with pytest.raises(InvalidInput, match=r"^commands\[0\]\.d:"):
        operator(arm, q0, [Command((0, 0, 1), np.nan, 0.1)], 5)
    with pytest.raises(InvalidInput, match="^rotation:"):
        general_axes(arm, q0, ((0, 0, 0), 0.1), ((1, 0, 0), 0.1), 5)
    with pytest.raises(InvalidInput, match="^b_form:"):
        screw_motion(arm, q0, goal, 5, b_form="second")
    with pytest.raises(InvalidInput, match="^b_form:"):
        straight_line_points(arm, q0, points, 5, spacing=0.1, b_form="second")
    for closing in (-1, 1.5, True):
        with pytest.raises(InvalidInput, match="^closing:"):
            screw_motion(arm, q0, goal, 5, closing=closing)
        with pytest.raises(InvalidInput, match="^closing:"):
            straight_line_points(arm, q0, points, 5, spacing=0.1, closing=closing)
    for substeps in (0, 2.0, lambda screw: 0):
        with pytest.raises(InvalidInput, match="^substeps:"):
            straight_line_points(arm, q0, points, 5, spacing=0.1, substeps=substeps)
    with pytest.raises(InvalidInput, match="^escape:"):
        ThesisSolver(escape=(0.0, 0.0))
    with pytest.raises(InvalidInput, match="^singular_cond:"):
        ThesisSolver(singular_cond=0.5)


def test_disps_b_is_the_twist_with_the_origins_second_order_term(rng):
    """disp_step: the twist / k less dtheta^2 / 2 U x (U x rho_n), batched as the screws are;
    equal to the twist for a pure translation and for an axis through the base origin."""
    from rrc_pin.guidance import Screw, disp_step

    T1 = [pin.SE3.Random().homogeneous for _ in range(4)]
    T2 = [pin.SE3.Random().homogeneous for _ in range(4)]
    screws = screw_from_poses(np.array(T1), np.array(T2))
    B = disp_step(screws, 3)
    for n in range(4):
        s = screw_from_poses(T1[n], T2[n])
        term = 0.5 * (float(s.theta) / 3) ** 2 * np.cross(s.u, np.cross(s.u, s.rho))
        np.testing.assert_allclose(B[n], screw_twist(s) / 3 - np.r_[term, 0, 0, 0], atol=1e-14)
        np.testing.assert_allclose(disp_step(s, 3, "twist"), screw_twist(s) / 3, atol=1e-15)
        assert np.linalg.norm(term) > 1e-4
    shift = Screw(np.array([0.0, 0, 1]), np.zeros(3), np.array(0.3), np.array(0.0), np.inf)
    through = Screw(np.array([0.0, 0, 1]), np.zeros(3), np.array(0.1), np.array(0.5), 0.2)
    for s in (shift, through):
        np.testing.assert_allclose(disp_step(s, 2), screw_twist(s) / 2, atol=1e-15)


@pytest.mark.parametrize("name", ARMS)
def test_type_iii_divisions_in_several_steps_with_disps_b(arms, name, rng):
    """Type III with each division a Type II run of 3 steps of DISP's B and one closing step:
    3k + 1 steps, ``division_ends`` every third row and the last, the hand point within one
    step's error of its line at the division ends, and the closing step lands on the goal
    to second order in the remaining displacement (DISP's B is not the exact twist: its extra
    term is second order too)."""
    arm = arms[name]
    q0, goal = start_and_goal(arm, rng)
    k = 8
    T0 = arm.fk(q0)
    points = np.stack(
        [goal[:3, 3], goal[:3, 3] + 0.1 * goal[:3, 2], goal[:3, 3] + 0.1 * goal[:3, 0]]
    )
    path = straight_line_points(
        arm, q0, points, k, spacing=0.1, substeps=3, b_form="disp", closing=1
    )
    assert len(path.q) == 3 * k + 2 and path.escapes == ()
    assert path.division_ends == (*range(3, 3 * k + 1, 3), 3 * k + 1)
    a, b = T0[:3, 3], goal[:3, 3]
    line = (b - a) / np.linalg.norm(b - a)
    step = np.linalg.norm(screw_twist(screw_from_poses(T0, goal))) / k
    for e in path.division_ends:
        p = path.hand[e][:3, 3]
        assert np.linalg.norm(p - a - ((p - a) @ line) * line) <= C2 * step**2
    before = pose_error(goal, path.hand[-2])
    after = pose_error(goal, path.hand[-1])
    assert after <= 20.0 * before**2 < 0.1 * before  # second order (measured up to 8.7)


def test_erratum_examples_1_and_3_sign_of_b(arms, rng):
    """Example 1: B = [0 0 dtheta  -rho2 dtheta  rho1 dtheta  0] (rows [w; v]) as printed is
    +dtheta u_w x rho_0: the hand point then moves 2 dtheta |rho_0| instead of staying. Eq.
    (4-11a) gives B's lower half dr u_v - dtheta u_w x rho_0 = (rho2, -rho1, 0) dtheta."""
    arm = arms["barker6"]
    q0, _ = start_and_goal(arm, rng)
    rho = arm.fk(q0)[:3, 3]
    dtheta = 1e-6
    J_hand = arm.jacobian(q0, ref="world_aligned")  # velocity of the hand point
    J = arm.jacobian(q0, ref="world")
    printed = np.r_[-rho[1] * dtheta, rho[0] * dtheta, 0.0, 0.0, 0.0, dtheta]  # [v; w]
    corrected = np.r_[rho[1] * dtheta, -rho[0] * dtheta, 0.0, 0.0, 0.0, dtheta]
    moved = J_hand[:3] @ np.linalg.solve(J, printed)
    np.testing.assert_allclose(np.linalg.norm(moved), 2 * dtheta * np.hypot(rho[0], rho[1]))
    still = J_hand[:3] @ np.linalg.solve(J, corrected)
    assert np.linalg.norm(still) < 1e-15
    # Example 3 adds dr along x to the v_x entry, with the same sign slip on the rho terms
    dr = 2e-6
    ex3 = np.r_[rho[1] * dtheta + dr, -rho[0] * dtheta, 0.0, 0.0, 0.0, dtheta]
    np.testing.assert_allclose(J_hand[:3] @ np.linalg.solve(J, ex3), [dr, 0, 0], atol=1e-15)


def test_erratum_illustration_4_goal_b2_in_the_text():
    """The text gives b2 = [-20.65 -9.29 -5.85]; the data cards (Table A2-5) -8.29. With -9.29
    the point is 1.71 units from a2 (the hand's points are 1 unit apart; 0.995 with -8.29), and
    the thesis's computed hand prints -8.29."""
    a2 = np.array([-20.30, -7.83, -6.66])
    assert np.linalg.norm(np.array([-20.65, -9.29, -5.85]) - a2) == pytest.approx(1.71, abs=0.01)
    assert np.linalg.norm(np.array([-20.65, -8.29, -5.85]) - a2) == pytest.approx(0.995, abs=0.001)


def test_exports_exist_and_are_sorted():
    from rrc_pin import guidance

    namespace: dict = {}
    exec("from rrc_pin.guidance import *", namespace)
    assert set(guidance.__all__) <= set(namespace)
    assert guidance.__all__ == sorted(guidance.__all__)


@pytest.mark.parametrize("degrees", [150.0, 170.0, 179.0, 180.0])
def test_type_iii_turns_gradually_up_to_a_half_turn(degrees):
    """Issue 33 item 5: panda at its ready pose, the goal 0.1 m along x and y turned about the
    hand's z, 20 divisions. The points' division turned the largest step by 20.5 deg at 150
    (uniform: 7.5), 48.8 at 170, 85 at 179 (1.33 rad of joint motion), and raised a foreign
    'points' error at 180; the divided turn gives 1.00x uniform (within 1.1x here)."""
    arm = rrc_pin.load("panda")
    q0 = arm.ready()
    T0 = arm.fk(q0)
    goal = T0.copy()
    goal[:3, 3] += [0.1, 0.1, 0.0]
    goal[:3, :3] = T0[:3, :3] @ pin.exp3(np.radians(degrees) * np.array([0.0, 0.0, 1.0]))
    k = 20
    path = straight_line(arm, q0, goal, k)
    turns = [pin.log3(path.hand[i + 1][:3, :3] @ path.hand[i][:3, :3].T) for i in range(k)]
    angles = np.degrees(np.linalg.norm(turns, axis=1))
    assert angles.max() <= 1.1 * degrees / k and angles.min() >= 0.9 * degrees / k
    axes = np.array(turns) / np.radians(angles)[:, None]
    assert np.all(axes @ axes[0] > 0.99)  # one axis, one way: no turn back
    assert np.all(np.abs(axes @ T0[:3, 2]) > 0.99)  # the hand's z
    assert np.abs(np.diff(path.q, axis=0)).max() < 0.2  # [rad] a joint in a step (1.34 at 179)
    assert pose_error(goal, path.hand[-1]) < 1e-3
    line = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    for T in path.hand:
        off = T[:3, 3] - T0[:3, 3]
        assert np.linalg.norm(off - (off @ line) * line) < 1e-3  # [m] on the line
    if degrees == 180.0:  # the thesis's division of the points cannot pass a half turn
        points = np.stack([goal[:3, 3], goal[:3, 3] + goal[:3, 2], goal[:3, 3] + goal[:3, 0]])
        with pytest.raises(InvalidInput, match="^goal_points: division 10 of 20: the divided"):
            straight_line_points(arm, q0, points, k, spacing=1.0)


# -- frame=: one frame of a robot with several tool frames ------------------------------------


def _goal_of(cell, q, frame):
    """A goal 5 cm and 0.2 rad from ``frame``'s pose at ``q``."""
    T = cell.fk(q, frame)
    goal = T.copy()
    goal[:3, 3] += [0.03, -0.02, 0.04]
    goal[:3, :3] = pin.exp3(np.array([0.0, 0.2, 0.1])) @ T[:3, :3]
    return goal


@pytest.mark.parametrize("solver", ["thesis", "resolver"])
@pytest.mark.parametrize("kind", ["straight_line", "screw_motion", "general"])
def test_guidance_takes_frame_on_a_cell(dual, kind, solver):
    """The frame named reaches its goal; the other arm's joints do not move."""
    q0 = dual.ready()
    goal = _goal_of(dual, q0, "left/tool")
    run = {"straight_line": straight_line, "screw_motion": screw_motion, "general": general}[kind]
    chosen = rrc_pin.Resolver(dual, dt=1.0) if solver == "resolver" else "thesis"
    path = run(dual, q0, goal, 10, solver=chosen, correction="newton", frame="left/tool")
    end = dual.fk(path.q[-1], "left/tool")
    assert np.linalg.norm(end[:3, 3] - goal[:3, 3]) < 1e-6
    assert np.abs(pin.log3(end[:3, :3] @ goal[:3, :3].T)).max() < 1e-6
    np.testing.assert_allclose(path.hand[-1], end, atol=1e-12)  # the path's hand is the frame's
    right = dual.arms["right"].q
    np.testing.assert_array_equal(path.q[:, right], np.tile(q0[right], (len(path.q), 1)))
    if solver == "resolver":
        assert (path.q >= dual.lower - 1e-12).all() and (path.q <= dual.upper + 1e-12).all()


def test_general_axes_and_operator_take_frame(dual):
    q0 = dual.ready()
    T0 = dual.fk(q0, "right/tool")
    path = general_axes(dual, q0, ((0, 0, 1), 0.2), ((1, 0, 0), 0.03), 10, correction="newton",
                        frame="right/tool")  # fmt: skip
    end = dual.fk(path.q[-1], "right/tool")
    assert end[0, 3] - T0[0, 3] == pytest.approx(0.03, abs=1e-6)
    paths = operator(dual, q0, [Command((0.0, 0.0, 1.0), 0.05, 0.0)], 5, frame="right/tool")
    moved = dual.fk(paths[-1].q[-1], "right/tool")[:3, 3] - T0[:3, 3]
    np.testing.assert_allclose(moved, [0.0, 0.0, 0.05], atol=1e-3)


def test_without_frame_a_cell_still_asks_for_one(dual):
    with pytest.raises(rrc_pin.ToolFrameRequired, match="frame: .*left/tool, right/tool"):
        straight_line(dual, dual.ready(), np.eye(4), 5)


@pytest.mark.parametrize(
    ("frame", "error", "match"),
    [
        ("middle", InvalidInput, r"frame: gsfc_dual has no frame 'middle'; its tool frames: "
                                 r"left/tool, right/tool, object"),
        (3, InvalidInput, "frame: expected a frame name"),
    ],
)
def test_an_unknown_frame_is_refused_with_the_names(dual, frame, error, match):
    with pytest.raises(error, match=match):
        straight_line(dual, dual.ready(), np.eye(4), 5, frame=frame)


def test_frame_needs_a_robot_and_no_floating_base():
    chain = DHChain("standard", [DHRow(a=0.3, alpha=0.0, d=0.0, theta=0.0)] * 6)
    with pytest.raises(InvalidInput, match="frame: frame= needs a rrc_pin.Robot"):
        screw_motion(chain, np.zeros(6), np.eye(4), 5, frame="tool")
    tripod = rrc_pin.load("yeh_tripod")
    with pytest.raises(InvalidInput, match="arm: yeh_tripod has a floating base"):
        straight_line(tripod, tripod.ready(), np.eye(4), 5, frame="leg1/flange")
