"""The protocol every closed-form fast path follows (docs/api.md, closed forms), and its helpers."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from solvers.validation import as_array, as_vector

Array = npt.NDArray[np.float64]
Entry = Any
"""A quantity of a kernel: a Python float (one configuration) or an (N,) float array."""


class ClosedForm(ABC):
    """Closed-form Jacobian and joint rates of one paper arm.

    Frames: the Jacobian rows are ``[v; w]`` of the origin of :attr:`frame` in base-frame
    axes (``world_aligned``), the first :attr:`task_dim` rows of ``Robot.jacobian(q)`` when
    the robot's tool frame is :attr:`frame`.

    Subclasses implement all four methods, the scalar ones on Python floats (one
    configuration; faster than a batch of one) and the batch ones on (N,) arrays, both from
    the same kernels.

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
            InputError: Wrong shape or non-finite entries.
        """

    @abstractmethod
    def joint_rates_batch(self, Q: npt.ArrayLike, X: npt.ArrayLike) -> Array:
        """Joint rates (N, nq) realising the task velocities ``X`` (N, task_dim) at ``Q`` (N, nq).

        ``X`` in [m/s] then [rad/s]. The exact solution where the Jacobian is square and
        regular, the minimum-norm one where the arm is redundant.

        Raises:
            InputError: Wrong shapes or non-finite entries.
        """

    @abstractmethod
    def jacobian(self, q: npt.ArrayLike) -> Array:
        """Jacobian at one configuration ``q`` (nq,): shape (task_dim, nq).

        Raises:
            InputError: ``q`` is not a finite (nq,) vector.
        """

    @abstractmethod
    def joint_rates(self, q: npt.ArrayLike, xdot: npt.ArrayLike) -> Array:
        """Joint rates (nq,) realising the task velocity ``xdot`` (task_dim,) at ``q`` (nq,).

        Raises:
            InputError: Wrong shapes or non-finite entries.
        """

    def _check_batch(self, Q: npt.ArrayLike, X: npt.ArrayLike) -> tuple[Array, Array]:
        """Validate ``Q`` (N, nq) and ``X`` (N, task_dim) with the same N."""
        Q = as_array(Q, "Q", (None, self.nq))
        return Q, as_array(X, "X", (Q.shape[0], self.task_dim))


def row(x: npt.ArrayLike, name: str, size: int) -> Array:
    """``x`` checked as a finite (size,) vector named ``name``, as a batch of one (1, size)."""
    return as_vector(x, name, size)[None]


def first(batch: Array) -> Array:
    """The first item of a batch (a batch of one answering a scalar call)."""
    item: Array = batch[0]
    return item


def dot(u: Sequence[Entry], v: Sequence[Entry]) -> Entry:
    """Sum of ``u[k] * v[k]``, skipping exact float zeros and ones (constant entries).

    Measured: the Jacobians and blocks of the closed forms hold such constants; skipping
    them saves 10-20 % of the batch time of the solves built on this.
    """
    acc: Entry = 0.0
    for a, b in zip(u, v, strict=True):
        if type(a) is float and (a == 0.0 or a == 1.0):
            if a:
                acc = acc + b
        elif type(b) is float and (b == 0.0 or b == 1.0):
            if b:
                acc = acc + a
        else:
            acc = acc + a * b
    return acc


def stack_entries(rows: Sequence[Sequence[Entry]], n: int) -> Array:
    """The matrices (n, R, C) whose entry (r, c) is ``rows[r][c]`` (a float or an (n,) array)."""
    out = np.empty((n, len(rows), len(rows[0])))
    for r, entries in enumerate(rows):
        for c, value in enumerate(entries):
            out[:, r, c] = value
    return out
