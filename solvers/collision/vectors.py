r"""Points and directions in space as tuples of three floats, for the compiled collision kernels.

numba keeps a tuple of floats in registers: a kernel that names its points ``a0``, ``u`` and
writes ``along(a0, s, u)`` for :math:`a_0 + s\,u` pays nothing for it, where a slice of an
array (a view, counted by numba's runtime at every creation) or a small temporary array costs
more than the arithmetic. Each function is one formula, in the order its terms are summed.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.compiled import kernel

Array = npt.NDArray[np.float64]
Vector = tuple[float, float, float]


@kernel
def dot(a: Vector, b: Vector) -> float:
    r""":math:`a \cdot b`."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@kernel
def sub(a: Vector, b: Vector) -> Vector:
    r""":math:`a - b`."""
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@kernel
def along(a: Vector, s: float, u: Vector) -> Vector:
    r""":math:`a + s\,u`."""
    return (a[0] + s * u[0], a[1] + s * u[1], a[2] + s * u[2])


@kernel
def cross(a: Vector, b: Vector) -> Vector:
    r""":math:`a \times b`."""
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@kernel
def norm(a: Vector) -> float:
    r""":math:`\|a\|`."""
    return math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])


@kernel
def placed(poses: Array, j: int, p: Vector) -> Vector:
    r""":math:`R_j p + t_j`: the point ``p`` given in frame ``j`` of ``poses`` (n, 4, 4)."""
    return (
        poses[j, 0, 0] * p[0] + poses[j, 0, 1] * p[1] + poses[j, 0, 2] * p[2] + poses[j, 0, 3],
        poses[j, 1, 0] * p[0] + poses[j, 1, 1] * p[1] + poses[j, 1, 2] * p[2] + poses[j, 1, 3],
        poses[j, 2, 0] * p[0] + poses[j, 2, 1] * p[1] + poses[j, 2, 2] * p[2] + poses[j, 2, 3],
    )
