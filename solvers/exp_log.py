r"""SO(3)'s exponential and logarithm, compiled, as Pinocchio's.

:func:`exp3` is ``pinocchio.exp3`` (spatial/explog.hxx): with :math:`t^2 = |v|^2 + \epsilon^2`,
:math:`\exp [v]_\times = \cos t\, I + \frac{\sin t}{t} [v]_\times + \frac{1 - \cos t}{t^2}
v v^T`, the ratios from their series :math:`1 - t^2/6`, :math:`1/2 - t^2/24` and
:math:`\cos t` from :math:`1 - t^2/2` at :math:`t \le` :data:`PREC3`.

:func:`log3` is ``pinocchio.log3`` (Pinocchio's ``log3_impl``, spatial/log.hxx) step by step:
the rotation renormalised (its first two columns scaled to unit length, the third and then
the first made of cross products), :math:`\cos\theta = (\operatorname{tr} R - 1)/2`, and

.. math::

    \log R = \frac{\theta}{\sin\theta}\,\operatorname{vee}\!\Big(\frac{R - R^T}{2}\Big),
    \qquad \theta = \arccos\frac{\operatorname{tr} R - 1}{2},

with :math:`\theta` taken from :math:`\sqrt{2(1 - \cos\theta)}` within :data:`PREC` of 0 and
of :math:`\pi` (the arc cosine's expansion), the ratio from its series
:math:`1 + |a|^2/6 + 3|a|^4/40` (:math:`a` the vee above) below :data:`PREC`, and near
:math:`\pi` (:math:`\cos\theta < -1 +` :data:`PREC`) the axis from the largest diagonal term of
:math:`R + R^T` (``compute_theta_axis``), the angle :math:`2\,\mathrm{atan2}(|axis|, w)`.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import inlined, kernel

Array = npt.NDArray[np.float64]

EPS = float(np.finfo(np.float64).eps)
"""The machine epsilon (Eigen's ``NumTraits<double>::epsilon``)."""
PREC = EPS ** (1.0 / 3.0)
"""Pinocchio's ``TaylorSeriesExpansion<double>::precision<2>()``: eps^(1/3)."""
PREC3 = EPS ** (1.0 / 4.0)
"""Pinocchio's ``TaylorSeriesExpansion<double>::precision<3>()``: eps^(1/4)."""


@inlined
def exp3(v: Array, out: Array) -> None:
    """``pinocchio.exp3(v)`` of a rotation vector ``v`` (3,) [rad] into ``out`` (3, 3)."""
    t2 = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + EPS * EPS
    t = math.sqrt(t2)
    st, ct = math.sin(t), math.cos(t)
    if t > PREC3:
        a_vxvx, a_vx = (1.0 - ct) / t2, st / t
    else:
        a_vxvx, a_vx, ct = 0.5 - t2 / 24.0, 1.0 - t2 / 6.0, 1.0 - t2 / 2.0
    for i in range(3):
        for j in range(3):
            out[i, j] = (a_vxvx * v[i]) * v[j]
    out[0, 1] -= a_vx * v[2]
    out[1, 0] += a_vx * v[2]
    out[0, 2] += a_vx * v[1]
    out[2, 0] -= a_vx * v[1]
    out[1, 2] -= a_vx * v[0]
    out[2, 1] += a_vx * v[0]
    for i in range(3):
        out[i, i] += ct


@kernel
def displaced(T: Array, delta: Array, out: Array) -> None:
    r"""Pose ``T`` (4, 4) moved by the base-axes displacement ``delta`` (6,) [m, rad] of its
    origin into ``out`` (4, 4): :math:`p + \delta_v`, :math:`\exp([\delta_\omega]_\times) R`."""  # noqa: D205, D209
    E = np.empty((3, 3))
    exp3(delta[3:], E)
    for i in range(3):
        for j in range(3):
            out[i, j] = E[i, 0] * T[0, j] + E[i, 1] * T[1, j] + E[i, 2] * T[2, j]
        out[i, 3] = T[i, 3] + delta[i]
        out[3, i] = T[3, i]
    out[3, 3] = T[3, 3]


@inlined
def renormalized(R: Array, out: Array) -> None:
    """Rotation ``R`` (3, 3) renormalised into ``out`` (``renormalize_rotation_matrix``)."""
    n0 = math.sqrt(R[0, 0] * R[0, 0] + R[1, 0] * R[1, 0] + R[2, 0] * R[2, 0])
    n1 = math.sqrt(R[0, 1] * R[0, 1] + R[1, 1] * R[1, 1] + R[2, 1] * R[2, 1])
    for i in range(3):
        out[i, 0] = R[i, 0] / n0
        out[i, 1] = R[i, 1] / n1
    for i in range(3):  # column 2 = column 0 x column 1
        j, k = (i + 1) % 3, (i + 2) % 3
        out[i, 2] = out[j, 0] * out[k, 1] - out[k, 0] * out[j, 1]
    for i in range(3):  # column 0 = column 1 x column 2
        j, k = (i + 1) % 3, (i + 2) % 3
        out[i, 0] = out[j, 1] * out[k, 2] - out[k, 1] * out[j, 2]


@inlined
def _singular_axis(i0: int, val: float, R: Array, axis: Array) -> float:
    """The angle near pi and its unit axis into ``axis`` (3,) from diagonal term ``i0``
    (Pinocchio's ``compute_theta_axis``); ``R`` renormalised."""  # noqa: D205, D209
    i1, i2 = (i0 + 1) % 3, (i0 + 2) % 3
    s = math.sqrt(val + EPS + EPS * EPS) * (1.0 if R[i2, i1] >= R[i1, i2] else -1.0)
    axis[i0] = s / 2.0
    axis[i1] = 1.0 / (2.0 * s) * (R[i1, i0] + R[i0, i1])
    axis[i2] = 1.0 / (2.0 * s) * (R[i2, i0] + R[i0, i2])
    w = 1.0 / (2.0 * s) * (R[i2, i1] - R[i1, i2])
    norm = math.sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2])
    for k in range(3):
        axis[k] /= norm
    return 2.0 * math.atan2(norm, w)


@inlined
def log3(R: Array, out: Array) -> float:
    """``pinocchio.log3(R)`` of rotation ``R`` (3, 3) into ``out`` (3,) [rad]; returns the angle.

    Module docstring; ``R`` is read only (renormalised into a copy).
    """
    Rn = np.empty((3, 3))
    renormalized(R, Rn)
    tr = Rn[0, 0] + (Rn[1, 1] + Rn[2, 2])  # Eigen's unrolled sum
    cos_value = (tr - 1.0) / 2.0
    a0 = 0.5 * (Rn[2, 1] - Rn[1, 2])
    a1 = 0.5 * (Rn[0, 2] - Rn[2, 0])
    a2 = 0.5 * (Rn[1, 0] - Rn[0, 1])
    if cos_value < -1.0 + PREC:  # near pi: the axis from the largest diagonal term
        v0, v1, v2 = (2.0 * Rn[0, 0] - tr + 1.0, 2.0 * Rn[1, 1] - tr + 1.0,
                      2.0 * Rn[2, 2] - tr + 1.0)  # fmt: skip
        i0 = (0 if v0 >= v2 else 2) if v0 >= v1 else (1 if v1 >= v2 else 2)
        val = v0 if i0 == 0 else (v1 if i0 == 1 else v2)
        theta = _singular_axis(i0, val, Rn, out)
        for k in range(3):
            out[k] *= theta
        return theta
    expansion = math.sqrt(2.0 * (1.0 - cos_value) + EPS * EPS)
    if tr > 3.0 - PREC:
        theta = expansion
    elif tr < -1.0 + PREC:
        theta = math.pi - expansion
    else:
        theta = math.acos(cos_value)
    if theta >= PREC:
        t = theta / math.sin(theta)
    else:
        a2n = a0 * a0 + a1 * a1 + a2 * a2
        t = 1.0 + a2n / 6.0 + a2n * a2n * 3.0 / 40.0
    out[0], out[1], out[2] = t * a0, t * a1, t * a2
    return theta


@inlined
def pose_error(target: Array, pose: Array, out: Array) -> None:
    """A frame's pose error to its target into ``out`` (6,): ``[p* - p; log(R* R^T)]`` [m, rad].

    Args:
        target: The goal pose (4, 4) [m].
        pose: The frame's pose (4, 4) in the same axes [m].
        out: Out (6,), rows [position; rotation] in those axes.
    """
    turn = np.empty((3, 3))  # R* R^T
    for i in range(3):
        out[i] = target[i, 3] - pose[i, 3]
        for j in range(3):
            turn[i, j] = (target[i, 0] * pose[j, 0] + target[i, 1] * pose[j, 1]
                          + target[i, 2] * pose[j, 2])  # fmt: skip
    log3(turn, out[3:])
