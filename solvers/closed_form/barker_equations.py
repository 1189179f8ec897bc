r"""The equations of Barker's closed form (NASA TM-85685, 1983), as compiled kernels.

Standard DH (Barker eq. (1)): alpha = (90, 0, alpha3, 90, 90, 0) deg, a = (0, ES, A3, 0, 0, 0),
r = (NO, SN, R3, WE, 0, 0), theta'_i = theta_i + (180, 90, 90, 180, 180, 0) deg; q is Barker's
theta_i. The controlled point is the wrist centre (origin of frames 4, 5, 6), so the Jacobian
is block lower-triangular (eq. (22)): the arm rates solve ``M thetadot_123 = TVEL^``
(eq. (25)), the wrist rates ``W thetadot_456 = RVEL~`` (eqs (47), (48)). Notation of the
report: ``S1 = sin(theta_1)``, ``C23 = cos(theta_2 + theta_3)``, ``SAL3 = sin(alpha_3)``,
``SN~ = SN + R3`` (the OCR'd report drops the tilde).

Each equation is one small kernel (:func:`~rrc_pin.solvers.compiled.kernel`:
``numba.njit(cache=True)``)
on the floats of one configuration, cited once; corrections to the printed equations are
cited as in docs/errata.md. The steps private to the arm's and the wrist's rates (eqs (25),
(34)-(44), (50), (51), (58), the band measures, the band's solve) and ``joint_rates`` are
:func:`~rrc_pin.solvers.compiled.inlined` into the kernels that call them, so that numba does
not compile and optimise each as a library of its own. The paths of
:mod:`rrc_pin.solvers.closed_form.barker` (the arm, the wrist, their bands) and the loops over
N configurations are at the end: a batch is a compiled loop over the same kernels.

Singular set (Appendix D): ``det J = det M det W = ES (S2 ES + F5)(SAL3 WE S3 + A3 C3) S5``
(up to sign), for any R3 and alpha3: conditions (32), (33) and S5 = 0.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.closed_form.base import finite
from rrc_pin.solvers.compiled import inlined, kernel
from rrc_pin.solvers.linalg import jacobi_svd, svd_rates

Array = npt.NDArray[np.float64]
Flags = npt.NDArray[np.bool_]


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
    """Sines and cosines of the joint angles of one configuration, and of theta_2 + theta_3."""

    s1: float
    c1: float
    s2: float
    c2: float
    s3: float
    c3: float
    s23: float
    c23: float
    s4: float
    c4: float
    s5: float
    c5: float
    s6: float
    c6: float


class FTerms(NamedTuple):
    """Barker's F1..F7 (eqs (27)-(31), (41), (37)), each [m]; F2 is a constant."""

    f1: float
    f2: float
    f3: float
    f4: float
    f5: float
    f6: float
    f7: float


# -- one configuration ---------------------------------------------------------------------


@kernel
def geometry(p: Array) -> BarkerGeometry:
    """The :class:`BarkerGeometry` of the kernels' parameters ``p`` (17,) (:func:`parameters`)."""
    return BarkerGeometry(p[0], p[1], p[2], p[3], p[4], p[5], p[6], p[7], p[8], p[9], p[10],
                          p[11], p[12])  # fmt: skip


def parameters(g: BarkerGeometry, band: float, rcond: float) -> Array:
    """The kernels' parameters (17,): the fields of ``g``, then the widths of :func:`widths`."""
    widths = (band * g.reach, band, rcond * g.reach, rcond)
    return np.array([*g, *widths], dtype=np.float64)


@kernel
def widths(p: Array, exact: bool) -> tuple[float, float]:
    """The band of the arm [m] and of the wrist [1] (of the exact path with ``exact``).

    ``band`` (or ``rcond``) times the reach L for the arm, ``band`` (``rcond``) for the wrist.
    """
    return (p[15], p[16]) if exact else (p[13], p[14])


@kernel
def joint_trig(q: Array) -> Trig:
    """Trigonometric terms of one configuration ``q`` (6,) [rad]."""
    return Trig(math.sin(q[0]), math.cos(q[0]), math.sin(q[1]), math.cos(q[1]),
                math.sin(q[2]), math.cos(q[2]), math.sin(q[1] + q[2]), math.cos(q[1] + q[2]),
                math.sin(q[3]), math.cos(q[3]), math.sin(q[4]), math.cos(q[4]),
                math.sin(q[5]), math.cos(q[5]))  # fmt: skip


@kernel
def turn1(t: Trig, x: float, y: float) -> tuple[float, float]:
    """``(C1 x + S1 y, S1 x - C1 y)``: the turn by theta_1 of Barker's D1, D2 (eqs (52), (53)).

    The components of a base-axis vector ``(x, y, .)`` along the horizontal unit vectors
    ``(C1, S1, 0)`` and ``(S1, -C1, 0)`` (orthogonal, its own inverse). The same turn takes
    the rows of eq. (25) (:func:`m_rotated`, :func:`m1_system`) and TVEL^
    (:func:`tvel_frame2`).
    """
    return t.c1 * x + t.s1 * y, t.s1 * x - t.c1 * y


@kernel
def f_terms(g: BarkerGeometry, t: Trig) -> FTerms:
    """F1..F7 of Barker eqs (27)-(31), (41) and (37); F2 with SN~ = SN + R3 (a constant)."""
    f5 = t.s23 * g.swe + t.c23 * g.a3  # eq. (31)
    f4 = t.c23 * g.swe - t.s23 * g.a3  # eq. (30)
    f1 = t.s2 * g.es + f5  # eq. (27)
    f3 = t.c2 * g.es + f4  # eq. (29)
    f6 = t.s1 * f1 + t.c1 * g.f2  # eq. (41)
    f7 = t.c1 * f1 - t.s1 * g.f2  # eq. (37)
    return FTerms(f1, g.f2, f3, f4, f5, f6, f7)


@kernel
def wrist_centre(g: BarkerGeometry, F: FTerms, p: Array) -> None:
    """p06, the wrist centre in base coordinates [m], into ``p`` (3,): ``(F7, F6, NO + F3)``.

    M's first column (eq. (26)) is ``z0 x p06 = (-F6, F7, 0)`` (eqs (14)-(16), p00 = 0),
    which gives the horizontal components; the height is the third entry of the fourth
    column of ``A1 A2 A3 A4`` (Appendix A): ``NO + ES C2 + SAL3 WE C23 - A3 S23 = NO + F3``
    (eqs (29), (30)).
    """
    p[0], p[1], p[2] = F.f7, F.f6, g.no + F.f3


@kernel
def eq33(g: BarkerGeometry, t: Trig) -> float:
    """SAL3 WE S3 + A3 C3 [m]: zero on Barker's singularity (33) (Appendix D, eq. (D8))."""
    return g.swe * t.s3 + g.a3 * t.c3


@kernel
def m_matrix(t: Trig, F: FTerms, M: Array) -> None:
    """Barker's M, eq. (26), into ``M[:3, :3]``: TVEL^ = M (thetadot_1, thetadot_2, thetadot_3)."""
    M[0, 0], M[0, 1], M[0, 2] = -F.f6, t.c1 * F.f3, t.c1 * F.f4
    M[1, 0], M[1, 1], M[1, 2] = F.f7, t.s1 * F.f3, t.s1 * F.f4
    M[2, 0], M[2, 1], M[2, 2] = 0.0, -F.f1, -F.f5


@inlined
def m_rotated(t: Trig, F: FTerms, T1: float, T2: float, T3: float, A: Array, b: Array) -> None:
    """Eq. (25) with its rows turned by theta_1, and TVEL^ with them: ``A`` (3, 3), ``b`` (3,).

    The :func:`turn1` of the first two rows of M, the third kept (eqs (37), (41)): the same
    least-squares problem as M (an orthogonal change of rows), sparser.
    """
    A[0, 0], A[0, 1], A[0, 2] = -F.f2, F.f3, F.f4
    A[1, 0], A[1, 1], A[1, 2] = -F.f1, 0.0, 0.0
    A[2, 0], A[2, 1], A[2, 2] = 0.0, -F.f1, -F.f5
    b[0], b[1] = turn1(t, T1, T2)
    b[2] = T3


@inlined
def det_adj2(g: BarkerGeometry, t: Trig, F: FTerms) -> tuple[float, float]:
    """Det M = ES F1 (SAL3 WE S3 + A3 C3) (eq. (D9)) [m^3] and ||adj M||_F^2 [m^4].

    The cross products of the rows of :func:`m_rotated` give ``||adj M||^2 = (ES e33)^2 +
    (F2 F5)^2 + F1^2 (F1^2 + F2^2 + F3^2 + F4^2 + F5^2)``, with ``F4^2 + F5^2 =
    (SAL3 WE)^2 + A3^2`` (eqs (30), (31)).
    """
    e = g.es * eq33(g, t)
    f1s = F.f1 * F.f1
    f2f5 = g.f2 * F.f5
    adj2 = e * e + f2f5 * f2f5 + f1s * (f1s + F.f3 * F.f3 + g.f2 * g.f2 + g.r2)
    return F.f1 * e, adj2


@inlined
def arm_full(
    t: Trig, F: FTerms, det: float, T1: float, T2: float, T3: float
) -> tuple[float, float, float]:
    """thetadot_1..3 [rad/s] by Barker eqs (34)-(36) (signs of (35), (36) corrected)."""
    u = T1 * F.f7 + T2 * F.f6
    return (
        (T1 * t.s1 - T2 * t.c1) * (F.f1 * F.f4 - F.f3 * F.f5) / det,  # eq. (34)
        (F.f5 * u + T3 * F.f1 * F.f4) / det,  # eq. (35), leading sign corrected
        -F.f1 * (u + T3 * F.f3) / det,  # eq. (36), sign of TVEL(2) F6 corrected
    )


@inlined
def m1_system(
    t: Trig, F: FTerms, T1: float, T2: float, T3: float, A: Array, b: Array
) -> float:
    """M1, g1 of eqs (40)-(43) corrected into ``A`` (2, 2), ``b`` (2,); returns ``ta``.

    ``M1 (thetadot_2, thetadot_3) = g1``. As printed, M1's first row is
    ``(C1 F2 - F6)(F3, F4) = -S1 F1 (F3, F4)``, which vanishes at theta_1 = 0 where M is
    regular. The row used here is ``(S1 row1 - C1 row2)`` of eq. (25) with eq. (39)
    substituted, divided by F2: ``[F1 F3 / F2, F1 F4 / F2] (thetadot_2, thetadot_3) =
    F1 ta / F2 - tb`` with ``(ta, tb)`` the :func:`turn1` of (TVEL(1), TVEL(2)); the second
    row is eq. (25)'s third.
    """
    ta, tb = turn1(t, T1, T2)
    k = F.f1 / F.f2
    A[0, 0], A[0, 1], A[1, 0], A[1, 1] = k * F.f3, k * F.f4, -F.f1, -F.f5
    b[0], b[1] = k * ta - tb, T3
    return ta


@inlined
def arm_from_m1(F: FTerms, th2: float, th3: float, ta: float) -> float:
    """thetadot_1 by Barker eq. (39), with thetadot_2, thetadot_3 of eq. (44)."""
    return (F.f3 * th2 + F.f4 * th3 - ta) / F.f2


@kernel
def rvel_tilde(
    t: Trig, th1: float, th2: float, th3: float, R1: float, R2: float, R3: float
) -> tuple[float, float, float]:
    """RVEL~ = RVEL^ - z0 thetadot_1 - z1 thetadot_2 - z2 thetadot_3, Barker eq. (48) [rad/s]."""
    s = th2 + th3
    return R1 + t.s1 * s, R2 - t.c1 * s, R3 - th1


@kernel
def wrist_equations(
    g: BarkerGeometry, t: Trig, r1: float, r2: float, r3: float
) -> tuple[float, float, float]:
    """thetadot_5 (eq. (49)) and the right-hand side (ga, gb) of M2 (eqs (58), (59)).

    ``(r1, r2, r3)`` is RVEL~ (eq. (48)); ``M2 (thetadot_4, thetadot_6) = (ga, gb)`` with M2
    of :func:`m2_matrix`, from D1..D5 of eqs (52)-(56). In the orthonormal directions
    (C4 x3 + S4 y3, z4, z3) the wrist block reads (S5 thetadot_6, thetadot_5, thetadot_4 +
    C5 thetadot_6): thetadot_5 separates, M2 carries the rest.
    """
    d1, d2 = turn1(t, r1, r2)  # eqs (52), (53)
    d3 = t.s23 * d1 + t.c23 * r3  # eq. (54)
    d4 = t.c23 * d1 - t.s23 * r3  # eq. (55)
    d5 = g.cal3 * d3 + g.sal3 * d2  # eq. (56)
    th5 = -t.c4 * d5 - t.s4 * d4  # eq. (49)
    return th5, -t.s4 * d5 + t.c4 * d4, g.sal3 * d3 - g.cal3 * d2  # eq. (59) ("D6" is D5)


@inlined
def wrist_regular(t: Trig, ga: float, gb: float) -> tuple[float, float]:
    """(thetadot_4, thetadot_6) by Barker eqs (51), (50): ``M2^-1 (ga, gb)``."""
    th6 = ga / t.s5  # eq. (50)
    return gb - t.c5 * th6, th6  # eq. (51)


@inlined
def m2_matrix(t: Trig, A: Array) -> None:
    """Barker's M2 = [[0, S5], [1, C5]] (eq. (58)) into ``A`` (2, 2): of thetadot_4, thetadot_6."""
    A[0, 0], A[0, 1], A[1, 0], A[1, 1] = 0.0, t.s5, 1.0, t.c5


@inlined
def wrist_s2(t: Trig) -> float:
    """The wrist's band measure ``s^2 = sigma_min(M2)^2 = 1 - |C5| = S5^2 / (1 + |C5|)``.

    Exact for M2 of eq. (58) (``M2^T M2`` has eigenvalues ``1 +- |C5|``); the last form has
    no cancellation near theta_5 = 0.
    """
    return t.s5 * t.s5 / (1.0 + abs(t.c5))


@inlined
def arm_s2(det: float, adj2: float) -> float:
    """The arm's band measure ``s^2 = det^2 / ||adj||_F^2 <= sigma_min^2`` of M or of M1.

    ``det``, ``adj2`` from :func:`det_adj2` for M; for the 2x2 M1 ``||adj M1||_F =
    ||M1||_F``. Zero where the adjugate is (the block has rank <= 1, so ``det = 0``).
    """
    return det * det / adj2 if adj2 > 0.0 else 0.0


@inlined
def arm_in_band(det: float, adj2: float, eps: float) -> bool:
    """Whether the arm is in its band, ``arm_s2(det, adj2) <= eps^2``, without the division."""
    return det * det <= eps * eps * adj2


@kernel
def frame3_axes(
    g: BarkerGeometry, t: Trig
) -> tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]]:
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


@kernel
def jacobian(g: BarkerGeometry, t: Trig, J: Array) -> None:
    """Wrist-centre Jacobian into ``J`` (6, 6), rows [v; w], base axes, Barker eqs (17), (22).

    Upper-left block M (eq. (26)); upper-right block zero (eq. (22)); lower rows the joint
    axes z0 = (0, 0, 1), z1 = z2 = (-S1, C1, 0) (eqs (C7), (C8), (C10)), z3 (eq. (C11)),
    z4 = -S4 x3 + C4 y3 (eq. (C12)), z5 = C4 S5 x3 + S4 S5 y3 + C5 z3 (eq. (C13), the third
    column of R0_6, eqs (B22)-(B24)).
    """
    m_matrix(t, f_terms(g, t), J)
    x3, y3, z3 = frame3_axes(g, t)
    a, b = t.c4 * t.s5, t.s4 * t.s5
    for i in range(3):
        J[i, 3] = J[i, 4] = J[i, 5] = 0.0
        J[3 + i, 3] = z3[i]
        J[3 + i, 4] = -t.s4 * x3[i] + t.c4 * y3[i]
        J[3 + i, 5] = a * x3[i] + b * y3[i] + t.c5 * z3[i]
    J[3, 0], J[3, 1], J[3, 2] = 0.0, -t.s1, -t.s1
    J[4, 0], J[4, 1], J[4, 2] = 0.0, t.c1, t.c1
    J[5, 0], J[5, 1], J[5, 2] = 1.0, 0.0, 0.0


@kernel
def hand_to_base(g: BarkerGeometry, t: Trig, R: Array) -> None:
    """R0_6 = L into ``R`` (3, 3) by Barker eqs (B6)-(B24) (eq. (B11) corrected to P2 = -S23).

    ``L = [x3 y3 z3] R3_6`` with R3_6's entries Q1..Q4 (eqs (B6)-(B9)): eqs (B16)-(B24)
    grouped by the axes of frame 3.
    """
    q1 = t.c4 * t.c5 * t.c6 - t.s4 * t.s6  # (B6)
    q2 = t.s4 * t.c5 * t.c6 + t.c4 * t.s6  # (B7)
    q3 = -t.c4 * t.c5 * t.s6 - t.s4 * t.c6  # (B8)
    q4 = -t.s4 * t.c5 * t.s6 + t.c4 * t.c6  # (B9)
    x3, y3, z3 = frame3_axes(g, t)
    a, b = t.c4 * t.s5, t.s4 * t.s5
    for i in range(3):
        R[i, 0] = x3[i] * q1 + y3[i] * q2 - z3[i] * t.s5 * t.c6  # (B16)-(B18)
        R[i, 1] = x3[i] * q3 + y3[i] * q4 + z3[i] * t.s5 * t.s6  # (B19)-(B21)
        R[i, 2] = a * x3[i] + b * y3[i] + t.c5 * z3[i]  # (B22)-(B24): z5, eq. (C13)


@kernel
def tvel_frame2(t: Trig, T1: float, T2: float, T3: float) -> tuple[float, float, float]:
    """Components of TVEL^ along X2, Y2, Z2, Barker eqs (B27)-(B29) corrected.

    ``R2_1 R1_0`` (eqs (B25), (B26)) gives, with ``(ta, tb)`` the :func:`turn1` of
    (TVEL(1), TVEL(2)): (TVEL)_X2 = S2 ta + C2 TVEL(3), (TVEL)_Y2 = C2 ta - S2 TVEL(3),
    (TVEL)_Z2 = -tb.
    """
    ta, tb = turn1(t, T1, T2)
    return t.s2 * ta + t.c2 * T3, t.c2 * ta - t.s2 * T3, -tb


# -- the paths: a block exactly outside its band, by the SVD inside ------------------------


@inlined
def band_solve(A: Array, b: Array, s2: float, eps: float, exact: bool, x: Array) -> None:
    r"""Rates ``x`` of a 2x2 or 3x3 block ``A x = b`` inside its band, by the SVD of ``A``.

    Default: damped least squares (Wampler 1986)

    .. math:: x = (A^T A + \lambda^2 I)^{-1} A^T b
        = \sum_i \frac{\sigma_i}{\sigma_i^2 + \lambda^2} (u_i^T b)\, v_i,
        \quad \lambda^2 = \epsilon^2 - s^2 \ge 0,

    ``s2`` the block's measure ``s^2 <= eps^2``. With ``exact``: the truncated pseudo-inverse,
    singular values ``<= eps`` dropped (M* of eq. (38), M1* of eq. (44), M2* of eq. (60)).
    The SVD is one-sided Jacobi (:func:`~rrc_pin.solvers.linalg.jacobi_svd`); ``A`` is
    overwritten.
    """
    m = b.size
    V = np.empty((m, m))
    sigma = np.empty(m)
    jacobi_svd(A, V, sigma)
    lambda_sq = np.full(m, 0.0 if exact else eps * eps - s2)
    cut = eps if exact else 0.0
    rank = 0 * m  # not the literal 0: one compiled signature of svd_rates
    for i in range(m):
        if sigma[i] > cut:
            rank += 1
    svd_rates(A, sigma, V, b, lambda_sq, rank, x)


@kernel
def arm_rates(
    g: BarkerGeometry, t: Trig, T1: float, T2: float, T3: float, reduced: bool, exact: bool,
    eps: float,
) -> tuple[float, float, float, bool]:  # fmt: skip
    """thetadot_1..3 [rad/s] for TVEL^ = (T1, T2, T3) [m/s], and whether in the arm's band.

    ``reduced``: eqs (39), (44) with M1 (2x2); else eqs (34)-(36). ``eps`` [m]: the band
    (``band L``, or ``rcond L`` with ``exact``); inside it :func:`band_solve` answers, eq. (38)
    (M) or eq. (44) (M1).
    """
    F = f_terms(g, t)
    if reduced:  # eqs (39), (44)
        A, b = np.empty((2, 2)), np.empty(2)
        ta = m1_system(t, F, T1, T2, T3, A, b)
        det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
        fro2 = A[0, 0] ** 2 + A[0, 1] ** 2 + A[1, 0] ** 2 + A[1, 1] ** 2  # ||adj M1||_F^2
        bad = arm_in_band(det, fro2, eps)
        if bad:
            x = np.empty(2)
            band_solve(A, b, arm_s2(det, fro2), eps, exact, x)
            th2, th3 = x[0], x[1]
        else:
            th2 = (A[1, 1] * b[0] - A[0, 1] * b[1]) / det
            th3 = (A[0, 0] * b[1] - A[1, 0] * b[0]) / det
        return arm_from_m1(F, th2, th3, ta), th2, th3, bad
    det, adj2 = det_adj2(g, t, F)
    bad = arm_in_band(det, adj2, eps)
    if not bad:
        th1, th2, th3 = arm_full(t, F, det, T1, T2, T3)
        return th1, th2, th3, bad
    A, b, x = np.empty((3, 3)), np.empty(3), np.empty(3)
    m_rotated(t, F, T1, T2, T3, A, b)  # eq. (38)
    band_solve(A, b, arm_s2(det, adj2), eps, exact, x)
    return x[0], x[1], x[2], bad


@kernel
def wrist_rates(
    g: BarkerGeometry, t: Trig, r1: float, r2: float, r3: float, exact: bool, eps: float
) -> tuple[float, float, float, bool]:
    """thetadot_4..6 [rad/s] from RVEL~ by eqs (49)-(51), and whether in the wrist's band.

    ``eps``: the band (``band``, or ``rcond`` with ``exact``); inside it :func:`band_solve`
    answers for M2 (eq. (60)); thetadot_5 is eq. (49) everywhere.
    """
    th5, ga, gb = wrist_equations(g, t, r1, r2, r3)
    s2 = wrist_s2(t)
    bad = s2 <= eps * eps
    if not bad:
        th4, th6 = wrist_regular(t, ga, gb)
        return th4, th5, th6, bad
    A, b, x = np.empty((2, 2)), np.empty(2), np.empty(2)
    m2_matrix(t, A)
    b[0], b[1] = ga, gb
    band_solve(A, b, s2, eps, exact, x)
    return x[0], th5, x[1], bad


@inlined
def joint_rates(
    g: BarkerGeometry, t: Trig, x: Array, reduced: bool, exact: bool, eps_arm: float,
    eps_wrist: float, out: Array,
) -> None:  # fmt: skip
    """Rates ``out`` (6,) for the twist ``x`` (6,): the arm, RVEL~ (eq. (48)), the wrist."""
    th1, th2, th3, _ = arm_rates(g, t, x[0], x[1], x[2], reduced, exact, eps_arm)
    r1, r2, r3 = rvel_tilde(t, th1, th2, th3, x[3], x[4], x[5])
    th4, th5, th6, _ = wrist_rates(g, t, r1, r2, r3, exact, eps_wrist)
    out[0], out[1], out[2], out[3], out[4], out[5] = th1, th2, th3, th4, th5, th6


@kernel
def singularity(
    g: BarkerGeometry, t: Trig, eps_arm: float, eps_wrist: float, values: Array, flags: Flags
) -> None:
    """Conditions (32), (33), S5 and det M (eq. (D9)) into ``values`` (4,); the bands' flags.

    ``flags`` (2,): inside the arm's band, inside the wrist's band.
    """
    F = f_terms(g, t)
    det, adj2 = det_adj2(g, t, F)
    values[0], values[1], values[2], values[3] = F.f1, eq33(g, t), t.s5, det
    flags[0] = arm_in_band(det, adj2, eps_arm)
    flags[1] = wrist_s2(t) <= eps_wrist * eps_wrist


# -- entry points: one configuration, and compiled loops over N ----------------------------


@kernel
def jacobian_at(p: Array, q: Array, J: Array) -> bool:
    """:func:`jacobian` at ``q`` (6,) into ``J`` (6, 6).

    False (J unset) unless ``q`` has that many entries, all finite.
    """
    if not finite(q, 6):
        return False
    jacobian(geometry(p), joint_trig(q), J)
    return True


@kernel
def joint_rates_at(p: Array, q: Array, x: Array, reduced: bool, exact: bool, out: Array) -> bool:
    """:func:`joint_rates` at ``q`` (6,) for ``x`` (6,).

    False (``out`` unset) unless both have that many entries, all finite.
    """
    if not (finite(q, 6) and finite(x, 6)):
        return False
    eps_arm, eps_wrist = widths(p, exact)
    joint_rates(geometry(p), joint_trig(q), x, reduced, exact, eps_arm, eps_wrist, out)
    return True


@kernel
def wrist_centre_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`wrist_centre` at each row of ``Q`` (N, 6) into ``out`` (N, 3)."""
    g = geometry(p)
    for k in range(Q.shape[0]):
        wrist_centre(g, f_terms(g, joint_trig(Q[k])), out[k])


@kernel
def jacobian_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`jacobian` at each row of ``Q`` (N, 6) into ``out`` (N, 6, 6)."""
    g = geometry(p)
    for k in range(Q.shape[0]):
        jacobian(g, joint_trig(Q[k]), out[k])


@kernel
def joint_rates_batch(
    p: Array, Q: Array, X: Array, reduced: bool, exact: bool, out: Array
) -> None:
    """:func:`joint_rates` at each row of ``Q`` (N, 6) for ``X`` (N, 6) into ``out`` (N, 6)."""
    g, (eps_arm, eps_wrist) = geometry(p), widths(p, exact)
    for k in range(Q.shape[0]):
        joint_rates(g, joint_trig(Q[k]), X[k], reduced, exact, eps_arm, eps_wrist, out[k])


@kernel
def arm_rates_batch(p: Array, Q: Array, T: Array, reduced: bool, exact: bool, out: Array) -> None:
    """:func:`arm_rates` at each row of ``Q`` (N, 6) for ``T`` (N, 3) into ``out`` (N, 3)."""
    g, eps = geometry(p), widths(p, exact)[0]
    for k in range(Q.shape[0]):
        th1, th2, th3, _ = arm_rates(g, joint_trig(Q[k]), T[k, 0], T[k, 1], T[k, 2], reduced,
                                     exact, eps)  # fmt: skip
        out[k, 0], out[k, 1], out[k, 2] = th1, th2, th3


@kernel
def wrist_rates_batch(p: Array, Q: Array, R: Array, exact: bool, out: Array) -> None:
    """:func:`wrist_rates` at each row of ``Q`` (N, 6) for RVEL~ ``R`` (N, 3) into ``out``."""
    g, eps = geometry(p), widths(p, exact)[1]
    for k in range(Q.shape[0]):
        th4, th5, th6, _ = wrist_rates(g, joint_trig(Q[k]), R[k, 0], R[k, 1], R[k, 2], exact, eps)
        out[k, 0], out[k, 1], out[k, 2] = th4, th5, th6


@kernel
def rvel_tilde_batch(Q: Array, ARM: Array, RVEL: Array, out: Array) -> None:
    """:func:`rvel_tilde` at each row of ``Q`` (N, 6), ``ARM``, ``RVEL`` (N, 3) into ``out``."""
    for k in range(Q.shape[0]):
        a, r = ARM[k], RVEL[k]
        out[k, 0], out[k, 1], out[k, 2] = rvel_tilde(joint_trig(Q[k]), a[0], a[1], a[2], r[0],
                                                     r[1], r[2])  # fmt: skip


@kernel
def tvel_frame2_batch(Q: Array, T: Array, out: Array) -> None:
    """:func:`tvel_frame2` at each row of ``Q`` (N, 6) for ``T`` (N, 3) into ``out`` (N, 3)."""
    for k in range(Q.shape[0]):
        out[k, 0], out[k, 1], out[k, 2] = tvel_frame2(joint_trig(Q[k]), T[k, 0], T[k, 1], T[k, 2])


@kernel
def f_terms_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`f_terms` at each row of ``Q`` (N, 6) into ``out`` (N, 7): F1..F7."""
    g = geometry(p)
    for k in range(Q.shape[0]):
        F = f_terms(g, joint_trig(Q[k]))
        for i in range(7):
            out[k, i] = F[i]


@kernel
def m_matrix_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`m_matrix` at each row of ``Q`` (N, 6) into ``out`` (N, 3, 3)."""
    g = geometry(p)
    for k in range(Q.shape[0]):
        t = joint_trig(Q[k])
        m_matrix(t, f_terms(g, t), out[k])


@kernel
def singularity_batch(p: Array, Q: Array, values: Array, flags: Flags) -> None:
    """:func:`singularity` at each row of ``Q`` (N, 6) into ``values`` (N, 4), ``flags`` (N, 2).

    The flags are those of the default path's bands.
    """
    g, (eps_arm, eps_wrist) = geometry(p), widths(p, False)
    for k in range(Q.shape[0]):
        singularity(g, joint_trig(Q[k]), eps_arm, eps_wrist, values[k], flags[k])


@kernel
def hand_to_base_batch(p: Array, Q: Array, out: Array) -> None:
    """:func:`hand_to_base` at each row of ``Q`` (N, 6) into ``out`` (N, 3, 3)."""
    g = geometry(p)
    for k in range(Q.shape[0]):
        hand_to_base(g, joint_trig(Q[k]), out[k])
