r"""Barker's closed-form resolved-rate equations (NASA TM-85685, 1983) for his PUMA-type arm.

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

Paths (``method``): ``"full"`` (default), eqs (34)-(36) for the arm and (49)-(51) for the
wrist; ``"reduced"``, eq. (39) + eq. (44) with the 2x2 M1 for the arm (eqs (40)-(43)
corrected), the same wrist. Both answer Barker's decoupled problem (the arm block first, then
the wrist with the arm's rotation removed, eq. (48)).

Singular neighbourhoods (the band). Each block has a measure ``s`` of its smallest singular
value: ``s^2 = det(M)^2 / ||adj M||_F^2 <= sigma_min(M)^2`` for M (equal to first order near
conditions (32), (33)), ``|det M1| / ||M1||_F`` for M1, and exactly
``s^2 = 1 - |C5| = S5^2 / (1 + |C5|)`` for the wrist's M2 (eq. (58)). With
``eps = band * L`` for the arm (``L = |ES| + hypot(SAL3 WE, A3)`` [m], the reach from joint 2
to the wrist centre) and ``eps = band`` for the wrist:

- outside the band (``s > eps``) the closed forms above answer, exactly;
- inside it (default, ``exact=False``) the block is solved by damped least squares
  ``(A^T A + lambda^2 I)^-1 A^T b`` with ``lambda^2 = eps^2 - s^2``: zero at the edge of the
  band, ``eps^2`` on the singular set. The rates are continuous in q across every
  singularity, and no block amplifies its command by more than ``1 / eps`` (Barker's
  "maximum angular rate penalty", text after eq. (51)); on the singular set the null
  direction gets no rate, as with the generalized inverses M*, M1*, M2*, and the other
  directions are damped by ``sigma^2 / (sigma^2 + eps^2)``;
- ``exact=True``: the exact inverse wherever ``s > rcond`` (times L for the arm), else the
  truncated pseudo-inverse (M* of eq. (38), M1* of eq. (44), M2* of eq. (60), singular
  values ``<= rcond`` dropped): finite, but as large as ``1 / s`` near a singularity.

``band = 0.01`` (default): the arm is damped where ``sigma_min(M) < 8.6 mm`` for the PUMA
values (2.8 % of random configurations within the limits), the wrist where
``|theta_5| < 0.81 deg`` (0.8 %); rates are at most 116 rad/m times ``|TVEL|`` and 100 times
``|RVEL~|``. Smaller bands are more exact near singularities and allow larger rates.

Singular set (Appendix D): ``det J = det M det W = ES (S2 ES + F5)(SAL3 WE S3 + A3 C3) S5``
(up to sign), for any R3 and alpha3: conditions (32), (33) and S5 = 0.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Literal, NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.closed_form._batch import blocks, cos_sin
from solvers.closed_form.base import Array, ClosedForm, Entry, first, row, stack_entries
from solvers.errors import InputError
from solvers.validation import as_array, as_vector, finite_number

Method = Literal["full", "reduced"]
METHODS: tuple[str, ...] = ("full", "reduced")
BLOCK = 8192
MIN_BAND = 1e-4
"""Smallest ``band``: the damped normal equations lose about ``eps / band^2`` relative."""


class BarkerGeometry(NamedTuple):
    """Barker's symbolic parameters (SI) and the constants derived from them.

    Attributes:
        no, es, sn, we, a3, r3, alpha3: The parameters of :class:`BarkerClosedForm` [m, rad].
        sal3: sin(alpha3).
        cal3: cos(alpha3).
        swe: SAL3 WE [m].
        f2: F2 = SN~ + CAL3 WE, SN~ = SN + R3 [m] (Barker eq. (28), with the tilde restored).
        reach: L = |ES| + hypot(SAL3 WE, A3) [m], the scale of the arm's band.
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

    @classmethod
    def from_parameters(
        cls, no: float, es: float, sn: float, we: float, a3: float, r3: float, alpha3: float
    ) -> BarkerGeometry:
        """Derive the constants from already validated parameters."""
        sal3, cal3 = math.sin(alpha3), math.cos(alpha3)
        swe = sal3 * we
        f2 = sn + r3 + cal3 * we
        reach = abs(es) + math.hypot(swe, a3)
        return cls(no, es, sn, we, a3, r3, alpha3, sal3, cal3, swe, f2, reach)


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


class BarkerSingularity(NamedTuple):
    """Values of Barker's singularity conditions at one configuration (floats) or N (arrays).

    Attributes:
        eq32: S2 ES + F5 = F1 [m]; zero on condition (32).
        eq33: SAL3 WE S3 + A3 C3 [m]; zero on condition (33).
        s5: sin(theta_5); zero on the wrist singularity.
        det_m: det M = ES eq32 eq33 [m^3] (eq. (D9)).
        arm_singular: Inside the arm's band (module docstring): the default path damps M.
        wrist_singular: Inside the wrist's band: the default path damps M2.
    """

    eq32: Entry
    eq33: Entry
    s5: Entry
    det_m: Entry
    arm_singular: Entry
    wrist_singular: Entry


# -- trigonometry --------------------------------------------------------------------------


def trig(q: Sequence[float]) -> Trig:
    """Trigonometric terms of one configuration ``q`` (6 floats) [rad], by :mod:`math`."""
    q1, q2, q3, q4, q5, q6 = q
    s, c = math.sin, math.cos
    return Trig(s(q1), c(q1), s(q2), c(q2), s(q3), c(q3), s(q2 + q3), c(q2 + q3),
                s(q4), c(q4), s(q5), c(q5), s(q6), c(q6))  # fmt: skip


def trig_batch(Q: Array, six: bool = False) -> Trig:
    """Trigonometric terms of ``Q`` (N, 6) [rad], (N,) each; theta_6 only with ``six``."""
    C, S = cos_sin(np.ascontiguousarray(Q.T[: 6 if six else 5]))
    s23 = S[1] * C[2] + C[1] * S[2]
    c23 = C[1] * C[2] - S[1] * S[2]
    sc6 = (S[5], C[5]) if six else (None, None)
    return Trig(S[0], C[0], S[1], C[1], S[2], C[2], s23, c23, S[3], C[3], S[4], C[4], *sc6)


# -- the equations (floats or arrays) ------------------------------------------------------


def f_terms(g: BarkerGeometry, t: Trig) -> FTerms:
    """F1..F7 of Barker eqs (27)-(31), (41) and (37); F2 with SN~ = SN + R3 (a float)."""
    f5 = t.s23 * g.swe + t.c23 * g.a3  # eq. (31)
    f4 = t.c23 * g.swe - t.s23 * g.a3  # eq. (30)
    f1 = t.s2 * g.es + f5  # eq. (27)
    f3 = t.c2 * g.es + f4  # eq. (29)
    f6 = t.s1 * f1 + t.c1 * g.f2  # eq. (41)
    f7 = t.c1 * f1 - t.s1 * g.f2  # eq. (37)
    return FTerms(f1, g.f2, f3, f4, f5, f6, f7)


def eq33(g: BarkerGeometry, t: Trig) -> Entry:
    """SAL3 WE S3 + A3 C3 [m]: zero on Barker's singularity (33) (Appendix D, eq. (D8))."""
    return g.swe * t.s3 + g.a3 * t.c3


def m_rows(t: Trig, F: FTerms) -> list[list[Entry]]:
    """Barker's M, eq. (26), by rows: TVEL^ = M (thetadot_1, thetadot_2, thetadot_3) [m]."""
    return [[-F.f6, t.c1 * F.f3, t.c1 * F.f4], [F.f7, t.s1 * F.f3, t.s1 * F.f4],
            [0.0, -F.f1, -F.f5]]  # fmt: skip


def det_adj2(g: BarkerGeometry, t: Trig, F: FTerms) -> tuple[Entry, Entry]:
    """Det M = ES F1 (SAL3 WE S3 + A3 C3) (eq. (D9)) [m^3] and ||adj M||_F^2 [m^4].

    Rows ``C1 row1 + S1 row2``, ``S1 row1 - C1 row2`` and row 3 of M are ``(-F2, F3, F4)``,
    ``(-F1, 0, 0)``, ``(0, -F1, -F5)`` (eqs (37), (41)); their cross products give
    ``||adj M||^2 = (ES e33)^2 + (F2 F5)^2 + F1^2 (F1^2 + F2^2 + F3^2 + F4^2 + F5^2)``.
    """
    e = g.es * eq33(g, t)
    f1s = F.f1 * F.f1
    adj2 = e * e + (g.f2 * F.f5) ** 2 + f1s * (f1s + g.f2 * g.f2 + F.f3 * F.f3 + F.f4 * F.f4
                                              + F.f5 * F.f5)  # fmt: skip
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
    thetadot_3) = F1 ta / F2 - tb``, ``ta = C1 TVEL(1) + S1 TVEL(2)``,
    ``tb = S1 TVEL(1) - C1 TVEL(2)``; the second row is eq. (25)'s third.
    """
    T1, T2, T3 = tvel
    ta = t.c1 * T1 + t.s1 * T2
    k = F.f1 / F.f2
    return [[k * F.f3, k * F.f4], [-F.f1, -F.f5]], [k * ta - (t.s1 * T1 - t.c1 * T2), T3], ta


def arm_from_m1(F: FTerms, th2: Entry, th3: Entry, ta: Entry) -> tuple[Entry, ...]:
    """thetadot_1 by Barker eq. (39), with thetadot_2, thetadot_3 of eq. (44)."""
    return (F.f3 * th2 + F.f4 * th3 - ta) / F.f2, th2, th3


def rvel_tilde(t: Trig, arm: Sequence[Entry], rvel: Sequence[Entry]) -> tuple[Entry, ...]:
    """RVEL~ = RVEL^ - z0 thetadot_1 - z1 thetadot_2 - z2 thetadot_3, Barker eq. (48) [rad/s]."""
    s = arm[1] + arm[2]
    return rvel[0] + t.s1 * s, rvel[1] - t.c1 * s, rvel[2] - arm[0]


def wrist_terms(g: BarkerGeometry, t: Trig, rt: Sequence[Entry]) -> tuple[Entry, Entry, Entry]:
    """thetadot_5 (eq. (49)) and the right-hand side (ga, gb) of M2 (eqs (58), (59)).

    ``M2 (thetadot_4, thetadot_6) = (ga, gb)`` with ``M2 = [[0, S5], [1, C5]]``, from D1..D5
    of eqs (52)-(56).

    In the orthonormal directions (C4 x3 + S4 y3, z4, z3) the wrist block reads (S5 thetadot_6,
    thetadot_5, thetadot_4 + C5 thetadot_6): thetadot_5 separates, M2 carries the rest.
    """
    d1 = t.c1 * rt[0] + t.s1 * rt[1]  # eq. (52)
    d2 = t.s1 * rt[0] - t.c1 * rt[1]  # eq. (53)
    d3 = t.s23 * d1 + t.c23 * rt[2]  # eq. (54)
    d4 = t.c23 * d1 - t.s23 * rt[2]  # eq. (55)
    d5 = g.cal3 * d3 + g.sal3 * d2  # eq. (56)
    th5 = -t.c4 * d5 - t.s4 * d4  # eq. (49)
    return th5, -t.s4 * d5 + t.c4 * d4, g.sal3 * d3 - g.cal3 * d2  # eq. (59) ("D6" is D5)


def wrist_regular(t: Trig, ga: Entry, gb: Entry) -> tuple[Entry, Entry]:
    """(thetadot_4, thetadot_6) by Barker eqs (51), (50)."""
    th6 = ga / t.s5  # eq. (50)
    return gb - t.c5 * th6, th6  # eq. (51)


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

    ``R2_1 R1_0`` (eqs (B25), (B26)) gives (TVEL)_X2 = S2 (C1 TVEL(1) + S1 TVEL(2)) + C2 TVEL(3),
    (TVEL)_Y2 = C2 (C1 TVEL(1) + S1 TVEL(2)) - S2 TVEL(3), (TVEL)_Z2 = C1 TVEL(2) - S1 TVEL(1).
    """
    ta = t.c1 * tvel[0] + t.s1 * tvel[1]
    return t.s2 * ta + t.c2 * tvel[2], t.c2 * ta - t.s2 * tvel[2], t.c1 * tvel[1] - t.s1 * tvel[0]


# -- generalized inverses in the band (arrays) ---------------------------------------------


def _det(N: list[list[Entry]]) -> Entry:
    """Determinant of a 2x2 or 3x3 matrix given by entries."""
    if len(N) == 2:
        return N[0][0] * N[1][1] - N[0][1] * N[1][0]
    return sum(N[0][j] * (N[1][(j + 1) % 3] * N[2][(j + 2) % 3]
                          - N[1][(j + 2) % 3] * N[2][(j + 1) % 3]) for j in range(3))  # fmt: skip


def band_solve(
    A: list[list[Entry]], b: Sequence[Entry], s2: Array, eps: float, exact: bool
) -> list[Array]:
    r"""Solve ``A x = b`` (2x2 or 3x3 blocks, entries (K,) arrays) inside a singular band.

    Default: damped least squares (Barker's generalized inverses, damped)

    .. math:: x = (A^T A + \lambda^2 I)^{-1} A^T b, \quad \lambda^2 = \epsilon^2 - s^2 > 0,

    by Cramer's rule (``A^T A + lambda^2 I`` has eigenvalues ``>= eps^2``). ``exact``: the
    truncated pseudo-inverse, singular values ``<= eps`` dropped (M*, M1*, M2*), by SVD.

    Args:
        A: Entries of the blocks, rows of floats or (K,) arrays.
        b: Right-hand sides, (K,) arrays.
        s2: Squared singular-value measures ``s^2 < eps^2``, (K,).
        eps: Band [units of A].
        exact: Truncate instead of damping.

    Returns:
        The solutions, one (K,) array per unknown.
    """
    n, k = len(A), s2.shape[0]
    if exact:
        stack = stack_entries(A, k)
        U, sv, Vt = np.linalg.svd(stack)
        w = np.einsum("kji,kj->ki", U, np.stack(np.broadcast_arrays(*b), axis=-1))
        w = np.where(sv > eps, w / np.where(sv > eps, sv, 1.0), 0.0)
        return list(np.einsum("kji,kj->ik", Vt, w))
    lam2 = eps * eps - s2
    N = [[sum(A[r][i] * A[r][j] for r in range(n)) + (lam2 if i == j else 0.0)
          for j in range(n)] for i in range(n)]  # fmt: skip
    h = [sum(A[r][i] * b[r] for r in range(n)) for i in range(n)]
    det = _det(N)
    cols = [[[h[r] if c == i else N[r][c] for c in range(n)] for r in range(n)] for i in range(n)]
    return [np.broadcast_to(_det(Ni) / det, (k,)) for Ni in cols]


def _at(value: Entry, idx: npt.NDArray[np.intp]) -> Entry:
    """``value[idx]`` for an array, ``value`` for a float (a constant entry)."""
    return value[idx] if isinstance(value, np.ndarray) else value


def _repair(
    out: Sequence[Array], A: list[list[Entry]], b: Sequence[Entry], s2: Array, eps: float,
    bad: npt.NDArray[np.bool_], exact: bool,
) -> None:  # fmt: skip
    """Overwrite ``out[i][bad]`` by :func:`band_solve` of the blocks at the rows ``bad``."""
    idx = np.flatnonzero(bad)
    if idx.size:
        A_bad = [[_at(v, idx) for v in r] for r in A]
        x = band_solve(A_bad, [_at(v, idx) for v in b], s2[idx], eps, exact)
        for o, xi in zip(out, x, strict=True):
            o[idx] = xi


# -- the closed form -----------------------------------------------------------------------


class BarkerClosedForm(ClosedForm):
    """Closed-form Jacobian and joint rates of Barker's arm, wrist centre as tool frame.

    Frames: :attr:`frame` is the generated URDF's ``"tool"`` frame, the wrist centre with the
    axes of frame 6. Twists ``[TVEL^; RVEL^]`` are ``world_aligned`` (wrist-centre velocity
    and angular velocity in base axes); operator commands in hand axes (``local``) go through
    :meth:`hand_twist_to_base` (eq. (20)).

    Args:
        no: Neck-to-base length NO = r1 [m].
        es: Elbow-to-shoulder length ES = a2 [m].
        sn: Shoulder-to-neck length SN = r2 [m].
        we: Wrist-to-elbow length WE = r4 [m].
        a3: Link length A3 = a3 [m].
        r3: Offset R3 = r3 [m].
        alpha3: Twist alpha3 [rad].
        rcond: Singular-value cutoff of the exact path, in [0, 0.5) (module docstring).
        band: Relative width of the damped singular neighbourhoods, in [1e-4, 0.5).

    Raises:
        InputError: A parameter is not a finite number, or ``rcond``, ``band`` out of range,
            naming it.
    """

    nq = 6
    task_dim = 6
    frame = "tool"

    def __init__(
        self, *, no: float, es: float, sn: float, we: float, a3: float, r3: float,
        alpha3: float, rcond: float = 1e-10, band: float = 1e-2,
    ) -> None:  # fmt: skip
        values = {"no": no, "es": es, "sn": sn, "we": we, "a3": a3, "r3": r3, "alpha3": alpha3}
        checked = {name: finite_number(value, name) for name, value in values.items()}
        self.rcond = finite_number(rcond, "rcond", 0.0, upper=0.5)
        self.band = finite_number(band, "band", MIN_BAND, upper=0.5)
        self.geometry = BarkerGeometry.from_parameters(**checked)
        scale = sum(abs(v) for k, v in checked.items() if k != "alpha3")
        self._has_reduced = abs(self.geometry.f2) > 1e-12 * scale  # eq. (39) divides by F2

    def __repr__(self) -> str:
        g = self.geometry
        return (
            f"BarkerClosedForm(no={g.no}, es={g.es}, sn={g.sn}, we={g.we}, a3={g.a3}, "
            f"r3={g.r3}, alpha3={g.alpha3}, rcond={self.rcond}, band={self.band})"
        )

    def _eps(self, exact: bool) -> tuple[float, float]:
        """Band of the arm [m] and of the wrist [1] (``rcond`` scaled for ``exact``)."""
        width = self.rcond if exact else self.band
        return width * self.geometry.reach, width

    # -- Jacobian, F terms, M ---------------------------------------------------------------

    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Wrist-centre Jacobian (6, 6) at ``q`` (6,) [rad], rows [v; w], base axes (eq. (22)).

        Raises:
            InputError: ``q`` is not a finite (6,) vector.
        """
        return np.array(jacobian_rows(self.geometry, trig(as_vector(q, "q", 6).tolist())))

    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """Wrist-centre Jacobians (N, 6, 6) at ``Q`` (N, 6) [rad], rows [v; w], base axes.

        Raises:
            InputError: ``Q`` is not a finite (N, 6) array.
        """
        Q = as_array(Q, "Q", (None, 6))
        return stack_entries(jacobian_rows(self.geometry, trig_batch(Q)), Q.shape[0])

    def f_terms(self, q: npt.ArrayLike) -> FTerms:
        """F1..F7 (eqs (27)-(31), (41), (37)) [m] at ``q`` (6,), as floats."""
        return FTerms(*(float(v[0]) for v in self.f_terms_batch(row(q, "q", 6))))

    def f_terms_batch(self, Q: npt.ArrayLike) -> FTerms:
        """F1..F7 [m] at ``Q`` (N, 6), each (N,)."""
        Q = as_array(Q, "Q", (None, 6))
        F = f_terms(self.geometry, trig_batch(Q))
        return F._replace(f2=np.full(Q.shape[0], F.f2))

    def m_matrix(self, q: npt.ArrayLike) -> Array:
        """Barker's M (3, 3) [m], eq. (26): ``TVEL^ = M thetadot_123``."""
        return first(self.m_matrix_batch(row(q, "q", 6)))

    def m_matrix_batch(self, Q: npt.ArrayLike) -> Array:
        """Barker's M at ``Q`` (N, 6): (N, 3, 3) [m]."""
        Q = as_array(Q, "Q", (None, 6))
        t = trig_batch(Q)
        return stack_entries(m_rows(t, f_terms(self.geometry, t)), Q.shape[0])

    def det_m(self, q: npt.ArrayLike) -> float:
        """Determinant of M [m^3] in the factored form of eq. (D9)."""
        return float(self.det_m_batch(row(q, "q", 6))[0])

    def det_m_batch(self, Q: npt.ArrayLike) -> Array:
        """Determinant of M (eq. (D9)) at ``Q`` (N, 6): (N,) [m^3]."""
        return np.asarray(self.singularity_batch(Q).det_m)

    def singularity(self, q: npt.ArrayLike) -> BarkerSingularity:
        """Values of conditions (32), (33) and S5 at ``q`` (6,), as Python scalars."""
        s = self.singularity_batch(row(q, "q", 6))
        return BarkerSingularity(*(v[0].item() for v in s))

    def singularity_batch(self, Q: npt.ArrayLike) -> BarkerSingularity:
        """Values of conditions (32), (33) and S5 at ``Q`` (N, 6), each (N,); band flags."""
        Q = as_array(Q, "Q", (None, 6))
        g, t = self.geometry, trig_batch(Q)
        F = f_terms(g, t)
        det, adj2 = det_adj2(g, t, F)
        eps_arm, eps_wrist = self._eps(exact=False)
        return BarkerSingularity(
            eq32=F.f1, eq33=eq33(g, t), s5=t.s5, det_m=det,
            arm_singular=det * det <= eps_arm**2 * adj2,
            wrist_singular=t.s5 * t.s5 <= eps_wrist**2 * (1.0 + np.abs(t.c5)),
        )  # fmt: skip

    # -- joint rates ------------------------------------------------------------------------

    def _arm(
        self, t: Trig, tvel: Sequence[Array], reduced: bool, exact: bool, repair: bool = True
    ) -> tuple[list[Array], npt.NDArray[np.bool_]]:
        """thetadot_1..3 (N,) each by the closed form, and the rows in the arm's band.

        With ``repair`` the rows in the band are solved by :func:`band_solve` (eq. (38) or
        eq. (44), damped or exact); without, their rates are meaningless (inf or NaN).
        """
        g = self.geometry
        F = f_terms(g, t)
        eps = self._eps(exact)[0]
        if reduced:  # eqs (39), (44)
            A, b, ta = m1_system(t, F, tvel)
            det = _det(A)
            fro2 = sum(v * v for r in A for v in r)
            th23 = [(A[1][1] * b[0] - A[0][1] * b[1]) / det,
                    (A[0][0] * b[1] - A[1][0] * b[0]) / det]  # fmt: skip
            bad = det * det <= eps * eps * fro2
            if repair:
                _repair(th23, A, b, det * det / np.where(fro2 > 0.0, fro2, 1.0), eps, bad, exact)
            return list(arm_from_m1(F, th23[0], th23[1], ta)), bad
        det, adj2 = det_adj2(g, t, F)
        out = list(arm_full(t, F, det, tvel))
        bad = det * det <= eps * eps * adj2
        if repair:
            s2 = det * det / np.where(adj2 > 0.0, adj2, 1.0)
            _repair(out, m_rows(t, F), tvel, s2, eps, bad, exact)  # eq. (38)
        return out, bad

    def _wrist(
        self, t: Trig, rt: Sequence[Array], exact: bool, repair: bool = True
    ) -> tuple[list[Array], npt.NDArray[np.bool_]]:
        """thetadot_4..6 (N,) each from RVEL~ by eqs (49)-(51), and the rows in the band.

        With ``repair`` those rows are solved by :func:`band_solve` on M2 (eq. (60)).
        """
        th5, ga, gb = wrist_terms(self.geometry, t, rt)
        th46 = list(wrist_regular(t, ga, gb))
        eps = self._eps(exact)[1]
        s2 = t.s5 * t.s5 / (1.0 + np.abs(t.c5))  # 1 - |C5|, without cancellation
        bad = s2 <= eps * eps
        if repair:
            _repair(th46, [[0.0, t.s5], [1.0, t.c5]], (ga, gb), s2, eps, bad, exact)
        return [th46[0], th5, th46[1]], bad

    def _rates(self, Q: Array, X: Array, reduced: bool, exact: bool, repair: bool) -> tuple[
        list[Array], npt.NDArray[np.bool_]
    ]:
        """Joint rates (N,) each at ``Q``, ``X`` (N, 6): arm, eq. (48), wrist; band rows."""
        t, x = trig_batch(Q), list(np.ascontiguousarray(X.T))
        arm, arm_bad = self._arm(t, x[:3], reduced, exact, repair)
        wrist, wrist_bad = self._wrist(t, rvel_tilde(t, arm, x[3:]), exact, repair)
        return arm + wrist, arm_bad | wrist_bad

    def arm_rates(
        self, q: npt.ArrayLike, tvel: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """thetadot_1..3 (3,) [rad/s] realising the wrist-centre velocity ``tvel`` (3,) [m/s].

        ``method="full"``: eqs (34)-(36); ``"reduced"``: eqs (39), (44). ``tvel`` is TVEL^ in
        base axes. In the arm's band: damped, or M* / M1* with ``exact`` (module docstring).

        Raises:
            InputError: Bad ``q``, ``tvel`` or ``method``.
        """
        return first(self.arm_rates_batch(row(q, "q", 6), row(tvel, "tvel", 3), method, exact))

    def arm_rates_batch(
        self, Q: npt.ArrayLike, TVEL: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """Batch :meth:`arm_rates`: ``Q`` (N, 6), ``TVEL`` (N, 3) -> (N, 3) [rad/s]."""
        reduced = self._reduced(method)
        Q = as_array(Q, "Q", (None, 6))
        T = as_array(TVEL, "TVEL", (Q.shape[0], 3))
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.stack(self._arm(trig_batch(Q), list(T.T), reduced, exact)[0], axis=1)

    def rvel_tilde(self, q: npt.ArrayLike, arm_rates: npt.ArrayLike, rvel: npt.ArrayLike) -> Array:
        """RVEL~ = RVEL^ - z0 thetadot_1 - z1 thetadot_2 - z2 thetadot_3 (eq. (48)), (3,)."""
        return first(self.rvel_tilde_batch(
            row(q, "q", 6), row(arm_rates, "arm_rates", 3), row(rvel, "rvel", 3)
        ))

    def rvel_tilde_batch(
        self, Q: npt.ArrayLike, ARM: npt.ArrayLike, RVEL: npt.ArrayLike
    ) -> Array:
        """Batch :meth:`rvel_tilde`: ``Q`` (N, 6), ``ARM``, ``RVEL`` (N, 3) -> (N, 3) [rad/s]."""
        Q = as_array(Q, "Q", (None, 6))
        A = as_array(ARM, "ARM", (Q.shape[0], 3))
        R = as_array(RVEL, "RVEL", (Q.shape[0], 3))
        return np.stack(rvel_tilde(trig_batch(Q), list(A.T), list(R.T)), axis=1)

    def wrist_rates(
        self, q: npt.ArrayLike, rvel_tilde: npt.ArrayLike, method: Method = "full",
        exact: bool = False,
    ) -> Array:  # fmt: skip
        """thetadot_4..6 (3,) [rad/s] from RVEL~ (eq. (48)) (3,) [rad/s], base axes.

        Eqs (49)-(51) for both methods; in the wrist's band damped, or M2* (eq. (60)) with
        ``exact`` (``pinv(W, rcond) @ rvel_tilde``).

        Raises:
            InputError: Bad ``q``, ``rvel_tilde`` or ``method``.
        """
        return first(self.wrist_rates_batch(
            row(q, "q", 6), row(rvel_tilde, "rvel_tilde", 3), method, exact
        ))

    def wrist_rates_batch(
        self, Q: npt.ArrayLike, RVEL_TILDE: npt.ArrayLike, method: Method = "full",
        exact: bool = False,
    ) -> Array:  # fmt: skip
        """Batch :meth:`wrist_rates`: ``Q`` (N, 6), ``RVEL_TILDE`` (N, 3) -> (N, 3) [rad/s]."""
        self._reduced(method)
        Q = as_array(Q, "Q", (None, 6))
        R = as_array(RVEL_TILDE, "RVEL_TILDE", (Q.shape[0], 3))
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.stack(self._wrist(trig_batch(Q), list(R.T), exact)[0], axis=1)

    def joint_rates(
        self, q: npt.ArrayLike, xdot: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """Joint rates (6,) [rad/s] realising the twist ``xdot = [TVEL^; RVEL^]`` (6,) at ``q``.

        Args:
            q: Joint positions (6,) [rad], Barker's theta_i.
            xdot: Wrist-centre velocity [m/s] and angular velocity [rad/s], base axes
                (``world_aligned``).
            method: ``"full"`` (eqs (34)-(36), (49)-(51)) or ``"reduced"`` (eqs (39), (44),
                (49)-(51)); see the module docstring.
            exact: In the singular bands, the exact inverse (truncated at ``rcond``) instead
                of the damped one.

        Returns:
            thetadot (6,): exact outside the bands; continuous in ``q`` and at most
            ``1 / band`` times the command inside them (``exact``: finite, never NaN).

        Raises:
            InputError: Bad ``q``, ``xdot`` or ``method``.
        """
        reduced = self._reduced(method)
        qv, xv = as_vector(q, "q", 6), as_vector(xdot, "xdot", 6)
        # One configuration on Python floats: 3.5 us against 60 us for the batch path on one
        # row (measured); that one answers in the bands and for the reduced method.
        g, t = self.geometry, trig(qv.tolist())
        F = f_terms(g, t)
        det, adj2 = det_adj2(g, t, F)
        eps_arm, eps_wrist = self._eps(exact)
        if (
            reduced
            or det * det <= eps_arm * eps_arm * adj2
            or t.s5 * t.s5 <= eps_wrist * eps_wrist * (1.0 + abs(t.c5))
        ):
            return first(self.joint_rates_batch(qv[None], xv[None], method, exact))
        x = xv.tolist()
        arm = arm_full(t, F, det, x[:3])
        th5, ga, gb = wrist_terms(g, t, rvel_tilde(t, arm, x[3:]))
        th4, th6 = wrist_regular(t, ga, gb)
        return np.array([*arm, th4, th5, th6])

    def joint_rates_batch(
        self, Q: npt.ArrayLike, X: npt.ArrayLike, method: Method = "full", exact: bool = False
    ) -> Array:
        """Batch :meth:`joint_rates`: ``Q`` (N, 6), ``X`` (N, 6) -> (N, 6) [rad/s].

        Raises:
            InputError: Bad ``Q``, ``X`` or ``method``.
        """
        reduced = self._reduced(method)
        Q, X = self._check_batch(Q, X)
        out = np.empty((Q.shape[0], 6))
        bad = np.empty(Q.shape[0], dtype=bool)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for rows in blocks(Q.shape[0], BLOCK):
                rates, bad[rows] = self._rates(Q[rows], X[rows], reduced, exact, repair=False)
                for j, v in enumerate(rates):
                    out[rows, j] = v
            idx = np.flatnonzero(bad)  # in a band: solved again, all at once
            if idx.size:
                rates = self._rates(Q[idx], X[idx], reduced, exact, repair=True)[0]
                out[idx] = np.stack(rates, axis=1)
        return out

    # -- hand frame (Appendix B) ------------------------------------------------------------

    def hand_to_base(self, q: npt.ArrayLike) -> Array:
        """R0_6 (3, 3) by eqs (B2)-(B24): hand (frame 6) axes in base axes."""
        return first(self.hand_to_base_batch(row(q, "q", 6)))

    def hand_to_base_batch(self, Q: npt.ArrayLike) -> Array:
        """R0_6 at ``Q`` (N, 6): (N, 3, 3)."""
        Q = as_array(Q, "Q", (None, 6))
        return stack_entries(hand_to_base_rows(self.geometry, trig_batch(Q, six=True)), len(Q))

    def hand_twist_to_base(self, q: npt.ArrayLike, twist: npt.ArrayLike) -> Array:
        """Operator command ``[TVEL; RVEL]`` (6,) in hand axes -> base axes, eq. (20)."""
        return first(self.hand_twist_to_base_batch(row(q, "q", 6), row(twist, "twist", 6)))

    def hand_twist_to_base_batch(self, Q: npt.ArrayLike, TWIST: npt.ArrayLike) -> Array:
        """Batch :meth:`hand_twist_to_base`: ``Q`` (N, 6), ``TWIST`` (N, 6) -> (N, 6)."""
        Q = as_array(Q, "Q", (None, 6))
        T = as_array(TWIST, "TWIST", (Q.shape[0], 6)).reshape(-1, 2, 3)
        out: Array = np.einsum("nij,nkj->nki", self.hand_to_base_batch(Q), T).reshape(-1, 6)
        return out

    def tvel_frame2(self, q: npt.ArrayLike, tvel: npt.ArrayLike) -> Array:
        """TVEL^ (3,) [m/s] resolved along X2, Y2, Z2 (eqs (B27)-(B29) corrected), (3,)."""
        return first(self.tvel_frame2_batch(row(q, "q", 6), row(tvel, "tvel", 3)))

    def tvel_frame2_batch(self, Q: npt.ArrayLike, TVEL: npt.ArrayLike) -> Array:
        """Batch :meth:`tvel_frame2`: ``Q`` (N, 6), ``TVEL`` (N, 3) -> (N, 3) [m/s]."""
        Q = as_array(Q, "Q", (None, 6))
        T = as_array(TVEL, "TVEL", (Q.shape[0], 3))
        return np.stack(tvel_frame2(trig_batch(Q), list(T.T)), axis=1)

    def _reduced(self, method: str) -> bool:
        if method == "full":
            return False
        if method != "reduced":
            raise InputError("method", f"expected one of {', '.join(METHODS)}, got {method!r}")
        if not self._has_reduced:
            raise InputError(
                "method", "the reduced path divides by F2 = SN + R3 + cos(alpha3) WE = 0"
            )
        return True
