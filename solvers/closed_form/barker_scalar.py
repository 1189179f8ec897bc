"""Scalar kernels of Barker's closed form in Python floats (one configuration, no arrays).

The same equations as :mod:`solvers.closed_form.barker_kernels`, written for one
configuration with :mod:`math`: for a single call, numpy's per-operation overhead (about a
microsecond per array operation) would dominate the few dozen flops of the closed form.
The geometry comes as the plain tuple ``(ES, SAL3 WE, A3, F2, SAL3, CAL3)`` (see
:func:`constants`) because tuple unpacking is faster than attribute access.
"""

from __future__ import annotations

from math import cos, sin, sqrt

import numpy as np

from solvers.closed_form.barker_kernels import BarkerGeometry
from solvers.closed_form.barker_pinv import pinv2_apply_scalar, pinv3_apply

Consts = tuple[float, float, float, float, float, float]
TrigS = tuple[float, float, float, float, float, float, float, float, float, float, float, float]
Vec3 = tuple[float, float, float]


def constants(g: BarkerGeometry) -> Consts:
    """(ES, SAL3 WE, A3, F2, SAL3, CAL3) of the geometry [m, m, m, m, -, -]."""
    return g.es, g.swe, g.a3, g.f2, g.sal3, g.cal3


def trig_scalar(q: list[float]) -> TrigS:
    """(S1, C1, S2, C2, S3, C3, S23, C23, S4, C4, S5, C5) of one configuration [rad]."""
    q1, q2, q3, q4, q5, _ = q
    return (
        sin(q1), cos(q1), sin(q2), cos(q2), sin(q3), cos(q3), sin(q2 + q3), cos(q2 + q3),
        sin(q4), cos(q4), sin(q5), cos(q5),
    )  # fmt: skip


def arm_scalar(k: Consts, tr: TrigS, tvel: list[float], reduced: bool, rcond: float) -> Vec3:
    """thetadot_1..3 [rad/s]: eqs (34)-(36) with M* (eq. (38)) where singular, or eqs (39), (44).

    See :func:`~solvers.closed_form.barker_kernels.arm_rates_full` and
    :func:`~solvers.closed_form.barker_kernels.arm_rates_reduced` for the corrections.
    """
    es, swe, a3, f2, _, _ = k
    s1, c1, s2, c2, s3, c3, s23, c23 = tr[:8]
    f5 = s23 * swe + c23 * a3  # eq. (31)
    f4 = c23 * swe - s23 * a3  # eq. (30)
    f1 = s2 * es + f5  # eq. (27)
    f3 = c2 * es + f4  # eq. (29)
    T1, T2, T3 = tvel
    if reduced:
        ta = c1 * T1 + s1 * T2
        r = f1 / f2
        g1 = r * ta - s1 * T1 + c1 * T2
        fro2 = 2.0 * f1 * f1 + f2 * f2 + f3 * f3 + f4 * f4 + f5 * f5
        th2, th3 = pinv2_apply_scalar(r * f3, r * f4, -f1, -f5, g1, T3, rcond, fro2)
        return (f3 * th2 + f4 * th3 - ta) / f2, th2, th3  # eqs (44), (39)
    f6 = s1 * f1 + c1 * f2  # eq. (41)
    f7 = c1 * f1 - s1 * f2  # eq. (37)
    det = f1 * (swe * s3 + a3 * c3) * es  # eq. (D9)
    fro2 = 2.0 * f1 * f1 + f2 * f2 + f3 * f3 + f4 * f4 + f5 * f5
    if abs(det) > rcond * fro2 * sqrt(fro2):
        u = T1 * f7 + T2 * f6
        return (
            (T1 * s1 - T2 * c1) * (f1 * f4 - f3 * f5) / det,  # eq. (34)
            (f5 * u + T3 * f1 * f4) / det,  # eq. (35), sign corrected
            -f1 * (u + T3 * f3) / det,  # eq. (36), sign corrected
        )
    M = np.array([[-f6, c1 * f3, c1 * f4], [f7, s1 * f3, s1 * f4], [0.0, -f1, -f5]])
    x = pinv3_apply(M[None], np.array([tvel]), rcond)[0]  # eq. (38)
    return float(x[0]), float(x[1]), float(x[2])


def rvel_tilde_scalar(tr: TrigS, arm: Vec3, rvel: list[float]) -> Vec3:
    """RVEL~ of Barker eq. (48) [rad/s]."""
    s = arm[1] + arm[2]
    return rvel[0] + tr[0] * s, rvel[1] - tr[1] * s, rvel[2] - arm[0]


def wrist_scalar(k: Consts, tr: TrigS, rt: Vec3, reduced: bool, rcond: float) -> Vec3:
    """thetadot_4..6 [rad/s] from RVEL~: eqs (49)-(51) (M2* where singular) or eqs (49), (60)."""
    sal3, cal3 = k[4], k[5]
    s1, c1 = tr[0], tr[1]
    s23, c23, s4, c4, s5, c5 = tr[6:]
    w1, w2, w3 = rt
    d1 = c1 * w1 + s1 * w2  # eq. (52)
    d2 = s1 * w1 - c1 * w2  # eq. (53)
    d3 = s23 * d1 + c23 * w3  # eq. (54)
    d4 = c23 * d1 - s23 * w3  # eq. (55)
    d5 = cal3 * d3 + sal3 * d2  # eq. (56)
    th5 = -c4 * d5 - s4 * d4  # eq. (49)
    ga = -s4 * d5 + c4 * d4  # eq. (59), first row ("D6" in the OCR is D5)
    gb = sal3 * d3 - cal3 * d2  # eq. (59), second row
    if reduced:
        th4, th6 = pinv2_apply_scalar(0.0, s5, 1.0, c5, ga, gb, rcond)  # eq. (60)
        return th4, th5, th6
    ac5 = abs(c5)
    if abs(s5) > rcond * (1.0 + ac5):
        th6 = ga / s5  # eq. (50)
        return gb - c5 * th6, th5, th6  # eq. (51)
    sg = 1.0 if c5 >= 0.0 else -1.0
    r = (sg * s5 * ga + (1.0 + ac5) * gb) / (2.0 * (1.0 + ac5))  # M2*, eq. (60)
    return r, th5, sg * r


def joint_rates_scalar(
    k: Consts, q: list[float], x: list[float], reduced: bool, rcond: float
) -> tuple[float, float, float, float, float, float]:
    """Joint rates (6,) [rad/s] realising ``x = [TVEL^; RVEL^]`` at ``q`` (arm, eq. (48), wrist)."""
    tr = trig_scalar(q)
    arm = arm_scalar(k, tr, x[:3], reduced, rcond)
    th4, th5, th6 = wrist_scalar(k, tr, rvel_tilde_scalar(tr, arm, x[3:]), reduced, rcond)
    return arm[0], arm[1], arm[2], th4, th5, th6


def joint_rates_full_scalar(
    k: Consts, q: list[float], x: list[float], rcond: float
) -> tuple[float, float, float, float, float, float]:
    """:func:`joint_rates_scalar` for ``reduced=False``, fused into one function.

    The default path of ``BarkerClosedForm.joint_rates``: eqs (34)-(36), (48), (52)-(56),
    (49)-(51) inline (a third faster than the composed kernels); where either block is
    singular it hands over to :func:`joint_rates_scalar` and its generalized inverses.
    """
    es, swe, a3, f2, sal3, cal3 = k
    q1, q2, q3, q4, q5, _ = q
    T1, T2, T3, W1, W2, W3 = x
    s1, c1, s2, c2 = sin(q1), cos(q1), sin(q2), cos(q2)
    s23, c23, s4, c4, s5, c5 = sin(q2 + q3), cos(q2 + q3), sin(q4), cos(q4), sin(q5), cos(q5)
    f5 = s23 * swe + c23 * a3  # eq. (31)
    f4 = c23 * swe - s23 * a3  # eq. (30)
    f1 = s2 * es + f5  # eq. (27)
    f3 = c2 * es + f4  # eq. (29)
    det = f1 * (swe * sin(q3) + a3 * cos(q3)) * es  # eq. (D9)
    fro2 = 2.0 * f1 * f1 + f2 * f2 + f3 * f3 + f4 * f4 + f5 * f5
    if abs(det) <= rcond * fro2 * sqrt(fro2) or abs(s5) <= rcond * (1.0 + abs(c5)):
        return joint_rates_scalar(k, q, x, False, rcond)
    u = T1 * (c1 * f1 - s1 * f2) + T2 * (s1 * f1 + c1 * f2)  # T1 F7 + T2 F6, eqs (37), (41)
    t1 = (T1 * s1 - T2 * c1) * (f1 * f4 - f3 * f5) / det  # eq. (34)
    t2 = (f5 * u + T3 * f1 * f4) / det  # eq. (35), sign corrected
    t3 = -f1 * (u + T3 * f3) / det  # eq. (36), sign corrected
    s = t2 + t3  # eq. (48): RVEL~ = RVEL^ - z0 t1 - z1 (t2 + t3)
    w1, w2, w3 = W1 + s1 * s, W2 - c1 * s, W3 - t1
    d1 = c1 * w1 + s1 * w2  # eq. (52)
    d2 = s1 * w1 - c1 * w2  # eq. (53)
    d3 = s23 * d1 + c23 * w3  # eq. (54)
    d4 = c23 * d1 - s23 * w3  # eq. (55)
    d5 = cal3 * d3 + sal3 * d2  # eq. (56)
    th6 = (-s4 * d5 + c4 * d4) / s5  # eq. (50)
    return t1, t2, t3, sal3 * d3 - cal3 * d2 - c5 * th6, -c4 * d5 - s4 * d4, th6  # (51), (49)


def jacobian_scalar(k: Consts, q: list[float]) -> np.ndarray:
    """Wrist-centre Jacobian (6, 6), rows [v; w], base axes (Barker eqs (22), (26), (C7)-(C12))."""
    es, swe, a3, f2, sal3, cal3 = k
    s1, c1, s2, c2, _, _, s23, c23, s4, c4, s5, c5 = trig_scalar(q)
    f5 = s23 * swe + c23 * a3
    f4 = c23 * swe - s23 * a3
    f1 = s2 * es + f5
    f3 = c2 * es + f4
    x1, x2, x3 = c1 * c23, s1 * c23, -s23  # x3 axis, eq. (B5) first column
    y1, y2, y3 = -c1 * s23 * cal3 - s1 * sal3, -s1 * s23 * cal3 + c1 * sal3, -c23 * cal3
    z1, z2, z3 = c1 * s23 * sal3 - s1 * cal3, s1 * s23 * sal3 + c1 * cal3, c23 * sal3  # (C11)
    a, b = c4 * s5, s4 * s5
    return np.array(
        [
            [-s1 * f1 - c1 * f2, c1 * f3, c1 * f4, 0.0, 0.0, 0.0],
            [c1 * f1 - s1 * f2, s1 * f3, s1 * f4, 0.0, 0.0, 0.0],
            [0.0, -f1, -f5, 0.0, 0.0, 0.0],
            [0.0, -s1, -s1, z1, -s4 * x1 + c4 * y1, a * x1 + b * y1 + c5 * z1],
            [0.0, c1, c1, z2, -s4 * x2 + c4 * y2, a * x2 + b * y2 + c5 * z2],
            [1.0, 0.0, 0.0, z3, -s4 * x3 + c4 * y3, a * x3 + b * y3 + c5 * z3],
        ]
    )
