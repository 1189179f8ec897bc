"""What every QP backend provides: one ``solve(problem) -> QPSolution`` method."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import NamedTuple

import numpy as np
import numpy.typing as npt

from solvers.qp_problem import QPProblem

Array = npt.NDArray[np.float64]


class QPSolution(NamedTuple):
    """What a backend returned for one :class:`~solvers.qp_problem.QPProblem`.

    Attributes:
        x: Primal solution (nx,), or None when none was found. Within the backend's
            tolerance only: the caller enforces the box exactly.
        found: True when the backend reports a solution (possibly inaccurate).
        status: The backend's own status string.
        iterations: Iterations used (0 where the backend does not say).
        build_time: Time spent turning the problem into the backend's data [s].
        solve_time: Time spent in the backend's solver [s].
        backend: Backend name.
    """

    x: Array | None
    found: bool
    status: str
    iterations: int
    build_time: float
    solve_time: float
    backend: str


class QPBackend(ABC):
    """A QP solver behind one method; may keep warm-start state between calls.

    Attributes:
        name: Backend name, as :func:`solvers.qp_backends.make_backend` takes it.
        warm_starts: True when the previous solution seeds the next solve.
    """

    name: str
    warm_starts: bool = False

    @abstractmethod
    def solve(self, problem: QPProblem) -> QPSolution:
        """Solve ``problem``.

        Raises:
            ProblemError: The backend raised (bad data, crash); not for an unsolved QP, which
                returns ``found=False``.
        """

    @abstractmethod
    def reset(self) -> None:
        """Forget every warm-start value (the next solve starts cold)."""

    @abstractmethod
    def warm_start_state(self) -> dict[str, Array]:
        """Copies of the values that seed the next solve, keyed by problem structure."""


def structure_key(problem: QPProblem) -> str:
    """Key of a problem's structure (kind and sizes): one warm-start slot per key."""
    ng = 0 if problem.G is None else problem.G.shape[0]
    return f"{problem.kind}:{problem.P.shape[0]}x{ng}"
