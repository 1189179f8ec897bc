"""Cartesian error of a tool pose: position difference and the quaternion orientation error.

The orientation error is Nguyen & Zhou's eqs. (32)-(37), computed by
:mod:`rrc_pin.solvers.closed_form.quaternion` (not rewritten here): the quaternion of ``R_d R^T``
from those of ``R`` and ``R_d`` (eqs. (32)-(34)), and the differential rotation
``2 delta s`` (eq. (37)), in base axes.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.closed_form.quaternion import (
    differential_rotation,
    quaternion_difference,
    quaternion_from_matrix,
)

Array = npt.NDArray[np.float64]


def pose_error(T: Array, T_d: Array) -> Array:
    """``[p_d - p; delta]`` (6,) [m, rad], base axes: what takes pose ``T`` to ``T_d``.

    Args:
        T: Current tool pose (4, 4), or a stack (N, 4, 4).
        T_d: Desired tool pose, same shape.

    Returns:
        (6,), or (N, 6) for stacks.
    """
    Ts, Tds = np.asarray(T, dtype=float), np.asarray(T_d, dtype=float)
    single = Ts.ndim == 2
    Ts, Tds = Ts.reshape(-1, 4, 4), Tds.reshape(-1, 4, 4)
    n = Ts.shape[0]
    quats = quaternion_from_matrix(np.concatenate([Ts[:, :3, :3], Tds[:, :3, :3]]))  # one call
    delta = differential_rotation(quaternion_difference(quats[:n], quats[n:]))
    out = np.concatenate([Tds[:, :3, 3] - Ts[:, :3, 3], delta], axis=1)
    return np.asarray(out[0] if single else out, dtype=np.float64)
