"""Nadkarni's Appendix II, Illustrations 1, 2 and 4-7: the thesis's data and our runs of them.

Lengths are in the thesis's units (taken as inches) and angles in degrees here only, where the
tables are transcribed; the runs are in SI on the catalogue arms ``nadkarni_c1`` and
``nadkarni_c2``. Each illustration gives rows of (label, printed numbers as strings, computed
numbers), so that a report and the tests read the same data.

Readings that reproduce the printed digits (docs/api.md, "Guidance"):

- Illustration 7 (Type I, Table A2-13): k = 35; the screw and the origin-to-origin line are
  located again at every step from the hand reached to the goal, a ``1 / (k - i)`` share each.
- Illustration 6 (Type IV, Table A2-11): k = 9 and 4; each command's twist is constant, its
  axis through the hand point where the command starts.
- Illustrations 4 and 5 (Types II and III, Tables A2-6 and A2-9) as the thesis's program DISP
  ran them: its vector B is eq. (4-19a) with the second-order term of the base origin's
  displacement (``b_form="disp"``, rrc_pin.guidance.screw_motion), and one closing step ends
  the run. Illustration 4: the escape is (-0.05, 0.05, 0.25, 0.25, -0.25, -0.25) rad (read
  from the table), then 16 steps along one screw and the closing step, toward goal points
  within the cards' rounding; the printed theta1 is 0.05 rad above the run's. Illustration 5:
  k = 27 divisions toward a goal triangle whose z point is 5 units out (b_2 = (15, -10, 20),
  docs/errata.md), each division a Type II run of :func:`disp_substeps` steps: every printed
  digit but step 1's theta4 (10.000 printed for 10.886), 38 steps.
"""

from __future__ import annotations

import textwrap
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from rrc_pin.dh import DHChain, nadkarni_link, translation
from rrc_pin.errors import InvalidInput
from rrc_pin.guidance.general import general
from rrc_pin.guidance.operator import Command, operator
from rrc_pin.guidance.screw import Screw, frames_from_points, screw_from_points
from rrc_pin.guidance.screw_motion import screw_motion
from rrc_pin.guidance.stepping import Array, Correction, GuidancePath
from rrc_pin.guidance.straight_line import straight_line_points
from rrc_pin.models import CATALOGUE, INCH

ILLUSTRATION_1_POSITIONS = (
    ((25.00, 0.00, 20.00), (30.00, 0.00, 20.00), (25.00, 0.00, 10.00)),
    ((-20.30, -7.83, -6.66), (-20.65, -8.29, -5.85), (-21.06, -7.18, -6.62)),
    ((-24.50, 5.30, 4.00), (-24.67, 5.47, 4.97), (-25.00, 6.00, 4.00)),
)
ILLUSTRATION_1_PRINTED = (  # u, rho_n, d, theta [deg], h
    (("0.5699", "-0.4433", "0.6918"), ("-1.758", "-0.762", "0.960"), "-40.79", "176.36", "-13.25"),
    (("0.8381", "-0.3386", "0.4276"), ("5.942", "6.862", "-6.212"), "-3.407", "-40.54", "4.815"),
)
ILLUSTRATION_4_GOAL = ((-20.30, -7.83, -6.66), (-20.65, -8.29, -5.85), (-21.06, -7.18, -6.62))
TABLE_A2_6 = (  # theta1..6 [deg]; the first row after the escape, then every printed step
    ("67.135", "82.865", "54.324", "14.324", "45.676", "15.676"),
    ("68.106", "83.55", "61.919", "17.688", "36.391", "12.618"),
    ("69.611", "84.265", "63.399", "20.212", "33.161", "10.420"),
    ("71.373", "85.001", "63.108", "22.239", "31.714", "8.608"),
    ("73.303", "85.772", "61.990", "23.914", "31.133", "7.039"),
    ("75.358", "86.589", "60.404", "25.317", "31.073", "5.666"),
    ("77.512", "87.459", "58.524", "26.499", "31.371", "4.450"),
    ("79.746", "88.388", "56.445", "27.495", "31.941", "3.37"),
)
TABLE_A2_6_FINAL = ("102.843", "100.014", "30.213", "29.926", "49.794", "-0.034")
ILLUSTRATION_4_HAND = (
    ("-20.30", "-7.83", "-6.65"),
    ("-20.65", "-8.29", "-5.83"),
    ("-21.06", "-7.18", "-6.61"),
)
CONFIG_2_GOAL = ((10.00, -10.00, 20.00), (11.00, -10.00, 20.00), (10.00, -10.00, 19.00))
TABLE_A2_9 = (  # r1, r2, r3, theta4, theta5, theta6
    ("-0.225", "26.496", "7.704", "10.000", "90.000", "0.000"),
    ("-0.948", "27.775", "7.407", "21.801", "90.000", "0.000"),
    ("-1.960", "28.790", "7.111", "32.005", "90.000", "0.000"),
    ("-3.108", "29.464", "6.815", "41.009", "90.000", "0.000"),
    ("-4.229", "29.864", "6.519", "48.652", "90.000", "0.000"),
    ("-5.317", "29.953", "6.222", "55.008", "90.000", "0.000"),
    ("-6.254", "29.919", "5.926", "60.255", "90.000", "0.000"),
    ("-7.138", "29.674", "5.630", "64.592", "90.000", "0.000"),
    ("-7.918", "29.343", "5.333", "68.199", "90.000", "0.000"),
)
TABLE_A2_9_FINAL = ("-15.000", "20.000", "0.000", "90.000", "90.000", "0.000")
TABLE_A2_11 = (  # stage 1: steps 1-3 and its end (step 9); stage 2: steps 1-4
    (1, ("0.00", "25.58", "7.56", "3.33", "90.00", "0.00")),
    (2, ("-0.03", "26.16", "7.11", "6.67", "90.00", "0.00")),
    (3, ("-0.10", "26.74", "6.67", "10.00", "90.00", "0.00")),
    (9, ("-1.20", "30.07", "4.00", "30.00", "90.00", "0.00")),
    (10, ("-1.53", "30.64", "3.75", "33.75", "90.00", "0.00")),
    (11, ("-1.90", "31.18", "3.50", "37.50", "90.00", "0.00")),
    (12, ("-2.29", "31.70", "3.25", "41.25", "90.00", "0.00")),
    (13, ("-2.73", "32.20", "3.00", "45.00", "90.00", "0.00")),
)
ILLUSTRATION_6_RHO = (("15.14", "-25.07", "16.00"), ("15.19", "-25.12", "17.00"))
TABLE_A2_13 = (
    ("-0.143", "25.020", "7.771", "2.571", "90.000", "0.000"),
    ("-0.306", "25.040", "7.543", "5.143", "90.000", "0.000"),
    ("-0.490", "25.058", "7.314", "7.714", "90.000", "0.000"),
    ("-0.694", "25.075", "7.086", "10.286", "90.000", "0.000"),
    ("-0.918", "25.087", "6.857", "12.857", "90.000", "0.000"),
    ("-1.162", "25.096", "6.629", "15.429", "90.000", "0.000"),
    ("-1.427", "25.100", "6.400", "18.000", "90.000", "0.000"),
    ("-1.710", "25.098", "6.171", "20.571", "90.000", "0.000"),
    ("-2.013", "25.089", "5.943", "23.143", "90.000", "0.000"),
    ("-2.336", "25.073", "5.714", "25.714", "90.000", "0.000"),
)
TABLE_A2_13_FINAL = ("-15.000", "20.010", "0.000", "90.000", "90.000", "0.000")
ILLUSTRATION_7_HAND = (
    ("10.00", "-10.01", "20.00"),
    ("11.00", "-10.01", "20.00"),
    ("10.00", "-10.01", "19.00"),
)


@dataclass(frozen=True)
class Row:
    """One printed line beside the computed numbers (thesis units, degrees).

    Attributes:
        label: What the line is (``step 3``, ``U(2)``...).
        printed: The thesis's numbers, as printed.
        computed: Ours, in the same units.
        note: Why the two differ where that is known (an erratum of docs/errata.md, or a
            reading), "" where they agree.
    """

    label: str
    printed: tuple[str, ...]
    computed: tuple[float, ...]
    note: str = ""

    def differs(self) -> tuple[bool, ...]:
        """Per entry, whether the computed number does not round to the printed digits."""
        out = []
        for p, c in zip(self.printed, self.computed, strict=True):
            digits = len(p.split(".")[1]) if "." in p else 0
            out.append(abs(c - float(p)) > 0.5 * 10.0**-digits * (1 + 1e-9))
        return tuple(out)


def chain(name: str) -> DHChain:
    """The catalogue DH chain of ``nadkarni_c1`` or ``nadkarni_c2`` (SI)."""
    return CATALOGUE[name].chain


def start(name: str) -> Array:
    """The tables' initial configuration of configuration #1 or #2 (SI)."""
    spec = CATALOGUE[name]
    return np.asarray(next(iter(spec.named_poses.values())), dtype=np.float64)


def thesis_units(q: npt.ArrayLike, prismatic: int) -> tuple[float, ...]:
    """Joint values in the tables' units: the first ``prismatic`` in inches, the rest degrees."""
    v = np.asarray(q, dtype=float)
    return tuple(float(x) for x in np.r_[v[:prismatic] / INCH, np.degrees(v[prismatic:])])


def hand_points(T: Array) -> tuple[tuple[float, ...], ...]:
    """The thesis's three hand points (origin, +z, +x at a_7 = 1) in inches."""
    p = T[:3, 3] / INCH
    return tuple(tuple(float(x) for x in v) for v in (p, p + T[:3, 2], p + T[:3, 0]))


def illustration_1() -> list[Row]:
    """Screw axes between the three positions of Table A2-1 (nominal printed inputs)."""
    rows = []
    P = np.asarray(ILLUSTRATION_1_POSITIONS)
    for n, printed in enumerate(ILLUSTRATION_1_PRINTED):
        s = screw_from_points(P[n], P[n + 1])
        u, rho, d, theta, h = printed
        tag = f"{n + 1}->{n + 2}"
        rows += [
            Row(f"u {tag}", u, tuple(float(x) for x in s.u)),
            Row(f"rho_n {tag}", rho, tuple(float(x) for x in s.rho)),
            Row(
                f"d, theta, h {tag}",
                (d, theta, h),
                (float(s.d), float(np.degrees(s.theta)), float(s.h)),
            ),
        ]
    return rows


ILLUSTRATION_2 = {  # as printed (rho_n(3) reads 0.65 for 0.065: docs/errata.md)
    "X*": (("0.00", "0.00", "0.00"), ("0.00", "0.00", "0.00"), ("-11.95", "0.00", "2.488"),
           ("-11.90", "0.241", "2.771"), ("-21.255", "0.241", "4.42"),
           ("-21.255", "0.241", "4.42"), ("-24.315", "5.273", "4.059")),
    "X": (("0.00", "0.00", "0.00"), ("0.065", "0.00", "0.369"), ("-11.90", "0.241", "2.771"),
          ("-11.90", "0.241", "2.771"), ("-21.255", "0.241", "4.42"),
          ("-24.315", "5.273", "4.059"), ("-24.833", "6.126", "3.998")),
    "U": (("0.00", "0.00", "1.00"), ("0.00", "-1.00", "0.00"), ("-0.985", "0.00", "0.174"),
          ("0.112", "-0.766", "0.633"), ("-0.985", "0.00", "0.174"),
          ("0.171", "0.174", "0.970"), ("0.171", "0.174", "0.970")),
    "rho_n": (("0.00", "0.00", "0.00"), ("0.00", "0.00", "0.00"), ("0.65", "0.00", "0.369"),
              ("-11.927", "0.426", "2.618"), ("0.115", "0.241", "0.652"),
              ("-21.374", "0.121", "3.747"), ("-24.433", "5.152", "3.386")),
}  # fmt: skip


def illustration_2() -> list[Row]:
    """Mechanism data of configuration #1 (Table A2-2) in the global frame.

    For each joint i = 1..7 (7: the hand): the origins of x*(i) and x(i), the unit vector U(i)
    along the joint axis and the foot rho_n(i) of the normal from the origin to it.
    """
    arm = chain("nadkarni_c1")
    q0 = start("nadkarni_c1")
    frames = arm.frames(q0)
    star = [frames[i] @ nadkarni_link(row, q0[i])[0] for i, row in enumerate(arm.rows)]
    star.append(arm.fk(q0))  # the hand frame is x*(7)
    x_frames = [*frames[1:], star[-1] @ translation(x=INCH)]  # a_7 = 1.00
    rows = []
    for i in range(7):
        p, u = star[i][:3, 3] / INCH, star[i][:3, 2]
        computed = {"X*": p, "X": x_frames[i][:3, 3] / INCH, "U": u, "rho_n": p - (p @ u) * u}
        for key, value in computed.items():
            note = RHO_N_3 if (key, i) == ("rho_n", 2) else ""
            rows.append(Row(f"{key}({i + 1})", ILLUSTRATION_2[key][i], tuple(map(float, value)),
                            note))  # fmt: skip
    return rows


RHO_N_3 = "erratum: 0.65 for 0.065, a dropped zero (X(2), two lines up, has it)"


ESCAPE_4 = np.array([-0.05, 0.05, 0.25, 0.25, -0.25, -0.25])
"""The singularity escape of Illustration 4 [rad], as Table A2-6's first row shows it."""


ILLUSTRATION_4_OFFSET = np.array(
    [
        [0.002008, 0.000733, -0.002869],
        [0.003305, 0.000070, 0.002493],
        [0.000447, 0.000342, -0.000046],
    ]
)
"""Offsets [in] within the cards' rounding (+-0.005) of Illustration 4's goal points that the
run reproduces Table A2-6 with (a least-squares witness over the 54 printed joint values, the
8.608 left out). Near the singular start the goal matters: with the cards as printed the rows
are 0.7 deg and the end 1.2 deg off. The offsets stand for what the two-decimal cards and the
three-decimal data leave open."""


def illustration_4_path(goal_offset: npt.ArrayLike = ILLUSTRATION_4_OFFSET) -> GuidancePath:
    """The run of Table A2-6 (DISP's reading of Type II).

    From the escape (theta1 0.05 rad below the table's), 16 steps of DISP's B along the screw
    to the goal cards + ``goal_offset`` [in], and one closing step.
    """
    arm = chain("nadkarni_c1")
    q = start("nadkarni_c1") + ESCAPE_4 + np.r_[ESCAPE_4[0], 0.0, 0.0, 0.0, 0.0, 0.0]
    points = (np.asarray(ILLUSTRATION_4_GOAL) + np.asarray(goal_offset)) * INCH
    return screw_motion(arm, q, frames_from_points(points), 16, b_form="disp", closing=1)


def illustration_4() -> list[Row]:
    """Type II on configuration #1 (Table A2-6) as DISP ran it (:func:`illustration_4_path`).

    The rows: the escape, every printed step and the final joints (theta1 printed 0.05 rad
    above the run's: the computed theta1 is shown raised by it), and the computed final hand.
    """
    path = illustration_4_path()
    printed = [*TABLE_A2_6[1:], TABLE_A2_6_FINAL]
    raised = path.q + np.r_[-ESCAPE_4[0], 0.0, 0.0, 0.0, 0.0, 0.0]
    kicked = np.radians([float(v) for v in TABLE_A2_6[0]]) - start("nadkarni_c1")
    rows = [Row("escape [rad]", tuple(f"{x:.2f}" for x in ESCAPE_4), tuple(map(float, kicked)))]
    for i, p in enumerate(printed[:-1], start=1):
        note = "erratum: 8.608 for 8.604" if i == 3 else ""
        rows.append(Row(f"step {i}", p, thesis_units(raised[i], 0), note))
    rows.append(Row("final (step 17)", printed[-1], thesis_units(raised[-1], 0)))
    for label, point, computed in zip(
        "abc", ILLUSTRATION_4_HAND, hand_points(path.hand[-1]), strict=True
    ):
        rows.append(Row(f"{label}2", point, computed))
    return rows


def printed_step_twists(arm: DHChain, table: tuple[tuple[str, ...], ...]) -> Array:
    """WORLD twists ``J(q_i) (q_{i+1} - q_i)`` (n - 1, 6) of the printed steps of a table."""
    Q = np.radians([[float(v) for v in row] for row in table])
    return np.array(
        [arm.jacobian(Q[i], ref="world") @ (Q[i + 1] - Q[i]) for i in range(len(Q) - 1)]
    )


ILLUSTRATION_5_GOAL = ((10.00, -10.00, 20.00), (15.00, -10.00, 20.00), (10.00, -10.00, 19.00))
"""The goal triangle the run of Illustration 5 used (docs/errata.md): b_2 5 units out on the
hand's z axis. Table A2-8 prints (11.00, -10.00, 20.00), the text (15.00, -24.00, 12.00); the
hand's final pose is the same, the sharing of the turn among the divisions is not."""


DISP_STEP_ANGLE = np.radians(3.55)
"""The turn [rad] per step by which the reading of Table A2-9 sets a division's steps.

Not stated in the thesis: the printed rows fix the steps of divisions 1-9 at 3, 3, 3, 3, 2, 2,
1, 1, 1 (their turns 10.89, 10.92, 10.20, 9.00, 7.64, 6.36, 5.25, 4.34, 3.61 deg), which
rounding the turn over any angle in (3.498, 3.602] deg gives; the later divisions (3.02 deg
and less) take one step with any of them."""


def disp_substeps(screw: Screw) -> int:
    """A division's steps by the reading of Table A2-9: its turn over 3.55 deg, rounded (>= 1)."""
    return max(1, int(np.floor(abs(float(screw.theta)) / DISP_STEP_ANGLE + 0.5)))


def illustration_5(correction: Correction = "none") -> tuple[list[Row], GuidancePath]:
    """Type III on configuration #2 (Table A2-9) as DISP ran it.

    k = 27 divisions toward the goal triangle of the run, each division a Type II run of
    :func:`disp_substeps` steps with DISP's vector B, and one closing step: 38 steps. The rows
    are the ends of divisions 1-9; step 1's theta4 prints 10.000 for 10.886 (docs/errata.md).
    """
    arm = chain("nadkarni_c2")
    goal = np.asarray(ILLUSTRATION_5_GOAL) * INCH
    path = straight_line_points(
        arm, start("nadkarni_c2"), goal, 27, spacing=INCH, substeps=disp_substeps,
        b_form="disp", closing=1, correction=correction,
    )  # fmt: skip
    ends = path.division_ends
    rows = [
        Row(f"step {i + 1}", p, thesis_units(path.q[ends[i]], 3),
            "erratum: theta4 10.000 for 10.886 (its r1, r2, r3 are 10.886's)" if i == 0 else "")
        for i, p in enumerate(TABLE_A2_9)
    ]  # fmt: skip
    rows.append(Row("final", TABLE_A2_9_FINAL, thesis_units(path.q[-1], 3)))
    return rows, path


def illustration_6(correction: Correction = "none") -> tuple[list[Row], list[GuidancePath]]:
    """Type IV on configuration #2 (Table A2-11): z in the global frame, then x in the hand's."""
    arm = chain("nadkarni_c2")
    q0 = start("nadkarni_c2")
    commands = [
        Command((0.0, 0.0, 1.0), 4.0 * INCH, np.radians(-30.0), "world_aligned"),
        Command((1.0, 0.0, 0.0), -1.0 * INCH, np.radians(15.0), "local"),
    ]
    paths = operator(arm, q0, commands, [9, 4], correction=correction)
    q = np.concatenate([paths[0].q, paths[1].q[1:]])
    rows = [Row(f"step {i}", p, thesis_units(q[i], 3)) for i, p in TABLE_A2_11]
    for n, (path, printed) in enumerate(zip(paths, ILLUSTRATION_6_RHO, strict=True)):
        rows.append(Row(f"rho_0 end of stage {n + 1}", printed, hand_points(path.hand[-1])[0]))
    within = "stage 2: within one unit of the last digit (docs/errata.md)"
    rows = [Row(r.label, r.printed, r.computed, within) if any(r.differs()) else r for r in rows]
    return rows, paths


def illustration_7(correction: Correction = "none") -> tuple[list[Row], GuidancePath]:
    """Type I (Example 4) on configuration #2 (Table A2-13), k = 35."""
    arm = chain("nadkarni_c2")
    goal = frames_from_points(np.asarray(CONFIG_2_GOAL) * INCH)
    path = general(arm, start("nadkarni_c2"), goal, 35, correction=correction)
    rows = [
        Row(f"step {i + 1}", p, thesis_units(path.q[i + 1], 3)) for i, p in enumerate(TABLE_A2_13)
    ]
    rows.append(Row("final", TABLE_A2_13_FINAL, thesis_units(path.q[-1], 3)))
    for label, printed, computed in zip(
        "abc", ILLUSTRATION_7_HAND, hand_points(path.hand[-1]), strict=True
    ):
        rows.append(Row(f"{label}2", printed, computed))
    return rows, path


def report(number: int) -> list[Row]:
    """The rows of Illustration ``number`` (1, 2, 4, 5, 6 or 7).

    Raises:
        InvalidInput: Another number (Illustration 3 is 1 and 2 in one run).
    """
    if number == 1:
        return illustration_1()
    if number == 2:
        return illustration_2()
    if number == 4:
        return illustration_4()
    if number == 5:
        return illustration_5()[0]
    if number == 6:
        return illustration_6()[0]
    if number == 7:
        return illustration_7()[0]
    raise InvalidInput("illustration", f"expected 1, 2, 4, 5, 6 or 7, got {number!r}")


TITLES = {
    1: "Illustration 1 (Table A2-1): screw axes between three positions of a body",
    2: "Illustration 2 (Table A2-2): configuration #1 in the global frame",
    4: "Illustration 4 (Table A2-6): Type II on configuration #1, escape, k = 16 + 1 closing",
    5: "Illustration 5 (Table A2-9): Type III on configuration #2, 27 divisions in 37 steps + 1",
    6: "Illustration 6 (Table A2-11): Type IV on configuration #2, k = 9 and 4",
    7: "Illustration 7 (Table A2-13): Type I on configuration #2, k = 35",
}
READINGS = {
    1: "The inputs are printed to two decimals: computed from them as printed, the screws lie "
    "within what their rounding allows, not on the printed digits (docs/api.md, Appendix II).",
    2: "",
    4: "Erratum: the printed theta1 is 0.05 rad (the escape's step) above the run's from the "
    "escape on; the computed theta1 is shown raised by it. The goal points are the cards' "
    "within their rounding. Every step within one unit of the last digit (0.001 deg), but "
    "8.608.",
    5: "Erratum: the run's goal b_2 is (15.00, -10.00, 20.00), 5 units out on the hand's z "
    "axis, not the cards' (11.00, -10.00, 20.00) nor the text's (15.00, -24.00, 12.00).",
    6: "",
    7: "Erratum: the table's columns are r1 r2 r3 theta4 theta5 theta6 (headed theta1 theta2 "
    "theta3).",
}
"""What a reader must know to compare an illustration's rows: the errata of docs/errata.md
that concern the whole table, and the readings."""


def format_report(number: int) -> str:
    """Illustration ``number`` as text: each printed line, then the computed numbers under it.

    Lengths in the thesis's units (inches), angles in degrees. A computed number that does not
    round to the printed digits is marked ``*``; where the reason is known (an erratum of
    docs/errata.md, a reading), it follows the printed line after ``<-``. Raises as
    :func:`report`.
    """
    rows = report(number)
    lines = [TITLES[number]]
    if READINGS[number]:
        lines += textwrap.wrap(READINGS[number], 92)
    lines.append("")
    marked = 0
    for row in rows:
        printed = " ".join(f"{p:>10} " for p in row.printed)
        note = f"  <- {row.note}" if row.note else ""
        lines.append(f"{row.label:<30} thesis   {printed}{note}".rstrip())
        computed = (round(c, 4) + 0.0 for c in row.computed)  # no "-0.0000"
        cells = [f"{c:10.4f}{'*' if off else ' '}"
                 for c, off in zip(computed, row.differs(), strict=True)]  # fmt: skip
        marked += sum(row.differs())
        lines.append(f"{'':<30} computed " + " ".join(cells).rstrip())
    lines += ["", f"* does not round to the printed digits ({marked} of "
              f"{sum(len(r.printed) for r in rows)}); <- the known reason (docs/errata.md)."]
    return "\n".join(lines)
