"""The protocol every closed-form fast path follows (docs/api.md, closed forms), and its helpers."""

from __future__ import annotations

import math
from abc import ABC, abstractmethod

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.checks import all_finite, as_array, as_vector
from rrc_pin.solvers.compiled import kernel
from rrc_pin.solvers.errors import InvalidInput

Array = npt.NDArray[np.float64]
_F64 = np.dtype(np.float64)


class ClosedForm(ABC):
    """Closed-form Jacobian and joint rates of one paper arm.

    Frames: the Jacobian rows are ``[v; w]`` of the origin of :attr:`frame` in base-frame
    axes (``world_aligned``), the first :attr:`task_dim` rows of ``Robot.jacobian(q)`` when
    the robot's tool frame is :attr:`frame`.

    Subclasses implement all four methods from the same compiled kernels: the batch ones
    loop over the rows inside the kernel.

    Attributes:
        nq: Number of joints.
        task_dim: Rows of the task: 6 (twist) or 3 (linear velocity only).
        frame: Name of the frame of the generated URDF whose twist the closed form answers
            for (``"tool"`` for every paper arm).
    """

    nq: int
    task_dim: int
    frame: str = "tool"

    @abstractmethod
    def jacobian_batch(self, Q: npt.ArrayLike) -> Array:
        """Jacobians (N, task_dim, nq) at N configurations ``Q`` (N, nq) [rad] or [m].

        Raises:
            InvalidInput: Wrong shape or non-finite entries.
        """

    @abstractmethod
    def joint_rates_batch(self, Q: npt.ArrayLike, X: npt.ArrayLike) -> Array:
        """Joint rates (N, nq) realising the task velocities ``X`` (N, task_dim) at ``Q`` (N, nq).

        ``X`` in [m/s] then [rad/s]. The exact solution where the Jacobian is square and
        regular, the minimum-norm one where the arm is redundant.

        Raises:
            InvalidInput: Wrong shapes or non-finite entries.
        """

    @abstractmethod
    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Jacobian at one configuration ``q`` (nq,): shape (task_dim, nq).

        Raises:
            InvalidInput: ``q`` is not a finite (nq,) vector.
        """

    @abstractmethod
    def joint_rates(self, q: npt.ArrayLike, xdot: npt.ArrayLike) -> Array:
        """Joint rates (nq,) realising the task velocity ``xdot`` (task_dim,) at ``q`` (nq,).

        Raises:
            InvalidInput: Wrong shapes or non-finite entries.
        """

    def _check_batch(self, Q: npt.ArrayLike, X: npt.ArrayLike) -> tuple[Array, Array]:
        """Validate ``Q`` (N, nq) and ``X`` (N, task_dim) with the same N."""
        Q = as_array(Q, "Q", (None, self.nq))
        return Q, as_array(X, "X", (Q.shape[0], self.task_dim))


def row(x: npt.ArrayLike, name: str, size: int) -> Array:
    """``x`` checked as a finite (size,) vector named ``name``, as a batch of one (1, size)."""
    return as_vector(x, name, size)[None]


def finite_rates(rates: Array, name: str) -> Array:
    """``rates``, checked finite: a command so large that its joint rates overflow is refused.

    Raises:
        InvalidInput: Naming ``name`` (the command) where a rate is not finite.
    """
    if not all_finite(rates):
        raise InvalidInput(name, "a command whose joint rates overflow the float range")
    return rates


def first(batch: Array) -> Array:
    """The first item of a batch (a batch of one answering a scalar call)."""
    item: Array = batch[0]
    return item


def vector(x: npt.ArrayLike, name: str, size: int) -> Array:
    """``x`` as a float64 vector for a kernel that checks its size and entries (:func:`finite`).

    A float64 vector passes as it is, anything else through
    :func:`~rrc_pin.solvers.checks.as_vector` (which raises :class:`InvalidInput` naming ``name``).
    Where the kernel refuses it, the caller calls ``as_vector`` again to raise. The checks of
    the common case are one pass inside the kernel.
    """
    if type(x) is np.ndarray and x.dtype is _F64 and x.ndim == 1:
        return x
    return as_vector(x, name, size)


@kernel
def finite(x: Array, size: int) -> bool:
    """Whether the vector ``x`` has ``size`` entries, all finite (the kernels' input check)."""
    if x.size != size:
        return False
    for i in range(size):
        if not math.isfinite(x[i]):
            return False
    return True
