r"""The equations of Barker's closed form (NASA TM-85685, 1983), for floats or arrays.

Standard DH (Barker eq. (1)): alpha = (90, 0, alpha3, 90, 90, 0) deg, a = (0, ES, A3, 0, 0, 0),
r = (NO, SN, R3, WE, 0, 0), theta'_i = theta_i + (180, 90, 90, 180, 180, 0) deg; q is Barker's
theta_i. The controlled point is the wrist centre (origin of frames 4, 5, 6), so the Jacobian
is block lower-triangular (eq. (22)): the arm rates solve ``M thetadot_123 = TVEL^``
(eq. (25)), the wrist rates ``W thetadot_456 = RVEL~`` (eqs (47), (48)). Notation of the
report: ``S1 = sin(theta_1)``, ``C23 = cos(theta_2 + theta_3)``, ``SAL3 = sin(alpha_3)``,
``SN~ = SN + R3`` (the OCR'd report drops the tilde).

Each equation is written once, in a kernel that takes Python floats (one configuration: the
scalar path) or (N,) arrays (the batch path) alike; corrections to the printed equations are
cited as in docs/errata.md.

The solvers of a block inside its singular band (:func:`damped_solve`,
:func:`truncated_solve`) are here too; :mod:`solvers.closed_form.barker` says when they answer.

Singular set (Appendix D): ``det J = det M det W = ES (S2 ES + F5)(SAL3 WE S3 + A3 C3) S5``
(up to sign), for any R3 and alpha3: conditions (32), (33) and S5 = 0.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from solvers.closed_form._batch import cos_sin
from solvers.closed_form.base import Array, Entry, dot, stack_entries


class BarkerGeometry(NamedTuple):
    """Barker's symbolic parameters (SI) and the constants derived from them.

    Attributes:
        no, es, sn, we, a3, r3, alpha3: The parameters of :class:`BarkerClosedForm` [m, rad].
        sal3: sin(alpha3).
        cal3: cos(alpha3).
        swe: SAL3 WE [m].
        f2: F2 = SN~ + CAL3 WE, SN~ = SN + R3 [m] (Barker eq. (28), with the tilde restored).
        reach: L = |ES| + hypot(SAL3 WE, A3) [m], the scale of the arm's band.
        r2: (SAL3 WE)^2 + A3^2 = F4^2 + F5^2 [m^2].
    """

    no: float
    es: float
    sn: float
    we: float
    a3: float
    r3: float
    alpha3: float
    sal3: float
    cal3: float
    swe: float
    f2: float
    reach: float
    r2: float

    @classmethod
    def from_parameters(
        cls, no: float, es: float, sn: float, we: float, a3: float, r3: float, alpha3: float
    ) -> BarkerGeometry:
        """Derive the constants from already validated parameters."""
        sal3, cal3 = math.sin(alpha3), math.cos(alpha3)
        swe = sal3 * we
        f2 = sn + r3 + cal3 * we
        reach = abs(es) + math.hypot(swe, a3)
        return cls(no, es, sn, we, a3, r3, alpha3, sal3, cal3, swe, f2, reach, swe * swe + a3 * a3)


class Trig(NamedTuple):
    """Sines and cosines of the joint angles (floats or (N,) arrays); s6, c6 only if asked."""

    s1: Entry
    c1: Entry
    s2: Entry
    c2: Entry
    s3: Entry
    c3: Entry
    s23: Entry
    c23: Entry
    s4: Entry
    c4: Entry
    s5: Entry
    c5: Entry
    s6: Entry = None
    c6: Entry = None


class FTerms(NamedTuple):
    """Barker's F1..F7 (eqs (27)-(31), (41), (37)), each [m]; F2 is a constant."""

    f1: Entry
    f2: Entry
    f3: Entry
    f4: Entry
    f5: Entry
    f6: Entry
    f7: Entry


# -- trigonometry --------------------------------------------------------------------------


def trig(q: Sequence[float]) -> Trig:
    """Trigonometric terms of one configuration ``q`` (6 floats) [rad], by :mod:`math`."""
    q1, q2, q3, q4, q5, q6 = q
    s, c = math.sin, math.cos
    return Trig(s(q1), c(q1), s(q2), c(q2), s(q3), c(q3), s(q2 + q3), c(q2 + q3),
                s(q4), c(q4), s(q5), c(q5), s(q6), c(q6))  # fmt: skip


def trig_batch(Q: Array, six: bool = False, out: tuple[Array, Array] | None = None) -> Trig:
    """Trigonometric terms of ``Q`` (N, 6) [rad], (N,) each; theta_6 only with ``six``.

    ``out``: optional flat buffers of at least ``5 N`` floats (``6 N`` with ``six``) for the
    cosines and sines, reused across the blocks of a batch.
    """
    k, n = 6 if six else 5, Q.shape[0]
    bufs = None if out is None else (out[0][: k * n].reshape(k, n), out[1][: k * n].reshape(k, n))
    C, S = cos_sin(np.ascontiguousarray(Q.T[:k]), bufs)
    s23 = S[1] * C[2] + C[1] * S[2]
    c23 = C[1] * C[2] - S[1] * S[2]
    sc6 = (S[5], C[5]) if six else (None, None)
    return Trig(S[0], C[0], S[1], C[1], S[2], C[2], s23, c23, S[3], C[3], S[4], C[4], *sc6)


# -- the equations (floats or arrays) ------------------------------------------------------


def turn1(t: Trig, x: Entry, y: Entry) -> tuple[Entry, Entry]:
    """``(C1 x + S1 y, S1 x - C1 y)``: the turn by theta_1 of Barker's D1, D2 (eqs (52), (53)).

    The components of a base-axis vector ``(x, y, .)`` along the horizontal unit vectors
    ``(C1, S1, 0)`` and ``(S1, -C1, 0)`` (orthogonal, its own inverse). The same turn takes
    the rows of eq. (25) (:func:`m_rotated`, :func:`m1_system`) and TVEL^
    (:func:`tvel_frame2`).
    """
    return t.c1 * x + t.s1 * y, t.s1 * x - t.c1 * y


def f_terms(g: BarkerGeometry, t: Trig) -> FTerms:
    """F1..F7 of Barker eqs (27)-(31), (41) and (37); F2 with SN~ = SN + R3 (a float)."""
    f5 = t.s23 * g.swe + t.c23 * g.a3  # eq. (31)
    f4 = t.c23 * g.swe - t.s23 * g.a3  # eq. (30)
    f1 = t.s2 * g.es + f5  # eq. (27)
    f3 = t.c2 * g.es + f4  # eq. (29)
    f6 = t.s1 * f1 + t.c1 * g.f2  # eq. (41)
    f7 = t.c1 * f1 - t.s1 * g.f2  # eq. (37)
    return FTerms(f1, g.f2, f3, f4, f5, f6, f7)


def wrist_centre(g: BarkerGeometry, t: Trig, F: FTerms) -> tuple[Entry, Entry, Entry]:
    """p06, the wrist centre in base coordinates [m]: ``(F7, F6, NO + F3)``.

    M's first column (eq. (26)) is ``z0 x p06 = (-F6, F7, 0)`` (eqs (14)-(16), p00 = 0),
    which gives the horizontal components; the height is the third entry of the fourth
    column of ``A1 A2 A3 A4`` (Appendix A): ``NO + ES C2 + SAL3 WE C23 - A3 S23 = NO + F3``
    (eqs (29), (30)).
    """
    return F.f7, F.f6, g.no + F.f3


def eq33(g: BarkerGeometry, t: Trig) -> Entry:
    """SAL3 WE S3 + A3 C3 [m]: zero on Barker's singularity (33) (Appendix D, eq. (D8))."""
    return g.swe * t.s3 + g.a3 * t.c3


def m_rows(t: Trig, F: FTerms) -> list[list[Entry]]:
    """Barker's M, eq. (26), by rows: TVEL^ = M (thetadot_1, thetadot_2, thetadot_3) [m]."""
    return [[-F.f6, t.c1 * F.f3, t.c1 * F.f4], [F.f7, t.s1 * F.f3, t.s1 * F.f4],
            [0.0, -F.f1, -F.f5]]  # fmt: skip


def m_rotated(
    t: Trig, F: FTerms, tvel: Sequence[Entry]
) -> tuple[list[list[Entry]], list[Entry]]:
    """Eq. (25) with its rows turned by theta_1, and TVEL^ with them.

    The :func:`turn1` of the first two rows of M, the third kept (eqs (37), (41)): the same
    least-squares problem as M (an orthogonal change of rows), sparser.
    """
    rows = [[-F.f2, F.f3, F.f4], [-F.f1, 0.0, 0.0], [0.0, -F.f1, -F.f5]]
    return rows, [*turn1(t, tvel[0], tvel[1]), tvel[2]]


def det_adj2(g: BarkerGeometry, t: Trig, F: FTerms) -> tuple[Entry, Entry]:
    """Det M = ES F1 (SAL3 WE S3 + A3 C3) (eq. (D9)) [m^3] and ||adj M||_F^2 [m^4].

    The cross products of the rows of :func:`m_rotated` give ``||adj M||^2 = (ES e33)^2 +
    (F2 F5)^2 + F1^2 (F1^2 + F2^2 + F3^2 + F4^2 + F5^2)``, with ``F4^2 + F5^2 =
    (SAL3 WE)^2 + A3^2`` (eqs (30), (31)).
    """
    e = g.es * eq33(g, t)
    f1s = F.f1 * F.f1
    adj2 = e * e + (g.f2 * F.f5) ** 2 + f1s * (f1s + F.f3 * F.f3 + g.f2 * g.f2 + g.r2)
    return F.f1 * e, adj2


def arm_full(t: Trig, F: FTerms, det: Entry, tvel: Sequence[Entry]) -> tuple[Entry, ...]:
    """thetadot_1..3 [rad/s] by Barker eqs (34)-(36) (signs of (35), (36) corrected)."""
    T1, T2, T3 = tvel
    u = T1 * F.f7 + T2 * F.f6
    return (
        (T1 * t.s1 - T2 * t.c1) * (F.f1 * F.f4 - F.f3 * F.f5) / det,  # eq. (34)
        (F.f5 * u + T3 * F.f1 * F.f4) / det,  # eq. (35), leading sign corrected
        -F.f1 * (u + T3 * F.f3) / det,  # eq. (36), sign of TVEL(2) F6 corrected
    )


def m1_system(
    t: Trig, F: FTerms, tvel: Sequence[Entry]
) -> tuple[list[list[Entry]], list[Entry], Entry]:
    """M1, g1 of eqs (40)-(43) corrected, and ``ta``: ``M1 (thetadot_2, thetadot_3) = g1``.

    As printed, M1's first row is ``(C1 F2 - F6)(F3, F4) = -S1 F1 (F3, F4)``, which vanishes
    at theta_1 = 0 where M is regular. The row used here is ``(S1 row1 - C1 row2)`` of
    eq. (25) with eq. (39) substituted, divided by F2: ``[F1 F3 / F2, F1 F4 / F2] (thetadot_2,
    thetadot_3) = F1 ta / F2 - tb`` with ``(ta, tb)`` the :func:`turn1` of (TVEL(1),
    TVEL(2)); the second row is eq. (25)'s third.
    """
    ta, tb = turn1(t, tvel[0], tvel[1])
    k = F.f1 / F.f2
    return [[k * F.f3, k * F.f4], [-F.f1, -F.f5]], [k * ta - tb, tvel[2]], ta


def arm_from_m1(F: FTerms, th2: Entry, th3: Entry, ta: Entry) -> tuple[Entry, ...]:
    """thetadot_1 by Barker eq. (39), with thetadot_2, thetadot_3 of eq. (44)."""
    return (F.f3 * th2 + F.f4 * th3 - ta) / F.f2, th2, th3


def rvel_tilde(t: Trig, arm: Sequence[Entry], rvel: Sequence[Entry]) -> tuple[Entry, ...]:
    """RVEL~ = RVEL^ - z0 thetadot_1 - z1 thetadot_2 - z2 thetadot_3, Barker eq. (48) [rad/s]."""
    s = arm[1] + arm[2]
    return rvel[0] + t.s1 * s, rvel[1] - t.c1 * s, rvel[2] - arm[0]


def wrist_terms(g: BarkerGeometry, t: Trig, rt: Sequence[Entry]) -> tuple[Entry, Entry, Entry]:
    """thetadot_5 (eq. (49)) and the right-hand side (ga, gb) of M2 (eqs (58), (59)).

    ``M2 (thetadot_4, thetadot_6) = (ga, gb)`` with M2 of :func:`m2_rows`, from D1..D5 of
    eqs (52)-(56).

    In the orthonormal directions (C4 x3 + S4 y3, z4, z3) the wrist block reads (S5 thetadot_6,
    thetadot_5, thetadot_4 + C5 thetadot_6): thetadot_5 separates, M2 carries the rest.
    """
    d1, d2 = turn1(t, rt[0], rt[1])  # eqs (52), (53)
    d3 = t.s23 * d1 + t.c23 * rt[2]  # eq. (54)
    d4 = t.c23 * d1 - t.s23 * rt[2]  # eq. (55)
    d5 = g.cal3 * d3 + g.sal3 * d2  # eq. (56)
    th5 = -t.c4 * d5 - t.s4 * d4  # eq. (49)
    return th5, -t.s4 * d5 + t.c4 * d4, g.sal3 * d3 - g.cal3 * d2  # eq. (59) ("D6" is D5)


def wrist_regular(t: Trig, ga: Entry, gb: Entry) -> tuple[Entry, Entry]:
    """(thetadot_4, thetadot_6) by Barker eqs (51), (50): ``M2^-1 (ga, gb)``."""
    th6 = ga / t.s5  # eq. (50)
    return gb - t.c5 * th6, th6  # eq. (51)


def m2_rows(t: Trig) -> list[list[Entry]]:
    """Barker's M2 = [[0, S5], [1, C5]], eq. (58), by rows: M2 (thetadot_4, thetadot_6)."""
    return [[0.0, t.s5], [1.0, t.c5]]


def wrist_s2(t: Trig) -> Entry:
    """The wrist's band measure ``s^2 = sigma_min(M2)^2 = 1 - |C5| = S5^2 / (1 + |C5|)``.

    Exact for M2 of eq. (58) (``M2^T M2`` has eigenvalues ``1 +- |C5|``); the last form has
    no cancellation near theta_5 = 0.
    """
    return t.s5 * t.s5 / (1.0 + abs(t.c5))


def arm_s2(det: Entry, adj2: Entry) -> Entry:
    """The arm's band measure ``s^2 = det^2 / ||adj||_F^2 <= sigma_min^2`` of M or of M1.

    ``det``, ``adj2`` from :func:`det_adj2` for M; for the 2x2 M1 ``||adj M1||_F =
    ||M1||_F``. Zero where the adjugate is (the block has rank <= 1, so ``det = 0``).
    """
    return det * det / (adj2 + (adj2 == 0.0))  # adj2 >= 0: 1 in place of 0


def arm_in_band(det: Entry, adj2: Entry, eps: float) -> Entry:
    """Whether the arm is in its band, ``arm_s2(det, adj2) <= eps^2``, without the division."""
    return det * det <= eps * eps * adj2


def frame3_axes(g: BarkerGeometry, t: Trig) -> tuple[tuple[Entry, ...], ...]:
    """Axes x3, y3, z3 in base coordinates: the columns of Barker eq. (B5).

    With P1 = -C23 and P2 = -S23 (eq. (B11) corrected): x3 = (-C1 P1, -S1 P1, P2),
    y3 = (T1, T3, P1 CAL3), z3 = (T2, T4, -P1 SAL3) (eqs (B12)-(B15); z3 is eq. (C11)).
    """
    s23c, s23s = t.s23 * g.cal3, t.s23 * g.sal3
    return (
        (t.c1 * t.c23, t.s1 * t.c23, -t.s23),
        (-t.c1 * s23c - t.s1 * g.sal3, -t.s1 * s23c + t.c1 * g.sal3, -t.c23 * g.cal3),
        (t.c1 * s23s - t.s1 * g.cal3, t.s1 * s23s + t.c1 * g.cal3, t.c23 * g.sal3),
    )


def wrist_axes(g: BarkerGeometry, t: Trig) -> tuple[tuple[Entry, ...], ...]:
    """Joint axes z3, z4, z5 in base coordinates.

    z4 = -S4 x3 + C4 y3 (eq. (C12)), z5 = C4 S5 x3 + S4 S5 y3 + C5 z3 (eq. (C13), the third
    column of R0_6, eqs (B22)-(B24)).
    """
    x3, y3, z3 = frame3_axes(g, t)
    a, b = t.c4 * t.s5, t.s4 * t.s5
    z4 = tuple(-t.s4 * x + t.c4 * y for x, y in zip(x3, y3, strict=True))
    z5 = tuple(a * x + b * y + t.c5 * z for x, y, z in zip(x3, y3, z3, strict=True))
    return z3, z4, z5


def jacobian_rows(g: BarkerGeometry, t: Trig) -> list[list[Entry]]:
    """Wrist-centre Jacobian, rows [v; w], base axes, Barker eqs (17), (22).

    Upper-left block M (eq. (26)); upper-right block zero (eq. (22)); lower rows the joint
    axes z0 = (0, 0, 1), z1 = z2 = (-S1, C1, 0) (eqs (C7), (C8), (C10)), z3, z4, z5.
    """
    M = m_rows(t, f_terms(g, t))
    z3, z4, z5 = wrist_axes(g, t)
    lower = [[0.0, -t.s1, -t.s1], [0.0, t.c1, t.c1], [1.0, 0.0, 0.0]]
    return [[*r, 0.0, 0.0, 0.0] for r in M] + [
        [*lower[i], z3[i], z4[i], z5[i]] for i in range(3)
    ]


def hand_to_base_rows(g: BarkerGeometry, t: Trig) -> list[list[Entry]]:
    """R0_6 = L by Barker eqs (B6)-(B24) (eq. (B11) corrected to P2 = -S23), by rows.

    ``L = [x3 y3 z3] R3_6`` with R3_6's entries Q1..Q4 (eqs (B6)-(B9)): eqs (B16)-(B24)
    grouped by the axes of frame 3.
    """
    q1 = t.c4 * t.c5 * t.c6 - t.s4 * t.s6  # (B6)
    q2 = t.s4 * t.c5 * t.c6 + t.c4 * t.s6  # (B7)
    q3 = -t.c4 * t.c5 * t.s6 - t.s4 * t.c6  # (B8)
    q4 = -t.s4 * t.c5 * t.s6 + t.c4 * t.c6  # (B9)
    x3, y3, z3 = frame3_axes(g, t)
    _, _, z5 = wrist_axes(g, t)
    s5c6, s5s6 = t.s5 * t.c6, t.s5 * t.s6
    return [[x3[i] * q1 + y3[i] * q2 - z3[i] * s5c6,  # (B16)-(B18)
             x3[i] * q3 + y3[i] * q4 + z3[i] * s5s6,  # (B19)-(B21)
             z5[i]] for i in range(3)]  # fmt: skip


def tvel_frame2(t: Trig, tvel: Sequence[Entry]) -> tuple[Entry, ...]:
    """Components of TVEL^ along X2, Y2, Z2, Barker eqs (B27)-(B29) corrected.

    ``R2_1 R1_0`` (eqs (B25), (B26)) gives, with ``(ta, tb)`` the :func:`turn1` of
    (TVEL(1), TVEL(2)): (TVEL)_X2 = S2 ta + C2 TVEL(3), (TVEL)_Y2 = C2 ta - S2 TVEL(3),
    (TVEL)_Z2 = -tb.
    """
    ta, tb = turn1(t, tvel[0], tvel[1])
    return t.s2 * ta + t.c2 * tvel[2], t.c2 * ta - t.s2 * tvel[2], -tb


# -- generalized inverses in the band (arrays) ---------------------------------------------


def damped_solve(
    A: list[list[Entry]], b: Sequence[Entry], s2: Entry, eps: float
) -> list[Entry]:
    r"""Damped least squares of a 2x2 or 3x3 block inside its band (floats or arrays).

    .. math:: x = (A^T A + \lambda^2 I)^{-1} A^T b, \quad \lambda^2 = \epsilon^2 - s^2 > 0,

    by Cholesky's method (``A^T A + lambda^2 I`` has eigenvalues ``>= eps^2``: backward
    stable, relative error about ``eps_machine sigma_max^2 / eps^2``). ``A`` by rows, ``s2``
    the block's measure ``s^2 < eps^2``, ``eps`` the band [units of A]; one entry per unknown.
    """
    n, lam2 = len(A), eps * eps - s2
    cols = list(zip(*A, strict=True))
    N = [[dot(cols[i], cols[j]) + (lam2 if i == j else 0.0) for j in range(n)]
         for i in range(n)]  # fmt: skip
    h = [dot(cols[i], b) for i in range(n)]
    L: list[list[Entry]] = [[0.0] * n for _ in range(n)]  # N = L L^T
    for i in range(n):
        for j in range(i + 1):
            v = N[i][j] - sum(L[i][k] * L[j][k] for k in range(j))
            L[i][j] = v**0.5 if i == j else v / L[j][j]
    y: list[Entry] = []
    for i in range(n):
        y.append((h[i] - sum(L[i][k] * y[k] for k in range(i))) / L[i][i])
    x: list[Entry] = [0.0] * n
    for i in reversed(range(n)):
        x[i] = (y[i] - sum(L[k][i] * x[k] for k in range(i + 1, n))) / L[i][i]
    return x


def truncated_solve(A: list[list[Entry]], b: Sequence[Entry], eps: float, k: int) -> list[Array]:
    """``A^+ b`` for K blocks (entries floats or (K,) arrays) by SVD: (K,) per unknown.

    Singular values ``<= eps`` are dropped: M* of eq. (38), M1* of eq. (44), M2* of eq. (60).
    """
    U, sv, Vt = np.linalg.svd(stack_entries(A, k))
    w = np.einsum("kji,kj->ki", U, np.stack(np.broadcast_arrays(*b, np.empty(k))[:-1], axis=-1))
    w = np.where(sv > eps, w / np.where(sv > eps, sv, 1.0), 0.0)
    return list(np.einsum("kji,kj->ik", Vt, w))
