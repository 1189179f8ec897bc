r"""The compiled kernels of a control tick: small functions, each one equation or one step.

Every function here is compiled by numba (``@njit(cache=True)``, through :func:`kernel`, which
only keeps the signature visible to mypy) and written as the textbook writes the math, in loops
where those read clearer than vector tricks. Arrays come in, arrays go out (preallocated by the
caller where a tick calls the kernel); nothing here allocates Python objects. The same source
runs as plain Python under ``NUMBA_DISABLE_JIT=1`` (one CI stage does), and tests/test_kernels.py
compares each kernel with a plain numpy reference.

The first call of a kernel in a fresh checkout compiles it (about 5 s for all of them, once:
numba caches the machine code in ``__pycache__``); later processes load it in milliseconds.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.tick.feasibility import inside
from rrc_pin.solvers.tick.linalg import householder_qr, least_norm_rates, max_abs

Array = npt.NDArray[np.float64]


@kernel
def uniform_scale(x: Array, lb: Array, ub: Array) -> float:
    """Largest s in [0, 1] with ``lb <= s x <= ub``, for bounds with ``lb <= 0 <= ub``."""
    s = 1.0
    for i in range(x.size):
        if x[i] > 0.0:
            s = min(s, ub[i] / x[i])
        elif x[i] < 0.0:
            s = min(s, lb[i] / x[i])
    return max(s, 0.0)


NULL_ROUNDING = 1e-12
"""[relative to its largest entry] A component of a null direction this small is the SVD's
rounding (a joint that no row moves): the row it belongs to does not bound the null
coefficient y (:func:`line_scale`; its bound there would be its slack's rounding over the
component's, anywhere in the box)."""


@kernel
def line_scale(w: Array, v: Array, lb: Array, ub: Array) -> tuple[float, float]:
    r"""The largest u in [0, 1] with ``lb <= u w + y v <= ub`` for some y, and that y nearest 0.

    Each row gives two half-planes :math:`\alpha u + \beta y \le \gamma` (:math:`\gamma \ge
    0`); eliminating y between each pair bounding it from opposite sides (Fourier-Motzkin
    elimination, Dantzig & Eaves 1973) leaves bounds on u alone. The direction problem of
    one null direction v, exactly. A component of v within :data:`NULL_ROUNDING` of its
    largest is taken as zero: its row bounds u alone, and is met by the rates to that
    component times ``|y|`` (the caller's clip).

    Args:
        w: Rates of the command (n,).
        v: Null-space direction (n,).
        lb: Lower bounds (n,) <= 0.
        ub: Upper bounds (n,) >= 0.

    Returns:
        u and y: the rates are ``u w + y v``.
    """
    n = w.size
    c = np.empty(n)  # v without its rounding
    rounding = NULL_ROUNDING * max_abs(v)
    for i in range(n):
        c[i] = v[i] if abs(v[i]) > rounding else 0.0
    u = 1.0
    for i in range(n):  # rows without y bound u alone
        if c[i] == 0.0:
            if w[i] > 0.0:
                u = min(u, ub[i] / w[i])
            elif w[i] < 0.0:
                u = min(u, lb[i] / w[i])
    # half-plane (a, b, g) of row i bounding y from above: b > 0 (the row's side where v > 0)
    for i in range(n):
        if c[i] == 0.0:
            continue
        a1, b1, g1 = (w[i], c[i], ub[i]) if c[i] > 0.0 else (-w[i], -c[i], -lb[i])
        for j in range(n):
            if c[j] == 0.0:
                continue
            a2, b2, g2 = (-w[j], -c[j], -lb[j]) if c[j] > 0.0 else (w[j], c[j], ub[j])
            coefficient = b1 * a2 - b2 * a1  # -b2 (plane 1) + b1 (plane 2): y eliminated
            if coefficient > 0.0 and b1 * g2 - b2 * g1 < u * coefficient:
                u = (b1 * g2 - b2 * g1) / coefficient
    u = max(u, 0.0)
    y_hi, v_hi, y_lo, v_lo = math.inf, 1.0, -math.inf, 1.0
    for i in range(n):
        if c[i] == 0.0:
            continue
        a1, b1, g1 = (w[i], c[i], ub[i]) if c[i] > 0.0 else (-w[i], -c[i], -lb[i])
        if (g1 - a1 * u) / b1 < y_hi:
            y_hi, v_hi = (g1 - a1 * u) / b1, b1
        a2, b2, g2 = (-w[i], -c[i], -lb[i]) if c[i] > 0.0 else (w[i], c[i], ub[i])
        if (g2 - a2 * u) / b2 > y_lo:
            y_lo, v_lo = (g2 - a2 * u) / b2, -b2
    if y_lo <= y_hi:
        return u, min(max(0.0, y_lo), y_hi)
    # rounding at a vertex: the y that leaves both rows by the same rate (a row with a
    # null component of rounding size, 1e-15, pins u; its y bound is off by up to 0.1)
    return u, (v_lo * y_lo + v_hi * y_hi) / (v_lo + v_hi)


@kernel
def direction_step(
    J: Array, b: Array, lb: Array, ub: Array, Q: Array, R: Array, w: Array, qdot: Array
) -> tuple[int, float]:
    r"""The top level's step within a box: its exact rates, whether they fit, else their scale.

    :func:`householder_qr` of :math:`J^T`, the least-norm rates w of :math:`Jx = b`
    (:func:`least_norm_rates`), :func:`inside`; where w leaves the box and the null space of J
    has at most one direction (:math:`Q_{:,m}`, a 7-joint arm's six rows), the direction
    problem's exact answer :math:`u\,w + y\,Q_{:,m}` (:func:`uniform_scale`,
    :func:`line_scale`); one call for what most ticks need (:mod:`rrc_pin.solvers.tick.direction`).

    Args:
        J: Rows (m, n).
        b: Their rates (m,).
        lb: Lower bounds (n,) (containing zero where the scale is asked for).
        ub: Upper bounds (n,).
        Q: Out: orthogonal factor (n, n).
        R: Out: triangular factor (n, m).
        w: Out: the least-norm rates (n,), set unless 0 is returned.
        qdot: Out: the scaled rates (n,), set where 1 is returned with u >= 0.

    Returns:
        ``(fit, u)``: fit 0 where the rows are numerically dependent or more than the joints
        (w not set), 1 where w is outside ``[lb, ub]``, 2 inside; u the largest scale in
        [0, 1] along w where fit is 1 and n - m <= 1, else -1.
    """
    m, n = J.shape
    householder_qr(J.T, Q, R)
    if m > n or not least_norm_rates(Q, R, b, w):
        return 0, -1.0
    if inside(w, lb, ub):
        return 2, -1.0
    if n - m > 1:
        return 1, -1.0
    if n == m:
        u = uniform_scale(w, lb, ub)
        for i in range(n):
            qdot[i] = u * w[i]
        return 1, u
    v = qdot  # Q's column m, contiguous: one compiled signature of line_scale
    for i in range(n):
        v[i] = Q[i, m]
    u, y = line_scale(w, v, lb, ub)
    for i in range(n):
        qdot[i] = u * w[i] + y * v[i]
    return 1, u


