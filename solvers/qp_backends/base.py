"""What every QP backend provides: ``solve(qp) -> QPSolution``, with its own warm starts."""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any

import numpy as np
import numpy.typing as npt

from rrc_pin.solvers.qp_backends.qp import QP
from rrc_pin.solvers.qp_backends.qp import QPSolution as QPSolution  # its home once

Array = npt.NDArray[np.float64]


class QPBackend(ABC):
    """A QP solver behind one method; keeps warm-start values per problem structure.

    Args:
        **options: The solver's settings (checked by
        :func:`rrc_pin.solvers.qp_backends.make_backend`).

    Attributes:
        name: Backend name, as :func:`rrc_pin.solvers.qp_backends.make_backend` takes it.
        options: The settings passed to the solver at every solve.
        time_limit: [s] The most time a solve may take, or None (set by ``make_backend``).
    """

    name: str
    time_limit: float | None = None

    def __init__(self, **options: Any) -> None:
        self.options = dict(options)
        self._last: dict[str, Array] = {}

    @abstractmethod
    def solve(self, qp: QP) -> QPSolution:
        """Solve ``qp``, warm-started from the last solution of the same ``qp.key``.

        Raises:
            ProblemError: The solver raised (bad data, unknown setting); an unsolved QP is
                not an error: it returns ``x = None``.
        """

    def _start(self, qp: QP) -> Array | None:
        """The last solution of ``qp.key`` if it has ``qp``'s size, else None.

        A key reused for another size must not pass a warm start of the wrong length.
        """
        x = self._last.get(qp.key)
        return x if x is not None and x.shape == qp.q.shape else None

    def _remember(self, qp: QP, x: Array | None) -> None:
        """Keep ``x`` as the warm start of ``qp.key``; a failed solve (None) drops it."""
        if x is None:
            self._last.pop(qp.key, None)
        else:
            self._last[qp.key] = x

    def reset(self) -> None:
        """Forget every warm-start value (the next solves start cold)."""
        self._last.clear()

    def warm_start_state(self) -> dict[str, Array]:
        """Copies of the values that seed the next solves, by problem key."""
        return {key: x.copy() for key, x in self._last.items()}
