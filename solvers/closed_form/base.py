"""The protocol every closed-form fast path follows (DESIGN.md, "Public API")."""

from __future__ import annotations

from abc import ABC, abstractmethod

import numpy as np
import numpy.typing as npt

from solvers.validation import as_array, as_vector


class ClosedForm(ABC):
    """Closed-form Jacobian and joint rates of one paper arm.

    Frames: the Jacobian rows are ``[v; w]`` of the tool-frame origin in base-frame axes
    (``world_aligned``), the first :attr:`task_dim` rows of ``Robot.jacobian(q)``.

    Subclasses implement the two batch methods; the scalar methods default to a batch of one
    and may be overridden by faster scalar code.

    Attributes:
        nq: Number of joints.
        task_dim: Rows of the task: 6 (twist) or 3 (linear velocity only).
    """

    nq: int
    task_dim: int

    @abstractmethod
    def jacobian_batch(self, Q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Jacobians at N configurations.

        Args:
            Q: Joint positions, shape (N, nq), [rad] or [m].

        Returns:
            Array of shape (N, task_dim, nq).

        Raises:
            InputError: Wrong shape or non-finite entries.
        """

    @abstractmethod
    def joint_rates_batch(self, Q: npt.ArrayLike, X: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Joint rates realising the task velocities at N configurations.

        Args:
            Q: Joint positions, shape (N, nq).
            X: Task velocities, shape (N, task_dim), [m/s] then [rad/s].

        Returns:
            Joint rates, shape (N, nq): the exact solution where the Jacobian is square and
            regular, the minimum-norm one where the arm is redundant.

        Raises:
            InputError: Wrong shapes or non-finite entries.
        """

    def jacobian(self, q: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Jacobian at one configuration ``q`` (nq,): shape (task_dim, nq)."""
        q = as_vector(q, "q", self.nq)
        return self.jacobian_batch(q[None, :])[0]

    def joint_rates(self, q: npt.ArrayLike, xdot: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Joint rates (nq,) realising the task velocity ``xdot`` (task_dim,) at ``q`` (nq,)."""
        q = as_vector(q, "q", self.nq)
        xdot = as_vector(xdot, "xdot", self.task_dim)
        return self.joint_rates_batch(q[None, :], xdot[None, :])[0]

    def _check_batch(
        self, Q: npt.ArrayLike, X: npt.ArrayLike | None = None
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64] | None]:
        """Validate ``Q`` (N, nq) and, if given, ``X`` (N, task_dim) with the same N."""
        Q = as_array(Q, "Q", (None, self.nq))
        if X is None:
            return Q, None
        X = as_array(X, "X", (Q.shape[0], self.task_dim))
        return Q, X
