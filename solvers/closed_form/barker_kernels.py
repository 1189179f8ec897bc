"""Vectorised kernels of Barker's closed form (NASA TM-85685): arrays of N configurations.

Notation of the report: ``S1 = sin(theta_1)``, ``C23 = cos(theta_2 + theta_3)``,
``SAL3 = sin(alpha_3)``, ``SN~ = SN + R3`` (the OCR'd report drops the tilde). Every function
takes the :class:`BarkerGeometry` and the trigonometric terms :class:`Trig` of shape (N,) and
returns (N, ...) arrays; nothing loops over N. Corrections to the printed equations are cited
as in ``docs/errata.d/barker.md``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.closed_form._batch import cos_sin
from solvers.closed_form.barker_pinv import pinv2_apply, pinv3_apply

Array = npt.NDArray[np.float64]


class BarkerGeometry(NamedTuple):
    """Barker's symbolic parameters (SI) and the constants derived from them.

    Attributes:
        no: Neck-to-base length NO = r1 [m].
        es: Elbow-to-shoulder length ES = a2 [m].
        sn: Shoulder-to-neck length SN = r2 [m].
        we: Wrist-to-elbow length WE = r4 [m].
        a3: Link length A3 = a3 [m].
        r3: Offset R3 = r3 [m].
        alpha3: Twist alpha3 [rad].
        sal3: sin(alpha3).
        cal3: cos(alpha3).
        swe: SAL3 WE [m].
        f2: F2 = SN~ + CAL3 WE, SN~ = SN + R3 [m] (Barker eq. (28), with the tilde restored).
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

    @classmethod
    def from_parameters(
        cls, no: float, es: float, sn: float, we: float, a3: float, r3: float, alpha3: float
    ) -> BarkerGeometry:
        """Derive the constants from already validated parameters."""
        sal3, cal3 = float(np.sin(alpha3)), float(np.cos(alpha3))
        return cls(no, es, sn, we, a3, r3, alpha3, sal3, cal3, sal3 * we, sn + r3 + cal3 * we)


class Trig(NamedTuple):
    """Sines and cosines of the joint angles, each of shape (N,); s6, c6 only if asked for."""

    s1: Array
    c1: Array
    s2: Array
    c2: Array
    s3: Array
    c3: Array
    s23: Array
    c23: Array
    s4: Array
    c4: Array
    s5: Array
    c5: Array
    s6: Array | None = None
    c6: Array | None = None


class FTerms(NamedTuple):
    """Barker's F1..F7 (eqs (27)-(31), (41), (37)), each [m]; F2 is a constant."""

    f1: Array
    f2: Array
    f3: Array
    f4: Array
    f5: Array
    f6: Array
    f7: Array


def trig(Q: Array, roll: bool = False) -> Trig:
    """Trigonometric terms of the configurations ``Q`` (N, 6) [rad].

    Works on the transposed, contiguous angles (elementwise numpy is several times faster on
    contiguous rows than on the columns of an (N, 6) array), by
    :func:`~solvers.closed_form._batch.cos_sin`, and skips theta_6, which only
    :func:`hand_to_base` needs (``roll=True``).
    """
    C, S = cos_sin(np.ascontiguousarray(Q.T[: 6 if roll else 5]))
    s23 = S[1] * C[2] + C[1] * S[2]
    c23 = C[1] * C[2] - S[1] * S[2]
    six = (S[5], C[5]) if roll else (None, None)
    return Trig(S[0], C[0], S[1], C[1], S[2], C[2], s23, c23, S[3], C[3], S[4], C[4], *six)


def f_terms(g: BarkerGeometry, t: Trig) -> FTerms:
    """F1..F7 of Barker eqs (27)-(31), (41) and (37); F2 with SN~ = SN + R3."""
    f5 = t.s23 * g.swe + t.c23 * g.a3  # eq. (31)
    f4 = t.c23 * g.swe - t.s23 * g.a3  # eq. (30)
    f1 = t.s2 * g.es + f5  # eq. (27)
    f3 = t.c2 * g.es + f4  # eq. (29)
    f2 = np.full_like(f1, g.f2)  # eq. (28)
    f6 = t.s1 * f1 + t.c1 * g.f2  # eq. (41)
    f7 = t.c1 * f1 - t.s1 * g.f2  # eq. (37)
    return FTerms(f1, f2, f3, f4, f5, f6, f7)


def eq33(g: BarkerGeometry, t: Trig) -> Array:
    """SAL3 WE S3 + A3 C3 [m]: zero on Barker's singularity (33) (Appendix D, eq. (D8))."""
    return g.swe * t.s3 + g.a3 * t.c3


def m_matrix(t: Trig, F: FTerms) -> Array:
    """Barker's M, eq. (26): TVEL^ = M (thetadot_1, thetadot_2, thetadot_3), shape (N, 3, 3)."""
    M = np.empty((t.s1.shape[0], 3, 3))
    M[:, 0, 0] = -F.f6  # -S1 F1 - C1 F2
    M[:, 0, 1] = t.c1 * F.f3
    M[:, 0, 2] = t.c1 * F.f4
    M[:, 1, 0] = F.f7  # C1 F1 - S1 F2
    M[:, 1, 1] = t.s1 * F.f3
    M[:, 1, 2] = t.s1 * F.f4
    M[:, 2, 0] = 0.0
    M[:, 2, 1] = -F.f1
    M[:, 2, 2] = -F.f5
    return M


def det_m(g: BarkerGeometry, t: Trig, F: FTerms) -> Array:
    """Determinant of M: (S2 ES + F5)(SAL3 WE S3 + A3 C3) ES, Barker eq. (D9), [m^3]."""
    return F.f1 * eq33(g, t) * g.es


def frame3_axes(g: BarkerGeometry, t: Trig) -> tuple[Array, Array, Array]:
    """Axes x3, y3, z3 in base coordinates, each (N, 3): the columns of Barker eq. (B5).

    With P1 = -C23 and P2 = -S23 (eq. (B11) corrected): x3 = (-C1 P1, -S1 P1, P2),
    y3 = (T1, T3, P1 CAL3), z3 = (T2, T4, -P1 SAL3) (eqs (B12)-(B15); z3 is eq. (C11)).
    """
    x3 = np.stack([t.c1 * t.c23, t.s1 * t.c23, -t.s23], axis=-1)
    y3 = np.stack(
        [-t.c1 * t.s23 * g.cal3 - t.s1 * g.sal3, -t.s1 * t.s23 * g.cal3 + t.c1 * g.sal3,
         -t.c23 * g.cal3],
        axis=-1,
    )  # fmt: skip
    z3 = np.stack(
        [t.c1 * t.s23 * g.sal3 - t.s1 * g.cal3, t.s1 * t.s23 * g.sal3 + t.c1 * g.cal3,
         t.c23 * g.sal3],
        axis=-1,
    )  # fmt: skip
    return x3, y3, z3


def jacobian(g: BarkerGeometry, t: Trig) -> Array:
    """Wrist-centre Jacobian, rows [v; w], base axes, Barker eqs (17), (22), shape (N, 6, 6).

    Upper-left block M (eq. (26)); upper-right block zero (eq. (22)); lower rows the joint
    axes z0 = (0, 0, 1), z1 = z2 = (-S1, C1, 0) (eqs (C7), (C8), (C10)), z3 (eq. (C11)),
    z4 = -S4 x3 + C4 y3 (eq. (C12)), z5 = C4 S5 x3 + S4 S5 y3 + C5 z3 (= third column of R0_6).
    """
    F = f_terms(g, t)
    n = t.s1.shape[0]
    J = np.zeros((n, 6, 6))
    J[:, :3, :3] = m_matrix(t, F)
    J[:, 5, 0] = 1.0
    J[:, 3, 1] = J[:, 3, 2] = -t.s1
    J[:, 4, 1] = J[:, 4, 2] = t.c1
    x3, y3, z3 = frame3_axes(g, t)
    J[:, 3:, 3] = z3
    J[:, 3:, 4] = -t.s4[:, None] * x3 + t.c4[:, None] * y3
    J[:, 3:, 5] = (t.c4 * t.s5)[:, None] * x3 + (t.s4 * t.s5)[:, None] * y3 + t.c5[:, None] * z3
    return J


def arm_rates_full(
    g: BarkerGeometry, t: Trig, tvel: Array, rcond: float
) -> tuple[Array, Array]:
    """thetadot_1..3 by Barker eqs (34)-(36) (signs of (35), (36) corrected), M* where singular.

    Where ``|det M| <= rcond ||M||_F^3`` the closed form is not used and M* (eq. (38)) is the
    truncated pseudo-inverse: the result equals ``pinv(M, rcond) @ TVEL^`` everywhere.

    Args:
        g: Geometry.
        t: Trigonometric terms (N,).
        tvel: TVEL^, wrist-centre velocity in base axes, (N, 3) [m/s].
        rcond: Relative singular-value cutoff.

    Returns:
        ``(rates, regular)``: (N, 3) [rad/s] and the (N,) mask where eqs (34)-(36) answered.
    """
    F = f_terms(g, t)
    det = det_m(g, t, F)
    fro2 = 2.0 * F.f1**2 + g.f2**2 + F.f3**2 + F.f4**2 + F.f5**2
    regular = np.abs(det) > rcond * fro2 * np.sqrt(fro2)
    T1, T2, T3 = tvel[:, 0], tvel[:, 1], tvel[:, 2]
    inv = np.where(regular, 1.0, 0.0) / np.where(regular, det, 1.0)
    u = T1 * F.f7 + T2 * F.f6
    out = np.empty((t.s1.shape[0], 3))
    out[:, 0] = (T1 * t.s1 - T2 * t.c1) * (F.f1 * F.f4 - F.f3 * F.f5) * inv  # eq. (34)
    out[:, 1] = (F.f5 * u + T3 * F.f1 * F.f4) * inv  # eq. (35), leading sign corrected
    out[:, 2] = -F.f1 * (u + T3 * F.f3) * inv  # eq. (36), sign of TVEL(2) F6 corrected
    if not np.all(regular):
        idx = np.flatnonzero(~regular)
        M = m_matrix(t, F)[idx]
        out[idx] = pinv3_apply(M, tvel[idx], rcond)  # eq. (38)
    return out, regular


def arm_rates_reduced(
    g: BarkerGeometry, t: Trig, tvel: Array, rcond: float
) -> tuple[Array, Array]:
    """thetadot_1..3 by Barker eq. (39) and eq. (44) with the 2x2 generalized inverse M1*.

    Eqs (40)-(43) corrected: as printed, M1's first row is ``(C1 F2 - F6)(F3, F4) =
    -S1 F1 (F3, F4)``, which vanishes at theta_1 = 0 where M is regular. The row used here is
    ``(S1 row1 - C1 row2)`` of eq. (25) with eq. (39) substituted, divided by F2:

        [F1 F3 / F2, F1 F4 / F2] (thetadot_2, thetadot_3) = F1 ta / F2 - tb,
        ta = C1 TVEL(1) + S1 TVEL(2),  tb = S1 TVEL(1) - C1 TVEL(2),

    with eq. (25)'s third row, so that at a singular configuration eq. (44) gives the
    least-squares solution of eq. (25) among those satisfying eq. (39), of least
    (thetadot_2, thetadot_3) norm. M1* cuts singular values ``<= rcond ||M||_F`` (an
    absolute scale: at the double singularity S2 = 0 with eq. (33) all of M1 vanishes).

    Returns:
        ``(rates, regular)``: (N, 3) [rad/s] and the (N,) mask where M1 was inverted.
    """
    F = f_terms(g, t)
    T1, T2, T3 = tvel[:, 0], tvel[:, 1], tvel[:, 2]
    ta = t.c1 * T1 + t.s1 * T2
    tb = t.s1 * T1 - t.c1 * T2
    k = F.f1 / g.f2
    fro2 = 2.0 * F.f1**2 + g.f2**2 + F.f3**2 + F.f4**2 + F.f5**2  # ||M||_F^2: absolute scale
    th2, th3, regular = pinv2_apply(
        k * F.f3, k * F.f4, -F.f1, -F.f5, k * ta - tb, T3, rcond, fro2
    )
    out = np.empty((t.s1.shape[0], 3))
    out[:, 0] = (F.f3 * th2 + F.f4 * th3 - ta) / g.f2  # eq. (39)
    out[:, 1] = th2
    out[:, 2] = th3
    return out, regular


def rvel_tilde(t: Trig, arm: Array, rvel: Array) -> Array:
    """RVEL~ = RVEL^ - z0 thetadot_1 - z1 thetadot_2 - z2 thetadot_3, Barker eq. (48), (N, 3)."""
    s = arm[:, 1] + arm[:, 2]
    return np.stack([rvel[:, 0] + t.s1 * s, rvel[:, 1] - t.c1 * s, rvel[:, 2] - arm[:, 0]], axis=-1)


def d_terms(g: BarkerGeometry, t: Trig, rt: Array) -> tuple[Array, Array, Array, Array, Array]:
    """D1..D5 of Barker eqs (52)-(56) from RVEL~ ``rt`` (N, 3) [rad/s]."""
    d1 = t.c1 * rt[:, 0] + t.s1 * rt[:, 1]  # eq. (52)
    d2 = t.s1 * rt[:, 0] - t.c1 * rt[:, 1]  # eq. (53)
    d3 = t.s23 * d1 + t.c23 * rt[:, 2]  # eq. (54)
    d4 = t.c23 * d1 - t.s23 * rt[:, 2]  # eq. (55)
    d5 = g.cal3 * d3 + g.sal3 * d2  # eq. (56)
    return d1, d2, d3, d4, d5


def wrist_rates(
    g: BarkerGeometry, t: Trig, rt: Array, rcond: float, reduced: bool
) -> tuple[Array, Array]:
    """thetadot_4..6 from RVEL~ (eq. (48)) by Barker eqs (49)-(51), or eq. (49) + eq. (60).

    ``reduced=False``: eqs (49)-(51) where ``|S5| > rcond (1 + |C5|)``, else M2*.
    ``reduced=True``: eq. (49) and eq. (60) with the generic closed-form M2* everywhere.
    Both equal ``pinv(W, rcond) @ RVEL~`` for the wrist block ``W = [z3 z4 z5]``: in the
    orthonormal directions (C4 x3 + S4 y3, z4, z3) W reads (S5 thetadot_6, thetadot_5,
    thetadot_4 + C5 thetadot_6), so thetadot_5 separates and M2 (eq. (58)) carries the rest.

    Returns:
        ``(rates, regular)``: (N, 3) [rad/s] and the (N,) mask where M2 was inverted.
    """
    _, d2, d3, d4, d5 = d_terms(g, t, rt)
    out = np.empty((t.s1.shape[0], 3))
    out[:, 1] = -t.c4 * d5 - t.s4 * d4  # eq. (49)
    ga = -t.s4 * d5 + t.c4 * d4  # eq. (59), first row (D5, printed "D6")
    gb = g.sal3 * d3 - g.cal3 * d2  # eq. (59), second row
    if reduced:
        zero = np.zeros_like(ga)
        th4, th6, regular = pinv2_apply(zero, t.s5, zero + 1.0, t.c5, ga, gb, rcond)  # eq. (60)
    else:
        ac5 = np.abs(t.c5)
        regular = np.abs(t.s5) > rcond * (1.0 + ac5)
        th6 = ga / np.where(regular, t.s5, 1.0)  # eq. (50)
        th4 = gb - t.c5 * th6  # eq. (51)
        if not np.all(regular):
            # M2* of M2 = [[0, S5], [1, C5]] (eq. (58)) truncated to its rank-one part.
            sg = np.where(t.c5 >= 0.0, 1.0, -1.0)
            k = (sg * t.s5 * ga + (1.0 + ac5) * gb) / (2.0 * (1.0 + ac5))
            th4 = np.where(regular, th4, k)
            th6 = np.where(regular, th6, sg * k)
    out[:, 0] = th4
    out[:, 2] = th6
    return out, regular


def hand_to_base(g: BarkerGeometry, t: Trig) -> Array:
    """R0_6 = L by Barker eqs (B6)-(B24) (eq. (B11) corrected to P2 = -S23), (N, 3, 3).

    ``t`` must come from ``trig(Q, roll=True)``.
    """
    if t.s6 is None or t.c6 is None:
        raise ValueError("hand_to_base needs trig(Q, roll=True)")
    q1 = t.c4 * t.c5 * t.c6 - t.s4 * t.s6  # (B6)
    q2 = t.s4 * t.c5 * t.c6 + t.c4 * t.s6  # (B7)
    q3 = -t.c4 * t.c5 * t.s6 - t.s4 * t.c6  # (B8)
    q4 = -t.s4 * t.c5 * t.s6 + t.c4 * t.c6  # (B9)
    p1 = -t.c23  # (B10)
    p2 = -t.s23  # (B11), printed "-S23 CAL3"
    t1 = t.c1 * g.cal3 * p2 - t.s1 * g.sal3  # (B12)
    t2 = -t.c1 * p2 * g.sal3 - t.s1 * g.cal3  # (B13)
    t3 = t.s1 * g.cal3 * p2 + t.c1 * g.sal3  # (B14)
    t4 = -t.s1 * p2 * g.sal3 + t.c1 * g.cal3  # (B15)
    s5c6 = t.s5 * t.c6
    s5s6 = t.s5 * t.s6
    c4s5 = t.c4 * t.s5
    s4s5 = t.s4 * t.s5
    L = np.empty((t.s1.shape[0], 3, 3))
    L[:, 0, 0] = -t.c1 * p1 * q1 + t1 * q2 - t2 * s5c6  # (B16)
    L[:, 1, 0] = -t.s1 * p1 * q1 + t3 * q2 - t4 * s5c6  # (B17)
    L[:, 2, 0] = p2 * q1 + p1 * g.cal3 * q2 + p1 * g.sal3 * s5c6  # (B18)
    L[:, 0, 1] = -t.c1 * p1 * q3 + t1 * q4 + t2 * s5s6  # (B19)
    L[:, 1, 1] = -t.s1 * p1 * q3 + t3 * q4 + t4 * s5s6  # (B20)
    L[:, 2, 1] = p2 * q3 + p1 * g.cal3 * q4 - p1 * g.sal3 * s5s6  # (B21)
    L[:, 0, 2] = -t.c1 * p1 * c4s5 + t1 * s4s5 + t2 * t.c5  # (B22)
    L[:, 1, 2] = -t.s1 * p1 * c4s5 + t3 * s4s5 + t4 * t.c5  # (B23)
    L[:, 2, 2] = p2 * c4s5 + p1 * g.cal3 * s4s5 - p1 * g.sal3 * t.c5  # (B24)
    return L


def tvel_frame2(t: Trig, tvel: Array) -> Array:
    """Components of TVEL^ along X2, Y2, Z2, Barker eqs (B27)-(B29) corrected, (N, 3).

    ``R2_1 R1_0`` (eqs (B25), (B26)) gives (TVEL)_X2 = S2 (C1 TVEL(1) + S1 TVEL(2)) + C2 TVEL(3),
    (TVEL)_Y2 = C2 (C1 TVEL(1) + S1 TVEL(2)) - S2 TVEL(3), (TVEL)_Z2 = C1 TVEL(2) - S1 TVEL(1).
    """
    ta = t.c1 * tvel[:, 0] + t.s1 * tvel[:, 1]
    return np.stack(
        [t.s2 * ta + t.c2 * tvel[:, 2], t.c2 * ta - t.s2 * tvel[:, 2],
         t.c1 * tvel[:, 1] - t.s1 * tvel[:, 0]],
        axis=-1,
    )  # fmt: skip
