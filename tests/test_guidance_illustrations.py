"""Nadkarni's Appendix II, Illustrations 2 and 4-7, against the printed digits.

Tolerance: half a unit of the last printed digit (``assert_printed``) where the reading in
rrc_pin.guidance.illustrations reproduces a table; otherwise a stated tolerance and the reason,
recorded in docs/errata.md.
"""

from __future__ import annotations

import re

import numpy as np
import pinocchio as pin
import pytest

from rrc_pin.errors import InvalidInput
from rrc_pin.guidance import screw_motion
from rrc_pin.guidance.illustrations import (
    ESCAPE_4,
    ILLUSTRATION_4_GOAL,
    ILLUSTRATION_4_HAND,
    ILLUSTRATION_5_GOAL,
    TABLE_A2_6,
    TABLE_A2_6_FINAL,
    TABLE_A2_9,
    TABLE_A2_11,
    chain,
    frames_from_points,
    hand_points,
    illustration_2,
    illustration_4,
    illustration_5,
    illustration_6,
    illustration_7,
    printed_step_twists,
    report,
    start,
)
from rrc_pin.models import INCH


def assert_printed(computed: float, printed: str, slack: float = 0.0) -> None:
    """``computed`` rounds to the printed value: half a unit of the last printed digit."""
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    tol = 0.5 * 10.0**-decimals + 1e-9 + slack
    assert abs(computed - float(printed)) <= tol, (computed, printed)


def assert_rows(rows, slack: float = 0.0) -> None:
    for row in rows:
        for c, p in zip(row.computed, row.printed, strict=True):
            assert_printed(c, p, slack)


def test_illustration_2_every_printed_number():
    """All 84 numbers to the printed digits but rho_n(3)'s x, printed 0.65 for 0.065."""
    rows = illustration_2()
    assert len(rows) == 28
    wrong = [r for r in rows if r.label == "rho_n(3)"]
    assert_rows([r for r in rows if r not in wrong])
    assert abs(wrong[0].computed[0] - 0.65) > 0.5
    assert_printed(wrong[0].computed[0], "0.065")


def test_illustration_7_every_row_to_the_printed_digits():
    """Type I, k = 35, the screw located again from the hand reached at every step."""
    rows, path = illustration_7()
    assert len(path.q) == 36
    assert_rows(rows)  # 10 printed steps, the final joints and the three hand points


def test_illustration_7_located_once_does_not_reproduce():
    """Eq. (4-17) as printed (U, theta and R located once): the table is not reproduced."""
    from rrc_pin.guidance import general

    goal = frames_from_points(np.array([[10, -10, 20], [11, -10, 20], [10, -10, 19.0]]) * INCH)
    path = general(chain("nadkarni_c2"), start("nadkarni_c2"), goal, 35, relocate=False)
    assert abs(path.q[-1][0] / INCH - (-15.0)) > 0.2  # r1 ends 0.23 short


def test_illustration_6_stage_1_to_the_printed_digits_stage_2_within_one_unit():
    """Type IV: stage 1 (9 steps) and its rho_0 to the printed digits; stage 2 (4 steps, hand
    frame) within one unit of the last digit (0.01): the computed values sit 0.004-0.006 from
    the printed ones, as if stage 2 started from a slightly different stage-1 end."""
    rows, paths = illustration_6()
    assert [len(p.q) - 1 for p in paths] == [9, 4]
    stage_1 = [r for r in rows if r.label in ("step 1", "step 2", "step 3", "step 9")]
    stage_1.append(next(r for r in rows if r.label == "rho_0 end of stage 1"))
    assert_rows(stage_1)
    assert_rows([r for r in rows if r not in stage_1], slack=0.005)


def test_illustration_6_refutes_disps_b_for_type_iv():
    """Type IV (GUIDM) keeps the twist of eq. (4-21): with DISP's second-order term added to
    stage 1's constant step, the end of stage 1 (printed -1.20 30.07 4.00 30.00) moves by
    more than 0.3 in, where the twist gives it to the printed digits."""
    from rrc_pin.guidance import Screw, disp_step

    arm, q = chain("nadkarni_c2"), start("nadkarni_c2")
    foot = np.array([15.0, -25.0, 0.0]) * INCH  # the normal from the origin to the axis
    screw = Screw(np.array([0.0, 0, 1]), foot, np.array(4.0 * INCH), np.radians(-30.0), 0.0)
    ends = {}
    for b_form in ("twist", "disp"):
        B, qi = disp_step(screw, 9, b_form), q.copy()
        for _ in range(9):
            qi = qi + np.linalg.solve(arm.jacobian(qi, ref="world"), B)
        ends[b_form] = np.r_[qi[:3] / INCH, np.degrees(qi[3])]
    printed = [float(v) for v in TABLE_A2_11[3][1][:4]]
    for c, p in zip(ends["twist"], TABLE_A2_11[3][1][:4], strict=True):
        assert_printed(c, p)
    assert np.abs(ends["disp"] - printed)[:2].max() > 0.3


def test_illustration_5_every_row_to_the_printed_digits():
    """Type III as DISP ran it: 27 divisions toward the goal triangle of the run (b_2 5 units
    out), each division a Type II run of 3, 3, 3, 3, 2, 2, 1, 1, 1, ... steps with DISP's B,
    and one closing step: every printed number of the nine rows and of the final row to the
    printed digits, but step 1's theta4, printed 10.000 for 10.886 (docs/errata.md); 38
    steps, as the table's "Total 38 steps"."""
    rows, path = illustration_5()
    assert len(path.q) - 1 == 38
    assert np.diff((0, *path.division_ends))[:9].tolist() == [3, 3, 3, 3, 2, 2, 1, 1, 1]
    assert len(path.division_ends) == 28  # 27 divisions and the closing step
    misprint = rows[0].computed[3]
    assert misprint == pytest.approx(np.degrees(np.arctan(5 / 26)), abs=1e-9)  # 10.886
    assert abs(misprint - float(rows[0].printed[3])) > 0.88
    for n, row in enumerate(rows):
        for j, (c, p) in enumerate(zip(row.computed, row.printed, strict=True)):
            if (n, j) != (0, 3):
                assert_printed(c, p)


def planned_divisions(arm, q0, goal_points, k=27, count=9):
    """The first ``count`` division frames of Type III from the hand at q0 (spacing 1 in)."""
    corners = np.array(hand_points(arm.fk(q0))) * INCH
    return [
        frames_from_points(corners + i / k * (goal_points - corners)) for i in range(1, count + 1)
    ]


def one_division(arm, q, target, n, b_form):
    """n steps of one vector B along the screw from the hand at q to target (DISPM)."""
    from rrc_pin.guidance import screw_from_poses
    from rrc_pin.guidance.screw_motion import disp_step

    B = disp_step(screw_from_poses(arm.fk(q), target), n, b_form)
    for _ in range(n):
        q = q + np.linalg.solve(arm.jacobian(q, ref="world"), B)
    return q


def test_illustration_5_each_division_from_the_printed_row_before_it():
    """Local evidence, free of the run's history: from each printed row (step 1's theta4 read
    as 10.886), one division of DISP's B gives the next printed row's r1, r2, r3 and theta4 to
    the printed digits (printed rounding of the row it starts from allowed: 0.0005 in on r1
    and r2). With eq. (4-19a)'s B (the twist) the same divisions miss r1 or r2 by 0.05-0.15 in;
    in one step each (no sub-steps), divisions 1-6 by 0.09-0.32 in. Starting step 2 from
    theta4 = 10.000 as printed misses r1 and r2 by 0.022 and 0.030 in."""
    arm = chain("nadkarni_c2")
    goal = np.asarray(ILLUSTRATION_5_GOAL) * INCH
    q0 = start("nadkarni_c2")
    corners = np.array(hand_points(arm.fk(q0))) * INCH
    planned = [frames_from_points(corners + i / 27 * (goal - corners)) for i in range(1, 10)]
    values = np.array([[float(v) for v in r] for r in TABLE_A2_9])
    printed = [q0] + [np.r_[r[:3] * INCH, np.radians(r[3:])] for r in values]
    as_printed = printed[1].copy()
    printed[1][3] = np.arctan(5 / 26)
    n = [3, 3, 3, 3, 2, 2, 1, 1, 1]
    twist_miss, single_miss = [], []
    for i in range(9):
        q = one_division(arm, printed[i], planned[i], n[i], "disp")
        got = np.r_[q[:3] / INCH, np.degrees(q[3])]
        for j, (c, p) in enumerate(zip(got, TABLE_A2_9[i][:4], strict=True)):
            if (i, j) != (0, 3):  # the misprint
                assert_printed(c, p, slack=0.0005 if i and j < 2 else 0.0)
        for b_form, k, misses in (("twist", n[i], twist_miss), ("disp", 1, single_miss)):
            other = one_division(arm, printed[i], planned[i], k, b_form)
            misses.append(np.abs(other[:2] - printed[i + 1][:2]).max() / INCH)
    assert min(twist_miss) > 0.04 and max(twist_miss) > 0.14
    assert max(single_miss) > 0.3 and min(single_miss[:6]) > 0.08
    q = one_division(arm, as_printed, planned[1], 3, "disp")
    miss = np.abs(q[:2] - printed[2][:2]) / INCH
    assert miss.min() > 0.02  # 40 times the rounding


def test_illustration_5_disps_b_from_the_single_steps():
    """The vector B of DISP, read off the printed steps 7-9 (one step each): J (q_i+1 - q_i)
    less the advance d u is a (-u x rho_n) + b rho_n (rho_n the foot of the normal from the
    base origin to the screw from the printed hand to the division's triangle) with a = dtheta
    to 3e-4 (nearer than sin dtheta) and b = dtheta^2 / 2 to 1 % (eq. (4-19a) has b = 0)."""
    from rrc_pin.guidance import screw_from_poses

    arm = chain("nadkarni_c2")
    goal = np.asarray(ILLUSTRATION_5_GOAL) * INCH
    q0 = start("nadkarni_c2")
    corners = np.array(hand_points(arm.fk(q0))) * INCH
    values = np.array([[float(v) for v in r] for r in TABLE_A2_9])
    Q = [np.r_[r[:3] * INCH, np.radians(r[3:])] for r in values]
    for i in (6, 7, 8):  # rows 6 -> 7, 7 -> 8, 8 -> 9 (steps 7, 8, 9)
        planned = frames_from_points(corners + (i + 1) / 27 * (goal - corners))
        s = screw_from_poses(arm.fk(Q[i - 1]), planned)
        B = arm.jacobian(Q[i - 1], ref="world") @ (Q[i] - Q[i - 1])
        basis = np.c_[-np.cross(s.u, s.rho), s.rho]
        (a, b), *_ = np.linalg.lstsq(basis, B[:3] - s.d * s.u, rcond=None)
        theta = float(s.theta)
        assert abs(a / theta - 1.0) < 3e-4 and abs(a - theta) < abs(a - np.sin(theta))
        assert abs(b / (theta**2 / 2) - 1.0) < 0.01


def test_illustration_5_each_part_of_the_reading_is_needed():
    """Without sub-steps, with eq. (4-19a)'s B, or without the closing step, the run misses the
    printed rows or the printed end: r1 or r2 off by > 0.05 in on some row, or the final r2
    20.0006 (which prints 20.001). The steps per division, 3, 3, 3, 3, 2, 2, 1, 1, 1, are the
    division's turn over c rounded for c in (3.498, 3.602] deg only. A cap of 10 deg on the
    joint steps (step 1 scaled to 10.000) misses row 1's r3 by 0.024 in (its r1, r2, r3 are
    those of a whole first division)."""
    from rrc_pin.guidance import screw_from_poses, straight_line_points
    from rrc_pin.guidance.illustrations import disp_substeps

    arm, q0 = chain("nadkarni_c2"), start("nadkarni_c2")
    goal = np.asarray(ILLUSTRATION_5_GOAL) * INCH
    printed = np.array([[float(v) for v in r[:2]] for r in TABLE_A2_9])

    def run(**options):
        path = straight_line_points(arm, q0, goal, 27, spacing=INCH, **options)
        ends = path.division_ends or tuple(range(1, 28))
        return path, np.array([path.q[e][:2] for e in ends[:9]]) / INCH

    for options in (
        {"substeps": 1, "b_form": "disp", "closing": 1},
        {"substeps": disp_substeps, "b_form": "twist", "closing": 1},
    ):
        assert np.abs(run(**options)[1] - printed).max() > 0.05
    path, rows = run(substeps=disp_substeps, b_form="disp", closing=0)
    assert np.abs(rows - printed).max() < 0.0005 + 1e-9
    assert path.q[-1][1] / INCH == pytest.approx(20.0006, abs=5e-5)
    # the steps per division: the turn over c, rounded, for c in (3.498, 3.602] deg only
    turns = [abs(float(screw_from_poses(path.hand[e], P).theta)) for e, P in zip(
        (0, *path.division_ends[:8]), planned_divisions(arm, q0, goal), strict=False)]  # fmt: skip
    for c, same in ((3.49, False), (3.50, True), (3.60, True), (3.61, False)):
        counts = [max(1, int(np.floor(t / np.radians(c) + 0.5))) for t in turns]
        assert (counts == [3, 3, 3, 3, 2, 2, 1, 1, 1]) == same, (c, counts)
    step_1 = run(substeps=disp_substeps, b_form="disp", closing=0)[0].q[3]
    capped = q0 + (step_1 - q0) * np.radians(10.0) / step_1[3]
    assert abs(capped[2] / INCH - float(TABLE_A2_9[0][2])) > 0.02


def test_illustration_5_with_the_printed_goal_does_not_reproduce():
    """With Table A2-8's b_2 = (11, -10, 20) (1 unit out) the turn is shared evenly: theta4 is
    2.203 deg after step 1 and 26.565 after step 9, against the printed 10.000 and 68.199."""
    from rrc_pin.guidance import straight_line_points

    goal = np.array([[10, -10, 20], [11, -10, 20], [10, -10, 19.0]]) * INCH
    path = straight_line_points(chain("nadkarni_c2"), start("nadkarni_c2"), goal, 27, spacing=INCH)
    theta4 = np.degrees(path.q[1:10, 3])
    np.testing.assert_allclose(theta4[[0, 8]], [2.203, 26.565], atol=1e-3)
    printed4 = np.array([float(r[3]) for r in TABLE_A2_9])
    assert np.all(theta4 < printed4 - 7.0)


def test_illustration_4_escape_and_one_constant_step():
    """Type II: the escape is (-0.05, 0.05, 0.25, 0.25, -0.25, -0.25) rad to the printed digits,
    and the seven printed steps are one constant twist (the screw located once, eq. (4-19a))."""
    rows = illustration_4()
    kick = np.radians([float(v) for v in TABLE_A2_6[0]]) - start("nadkarni_c1")
    np.testing.assert_allclose(kick, ESCAPE_4, atol=np.radians(0.0005))
    arm = chain("nadkarni_c1")
    twists = printed_step_twists(arm, TABLE_A2_6)
    # the rounding of the printed angles (half a unit: 0.0005 deg, 0.005 deg for the last
    # 3.37) moves step i's twist by at most sum_j |J_ij| (r_i,j + r_i+1,j)
    half = np.radians([[0.5 * 10.0 ** -len(v.split(".")[1]) for v in row] for row in TABLE_A2_6])
    Q = np.radians([[float(v) for v in row] for row in TABLE_A2_6])
    bound = np.array([np.abs(arm.jacobian(Q[i], ref="world")) @ (half[i] + half[i + 1])
                      for i in range(len(Q) - 1)])  # fmt: skip
    # five of the seven agree within the rounding; steps 3 and 4 (either side of the row
    # 71.373 ... 8.608) within 3x it: one entry 0.004 deg off (theta6 8.604 would fit)
    for i in range(len(twists)):
        for j in range(i):
            slack = 1.0 if {i, j}.isdisjoint({2, 3}) else 3.0
            assert np.all(np.abs(twists[i] - twists[j]) <= slack * (bound[i] + bound[j]))
    assert np.abs(twists[0]).max() > 50 * bound.max()  # a real step, well above the rounding
    assert rows[0].label.startswith("escape")


def test_illustration_4_printed_final_theta1_is_off_by_the_escape():
    """The hand the thesis prints is that of the printed final joints with theta1 lowered by
    0.05 rad (2.865 deg, the escape's theta1 step); the printed final joints as they stand put
    the hand 0.4-1 in away in x and y (z, which theta1 does not move, agrees)."""
    arm = chain("nadkarni_c1")
    final = np.radians([float(v) for v in TABLE_A2_6_FINAL])
    as_printed = np.array(hand_points(arm.fk(final)))
    printed = np.array([[float(x) for x in p] for p in ILLUSTRATION_4_HAND])
    assert np.abs(as_printed[:, :2] - printed[:, :2]).max() > 0.4
    np.testing.assert_allclose(as_printed[:, 2], printed[:, 2], atol=0.005 + 1e-9)
    final[0] += ESCAPE_4[0]
    shifted = np.array(hand_points(arm.fk(final)))
    assert np.abs(shifted - printed).max() <= 0.005 + 1e-9


def test_illustration_4_rows_final_and_hand_as_disp_ran_it():
    """Type II as DISP ran it: from the escape (theta1 0.05 rad below the table's), 16 steps of
    DISP's B along the screw to the goal and one closing step (17; the table says 22), toward
    goal points within the cards' rounding (+-0.005 in, ILLUSTRATION_4_OFFSET): every printed
    step and the final joints within one unit of the last printed digit (0.001 deg; the row
    71.373 ... 8.608 has 8.604, the erratum), the computed hand to the printed digits. With the
    same goal, eq. (4-19a)'s B misses the rows by 0.57 deg; without the closing step the final
    joints are 4.2 deg off, with two 0.24 deg; with the cards as printed, 0.7 and 1.2 deg."""
    from rrc_pin.guidance.illustrations import ILLUSTRATION_4_OFFSET, illustration_4_path

    assert np.abs(ILLUSTRATION_4_OFFSET).max() <= 0.005
    path = illustration_4_path()
    assert len(path.q) - 1 == 17 and path.escapes == ()
    printed = [*TABLE_A2_6[1:], TABLE_A2_6_FINAL]
    raised = np.degrees(path.q[[1, 2, 3, 4, 5, 6, 7, -1]]) + np.r_[np.degrees(0.05), 0, 0, 0, 0, 0]
    for n, (row, computed) in enumerate(zip(printed, raised, strict=True)):
        for j, (c, p) in enumerate(zip(computed, row, strict=True)):
            if (n, j) == (2, 5):
                assert abs(c - 8.604) < 0.0005 and abs(c - float(p)) < 0.004
            else:
                assert_printed(c, p, slack=0.5 * 10.0 ** -len(p.split(".")[1]))
    for computed, p in zip(hand_points(path.hand[-1]), ILLUSTRATION_4_HAND, strict=True):
        for c, v in zip(computed, p, strict=True):
            assert_printed(c, v)

    arm = chain("nadkarni_c1")
    goal = frames_from_points((np.asarray(ILLUSTRATION_4_GOAL) + ILLUSTRATION_4_OFFSET) * INCH)
    final = np.radians([float(v) for v in TABLE_A2_6_FINAL]) - np.r_[0.05, 0, 0, 0, 0, 0]
    twist = screw_motion(arm, path.q[0], goal, 16, b_form="twist", closing=1)
    assert np.degrees(np.abs(twist.q[1:8] - path.q[1:8])).max() > 0.5
    for closing, off in ((0, 4.0), (2, 0.2)):
        other = screw_motion(arm, path.q[0], goal, 16, b_form="disp", closing=closing)
        assert np.degrees(np.abs(other.q[-1] - final)).max() > off
    # near the singular start (condition number 9.8e3; 248 after the escape) the goal's
    # rounding matters: with the cards as printed the rows are 0.7 deg and the end 1.2 deg off
    cards = frames_from_points(np.asarray(ILLUSTRATION_4_GOAL) * INCH)
    other = screw_motion(arm, path.q[0], cards, 16, b_form="disp", closing=1)
    assert np.degrees(np.abs(other.q[1:8] - path.q[1:8])).max() > 0.6
    assert np.degrees(np.abs(other.q[-1] - final)).max() > 1.0
    assert 5e3 < np.linalg.cond(arm.jacobian(start("nadkarni_c1"), ref="world")) < 1e4
    assert np.linalg.cond(arm.jacobian(path.q[0], ref="world")) < 300


def end_error(paths, expected):
    return max(
        np.abs(np.array(hand_points(p.hand[-1])[0]) - e).max()
        for p, e in zip(paths, expected, strict=True)
    )


def test_second_order_correction_on_illustration_6():
    """Open-loop steps: first order ends 0.20 in off, eq. (5-5) 0.004 in (one revolute joint
    turns, behind the prismatic ones: (5-5) is second order here), Newton 1e-12."""
    expected = [(15.0, -25.0, 16.0), (15.0, -25.0, 17.0)]
    errors = {c: end_error(illustration_6(c)[1], expected) for c in ("none", "eq5_5", "newton")}
    assert 0.1 < errors["none"] < 0.2
    assert errors["eq5_5"] < errors["none"] / 40
    assert errors["newton"] < 1e-10


def test_second_order_correction_on_illustrations_5_and_7():
    """Steps located again from the hand reached: the end error is already one step's
    (Illustration 7: first order 0.01 in; Illustration 5 at the end of its last division,
    before DISP's closing step: 6e-4 in); Newton removes it."""
    goal = (10.0, -10.0, 20.0)

    def last(path):
        return path.hand[path.division_ends[26]] if path.division_ends else path.hand[-1]

    for run, low in ((illustration_5, 5e-4), (illustration_7, 1e-3)):
        first = np.abs(np.array(hand_points(last(run()[1]))[0]) - goal).max()
        newton = np.abs(np.array(hand_points(last(run("newton")[1]))[0]) - goal).max()
        assert first > low and newton < 1e-9


def test_report_rows_and_bad_number():
    for n in (1, 2, 4, 5, 6, 7):
        assert report(n)
    with pytest.raises(InvalidInput, match="^illustration:"):
        report(3)


def test_exact_pose_error_is_zero_with_newton():
    arm = chain("nadkarni_c2")
    _, path = illustration_7("newton")
    goal = frames_from_points(np.array([[10, -10, 20], [11, -10, 20], [10, -10, 19.0]]) * INCH)
    err = pin.log6(pin.SE3(goal) * pin.SE3(arm.fk(path.q[-1])).inverse()).vector
    assert np.abs(err).max() < 1e-12


def test_cli_prints_the_thesis_beside_the_computed(capsys):
    from rrc_pin.cli import main

    assert main(["guidance", "--illustration", "7"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("Illustration 7")
    step_10 = lines.index(next(line for line in lines if line.startswith("step 10 ")))
    assert lines[step_10].split()[-6:] == ["-2.336", "25.073", "5.714", "25.714", "90.000", "0.000"]
    computed = [float(x) for x in lines[step_10 + 1].split()[1:]]
    np.testing.assert_allclose(computed, [-2.3357, 25.0726, 5.7143, 25.7143, 90.0, 0.0], atol=1e-4)
    with pytest.raises(SystemExit):
        main(["guidance", "--illustration", "3"])


def test_illustration_4_step_is_the_screw_from_the_escape_over_16():
    """The printed constant step is DISP's B for the screw from the hand at the escape, theta1
    taken 0.05 rad below its printed value (as at the end), to the goal, divided by 16, not 22:
    every component lies in the envelope the goal points' rounding (+-0.005) spans (with
    DISP's B and with eq. (4-19a)'s), and the goal of the run (ILLUSTRATION_4_OFFSET) gives the
    step within 0.13 rounding bounds of a printed step (eq. (4-19a)'s B at best 1.7); with
    k = 15, 17, 22 or theta1 as printed, components fall outside the envelope."""
    from rrc_pin.guidance import screw_from_poses
    from rrc_pin.guidance.screw_motion import disp_step

    arm = chain("nadkarni_c1")
    twists = printed_step_twists(arm, TABLE_A2_6)
    half = np.radians([[0.5 * 10.0 ** -len(v.split(".")[1]) for v in row] for row in TABLE_A2_6])
    Q = np.radians([[float(v) for v in row] for row in TABLE_A2_6])
    bound = np.max(
        [np.abs(arm.jacobian(Q[i], ref="world")) @ (half[i] + half[i + 1]) for i in range(7)],
        axis=0,
    )
    step = np.r_[twists[:2], twists[4:]].mean(axis=0)  # the five steps within the rounding
    goal = np.asarray(ILLUSTRATION_4_GOAL)
    jitter = np.random.default_rng(3).uniform(-0.005, 0.005, size=(3000, 3, 3))

    def located(k, d_theta1, moved, b_form="disp"):
        """The actual step (the printed frame turned by d_theta1 about z) and B of screws / k."""
        turn = pin.exp3(np.r_[0.0, 0.0, d_theta1])
        actual = np.r_[turn @ step[:3], turn @ step[3:]]
        T = arm.fk(start("nadkarni_c1") + ESCAPE_4 + np.r_[d_theta1, 0, 0, 0, 0, 0])
        T = np.broadcast_to(T, (*moved.shape[:-2], 4, 4))
        screw = screw_from_poses(T, frames_from_points(moved * INCH))
        return actual, disp_step(screw, k, b_form)

    for b_form in ("disp", "twist"):
        for k, d_theta1 in [(16, -0.05), (22, -0.05), (15, -0.05), (17, -0.05), (16, 0.0)]:
            actual, cloud = located(k, d_theta1, goal + jitter, b_form)
            inside = (cloud.min(axis=0) <= actual) & (actual <= cloud.max(axis=0))
            assert inside.all() == ((k, d_theta1) == (16, -0.05)), (k, d_theta1, inside)
    from rrc_pin.guidance.illustrations import ILLUSTRATION_4_OFFSET

    actual, B = located(16, -0.05, goal + ILLUSTRATION_4_OFFSET)
    assert np.abs((B - actual) / bound).max() < 1.0


def test_the_report_marks_every_mismatch_and_names_the_known_errata():
    """Issue 33 item 8: the thesis's numbers were printed beside ours with no word on the
    known errata (docs/errata.md)."""
    from rrc_pin.guidance.illustrations import READINGS, format_report, report

    for number in (1, 2, 4, 5, 6, 7):
        rows = report(number)
        for row in rows:
            if row.note:  # a reason is given only where something differs
                assert any(row.differs()), (number, row.label)
            elif any(row.differs()):  # else the illustration's reading says why
                assert READINGS[number], (number, row.label)
        text = format_report(number)
        marked = sum(sum(row.differs()) for row in rows)
        assert len(re.findall(r"\d\*", text)) == marked  # a number marked, not "X*(1)"
        assert f"({marked} of {sum(len(row.printed) for row in rows)})" in text
    two = format_report(2)
    assert "0.369   <- erratum: 0.65 for 0.065" in two and "0.0651*" in two
    four = format_report(4)
    assert "8.608   <- erratum: 8.608 for 8.604" in four and "8.6041*" in four
    assert "Erratum: the printed theta1 is 0.05 rad" in four
    five = format_report(5)
    assert "<- erratum: theta4 10.000 for 10.886" in five and "10.8855*" in five
    assert "(15.00, -10.00, 20.00)" in five
    assert "r1 r2 r3 theta4 theta5 theta6" in format_report(7)
