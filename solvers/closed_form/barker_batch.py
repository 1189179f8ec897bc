"""Blocked evaluation of Barker's default joint rates for large batches (NASA TM-85685).

:func:`joint_rates_full` is ``BarkerClosedForm.joint_rates_batch`` with ``method="full"`` at
regular configurations: eqs (34)-(36) for the arm, eq. (48) and eqs (52)-(56), (49)-(51) for
the wrist, evaluated block by block (:data:`~solvers.closed_form._batch.CHUNK`
configurations) into preallocated buffers with in-place ufuncs, the trigonometry by
:func:`~solvers.closed_form._batch.cos_sin`. Configurations that may be singular are only
flagged, by a screen cheaper than the exact tests of
:func:`~solvers.closed_form.barker_kernels.arm_rates_full` and
:func:`~solvers.closed_form.barker_kernels.wrist_rates`, and left to the caller, which
recomputes those few rows with the general kernels (generalized inverses included).

Two identities save work without changing the result beyond rounding: with
``ta = C1 TVEL(1) + S1 TVEL(2)`` and ``tb = S1 TVEL(1) - C1 TVEL(2)``,
``TVEL(1) F7 + TVEL(2) F6 = F1 ta - F2 tb`` (eqs (37), (41)); and in eqs (52)-(53) the joint-2
and joint-3 terms of RVEL~ (eq. (48)) cancel from D1 and add to D2 with unit weight:
``D1 = C1 RVEL(1) + S1 RVEL(2)``, ``D2 = S1 RVEL(1) - C1 RVEL(2) + thetadot_2 + thetadot_3``.
"""

from __future__ import annotations

from math import hypot, sqrt

import numpy as np
import numpy.typing as npt

from solvers.closed_form._batch import CHUNK, blocks, cos_sin
from solvers.closed_form.barker_scalar import Consts

Array = npt.NDArray[np.float64]
_SCRATCH = 21  # rows of the block workspace: the named intermediates below


def screen_bounds(k: Consts, rcond: float) -> tuple[float, float]:
    """Thresholds ``(det_min, s5_min)`` above which a configuration is surely regular.

    The exact tests are ``|det M| > rcond ||M||_F^3`` and ``|S5| > rcond (1 + |C5|)``. With
    ``R = hypot(SAL3 WE, A3)``, (F5, F4) is (A3, SAL3 WE) turned by theta_2 + theta_3, so
    ``F4^2 + F5^2 = R^2``, ``F1^2 + F3^2 = |ES (S2, C2) + (F5, F4)|^2 <= (|ES| + R)^2`` and
    ``F1^2 <= (|ES| + R)^2``: ``||M||_F^2 = 2 F1^2 + F2^2 + F3^2 + F4^2 + F5^2 <=
    2 (|ES| + R)^2 + F2^2 + R^2``; and ``1 + |C5| <= 2``. Passing both screens implies both
    exact tests (a margin of 1e-12 covers rounding).
    """
    es, swe, a3, f2 = k[0], k[1], k[2], k[3]
    r = hypot(swe, a3)
    fro2 = (2.0 * (abs(es) + r) ** 2 + f2 * f2 + r * r) * (1.0 + 1e-12)
    return rcond * fro2 * sqrt(fro2), 2.0 * rcond


def joint_rates_full(
    k: Consts, Q: Array, X: Array, rcond: float, chunk: int = CHUNK
) -> tuple[Array, Array]:
    """Joint rates by eqs (34)-(36), (48), (52)-(56), (49)-(51), block by block.

    Args:
        k: Constants ``(ES, SAL3 WE, A3, F2, SAL3, CAL3)`` of
            :func:`~solvers.closed_form.barker_scalar.constants`.
        Q: Joint positions (N, 6) [rad], finite (validated by the caller).
        X: Twists ``[TVEL^; RVEL^]`` (N, 6), base axes, finite.
        rcond: Relative singular-value cutoff of the caller.
        chunk: Configurations per block.

    Returns:
        ``(rates, suspect)``: rates (N, 6) [rad/s], exact at every configuration not in
        ``suspect``; ``suspect`` the sorted indices (int array) that fail
        :func:`screen_bounds`, where the rates are meaningless (possibly inf or NaN) and
        must be recomputed.
    """
    es, swe, a3, f2, sal3, cal3 = k
    det_min, s5_min = screen_bounds(k, rcond)
    n = Q.shape[0]
    out = np.empty((n, 6))
    m = max(min(n, chunk), 1)
    qbuf, cbuf, sbuf = np.empty(5 * m), np.empty(5 * m), np.empty(5 * m)
    xbuf, obuf = np.empty(6 * m), np.empty(6 * m)
    work = np.empty((_SCRATCH, m))
    mul, add, sub = np.multiply, np.add, np.subtract
    suspect: list[Array] = []
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for rows in blocks(n, m):
            b = rows.stop - rows.start
            qt = qbuf[: 5 * b].reshape(5, b)
            np.copyto(qt, Q[rows, :5].T)
            c, s = cos_sin(qt, (cbuf[: 5 * b].reshape(5, b), sbuf[: 5 * b].reshape(5, b)), 5 * m)
            xt = xbuf[: 6 * b].reshape(6, b)
            np.copyto(xt, X[rows].T)
            o = obuf[: 6 * b].reshape(6, b)
            (s1, s2, s3, s4, s5), (c1, c2, c3, c4, c5) = s, c
            T1, T2, T3, W1, W2, W3 = xt
            t1, t2, t3, th4, th5, th6 = o
            (s23, c23, f1, f3, f4, f5, det, tmp, tmp2, ta, tb, u, inv, f14, sm, d1, d2, w3, d3,
             d4, d5) = work[:, :b]  # fmt: skip
            mul(s2, c3, out=s23)
            s23 += mul(c2, s3, out=tmp)  # S23
            mul(c2, c3, out=c23)
            c23 -= mul(s2, s3, out=tmp)  # C23
            mul(s23, swe, out=f5)
            f5 += mul(c23, a3, out=tmp)  # eq. (31)
            mul(c23, swe, out=f4)
            f4 -= mul(s23, a3, out=tmp)  # eq. (30)
            add(mul(s2, es, out=f1), f5, out=f1)  # eq. (27)
            add(mul(c2, es, out=f3), f4, out=f3)  # eq. (29)
            mul(s3, swe * es, out=det)
            det += mul(c3, a3 * es, out=tmp)
            det *= f1  # det M = F1 (SAL3 WE S3 + A3 C3) ES, eq. (D9)
            low_det = np.abs(det, out=tmp).min() <= det_min
            if low_det or np.abs(s5, out=tmp2).min() <= s5_min:
                flagged = (np.abs(det, out=tmp) <= det_min) | (np.abs(s5, out=tmp2) <= s5_min)
                suspect.append(rows.start + np.flatnonzero(flagged))
            # Arm, eqs (34)-(36) (signs of (35), (36) corrected).
            mul(c1, T1, out=ta)
            ta += mul(s1, T2, out=tmp)
            mul(s1, T1, out=tb)
            tb -= mul(c1, T2, out=tmp)
            mul(f1, ta, out=u)
            u -= mul(tb, f2, out=tmp)  # TVEL(1) F7 + TVEL(2) F6
            np.divide(1.0, det, out=inv)
            mul(f1, f4, out=f14)
            sub(f14, mul(f3, f5, out=tmp), out=t1)
            t1 *= tb
            t1 *= inv  # eq. (34)
            mul(f5, u, out=t2)
            t2 += mul(T3, f14, out=tmp)
            t2 *= inv  # eq. (35)
            mul(T3, f3, out=t3)
            t3 += u
            t3 *= f1
            np.negative(mul(t3, inv, out=t3), out=t3)  # eq. (36)
            # Wrist: RVEL~ (eq. (48)) folded into D1..D5 (eqs (52)-(56)), then (49)-(51).
            add(t2, t3, out=sm)
            mul(c1, W1, out=d1)
            d1 += mul(s1, W2, out=tmp)
            mul(s1, W1, out=d2)
            d2 -= mul(c1, W2, out=tmp)
            d2 += sm
            sub(W3, t1, out=w3)
            mul(s23, d1, out=d3)
            d3 += mul(c23, w3, out=tmp)
            mul(c23, d1, out=d4)
            d4 -= mul(s23, w3, out=tmp)
            mul(d3, cal3, out=d5)
            d5 += mul(d2, sal3, out=tmp)
            mul(c4, d5, out=th5)
            th5 += mul(s4, d4, out=tmp)
            np.negative(th5, out=th5)  # eq. (49)
            mul(c4, d4, out=th6)
            th6 -= mul(s4, d5, out=tmp)
            th6 /= s5  # eq. (50)
            mul(d3, sal3, out=th4)
            th4 -= mul(d2, cal3, out=tmp)
            th4 -= mul(c5, th6, out=tmp)  # eq. (51)
            block = out[rows]
            for j in range(6):  # column by column: faster than one transposing copy
                block[:, j] = o[j]
    empty = np.empty(0, dtype=np.intp)
    return out, np.concatenate(suspect) if suspect else empty
