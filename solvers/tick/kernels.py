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
def clamp_pushed(J: Array, w: Array, lb: Array, ub: Array, still: float, out: Array) -> bool:
    """J's columns of the joints that ``w`` pushes against a bound holding them still, zeroed.

    A joint is held where its bound on the side ``w`` moves it is within ``still`` of zero
    (Baerlocher & Boulic 2004's clamping).

    Args:
        J: The rows (m, n).
        w: The rates (n,).
        lb: Lower bounds (n,).
        ub: Upper bounds (n,).
        still: A bound within this of zero holds its joint.
        out: Out: J with those columns zeroed (m, n), set where True is returned.

    Returns:
        Whether any joint is held.
    """
    m, n = J.shape
    any_held = False
    for j in range(n):
        held = (w[j] > 0.0 and ub[j] <= still) or (w[j] < 0.0 and lb[j] >= -still)
        any_held = any_held or held
        for i in range(m):
            out[i, j] = 0.0 if held else J[i, j]
    return any_held


@kernel
def damping_lambda_sq(
    sigma: Array, rank: int, scale: float, along: Array, dt: float, threshold: float, lam: Array
) -> bool:
    r"""Squared damping per singular direction (:mod:`rrc_pin.solvers.tick.damping`'s schedule).

    With the onset :math:`\sigma_{on} = \sigma_1/\kappa`, every direction i < rank whose
    singular value is below it gets :math:`\lambda_i^2 = (1 - (\sigma_i/\sigma_{on})^2)\,
    \max(\sigma_{on}^2, \sigma_1 |u_i^T b|\,\Delta t)\,(1 - u^*)` (Maciejewski & Klein 1988's
    smooth onset, with a floor for the step), the others zero.

    Args:
        sigma: Singular values (k,), descending.
        rank: How many of them count.
        scale: The LP maximum :math:`u^*` in [0, 1].
        along: :math:`|u_i^T b|` (k,).
        dt: The step [s].
        threshold: :math:`\kappa`.
        lam: Out: the squared damping (k,), set where True is returned.

    Returns:
        False where none applies (no rank, :math:`u^* \ge 1`, or every counted singular value
        at or above the onset).
    """
    if rank == 0 or scale >= 1.0:
        return False
    onset = sigma[0] / threshold
    if sigma[rank - 1] >= onset:
        return False
    for i in range(sigma.size):
        lam[i] = 0.0
        if i < rank and sigma[i] < onset:
            floor = max(onset * onset, sigma[0] * along[i] * dt)
            ratio = sigma[i] / onset
            lam[i] = (1.0 - ratio * ratio) * floor * (1.0 - scale)
    return True


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


@kernel
def scale_and_veer(y: Array, b: Array, factor: Array | None = None) -> tuple[float, float]:
    r"""Fraction of ``b`` achieved along it by ``y`` (in [0, 1]) and the angle between them [rad].

    The scale is :math:`y^Tb/b^Tb` and the angle :math:`\arccos(y^Tb/(|y||b|))`, computed on
    both divided by their largest entries so that no product overflows; the ratio of those
    entries is formed with the larger one as divisor (a subnormal command's would overflow).

    Args:
        y: Achieved rates (m,).
        b: Commanded rates (m,).
        factor: Row factors (m,) of a level's metric, or None: the scale and angle of
            ``factor * y`` and ``factor * b``, both first divided by b's largest entry where
            it exceeds 1 (so that the factors cannot overflow a command near the float range;
            a subnormal one is not divided up: the achieved rates would overflow).

    Returns:
        (scale, veer): (1, 0) for a zero command, (0, 0) for zero rates.
    """
    m = b.size
    ys, bs = np.empty(m), np.empty(m)
    if factor is None:
        for i in range(m):
            ys[i] = y[i]
            bs[i] = b[i]
    else:
        peak = 1.0
        for i in range(m):
            peak = max(peak, abs(b[i]))
        for i in range(m):
            ys[i] = factor[i] * (y[i] / peak)
            bs[i] = factor[i] * (b[i] / peak)
    top_b = 0.0
    top_y = 0.0
    for i in range(m):
        top_b = max(top_b, abs(bs[i]))
        top_y = max(top_y, abs(ys[i]))
    if top_b == 0.0:
        return 1.0, 0.0
    if top_y == 0.0:
        return 0.0, 0.0
    yb = yy = bb = 0.0
    for i in range(m):
        yn, bn = ys[i] / top_y, bs[i] / top_b
        yb += yn * bn
        yy += yn * yn
        bb += bn * bn
    cosine = yb / (math.sqrt(yy) * math.sqrt(bb))
    veer = math.acos(min(max(cosine, -1.0), 1.0))
    along = yb / bb  # the scale, times top_b / top_y
    if along <= 0.0:
        return 0.0, veer
    if top_y <= top_b:
        return min(along * (top_y / top_b), 1.0), veer
    ratio = top_b / top_y
    return (along / ratio if along < ratio else 1.0), veer
