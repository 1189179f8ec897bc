r"""Rates against the step's bounds: finite, inside the box and the rows, or brought into them.

The box is ``lb <= x <= ub`` (the step's joint box), the rows ``G x <= h`` (the limits'
constraint rows); a level's QP bounds are widened around its start (:func:`around_start`).
Each kernel is compiled by numba (``@njit(cache=True)``, through
:func:`~rrc_pin.solvers.compiled.kernel`) and runs as plain Python under
``NUMBA_DISABLE_JIT=1``; tests/test_feasibility.py compares each with plain numpy.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]

@kernel
def all_finite(x: Array) -> bool:
    """Whether every entry of ``x`` (n,) is finite (no NaN or infinity)."""
    for i in range(x.size):
        if not math.isfinite(x[i]):
            return False
    return True


@kernel
def inside(x: Array, lb: Array, ub: Array) -> bool:
    """Whether ``lb <= x <= ub`` holds exactly (False for NaN)."""
    for i in range(x.size):
        if not lb[i] <= x[i] <= ub[i]:
            return False
    return True


@kernel
def clip_into(x: Array, lb: Array, ub: Array) -> float:
    """``x`` clipped into ``[lb, ub]`` in place; returns the Euclidean size of the change."""
    s = 0.0
    for i in range(x.size):
        y = min(max(x[i], lb[i]), ub[i])
        s += (y - x[i]) * (y - x[i])
        x[i] = y
    return math.sqrt(s)


@kernel
def rows_hold(G: Array, x: Array, h: Array, tol: float) -> bool:
    """Whether ``G x <= h + tol`` holds (False for NaN)."""
    p, n = G.shape
    for i in range(p):
        s = 0.0
        for j in range(n):
            s += G[i, j] * x[j]
        if not s <= h[i] + tol:
            return False
    return True


@kernel
def into_rows(G: Array, h: Array, x: Array) -> float:
    """The factor in [0, 1] that brings rates ``x`` (n,) within the rows ``G x <= h`` (p, n)
    when they are scaled by it (1: they hold). Standing still must meet the rows (``h >= 0``).

    A row counts as left only where ``G x`` exceeds ``h`` by more than the rounding of the
    sum, n eps sum_j |G_ij x_j| (Higham 2002, eq. 3.5): a row held at ``h = 0`` and met to
    rounding (1e-17 over) would otherwise have the whole answer scaled to zero.
    """  # noqa: D205
    p, n = G.shape
    factor = 1.0
    for i in range(p):
        value, size = 0.0, 0.0
        for j in range(n):
            value += G[i, j] * x[j]
            size += abs(G[i, j] * x[j])
        if value - h[i] > n * EPS * size:
            factor = min(factor, h[i] / value)
    return factor if factor == 1.0 else factor * (1.0 - 4.0 * EPS)


EPS = 2.220446049250313e-16
"""Machine epsilon of float64."""


@kernel
def around_start(lo: Array, hi: Array, tol: float, rounding: float) -> None:
    """The bounds ``lo <= C z <= hi`` of a level's QP in a subspace, ``z = 0`` its start (the
    rates so far), widened in place: each that the start breaks by at most ``tol`` (the
    backend's tolerance, within which the levels above were answered) to the start, and every
    one by ``rounding``.

    A bound the start breaks by more is kept: that start is no answer the level may stay at
    (a top level's least-norm rates of the equality rows where a row asks a pair apart, or
    they leave the box), and the level restores it or fails.
    """  # noqa: D205
    for i in range(lo.size):
        if lo[i] <= tol:
            lo[i] = min(lo[i], 0.0)
        if hi[i] >= -tol:
            hi[i] = max(hi[i], 0.0)
        lo[i] -= rounding
        hi[i] += rounding


UNMOVED = 16.0 * EPS
"""Relative size at or below which a row's coefficients in a level's subspace are rounding
(:func:`release_unmoved`)."""


@kernel
def release_unmoved(C: Array, G: Array, lo: Array, hi: Array) -> None:
    """Drop, in place (both sides made infinite), the rows ``lo <= C z <= hi`` of a level's QP
    in a subspace, ``z = 0`` its start, that the start meets and whose coefficients are at most
    :data:`UNMOVED` of their own row's size: the joint box (C's first n rows, of unit size)
    then the rows ``G`` (p, n) (C's last p).

    The levels above hold such a row (a joint they keep at its bound, a row in the span of
    their tasks): its coefficients in the subspace are the rounding of its null space's basis,
    in no direction of the level's. Kept, the margin of 1e-12 an answer is sought inside its
    rows by makes it a bound of z (1e-24 over 1e-16: a plane through the start, in a direction
    of rounding), and the level's projection stays at its start. Dropped, the answer moves it
    by rounding.
    """  # noqa: D205
    p = G.shape[0]
    n = C.shape[0] - p
    for i in range(C.shape[0]):
        if not lo[i] <= 0.0 <= hi[i]:
            continue
        size = 1.0
        if i >= n:
            size = 0.0
            for j in range(G.shape[1]):
                size += G[i - n, j] * G[i - n, j]
            size = math.sqrt(size)
        coefficients = 0.0
        for j in range(C.shape[1]):
            coefficients += C[i, j] * C[i, j]
        if math.sqrt(coefficients) <= UNMOVED * size:
            lo[i], hi[i] = -math.inf, math.inf
